//! Property tests of `parse_section` (the `[trajectory]` and `[imu]` sections): valid sections
//! round-trip serialise → parse → equal; any text, and sections with NaN/inf/huge or mistyped
//! values, give a value or the typed `InsError::Toml` naming the section — never a panic — and
//! `validate` refuses non-finite numbers naming the field.
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use ins_errors::InsError;
use ins_errors::config::{BiasModel, ImuConfig, SegmentConfig, TrajectoryConfig, parse_section};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngSeed};

fn config(cases: u32) -> Config {
    Config {
        cases,
        rng_seed: RngSeed::Fixed(0x696e_7300),
        failure_persistence: None,
        ..Config::default()
    }
}

fn section_text<T: serde::Serialize>(name: &str, value: &T) -> String {
    let mut table = toml::Table::new();
    table.insert(name.into(), toml::Value::try_from(value).unwrap());
    toml::to_string(&table).unwrap()
}

fn finite() -> impl Strategy<Value = f64> {
    prop_oneof![
        -1e6f64..1e6,
        Just(0.0),
        Just(f64::MIN_POSITIVE),
        Just(1e300)
    ]
}

fn any_f64() -> impl Strategy<Value = f64> {
    prop_oneof![
        4 => finite(),
        1 => Just(f64::NAN),
        1 => Just(f64::INFINITY),
        1 => Just(f64::NEG_INFINITY),
    ]
}

proptest! {
    #![proptest_config(config(256))]

    /// Any IMU section (finite or not) survives the TOML round trip; `validate` accepts it
    /// exactly when every field is finite and ≥ 0.
    #[test]
    fn imu_sections_round_trip_and_validate_by_the_rules(
        v in prop::array::uniform4(any_f64()),
        fixed in any::<bool>(),
    ) {
        let imu = ImuConfig {
            accel_bias_sigma_mg: v[0],
            gyro_drift_sigma_degph: v[1],
            accel_noise_var_per_sample_mg2: v[2],
            gyro_noise_var_per_sample_degph2: v[3],
            bias_model: if fixed { BiasModel::FixedMagnitudeRandomSign } else { BiasModel::GaussianRandomConstant },
        };
        let back: ImuConfig = parse_section(&section_text("imu", &imu), "imu").unwrap();
        // NaN ≠ NaN: compare bit patterns.
        let bits = |c: &ImuConfig| [c.accel_bias_sigma_mg, c.gyro_drift_sigma_degph, c.accel_noise_var_per_sample_mg2, c.gyro_noise_var_per_sample_degph2].map(f64::to_bits);
        prop_assert_eq!(bits(&back), bits(&imu));
        prop_assert_eq!(back.bias_model, imu.bias_model);
        let valid = v.iter().all(|x| x.is_finite() && *x >= 0.0);
        match imu.validate() {
            Ok(()) => prop_assert!(valid),
            Err(InsError::InvalidConfig { field, .. }) => {
                prop_assert!(!valid);
                prop_assert!(field.starts_with("imu."), "{}", field);
            }
            Err(other) => prop_assert!(false, "unexpected {other}"),
        }
    }

    /// Trajectories with random segments round-trip exactly.
    #[test]
    fn trajectory_sections_round_trip(
        start in prop::array::uniform6(finite()),
        segs in prop::collection::vec(prop::array::uniform4(finite()), 0..20),
    ) {
        let mut t = TrajectoryConfig::paper();
        t.start_lat_deg = start[0];
        t.start_lon_deg = start[1];
        t.start_alt_m = start[2];
        t.start_speed_mps = start[3];
        t.start_heading_deg = start[4];
        t.step_s = start[5];
        t.segments = segs
            .iter()
            .map(|s| SegmentConfig {
                duration_s: s[0],
                along_accel_mps2: s[1],
                turn_rate_degps: s[2],
                path_angle_rate_degps: s[3],
            })
            .collect();
        let back: TrajectoryConfig = parse_section(&section_text("trajectory", &t), "trajectory").unwrap();
        prop_assert_eq!(back, t);
    }

    /// Any text: a section or the typed error naming it, never a panic.
    #[test]
    fn any_text_parses_or_names_the_section(
        text in prop_oneof![
            "\\PC{0,200}",
            "\\[imu\\]\n([a-z_]{1,30} = [-+0-9a-z.e\"\\[\\], ]{0,16}\n){0,6}",
        ],
    ) {
        match parse_section::<ImuConfig>(&text, "imu") {
            Ok(_) => {}
            Err(InsError::Toml { section, source }) => {
                prop_assert_eq!(section, "imu");
                prop_assert!(!source.message.is_empty());
            }
            Err(other) => prop_assert!(false, "unexpected {other}"),
        }
    }
}
