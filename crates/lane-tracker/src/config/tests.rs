use super::*;

#[test]
fn presets_parse_and_validate() {
    let out = TrackerConfig::outdoor().unwrap();
    let ind = TrackerConfig::indoor().unwrap();
    assert!(ind.gradient.magnitude_threshold < out.gradient.magnitude_threshold);
    assert_eq!(TrackerConfig::preset("outdoor").unwrap().unwrap(), out);
}

#[test]
fn unknown_field_is_refused_naming_it() {
    let text = OUTDOOR_TOML.replace("[track]", "[track]\nwindow_width = 3");
    let err = TrackerConfig::from_toml_str("x.toml", &text).unwrap_err();
    let msg = err.to_string();
    let line = 1 + text[..text.find("window_width").unwrap()]
        .matches('\n')
        .count();
    match &err {
        TrackerError::ConfigFile(e) => {
            assert_eq!(
                (e.path.as_str(), e.line, e.column),
                ("x.toml", Some(line), Some(1))
            );
        }
        other => panic!("{other:?}"),
    }
    assert!(
        msg.starts_with(&format!("x.toml:{line}:1: unknown field `window_width`")),
        "{msg}"
    );
}

#[test]
fn missing_field_is_refused_naming_it() {
    let text: String = OUTDOOR_TOML
        .lines()
        .filter(|l| !l.starts_with("r_sigma_px"))
        .map(|l| format!("{l}\n"))
        .collect();
    let msg = TrackerConfig::from_toml_str("x.toml", &text)
        .unwrap_err()
        .to_string();
    assert!(msg.contains("r_sigma_px"), "{msg}");
}

#[test]
fn an_out_of_range_field_in_a_file_names_the_file_line_and_column() {
    let text = OUTDOOR_TOML.replace("r_sigma_px = 2.0", "r_sigma_px = -2.0");
    let line = 1 + text[..text.find("r_sigma_px = -2.0").unwrap()]
        .matches('\n')
        .count();
    let msg = TrackerConfig::from_toml_str("cfg/bad.toml", &text)
        .unwrap_err()
        .to_string();
    assert_eq!(
        msg,
        format!("cfg/bad.toml:{line}:1: `filter.r_sigma_px` = -2: must be finite and > 0 px")
    );
}

