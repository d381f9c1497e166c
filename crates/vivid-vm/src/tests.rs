use super::*;

fn log_of(lines: &[&str]) -> SerialLog {
    SerialLog {
        lines: lines.iter().map(|l| (*l).to_owned()).collect(),
        killed: false,
    }
}

/// A nav-app `--json` frame line (lanes abridged to what the checks read).
fn frame(n: u64, seq: u64, ts: u64) -> String {
    format!(
        r#"{{"schema":1,"frame":{n},"t_s":0.0,"lanes":[{{"side":"left","state":"lost"}},{{"side":"right","state":"lost"}}],"track_us":900.0,"capture":{{"sequence":{seq},"timestamp_us":{ts},"format":"GREY","width_px":320,"height_px":240,"missed":0,"signal_lost":false,"mean_grey":65.0}}}}"#
    )
}

fn stream_log(seqs: &[u64], rc: i32) -> SerialLog {
    let stamped: Vec<(u64, u64)> = seqs.iter().map(|&s| (s, 1000 + s)).collect();
    stream_log_stamped(&stamped, rc)
}

/// A stream case's log with these `(sequence, timestamp_us)` frames.
fn stream_log_stamped(frames: &[(u64, u64)], rc: i32) -> SerialLog {
    let mut lines = vec!["VIVID-CASE-BEGIN s".to_owned()];
    for (i, &(s, ts)) in frames.iter().enumerate() {
        // Kernel noise on the console must not confuse the parser.
        lines.push(format!(
            "[    1.0] some kernel line {}",
            frame(i as u64, s, ts)
        ));
    }
    lines.push(format!(
        r#"{{"schema":1,"summary":{{"device":{{"device":"/dev/video0","input_index":1,"std_id":4096,"width_px":320,"height_px":240,"format":"GREY","stride_bytes":320,"buffers":4}},"frames":{},"errored_dropped":0,"sequence_gaps":0,"controls_set":0,"exit":"max-frames","exit_code":0,"error":null}}}}"#,
        frames.len()
    ));
    lines.push(format!("VIVID-CASE-END s rc={rc}"));
    SerialLog {
        lines,
        killed: false,
    }
}

fn verdict(log: &SerialLog, expect: Expect) -> Verdict {
    let cases = [Case {
        name: "s",
        args: String::new(),
        expect,
    }];
    judge(&cases, log).remove(0)
}

const GREY3: Expect = Expect::Stream {
    fourcc: "GREY",
    frames: 3,
    optional: false,
};

#[test]
fn stream_case_passes_only_with_increasing_sequence_and_exit_zero() {
    assert!(matches!(
        verdict(&stream_log(&[0, 1, 2], 0), GREY3),
        Verdict::Pass(_)
    ));
    assert!(matches!(
        verdict(&stream_log(&[0, 2, 1], 0), GREY3),
        Verdict::Fail(_)
    ));
    assert!(matches!(
        verdict(&stream_log(&[0, 1, 2], 1), GREY3),
        Verdict::Fail(_)
    ));
    // Too few frames.
    assert!(matches!(
        verdict(&stream_log(&[0, 1], 0), GREY3),
        Verdict::Fail(_)
    ));
}

#[test]
fn a_repeated_sequence_number_passes_only_with_a_later_timestamp() {
    // vivid derives a buffer's sequence number from the time since streaming started: a thread
    // woken twice within one frame period (a stalled emulated machine) fills two buffers with the
    // same number, 18 ms apart (seen in CI). Two distinct frames, in order: not a fault of ours.
    let repeated = [(0, 4_642_968), (0, 4_661_025), (1, 4_678_687)];
    assert!(matches!(
        verdict(&stream_log_stamped(&repeated, 0), GREY3),
        Verdict::Pass(_)
    ));
    // The same buffer delivered twice (same number, same timestamp), a timestamp going back, or
    // a number going back still fail.
    for bad in [
        [(0, 1000), (0, 1000), (1, 1033)],
        [(0, 1000), (1, 990), (2, 1066)],
        [(1, 1000), (0, 1033), (2, 1066)],
    ] {
        assert!(
            matches!(
                verdict(&stream_log_stamped(&bad, 0), GREY3),
                Verdict::Fail(_)
            ),
            "{bad:?}"
        );
    }
}

