//! `grab`: stream grey frames from a V4L2 capture device and print one JSON object per line.
//!
//! A hardware smoke test without the tracker (`cargo xtask vivid` now runs `nav-app --device`,
//! which takes the same capture flags); build it statically to try it on a bare system:
//!
//! ```text
//! grab --device /dev/video0 --input-name S-Video --std ntsc --size 320x240 --max-frames 60 --json
//!      [--format YUYV] [--timeout-ms 2000] [--max-timeouts 3]
//!      [--ctrl NAME=VALUE@FRAME]... [--ctrl-on-timeout NAME=VALUE]... [--list]
//! ```
//!
//! Lines: `{"type":"open",…}`, `{"type":"frame",…}` per delivered frame, `{"type":"ctrl",…}` per
//! control set, `{"type":"timeout",…}`, and last `{"type":"summary",…,"exit":…}` where `exit` is
//! `max-frames` (exit code 0), `device-gone` (3), `timeout` (4) or `error` (2).
//! `--ctrl` sets a control (e.g. vivid's `Disconnect`, `Inject V4L2_BUF_FLAG_ERROR`,
//! `Percentage of Dropped Buffers`, `Standard Signal Mode`) once `FRAME` frames have been
//! delivered; `--ctrl-on-timeout` sets one at the first timeout (to end an injected outage).

use std::fmt::Write as _;
use std::process::ExitCode;
use std::time::Instant;

use bt848_capture::{Capture, CaptureConfig, CaptureError, InputSelect, PixelFormat, VideoStd};

struct CtrlAt {
    name: String,
    value: i32,
    at_frame: u64,
}

struct Args {
    device: String,
    config: CaptureConfig,
    max_frames: u64,
    max_timeouts: u32,
    ctrls: Vec<CtrlAt>,
    ctrls_on_timeout: Vec<(String, i32)>,
    list: bool,
}

fn parse_ctrl(spec: &str) -> Result<(String, i32, Option<u64>), String> {
    let (name, rest) = spec
        .rsplit_once('=')
        .ok_or(format!("--ctrl {spec:?}: no '='"))?;
    let (value, at) = match rest.split_once('@') {
        Some((v, at)) => (
            v,
            Some(
                at.parse::<u64>()
                    .map_err(|e| format!("--ctrl {spec:?}: {e}"))?,
            ),
        ),
        None => (rest, None),
    };
    let value = value
        .parse::<i32>()
        .map_err(|e| format!("--ctrl {spec:?}: {e}"))?;
    Ok((name.to_owned(), value, at))
}

fn parse_args() -> Result<Args, String> {
    let mut args = Args {
        device: "/dev/video0".into(),
        config: CaptureConfig {
            timeout_ms: 2000,
            ..CaptureConfig::default()
        },
        max_frames: 60,
        max_timeouts: 3,
        ctrls: Vec::new(),
        ctrls_on_timeout: Vec::new(),
        list: false,
    };
    let mut it = std::env::args().skip(1);
    while let Some(flag) = it.next() {
        let mut value = || it.next().ok_or(format!("{flag} needs a value"));
        match flag.as_str() {
            "--device" => args.device = value()?,
            "--input-name" => args.config.input = InputSelect::Name(value()?),
            "--input-index" => {
                args.config.input =
                    InputSelect::Index(value()?.parse().map_err(|e| format!("{e}"))?);
            }
            "--std" => args.config.std = value()?.parse::<VideoStd>().map_err(|e| e.to_string())?,
            "--size" => {
                let (w, h) = bt848_capture::parse_size(&value()?).map_err(|e| e.to_string())?;
                args.config.width_px = w;
                args.config.height_px = h;
            }
            "--format" => {
                let v = value()?;
                let bytes: [u8; 4] = v
                    .as_bytes()
                    .try_into()
                    .map_err(|_| format!("bad fourcc {v:?}"))?;
                let f =
                    PixelFormat::from_fourcc(bytes).ok_or(format!("unsupported fourcc {v:?}"))?;
                args.config.pixel_formats = vec![f];
            }
            "--buffers" => args.config.buffers = value()?.parse().map_err(|e| format!("{e}"))?,
            "--timeout-ms" => {
                args.config.timeout_ms = value()?.parse().map_err(|e| format!("{e}"))?
            }
            "--max-frames" => args.max_frames = value()?.parse().map_err(|e| format!("{e}"))?,
            "--max-timeouts" => args.max_timeouts = value()?.parse().map_err(|e| format!("{e}"))?,
            "--ctrl" => {
                let (name, value, at) = parse_ctrl(&value()?)?;
                args.ctrls.push(CtrlAt {
                    name,
                    value,
                    at_frame: at.unwrap_or(0),
                });
            }
            "--ctrl-on-timeout" => {
                let (name, value, _) = parse_ctrl(&value()?)?;
                args.ctrls_on_timeout.push((name, value));
            }
            "--json" => {}
            "--list" => args.list = true,
            other => return Err(format!("unknown argument {other:?}")),
        }
    }
    Ok(args)
}