#[test]
fn each_out_of_range_field_is_named() {
    type Edit = fn(&mut TrackerConfig);
    let cases: &[(&str, Edit)] = &[
        ("frame.working_width_px", |c| c.frame.working_width_px = 15),
        ("exposure.below_median_grey", |c| {
            c.exposure.below_median_grey = -1.0
        }),
        ("exposure.below_median_grey", |c| {
            c.exposure.below_median_grey = 256.0
        }),
        ("denoise.above_noise_grey", |c| {
            c.denoise.above_noise_grey = -1.0
        }),
        ("denoise.above_noise_grey", |c| {
            c.denoise.above_noise_grey = f64::NAN
        }),
        ("frame.working_width_px", |c| {
            c.frame.working_width_px = 16385
        }),
        ("gradient.magnitude_threshold", |c| {
            c.gradient.magnitude_threshold = 3000
        }),
        ("gradient.adaptive_keep_fraction", |c| {
            c.gradient.adaptive_keep_fraction = -0.1
        }),
        ("gradient.min_edge_angle_deg", |c| {
            c.gradient.min_edge_angle_deg = -1.0
        }),
        ("gradient.max_edge_angle_deg", |c| {
            c.gradient.max_edge_angle_deg = 5.0
        }),
        ("gradient.periodic_min_stripes", |c| {
            c.gradient.periodic_min_stripes = 2
        }),
        ("gradient.periodic_min_stripes", |c| {
            c.gradient.periodic_min_stripes = 17
        }),
        ("gradient.periodic_max_width_px", |c| {
            c.gradient.periodic_max_width_px = 0
        }),
        ("roi.top_row_fraction", |c| c.roi.top_row_fraction = 1.0),
        ("roi.bottom_row_fraction", |c| {
            c.roi.bottom_row_fraction = 0.1
        }),
        ("roi.fallback_top_row_fraction", |c| {
            c.roi.fallback_top_row_fraction = Some(c.roi.top_row_fraction)
        }),
        ("roi.fallback_top_row_fraction", |c| {
            c.roi.fallback_top_row_fraction = Some(-0.1)
        }),
        ("roi.fallback_top_row_fraction", |c| {
            c.roi.fallback_top_row_fraction = Some(f64::NAN)
        }),
        ("init.theta_step_deg", |c| c.init.theta_step_deg = 0.0),
        ("init.rho_step_px", |c| c.init.rho_step_px = 51.0),
        ("init.band_half_width_px", |c| {
            c.init.band_half_width_px = f64::INFINITY
        }),
        ("init.min_points", |c| c.init.min_points = 2),
        ("init.refit_iterations", |c| c.init.refit_iterations = 11),
        ("init.orientation_tolerance_deg", |c| {
            c.init.orientation_tolerance_deg = -5.0
        }),
        ("init.orientation_tolerance_deg", |c| {
            c.init.orientation_tolerance_deg = f64::NAN
        }),
        ("track.orientation_tolerance_deg", |c| {
            c.track.orientation_tolerance_deg = 91.0
        }),
        ("track.inlier_half_width_px", |c| {
            c.track.inlier_half_width_px = 0.0
        }),
        ("track.window_half_width_px", |c| {
            c.track.window_half_width_px = 0
        }),
        ("track.max_points_per_lane", |c| {
            c.track.max_points_per_lane = 2
        }),
        ("track.reinit_min_points", |c| {
            c.track.reinit_min_points = 2000
        }),
        ("track.lost_after_frames", |c| c.track.lost_after_frames = 0),
        ("track.revalidate_every_frames", |c| {
            c.track.revalidate_every_frames = 100_001
        }),
        ("track.revalidate_below_points", |c| {
            c.track.revalidate_below_points = c.track.max_points_per_lane + 1
        }),
        ("track.revalidate_keep_factor", |c| {
            c.track.revalidate_keep_factor = 0.5
        }),
        ("track.revalidate_keep_factor", |c| {
            c.track.revalidate_keep_factor = f64::INFINITY
        }),
        ("track.max_jump_px", |c| c.track.max_jump_px = -1.0),
        ("track.min_lane_separation_px", |c| {
            c.track.min_lane_separation_px = f64::NAN
        }),
        ("filter.q_sigma_px", |c| c.filter.q_sigma_px[1] = 0.0),
        ("filter.r_sigma_px", |c| c.filter.r_sigma_px = 0.0),
        ("filter.p0_sigma_px", |c| c.filter.p0_sigma_px[2] = f64::NAN),
        ("filter.wrls_lambda", |c| c.filter.wrls_lambda = 1.5),
        ("init.ego_pair.width_weight", |c| {
            c.init.ego_pair.width_weight = -1.0
        }),
        ("init.ego_pair.min_support_frac", |c| {
            c.init.ego_pair.min_support_frac = 1.5
        }),
        ("init.ego_pair.lone_min_lean_deg", |c| {
            c.init.ego_pair.lone_min_lean_deg = 90.0
        }),
        ("init.ego_pair.meet_top_frac", |c| {
            c.init.ego_pair.meet_top_frac = 0.5
        }),
        ("init.kerb_foot", |c| {
            c.init.kerb_foot = true;
            c.gradient.stripe_max_width_px = 3;
        }),
        ("init.stripe_trace", |c| {
            c.init.stripe_trace = true;
            c.gradient.stripe_max_width_px = 1;
        }),
    ];
    for (field, edit) in cases {
        let mut cfg = TrackerConfig::outdoor().unwrap();
        cfg.validate().unwrap();
        edit(&mut cfg);
        match cfg.validate() {
            Err(e) if e.config_field().is_some() => {
                assert_eq!(e.config_field(), Some(*field), "{e}");
            }
            other => panic!("{field}: expected a field error, got {other:?}"),
        }
    }
}

