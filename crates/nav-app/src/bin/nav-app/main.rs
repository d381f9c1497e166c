//! `nav-app`: the product binary — the lane tracker at the terminal (`lane.rs`), the labelled
//! lane benchmark on a user's own labels (`nav-app eval-lanes`, `nav-app import-lanes`,
//! `bench.rs`), the INS/SD log replay (`nav-app ins`, `ins.rs`) and the INS/SD paper's Monte
//! Carlo (`nav-app monte-carlo`, `monte_carlo.rs`). Each is a thin layer of argument parsing and
//! printing over the library crates (`lane-tracker` and `lane-io` for the lanes, `lane-scenes`
//! for the rendered sample input, `lane-bench` for the benchmark, `ins-sim` and
//! `ins-monte-carlo` for the INS).
//!
//! ```text
//! nav-app [--input PATH | --device PATH] [--config default|outdoor|indoor|FILE.toml]
//!         [--estimator kif|wrls] [--json] [--overlay DIR|FILE.y4m] [--max-frames N] [--loop]
//!         [--dir-fps HZ] [--topic TOPIC] [--mcap-out FILE]
//!         [--camera robot|highway|FILE.toml [--birdseye DIR]]
//!         [--foxglove [ADDR] [--wait-client]] [--realtime]
//!         [--input-name NAME | --input-index N] [--std ntsc|pal|…] [--size WxH] [--max-timeouts N]
//! ```
//! With neither `--input` nor `--device` it runs on a rendered sample (the project's own
//! deterministic scene `curve_left_dashed`, `lane_scenes`). `--input -` reads a YUV4MPEG2
//! stream on stdin.
//!
//! ## Live capture (`--device`, feature `capture`)
//! `--device /dev/video0 --input-name S-Video --std ntsc --size 320x240` streams grey frames from
//! a V4L2 capture node (the paper's BT848/878 card under `bttv`, or vivid) through
//! `lane_io::capture_source`. The driver's size and format are used; ERROR-flagged buffers are
//! dropped and counted, dropped frames counted from sequence gaps, signal loss flagged per frame.
//! On stderr: frames/s, errored and dropped frames, timeouts and signal loss at the end (and
//! signal-loss changes as they happen). With `--json` every frame object also carries
//! `"capture": {"sequence", "timestamp_us", "format", "width_px", "height_px", "missed",
//! "signal_lost", "mean_grey"}`, and the last line is always (also after an error)
//! the summary line with the capture counters (`docs/json.md`).
//!
//! A frame timeout (no frame within the timeout, 1000 ms) restarts the stream and is reported;
//! the `--max-timeouts`-th in a row (default 3) ends the run. Built without the `capture` feature,
//! `--device` fails saying capture is not in this build.
//!
//! ## The labelled lane benchmark
//! `nav-app import-lanes --format tusimple|culane --out SETS/NAME [--root DIR] [--kind
//! road|indoor] LABELS…` writes TuSimple or CULane labels as a set; `nav-app eval-lanes --data
//! SETS [--config NAME|FILE…] [--out DIR] [--dev-only] [--census] [--check|--record --floors
//! FILE]` scores the tracker on every set under `SETS` (see `lane_bench::protocol`).
//!
//! ## INS/SD log replay
//! `nav-app ins --imu imu.csv [--sightings sightings.csv --landmarks landmarks.toml]
//! [--init initial.toml | --truth reference.csv [--start-s T]] [--config filter.toml | --preset
//! mems|paper] [--filter none|kf|akf|akf_sage_husa|akf_structured] [--align-s S] [--gate P]
//! [--max-gap-s S] [--rate HZ] --out solution.csv [--truth reference.csv [--metrics-json FILE]
//! [--plot FILE.png]]` replays an IMU log (increments or rates) through the online filter
//! (`ins_sd_filter`), aided by sightings or unaided; the filter settings come from a filter file
//! in datasheet units or a compiled-in preset (`ins_sim::filter_file`; default `mems`, so it runs
//! from any directory). `nav-app ins sightings --reference reference.csv --landmarks
//! landmarks.toml [--make-landmarks N] --out sightings.csv` writes sightings from a reference
//! trajectory. The formats are in `ins_sim::logs`; `nav-app monte-carlo --export-logs DIR` writes
//! a simulated run in them.
//!
//! ## The INS/SD Monte Carlo
//! `nav-app monte-carlo [--config configs/paper.toml] [--runs N] [--seed S] [--out DIR]
//! [--threads T] [--shard i/n] [--duration S] [--filters LIST] [--sweep KEY=V1,…]
//! [--export-logs DIR]`, `nav-app monte-carlo merge DIR… [--out DIR] [--allow-partial]` and
//! `nav-app monte-carlo scenarios [--dir configs/mismatch] [--matched configs/paper.toml]`:
//! see `ins_monte_carlo` (outputs, statistics, shards on a cluster). The scenario
//! file is required to exist (`configs/paper.toml` in the current directory unless `--config`).
//!
//! Hidden test flags (for `cargo xtask vivid`, not in `--help`): `--format FOURCC` (only this
//! pixel format), `--timeout-ms MS`, `--ctrl NAME=VALUE@FRAME` (set a V4L2 control once FRAME
//! frames have been delivered; repeatable), `--ctrl-on-timeout NAME=VALUE` (set at the first
//! timeout; repeatable).
//!
//! ## Damaged input and the summary
//! A frame that cannot be used — an image of a directory that does not decode, a YUV4MPEG2 stream
//! damaged where a `FRAME` header should be (the reader skips to the next `FRAME` marker, see
//! `lane_io::y4m::Y4mSource`), a short last frame — is reported on stderr, counted and skipped;
//! the run goes on. The last stderr line says `N frames tracked, L frames lost (B bytes
//! skipped)`. With `--json` the last stdout line is always (every input, also after an error)
//! the summary line (`docs/json.md`).
//!
//! ## Live (`--foxglove`, `live.rs`)
//! `--foxglove [ADDR]` serves the channels of `--mcap-out` live over Foxglove's WebSocket
//! protocol (crate `foxglove_live`; default `127.0.0.1:8765`), for the lanes and for `nav-app ins`;
//! `--wait-client` waits for a subscription, `--realtime` paces a recorded input at its own
//! timestamps, and Ctrl-C (SIGINT) ends a run cleanly (`"exit": "interrupted"`).
//!
//! ## Lanes in metres (`--camera`)
//! With a camera file (read by `lane_io::config::load_camera_config`, the model in
//! `lane_tracker::camera`) every `--json` frame object also carries `ego_lane`
//! (`lateral_offset_m`, `heading_rad`, `curvature_per_m`, `lane_width_m` and each one's
//! `*_sigma`; `null` unless both lanes are held) and `lane_cov_px` (each lane's 3×3 covariance
//! of `[a1, a2, a3]`, rows, or `null`); `--birdseye DIR` writes `birdseye_NNNNNN.png`, the
//! ground seen from above (`lane_io::birdseye`). The camera file must be for the input's frame
//! size (`image_size_px`).
//!
//! ## Exit codes
//! `docs/exit-codes.md` (each subcommand's `--help` prints its own).

