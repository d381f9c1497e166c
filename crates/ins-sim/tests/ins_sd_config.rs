//! Scenario file: `configs/paper.toml` equals `Scenario::paper_default()`, bad input is rejected
//! with an error naming the section or the dotted field.
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use ins_sim::{Scenario, SimError, run_seed};

fn paper_toml() -> String {
    std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../configs/paper.toml"
    ))
    .unwrap()
}

/// Replaces the first line `key = …` (after `[section]`) with `key = value`.
fn with_value(text: &str, section: &str, key: &str, value: &str) -> String {
    let start = text.find(&format!("\n[{section}]")).expect("section");
    let rel = text[start..].find(&format!("\n{key} = ")).expect("key") + start + 1;
    let end = rel + text[rel..].find('\n').unwrap();
    format!("{}{key} = {value}{}", &text[..rel], &text[end..])
}

fn field_of(e: &SimError) -> String {
    match e {
        SimError::ScenarioInvalid { field, .. } => field.clone(),
        SimError::ScenarioParse { section, .. } => section.clone(),
        SimError::ScenarioFile { field, .. } => field.clone(),
        other => panic!("not a scenario error: {other:?}"),
    }
}

#[test]
fn paper_toml_equals_paper_default() {
    let s = Scenario::from_toml_str(&paper_toml()).unwrap();
    assert_eq!(s, Scenario::paper_default());
    assert_eq!(s.duration_s(), 900.0);
    assert_eq!(s.default_runs(), 100);
    assert_eq!(s.samples_per_run(), 901);
    assert_eq!(s.filter.open_loop_until_s, 195.0);
    assert_eq!(s.filter.akf_window, 10);
    assert!(s.assumptions().len() >= 8);
}

#[test]
fn invalid_values_name_the_field() {
    let base = paper_toml();
    let cases = [
        ("filter", "r_var_m2", "0.0", "filter.r_var_m2"),
        ("filter", "p0_pos_sigma_m", "-1.0", "filter.p0_pos_sigma_m"),
        (
            "filter",
            "q_accel_bias_rw_psd_mg2_per_s",
            "-1e-3",
            "filter.q_accel_bias_rw_psd_mg2_per_s",
        ),
        ("filter", "phi_subintervals", "0", "filter.phi_subintervals"),
        (
            "filter",
            "phi_subintervals",
            "1000",
            "filter.phi_subintervals",
        ),
        ("filter", "akf_window", "0", "filter.akf_window"),
        // The limit is the estimator's ring size, akf::DEFAULT_WINDOW_CAPACITY.
        ("filter", "akf_window", "65", "filter.akf_window"),
        (
            "filter",
            "akf_min_variance",
            "-1.0",
            "filter.akf_min_variance",
        ),
        (
            "filter",
            "sage_husa_forgetting",
            "1.5",
            "filter.sage_husa_forgetting",
        ),
        (
            "filter",
            "p0_psi_sigma_mrad",
            "0.0",
            "filter.p0_psi_sigma_mrad",
        ),
        (
            "filter",
            "open_loop_until_s",
            "-5.0",
            "filter.open_loop_until_s",
        ),
        ("monte_carlo", "runs", "0", "monte_carlo.runs"),
        (
            "imu",
            "accel_bias_sigma_mg",
            "-3.0",
            "imu.accel_bias_sigma_mg",
        ),
        ("sighting", "noise_var_m2", "-40.0", "sighting.noise_var_m2"),
        (
            "sighting",
            "update_period_s",
            "0.015",
            "sighting.update_period_s",
        ),
        ("trajectory", "end_time_s", "900.5", "trajectory.end_time_s"),
    ];
    for (section, key, value, want) in cases {
        let text = with_value(&base, section, key, value);
        let e = Scenario::from_toml_str(&text).expect_err(want);
        assert_eq!(field_of(&e), want, "{section}.{key} = {value}: {e}");
        assert!(e.to_string().contains(want), "{e}");
    }
}

