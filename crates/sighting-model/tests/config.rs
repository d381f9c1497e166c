//! The `[sighting]` configuration section: parsing, validation naming the field, geometry
//! checks.
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

mod common;

use common::paper_start;
use sighting_model::{LandmarkConfig, SightingConfig, SightingError};

const GOOD: &str = r#"
[sighting]
noise_var_m2 = 40.0
update_period_s = 1.0
min_range_m = 100.0
landmarks = [
  { lat_deg = -23.29, lon_deg = -45.80, alt_m = 20.0 },
  { lat_deg = -23.20, lon_deg = -45.85, alt_m = 10.0 },
  { lat_deg = -23.25, lon_deg = -45.89, alt_m = 30.0 },
]
"#;

fn parse(text: &str) -> Result<SightingConfig, String> {
    let table: toml::Table = text.parse().map_err(|e| format!("{e}"))?;
    let section = table.get("sighting").ok_or("no [sighting]")?.clone();
    section
        .try_into()
        .map_err(|e: toml::de::Error| format!("{e}"))
}

fn field_of(e: SightingError) -> String {
    match e {
        SightingError::InvalidField { field, .. } => field,
        other => panic!("expected InvalidField, got {other:?}"),
    }
}

#[test]
fn paper_toml_sighting_section_holds_table_1() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../configs/paper.toml");
    let text = std::fs::read_to_string(path).unwrap();
    let cfg = parse(&text).unwrap();
    cfg.validate().unwrap();
    // Table 1 of the paper, typed here from the paper.
    assert_eq!(cfg.noise_var_m2, 40.0);
    assert_eq!(cfg.update_period_s, 1.0);
    let expected = [
        (-23.29, -45.80, 20.0),
        (-23.20, -45.85, 10.0),
        (-23.25, -45.89, 30.0),
    ];
    assert_eq!(cfg.landmarks.len(), 3);
    for (l, (lat, lon, alt)) in cfg.landmarks.iter().zip(expected) {
        assert_eq!((l.lat_deg, l.lon_deg, l.alt_m), (lat, lon, alt));
    }
    assert_eq!(cfg, SightingConfig::paper());
    // All three landmarks are usable from the paper's start point.
    assert_eq!(cfg.check_vehicle(&paper_start()).unwrap().len(), 3);
    assert_eq!(cfg.landmarks3().unwrap()[2].id(), 2);
}

#[test]
fn good_section_parses_and_round_trips() {
    let cfg = parse(GOOD).unwrap();
    cfg.validate().unwrap();
    let mut outer = toml::Table::new();
    outer.insert("sighting".into(), toml::Value::try_from(&cfg).unwrap());
    let text = toml::to_string(&outer).unwrap();
    assert_eq!(parse(&text).unwrap(), cfg);
}

#[test]
fn unknown_and_missing_fields_are_rejected_by_the_parser() {
    let unknown = GOOD.replace(
        "min_range_m = 100.0",
        "min_range_m = 100.0\nnoise_sigma_m = 6.3",
    );
    let e = parse(&unknown).unwrap_err();
    assert!(e.contains("noise_sigma_m"), "{e}");
    let in_landmark = GOOD.replace("alt_m = 10.0", "alt_m = 10.0, height_m = 3.0");
    let e = parse(&in_landmark).unwrap_err();
    assert!(e.contains("height_m"), "{e}");
    let missing = GOOD.replace("update_period_s = 1.0\n", "");
    let e = parse(&missing).unwrap_err();
    assert!(e.contains("update_period_s"), "{e}");
}

#[test]
fn validate_names_the_offending_field() {
    let base = SightingConfig::paper();
    let cases: Vec<(SightingConfig, &str)> = vec![
        (
            SightingConfig {
                noise_var_m2: -1.0,
                ..base.clone()
            },
            "noise_var_m2",
        ),
        (
            SightingConfig {
                noise_var_m2: f64::NAN,
                ..base.clone()
            },
            "noise_var_m2",
        ),
        (
            SightingConfig {
                update_period_s: 0.0,
                ..base.clone()
            },
            "update_period_s",
        ),
        (
            SightingConfig {
                update_period_s: f64::INFINITY,
                ..base.clone()
            },
            "update_period_s",
        ),
        (
            SightingConfig {
                min_range_m: -5.0,
                ..base.clone()
            },
            "min_range_m",
        ),
        (
            {
                let mut c = base.clone();
                c.landmarks[1].lat_deg = f64::NAN;
                c
            },
            "landmarks[1].lat_deg",
        ),
        (
            {
                let mut c = base.clone();
                c.landmarks[2].lat_deg = -95.0;
                c
            },
            "landmarks[2].lat_deg",
        ),
        (
            {
                let mut c = base.clone();
                c.landmarks[0].lon_deg = f64::INFINITY;
                c
            },
            "landmarks[0].lon_deg",
        ),
        (
            {
                let mut c = base.clone();
                c.landmarks[2].alt_m = f64::NAN;
                c
            },
            "landmarks[2].alt_m",
        ),
    ];
    for (cfg, field) in cases {
        let e = cfg.validate().unwrap_err();
        assert!(
            e.to_string().contains(field),
            "message `{e}` should name {field}"
        );
        assert_eq!(field_of(e), field);
    }
    // Zero variance is valid (disables the simulated noise).
    SightingConfig {
        noise_var_m2: 0.0,
        ..base.clone()
    }
    .validate()
    .unwrap();
}

#[test]
fn landmark_counts_are_checked() {
    let empty = SightingConfig {
        landmarks: vec![],
        ..SightingConfig::paper()
    };
    assert_eq!(
        empty.validate(),
        Err(SightingError::LandmarkCount {
            expected: 1,
            found: 0
        })
    );
    let mut two = SightingConfig::paper();
    two.landmarks.pop();
    two.validate().unwrap();
    assert_eq!(
        two.landmarks3().unwrap_err(),
        SightingError::LandmarkCount {
            expected: 3,
            found: 2
        }
    );
}

#[test]
fn landmark_at_the_vehicle_position_fails_the_geometry_check() {
    let start = paper_start();
    let mut cfg = SightingConfig::paper();
    cfg.landmarks[1] = LandmarkConfig {
        lat_deg: start.lat_rad.to_degrees(),
        lon_deg: start.lon_rad.to_degrees(),
        alt_m: start.alt_m + 30.0,
    };
    cfg.validate().unwrap(); // the section alone is fine…
    match cfg.check_vehicle(&start) {
        // …but from the vehicle the landmark is 30 m away, under the 100 m minimum.
        Err(SightingError::RangeTooShort {
            landmark: 1,
            range_m,
            min_range_m,
        }) => {
            assert!((range_m - 30.0).abs() < 1e-6 && min_range_m == 100.0)
        }
        other => panic!("expected RangeTooShort for landmark 1, got {other:?}"),
    }
}
