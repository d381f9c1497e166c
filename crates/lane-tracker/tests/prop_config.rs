//! Property tests of the tracker's TOML configurations (the presets): mutated
//! text (edited values, NaN/inf/huge numbers, deleted and inserted lines, flipped bytes) never
//! panics and gives either a valid configuration or the typed error naming the file, a line of
//! it and the column; a non-finite number in any field is refused at that field's line; valid
//! configurations round-trip serialise → parse → equal.
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use lane_tracker::{INDOOR_TOML, OUTDOOR_TOML, TrackerConfig, TrackerError};
use proptest::prelude::*;
use proptest::sample::Index;
use toml_config::mutate::{
    apply, check_location, config, edit, key_lines, line_of, with_value_on_line,
};

proptest! {
    #![proptest_config(config(256))]

    #[test]
    fn mutated_tracker_configs_parse_or_name_the_file_line_and_column(
        preset in prop::sample::select(vec![OUTDOOR_TOML, INDOOR_TOML]),
        edits in prop::collection::vec(edit(), 1..4),
    ) {
        let text = edits.iter().fold(preset.to_owned(), |t, e| apply(&t, e));
        match TrackerConfig::from_toml_str("cfg/p.toml", &text) {
            Ok(cfg) => prop_assert!(cfg.validate().is_ok()),
            Err(TrackerError::ConfigFile(e)) => {
                prop_assert_eq!(&e.path, "cfg/p.toml");
                prop_assert!(e.to_string().starts_with("cfg/p.toml"), "{}", e);
                prop_assert_eq!(e.to_string().matches("cfg/p.toml").count(), 1);
                check_location(&text, e.line, e.column)?;
            }
            Err(other) => prop_assert!(false, "not a located config error: {other:?}"),
        }
    }

    /// NaN and infinities are refused in every numeric field of the tracker, at its line.
    #[test]
    fn non_finite_tracker_fields_are_refused_at_their_line(
        key in any::<Index>(),
        value in prop::sample::select(vec!["nan", "-nan", "inf", "-inf", "[nan, 1.0, 1.0]", "[1.0, 1.0, inf]"]),
    ) {
        let keys: Vec<(usize, String)> = key_lines(OUTDOOR_TOML)
            .into_iter()
            .filter(|(l, _)| OUTDOOR_TOML.lines().nth(*l).unwrap().contains('.'))
            .collect();
        let (line, name) = &keys[key.index(keys.len())];
        let is_array = OUTDOOR_TOML.lines().nth(*line).unwrap().contains('[');
        prop_assume!(is_array == value.starts_with('['));
        let text = with_value_on_line(OUTDOOR_TOML, *line, value);
        match TrackerConfig::from_toml_str("p.toml", &text) {
            Err(TrackerError::ConfigFile(e)) => {
                prop_assert_eq!(e.line, Some(line + 1), "{}", e);
                prop_assert!(e.message.contains(name.as_str()), "{}", e);
            }
            other => prop_assert!(false, "{name} = {value}: {other:?}"),
        }
    }

    /// A valid configuration, serialised, parses back equal.
    #[test]
    fn valid_tracker_configs_round_trip(
        indoor in any::<bool>(),
        scale in prop::array::uniform16(0.5f64..1.5),
        threshold in 0u16..=2040,
        points in 3usize..=1000,
    ) {
        let mut c = if indoor { TrackerConfig::indoor() } else { TrackerConfig::outdoor() }.unwrap();
        c.gradient.magnitude_threshold = threshold;
        c.track.max_points_per_lane = points;
        c.track.reinit_min_points = c.track.reinit_min_points.min(points);
        c.gradient.adaptive_keep_fraction = (scale[0] - 0.5).clamp(0.0, 1.0);
        c.init.band_half_width_px *= scale[1];
        c.init.theta_step_deg *= scale[2];
        c.init.rho_step_px *= scale[3];
        c.track.inlier_half_width_px *= scale[4];
        c.track.max_jump_px *= scale[5];
        c.track.min_lane_separation_px *= scale[6];
        c.filter.r_sigma_px *= scale[7];
        c.filter.q_sigma_px = [c.filter.q_sigma_px[0] * scale[8], c.filter.q_sigma_px[1] * scale[9], c.filter.q_sigma_px[2] * scale[10]];
        c.filter.p0_sigma_px = c.filter.p0_sigma_px.map(|v| v * scale[11]);
        c.filter.wrls_lambda = (c.filter.wrls_lambda * scale[12]).min(1.0);
        c.roi.top_row_fraction *= scale[13].min(1.0);
        prop_assume!(c.validate().is_ok());
        let text = toml::to_string(&c).unwrap();
        prop_assert_eq!(TrackerConfig::from_toml_str("rt.toml", &text).unwrap(), c);
    }
}

#[test]
fn the_edit_helpers_edit_what_they_say() {
    let t = with_value_on_line(
        OUTDOOR_TOML,
        line_of_unwrapped(OUTDOOR_TOML, "r_sigma_px"),
        "nan",
    );
    assert!(t.contains("r_sigma_px = nan # σ of one edge pixel"), "{t}");
    assert!(
        key_lines(OUTDOOR_TOML)
            .iter()
            .any(|(_, k)| k == "wrls_lambda")
    );
}

/// The 0-based line of the first occurrence of `needle`, which must occur.
fn line_of_unwrapped(text: &str, needle: &str) -> usize {
    line_of(text, needle).expect("the needle occurs in the text")
}