#[test]
fn the_configuration_and_the_components_agree_on_every_stage_one_and_two_range() {
    // A value the configuration accepts is one the tracker's components accept, and the
    // other way round: the ranges are checked once, by the crates that use the values.
    let values = [
        -1.0, 0.0, 0.005, 0.01, 0.5, 5.0, 10.0, 10.5, 45.0, 50.0, 89.0, 90.0, 1e4,
    ];
    type Set = fn(&mut TrackerConfig, f64);
    let fields: &[(&str, Set)] = &[
        ("theta_step_deg", |c, v| c.init.theta_step_deg = v),
        ("rho_step_px", |c, v| c.init.rho_step_px = v),
        ("band_half_width_px", |c, v| c.init.band_half_width_px = v),
        ("min_points", |c, v| c.init.min_points = v.max(0.0) as usize),
        ("refit_iterations", |c, v| {
            c.init.refit_iterations = v.max(0.0) as u32
        }),
        ("min_edge_angle_deg", |c, v| {
            c.gradient.min_edge_angle_deg = v
        }),
        ("max_edge_angle_deg", |c, v| {
            c.gradient.max_edge_angle_deg = v
        }),
        ("adaptive_keep_fraction", |c, v| {
            c.gradient.adaptive_keep_fraction = v
        }),
    ];
    let mut accepted = 0;
    for (name, set) in fields {
        for &v in &values {
            let mut cfg = TrackerConfig::outdoor().unwrap();
            set(&mut cfg, v);
            let by_config = cfg.validate().is_ok();
            let by_components = cfg.gradient.params().validate().is_ok()
                && cfg
                    .gradient
                    .hough_bands()
                    .iter()
                    .all(|b| b.validate().is_ok())
                && cfg.init.hough_params().validate().is_ok()
                && cfg.init.lane_params().validate().is_ok();
            let tracker = crate::LaneTracker::new(&cfg, crate::Estimator::Kif, 320, 240);
            assert_eq!(by_config, by_components, "{name} = {v}");
            assert_eq!(by_config, tracker.is_ok(), "{name} = {v}: {tracker:?}");
            accepted += usize::from(by_config);
        }
    }
    assert!(
        accepted > 20,
        "the sweep must cover accepted values too ({accepted})"
    );
}

#[test]
fn scale_pixels_scales_pixel_fields_only() {
    let base = TrackerConfig::outdoor().unwrap();
    let mut c = base;
    c.scale_pixels(4.0);
    c.validate().unwrap();
    assert_eq!(
        c.track.window_half_width_px,
        4 * base.track.window_half_width_px
    );
    assert_eq!(c.filter.r_sigma_px, 4.0 * base.filter.r_sigma_px);
    assert_eq!(c.filter.q_sigma_px[0], 4.0 * base.filter.q_sigma_px[0]);
    assert_eq!(
        c.init.band_half_width_px,
        4.0 * base.init.band_half_width_px
    );
    assert_eq!(
        c.gradient.periodic_max_width_px,
        4 * base.gradient.periodic_max_width_px
    );
    let mut unscaled = c.gradient;
    unscaled.periodic_max_width_px = base.gradient.periodic_max_width_px;
    assert_eq!(unscaled, base.gradient);
    assert_eq!(c.roi, base.roi);
    assert_eq!(c.track.max_points_per_lane, base.track.max_points_per_lane);
}

