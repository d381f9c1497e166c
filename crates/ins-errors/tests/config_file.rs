//! The shared scenario file `configs/paper.toml`: our sections parse, validate and equal the
//! built-in paper defaults; bad input names the field.
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use ins_errors::InsError;
use ins_errors::config::{ImuConfig, TrajectoryConfig, parse_section};

fn paper_toml() -> String {
    std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../configs/paper.toml"
    ))
    .unwrap()
}

#[test]
fn paper_file_sections_match_defaults() {
    let text = paper_toml();
    let t: TrajectoryConfig = parse_section(&text, "trajectory").unwrap();
    t.validate().unwrap();
    let d = TrajectoryConfig::paper();
    assert!((t.start_lat_deg - d.start_lat_deg).abs() < 1e-12);
    assert!((t.start_lon_deg - d.start_lon_deg).abs() < 1e-12);
    assert_eq!(t.segments, d.segments);
    assert_eq!(
        (t.step_s, t.end_time_s, t.start_alt_m),
        (d.step_s, d.end_time_s, d.start_alt_m)
    );
    let i: ImuConfig = parse_section(&text, "imu").unwrap();
    i.validate().unwrap();
    assert_eq!(i, ImuConfig::paper());
}

fn imu_with(line: &str) -> String {
    let text = paper_toml();
    let table: toml::Table = text.parse().unwrap();
    let mut imu = toml::Table::new();
    imu.insert("imu".into(), table["imu"].clone());
    let base = toml::to_string(&imu).unwrap();
    // Replace one key (given as `key = value`).
    let key = line.split('=').next().unwrap().trim();
    base.lines()
        .map(|l| {
            if l.trim_start().starts_with(key) {
                line.to_string()
            } else {
                l.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join("\n")
}

#[test]
fn bad_values_in_file_name_the_field() {
    let cases = [
        (
            "gyro_drift_sigma_degph = nan",
            "imu.gyro_drift_sigma_degph must be finite and ≥ 0, got NaN",
        ),
        (
            "accel_noise_var_per_sample_mg2 = -1.0",
            "imu.accel_noise_var_per_sample_mg2 must be finite and ≥ 0, got -1.0",
        ),
        (
            "gyro_noise_var_per_sample_degph2 = inf",
            "imu.gyro_noise_var_per_sample_degph2 must be finite and ≥ 0, got inf",
        ),
    ];
    for (line, msg) in cases {
        let c: ImuConfig = parse_section(&imu_with(line), "imu").unwrap();
        let e = c.validate().unwrap_err();
        assert_eq!(e.to_string(), msg);
    }
    // Wrong type and unknown key are parse errors naming the key.
    let e =
        parse_section::<ImuConfig>(&imu_with("accel_bias_sigma_mg = \"3\""), "imu").unwrap_err();
    assert!(
        matches!(&e, InsError::Toml { source, .. }
            if source.message.contains("accel_bias_sigma_mg") && source.line.is_some()),
        "{e}"
    );
    let e = parse_section::<ImuConfig>(&imu_with("bias_model = \"sometimes\""), "imu").unwrap_err();
    assert!(
        matches!(&e, InsError::Toml { source, .. } if source.message.contains("bias_model")),
        "{e:?}"
    );
}
