//! `nav-app ins` refuses what cannot be right (issue 54, items 1 and 2): logs on other clocks
//! exit 1 naming each file and its time span, a filter that used no sighting needs
//! `--allow-unaided`, `--filter none --sightings` warns, unused rows are counted in the summary
//! and the metrics JSON, and `--align-s` on a moving vehicle exits 1 with the measured speed and
//! the limit. Small logs written here: a level IMU at rest, 100 Hz, and a 10 Hz reference.
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn nav_app(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_nav-app"))
        .args(args)
        .output()
        .unwrap()
}

fn argv(a: &[String]) -> Vec<&str> {
    a.iter().map(String::as_str).collect()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("nav-app-ins-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// 20 s of a level IMU at rest at 40° N, 100 Hz, t = 0.01 … 20 s.
fn write_imu(path: &Path) {
    let mut text = String::from(
        "t_s,gyro_x_radps,gyro_y_radps,gyro_z_radps,accel_x_mps2,accel_y_mps2,accel_z_mps2\n",
    );
    let w = 7.292_115e-5_f64;
    let lat = 40f64.to_radians();
    for k in 1..=2000 {
        let e = ((k * 7919) % 1000) as f64 / 1000.0 - 0.4995;
        writeln!(
            text,
            "{:.2},{:e},{:e},{:e},{:e},{:e},-9.8015",
            k as f64 * 0.01,
            w * lat.cos() + 1e-4 * e,
            -1e-4 * e,
            -w * lat.sin(),
            2e-3 * e,
            -2e-3 * e
        )
        .unwrap();
    }
    std::fs::write(path, text).unwrap();
}

/// A 10 Hz reference of 20 s from `t0_s`, level, heading north, at `speed_mps` north.
fn write_reference(path: &Path, t0_s: f64, speed_mps: f64) {
    let mut text = String::from("t_s,lat_deg,lon_deg,alt_m,vn_mps,ve_mps,vd_mps,qw,qx,qy,qz\n");
    for k in 0..=200 {
        let dt = k as f64 * 0.1;
        let lat = 40.0 + (speed_mps * dt / 6.36e6).to_degrees();
        writeln!(
            text,
            "{:.3},{lat:.10},-105,1600,{speed_mps},0,0,1,0,0,0",
            t0_s + dt
        )
        .unwrap();
    }
    std::fs::write(path, text).unwrap();
}

/// Landmarks and 1 Hz sightings from the reference in `dir` (`nav-app ins sightings`).
fn write_sightings(dir: &Path) -> (String, String) {
    let p = |n: &str| dir.join(n).display().to_string();
    let o = nav_app(&[
        "ins",
        "sightings",
        "--reference",
        &p("truth.csv"),
        "--landmarks",
        &p("lm.toml"),
        "--make-landmarks",
        "8",
        "--landmark-range-m",
        "30",
        "100",
        "--max-per-epoch",
        "4",
        "--out",
        &p("sightings.csv"),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    (p("sightings.csv"), p("lm.toml"))
}

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
    assert_eq!(
        e.trim_end(),
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
