//! The verdict: the serial log split into cases, each case's JSON lines checked against what it
//! expects.

use super::*;

pub(super) enum Verdict {
    Pass(String),
    Skip(String),
    Fail(String),
}

impl Verdict {
    pub(super) fn detail(&self) -> &str {
        match self {
            Verdict::Pass(s) | Verdict::Skip(s) | Verdict::Fail(s) => s,
        }
    }
}

/// One case's guest output, from nav-app's JSON lines (frames flattened by [`flatten_frame`];
/// `open` is the summary's `device` object).
#[derive(Default)]
pub(super) struct CaseOutput {
    pub(super) rc: Option<i64>,
    pub(super) open: Option<Value>,
    pub(super) frames: Vec<Value>,
    /// nav-app's stderr warnings about frame timeouts.
    pub(super) timeouts: usize,
    /// nav-app's human-mode device line (`nav-app: device …: N frames in …`).
    pub(super) human: Option<String>,
    pub(super) summary: Option<Value>,
    pub(super) panicked: bool,
}

/// A nav-app `--json` frame object as the flat record the checks read: `seq`, `ts_us`, `w`, `h`,
/// `fourcc`, `missed`, `signal_lost`, `mean` from its `"capture"` object, and `lanes`, the
/// number of lane reports (2 when the tracker ran on the frame).
pub(super) fn flatten_frame(v: &Value) -> Value {
    let c = &v["capture"];
    serde_json::json!({
        "seq": c["sequence"], "ts_us": c["timestamp_us"], "w": c["width_px"], "h": c["height_px"],
        "fourcc": c["format"], "missed": c["missed"], "signal_lost": c["signal_lost"],
        "mean": c["mean_grey"], "lanes": v["lanes"].as_array().map_or(0, Vec::len),
    })
}

pub(super) fn split_cases(log: &SerialLog) -> BTreeMap<String, CaseOutput> {
    let mut out: BTreeMap<String, CaseOutput> = BTreeMap::new();
    let mut current: Option<String> = None;
    for line in &log.lines {
        if let Some(name) = line.strip_prefix("VIVID-CASE-BEGIN ") {
            current = Some(name.trim().to_owned());
            out.entry(name.trim().to_owned()).or_default();
            continue;
        }
        if let Some(rest) = line.strip_prefix("VIVID-CASE-END ") {
            let mut parts = rest.split_whitespace();
            let name = parts.next().unwrap_or_default().to_owned();
            let rc = parts
                .next()
                .and_then(|p| p.strip_prefix("rc="))
                .and_then(|r| r.parse().ok());
            out.entry(name).or_default().rc = rc;
            current = None;
            continue;
        }
        let Some(name) = &current else { continue };
        let o = out.entry(name.clone()).or_default();
        if line.contains("panicked") {
            o.panicked = true;
        }
        if line.contains("nav-app: warning:") && line.contains("no frame within") {
            o.timeouts += 1;
            continue;
        }
        if line.contains("nav-app: device ") {
            o.human = Some(line.clone());
            continue;
        }
        // Kernel messages may share the console: only parse what starts like nav-app's JSON.
        let parse = |key: &str| {
            line.find(key)
                .and_then(|start| serde_json::from_str::<Value>(&line[start..]).ok())
        };
        // Objects start with `"schema"` (JSON schema 1) or, before it, with their first field.
        let Some(v) = parse("{\"schema\"")
            .or_else(|| parse("{\"frame\""))
            .or_else(|| parse("{\"summary\""))
        else {
            continue;
        };
        if let Some(s) = v.get("summary") {
            o.open = s.get("device").filter(|d| !d.is_null()).cloned();
            o.summary = Some(s.clone());
        } else if v.get("frame").is_some() {
            o.frames.push(flatten_frame(&v));
        }
    }
    out
}

pub(super) fn num(v: Option<&Value>, key: &str) -> u64 {
    v.and_then(|v| v.get(key))
        .and_then(Value::as_u64)
        .unwrap_or(0)
}

pub(super) fn text<'a>(v: Option<&'a Value>, key: &str) -> &'a str {
    v.and_then(|v| v.get(key))
        .and_then(Value::as_str)
        .unwrap_or("")
}

