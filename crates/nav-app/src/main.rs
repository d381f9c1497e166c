//! `nav-app`: the lane tracker at the terminal.
//!
//! ```text
//! nav-app [--input PATH | --device PATH] [--config outdoor|indoor|FILE.toml] [--estimator kif|wrls]
//!         [--json] [--overlay DIR|FILE.y4m] [--max-frames N] [--loop]
//! ```
//! With neither `--input` nor `--device` it runs on the bundled 30-frame sample (real highway
//! video, udacity/CarND-LaneLines-P1, MIT). `--input -` reads a YUV4MPEG2 stream on stdin.

use std::io::{BufWriter, Cursor, Write};
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::{Duration, Instant};

use anyhow::{Context, Result, bail};
use clap::{Parser, ValueEnum};
use nav_app::overlay::{OverlaySink, render_overlay};
use nav_app::sources::{open_device, open_input};
use nav_app::y4m::Y4mSource;
use nav_app::{
    Estimator, FrameSource, GreyFrame, LaneReport, LaneState, LaneTracker, TrackerConfig,
};
use serde::Serialize;

/// The bundled sample: first 30 frames of udacity's solidWhiteRight, 320×240 grey.
const SAMPLE_Y4M: &[u8] = include_bytes!("../../../fixtures/udacity/solidWhiteRight-first30.y4m");
const SAMPLE_NAME: &str = "bundled sample (udacity solidWhiteRight, 30 frames, MIT)";

#[derive(Debug, Clone, Copy, ValueEnum)]
enum EstimatorArg {
    /// Kalman information filter (paper eqs. 6–12, 24).
    Kif,
    /// Exponentially weighted recursive least squares (paper eqs. 25–27).
    Wrls,
}

#[derive(Parser, Debug)]
#[command(
    name = "nav-app",
    version,
    about = "Lane-mark tracker (Pimentel & Hemerly): gradient → Hough+LS → KIF"
)]
struct Args {
    /// Image (PNG/JPEG/PGM), directory of images, .y4m file, or `-` for a YUV4MPEG2 stream on stdin.
    #[arg(long, value_name = "PATH", conflicts_with = "device")]
    input: Option<PathBuf>,
    /// Capture device (e.g. /dev/video0).
    #[arg(long, value_name = "PATH")]
    device: Option<PathBuf>,
    /// Preset name (`outdoor`, `indoor`) or a TOML file.
    #[arg(long, value_name = "NAME|FILE", default_value = "outdoor")]
    config: String,
    /// Recursive estimator.
    #[arg(long, value_enum, default_value = "kif")]
    estimator: EstimatorArg,
    /// One JSON object per frame on stdout; nothing else on stderr but errors.
    #[arg(long)]
    json: bool,
    /// Write annotated frames: a directory of PNGs, or a colour .y4m file.
    #[arg(long, value_name = "DIR|FILE.y4m")]
    overlay: Option<PathBuf>,
    /// Stop after this many frames.
    #[arg(long, value_name = "N")]
    max_frames: Option<u64>,
    /// Start the input again at its end (files and directories; with --max-frames for soak tests).
    #[arg(long = "loop")]
    repeat: bool,
    /// Frame rate assumed for a directory of images, frames/s.
    #[arg(long, value_name = "HZ", default_value_t = 25.0)]
    dir_fps: f64,
}

#[derive(Serialize)]
struct FrameJson<'a> {
    frame: u64,
    t_s: f64,
    lanes: &'a [LaneReport; 2],
    /// Wall time of `LaneTracker::track` on this frame, µs.
    track_us: f64,
}

fn open_source(args: &Args) -> Result<Box<dyn FrameSource>> {
    if let Some(dev) = &args.device {
        return Ok(open_device(dev)?);
    }
    match &args.input {
        Some(p) => Ok(open_input(p, args.dir_fps)?),
        None => Ok(Box::new(Y4mSource::new(
            Cursor::new(SAMPLE_Y4M),
            SAMPLE_NAME,
        )?)),
    }
}

fn lane_text(r: &LaneReport) -> String {
    match r.state {
        LaneState::Tracking | LaneState::Coasting => {
            format!("{} ({} pts)", r.state.name(), r.points)
        }
        other => other.name().to_owned(),
    }
}