#[test]
fn unknown_keys_sections_and_types_name_the_section_and_key() {
    let base = paper_toml();
    // Unknown key in [filter].
    let text = base.replace("\n[filter]\n", "\n[filter]\nr_sigma_m = 6.0\n");
    let e = Scenario::from_toml_str(&text).unwrap_err();
    assert_eq!(field_of(&e), "filter");
    assert!(e.to_string().contains("r_sigma_m"), "{e}");
    // Unknown section.
    let e = Scenario::from_toml_str(&format!("{base}\n[camera]\nfov_deg = 3.0\n")).unwrap_err();
    assert_eq!(field_of(&e), "camera", "{e}");
    // Missing section.
    let start = base.find("\n[monte_carlo]").unwrap();
    let e = Scenario::from_toml_str(&base[..start]).unwrap_err();
    assert_eq!(field_of(&e), "monte_carlo", "{e}");
    // Wrong type.
    let e =
        Scenario::from_toml_str(&with_value(&base, "filter", "akf_window", "\"ten\"")).unwrap_err();
    assert_eq!(field_of(&e), "filter");
    assert!(e.to_string().contains("akf_window"), "{e}");
    // Bad projection name.
    let e = Scenario::from_toml_str(&with_value(&base, "filter", "akf_projection", "\"svd\""))
        .unwrap_err();
    assert_eq!(field_of(&e), "filter", "{e}");
    // Not TOML at all.
    let e = Scenario::from_toml_str("[filter\n").unwrap_err();
    assert_eq!(field_of(&e), "(document)", "{e}");
}

#[test]
fn two_landmarks_are_rejected_by_name() {
    let mut s = Scenario::paper_default();
    s.sighting.landmarks.pop();
    let e = s.validate().unwrap_err();
    assert_eq!(field_of(&e), "sighting.landmarks", "{e}");
}

#[test]
fn truncation_keeps_the_start_and_validates() {
    let s = Scenario::paper_default().truncated(100.0).unwrap();
    assert_eq!(s.duration_s(), 100.0);
    assert_eq!(s.samples_per_run(), 101);
    let total: f64 = s.trajectory.segments.iter().map(|g| g.duration_s).sum();
    assert!(total <= 100.0 + 1e-9);
    assert_eq!(
        s.trajectory.segments[0],
        Scenario::paper_default().trajectory.segments[0]
    );
    assert!(Scenario::paper_default().truncated(10.5).is_err());
    assert!(Scenario::paper_default().truncated(901.0).is_err());
}

#[test]
fn run_seeds_are_distinct_and_unchanged() {
    let mut seen = std::collections::HashSet::new();
    for i in 0..1000 {
        let s = run_seed(2009, i);
        assert_eq!(s, run_seed(2009, i));
        assert!(seen.insert(s), "collision at {i}");
    }
    assert_ne!(run_seed(1, 0), run_seed(2, 0));
    // The seeds of the runs before the mode parameter was dropped (every output depends on
    // them): SplitMix64 of the master seed and the index, pinned.
    assert_eq!(run_seed(2009, 0), 0x206a_5550_305e_afcc);
    assert_eq!(run_seed(2009, 1), 0x5ffd_0745_1ac7_ed6c);
    assert_eq!(run_seed(2009, 99), 0x71ea_cee5_e214_8e72);
}

#[test]
fn measurement_jacobian_option_parses_defaults_to_verified_and_rejects_unknown_values() {
    use ins_sim::MeasurementJacobian;
    let base = paper_toml();
    assert_eq!(
        Scenario::from_toml_str(&base)
            .unwrap()
            .filter
            .measurement_jacobian,
        MeasurementJacobian::Verified
    );
    let printed = with_value(&base, "filter", "measurement_jacobian", "\"paper_printed\"");
    let s = Scenario::from_toml_str(&printed).unwrap();
    assert_eq!(
        s.filter.measurement_jacobian,
        MeasurementJacobian::PaperPrinted
    );
    assert!(s.assumptions().iter().any(|a| a.contains("AS PRINTED")));
    // Absent key: the verified H.
    let start = base.find("\nmeasurement_jacobian = ").unwrap() + 1;
    let end = start + base[start..].find('\n').unwrap() + 1;
    let absent = format!("{}{}", &base[..start], &base[end..]);
    assert!(!absent.contains("\nmeasurement_jacobian"));
    assert_eq!(
        Scenario::from_toml_str(&absent)
            .unwrap()
            .filter
            .measurement_jacobian,
        MeasurementJacobian::Verified
    );
    // Unknown value: a parse error in [filter] naming the key's accepted values.
    let bad = with_value(&base, "filter", "measurement_jacobian", "\"printed\"");
    let e = Scenario::from_toml_str(&bad).unwrap_err();
    assert_eq!(field_of(&e), "filter");
    assert!(e.to_string().contains("paper_printed"), "{e}");
}

