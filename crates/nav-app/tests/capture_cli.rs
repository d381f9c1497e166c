//! `nav-app --device` without a capture device: the flags, errors, exit codes and the JSON summary.
//! (The real-driver behaviour is tested in a VM by `cargo xtask vivid`.)
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use std::process::{Command, Output};

fn nav_app(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_nav-app"))
        .args(args)
        .output()
        .unwrap()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn last_json_line(o: &Output) -> serde_json::Value {
    let text = String::from_utf8(o.stdout.clone()).unwrap();
    let line = text.lines().last().expect("no stdout line");
    serde_json::from_str(line).unwrap()
}

#[cfg(feature = "capture")]
fn scratch_file(name: &str, bytes: &[u8]) -> std::path::PathBuf {
    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("nav-app-capture-cli");
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

#[test]
fn help_lists_the_capture_flags_but_not_the_test_hooks() {
    let o = nav_app(&["--help"]);
    assert!(o.status.success());
    let help = String::from_utf8(o.stdout).unwrap();
    for flag in [
        "--device",
        "--input-name",
        "--input-index",
        "--std",
        "--size",
        "--max-timeouts",
    ] {
        assert!(help.contains(flag), "{flag} missing from --help:\n{help}");
    }
    for hidden in ["--ctrl", "--format", "--timeout-ms"] {
        assert!(!help.contains(hidden), "{hidden} shown in --help:\n{help}");
    }
}

#[test]
fn capture_flags_need_a_device_and_valid_values_usage_exit_2() {
    let o = nav_app(&["--input-name", "S-Video"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("--device"), "{}", stderr(&o));
    let o = nav_app(&["--device", "/nonexistent/video0", "--std", "ntsc-x"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("unknown standard") && stderr(&o).contains("secam"),
        "{}",
        stderr(&o)
    );
    let o = nav_app(&["--device", "/nonexistent/video0", "--size", "320by240"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("WIDTHxHEIGHT"), "{}", stderr(&o));
    let o = nav_app(&[
        "--device",
        "/nonexistent/video0",
        "--input-name",
        "S-Video",
        "--input-index",
        "1",
    ]);
    assert_eq!(
        o.status.code(),
        Some(2),
        "name and index exclude each other"
    );
}

#[test]
fn bad_test_hook_and_option_values_exit_1_naming_them() {
    let o = nav_app(&["--device", "/nonexistent/video0", "--ctrl", "Disconnect"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr(&o).contains("control") && stderr(&o).contains("\"Disconnect\""),
        "{}",
        stderr(&o)
    );
    let o = nav_app(&["--device", "/nonexistent/video0", "--max-timeouts", "0"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr(&o).contains("max_consecutive_timeouts"),
        "{}",
        stderr(&o)
    );
    let o = nav_app(&["--device", "/nonexistent/video0", "--format", "MJPG"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr(&o).contains("--format") && stderr(&o).contains("YUYV"),
        "{}",
        stderr(&o)
    );
}

#[cfg(feature = "capture")]
#[test]
fn a_missing_device_is_a_clear_error_with_exit_1_and_a_json_summary() {
    let o = nav_app(&["--device", "/nonexistent/video0", "--json"]);
    assert_eq!(o.status.code(), Some(1));
    let e = stderr(&o);
    assert!(e.contains("cannot open /nonexistent/video0"), "{e}");
    assert!(!e.contains("panicked"), "{e}");
    let v = last_json_line(&o);
    let s = &v["summary"];
    assert_eq!(s["exit"], "error");
    assert_eq!(s["exit_code"], 1);
    assert_eq!(s["frames"], 0);
    assert!(s["device"].is_null());
    assert!(
        s["error"].as_str().unwrap().contains("/nonexistent/video0"),
        "{s}"
    );
}

#[cfg(feature = "capture")]
#[test]
fn a_file_that_is_not_a_v4l2_device_is_refused_at_querycap() {
    let p = scratch_file("not-a-device", b"plain file");
    let o = nav_app(&["--device", p.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(1));
    let e = stderr(&o);
    assert!(e.contains("VIDIOC_QUERYCAP"), "{e}");
    assert!(e.contains(p.to_str().unwrap()), "{e}");
    // Human mode: no JSON on stdout, and no device summary for a device never opened.
    assert!(o.stdout.is_empty());
    assert!(!e.contains("frames/s"), "{e}");
}

#[cfg(not(feature = "capture"))]
#[test]
fn without_the_capture_feature_device_says_so() {
    let o = nav_app(&["--device", "/dev/video0", "--json"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr(&o).contains("not available in this build")
            && stderr(&o).contains("--features capture"),
        "{}",
        stderr(&o)
    );
    let v = last_json_line(&o);
    assert_eq!(v["summary"]["exit"], "error");
}