// The argument structs' doc comments (in `ins.rs`, `lane.rs`, `monte_carlo.rs`) are the
// `--help` text clap prints verbatim (`[default: OUT_ROOT/<config>-…]`, `[[landmarks]]`,
// `[trajectory]`), not rustdoc markup: rustdoc would read those brackets as links.
#![allow(rustdoc::broken_intra_doc_links, rustdoc::invalid_html_tags)]

use std::process::ExitCode;

mod bench;
mod device_args;
mod ins;
mod lane;
mod live;
mod monte_carlo;

/// `e` and its causes on one line, `e: cause: cause's cause…`, following
/// [`std::error::Error::source`] (for an `anyhow::Error`, what its `{:#}` prints). Every error of
/// the workspace displays only its own message (where and what failed) and leaves its cause to
/// its source, so each cause appears once. The one way the binary prints an error.
pub(crate) fn error_chain(e: &(dyn std::error::Error + 'static)) -> String {
    let mut shown = e.to_string();
    let mut next = e.source();
    while let Some(cause) = next {
        shown.push_str(": ");
        shown.push_str(&cause.to_string());
        next = cause.source();
    }
    shown
}

fn main() -> ExitCode {
    // Subcommands are dispatched by hand so that the tracker's flags stay at the top level
    // (`nav-app --input …`), as the paper's tool and every earlier release had them.
    match std::env::args_os().nth(1) {
        Some(a) if a == "ins" => ins::main(std::env::args_os().skip(1)),
        Some(a) if a == "monte-carlo" => monte_carlo::main(std::env::args_os().skip(1)),
        Some(a) if a == "eval-lanes" => bench::eval_main(std::env::args_os().skip(1)),
        Some(a) if a == "import-lanes" => bench::import_main(std::env::args_os().skip(1)),
        _ => lane::main(),
    }
}

#[cfg(test)]
mod tests {
    use std::error::Error;
    use std::fmt;

    /// An error with a message and maybe a cause.
    #[derive(Debug)]
    struct Layer(&'static str, Option<Box<Layer>>);

    impl fmt::Display for Layer {
        fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
            f.write_str(self.0)
        }
    }

    impl Error for Layer {
        fn source(&self) -> Option<&(dyn Error + 'static)> {
            self.1.as_deref().map(|l| l as &(dyn Error + 'static))
        }
    }

    #[test]
    fn the_chain_is_every_message_in_order_joined_by_colons_and_nothing_left_out() {
        let leaf = Layer("No such file or directory (os error 2)", None);
        assert_eq!(
            super::error_chain(&leaf),
            "No such file or directory (os error 2)"
        );
        // Nothing is left out, not even a message that repeats an earlier one's text: each
        // error shows only its own message, so a repeat is information, not a duplicate.
        let chain = Layer(
            "imu.csv",
            Some(Box::new(Layer(
                "imu",
                Some(Box::new(Layer("imu.csv", None))),
            ))),
        );
        assert_eq!(super::error_chain(&chain), "imu.csv: imu: imu.csv");
        // Through anyhow's context, as the binary's errors are.
        let e = anyhow::Error::new(Layer("cause", None)).context("what failed");
        assert_eq!(super::error_chain(e.as_ref()), "what failed: cause");
        assert_eq!(super::error_chain(e.as_ref()), format!("{e:#}"));
    }
}