#[test]
fn frames_must_be_tracked_and_test_controls_all_set() {
    // A frame object without the tracker's two lane reports fails the case.
    let mut log = stream_log(&[0, 1, 2], 0);
    log.lines[2] = log.lines[2].replace(r#"{"side":"left","state":"lost"},"#, "");
    assert!(matches!(verdict(&log, GREY3), Verdict::Fail(_)));
    // A case that sets one control passes only if the summary counts it.
    let cases = [Case {
        name: "s",
        args: "--ctrl 'Disconnect=1@1'".into(),
        expect: GREY3,
    }];
    let log = stream_log(&[0, 1, 2], 0);
    assert!(matches!(judge(&cases, &log)[0], Verdict::Fail(_)));
    let mut log = stream_log(&[0, 1, 2], 0);
    let n = log.lines.len();
    log.lines[n - 2] = log.lines[n - 2].replace(r#""controls_set":0"#, r#""controls_set":1"#);
    assert!(matches!(judge(&cases, &log)[0], Verdict::Pass(_)));
}

#[test]
fn unfinished_or_missing_case_fails() {
    let mut log = stream_log(&[0, 1, 2], 0);
    log.lines.pop(); // no END marker: the guest hung or the VM died
    assert!(matches!(verdict(&log, GREY3), Verdict::Fail(_)));
    assert!(matches!(
        verdict(&log_of(&["VIVID-READY"]), GREY3),
        Verdict::Fail(_)
    ));
}

#[test]
fn disconnect_requires_device_gone_exit() {
    let expect = Expect::Disconnect {
        at_least: 1,
        max_frames: 60,
    };
    let gone = log_of(&[
        "VIVID-CASE-BEGIN s",
        r#"{"summary":{"device":null,"frames":10,"controls_set":0,"exit":"device-gone","exit_code":3,"error":"gone"}}"#,
        "VIVID-CASE-END s rc=3",
    ]);
    assert!(matches!(verdict(&gone, expect), Verdict::Pass(_)));
    let panicked = log_of(&[
        "VIVID-CASE-BEGIN s",
        "thread 'main' panicked at src/x.rs:1:1",
        r#"{"summary":{"device":null,"frames":10,"controls_set":0,"exit":"device-gone","exit_code":3,"error":"gone"}}"#,
        "VIVID-CASE-END s rc=3",
    ]);
    assert!(matches!(verdict(&panicked, expect), Verdict::Fail(_)));
}

#[test]
fn timeout_limit_requires_exit_4_after_the_given_timeouts() {
    let expect = Expect::TimeoutLimit {
        at_least: 5,
        timeouts: 2,
    };
    fn log(rc: i32, timeouts: u32) -> SerialLog {
        let summary = format!(
            r#"{{"summary":{{"frames":5,"timeouts":{timeouts},"restarts":{timeouts},"exit":"timeout","exit_code":{rc}}}}}"#
        );
        let end = format!("VIVID-CASE-END s rc={rc}");
        log_of(&["VIVID-CASE-BEGIN s", &summary, &end])
    }
    assert!(matches!(verdict(&log(4, 2), expect), Verdict::Pass(_)));
    assert!(matches!(verdict(&log(1, 2), expect), Verdict::Fail(_)));
    assert!(matches!(verdict(&log(4, 1), expect), Verdict::Fail(_)));
}

#[test]
fn cpio_newc_entries_are_aligned_and_terminated() {
    let mut c = Cpio::new();
    c.file("init", b"abc", true);
    let buf = c.finish();
    assert_eq!(&buf[..6], b"070701");
    // Header 110 bytes + "init\0" (5) = 115 → padded to 116, then 3 data bytes → 120.
    let mode = u32::from_str_radix(std::str::from_utf8(&buf[14..22]).unwrap(), 16).unwrap();
    assert_eq!(mode, 0o100_755);
    assert_eq!(&buf[110..115], b"init\0");
    assert_eq!(&buf[116..119], b"abc");
    assert_eq!(&buf[120..126], b"070701");
    assert!(buf.windows(11).any(|w| w == b"TRAILER!!!\0"));
    assert_eq!(buf.len() % 4, 0);
}

#[test]
fn init_script_runs_every_case_between_markers() {
    let script = init_script(&cases());
    for c in cases() {
        assert!(script.contains(&format!("echo 'VIVID-CASE-BEGIN {}'", c.name)));
        assert!(script.contains(&format!("VIVID-CASE-END {} rc=$?", c.name)));
    }
    assert!(script.contains(VIVID_PARAMS));
    // Disconnect must be the last case: vivid stays gone while any handle is open.
    assert_eq!(cases().last().map(|c| c.name), Some("fault-disconnect"));
}
