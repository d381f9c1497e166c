//! The `nav-app` binary end to end: JSON schema, overlays, bad input and exit codes.
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn nav_app(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_nav-app"))
        .args(args)
        .output()
        .unwrap()
}

fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("nav-app-cli")
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The project's rendered scene `name` (`lane_scenes`, deterministic) as a YUV4MPEG2 file in
/// the test target directory, written once (atomically, tests run in parallel).
fn rendered(name: &str) -> String {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("rendered");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(format!("{name}.y4m"));
    if !path.exists() {
        let spec = lane_scenes::SCENES
            .iter()
            .find(|s| s.name == name)
            .copied()
            .unwrap();
        let mut bytes = Vec::new();
        lane_scenes::write_scene_y4m(spec, 320, 240, &mut bytes, name).unwrap();
        let tmp = dir.join(format!("{name}.{:?}.tmp", std::thread::current().id()));
        std::fs::write(&tmp, bytes).unwrap();
        std::fs::rename(&tmp, &path).unwrap();
    }
    path.display().to_string()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// The `--json` output split into the frame objects and the closing summary (always last).
fn json_output(o: &Output) -> (Vec<serde_json::Value>, serde_json::Value) {
    let text = String::from_utf8(o.stdout.clone()).unwrap();
    let mut values: Vec<serde_json::Value> = text
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    let summary = values.pop().expect("a summary line");
    assert_eq!(
        summary["schema"], 1,
        "the summary line carries the schema version"
    );
    assert!(
        values.iter().all(|v| v.get("summary").is_none()),
        "only the last line is a summary"
    );
    (values, summary["summary"].clone())
}

#[test]
fn with_no_input_it_runs_on_the_rendered_sample() {
    let o = nav_app(&["--max-frames", "5"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(
        e.contains("rendered scene `curve_left_dashed`") && e.contains("5 frames"),
        "{e}"
    );
    assert!(o.stdout.is_empty(), "human output goes to stderr");
}

#[test]
fn json_is_one_object_per_frame_with_the_documented_schema() {
    let o = nav_app(&["--input", &rendered("straight_solid"), "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(o.stderr.is_empty(), "quiet under --json: {}", stderr(&o));
    let (frames, summary) = json_output(&o);
    assert_eq!(frames.len(), 24);
    assert_eq!(summary["tracked_frames"], 24);
    assert_eq!(summary["lost_frames"], 0);
    assert_eq!(summary["skipped_bytes"], 0);
    assert_eq!(summary["exit"], "end");
    assert_eq!(summary["exit_code"], 0);
    assert!(summary["error"].is_null());
    assert!(
        summary["input"]
            .as_str()
            .unwrap()
            .ends_with("straight_solid.y4m")
    );
    for (i, v) in frames.iter().enumerate() {
        // The documented fields, no more (docs/json.md, lane_io::lane_frame::LaneFrame), schema 1.
        let mut keys: Vec<&str> = v.as_object().unwrap().keys().map(String::as_str).collect();
        keys.sort_unstable();
        assert_eq!(
            keys,
            [
                "exposure", "frame", "lanes", "noise", "road", "schema", "t_s", "track_us"
            ]
        );
        // Rendered frames exposed as the settings assume: measured, above the limit, not
        // brightened.
        let median = v["exposure"]["median_grey"].as_f64().unwrap();
        assert!(median >= 50.0, "median grey {median}");
        assert_eq!(v["exposure"]["gain"], 1.0);
        // Rendered frames with σ = 2 noise: measured, below the default's limit, not smoothed.
        let sigma = v["noise"]["sigma_grey"].as_f64().unwrap();
        assert!(sigma > 0.5 && sigma < 4.0, "σ̂ {sigma}");
        assert_eq!(v["noise"]["denoised"], false);
        let mut road: Vec<&str> = v["road"]
            .as_object()
            .unwrap()
            .keys()
            .map(String::as_str)
            .collect();
        road.sort_unstable();
        assert_eq!(
            road,
            [
                "bottom_row_px",
                "horizon_row_px",
                "refused",
                "search_rows_px"
            ]
        );
        // A rendered road down to the last row, both lanes closing in upwards.
        assert_eq!(v["road"]["bottom_row_px"], 240.0);
        assert!(v["road"]["horizon_row_px"].as_f64().unwrap() < 240.0);
        assert_eq!(v["schema"], 1);
        assert!(v["track_us"].as_f64().unwrap() > 0.0);
        assert_eq!(v["frame"].as_u64(), Some(i as u64));
        assert!((v["t_s"].as_f64().unwrap() - i as f64 / 25.0).abs() < 1e-9);
        let lanes = v["lanes"].as_array().unwrap();
        assert_eq!(lanes.len(), 2);
        for lane in lanes {
            let mut keys: Vec<&str> = lane
                .as_object()
                .unwrap()
                .keys()
                .map(String::as_str)
                .collect();
            keys.sort_unstable();
            assert_eq!(
                keys,
                [
                    "coeffs",
                    "far",
                    "initialised",
                    "points",
                    "rows",
                    "side",
                    "state"
                ]
            );
        }
        assert_eq!(lanes[0]["side"], "left");
        assert_eq!(lanes[1]["side"], "right");
        for lane in lanes {
            assert_eq!(lane["state"], "tracking");
            assert_eq!(lane["coeffs"].as_array().unwrap().len(), 3);
            assert_eq!(lane["rows"].as_array().unwrap().len(), 2);
            assert!(lane["points"].as_u64().unwrap() > 0);
        }
    }
}

#[test]
fn a_still_image_is_one_frame() {
    let dir = scratch("still");
    let png = dir.join("frame.png");
    image::GrayImage::from_pixel(64, 48, image::Luma([90]))
        .save(&png)
        .unwrap();
    let o = nav_app(&["--input", png.to_str().unwrap(), "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let (frames, _) = json_output(&o);
    assert_eq!(frames.len(), 1);
    let v = &frames[0];
    assert_eq!(v["lanes"][0]["state"], "initialising");
    assert!(
        v["lanes"][0]["coeffs"].is_null(),
        "no lane on a blank frame: no coefficients"
    );
}

#[test]
fn overlays_are_written_as_pngs_or_a_colour_y4m() {
    let dir = scratch("overlay");
    let png_dir = dir.join("pngs");
    let o = nav_app(&["--max-frames", "3", "--overlay", png_dir.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let mut files: Vec<_> = std::fs::read_dir(&png_dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    files.sort();
    assert_eq!(files.len(), 3);
    let img = image::open(&files[1]).unwrap().to_rgb8();
    assert_eq!(img.dimensions(), (320, 240));
    // The fitted parabolas are drawn in colour: some pixels are strongly red or blue.
    let coloured = img
        .pixels()
        .filter(|p| p[0] > 200 && p[1] < 80 || p[2] > 200 && p[0] < 100)
        .count();
    assert!(coloured > 50, "{coloured} coloured pixels");

    let y4m = dir.join("ov.y4m");
    let o = nav_app(&["--max-frames", "4", "--overlay", y4m.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let bytes = std::fs::read(&y4m).unwrap();
    assert!(bytes.starts_with(b"YUV4MPEG2 W320 H240"));
    assert_eq!(
        bytes.len(),
        bytes.iter().position(|&b| b == b'\n').unwrap() + 1 + 4 * (6 + 320 * 240 * 3 / 2)
    );
}

#[cfg(not(feature = "capture"))]
#[test]
fn device_exits_non_zero_saying_capture_is_unavailable() {
    let o = nav_app(&["--device", "/dev/video0"]);
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains("not available in this build"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn fatal_bad_input_exits_non_zero_naming_the_file() {
    let dir = scratch("fatal");
    let bad_header = dir.join("bad_header.y4m");
    std::fs::write(&bad_header, b"YUV4MPEG2 W320 Hx Cmono\n").unwrap();
    let chroma = dir.join("chroma.y4m");
    std::fs::write(&chroma, b"YUV4MPEG2 W4 H4 C422\nFRAME\n").unwrap();
    let corrupt = dir.join("corrupt.png");
    std::fs::write(&corrupt, b"\x89PNG\r\n\x1a\nnope").unwrap();
    let mixed = dir.join("mixed");
    std::fs::create_dir_all(&mixed).unwrap();
    std::fs::write(mixed.join("readme.md"), b"x").unwrap();
    for (path, needle) in [
        (&bad_header, "bad_header.y4m"),
        (&chroma, "C422"),
        (&corrupt, "corrupt.png"),
        (&mixed, "readme.md"),
    ] {
        let o = nav_app(&["--input", path.to_str().unwrap()]);
        assert!(!o.status.success(), "{}", path.display());
        assert!(
            stderr(&o).contains(needle),
            "{}: {}",
            path.display(),
            stderr(&o)
        );
    }
    let size_change = dir.join("size.y4m");
    let mut s = b"YUV4MPEG2 W4 H4 Cmono\nFRAME\n".to_vec();
    s.extend_from_slice(&[0; 16]);
    s.extend_from_slice(b"YUV4MPEG2 W8 H4 Cmono\nFRAME\n");
    s.extend_from_slice(&[0; 32]);
    std::fs::write(&size_change, &s).unwrap();
    let o = nav_app(&["--input", size_change.to_str().unwrap()]);
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains("frame 1") && stderr(&o).contains("size changed"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn a_short_last_frame_is_reported_skipped_and_counted_as_lost_exit_5() {
    let dir = scratch("short");
    let mut bytes = std::fs::read(rendered("straight_solid")).unwrap();
    let frame_len = 6 + 320 * 240;
    let header_len = bytes.iter().position(|&b| b == b'\n').unwrap() + 1;
    bytes.truncate(header_len + 3 * frame_len + 1000);
    let path = dir.join("short.y4m");
    std::fs::write(&path, &bytes).unwrap();
    let o = nav_app(&["--input", path.to_str().unwrap(), "--json"]);
    assert_eq!(o.status.code(), Some(5), "{}", stderr(&o));
    let (frames, summary) = json_output(&o);
    assert_eq!(frames.len(), 3);
    assert_eq!(summary["lost_frames"], 1);
    assert_eq!(summary["skipped_bytes"], 1000 - 6);
    assert_eq!(summary["exit_code"], 5);
    let e = stderr(&o);
    assert!(
        e.contains("frame 3") && e.contains("short frame") && e.contains("1 frames lost"),
        "{e}"
    );
}

#[test]
fn a_bad_config_exits_1_naming_the_file_line_column_and_field_once() {
    let dir = scratch("config");
    let text = std::fs::read_to_string(format!(
        "{}/../../configs/outdoor.toml",
        env!("CARGO_MANIFEST_DIR")
    ))
    .unwrap()
    .replace("r_sigma_px = 2.0", "r_sigma_px = -2.0");
    let path = dir.join("bad.toml");
    std::fs::write(&path, &text).unwrap();
    let line = 1 + text[..text.find("r_sigma_px = -2.0").unwrap()]
        .matches('\n')
        .count();
    let o = nav_app(&["--config", path.to_str().unwrap(), "--max-frames", "1"]);
    assert_eq!(o.status.code(), Some(1));
    let e = stderr(&o);
    assert!(e.contains("filter.r_sigma_px"), "{e}");
    let at = format!("{}:{line}:1: ", path.display());
    assert!(e.contains(&at), "{e} lacks {at}");
    assert_eq!(e.matches(path.to_str().unwrap()).count(), 1, "{e}");

    // A misspelt key: located at the key, named once.
    let text = text
        .replace("r_sigma_px = -2.0", "r_sigma_px = 2.0")
        .replace("wrls_lambda", "wrls_lamda");
    let line = 1 + text[..text.find("wrls_lamda").unwrap()]
        .matches('\n')
        .count();
    std::fs::write(&path, &text).unwrap();
    let o = nav_app(&["--config", path.to_str().unwrap(), "--max-frames", "1"]);
    assert_eq!(o.status.code(), Some(1));
    let e = stderr(&o);
    let at = format!("{}:{line}:1: unknown field `wrls_lamda`", path.display());
    assert!(e.contains(&at), "{e} lacks {at}");
}

#[test]
fn loop_repeats_a_file_up_to_max_frames() {
    let o = nav_app(&[
        "--input",
        &rendered("straight_solid"),
        "--loop",
        "--max-frames",
        "60",
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let (frames, summary) = json_output(&o);
    let frames: Vec<u64> = frames
        .iter()
        .map(|v| v["frame"].as_u64().unwrap())
        .collect();
    assert_eq!(frames, (0..60).collect::<Vec<_>>());
    assert_eq!(summary["exit"], "max-frames");
}

#[test]
fn a_y4m_stream_on_stdin_is_read_with_input_dash() {
    use std::io::Write;
    let bytes = std::fs::read(rendered("shadows")).unwrap();
    let mut child = Command::new(env!("CARGO_BIN_EXE_nav-app"))
        .args(["--input", "-", "--json", "--max-frames", "10"])
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let mut stdin = child.stdin.take().unwrap();
    // The tracker may stop reading after 10 frames: a broken pipe here is fine.
    let writer = std::thread::spawn(move || {
        let _ = stdin.write_all(&bytes);
    });
    let o = child.wait_with_output().unwrap();
    writer.join().unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let (frames, summary) = json_output(&o);
    assert_eq!(frames.len(), 10);
    assert_eq!(summary["input"], "stdin");
}

/// `straight_solid.y4m` (24 frames, 320×240 mono) with one flipped byte in the `FRAME` header of
/// each frame in `damaged`.
fn damaged_fixture(damaged: &[usize]) -> Vec<u8> {
    let mut bytes = std::fs::read(rendered("straight_solid")).unwrap();
    let header_len = bytes.iter().position(|&b| b == b'\n').unwrap() + 1;
    let record = 6 + 320 * 240;
    for (k, &i) in damaged.iter().enumerate() {
        let at = header_len + i * record + k % 6;
        assert_eq!(&bytes[header_len + i * record..][..6], b"FRAME\n");
        bytes[at] ^= 0x01;
    }
    bytes
}

fn run_on_stdin(args: &[&str], bytes: Vec<u8>) -> Output {
    use std::io::Write;
    let mut child = Command::new(env!("CARGO_BIN_EXE_nav-app"))
        .args(args)
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let mut stdin = child.stdin.take().unwrap();
    let writer = std::thread::spawn(move || {
        // Small writes: the reader sees the stream as a pipe delivers it.
        for chunk in bytes.chunks(4093) {
            if stdin.write_all(chunk).is_err() {
                break;
            }
        }
    });
    let o = child.wait_with_output().unwrap();
    writer.join().unwrap();
    o
}

#[test]
fn a_damaged_frame_header_loses_one_frame_and_the_stream_plays_to_its_end() {
    let damaged = [5usize, 17];
    let bytes = damaged_fixture(&damaged);
    let dir = scratch("damaged");
    let path = dir.join("damaged.y4m");
    std::fs::write(&path, &bytes).unwrap();
    let from_file = nav_app(&["--input", path.to_str().unwrap(), "--json"]);
    let from_pipe = run_on_stdin(&["--input", "-", "--json"], bytes);
    for (o, input) in [(&from_file, path.to_str().unwrap()), (&from_pipe, "stdin")] {
        assert_eq!(o.status.code(), Some(5), "{input}: {}", stderr(o));
        let (frames, summary) = json_output(o);
        let indices: Vec<u64> = frames
            .iter()
            .map(|v| v["frame"].as_u64().unwrap())
            .collect();
        let want: Vec<u64> = (0..24u64)
            .filter(|i| !damaged.contains(&(*i as usize)))
            .collect();
        assert_eq!(indices, want, "{input}: every good frame after the damage");
        for v in &frames {
            for lane in v["lanes"].as_array().unwrap() {
                assert_eq!(lane["state"], "tracking", "{input}: {v}");
            }
            let i = v["frame"].as_f64().unwrap();
            assert!((v["t_s"].as_f64().unwrap() - i / 25.0).abs() < 1e-9);
        }
        assert_eq!(summary["input"], input);
        assert_eq!(summary["tracked_frames"], 22);
        assert_eq!(summary["lost_frames"], 2);
        assert_eq!(summary["skipped_bytes"], 2 * (6 + 320 * 240));
        assert_eq!(summary["exit"], "end");
        assert_eq!(summary["exit_code"], 5);
        let e = stderr(o);
        assert!(
            e.contains("frame 5: damaged stream") && e.contains("frame 17: damaged stream"),
            "{e}"
        );
    }
    // The human summary says it too.
    let o = nav_app(&["--input", path.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(5));
    let e = stderr(&o);
    assert!(
        e.contains("22 frames tracked, 2 frames lost (153612 bytes skipped)"),
        "{e}"
    );
}

#[test]
fn help_documents_the_exit_codes_and_the_summary() {
    let o = nav_app(&["--help"]);
    assert!(o.status.success());
    let help = String::from_utf8(o.stdout).unwrap();
    for needle in [
        "Exit codes",
        "5  finished, but frames of the input were lost",
        "\"lost_frames\"",
        "\"skipped_bytes\"",
    ] {
        assert!(
            help.contains(needle),
            "{needle} missing from --help:\n{help}"
        );
    }
}

#[test]
fn a_missing_input_names_the_file_and_its_os_error_once() {
    let o = nav_app(&["--input", "/nonexistent/clip.y4m"]);
    assert_eq!(o.status.code(), Some(1));
    let e = stderr(&o);
    assert_eq!(e.matches("/nonexistent/clip.y4m").count(), 1, "{e}");
    assert_eq!(e.matches("No such file or directory").count(), 1, "{e}");
    let o = nav_app(&["--config", "/nonexistent/tracker.toml"]);
    assert_eq!(o.status.code(), Some(1));
    let e = stderr(&o);
    assert_eq!(e.matches("No such file or directory").count(), 1, "{e}");
}

#[test]
fn ins_replays_exported_logs_prints_truth_errors_and_names_bad_lines() {
    use ins_sim::logs::{self, names};
    use ins_sim::{Mode, Scenario};
    let dir = scratch("ins-replay");
    let sc = Scenario::paper_default().truncated(20.0).unwrap();
    let (_, records) = logs::export_run(&sc, Mode::Kf, 7, &dir).unwrap();
    let p = |n: &str| dir.join(n).display().to_string();
    let out = p("solution.csv");
    let args = [
        "ins",
        "--imu",
        &p(names::IMU),
        "--sightings",
        &p(names::SIGHTINGS),
        "--landmarks",
        &p(names::LANDMARKS),
        "--init",
        &p(names::INITIAL),
        "--config",
        &p(names::SCENARIO),
        "--out",
        &out,
        "--truth",
        &p(names::TRUTH),
    ];
    let o = nav_app(&args);
    let e = stderr(&o);
    assert!(o.status.success(), "{e}");
    assert!(
        e.contains("2000 IMU samples to t = 20.000 s")
            && e.contains("20 sighting epochs, 60 sightings used"),
        "{e}"
    );
    // The printed last error is the simulated run's record at 20 s (open loop until 195 s:
    // the solution is the INS corrected by x̂, the record INS − x̂, equal to round-off).
    let r = records[20].pos_err_ned_m;
    let n = (r[0] * r[0] + r[1] * r[1] + r[2] * r[2]).sqrt();
    assert!(e.contains(&format!("last {n:>9.3} m")), "{e} (last {n:.3})");
    // A row at the start and after every IMU sample; the 20 epochs' rows carry their counts.
    let text = std::fs::read_to_string(&out).unwrap();
    assert_eq!(
        text.lines().count(),
        1 + 1 + 2000,
        "header, start, 2000 samples"
    );
    assert_eq!(
        text.lines().skip(1).filter(|l| !l.ends_with(",,,")).count(),
        20
    );
    // From another directory with no --config: the compiled-in mems preset.
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_nav-app"))
        .current_dir("/")
        .args(&args[..9])
        .args(["--out", &p("solution_mems.csv")])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    // A malformed IMU line: exit 1, the message names file:line:column.
    let imu = std::fs::read_to_string(p(names::IMU)).unwrap();
    let bad = dir.join("imu_bad.csv");
    std::fs::write(&bad, imu.replacen("\n1e-1,", "\n1e-1x,", 1)).unwrap();
    let bad_s = bad.display().to_string();
    let mut a = args;
    a[2] = &bad_s;
    let o = nav_app(&a);
    assert_eq!(o.status.code(), Some(1));
    let e = stderr(&o);
    assert!(e.contains(&format!("{bad_s}:11:1:")), "{e}");
    // A bad landmark table (TOML): its file and line, named once, and the key.
    let lm = std::fs::read_to_string(p(names::LANDMARKS)).unwrap();
    let bad = dir.join("landmarks_bad.toml");
    std::fs::write(&bad, lm.replacen("alt_m", "height_m", 1)).unwrap();
    let bad_s = bad.display().to_string();
    let mut a = args;
    a[6] = &bad_s;
    let o = nav_app(&a);
    assert_eq!(o.status.code(), Some(1));
    let e = stderr(&o);
    assert!(
        e.contains(&format!("{bad_s}:")) && e.contains("height_m"),
        "{e}"
    );
    assert_eq!(e.matches(&bad_s).count(), 1, "{e}");
}

/// Each cause of a nested error is printed once: every error shows only its own message (where
/// and what failed) and keeps its cause as its source, and the binary prints the chain
/// `error: cause: cause…` (`error_chain` in main.rs) with no de-duplication. Two chains: a
/// frame of an image directory that does not decode (skipped: the frame, the file, the
/// decoder's message), and an IMU log that is not there (the log, the OS error).
#[test]
fn each_cause_of_a_nested_error_is_printed_once() {
    // The lane half: a warning for a non-fatal frame error, three levels deep.
    let dir = scratch("nested");
    let frames = dir.join("frames");
    std::fs::create_dir_all(&frames).unwrap();
    image::GrayImage::new(320, 240)
        .save(frames.join("0001.png"))
        .unwrap();
    let corrupt = frames.join("0002.png");
    std::fs::write(&corrupt, b"\x89PNG\r\n\x1a\nnope").unwrap();
    let decoder = image::open(&corrupt).unwrap_err().to_string();
    let o = nav_app(&["--input", frames.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(5), "{}", stderr(&o));
    let e = stderr(&o);
    let warning = e
        .lines()
        .find(|l| l.starts_with("nav-app: warning: "))
        .unwrap_or_else(|| panic!("no warning in {e}"));
    let corrupt_s = corrupt.display().to_string();
    assert_eq!(
        warning,
        format!("nav-app: warning: frame 1: skipped: {corrupt_s}: cannot decode image: {decoder}")
    );
    for cause in [corrupt_s.as_str(), "cannot decode image", decoder.as_str()] {
        assert_eq!(e.matches(cause).count(), 1, "`{cause}` not once in {e}");
    }

    // The INS half: a fatal error with the binary's context over the library's error and its
    // OS error.
    use ins_sim::logs::{self, names};
    use ins_sim::{Mode, Scenario};
    let logs_dir = dir.join("logs");
    let sc = Scenario::paper_default().truncated(2.0).unwrap();
    logs::export_run(&sc, Mode::Kf, 7, &logs_dir).unwrap();
    let p = |n: &str| logs_dir.join(n).display().to_string();
    let missing = logs_dir.join("absent_imu.csv").display().to_string();
    let o = nav_app(&[
        "ins",
        "--imu",
        &missing,
        "--filter",
        "none",
        "--init",
        &p(names::INITIAL),
        "--out",
        &p("solution.csv"),
    ]);
    assert_eq!(o.status.code(), Some(1));
    let e = stderr(&o);
    let os = std::fs::read(&missing).unwrap_err().to_string();
    assert!(e.starts_with("nav-app ins: error: "), "{e}");
    for cause in [missing.as_str(), os.as_str()] {
        assert_eq!(e.matches(cause).count(), 1, "`{cause}` not once in {e}");
    }
}

#[test]
fn a_reader_that_closes_the_pipe_ends_the_run_with_an_error_not_a_panic() {
    // `nav-app --json | head -1`: the reader goes after one line.
    let input = rendered("straight_solid");
    let mut child = Command::new(env!("CARGO_BIN_EXE_nav-app"))
        .args(["--input", &input, "--json"])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let mut stdout = child.stdout.take().unwrap();
    let mut first = [0u8; 64];
    std::io::Read::read_exact(&mut stdout, &mut first).unwrap();
    drop(stdout);
    let o = child.wait_with_output().unwrap();
    let err = stderr(&o);
    assert!(!err.contains("panicked"), "{err}");
    assert!(
        o.status.code().is_some(),
        "ended by a signal: {:?}",
        o.status
    );
}
