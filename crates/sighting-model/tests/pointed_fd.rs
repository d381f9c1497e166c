//! Pointed sightings: the conversion of a measured direction into offsets, differentiated by
//! central finite differences of the nonlinear model, against the analytic H; and the round trips
//! offsets → direction → offsets and truth → direction → offsets.
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

mod common;

use common::{STEP_POS_M, STEP_PSI_RAD, paper_pose, random_geometry};
use ins_errors::earth::radii_of_curvature_m;
use nalgebra::{SMatrix, Vector2, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use sighting_model::{
    Landmark, LosFrame, NavPose, POS_ERR_COL, PSI_COL, STATE_DIM, jacobian_for_frame,
    line_of_sight, los_from_offsets, los_from_truth, offsets_from_los, paper_landmarks,
    true_pose_from_errors,
};

/// Offsets a filter at `computed` derives from the direction a device at the truth (computed
/// minus the errors) measured, noise-free.
fn z_of(
    computed: &NavPose,
    lm: &Landmark,
    frame: LosFrame,
    dp: &Vector3<f64>,
    psi: &Vector3<f64>,
) -> Vector2<f64> {
    let truth = true_pose_from_errors(computed, dp, psi);
    let u = los_from_truth(&truth, lm, frame, &Vector2::zeros()).unwrap();
    offsets_from_los(computed, lm, frame, &u).unwrap()
}

fn fd(computed: &NavPose, lm: &Landmark, frame: LosFrame) -> SMatrix<f64, 2, STATE_DIM> {
    let mut j = SMatrix::<f64, 2, STATE_DIM>::zeros();
    for k in 0..3 {
        let mut e = Vector3::zeros();
        e[k] = STEP_POS_M;
        let zp = z_of(computed, lm, frame, &e, &Vector3::zeros());
        let zm = z_of(computed, lm, frame, &-e, &Vector3::zeros());
        j.set_column(POS_ERR_COL + k, &((zp - zm) / (2.0 * STEP_POS_M)));
        let mut e = Vector3::zeros();
        e[k] = STEP_PSI_RAD;
        let zp = z_of(computed, lm, frame, &Vector3::zeros(), &e);
        let zm = z_of(computed, lm, frame, &Vector3::zeros(), &-e);
        j.set_column(PSI_COL + k, &((zp - zm) / (2.0 * STEP_PSI_RAD)));
    }
    j
}

/// Worst |H − FD| / (rel |FD| + floor) over the δp and ψ columns.
/// `floor_pos` is the absolute floor of the position columns (m/m; each row has unit norm).
fn worst(h: &SMatrix<f64, 2, STATE_DIM>, fd: &SMatrix<f64, 2, STATE_DIM>, floor_pos: f64) -> f64 {
    let mut worst: f64 = 0.0;
    for r in 0..2 {
        for c in (POS_ERR_COL..POS_ERR_COL + 3).chain(PSI_COL..PSI_COL + 3) {
            let (rel, floor) = if c < PSI_COL {
                (1e-6, floor_pos)
            } else {
                (1e-6, 1e-3)
            };
            worst = worst.max((h[(r, c)] - fd[(r, c)]).abs() / (rel * fd[(r, c)].abs() + floor));
        }
    }
    worst
}

#[test]
fn body_direction_h_matches_central_differences() {
    let mut rng = ChaCha8Rng::seed_from_u64(0x0090_17ed);
    for i in 0..200 {
        let (computed, lm) = random_geometry(&mut rng, i);
        let h = jacobian_for_frame(&computed, &lm, LosFrame::Body).unwrap();
        let d = fd(&computed, &lm, LosFrame::Body);
        let w = worst(&h, &d, 1e-7);
        assert!(w <= 1.0, "geometry {i}: worst {w}\nH = {h}\nFD = {d}");
    }
    let computed = paper_pose();
    for lm in paper_landmarks() {
        let h = jacobian_for_frame(&computed, &lm, LosFrame::Body).unwrap();
        assert!(worst(&h, &fd(&computed, &lm, LosFrame::Body), 1e-7) <= 1.0);
    }
}

#[test]
fn local_level_direction_h_has_no_attitude_columns_and_matches_differences() {
    let mut rng = ChaCha8Rng::seed_from_u64(0x1e7e1);
    for i in 0..200 {
        let (computed, lm) = random_geometry(&mut rng, i);
        let h = jacobian_for_frame(&computed, &lm, LosFrame::LocalLevel).unwrap();
        assert!(h.fixed_view::<2, 3>(0, PSI_COL).iter().all(|v| *v == 0.0));
        let d = fd(&computed, &lm, LosFrame::LocalLevel);
        // The level frame of the device (at the truth) and the filter's (at the computed
        // position) differ by the tilt δθ ≈ δp/R, which H leaves out: an error of about
        // ρ(1 + |tan φ|)/R of each (unit-norm) row in the position columns (documented in `pointed`).
        let range = line_of_sight(&computed.position, &lm).unwrap().range_m;
        let (rn, _) = radii_of_curvature_m(computed.position.lat_rad);
        // (δθ also has a down component δp_E tan φ / R.)
        let tilt = 2.0 * range / rn * (1.0 + computed.position.lat_rad.tan().abs());
        let w = worst(&h, &d, tilt + 1e-7);
        assert!(w <= 1.0, "geometry {i}: worst {w}\nH = {h}\nFD = {d}");
        // and the FD ψ columns are zero: the attitude does not enter.
        assert!(
            d.fixed_view::<2, 3>(0, PSI_COL)
                .iter()
                .all(|v| v.abs() < 1e-6)
        );
    }
}

#[test]
fn offsets_round_trip_through_a_body_direction() {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    for i in 0..100 {
        let (pose, lm) = random_geometry(&mut rng, i);
        let z = Vector2::new(
            rng.random_range(-500.0..500.0),
            rng.random_range(-500.0..500.0),
        );
        let u = los_from_offsets(&pose, &lm, &z).unwrap();
        assert!((u.norm() - 1.0).abs() < 1e-12);
        let back = offsets_from_los(&pose, &lm, LosFrame::Body, &u).unwrap();
        assert!(
            (back - z).norm() < 1e-9 * (1.0 + z.norm()),
            "{i}: {z} -> {back}"
        );
    }
}

#[test]
fn a_filter_at_the_truth_recovers_the_synthetic_noise() {
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    for i in 0..100 {
        let (truth, lm) = random_geometry(&mut rng, i);
        let noise = Vector2::new(rng.random_range(-3.0..3.0), rng.random_range(-3.0..3.0));
        for frame in [LosFrame::Body, LosFrame::LocalLevel] {
            let u = los_from_truth(&truth, &lm, frame, &noise).unwrap();
            let z = offsets_from_los(&truth, &lm, frame, &u).unwrap();
            assert!((z - noise).norm() < 1e-8, "{i} {frame:?}: {noise} -> {z}");
        }
    }
}

#[test]
fn bad_directions_are_errors() {
    let pose = paper_pose();
    let lm = paper_landmarks()[0];
    for u in [Vector3::zeros(), Vector3::new(f64::NAN, 0.0, 1.0)] {
        assert!(offsets_from_los(&pose, &lm, LosFrame::Body, &u).is_err());
    }
    // The direction away from the landmark is behind the camera.
    let away = -los_from_truth(&pose, &lm, LosFrame::LocalLevel, &Vector2::zeros()).unwrap();
    let e = offsets_from_los(&pose, &lm, LosFrame::LocalLevel, &away).unwrap_err();
    assert!(
        matches!(e, sighting_model::SightingError::BehindCamera { .. }),
        "{e}"
    );
    assert_eq!(LosFrame::parse("ned"), Some(LosFrame::LocalLevel));
    assert_eq!(
        LosFrame::parse(LosFrame::Body.as_str()),
        Some(LosFrame::Body)
    );
    assert_eq!(LosFrame::parse("enu"), None);
}
