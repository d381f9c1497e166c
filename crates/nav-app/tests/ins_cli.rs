//! `nav-app ins` refuses what cannot be right (issue 54, items 1 and 2): logs on other clocks
//! exit 1 naming each file and its time span, a filter that used no sighting needs
//! `--allow-unaided`, `--filter none --sightings` warns, unused rows are counted in the summary
//! and the metrics JSON, and `--align-s` on a moving vehicle exits 1 with the measured speed and
//! the limit. Small logs written here: a level IMU at rest, 100 Hz, and a 10 Hz reference.
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

mod ins_common;

use ins_common::{argv, nav_app, scratch, stderr, write_imu, write_reference, write_sightings};

/// The trap: a reference on the device's boot clock gave `0 IMU samples`, `position
/// RMS 0.000 m`, exit 0 and a metrics JSON.
#[test]
fn ins_refuses_a_reference_on_another_clock_exit_1_naming_each_file_and_its_span() {
    let dir = scratch("clock");
    let p = |n: &str| dir.join(n).display().to_string();
    write_imu(&dir.join("imu.csv"));
    write_reference(&dir.join("truth.csv"), 0.0, 0.0);
    let (s, lm) = write_sightings(&dir);
    write_reference(&dir.join("truth.csv"), 46_408.547, 0.0);
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
        "--out",
        &p("o.csv"),
        "--metrics-json",
        &p("m.json"),
    ]);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{e}");
    // The last line: the settings line comes first.
    assert_eq!(
        e.trim_end().lines().last().unwrap_or(""),
        format!(
            "nav-app ins: error: the inputs do not overlap in time: no IMU sample after the start of the replay at t = 46408.547 s; IMU log {}: t = 0.010–20.000 s (2000 rows); reference {}: t = 46408.547–46428.547 s (201 rows); sightings {s}: t = 1.000–20.000 s (80 rows)",
            p("imu.csv"),
            p("truth.csv"),
        )
    );
    assert!(
        !dir.join("m.json").exists(),
        "no metrics JSON for a refused run"
    );
    assert!(
        !dir.join("o.csv").exists(),
        "no partial solution left by a refused run"
    );
}

/// `--filter kf` with sightings on another clock: exit 1 unless `--allow-unaided`; allowed,
/// the summary line and the metrics JSON count the sightings not used.
#[test]
fn ins_kf_that_used_no_sighting_needs_allow_unaided_and_counts_the_rows_not_used() {
    let dir = scratch("unaided");
    let p = |n: &str| dir.join(n).display().to_string();
    write_imu(&dir.join("imu.csv"));
    // Sightings from a reference 5000 s later; the replay's reference on the IMU's clock.
    write_reference(&dir.join("truth.csv"), 5000.0, 0.0);
    let (s, lm) = write_sightings(&dir);
    write_reference(&dir.join("truth.csv"), 0.0, 0.0);
    let mut args = vec![
        "ins".to_string(),
        "--imu".into(),
        p("imu.csv"),
        "--truth".into(),
        p("truth.csv"),
        "--sightings".into(),
        s,
        "--landmarks".into(),
        lm,
        "--out".into(),
        p("o.csv"),
        "--metrics-json".into(),
        p("m.json"),
    ];
    let o = nav_app(&argv(&args));
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{e}");
    assert!(
        e.contains("the filter used no sighting (0 epochs applied, 0 sightings rejected by the gate; 0 sightings at or before the start at t = 0.000 s, 80 after the IMU's last sample at t = 20.000 s)")
            && e.contains("--allow-unaided"),
        "{e}"
    );
    args.push("--allow-unaided".into());
    let o = nav_app(&argv(&args));
    let e = stderr(&o);
    assert!(o.status.success(), "{e}");
    assert!(
        e.contains("rows not used: IMU 0 at or before the start, sightings 0 at or before the start and 80 after the IMU's end, reference 0 before the start and 0 after the IMU's end"),
        "{e}"
    );
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("m.json")).unwrap()).unwrap();
    assert_eq!(json["unused"]["sightings_after_end"], 80);
    assert_eq!(json["sightings_used"], 0);
    assert_eq!(json["inputs"][2]["role"], "sightings");
}

/// `--filter none --sightings …` said nothing about the sightings it ignored.
#[test]
fn ins_filter_none_with_sightings_warns_that_they_are_ignored() {
    let dir = scratch("none");
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
        "--filter",
        "none",
        "--out",
        &p("o.csv"),
    ]);
    let e = stderr(&o);
    assert!(o.status.success(), "{e}");
    assert!(
        e.contains(&format!(
            "nav-app ins: warning: --filter none runs the INS unaided: the sightings ({s}) are ignored"
        )),
        "{e}"
    );
}

/// `--align-s` on a moving vehicle took its turning as gyro bias: now exit 1 with the
/// reference's speed and the filter file's limit; at rest it aligns and says how still it was.
#[test]
fn ins_align_on_a_moving_reference_exits_1_with_the_speed_and_the_limit() {
    let dir = scratch("align");
    let p = |n: &str| dir.join(n).display().to_string();
    write_imu(&dir.join("imu.csv"));
    write_reference(&dir.join("truth.csv"), 0.0, 9.5);
    let args = [
        "ins",
        "--imu",
        &p("imu.csv"),
        "--truth",
        &p("truth.csv"),
        "--filter",
        "none",
        "--align-s",
        "5",
        "--out",
        &p("o.csv"),
    ];
    let o = nav_app(&args);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{e}");
    assert!(
        e.contains(&format!(
            "nav-app ins: error: {}: the vehicle is not at rest over the alignment window t = 0.000–5.000 s: the reference's speed reaches 9.5000 m/s, above the filter file's align.max_speed_mps = 0.3 m/s",
            p("imu.csv")
        )),
        "{e}"
    );
    write_reference(&dir.join("truth.csv"), 0.0, 0.0);
    let o = nav_app(&args);
    let e = stderr(&o);
    assert!(o.status.success(), "{e}");
    assert!(
        e.contains("at rest (spread of the 1-s means: accelerometer"),
        "{e}"
    );
}
