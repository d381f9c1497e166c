//! Interval ↔ per-step process noise helpers against the closed-form Van Loan discretisation.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used)]

mod common;

use akf::AkfError;
use akf::interval::{
    InverseOptions, accumulate_interval, accumulate_interval_const, per_step_q_exact,
    per_step_q_exact_const, per_step_q_uniform,
};
use common::*;
use nalgebra::SMatrix;

#[test]
fn accumulated_per_step_noise_equals_the_closed_form_over_the_interval() {
    // Exact white-acceleration discretisation composes: 100 steps of 0.01 s ≡ one step of 1 s.
    let (phi, qd) = cv_model(0.01, 0.7);
    let (phi_t, q_t) = accumulate_interval_const(&phi, &qd, 100).unwrap();
    let (phi_ref, q_ref) = cv_model(1.0, 0.7);
    assert!((phi_t - phi_ref).norm() < 1e-13);
    assert!((q_t - q_ref).norm() < 1e-12 * q_ref.norm());
    // Same through the time-varying entry point.
    let steps = vec![phi; 100];
    let (phi_v, q_v) = accumulate_interval(&steps, &qd).unwrap();
    assert!((phi_v - phi_t).norm() < 1e-15 && (q_v - q_t).norm() < 1e-15);
}

#[test]
fn exact_inverse_recovers_the_per_step_noise() {
    let (phi, qd) = cv_model(0.01, 0.7);
    let (_, q_t) = accumulate_interval_const(&phi, &qd, 100).unwrap();
    let back = per_step_q_exact_const(&q_t, &phi, 100, InverseOptions::default()).unwrap();
    assert!((back - qd).norm() < 1e-10 * qd.norm(), "{back} vs {qd}");

    // 15 states, time-varying near-identity steps (INS-like: 100 steps of small dynamics).
    let mut rng = rng(501);
    let steps: Vec<SMatrix<f64, 15, 15>> = (0..100)
        .map(|_| SMatrix::identity() + uniform_mat::<15, 15>(&mut rng) * 0.005)
        .collect();
    let qd15 = random_spd::<15>(&mut rng, 0.01) * 1e-4;
    let (_, q_t15) = accumulate_interval(&steps, &qd15).unwrap();
    let back15 = per_step_q_exact(&q_t15, &steps, InverseOptions::default()).unwrap();
    assert!((back15 - qd15).norm() < 1e-9 * qd15.norm());
}

#[test]
fn uniform_split_is_exact_for_identity_dynamics_only() {
    let mut rng = rng(502);
    let q_t = random_spd::<4>(&mut rng, 0.1);
    let (_, acc) = accumulate_interval_const(
        &SMatrix::<f64, 4, 4>::identity(),
        &per_step_q_uniform(&q_t, 10).unwrap(),
        10,
    )
    .unwrap();
    assert!((acc - q_t).norm() < 1e-13 * q_t.norm());
    // For the CV model the velocity entry is still right (it accumulates linearly) but the
    // position entry is 10⁴× too large: Q_T11 = qT³/3 vs Q_d11 = q dt³/3 with T = 100 dt.
    let (phi, qd) = cv_model(0.01, 0.7);
    let (_, q_t) = accumulate_interval_const(&phi, &qd, 100).unwrap();
    let u = per_step_q_uniform(&q_t, 100).unwrap();
    assert!((u[(1, 1)] - qd[(1, 1)]).abs() < 1e-12);
    assert!((u[(0, 0)] / qd[(0, 0)] - 1e4).abs() < 1.0);
}

#[test]
fn helpers_reject_bad_arguments_and_report_divergence() {
    let (phi, qd) = cv_model(0.01, 0.7);
    assert!(matches!(
        per_step_q_uniform(&qd, 0),
        Err(AkfError::InvalidParameter {
            field: "n_steps",
            ..
        })
    ));
    assert!(matches!(
        accumulate_interval::<2>(&[], &qd),
        Err(AkfError::InvalidParameter {
            field: "n_steps",
            ..
        })
    ));
    let mut bad = phi;
    bad[(0, 1)] = f64::NAN;
    assert!(matches!(
        per_step_q_exact_const(&qd, &bad, 10, InverseOptions::default()),
        Err(AkfError::NonFinite {
            what: "phi_step",
            ..
        })
    ));
    // Fast growth over the interval (Φ = 1.5 I, 10 steps): L's eigenvalues are far from n and
    // the Richardson iteration cannot converge; it must say so instead of returning garbage.
    let fast = SMatrix::<f64, 2, 2>::identity() * 1.5;
    assert!(matches!(
        per_step_q_exact_const(&qd, &fast, 10, InverseOptions::default()),
        Err(AkfError::NotConverged { .. })
    ));
    assert!(matches!(
        per_step_q_exact_const(
            &qd,
            &phi,
            10,
            InverseOptions {
                max_iterations: 10,
                rel_tolerance: 0.0
            }
        ),
        Err(AkfError::InvalidParameter {
            field: "rel_tolerance",
            ..
        })
    ));
}
