//! Property tests of the INS scenario's TOML configuration: mutated
//! text (edited values, NaN/inf/huge numbers, deleted and inserted lines, flipped bytes) never
//! panics and gives either a valid configuration or the typed error naming the file, a line of
//! it and the column; a non-finite number in any field is refused at that field's line; valid
//! configurations round-trip serialise → parse → equal.
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use ins_sim::{Scenario, SimError};
use proptest::prelude::*;
use proptest::sample::Index;
use toml_config::mutate::{
    apply, check_location, config, edit, key_lines, line_of, with_value_on_line,
};

fn paper_toml() -> String {
    std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../configs/paper.toml"
    ))
    .unwrap()
}

proptest! {
    #![proptest_config(config(64))]

    #[test]
    fn mutated_scenarios_parse_or_name_the_file_line_and_column(
        edits in prop::collection::vec(edit(), 1..4),
    ) {
        let text = edits.iter().fold(paper_toml(), |t, e| apply(&t, e));
        match Scenario::from_toml_named("configs/s.toml", &text) {
            Ok(s) => prop_assert!(s.validate().is_ok()),
            Err(SimError::ScenarioFile { error, .. }) => {
                prop_assert_eq!(&error.path, "configs/s.toml");
                check_location(&text, error.line, error.column)?;
            }
            Err(other) => prop_assert!(false, "not a located scenario error: {other:?}"),
        }
    }

    /// NaN and infinities are refused in every numeric field of the scenario, at its line.
    #[test]
    fn non_finite_scenario_fields_are_refused_at_their_line(
        key in any::<Index>(),
        value in prop::sample::select(vec!["nan", "-nan", "inf", "-inf"]),
    ) {
        let base = paper_toml();
        let keys: Vec<(usize, String)> = key_lines(&base)
            .into_iter()
            .filter(|(l, _)| {
                let v = base.lines().nth(*l).unwrap().split_once('=').unwrap().1;
                v.trim().split('#').next().unwrap().trim().parse::<f64>().is_ok()
            })
            .collect();
        let (line, name) = &keys[key.index(keys.len())];
        let text = with_value_on_line(&base, *line, value);
        match Scenario::from_toml_named("s.toml", &text) {
            Err(SimError::ScenarioFile { error, field }) => {
                prop_assert!(field.ends_with(name.as_str()) || error.message.contains(name.as_str()), "{} / {}", field, error);
                prop_assert_eq!(error.line, Some(line + 1), "{}", error);
            }
            other => prop_assert!(false, "{name} = {value}: {other:?}"),
        }
    }

    /// The scenario's sections, edited within their valid ranges and serialised, parse back
    /// equal.
    #[test]
    fn valid_scenarios_round_trip(
        r_var in 1.0f64..100.0,
        p0 in 0.1f64..10.0,
        window in 1usize..=64,
        runs in 1usize..10_000,
        // TOML integers are i64: a seed above i64::MAX cannot be written to a scenario file.
        seed in 0..=i64::MAX as u64,
        open_loop in 0.0f64..900.0,
    ) {
        let mut s = Scenario::paper_default();
        s.filter.r_var_m2 = r_var;
        s.filter.p0_pos_sigma_m = p0;
        s.filter.akf_window = window;
        s.filter.open_loop_until_s = open_loop;
        s.monte_carlo.runs = runs;
        s.monte_carlo.seed = seed;
        prop_assume!(s.validate().is_ok());
        let mut table = toml::Table::new();
        table.insert("trajectory".into(), toml::Value::try_from(&s.trajectory).unwrap());
        table.insert("imu".into(), toml::Value::try_from(&s.imu).unwrap());
        table.insert("sighting".into(), toml::Value::try_from(&s.sighting).unwrap());
        table.insert("filter".into(), toml::Value::try_from(&s.filter).unwrap());
        table.insert("monte_carlo".into(), toml::Value::try_from(&s.monte_carlo).unwrap());
        let text = toml::to_string(&table).unwrap();
        prop_assert_eq!(Scenario::from_toml_named("rt.toml", &text).unwrap(), s);
    }
}

#[test]
fn the_edit_helpers_edit_what_they_say() {
    let paper = paper_toml();
    let t = with_value_on_line(&paper, line_of_unwrapped(&paper, "r_var_m2"), "nan");
    assert!(
        t.lines()
            .any(|l| l.trim_start().starts_with("r_var_m2 = nan")),
        "{t}"
    );
    assert!(key_lines(&paper).iter().any(|(_, k)| k == "r_var_m2"));
}

/// The 0-based line of the first occurrence of `needle`, which must occur.
fn line_of_unwrapped(text: &str, needle: &str) -> usize {
    line_of(text, needle).expect("the needle occurs in the text")
}