#[test]
fn scenario_errors_name_the_file_line_and_column() {
    let base = paper_toml();
    let line_of =
        |text: &str, needle: &str| 1 + text[..text.find(needle).unwrap()].matches('\n').count();
    // Out of range: located at the key.
    let text = with_value(&base, "filter", "r_var_m2", "-40.0");
    let e = Scenario::from_toml_named("configs/mine.toml", &text).unwrap_err();
    let line = line_of(&text, "r_var_m2 = -40.0");
    assert_eq!(field_of(&e), "filter.r_var_m2");
    let msg = e.to_string();
    assert!(
        msg.starts_with(&format!("configs/mine.toml:{line}:1: filter.r_var_m2")),
        "{msg}"
    );
    // Unknown key: located at the key; wrong type: at the value.
    let text = base.replace("\n[filter]\n", "\n[filter]\nr_sigma_m = 6.0\n");
    let e = Scenario::from_toml_named("m.toml", &text).unwrap_err();
    let line = line_of(&text, "r_sigma_m = 6.0");
    assert!(
        e.to_string()
            .starts_with(&format!("m.toml:{line}:1: unknown field `r_sigma_m`")),
        "{e}"
    );
    let text = with_value(&base, "filter", "akf_window", "\"ten\"");
    let e = Scenario::from_toml_named("m.toml", &text).unwrap_err();
    let line = line_of(&text, "akf_window = \"ten\"");
    assert!(
        e.to_string().starts_with(&format!("m.toml:{line}:14: ")),
        "{e}"
    );
    assert!(e.to_string().contains("filter.akf_window"), "{e}");
    // Unknown section: at its header; syntax error: at the token.
    let text = format!("{base}\n[camera]\nfov_deg = 3.0\n");
    let e = Scenario::from_toml_named("m.toml", &text).unwrap_err();
    let line = line_of(&text, "[camera]");
    assert!(
        e.to_string()
            .starts_with(&format!("m.toml:{line}:2: unknown section `camera`")),
        "{e}"
    );
    let e = Scenario::from_toml_named("m.toml", "[filter\n").unwrap_err();
    assert!(e.to_string().starts_with("m.toml:1:"), "{e}");
    // The path appears once.
    assert_eq!(e.to_string().matches("m.toml").count(), 1);
}

/// `nav-app ins --config`: a scenario (a top-level `trajectory` table, however it is written)
/// and a filter file are told apart by parsing, not by searching the text for `[trajectory]`.
#[test]
fn settings_files_are_told_apart_by_their_parsed_tables() {
    use ins_sim::logs::FilterSettings;
    let scenario = Scenario::paper_default().to_toml_string().unwrap();
    assert!(matches!(
        FilterSettings::from_toml_named("s.toml", &scenario),
        Ok(FilterSettings::Scenario(_))
    ));
    // The header written with spaces (valid TOML): no `[trajectory]` in the text.
    let spaced = scenario.replacen("[trajectory]", "[ trajectory ] # the flight", 1);
    assert!(!spaced.contains("[trajectory]"));
    assert!(matches!(
        FilterSettings::from_toml_named("s.toml", &spaced),
        Ok(FilterSettings::Scenario(_))
    ));
    // A filter file that mentions `[trajectory]` in a comment is still a filter file.
    let filter = "# not a scenario: no [trajectory]\npreset = \"paper\"\n";
    assert!(matches!(
        FilterSettings::from_toml_named("f.toml", filter),
        Ok(FilterSettings::File(_))
    ));
    // A syntax error names the file, line and column.
    match FilterSettings::from_toml_named("bad.toml", "preset = \n") {
        Err(e) => assert!(e.to_string().starts_with("bad.toml:1:"), "{e}"),
        Ok(_) => panic!("a syntax error was accepted"),
    }
}
