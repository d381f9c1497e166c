//! The replay's filter file: datasheet units to the filter's densities (the paper preset gives
//! the Monte Carlo's tuned KF), the discrete Q by Van Loan against its closed form and the
//! filter's discretisation against Van Loan, and located errors for bad files.
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use ins_errors::error_model::{Mat15, discretize_fast, van_loan};
use ins_sim::filter_file::FilterFile;
use ins_sim::{Mode, Scenario, SimError};
use nalgebra::SMatrix;

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs().max(1e-300)
}

#[test]
fn the_paper_preset_is_the_monte_carlos_tuned_kf() {
    let file = FilterFile::preset("paper").unwrap();
    let ours = file.filter_config(Mode::Kf, 0.01, 0.0).unwrap();
    let mc = Scenario::paper_default().online_filter_config(Mode::Kf);
    let (a, b) = (ours.process_noise.as_array(), mc.process_noise.as_array());
    for k in 0..4 {
        assert!(
            rel(a[k], b[k]) < 1e-12 || (a[k] == 0.0 && b[k] == 0.0),
            "{k}: {a:?} vs {b:?}"
        );
    }
    let (a, b) = (ours.p0_sigma.variances(), mc.p0_sigma.variances());
    for k in 0..5 {
        assert!(rel(a[k], b[k]) < 1e-12, "{k}: {a:?} vs {b:?}");
    }
    assert!(rel(ours.r_var_m2, mc.r_var_m2) < 1e-12);
    assert_eq!(ours.open_loop_until_s, mc.open_loop_until_s);
    assert_eq!(ours.update_period_s, mc.update_period_s);
    assert_eq!(ours.phi_subintervals, mc.phi_subintervals);
    assert_eq!(ours.gate_probability, mc.gate_probability);
}

/// The chain δṗ = δv, δv̇ = ∇ + w_a, ψ̇ = w_g, ∇̇ = w_∇, ε̇ = w_ε (level, at rest, C = I).
fn chain() -> Mat15 {
    let mut a = Mat15::zeros();
    for i in 0..3 {
        a[(i, 3 + i)] = 1.0;
        a[(3 + i, 9 + i)] = 1.0;
    }
    a
}

fn w_of(q: [f64; 4]) -> Mat15 {
    let mut w = Mat15::zeros();
    for i in 0..3 {
        w[(3 + i, 3 + i)] = q[0];
        w[(6 + i, 6 + i)] = q[1];
        w[(9 + i, 9 + i)] = q[2];
        w[(12 + i, 12 + i)] = q[3];
    }
    w
}

#[test]
fn van_loan_matches_the_closed_form_and_the_filter_matches_van_loan() {
    for name in ["mems", "paper"] {
        let q = FilterFile::preset(name).unwrap().process_noise().as_array();
        let (qa, qg, qb, qe) = (q[0], q[1], q[2], q[3]);
        let a = chain();
        // G = the rows 3..15 of the identity, Q_c = diag of the four densities.
        let mut g = SMatrix::<f64, 15, 12>::zeros();
        let mut qc = SMatrix::<f64, 12, 12>::zeros();
        for i in 0..12 {
            g[(3 + i, i)] = 1.0;
            qc[(i, i)] = q[i / 3];
        }
        for t in [0.01, 0.5, 1.0] {
            let (_, vl) = van_loan(&a, &g, &qc, t).unwrap();
            let closed = [
                ((0, 0), qa * t.powi(3) / 3.0 + qb * t.powi(5) / 20.0),
                ((0, 3), qa * t * t / 2.0 + qb * t.powi(4) / 8.0),
                ((0, 9), qb * t.powi(3) / 6.0),
                ((3, 3), qa * t + qb * t.powi(3) / 3.0),
                ((3, 9), qb * t * t / 2.0),
                ((9, 9), qb * t),
                ((6, 6), qg * t),
                ((12, 12), qe * t),
            ];
            for ((r, c), want) in closed {
                let tol = 1e-9 * want.abs() + 1e-300;
                assert!(
                    (vl[(r, c)] - want).abs() <= tol,
                    "{name} T={t} Q[{r},{c}] = {} vs {want}",
                    vl[(r, c)]
                );
                assert!((vl[(c, r)] - want).abs() <= tol);
            }
            // What the filter uses: series Φ, Simpson Q (exact for this polynomial chain up
            // to the T⁵ term Simpson integrates to 1/20·(1 + 1/120)).
            let (_, fast) = discretize_fast(&a, &w_of(q), t);
            for r in 0..15 {
                for c in 0..15 {
                    let d = (fast[(r, c)] - vl[(r, c)]).abs();
                    assert!(
                        d <= 1e-2 * vl[(r, c)].abs() + 1e-18,
                        "{name} T={t} [{r},{c}]: {} vs {}",
                        fast[(r, c)],
                        vl[(r, c)]
                    );
                }
            }
        }
    }
}