#[test]
fn roi_rows_follow_the_fractions_and_stay_inside_tiny_images() {
    let mut cfg = TrackerConfig::outdoor().unwrap();
    cfg.roi.top_row_fraction = 0.5;
    cfg.roi.bottom_row_fraction = 1.0;
    assert_eq!(cfg.roi_rows(240), (120, 240));
    let (t, b) = cfg.roi_rows(4);
    assert!(t < b && b <= 4 && b - t >= 3, "{t}..{b}");
}

#[test]
fn the_second_search_rows_run_from_their_fraction_to_the_roi_bottom_and_are_off_when_absent() {
    let mut cfg = TrackerConfig::outdoor().unwrap();
    assert_eq!(
        cfg.roi.fallback_top_row_fraction, None,
        "absent in the file: no second search"
    );
    assert_eq!(cfg.fallback_roi_rows(240), None);
    cfg.roi.top_row_fraction = 0.5;
    cfg.roi.bottom_row_fraction = 0.9;
    cfg.roi.fallback_top_row_fraction = Some(0.25);
    cfg.validate().unwrap();
    assert_eq!(cfg.roi_rows(240), (120, 216));
    assert_eq!(cfg.fallback_roi_rows(240), Some((60, 216)));
    let default = TrackerConfig::default_preset().unwrap();
    let (top, bottom) = default.roi_rows(240);
    let (tall_top, tall_bottom) = default
        .fallback_roi_rows(240)
        .expect("the default searches again");
    assert!(tall_top < top && tall_bottom == bottom);
}

#[test]
fn the_kerb_reading_needs_a_face_range_and_keeps_it_when_scaled() {
    let mut cfg = TrackerConfig::default_preset().unwrap();
    assert!(cfg.init.kerb_foot);
    cfg.gradient.stripe_max_width_px = 4;
    cfg.validate().unwrap();
    cfg.gradient.stripe_max_width_px = 3;
    assert!(matches!(
        cfg.validate(),
        Err(TrackerError::ConfigField {
            field: "init.kerb_foot",
            ..
        })
    ));
    // A small frame: 12 px × 0.2 would round to 2; with the kerb reading it stays at 4.
    let mut small = TrackerConfig::default_preset().unwrap();
    small.scale_pixels(0.2);
    assert_eq!(small.gradient.stripe_max_width_px, 4);
    small.validate().unwrap();
    small.init.kerb_foot = false;
    small.gradient.stripe_max_width_px = 12;
    small.scale_pixels(0.2);
    assert_eq!(small.gradient.stripe_max_width_px, 2);
}

#[test]
fn the_stripe_trace_needs_a_two_pixel_stripe_and_keeps_it_when_scaled() {
    let mut cfg = TrackerConfig::default_preset().unwrap();
    assert!(cfg.init.stripe_trace);
    cfg.init.kerb_foot = false;
    cfg.gradient.stripe_max_width_px = 2;
    cfg.validate().unwrap();
    // 16 px × 0.05 rounds to 1: with the trace it stays at 2, without it falls to 1.
    let mut small = TrackerConfig::default_preset().unwrap();
    small.init.kerb_foot = false;
    small.scale_pixels(0.05);
    assert_eq!(small.gradient.stripe_max_width_px, 2);
    small.validate().unwrap();
    small.init.stripe_trace = false;
    small.gradient.stripe_max_width_px = 16;
    small.scale_pixels(0.05);
    assert_eq!(small.gradient.stripe_max_width_px, 1);
}

