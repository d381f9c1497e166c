//! Property tests of the tracker's TOML configurations (the presets): mutated
//! text (edited values, NaN/inf/huge numbers, deleted and inserted lines, flipped bytes) never
//! panics and gives either a valid configuration or the typed error naming the file, a line of
//! it and the column; a non-finite number in any field is refused at that field's line; valid
//! configurations round-trip serialise → parse → equal.
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use lane_tracker::{INDOOR_TOML, OUTDOOR_TOML, TrackerConfig, TrackerError};
use proptest::prelude::*;
use proptest::sample::Index;
use proptest::test_runner::{Config, RngSeed};

fn config(cases: u32) -> Config {
    Config {
        cases,
        rng_seed: RngSeed::Fixed(0x746f_6d6c),
        failure_persistence: None,
        ..Config::default()
    }
}

/// Lines of `text` of the form `key = value [# comment]`: (line index, key).
fn key_lines(text: &str) -> Vec<(usize, String)> {
    text.lines()
        .enumerate()
        .filter_map(|(i, l)| {
            let (k, _) = l.split_once('=')?;
            let k = k.trim();
            (!k.is_empty()
                && !l.trim_start().starts_with('#')
                && k.chars().all(|c| c.is_ascii_alphanumeric() || c == '_'))
            .then(|| (i, k.to_owned()))
        })
        .collect()
}

/// `text` with the value on line `line` replaced by `value` (its comment kept).
fn with_value_on_line(text: &str, line: usize, value: &str) -> String {
    let mut out = String::new();
    for (i, l) in text.lines().enumerate() {
        if i == line {
            let (k, rest) = l.split_once('=').unwrap();
            let comment = rest.find('#').map_or("", |c| &rest[c..]);
            out.push_str(&format!("{k}= {value} {comment}"));
        } else {
            out.push_str(l);
        }
        out.push('\n');
    }
    out
}

/// An edit of a configuration text.
#[derive(Debug, Clone)]
enum Edit {
    /// Replace the value of one `key = value` line.
    Value(Index, &'static str),
    /// Delete one line.
    DeleteLine(Index),
    /// Insert a line before another.
    InsertLine(Index, String),
    /// Flip one bit of one byte (the text is then read lossily as UTF-8).
    FlipBit(Index, u8),
}

const VALUES: &[&str] = &[
    "nan",
    "+nan",
    "-nan",
    "inf",
    "-inf",
    "1e308",
    "-1e308",
    "1e999",
    "0",
    "-1",
    "0.0",
    "99999999999999999999",
    "-99999999999999999999",
    "1.7976931348623157e308",
    "5e-324",
    "\"ten\"",
    "true",
    "[1.0, 2.0]",
    "[]",
    "{ a = 1 }",
    "",
    "1979-05-27",
    "'",
    "[1.0, nan, 3.0]",
];

fn edit() -> impl Strategy<Value = Edit> {
    prop_oneof![
        3 => (any::<Index>(), prop::sample::select(VALUES)).prop_map(|(i, v)| Edit::Value(i, v)),
        1 => any::<Index>().prop_map(Edit::DeleteLine),
        1 => (
            any::<Index>(),
            prop_oneof![
                Just("junk = 1".to_owned()),
                Just("[extra]".to_owned()),
                Just("[filter]".to_owned()),
                Just("[[trajectory.segments]]".to_owned()),
                "[ -~]{0,20}",
            ]
        )
            .prop_map(|(i, l)| Edit::InsertLine(i, l)),
        1 => (any::<Index>(), 0u8..8).prop_map(|(i, b)| Edit::FlipBit(i, b)),
    ]
}

fn apply(text: &str, e: &Edit) -> String {
    match e {
        Edit::Value(i, v) => {
            let keys = key_lines(text);
            if keys.is_empty() {
                return text.to_owned();
            }
            with_value_on_line(text, keys[i.index(keys.len())].0, v)
        }
        Edit::DeleteLine(i) => {
            let lines: Vec<&str> = text.lines().collect();
            let drop = i.index(lines.len().max(1));
            lines
                .iter()
                .enumerate()
                .filter(|(k, _)| *k != drop)
                .map(|(_, l)| format!("{l}\n"))
                .collect()
        }
        Edit::InsertLine(i, new) => {
            let mut lines: Vec<String> = text.lines().map(str::to_owned).collect();
            let at = i.index(lines.len() + 1);
            lines.insert(at, new.clone());
            lines.iter().map(|l| format!("{l}\n")).collect()
        }
        Edit::FlipBit(i, bit) => {
            let mut bytes = text.as_bytes().to_vec();
            if !bytes.is_empty() {
                let k = i.index(bytes.len());
                bytes[k] ^= 1 << bit;
            }
            String::from_utf8_lossy(&bytes).into_owned()
        }
    }
}

/// A located error must point into the text: a line that exists, a column within it (+1 for
/// an error at the end of a line).
fn check_location(
    text: &str,
    line: Option<usize>,
    column: Option<usize>,
) -> Result<(), TestCaseError> {
    if let (Some(l), Some(c)) = (line, column) {
        let n_lines = text.lines().count().max(1);
        prop_assert!(l >= 1 && l <= n_lines + 1, "line {} of {}", l, n_lines);
        let len = text.lines().nth(l - 1).map_or(0, |s| s.chars().count());
        prop_assert!(
            c >= 1 && c <= len + 1,
            "column {} of a {}-character line",
            c,
            len
        );
    }
    Ok(())
}

/// The 0-based line of the first occurrence of `needle`.
fn line_of(text: &str, needle: &str) -> usize {
    text[..text.find(needle).unwrap()].matches('\n').count()
}

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
    let t = with_value_on_line(OUTDOOR_TOML, line_of(OUTDOOR_TOML, "r_sigma_px"), "nan");
    assert!(t.contains("r_sigma_px = nan # σ of one edge pixel"), "{t}");
    assert!(
        key_lines(OUTDOOR_TOML)
            .iter()
            .any(|(_, k)| k == "wrls_lambda")
    );
}
