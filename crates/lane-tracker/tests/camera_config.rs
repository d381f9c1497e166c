//! The camera file parser (`--camera`): random and mutated inputs never panic (a typed error or a
//! validated config), valid configs round-trip serialise → parse.
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use lane_tracker::TrackerError;
use lane_tracker::camera::{
    CAMERA_HIGHWAY_TOML, CAMERA_ROBOT_TOML, CameraConfig, HomographyConfig, IntrinsicsConfig,
    LookaheadConfig, MountingConfig,
};
use proptest::prelude::*;
use proptest::strategy::ValueTree;
use proptest::test_runner::{Config, RngSeed, TestRunner};

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

/// Configs near the presets: a pinhole camera (focal length, principal point inside the image,
/// height, pitch down, small roll and yaw) or a homography of a trapezoid in the image onto a
/// rectangle on the ground ahead, with an ordered look-ahead. Most are valid; some are not (a
/// look-ahead beyond the horizon, a trapezoid the other way up).
fn plausible_config() -> impl Strategy<Value = CameraConfig> {
    let pinhole = (
        100.0f64..2000.0,
        0.2f64..0.8,
        0.2f64..0.8,
        0.1f64..5.0,
        -0.1f64..0.8,
        -0.1f64..0.1,
        -0.1f64..0.1,
    );
    let trapezoid = (
        0.3f64..0.5,
        0.02f64..0.2,
        0.3f64..0.7,
        1.0f64..3.0,
        2.0f64..10.0,
        5.0f64..60.0,
    );
    (
        (64usize..2000, 48usize..1500),
        prop_oneof![pinhole.prop_map(Ok), trapezoid.prop_map(Err)],
        (0.5f64..20.0, 1.1f64..10.0),
    )
        .prop_map(|((w, h), camera, (near, ratio))| {
            let (wf, hf) = (w as f64, h as f64);
            let (intrinsics, mounting, homography) = match camera {
                Ok((f, cx, cy, height, pitch, roll, yaw)) => (
                    Some(IntrinsicsConfig {
                        focal_length_px: f,
                        principal_point_px: [cx * wf, cy * hf],
                    }),
                    Some(MountingConfig {
                        height_m: height,
                        pitch_down_rad: pitch,
                        roll_rad: roll,
                        yaw_rad: yaw,
                    }),
                    None,
                ),
                Err((bottom, top, top_row, half_m, near_m, far_m)) => (
                    None,
                    None,
                    Some(HomographyConfig {
                        image_points_px: [
                            [(0.5 - bottom) * wf, hf - 1.0],
                            [(0.5 + bottom) * wf, hf - 1.0],
                            [(0.5 + top) * wf, top_row * hf],
                            [(0.5 - top) * wf, top_row * hf],
                        ],
                        // Ground frame: X forward, Y right.
                        ground_points_m: [
                            [near_m, -half_m],
                            [near_m, half_m],
                            [near_m + far_m, half_m],
                            [near_m + far_m, -half_m],
                        ],
                    }),
                ),
            };
            CameraConfig {
                image_size_px: [w, h],
                intrinsics,
                mounting,
                homography,
                lookahead: LookaheadConfig {
                    near_m: near,
                    far_m: near * ratio,
                },
            }
        })
}

/// Any config the validator accepts serialises to TOML and parses back to itself, and one it
/// refuses is refused again when read from its own TOML (the loader validates what it parses).
/// Arbitrary configs (almost all invalid) and plausible ones (mostly valid) are drawn; the test
/// fails unless both pinhole and homography configs were accepted often enough for the round
/// trip to have been exercised.
#[test]
fn valid_configs_round_trip_and_invalid_ones_are_refused_from_their_toml() {
    let mut runner = TestRunner::new(proptest_config());
    let (mut pinholes, mut homographies, mut refused) = (0usize, 0usize, 0usize);
    for _ in 0..512 {
        let strategy = prop_oneof![arb_config(), plausible_config()];
        let cfg = strategy.new_tree(&mut runner).unwrap().current();
        let text = toml::to_string(&cfg);
        match cfg.validate() {
            Ok(()) => {
                let back = CameraConfig::from_toml_str("round trip", &text.unwrap()).unwrap();
                assert_eq!(back, cfg);
                if cfg.homography.is_some() {
                    homographies += 1;
                } else {
                    pinholes += 1;
                }
            }
            Err(_) => {
                // Non-finite values have no TOML form the serialiser writes back; any that does
                // must be refused on load.
                if let Ok(text) = text {
                    assert!(
                        CameraConfig::from_toml_str("refused", &text).is_err(),
                        "an invalid config loads from its TOML: {cfg:?}"
                    );
                }
                refused += 1;
            }
        }
    }
    assert!(
        pinholes >= 50 && homographies >= 50 && refused >= 100,
        "accepted {pinholes} pinhole and {homographies} homography configs, refused {refused}"
    );
}