#[test]
fn a_value_a_component_refuses_names_its_field_and_keeps_the_components_error() {
    use std::error::Error as _;
    let mut cfg = TrackerConfig::default_preset().unwrap();
    cfg.init.ego_pair.min_width_frac = -1.0;
    let e = cfg.validate().expect_err("refused");
    assert_eq!(
        e.config_field(),
        Some("init.ego_pair.min_width_frac"),
        "{e}"
    );
    let source = e.source().expect("the component's error");
    assert!(
        matches!(
            source.downcast_ref::<hough_init::HoughError>(),
            Some(hough_init::HoughError::InvalidParam {
                field: "min_width_frac",
                ..
            })
        ),
        "{source:?}"
    );
    let mut cfg = TrackerConfig::default_preset().unwrap();
    cfg.gradient.min_edge_angle_deg = 95.0;
    let e = cfg.validate().expect_err("refused");
    assert_eq!(e.config_field(), Some("gradient.min_edge_angle_deg"), "{e}");
    assert!(
        e.source()
            .and_then(|s| s.downcast_ref::<vision_gradient::GradientError>())
            .is_some(),
        "{e:?}"
    );
    // From a file, the same refusal is located at its key.
    let text = crate::config::DEFAULT_TOML.replace("min_width_frac = 0.2", "min_width_frac = -1.0");
    let line = text
        .lines()
        .position(|l| l.starts_with("min_width_frac"))
        .expect("the key")
        + 1;
    match TrackerConfig::from_toml_str("cfg.toml", &text) {
        Err(TrackerError::ConfigFile(f)) => {
            assert_eq!(f.line, Some(line), "{f}");
            assert!(f.message.contains("init.ego_pair.min_width_frac"), "{f}");
        }
        other => panic!("expected a located error, got {other:?}"),
    }
}

#[test]
fn the_working_width_is_320_when_absent_and_located_in_a_file_when_out_of_range() {
    // The presets have no `[frame]`: they are tuned at 320 px and work there.
    for preset in [OUTDOOR_TOML, INDOOR_TOML] {
        assert!(!preset.contains("[frame]"));
        let c = TrackerConfig::from_toml_str("p.toml", preset).unwrap();
        assert_eq!(c.frame.working_width_px, DEFAULT_WORKING_WIDTH_PX);
    }
    let default = TrackerConfig::default_preset().unwrap();
    assert_eq!(default.frame.working_width_px, 320);
    let text = DEFAULT_TOML.replace("working_width_px = 320", "working_width_px = 8");
    let line = 1 + text[..text.find("working_width_px = 8").unwrap()]
        .matches('\n')
        .count();
    let msg = TrackerConfig::from_toml_str("w.toml", &text)
        .unwrap_err()
        .to_string();
    assert!(
        msg.starts_with(&format!("w.toml:{line}:1: `frame.working_width_px` = 8")),
        "{msg}"
    );
    // 0: the input's own size, accepted.
    let text = DEFAULT_TOML.replace("working_width_px = 320", "working_width_px = 0");
    assert_eq!(
        TrackerConfig::from_toml_str("w.toml", &text)
            .unwrap()
            .frame
            .working_width_px,
        0
    );
}

#[test]
fn denoising_is_off_when_absent_and_its_limit_is_located_in_a_file_when_out_of_range() {
    for preset in [OUTDOOR_TOML, INDOOR_TOML] {
        let c = TrackerConfig::from_toml_str("p.toml", preset).unwrap();
        assert_eq!(c.denoise.above_noise_grey, 0.0);
        assert_eq!(
            c.exposure.below_median_grey, 0.0,
            "brightening off when absent"
        );
    }
    assert_eq!(
        TrackerConfig::default_preset()
            .unwrap()
            .exposure
            .below_median_grey,
        50.0
    );
    assert_eq!(
        TrackerConfig::default_preset()
            .unwrap()
            .denoise
            .above_noise_grey,
        4.0
    );
    let text = DEFAULT_TOML.replace("above_noise_grey = 4.0", "above_noise_grey = 300.0");
    let line = 1 + text[..text.find("above_noise_grey = 300").unwrap()]
        .matches('\n')
        .count();
    let msg = TrackerConfig::from_toml_str("d.toml", &text)
        .unwrap_err()
        .to_string();
    assert!(
        msg.starts_with(&format!(
            "d.toml:{line}:1: `denoise.above_noise_grey` = 300"
        )),
        "{msg}"
    );
}