fn toml_error(text: &str) -> String {
    match FilterFile::from_toml_str(text, "f.toml") {
        Err(e @ SimError::LogToml { .. }) => e.to_string(),
        other => panic!("expected a located TOML error, got {other:?}"),
    }
}

#[test]
fn bad_filter_files_name_the_line_and_the_key() {
    let e = toml_error("[imu]\ngyro_arw_deg_per_rt_h = 1.0\ngyro_arw = 2.0\n");
    assert!(e.contains("f.toml:3"), "{e}");
    assert!(e.contains("gyro_arw"), "{e}");
    let e = toml_error("preset = \"navigation\"\n");
    assert!(
        e.contains("f.toml:1") && e.contains("unknown preset"),
        "{e}"
    );
    let e = toml_error("[sighting]\n\nsigma_m = -1.0\n");
    assert!(
        e.contains("f.toml:3") && e.contains("sighting.sigma_m"),
        "{e}"
    );
    let e = toml_error("[sighting]\ngate_probability = 1.5\n");
    assert!(
        e.contains("f.toml:2") && e.contains("gate_probability"),
        "{e}"
    );
    // An override keeps the rest of the preset.
    let f = FilterFile::from_toml_str("preset = \"paper\"\n[sighting]\nsigma_m = 2.0\n", "f.toml")
        .unwrap();
    assert_eq!(f.sighting_sigma_m, 2.0);
    assert_eq!(f.feedback_from_s, 195.0);
    assert_eq!(
        FilterFile::from_toml_str("", "empty.toml").unwrap(),
        FilterFile::preset("mems").unwrap()
    );
}

/// `nav-app ins --print-config` (issue 54, item 3): the printed settings read back to the same
/// settings, field for field, for both presets, overrides with awkward floats, and the gate
/// override (none written as 0).
#[test]
fn printed_settings_read_back_to_the_same_settings() {
    let over = "preset = \"paper\"\n[imu]\ngyro_arw_deg_per_rt_h = 0.1234567890123456789\n\
                [sighting]\nsigma_m = 1e-7\n[filter]\nfeedback_from_s = 12.5\nakf_window = 7\n\
                [align]\nmax_speed_mps = 3e20\n";
    let cases = [
        FilterFile::preset("mems").unwrap(),
        FilterFile::preset("paper").unwrap(),
        FilterFile::from_toml_str(over, "over.toml").unwrap(),
        FilterFile::preset("mems").unwrap().with_gate(0.0).unwrap(),
        FilterFile::preset("paper")
            .unwrap()
            .with_gate(0.95)
            .unwrap(),
    ];
    for f in cases {
        let text = f.to_toml("test");
        let back = FilterFile::from_toml_str(&text, "printed.toml").unwrap();
        assert_eq!(back, f, "{text}");
        assert!(
            text.contains("feedback_from_s") && text.contains(", s"),
            "{text}"
        );
    }
    assert_eq!(
        FilterFile::preset("mems")
            .unwrap()
            .with_gate(0.0)
            .unwrap()
            .gate_probability,
        None
    );
    let e = FilterFile::preset("mems")
        .unwrap()
        .with_gate(1.5)
        .unwrap_err();
    assert!(e.to_string().contains("gate"), "{e}");
}