/// Frames are 320×240, tracked (two lane reports each), with strictly increasing timestamps and
/// sequence numbers that never go back. A number may repeat: vivid derives it from the time since
/// streaming started, so a capture thread woken twice within one frame period (an emulated
/// machine that stalled) fills two buffers with the same number, one period apart or less; the
/// capture counts no gap there. The same buffer delivered twice would repeat the timestamp too.
pub(super) fn check_frames(o: &CaseOutput, fourcc: Option<&str>) -> Result<(), String> {
    let mut last: Option<(u64, i64)> = None;
    for f in &o.frames {
        let (w, h) = (num(Some(f), "w"), num(Some(f), "h"));
        if (w, h) != (320, 240) {
            return Err(format!("frame {w}x{h}, expected 320x240"));
        }
        if num(Some(f), "lanes") != 2 {
            return Err(format!("frame without the tracker's two lane reports: {f}"));
        }
        if let Some(fc) = fourcc
            && text(Some(f), "fourcc") != fc
        {
            return Err(format!(
                "frame fourcc {}, expected {fc}",
                text(Some(f), "fourcc")
            ));
        }
        let seq = num(Some(f), "seq");
        let ts = f.get("ts_us").and_then(Value::as_i64).unwrap_or(0);
        if let Some((ls, lt)) = last
            && (seq < ls || ts <= lt)
        {
            return Err(format!(
                "sequence going back or timestamp not increasing: ({ls},{lt}) then ({seq},{ts})"
            ));
        }
        last = Some((seq, ts));
    }
    Ok(())
}

/// Mean of the per-frame mean grey levels of a case.
pub(super) fn mean_level(o: &CaseOutput) -> Option<f64> {
    let levels: Vec<f64> = o
        .frames
        .iter()
        .filter_map(|f| f.get("mean").and_then(Value::as_f64))
        .collect();
    (!levels.is_empty()).then(|| levels.iter().sum::<f64>() / levels.len() as f64)
}

/// Largest difference, grey levels, allowed between a format's mean frame level and GREY's.
/// vivid draws the same test pattern in every format; Y'CbCr formats carry studio-range luma
/// (16–235, ≈ +8 here) and RGB ones the pattern's R'G'B' through our BT.601 weights (≈ +2), while
/// reading a wrong byte (a chroma sample, a padding byte) moves the mean by tens of levels.
pub(super) const MEAN_TOLERANCE: f64 = 12.0;

pub(super) fn judge(cases: &[Case], log: &SerialLog) -> Vec<Verdict> {
    let outputs = split_cases(log);
    let grey_mean = outputs.get("stream-grey").and_then(mean_level);
    cases
        .iter()
        .map(|c| match outputs.get(c.name) {
            None => Verdict::Fail("case never started (VM died or timed out?)".into()),
            Some(o) if o.rc.is_none() => Verdict::Fail("case never finished".into()),
            Some(o) if o.panicked => Verdict::Fail("guest panicked".into()),
            Some(o) => judge_one(
                c.expect,
                o,
                grey_mean,
                c.args.matches("--ctrl").count() as u64,
            ),
        })
        .collect()
}

