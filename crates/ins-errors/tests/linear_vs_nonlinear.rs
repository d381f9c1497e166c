//! The linear error model (Φ from A along the computed trajectory) against the nonlinear INS.
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use ins_errors::config::TrajectoryConfig;
use ins_errors::error_model::{Transition, error_state, inject_errors, system_matrix};
use ins_errors::strapdown::Strapdown;
use ins_errors::trajectory::Trajectory;
use nalgebra::{SVector, Vector3};

const MG: f64 = 9.806_65e-3;
const DEGPH: f64 = std::f64::consts::PI / 180.0 / 3600.0;

fn names(i: usize) -> &'static str {
    [
        "dpN", "dpE", "dpD", "dvN", "dvE", "dvD", "psiN", "psiE", "psiD",
    ][i]
}

/// Runs both models from `t_start_s` for `dur_s`; returns (nonlinear, linear) error states at
/// the checkpoints.
fn run(
    t_start_s: f64,
    dur_s: f64,
    dp: Vector3<f64>,
    dv: Vector3<f64>,
    psi: Vector3<f64>,
    bias: Vector3<f64>,
    drift: Vector3<f64>,
) -> Vec<(f64, SVector<f64, 9>, SVector<f64, 9>)> {
    let tr = Trajectory::new(&TrajectoryConfig::paper()).unwrap();
    let ts = tr.step_s();
    let k0 = (t_start_s / ts).round() as usize;
    let n = (dur_s / ts).round() as usize;
    let mut it = tr.samples().skip(k0);
    let s0 = it.next().unwrap();
    let truth0 = s0.nav_state();
    let mut ins = Strapdown::new(inject_errors(&truth0, &dp, &dv, &psi), ts).unwrap();
    let mut x = SVector::<f64, 15>::zeros();
    x.fixed_rows_mut::<3>(0).copy_from(&dp);
    x.fixed_rows_mut::<3>(3).copy_from(&dv);
    x.fixed_rows_mut::<3>(6).copy_from(&psi);
    x.fixed_rows_mut::<3>(9).copy_from(&bias);
    x.fixed_rows_mut::<3>(12).copy_from(&drift);
    let mut imu = (s0.specific_force_body_mps2, s0.ang_rate_ib_body_radps);
    let mut out = Vec::new();
    for (k, s) in it.take(n).enumerate() {
        ins.step(&(imu.0 + bias), &(imu.1 + drift));
        // A from the INS's own outputs after the step (f_n of the step's midpoint).
        let a = system_matrix(&ins.linearization_point());
        let phi = Transition::series(&a, ts).to_dense();
        x = phi * x;
        imu = (s.specific_force_body_mps2, s.ang_rate_ib_body_radps);
        if (k + 1) % (n / 4) == 0 {
            let truth = s.nav_state();
            let e = error_state(&truth, ins.state());
            out.push((s.t_s, e, x.fixed_rows::<9>(0).into_owned()));
        }
    }
    out
}

/// Component-wise check: every component whose nonlinear value exceeds 20 % of its group's
/// (δp, δv, ψ) largest value must agree within `rel` (relative); the smaller ones (crossing
/// zero, "~0") within `rel`/3 × that group's largest value.
fn check(res: &[(f64, SVector<f64, 9>, SVector<f64, 9>)], rel: f64) {
    let mut failures = Vec::new();
    for (t, nl, lin) in res {
        for g in 0..3 {
            let scale = (0..3).map(|i| nl[3 * g + i].abs()).fold(0.0, f64::max);
            for i in 3 * g..3 * g + 3 {
                let err = (lin[i] - nl[i]).abs();
                let (ok, what) = if nl[i].abs() > 0.2 * scale {
                    (err <= rel * nl[i].abs(), "relative")
                } else {
                    (err <= rel / 3.0 * scale, "vs group scale")
                };
                println!(
                    "t={t:6.1} {:5} nonlinear {:+.6e} linear {:+.6e} rel {:.2e}",
                    names(i),
                    nl[i],
                    lin[i],
                    err / nl[i].abs().max(1e-300)
                );
                if !ok {
                    failures.push(format!(
                        "t={t} {} ({what}): nonlinear {} linear {}",
                        names(i),
                        nl[i],
                        lin[i]
                    ));
                }
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

fn run_scaled(scale: f64) -> Vec<(f64, SVector<f64, 9>, SVector<f64, 9>)> {
    run(
        30.0,
        100.0,
        Vector3::new(20.0, -15.0, 5.0) * scale,
        Vector3::new(0.2, -0.1, 0.05) * scale,
        Vector3::new(0.5e-3, -0.4e-3, 1.0e-3) * scale,
        Vector3::new(3.0, -2.0, 2.5) * MG * scale,
        Vector3::new(2.0, -1.5, 1.0) * DEGPH * scale,
    )
}

/// Initial errors and sensor errors of the size the paper's filter sees, propagated for 100 s
/// through the first manoeuvres (straight, 40° turn, acceleration): the linear model agrees with
/// the nonlinear INS within 3 % on every component (measured: ≤ 0.5 % except where a component
/// crosses zero).
#[test]
fn linear_model_tracks_nonlinear_ins_through_manoeuvres() {
    check(&run_scaled(1.0), 0.03);
}

/// The remaining mismatch is second order (products such as ψ × C̃∇ and ψ²f): halving every
/// error divides the absolute mismatch by ≈ 4, i.e. halves the relative mismatch, in each group
/// (measured ratios 2.08, 2.06, 2.17). A missing or wrong first-order term would leave the
/// relative mismatch unchanged (ratio ≈ 1).
#[test]
fn mismatch_is_quadratic_in_error_size() {
    let mismatch = |res: &[(f64, SVector<f64, 9>, SVector<f64, 9>)], g: usize| -> f64 {
        res.iter()
            .map(|(_, nl, lin)| {
                (lin - nl).fixed_rows::<3>(3 * g).norm() / nl.fixed_rows::<3>(3 * g).norm()
            })
            .fold(0.0, f64::max)
    };
    let full = run_scaled(1.0);
    let half = run_scaled(0.5);
    for g in 0..3 {
        let ratio = mismatch(&full, g) / mismatch(&half, g);
        println!(
            "group {g}: relative mismatch {:.3e} (full) / {:.3e} (half) = {ratio:.2}",
            mismatch(&full, g),
            mismatch(&half, g)
        );
        // Relative mismatch ∝ error size → ratio 2 for a purely second-order residual.
        assert!((1.7..2.3).contains(&ratio), "group {g}: ratio {ratio}");
    }
}

/// Sensor errors only (no initial error), 120 s in the turn-and-climb segments: same check.
#[test]
fn linear_model_tracks_sensor_error_response() {
    let res = run(
        150.0,
        120.0,
        Vector3::zeros(),
        Vector3::zeros(),
        Vector3::zeros(),
        Vector3::new(-2.0, 3.0, -3.0) * MG,
        Vector3::new(-1.0, 2.0, 2.0) * DEGPH,
    );
    check(&res, 0.02);
}
