//! The camera file parser (`--camera`): random and mutated inputs never panic (a typed error or a
//! validated config), valid configs round-trip serialise → parse.
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use lane_tracker::TrackerError;
use lane_tracker::camera::{
    CAMERA_HIGHWAY_TOML, CAMERA_ROBOT_TOML, CameraConfig, HomographyConfig, IntrinsicsConfig,
    LookaheadConfig, MountingConfig,
};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngSeed};

fn proptest_config() -> Config {
    Config {
        cases: 256,
        rng_seed: RngSeed::Fixed(0x6361_6d65),
        failure_persistence: None,
        ..Config::default()
    }
}

fn parse(text: &str) {
    // Never panics; an accepted config is valid and builds a model.
    if let Ok(cfg) = CameraConfig::from_toml_str("fuzz", text) {
        cfg.model().unwrap();
    }
}

fn finite() -> impl Strategy<Value = f64> {
    prop_oneof![
        -1e3f64..1e3,
        Just(0.0),
        Just(f64::NAN),
        Just(f64::INFINITY),
        Just(-1e300)
    ]
}

fn arb_config() -> impl Strategy<Value = CameraConfig> {
    let intr = (finite(), finite(), finite()).prop_map(|(f, cx, cy)| IntrinsicsConfig {
        focal_length_px: f,
        principal_point_px: [cx, cy],
    });
    let mount = (finite(), -2.0f64..2.0, -2.0f64..2.0, -2.0f64..2.0).prop_map(|(h, p, r, y)| {
        MountingConfig {
            height_m: h,
            pitch_down_rad: p,
            roll_rad: r,
            yaw_rad: y,
        }
    });
    let hom = (
        prop::array::uniform4(prop::array::uniform2(-500.0f64..500.0)),
        prop::array::uniform4(prop::array::uniform2(-50.0f64..50.0)),
    )
        .prop_map(|(i, g)| HomographyConfig {
            image_points_px: i,
            ground_points_m: g,
        });
    (
        (0usize..5000, 0usize..5000),
        prop::option::of(intr),
        prop::option::of(mount),
        prop::option::of(hom),
        (finite(), finite()),
    )
        .prop_map(
            |((w, h), intrinsics, mounting, homography, (n, f))| CameraConfig {
                image_size_px: [w, h],
                intrinsics,
                mounting,
                homography,
                lookahead: LookaheadConfig {
                    near_m: n,
                    far_m: f,
                },
            },
        )
}

proptest! {
    #![proptest_config(proptest_config())]

    /// Arbitrary text is refused with an error (or, by chance, parsed), never a panic.
    #[test]
    fn arbitrary_text_never_panics(text in "\\PC{0,400}") {
        parse(&text);
    }

    /// A preset with one line deleted, duplicated or with a value replaced never panics; a
    /// rejection is a typed configuration error.
    #[test]
    fn mutated_presets_never_panic(
        preset in prop_oneof![Just(CAMERA_ROBOT_TOML), Just(CAMERA_HIGHWAY_TOML)],
        line in 0usize..40,
        op in 0u8..3,
        value in prop_oneof![
            Just("nan".to_owned()), Just("-inf".to_owned()), Just("0".to_owned()),
            Just("1e308".to_owned()), Just("\"x\"".to_owned()), Just("[1, 2]".to_owned()),
            Just("[[0,0],[1,0],[2,0],[3,0]]".to_owned()), (-1e4f64..1e4).prop_map(|v| v.to_string())
        ],
    ) {
        let lines: Vec<&str> = preset.lines().collect();
        let i = line % lines.len();
        let mut out: Vec<String> = lines.iter().map(|l| (*l).to_owned()).collect();
        match op {
            0 => { out.remove(i); }
            1 => { let l = out[i].clone(); out.insert(i, l); }
            _ => {
                if let Some((k, _)) = lines[i].split_once('=') {
                    out[i] = format!("{k}= {value}");
                }
            }
        }
        let text = out.join("\n");
        match CameraConfig::from_toml_str("mutated", &text) {
            Ok(cfg) => { cfg.model().unwrap(); }
            Err(e) => prop_assert!(
                matches!(e, TrackerError::ConfigFile(_)) || e.config_field().is_some(),
                "{e:?}"
            ),
        }
    }

    /// Any config the validator accepts serialises to TOML and parses back to itself.
    #[test]
    fn valid_configs_round_trip(cfg in arb_config()) {
        if cfg.validate().is_ok() {
            let text = toml::to_string(&cfg).unwrap();
            let back = CameraConfig::from_toml_str("round trip", &text).unwrap();
            prop_assert_eq!(back, cfg);
        }
    }

    /// Modelled cameras near the presets are accepted and round-trip.
    #[test]
    fn plausible_cameras_validate_and_round_trip(
        f in 100.0f64..2000.0, h in 0.1f64..3.0, pitch in 0.0f64..0.5,
        roll in -0.1f64..0.1, yaw in -0.1f64..0.1, near in 0.5f64..3.0,
    ) {
        let cfg = CameraConfig {
            image_size_px: [320, 240],
            intrinsics: Some(IntrinsicsConfig { focal_length_px: f, principal_point_px: [159.5, 119.5] }),
            mounting: Some(MountingConfig { height_m: h, pitch_down_rad: pitch, roll_rad: roll, yaw_rad: yaw }),
            homography: None,
            lookahead: LookaheadConfig { near_m: near, far_m: 2.0 * near },
        };
        cfg.validate().unwrap();
        let text = toml::to_string(&cfg).unwrap();
        prop_assert_eq!(CameraConfig::from_toml_str("rt", &text).unwrap(), cfg);
    }
}

#[test]
fn a_bad_camera_field_is_named_with_its_file_line_and_column() {
    let text = CAMERA_ROBOT_TOML.replacen("height_m", "hieght_m", 1);
    let e = CameraConfig::from_toml_str("cam.toml", &text)
        .unwrap_err()
        .to_string();
    let line = text
        .lines()
        .position(|l| l.contains("hieght_m"))
        .expect("mutated key present")
        + 1;
    assert!(e.starts_with(&format!("cam.toml:{line}:")), "{e}");
    assert!(e.contains("hieght_m"), "{e}");
}
