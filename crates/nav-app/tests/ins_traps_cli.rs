//! The smaller traps of issue 54 ("Why", point 6): the distance from the default start to the
//! first IMU sample is a lead-in, not an IMU gap; the usage lines name the command as typed
//! (`nav-app ins`, not `ins`). Small logs written here (`ins_common`).
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

mod ins_common;

use ins_common::{nav_app, scratch, stderr, write_imu, write_reference, write_sightings};

/// A reference whose first row (the default start) is 0.03 s before the first IMU sample was
/// reported as "1 IMU gaps bridged (longest 0.030 s)".
#[test]
fn ins_a_default_start_before_the_first_imu_sample_is_a_lead_in_not_a_gap() {
    let dir = scratch("lead-in");
    let p = |n: &str| dir.join(n).display().to_string();
    write_imu(&dir.join("imu.csv")); // t = 0.01 … 20 s
    write_reference(&dir.join("truth.csv"), -0.02, 0.0); // t = −0.02 … 19.98 s
    let o = nav_app(&[
        "ins",
        "--imu",
        &p("imu.csv"),
        "--truth",
        &p("truth.csv"),
        "--filter",
        "none",
        "--out",
        &p("o.csv"),
        "--metrics-json",
        &p("m.json"),
    ]);
    let e = stderr(&o);
    assert!(o.status.success(), "{e}");
    assert!(
        e.contains(
            "from the start at t = -0.020 s (the first 0.030 s after it), 0 IMU gaps bridged (longest 0.000 s)"
        ),
        "{e}"
    );
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("m.json")).unwrap()).unwrap();
    assert_eq!(json["gaps"], 0);
    let lead_in_s = json["lead_in_s"].as_f64().unwrap();
    assert!((lead_in_s - 0.03).abs() < 1e-9, "{lead_in_s}");
}

/// Every usage line names the command as it is typed: clap took the name of the subcommand's
/// own parser (`Usage: ins [OPTIONS]`).
#[test]
fn usage_lines_name_the_whole_command() {
    for (args, usage) in [
        (
            &["ins", "--no-such-option"][..],
            "Usage: nav-app ins [OPTIONS]",
        ),
        (
            &["ins", "sightings", "--no-such-option"][..],
            "Usage: nav-app ins sightings [OPTIONS]",
        ),
        (
            &["monte-carlo", "--no-such-option"][..],
            "Usage: nav-app monte-carlo [OPTIONS]",
        ),
        (
            &["monte-carlo", "merge", "--no-such-option"][..],
            "Usage: nav-app monte-carlo merge",
        ),
    ] {
        let o = nav_app(args);
        let e = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {e}");
        assert!(e.contains(usage), "{args:?}: {e}");
    }
    for (args, usage) in [
        (&["ins", "--help"][..], "Usage: nav-app ins [OPTIONS]"),
        (
            &["ins", "sightings", "--help"][..],
            "Usage: nav-app ins sightings [OPTIONS]",
        ),
        (
            &["monte-carlo", "--help"][..],
            "Usage: nav-app monte-carlo [OPTIONS]",
        ),
    ] {
        let o = nav_app(args);
        let out = String::from_utf8_lossy(&o.stdout);
        assert!(o.status.success(), "{args:?}: {}", stderr(&o));
        assert!(out.contains(usage), "{args:?}: {out}");
    }
}

/// `--plot` draws the errors with the envelopes of the solution file it wrote (the envelopes'
/// data is tested in `ins_plot::replay`): a PNG of the figure size.
#[test]
fn ins_plot_writes_the_error_figure() {
    let dir = scratch("plot");
    let p = |n: &str| dir.join(n).display().to_string();
    write_imu(&dir.join("imu.csv"));
    write_reference(&dir.join("truth.csv"), 0.0, 0.0);
    let (s, lm) = write_sightings(&dir);
    let o = nav_app(&[
        "ins",
        "--imu",
        &p("imu.csv"),
        "--truth",
        &p("truth.csv"),
        "--sightings",
        &s,
        "--landmarks",
        &lm,
        "--rate",
        "10",
        "--out",
        &p("o.csv"),
        "--plot",
        &p("errors.png"),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let png = std::fs::read(dir.join("errors.png")).unwrap();
    assert_eq!(&png[1..4], b"PNG");
    // Width and height, big-endian, in the IHDR chunk.
    let be = |i: usize| u32::from_be_bytes([png[i], png[i + 1], png[i + 2], png[i + 3]]);
    assert_eq!((be(16), be(20)), (1000, 760));
}
