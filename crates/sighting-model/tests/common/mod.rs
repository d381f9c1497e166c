//! Shared helpers for the integration tests: geometries and central finite differences of the
//! nonlinear model.
#![allow(dead_code)]

use nalgebra::{Rotation3, SMatrix, Vector3};
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use sighting_model::{
    Geodetic, Landmark, NavPose, POS_ERR_COL, PSI_COL, STATE_DIM, sighting_offset_m,
    true_pose_from_errors,
};

/// Paper §6 start point (−23°12′, −45°52′, 6000 m).
pub fn paper_start() -> Geodetic {
    Geodetic::from_deg(-(23.0 + 12.0 / 60.0), -(45.0 + 52.0 / 60.0), 6000.0)
}

/// Finite-difference steps: δp in metres, ψ in radians.
pub const STEP_POS_M: f64 = 0.5;
pub const STEP_PSI_RAD: f64 = 1e-5;

/// Central finite differences of `sighting_offset_m` with respect to δp and ψ at zero error
/// (computed pose fixed, truth = computed − error per the contract). Columns other than δp and ψ
/// are left at zero: the nonlinear model takes no velocity or sensor-bias input.
pub fn fd_jacobian(computed: &NavPose, landmark: &Landmark) -> SMatrix<f64, 2, STATE_DIM> {
    fd_jacobian_with(computed, landmark, |c, dp, psi| {
        true_pose_from_errors(c, dp, psi)
    })
}

/// As [`fd_jacobian`] with a caller-supplied truth constructor (used for the φ-angle variant).
pub fn fd_jacobian_with(
    computed: &NavPose,
    landmark: &Landmark,
    truth_of: impl Fn(&NavPose, &Vector3<f64>, &Vector3<f64>) -> NavPose,
) -> SMatrix<f64, 2, STATE_DIM> {
    let mut j = SMatrix::<f64, 2, STATE_DIM>::zeros();
    for k in 0..3 {
        for (col0, step) in [(POS_ERR_COL, STEP_POS_M), (PSI_COL, STEP_PSI_RAD)] {
            let mut e = Vector3::zeros();
            e[k] = step;
            let (plus, minus) = if col0 == POS_ERR_COL {
                (
                    truth_of(computed, &e, &Vector3::zeros()),
                    truth_of(computed, &-e, &Vector3::zeros()),
                )
            } else {
                (
                    truth_of(computed, &Vector3::zeros(), &e),
                    truth_of(computed, &Vector3::zeros(), &-e),
                )
            };
            let zp = sighting_offset_m(&plus, computed, landmark).unwrap();
            let zm = sighting_offset_m(&minus, computed, landmark).unwrap();
            j.set_column(col0 + k, &((zp - zm) / (2.0 * step)));
        }
    }
    j
}

/// A random computed pose and a landmark 1–40 km away horizontally, 0–2 km high, vehicle at
/// 300–10 000 m, any attitude.
pub fn random_geometry(rng: &mut ChaCha8Rng, id: usize) -> (NavPose, Landmark) {
    let lat = rng.random_range(-70.0..70.0_f64);
    let lon = rng.random_range(-180.0..180.0_f64);
    let alt = rng.random_range(300.0..10_000.0_f64);
    let position = Geodetic::from_deg(lat, lon, alt);
    let c_b_n = Rotation3::from_euler_angles(
        rng.random_range(-3.1..3.1),
        rng.random_range(-1.5..1.5),
        rng.random_range(-3.1..3.1),
    );
    let dist_m = rng.random_range(1_000.0..40_000.0_f64);
    let bearing = rng.random_range(0.0..std::f64::consts::TAU);
    let r = 6.371e6;
    let l_lat = lat + (dist_m * bearing.cos() / r).to_degrees();
    let l_lon = lon + (dist_m * bearing.sin() / (r * lat.to_radians().cos())).to_degrees();
    let landmark = Landmark::from_deg(id, l_lat, l_lon, rng.random_range(0.0..2_000.0)).unwrap();
    (NavPose { position, c_b_n }, landmark)
}

/// Level flight at the paper's start point, heading 30°.
pub fn paper_pose() -> NavPose {
    NavPose {
        position: paper_start(),
        c_b_n: Rotation3::from_euler_angles(0.02, -0.01, 0.52),
    }
}