/// `controls`: how many test-hook controls the case sets (`--ctrl` and `--ctrl-on-timeout`).
pub(super) fn judge_one(
    expect: Expect,
    o: &CaseOutput,
    grey_mean: Option<f64>,
    controls: u64,
) -> Verdict {
    let rc = o.rc.unwrap_or(-1);
    let s = o.summary.as_ref();
    let frames = num(s, "frames");
    let exit = text(s, "exit");
    let counters = format!(
        "rc={rc} exit={exit} frames={frames} errored={} gaps={} timeouts={} restarts={} no_signal={} fps={}",
        num(s, "errored_dropped"),
        num(s, "sequence_gaps"),
        num(s, "timeouts"),
        num(s, "restarts"),
        num(s, "signal_lost_frames"),
        s.and_then(|s| s.get("fps"))
            .map_or("?".into(), Value::to_string),
    );
    let fail = |why: String| Verdict::Fail(format!("{why}; {counters}"));
    let ok_run = |want: u64| -> Result<(), String> {
        let restarted = matches!(expect, Expect::TimeoutRestart { .. });
        if rc != 0 || exit != "max-frames" {
            return Err(format!(
                "expected exit max-frames rc=0 ({})",
                text(s, "error")
            ));
        }
        if frames != want || o.frames.len() as u64 != want {
            return Err(format!(
                "expected {want} frames, summary {frames}, lines {}",
                o.frames.len()
            ));
        }
        if num(s, "controls_set") != controls {
            return Err(format!(
                "{} of {controls} test controls set",
                num(s, "controls_set")
            ));
        }
        // After a stream restart the driver numbers frames from 0 again.
        if restarted {
            Ok(())
        } else {
            check_frames(o, None)
        }
    };
    let result: Result<String, String> = match expect {
        Expect::Stream {
            fourcc,
            frames: want,
            optional,
        } => {
            if optional
                && exit == "error"
                && text(s, "error").contains("none of the wanted formats")
            {
                return Verdict::Skip(format!("driver lacks {fourcc}"));
            }
            ok_run(want)
                .and_then(|()| check_frames(o, Some(fourcc)))
                .and_then(|()| {
                    let std = num(o.open.as_ref(), "std_id");
                    if std & 0x1000 == 0 {
                        return Err(format!("std_id {std:#x} lacks NTSC-M"));
                    }
                    if num(o.open.as_ref(), "input_index") != 1 {
                        return Err("S-Video is input 1".into());
                    }
                    let mean = mean_level(o).unwrap_or(-1.0);
                    let level = match grey_mean {
                        Some(g) if (mean - g).abs() > MEAN_TOLERANCE => {
                            return Err(format!(
                                "mean grey {mean:.1} vs GREY's {g:.1}: wrong bytes read?"
                            ));
                        }
                        Some(g) => format!(", mean grey {mean:.1} (GREY {g:.1})"),
                        None => format!(", mean grey {mean:.1}"),
                    };
                    Ok(format!(
                        "{want} frames {fourcc} 320x240, seq in order, NTSC-M{level}"
                    ))
                })
        }
        Expect::Std { mask, frames: want } => ok_run(want).and_then(|()| {
            let std = num(o.open.as_ref(), "std_id");
            if std & mask == 0 || std & 0x1000 != 0 {
                Err(format!("std_id {std:#x} is not within {mask:#x}"))
            } else {
                Ok(format!("std_id {std:#x}"))
            }
        }),
        Expect::Input { index } => ok_run(num(s, "frames")).and_then(|()| {
            let got = num(o.open.as_ref(), "input_index");
            if got == index && frames > 0 {
                Ok(format!("input {got}"))
            } else {
                Err(format!("input {got}"))
            }
        }),
        Expect::CleanError { text: needle } => {
            if rc == EXIT_ERROR && exit == "error" && text(s, "error").contains(needle) {
                Ok(format!("error: {}", text(s, "error")))
            } else {
                Err(format!("expected a clean error containing {needle:?}"))
            }
        }
        Expect::BufError { frames: want } => ok_run(want).and_then(|()| {
            if num(s, "errored_dropped") >= 1 {
                Ok("ERROR-flagged buffers dropped and counted".into())
            } else {
                Err("no errored buffer counted".into())
            }
        }),
        Expect::Dropped { frames: want } => ok_run(want).and_then(|()| {
            let gaps = num(s, "sequence_gaps");
            let missed: u64 = o.frames.iter().map(|f| num(Some(f), "missed")).sum();
            if gaps >= 1 && gaps == missed {
                Ok(format!("{gaps} dropped frames counted from sequence gaps"))
            } else {
                Err(format!("gaps {gaps}, per-frame missed sum {missed}"))
            }
        }),
        Expect::NoSignal { frames: want } => ok_run(want).and_then(|()| {
            let lost = num(s, "signal_lost_frames");
            let last_ok =
                o.frames.last().and_then(|f| f.get("signal_lost")) == Some(&Value::Bool(false));
            if lost >= 1 && last_ok {
                Ok(format!(
                    "{lost} frames flagged signal-lost, signal back at the end"
                ))
            } else {
                Err(format!(
                    "signal_lost_frames {lost}, last frame restored: {last_ok}"
                ))
            }
        }),
        Expect::TimeoutRestart { frames: want } => ok_run(want).and_then(|()| {
            if num(s, "timeouts") >= 1 && num(s, "restarts") >= 1 && o.timeouts >= 1 {
                Ok("timeout reported, stream restarted, frames resumed".into())
            } else {
                Err("no timeout/restart seen".into())
            }
        }),
        Expect::TimeoutLimit { at_least, timeouts } => {
            if rc == EXIT_TIMEOUTS
                && exit == "timeout"
                && frames >= at_least
                && num(s, "timeouts") == timeouts
                && num(s, "restarts") >= timeouts - 1
            {
                Ok(format!(
                    "{timeouts} timeouts in a row after {frames} frames: exit 4 (timeout)"
                ))
            } else {
                Err(format!(
                    "expected exit timeout rc={EXIT_TIMEOUTS} after {timeouts} timeouts"
                ))
            }
        }
        Expect::Human { frames: want } => {
            let line = o.human.as_deref().unwrap_or("");
            let ok = rc == 0
                && line.contains(&format!(" {want} frames in "))
                && line.contains("frames/s")
                && line.contains("errored buffers")
                && line.contains("sequence gaps");
            if ok {
                Ok(format!("stderr: {}", line.trim()))
            } else {
                Err(format!("rc={rc}, stderr device line {line:?}"))
            }
        }
        Expect::Disconnect {
            at_least,
            max_frames,
        } => {
            if rc == EXIT_DEVICE_GONE
                && exit == "device-gone"
                && frames >= at_least
                && frames < max_frames
            {
                Ok(format!(
                    "ENODEV after {frames} frames: clean device-gone exit"
                ))
            } else {
                Err("expected exit device-gone rc=3".into())
            }
        }
    };
    match result {
        Ok(msg) => Verdict::Pass(format!("{msg}; {counters}")),
        Err(why) => fail(why),
    }
}
