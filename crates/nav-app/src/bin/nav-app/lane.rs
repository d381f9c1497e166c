//! `nav-app [--input …]`: the lane tracker over one frame loop (files, directories, YUV4MPEG2
//! streams, live capture), with the per-frame JSON, overlays and the metric ego lane.

use std::io::{BufWriter, Write};
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::{Duration, Instant};

use anyhow::{Context, Result, bail};
use clap::{Parser, ValueEnum};
use lane_io::birdseye::BirdseyeView;
use lane_io::capture_source::{self, CaptureMonitor, DeviceSetup, DeviceStats};
use lane_scenes::{SCENES, SceneSource};
use std::io::IsTerminal;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use lane_io::frame_loop::{FrameLoop, Step, Tracked};
use lane_io::lane_frame::{LANE_FRAME_SCHEMA, LaneFrame};
use lane_io::overlay::{OverlaySink, render_overlay};
use lane_io::sources::open_input;
use lane_io::{FrameSource, LaneIoError};
use lane_tracker::camera::CameraModel;
use lane_tracker::{Estimator, LaneReport, LaneState, Side};
use serde::Serialize;

use crate::device_args::{DeviceArgs, device_options};
use crate::live::{self, LaneOutput, Live, LiveArgs, Pacer};
use foxglove_live::LiveStats;
use lane_io::mcap_sink::{LaneEncoder, LaneMcapSink, frame_t_ns};

/// The default input: a scene the project renders itself (`lane_scenes`, deterministic), a
/// curved road with dashed marks, 320×240.
const SAMPLE_SCENE: &str = "curve_left_dashed";
const SAMPLE_NAME: &str = "rendered sample (scene curve_left_dashed, 320×240)";

/// Shown at the end of `--help`.
const AFTER_HELP: &str = "\
With neither --input nor --device, nav-app tracks a rendered sample (the project's own synthetic
scene curve_left_dashed, 320×240, deterministic) with configs/default.toml.

Damaged input: an undecodable image of a directory, a YUV4MPEG2 stream damaged where a FRAME
header should be (the reader skips to the next FRAME marker) or a short last frame is reported,
counted and skipped. The last stderr line says how many frames were tracked and lost and how many
bytes were skipped; with --json the last stdout line is a {\"summary\": {...}} object with
\"tracked_frames\", \"lost_frames\", \"skipped_bytes\", \"exit\", \"exit_code\" and \"error\".

Exit codes:
  0  success
  1  error (bad input, configuration, capture setup or streaming error)
  2  bad command line
  3  capture device gone (ENODEV)
  4  --max-timeouts frame timeouts in a row
  5  finished, but frames of the input were lost (lost_frames > 0)

Subcommands (each with its own --help):
  nav-app ins …          replay IMU and sighting logs through the INS/SD filter
  nav-app monte-carlo …  the INS/SD paper's Monte Carlo (also `merge` and `scenarios`)";

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
    about = "Lane-mark tracker (Pimentel & Hemerly): gradient → Hough+LS → KIF",
    after_help = AFTER_HELP
)]
struct Args {
    /// Image (PNG/JPEG/PGM), directory of images, .y4m file, or `-` for a YUV4MPEG2 stream on stdin
    /// [default, with neither --input nor --device: a rendered sample, the project's own scene
    /// curve_left_dashed, 24 frames].
    #[arg(long, value_name = "PATH", conflicts_with = "device")]
    input: Option<PathBuf>,
    /// Capture device (e.g. /dev/video0).
    #[arg(long, value_name = "PATH")]
    device: Option<PathBuf>,
    /// Preset name (`default`, `outdoor`, `indoor`) or a TOML file.
    #[arg(long, value_name = "NAME|FILE", default_value = "default")]
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
    /// Camera model (TOML, or the presets `robot`, `highway`): adds the ego lane in metres
    /// (`ego_lane`) and each lane's coefficient covariance (`lane_cov_px`) to the JSON.
    #[arg(long, value_name = "robot|highway|FILE.toml")]
    camera: Option<String>,
    /// Write bird's-eye (inverse perspective) views of the ground with the lanes, one PNG per
    /// frame, into this directory (needs --camera; with --camera the view is also on
    /// --mcap-out's and --foxglove's /camera/birdseye).
    #[arg(long, value_name = "DIR", requires = "camera")]
    birdseye: Option<PathBuf>,
    /// Stop after this many frames.
    #[arg(long, value_name = "N")]
    max_frames: Option<u64>,
    /// Start the input again at its end (files and directories; with --max-frames for soak tests).
    #[arg(long = "loop")]
    repeat: bool,
    /// Frame rate assumed for a directory of images, frames/s.
    #[arg(long, value_name = "HZ", default_value_t = 25.0)]
    dir_fps: f64,
    /// With a ROS 2 bag (`--input run.mcap`): the image topic (sensor_msgs/msg/Image or
    /// CompressedImage); default: the bag's only image topic.
    #[arg(long, value_name = "TOPIC")]
    topic: Option<String>,
    /// Also write the lanes to this MCAP file for Foxglove: the grey frame
    /// (foxglove.RawImage, /camera/image), the lanes drawn on it (foxglove.ImageAnnotations,
    /// /camera/lanes) and the lane estimate with its covariance (JSON, /lanes).
    #[arg(long, value_name = "FILE")]
    mcap_out: Option<PathBuf>,
    #[command(flatten)]
    live: LiveArgs,
    #[command(flatten)]
    dev: DeviceArgs,
}

