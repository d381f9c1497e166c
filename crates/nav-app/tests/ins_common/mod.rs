//! Helpers of the `nav-app ins` tests: the binary, scratch directories, and small logs written
//! here (a level IMU at rest, 100 Hz; a 10 Hz reference; sightings from it).
#![allow(dead_code, clippy::unwrap_used, clippy::expect_used, missing_docs)]

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

pub fn nav_app(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_nav-app"))
        .args(args)
        .output()
        .unwrap()
}

pub fn argv(a: &[String]) -> Vec<&str> {
    a.iter().map(String::as_str).collect()
}

pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

pub fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("nav-app-ins-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// 20 s of a level IMU at rest at 40° N, 100 Hz, t = 0.01 … 20 s.
pub fn write_imu(path: &Path) {
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
pub fn write_reference(path: &Path, t0_s: f64, speed_mps: f64) {
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
pub fn write_sightings(dir: &Path) -> (String, String) {
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
