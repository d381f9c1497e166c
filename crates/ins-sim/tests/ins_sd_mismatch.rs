//! The `[mismatch]` section: every file of configs/mismatch/ loads; a mismatch with no effect
//! takes the world path yet reproduces the matched run bit for bit (common random numbers);
//! each mismatch changes the run the way it says (fewer sightings in limited view, outliers
//! gated, …). Short flights, one run each.
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use ins_sim::{Mode, Sample, Scenario, SimRunOutcome, run, run_seed};

fn load(name: &str) -> Scenario {
    let path = format!(
        "{}/../../configs/mismatch/{name}.toml",
        env!("CARGO_MANIFEST_DIR")
    );
    Scenario::from_toml_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn go(sc: &Scenario, mode: Mode) -> (SimRunOutcome, Vec<Sample>) {
    let mut out = vec![Sample::default(); sc.samples_per_run()];
    let o = run(sc, mode, run_seed(sc.monte_carlo.seed, 1), &mut out).unwrap();
    (o, out)
}

const ALL: [&str; 8] = [
    "angular_noise",
    "bias_instability",
    "latency",
    "limited_view",
    "outliers",
    "outliers_no_gate",
    "scale_misalignment",
    "survey_error",
];

#[test]
fn every_scenario_file_loads_and_differs_from_the_paper_only_in_its_mismatch() {
    let paper = Scenario::paper_default();
    for name in ALL {
        let sc = load(name);
        assert!(!sc.mismatch.is_matched(), "{name}");
        assert_eq!(sc.trajectory, paper.trajectory, "{name}");
        assert_eq!(sc.imu, paper.imu, "{name}");
        assert_eq!(sc.monte_carlo, paper.monte_carlo, "{name}");
    }
}

#[test]
fn a_mismatch_without_effect_is_the_matched_run_bit_for_bit() {
    // Field of regard 179.99° from nadir at 6 km altitude excludes nothing, but switches the
    // simulation onto the mismatch path (scale/misalignment matrices = I, Gauss–Markov = 0,
    // zero survey, angular and outlier errors): every record equals the matched run's.
    let matched = Scenario::paper_default().truncated(30.0).unwrap();
    let mut sc = matched.clone();
    sc.mismatch.camera_max_off_nadir_deg = 179.99;
    assert!(!sc.mismatch.is_matched());
    for mode in [Mode::Standalone, Mode::Kf, Mode::Akf] {
        assert_eq!(go(&matched, mode).1, go(&sc, mode).1, "{}", mode.name());
    }
}

#[test]
fn each_mismatch_changes_the_run_as_documented() {
    let t = 60.0;
    let matched = Scenario::paper_default().truncated(t).unwrap();
    let (m_out, m_rec) = go(&matched, Mode::Kf);
    assert_eq!(m_out.sightings_used, 180);
    for name in ALL {
        let sc = load(name).truncated(t).unwrap();
        let (o, rec) = go(&sc, Mode::Kf);
        assert_ne!(rec[60].pos_err_ned_m, m_rec[60].pos_err_ned_m, "{name}");
        match name {
            "limited_view" => {
                assert!(o.sightings_used < 180, "{name}: {}", o.sightings_used);
                assert!(rec[1..].iter().all(|s| s.nis_dof <= 6));
                assert!(rec[1..].iter().any(|s| s.nis_dof < 6));
            }
            "outliers" => {
                assert!(o.sightings_rejected >= 1, "{name}");
                assert_eq!(o.sightings_used + o.sightings_rejected, 180);
            }
            _ => {
                assert_eq!(o.sightings_used, 180, "{name}");
                assert_eq!(o.sightings_rejected, 0, "{name}");
            }
        }
    }
}

#[test]
fn invalid_mismatch_values_name_the_field() {
    let text = std::fs::read_to_string(format!(
        "{}/../../configs/mismatch/latency.toml",
        env!("CARGO_MANIFEST_DIR")
    ))
    .unwrap();
    let bad = text.replace("latency_s = 0.05", "latency_s = 0.005");
    let e = Scenario::from_toml_str(&bad).unwrap_err().to_string();
    assert!(e.contains("mismatch.latency_s"), "{e}");
    let bad = text.replace(
        "latency_s = 0.05",
        "latency_s = 0.05\noutlier_fraction = 2.0",
    );
    let e = Scenario::from_toml_str(&bad).unwrap_err().to_string();
    assert!(e.contains("mismatch.outlier_fraction"), "{e}");
    let bad = text.replace("latency_s = 0.05", "latncy_s = 0.05");
    let e = Scenario::from_toml_str(&bad).unwrap_err().to_string();
    assert!(e.contains("latncy_s") && e.contains("mismatch"), "{e}");
}