/// JSON string literal.
fn js(s: &str) -> String {
    let mut out = String::with_capacity(s.len() + 2);
    out.push('"');
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            c if (c as u32) < 0x20 => {
                let _ = write!(out, "\\u{:04x}", c as u32);
            }
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

/// `e` and its causes, `e: cause: …` (a capture error shows only its own message and keeps the
/// OS error as its source).
fn shown(e: &CaptureError) -> String {
    std::iter::successors(Some(e as &dyn std::error::Error), |c| c.source())
        .map(ToString::to_string)
        .collect::<Vec<_>>()
        .join(": ")
}

fn set_ctrl(cap: &mut Capture, name: &str, value: i32, at_frame: u64) {
    let result = cap.set_control(name, value);
    let err = match &result {
        Ok(()) => "null".to_owned(),
        Err(e) => js(&shown(e)),
    };
    println!(
        "{{\"type\":\"ctrl\",\"name\":{},\"value\":{value},\"at_frame\":{at_frame},\"ok\":{},\"error\":{err}}}",
        js(name),
        result.is_ok()
    );
}

fn main() -> ExitCode {
    let args = match parse_args() {
        Ok(a) => a,
        Err(e) => {
            eprintln!("grab: {e}");
            println!(
                "{{\"type\":\"summary\",\"exit\":\"error\",\"error\":{}}}",
                js(&e)
            );
            return ExitCode::from(2);
        }
    };
    if args.list {
        match bt848_capture::list_inputs(&args.device) {
            Ok(inputs) => {
                for i in inputs {
                    println!(
                        "{{\"type\":\"input\",\"index\":{},\"name\":{},\"tuner\":{},\"std_mask\":{},\"status\":{}}}",
                        i.index,
                        js(&i.name),
                        i.is_tuner,
                        i.std_mask,
                        i.status
                    );
                }
            }
            Err(e) => println!("{{\"type\":\"error\",\"error\":{}}}", js(&shown(&e))),
        }
    }
    let mut cap = match Capture::open(&args.device, &args.config) {
        Ok(c) => c,
        Err(e) => {
            let exit = if matches!(e, CaptureError::DeviceGone { .. }) {
                "device-gone"
            } else {
                "error"
            };
            println!(
                "{{\"type\":\"summary\",\"frames\":0,\"exit\":\"{exit}\",\"error\":{}}}",
                js(&shown(&e))
            );
            return ExitCode::from(2);
        }
    };
    let std = cap.std_id().map_or("null".to_owned(), |s| s.to_string());
    println!(
        "{{\"type\":\"open\",\"device\":{},\"input_index\":{},\"std_id\":{std},\"width\":{},\"height\":{},\"fourcc\":{},\"stride\":{},\"buffers\":{}}}",
        js(&args.device),
        cap.input_index(),
        cap.width_px(),
        cap.height_px(),
        js(&cap.pixel_format().to_string()),
        cap.stride_bytes(),
        cap.buffer_count()
    );
    let mut grey = vec![0u8; cap.width_px() as usize * cap.height_px() as usize];
    let mut ctrls_done = vec![false; args.ctrls.len()];
    let mut timeout_ctrls_done = false;
    let mut consecutive_timeouts = 0u32;
    let started = Instant::now();
    let (exit, code, error) = loop {
        let delivered = cap.stats().frames;
        for (c, done) in args.ctrls.iter().zip(ctrls_done.iter_mut()) {
            if !*done && delivered >= c.at_frame {
                *done = true;
                set_ctrl(&mut cap, &c.name, c.value, delivered);
            }
        }
        if delivered >= args.max_frames {
            break ("max-frames", 0u8, None);
        }
        match cap.next_frame(&mut grey) {
            Ok(info) => {
                consecutive_timeouts = 0;
                let sum: u64 = grey.iter().map(|&p| u64::from(p)).sum();
                let mean = sum as f64 / grey.len().max(1) as f64;
                println!(
                    "{{\"type\":\"frame\",\"n\":{},\"seq\":{},\"ts_us\":{},\"w\":{},\"h\":{},\"fourcc\":{},\"missed\":{},\"signal_lost\":{},\"mean\":{mean:.2}}}",
                    cap.stats().frames,
                    info.sequence,
                    info.timestamp_us,
                    info.width,
                    info.height,
                    js(&bt848_capture::convert::fourcc_string(
                        info.pixel_format_fourcc
                    )),
                    info.frames_missed_before,
                    info.signal_lost
                );
            }
            Err(CaptureError::Timeout { restarted, .. }) => {
                consecutive_timeouts += 1;
                println!("{{\"type\":\"timeout\",\"restarted\":{restarted}}}");
                if !timeout_ctrls_done {
                    timeout_ctrls_done = true;
                    let delivered = cap.stats().frames;
                    for (name, value) in &args.ctrls_on_timeout {
                        set_ctrl(&mut cap, name, *value, delivered);
                    }
                }
                if consecutive_timeouts >= args.max_timeouts {
                    break ("timeout", 4, None);
                }
            }
            Err(e @ CaptureError::DeviceGone { .. }) => {
                break ("device-gone", 3, Some(shown(&e)));
            }
            Err(e) => break ("error", 2, Some(shown(&e))),
        }
    };
    let s = cap.stats();
    let secs = started.elapsed().as_secs_f64();
    let fps = if secs > 0.0 {
        s.frames as f64 / secs
    } else {
        0.0
    };
    println!(
        "{{\"type\":\"summary\",\"frames\":{},\"errored_dropped\":{},\"sequence_gaps\":{},\"timeouts\":{},\"restarts\":{},\"signal_lost_frames\":{},\"fps\":{fps:.2},\"exit\":\"{exit}\",\"error\":{}}}",
        s.frames,
        s.errored_dropped,
        s.sequence_gaps,
        s.timeouts,
        s.restarts,
        s.signal_lost_frames,
        error.map_or("null".to_owned(), |e| js(&e))
    );
    drop(cap);
    ExitCode::from(code)
}
