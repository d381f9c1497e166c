//! Feedback corrections and sensor corrections of the mechanization; input errors.
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use ins_errors::InsError;
use ins_errors::config::TrajectoryConfig;
use ins_errors::earth::Geodetic;
use ins_errors::error_model::{error_state, inject_errors};
use ins_errors::strapdown::{NavState, Strapdown};
use ins_errors::trajectory::Trajectory;
use nalgebra::{UnitQuaternion, Vector3};

fn truth_at(k: usize) -> (Trajectory, NavState) {
    let tr = Trajectory::new(&TrajectoryConfig::paper()).unwrap();
    let s = tr.samples().nth(k).unwrap();
    (tr, s.nav_state())
}

/// Correcting by the exact errors (contract conventions) returns the truth up to second-order
/// terms: position ≈ |δθ|·|δp| (δp is defined at the truth's NED, the correction applied at the
/// computed one, plus the curvature term |δp|²/2R) ≈ 3 mm (measured 3.3 mm); velocity and
/// attitude are restored exactly (measured ≤ 7e-15).
#[test]
fn apply_correction_with_exact_errors_restores_truth() {
    let (tr, truth) = truth_at(13_000);
    let dp = Vector3::new(120.0, -80.0, 15.0);
    let dv = Vector3::new(0.5, -0.3, 0.1);
    let psi = Vector3::new(2e-3, -1e-3, 5e-3);
    let mut ins = Strapdown::new(inject_errors(&truth, &dp, &dv, &psi), tr.step_s()).unwrap();
    let before = error_state(&truth, ins.state());
    ins.apply_correction(&dp, &dv, &psi);
    let after = error_state(&truth, ins.state());
    println!("before {before:?}\nafter {after:?}");
    assert!(
        after.fixed_rows::<3>(0).norm() < 5e-3,
        "position residual {}",
        after.fixed_rows::<3>(0).norm()
    );
    assert!(
        after.fixed_rows::<3>(3).norm() < 1e-10,
        "velocity residual {}",
        after.fixed_rows::<3>(3).norm()
    );
    assert!(
        after.fixed_rows::<3>(6).norm() < 1e-10,
        "attitude residual {}",
        after.fixed_rows::<3>(6).norm()
    );
    // A wrong sign anywhere would double the error instead.
    assert!(before.norm() > 100.0);
}

/// Biased sensors with the biases set as sensor corrections behave like perfect sensors.
#[test]
fn sensor_corrections_are_subtracted_from_measurements() {
    let tr = Trajectory::new(&TrajectoryConfig::paper()).unwrap();
    let bias = Vector3::new(0.03, -0.02, 0.025);
    let drift = Vector3::new(1e-5, -2e-5, 5e-6);
    let run = |corrected: bool| {
        let mut it = tr.samples().take(6001);
        let s0 = it.next().unwrap();
        let mut ins = Strapdown::new(s0.nav_state(), tr.step_s()).unwrap();
        if corrected {
            // Split into set + add to exercise both entry points.
            ins.set_sensor_corrections(&(0.5 * bias), &(0.5 * drift));
            ins.add_sensor_corrections(&(0.5 * bias), &(0.5 * drift));
        }
        let mut imu = (s0.specific_force_body_mps2, s0.ang_rate_ib_body_radps);
        let mut last = None;
        for s in it {
            ins.step(&(imu.0 + bias), &(imu.1 + drift));
            imu = (s.specific_force_body_mps2, s.ang_rate_ib_body_radps);
            last = Some(s.nav_state());
        }
        error_state(&last.unwrap(), ins.state()).norm()
    };
    let corrected = run(true);
    let raw = run(false);
    println!("60 s error norm: corrected {corrected:.3e}, uncorrected {raw:.3e}");
    assert!(corrected < 1e-4, "{corrected}");
    assert!(raw > 10.0, "{raw}");
}

#[test]
fn new_rejects_bad_step_and_state() {
    let (_, truth) = truth_at(0);
    assert!(matches!(
        Strapdown::new(truth, 0.0),
        Err(InsError::InvalidArgument { arg: "step_s", .. })
    ));
    let bad = NavState {
        pos: Geodetic {
            lat_rad: f64::NAN,
            ..truth.pos
        },
        ..truth
    };
    assert!(matches!(
        Strapdown::new(bad, 0.01),
        Err(InsError::InvalidArgument { arg: "initial", .. })
    ));
    let pole = NavState {
        pos: Geodetic::from_deg(90.0, 0.0, 0.0),
        vel_ned_mps: Vector3::zeros(),
        att_b_to_n: UnitQuaternion::identity(),
    };
    assert!(Strapdown::new(pole, 0.01).is_err());
}
