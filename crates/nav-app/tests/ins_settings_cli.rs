//! `nav-app ins` shows the settings in force (issue 54, item 3): `--print-config` prints them as
//! a filter file that, given back as `--config`, reproduces the run byte for byte; the replay's
//! first line names the preset, the sighting σ, the gate and the feedback start; a log that
//! ends before feedback starts is warned about. Small logs written here (`ins_common`).
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

mod ins_common;

use ins_common::{nav_app, scratch, stderr, write_imu, write_reference, write_sightings};

/// A replay of the test's logs in `dir` with `extra` options, solution to `out`.
fn replay(dir: &std::path::Path, out: &str, extra: &[&str]) -> std::process::Output {
    let p = |n: &str| dir.join(n).display().to_string();
    let mut args: Vec<String> = [
        "ins",
        "--imu",
        &p("imu.csv"),
        "--truth",
        &p("truth.csv"),
        "--sightings",
        &p("sightings.csv"),
        "--landmarks",
        &p("lm.toml"),
        "--out",
        &p(out),
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    args.extend(extra.iter().map(|s| s.to_string()));
    let o = nav_app(&args.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(o.status.success(), "{}", stderr(&o));
    o
}

#[test]
fn ins_print_config_given_back_as_config_reproduces_the_solution_byte_for_byte() {
    let dir = scratch("print-config");
    let p = |n: &str| dir.join(n).display().to_string();
    write_imu(&dir.join("imu.csv"));
    write_reference(&dir.join("truth.csv"), 0.0, 0.0);
    write_sightings(&dir);
    std::fs::write(
        dir.join("user.toml"),
        "preset = \"mems\"\n[imu]\ngyro_arw_deg_per_rt_h = 7.123456789012345\n\
         [sighting]\nsigma_m = 2.5\n[filter]\nfeedback_from_s = 3.0\n",
    )
    .unwrap();
    let flags = ["--config", &p("user.toml"), "--gate", "0.99"];
    let o = replay(&dir, "a.csv", &flags);
    let e = stderr(&o);
    assert!(
        e.contains(&format!(
            "nav-app ins: settings: {} over preset mems; --filter kf; sighting σ 2.500 m; gate 0.99; feedback from t = 3.000 s (3.000 s after the start)",
            p("user.toml")
        )),
        "{e}"
    );
    let printed = nav_app(&[
        "ins",
        "--print-config",
        flags[0],
        flags[1],
        flags[2],
        flags[3],
    ]);
    assert!(printed.status.success(), "{}", stderr(&printed));
    let text = String::from_utf8(printed.stdout).unwrap();
    for line in [
        "preset = \"mems\"",
        "gyro_arw_deg_per_rt_h = 7.123456789012345",
        "sigma_m = 2.5",
        "gate_probability = 0.99",
        "feedback_from_s = 3.0",
        "# σ of w and h, m at the landmark",
        "# gyro angle random walk, °/√h",
    ] {
        assert!(text.contains(line), "`{line}` in\n{text}");
    }
    std::fs::write(dir.join("printed.toml"), &text).unwrap();
    replay(&dir, "b.csv", &["--config", &p("printed.toml")]);
    let (a, b) = (
        std::fs::read(dir.join("a.csv")).unwrap(),
        std::fs::read(dir.join("b.csv")).unwrap(),
    );
    assert!(a == b, "the printed settings replay to another solution");
    // The settings matter on this log: without the overrides the solution differs.
    replay(&dir, "c.csv", &[]);
    assert!(std::fs::read(dir.join("c.csv")).unwrap() != a);
}

#[test]
fn ins_warns_when_the_log_ends_before_feedback_starts() {
    let dir = scratch("feedback");
    write_imu(&dir.join("imu.csv"));
    write_reference(&dir.join("truth.csv"), 0.0, 0.0);
    write_sightings(&dir);
    let e = stderr(&replay(&dir, "o.csv", &["--preset", "paper"]));
    assert!(
        e.contains("nav-app ins: settings: preset paper; --filter kf; sighting σ 6.325 m; gate none; feedback from t = 195.000 s (195.000 s after the start)"),
        "{e}"
    );
    assert!(
        e.contains("nav-app ins: warning: the IMU log ends at t = 20.000 s, before feedback starts at t = 195.000 s"),
        "{e}"
    );
    let e = stderr(&replay(&dir, "o.csv", &["--preset", "mems"]));
    assert!(!e.contains("warning"), "{e}");
    // --help names the paper preset's feedback start and σ.
    let help = nav_app(&["ins", "--help"]);
    let help = String::from_utf8_lossy(&help.stdout);
    assert!(
        help.contains("feedback from 195 s") && help.contains("6.32 m"),
        "{help}"
    );
}

/// `--print-config` prints filter files only: a simulation scenario (the older way) is an error
/// naming it; a gate outside (0, 1) is refused.
#[test]
fn ins_print_config_refuses_a_scenario_and_a_bad_gate() {
    let scenario = concat!(env!("CARGO_MANIFEST_DIR"), "/../../configs/paper.toml");
    let o = nav_app(&["ins", "--print-config", "--config", scenario]);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{e}");
    assert!(
        e.contains("is a simulation scenario (the older way), not a filter file"),
        "{e}"
    );
    let o = nav_app(&["ins", "--print-config", "--gate", "1.5"]);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{e}");
    assert!(
        e.contains("gate: must be within (0, 1), or 0 for no gate"),
        "{e}"
    );
}