/// Version of the per-frame `--json` objects and of the summary line ([`LaneFrame`]'s).
const JSON_SCHEMA: u32 = LANE_FRAME_SCHEMA;

/// The last line of a `--json` run.
#[derive(Serialize)]
struct SummaryJson<'a> {
    /// [`JSON_SCHEMA`].
    schema: u32,
    summary: SummaryBody<'a>,
}

#[derive(Serialize)]
struct SummaryBody<'a> {
    /// The `--input` (file, directory, `stdin` or the rendered sample); absent with `--device`.
    #[serde(skip_serializing_if = "Option::is_none")]
    input: Option<String>,
    /// With `--device`: the device setup (`null` when it could not be opened).
    #[serde(skip_serializing_if = "Option::is_none")]
    device: Option<Option<DeviceSetup>>,
    /// With `--device`: the capture counters.
    #[serde(flatten)]
    stats: Option<DeviceStats>,
    tracked_frames: u64,
    lost_frames: u64,
    skipped_bytes: u64,
    /// With `--foxglove`: the live server's clients and messages sent and dropped.
    #[serde(skip_serializing_if = "Option::is_none")]
    foxglove: Option<LiveStats>,
    exit: &'a str,
    exit_code: u8,
    error: Option<String>,
}

/// What a run did, filled as it goes (also when it fails).
#[derive(Debug, Default)]
struct RunStats {
    /// Frames tracked.
    frames: u64,
    /// Frames of the input lost to damage (not delivered): see `LaneIoError::lost_frames`.
    lost_frames: u64,
    /// Bytes of a stream skipped while resynchronising (and of short last frames).
    skipped_bytes: u64,
    /// Ctrl-C ended the run.
    interrupted: bool,
}

/// Exit code of a run that finished but lost frames of its input to damage.
const EXIT_FRAMES_LOST: u8 = 5;