fn run(args: &Args) -> Result<()> {
    let cfg = TrackerConfig::load(&args.config)?;
    let estimator = match args.estimator {
        EstimatorArg::Kif => Estimator::Kif,
        EstimatorArg::Wrls => Estimator::Wrls,
    };
    if args.dir_fps <= 0.0 || !args.dir_fps.is_finite() {
        bail!(
            "--dir-fps must be a positive number of frames/s, got {}",
            args.dir_fps
        );
    }
    let mut source = open_source(args)?;
    let quiet = args.json;
    if !quiet {
        eprintln!("nav-app: input {}", source.describe());
    }
    let fps_out = source.frame_rate_hz().unwrap_or(25.0);
    let mut overlay = match &args.overlay {
        Some(p) => Some(OverlaySink::open(p, fps_out)?),
        None => None,
    };
    let mut frame = GreyFrame::default();
    let mut rgb = Vec::new();
    let mut tracker: Option<LaneTracker> = None;
    let stdout = std::io::stdout();
    let mut out = BufWriter::new(stdout.lock());
    let (mut frames, mut bad_frames, mut loop_base) = (0u64, 0u64, 0u64);
    let mut last_index = 0u64;
    let mut track_time = Duration::ZERO;
    let started = Instant::now();
    let mut last_states = [LaneState::Initialising; 2];
    while args.max_frames.is_none_or(|m| frames < m) {
        let meta = match source.next_frame(&mut frame) {
            Ok(Some(m)) => m,
            Ok(None) => {
                if args.repeat
                    && frames > 0
                    && args.input.as_ref().is_some_and(|p| p.as_os_str() != "-")
                {
                    loop_base += last_index + 1;
                    source = open_source(args)?;
                    continue;
                }
                break;
            }
            Err(e) if !e.is_fatal() => {
                bad_frames += 1;
                eprintln!("nav-app: warning: {e}");
                continue;
            }
            Err(e) => return Err(e.into()),
        };
        last_index = meta.index;
        let t = match &mut tracker {
            Some(t) if t.frame_size() == (frame.width, frame.height) => t,
            slot => {
                if let Some(old) = slot.as_ref() {
                    bail!(
                        "frame {}: size changed from {:?} to {}×{}",
                        meta.index,
                        old.frame_size(),
                        frame.width,
                        frame.height
                    );
                }
                slot.insert(LaneTracker::new(
                    &cfg,
                    estimator,
                    frame.width,
                    frame.height,
                )?)
            }
        };
        let t0 = Instant::now();
        let report = t.track(&frame)?;
        let dt = t0.elapsed();
        track_time += dt;
        frames += 1;
        let index = loop_base + meta.index;
        if args.json {
            serde_json::to_writer(
                &mut out,
                &FrameJson {
                    frame: index,
                    t_s: meta.t_s,
                    lanes: &report.lanes,
                    track_us: dt.as_secs_f64() * 1e6,
                },
            )
            .context("cannot write JSON to stdout")?;
            out.write_all(b"\n")
                .context("cannot write JSON to stdout")?;
        }
        if let Some(sink) = overlay.as_mut() {
            render_overlay(&frame, t, &mut rgb);
            sink.write(index, &rgb, frame.width, frame.height)?;
        }
        let states = [report.lanes[0].state, report.lanes[1].state];
        if !quiet && (states != last_states || frames % 100 == 1) {
            let fps = frames as f64 / track_time.as_secs_f64().max(1e-9);
            eprintln!(
                "frame {index:6}  t={:7.2}s  left: {:22}  right: {:22}  tracker {fps:8.0} frames/s",
                meta.t_s,
                lane_text(&report.lanes[0]),
                lane_text(&report.lanes[1]),
            );
        }
        last_states = states;
    }
    out.flush().context("cannot write to stdout")?;
    if let Some(sink) = overlay {
        sink.finish()?;
    }
    if !quiet {
        let wall = started.elapsed().as_secs_f64();
        let per_frame_us = 1e6 * track_time.as_secs_f64() / frames.max(1) as f64;
        eprintln!(
            "nav-app: {frames} frames ({bad_frames} bad, skipped) in {wall:.2} s; tracking {per_frame_us:.1} µs/frame \
             ({:.0} frames/s)",
            1e6 / per_frame_us.max(1e-9)
        );
        if let Some(t) = &tracker {
            let c = t.counters();
            eprintln!(
                "nav-app: initialisations left {} right {}; gated jumps {:?}; gated crossings {:?}",
                c.initialisations[0], c.initialisations[1], c.gated_jumps, c.gated_crossings
            );
        }
    } else if bad_frames > 0 {
        eprintln!("nav-app: {bad_frames} bad frames skipped");
    }
    if frames == 0 {
        bail!("no frame could be read");
    }
    Ok(())
}

fn main() -> ExitCode {
    let args = Args::parse();
    match run(&args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("nav-app: error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