fn open_source(args: &Args) -> Result<Box<dyn FrameSource>> {
    match &args.input {
        Some(p) if lane_io::mcap_source::is_mcap(p) => Ok(Box::new(
            lane_io::mcap_source::McapImageSource::open(p, args.topic.as_deref())?,
        )),
        Some(p) => {
            if args.topic.is_some() {
                bail!("--topic is for a ROS 2 bag (--input FILE.mcap)");
            }
            Ok(open_input(p, args.dir_fps)?)
        }
        None => {
            let spec = SCENES
                .iter()
                .find(|s| s.name == SAMPLE_SCENE)
                .copied()
                .context("the rendered sample scene is missing from lane_scenes::SCENES")?;
            Ok(Box::new(SceneSource::new(spec, 320, 240)))
        }
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

/// Run the tracker, counting frames in `stats`. With `--device` the capture monitor is left in
/// `monitor` (also when the run fails) for the summary.
/// With `--foxglove` the live server is left in `live` (also when the run fails), for the summary.
fn run(
    args: &Args,
    monitor: &mut Option<CaptureMonitor>,
    live: &mut Option<Live>,
    stats: &mut RunStats,
) -> Result<()> {
    let cfg = lane_io::config::load_tracker_config(&args.config)?;
    if args.live.realtime && args.device.is_some() {
        bail!("--realtime paces a recorded input; a --device delivers frames at its own pace");
    }
    let camera: Option<CameraModel> = match &args.camera {
        Some(c) => Some(lane_io::config::load_camera_config(c)?.model()?),
        None => None,
    };
    // With a camera model, the bird's-eye view: PNGs with --birdseye, a channel of --mcap-out
    // and --foxglove.
    let view = camera.as_ref().map(BirdseyeView::for_camera).transpose()?;
    if let Some(dir) = &args.birdseye {
        std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    }
    if let Some(addr) = &args.live.foxglove {
        *live = Some(Live::start_lanes(addr, view.clone())?);
    }
    let mut live = live.as_mut();
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
    let mut source = match &args.device {
        Some(dev) => {
            let (source, m) = capture_source::open(dev, &device_options(&args.dev)?)?;
            *monitor = Some(m);
            source
        }
        None => open_source(args)?,
    };
    let quiet = args.json;
    let mut signal_lost = false;
    if !quiet {
        eprintln!("nav-app: input {}", source.describe());
    }
    let fps_out = source.frame_rate_hz().unwrap_or(25.0);
    let mut overlay = match &args.overlay {
        Some(p) => Some(OverlaySink::open(p, fps_out)?),
        None => None,
    };
    let mut mcap_out = match &args.mcap_out {
        Some(p) => {
            let mut sink = LaneMcapSink::create(p)?;
            if view.is_some() {
                sink.add_birdseye_channel()?;
            }
            Some(sink)
        }
        None => None,
    };
    if let Some(l) = live.as_deref()
        && !quiet
    {
        eprintln!("nav-app: serving Foxglove on ws://{}", l.addr());
    }
    if let Some(l) = live.as_deref()
        && args.live.wait_client
    {
        if !quiet {
            eprintln!("nav-app: waiting for a client to subscribe (--wait-client)");
        }
        l.wait_client();
    }
    let mut pacer = args.live.realtime.then(Pacer::default);
    let mut encoder = LaneEncoder::default();
    let mut lanes_json = Vec::new();
    let (mut rgb, mut birdseye_rgb) = (Vec::new(), Vec::new());
    let mut lanes = FrameLoop::new(cfg, estimator);
    let stdout = std::io::stdout();
    let mut out = BufWriter::new(stdout.lock());
    let mut loop_base = 0u64;
    let mut last_index = 0u64;
    let mut track_time = Duration::ZERO;
    let started = Instant::now();
    let mut last_states = [LaneState::Initialising; 2];
    let bar = progress_bar(!quiet && args.device.is_none());
    let mut shown_lost = 0u64;
    while args.max_frames.is_none_or(|m| stats.frames < m) {
        if live::interrupted() {
            stats.interrupted = true;
            break;
        }
        let Tracked {
            meta,
            frame,
            tracker: t,
            report,
            track_time: dt,
        } = match lanes.step(&mut source)? {
            Step::Tracked(tracked) => tracked,
            Step::End => {
                if args.repeat
                    && stats.frames > 0
                    && args.input.as_ref().is_some_and(|p| p.as_os_str() != "-")
                {
                    loop_base += last_index + 1;
                    source = open_source(args)?;
                    continue;
                }
                break;
            }
            Step::Skipped(e) => {
                stats.lost_frames += e.lost_frames();
                stats.skipped_bytes += e.skipped_bytes();
                say(
                    &bar,
                    &format!("nav-app: warning: {}", crate::error_chain(&e)),
                );
                continue;
            }
        };
        if stats.frames == 0
            && let Some(cam) = &camera
        {
            cam.check_frame_size(frame.width(), frame.height())?;
        }
        if let Some(p) = pacer.as_mut() {
            p.wait(meta.t_s);
        }
        last_index = meta.index;
        track_time += dt;
        stats.frames += 1;
        let index = loop_base + meta.index;
        let ego = camera.as_ref().map(|c| c.ego_lane(t, &report));
        let capture = monitor.as_ref().and_then(CaptureMonitor::last_frame);
        if let Some(c) = capture
            && c.signal_lost != signal_lost
        {
            signal_lost = c.signal_lost;
            if !quiet {
                let what = if signal_lost { "lost" } else { "back" };
                eprintln!("nav-app: frame {index}: input signal {what}");
            }
        }
        // Rendered here for the PNGs and the file; a live-only run renders it on the encoder's
        // thread.
        if let Some(v) = &view
            && (args.birdseye.is_some() || mcap_out.is_some())
        {
            v.render(frame, &report, ego.flatten(), &mut birdseye_rgb);
        }
        let wants = live.as_deref().map_or([false; 4], Live::lane_wants);
        if args.json || mcap_out.is_some() || wants.contains(&true) {
            let frame_json = LaneFrame {
                schema: JSON_SCHEMA,
                frame: index,
                t_s: meta.t_s,
                lanes: &report.lanes,
                road: report.road,
                exposure: t.frame_exposure(),
                noise: t.frame_noise(),
                track_us: dt.as_secs_f64() * 1e6,
                ego_lane: ego,
                lane_cov_px: (camera.is_some() || mcap_out.is_some() || live.is_some()).then(
                    || {
                        [Side::Left, Side::Right]
                            .map(|s| t.lane_covariance_px(s).map(|p| p.transpose().into()))
                    },
                ),
                capture,
            };
            // Encoded once: the --json line, the MCAP file's and the live /lanes message are
            // the same bytes.
            lanes_json.clear();
            serde_json::to_writer(&mut lanes_json, &frame_json)
                .context("cannot encode the frame as JSON")?;
            if args.json {
                out.write_all(&lanes_json)
                    .and_then(|()| out.write_all(b"\n"))
                    .context("cannot write JSON to stdout")?;
            }
            let t_ns = frame_t_ns(meta.t_s);
            if let Some(sink) = mcap_out.as_mut() {
                encoder.encode_image(t_ns, frame)?;
                encoder.encode_annotations(t_ns, frame.width(), frame.height(), &report)?;
                if let Some(v) = &view {
                    encoder.encode_birdseye(t_ns, v, &birdseye_rgb)?;
                }
                sink.write_encoded(t_ns, &encoder, &lanes_json)?;
            }
            if let Some(l) = live.as_deref_mut() {
                let output = LaneOutput {
                    t_ns,
                    frame,
                    report: &report,
                    ego: ego.flatten(),
                    lanes_json: &lanes_json,
                };
                l.lane_frame(&output, mcap_out.is_some().then_some(&encoder), wants)?;
            }
        }
        if let Some(sink) = overlay.as_mut() {
            render_overlay(frame, t, &mut rgb);
            sink.write(index, &rgb, frame.width(), frame.height())?;
        }
        if let (Some(dir), Some(v)) = (&args.birdseye, &view) {
            let path = dir.join(format!("birdseye_{index:06}.png"));
            v.write_png(&path, &birdseye_rgb)?;
        }
        let states = [report.lanes[0].state, report.lanes[1].state];
        if !quiet && (states != last_states || stats.frames % 100 == 1) {
            let fps = stats.frames as f64 / track_time.as_secs_f64().max(1e-9);
            say(
                &bar,
                &format!(
                    "frame {index:6}  t={:7.2}s  left: {:22}  right: {:22}  tracker {fps:8.0} frames/s",
                    meta.t_s,
                    lane_text(&report.lanes[0]),
                    lane_text(&report.lanes[1]),
                ),
            );
        }
        last_states = states;
        bar.inc(1);
        if stats.lost_frames != shown_lost {
            shown_lost = stats.lost_frames;
            bar.set_message(format!("{shown_lost} lost"));
        }
    }
    bar.finish_and_clear();
    out.flush().context("cannot write to stdout")?;
    if let Some(sink) = overlay {
        sink.finish()?;
    }
    if let Some(sink) = mcap_out {
        sink.finish()?;
    }
    let (frames, lost, skipped) = (stats.frames, stats.lost_frames, stats.skipped_bytes);
    if !quiet {
        let wall = started.elapsed().as_secs_f64();
        let per_frame_us = 1e6 * track_time.as_secs_f64() / frames.max(1) as f64;
        eprintln!(
            "nav-app: {frames} frames tracked, {lost} frames lost ({skipped} bytes skipped) in \
             {wall:.2} s; tracking {per_frame_us:.1} µs/frame ({:.0} frames/s)",
            1e6 / per_frame_us.max(1e-9)
        );
        if let Some(t) = lanes.tracker() {
            let c = t.counters();
            eprintln!(
                "nav-app: initialisations left {} right {}; gated jumps {:?}; gated crossings {:?}; \
                 pairs initialised again {}; re-validations {} (lanes replaced {:?}); weak lanes set \
                 aside {:?}; lane changes {}",
                c.initialisations[0],
                c.initialisations[1],
                c.gated_jumps,
                c.gated_crossings,
                c.gated_pairs,
                c.revalidations,
                c.revalidation_switches,
                c.set_asides,
                c.lane_changes
            );
        }
    } else if lost > 0 {
        eprintln!("nav-app: {lost} frames lost ({skipped} bytes skipped)");
    }
    if frames == 0 && !stats.interrupted {
        bail!("no frame could be read");
    }
    Ok(())
}

/// A progress bar on stderr (frames done, rate, frames lost) when `wanted` (not `--json`, a file
/// or stream rather than a device) and stderr is a terminal; hidden otherwise, so nothing of it
/// ever reaches stdout, a pipe or a log file.
fn progress_bar(wanted: bool) -> ProgressBar {
    if !(wanted && std::io::stderr().is_terminal()) {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr());
    if let Ok(style) =
        ProgressStyle::with_template("{spinner} {pos} frames  {per_sec}  {elapsed_precise}  {msg}")
    {
        bar.set_style(style);
    }
    bar.set_message("0 lost");
    bar
}

/// A status line on stderr, above the progress bar when there is one.
fn say(bar: &ProgressBar, line: &str) {
    if bar.is_hidden() {
        eprintln!("{line}");
    } else {
        bar.println(line);
    }
}

/// The documented exit code and `exit` name of a failed run.
fn failure_kind(e: &anyhow::Error) -> (u8, &'static str) {
    match e.downcast_ref::<LaneIoError>() {
        Some(LaneIoError::DeviceGone { .. }) => (3, "device-gone"),
        Some(LaneIoError::CaptureTimeout { .. }) => (4, "timeout"),
        _ => (1, "error"),
    }
}

/// `nav-app [options]`: track lanes; returns the process exit code.
pub fn main() -> ExitCode {
    let args = Args::parse();
    let mut monitor = None;
    let mut run_stats = RunStats::default();
    let mut live = None;
    live::install_sigint();
    let result = run(&args, &mut monitor, &mut live, &mut run_stats);
    let foxglove = live.map(Live::shutdown);
    let lost = run_stats.lost_frames > 0;
    let ok_code = if lost { EXIT_FRAMES_LOST } else { 0 };
    let (code, exit, error) = match &result {
        Ok(()) if run_stats.interrupted => (ok_code, "interrupted", None),
        Ok(()) if args.max_frames.is_some_and(|m| run_stats.frames >= m) => {
            (ok_code, "max-frames", None)
        }
        Ok(()) => (ok_code, "end", None),
        Err(e) => {
            let (code, exit) = failure_kind(e);
            (code, exit, Some(crate::error_chain(e.as_ref())))
        }
    };
    if let Some(e) = &error {
        eprintln!("nav-app: error: {e}");
    }
    if let Some(f) = foxglove
        && !args.json
    {
        eprintln!(
            "nav-app: Foxglove: {} clients, {} messages sent, {} dropped",
            f.clients, f.sent, f.dropped
        );
    }
    let stats = args.device.as_ref().map(|_| {
        monitor
            .as_ref()
            .map(CaptureMonitor::stats)
            .unwrap_or_default()
    });
    if args.json {
        let input = match (&args.device, &args.input) {
            (Some(_), _) => None,
            (None, Some(p)) if p.as_os_str() == "-" => Some("stdin".to_owned()),
            (None, Some(p)) => Some(p.display().to_string()),
            (None, None) => Some(SAMPLE_NAME.to_owned()),
        };
        let summary = SummaryJson {
            schema: JSON_SCHEMA,
            summary: SummaryBody {
                input,
                device: args
                    .device
                    .as_ref()
                    .map(|_| monitor.as_ref().and_then(CaptureMonitor::setup)),
                stats,
                tracked_frames: run_stats.frames,
                lost_frames: run_stats.lost_frames,
                skipped_bytes: run_stats.skipped_bytes,
                foxglove,
                exit,
                exit_code: code,
                error,
            },
        };
        // Written, not printed: a reader that closed the pipe (`| head -1`) is no panic; the
        // summary then has nowhere to go and is dropped.
        let written = serde_json::to_string(&summary)
            .map_err(std::io::Error::other)
            .and_then(|line| writeln!(std::io::stdout().lock(), "{line}"));
        match written {
            Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => {
                eprintln!("nav-app: error: cannot write the JSON summary: {e}")
            }
            _ => {}
        }
    } else if let (Some(dev), Some(stats), Some(_)) = (&args.device, stats, &monitor) {
        eprintln!(
            "nav-app: device {}: {} frames in {:.2} s ({:.1} frames/s); dropped: {} errored \
             buffers, {} frames (sequence gaps); {} timeouts ({} restarts); {} frames without \
             signal",
            dev.display(),
            stats.capture.frames,
            stats.elapsed_s,
            stats.fps,
            stats.capture.errored_dropped,
            stats.capture.sequence_gaps,
            stats.capture.timeouts,
            stats.capture.restarts,
            stats.capture.signal_lost_frames
        );
    }
    ExitCode::from(code)
}
