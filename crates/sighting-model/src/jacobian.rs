//! The analytic measurement matrix H (Jacobian of (w, h) with respect to the 15-state error
//! vector of the shared contract), evaluated at the computed position.

use ins_errors::earth::{Geodetic, geodetic_to_ecef, ned_from_ecef, skew};
use nalgebra::{Matrix3, SMatrix, Vector3};

use crate::SightingError;
use crate::model::{Landmark, LineOfSight, los_from_ecef};

/// Length of the error state (δp, δv, ψ, ∇, ε).
pub const STATE_DIM: usize = 15;
/// First column of the position error δp (NED, metres) in the error state.
pub const POS_ERR_COL: usize = 0;
/// First column of the psi-angle misalignment ψ (radians) in the error state.
pub const PSI_COL: usize = 6;
/// Measurement rows per landmark: (w, h).
pub const ROWS_PER_LANDMARK: usize = 2;

/// The 2×15 block of one landmark from its computed line of sight:
/// H = S C_cam^cᵀ [ I₃ | 0 | [r̃×] | 0 | 0 ], S = first two rows.
fn block_from_los(los: &LineOfSight) -> SMatrix<f64, 2, STATE_DIM> {
    let c_cam_c_t = los.camera_axes_ned().transpose();
    let h_psi: Matrix3<f64> = c_cam_c_t * skew(&los.los_ned_m);
    let mut h = SMatrix::<f64, 2, STATE_DIM>::zeros();
    h.fixed_view_mut::<2, 3>(0, POS_ERR_COL)
        .copy_from(&c_cam_c_t.fixed_rows::<2>(0));
    h.fixed_view_mut::<2, 3>(0, PSI_COL)
        .copy_from(&h_psi.fixed_rows::<2>(0));
    h
}

/// Measurement matrix of one landmark (rows w, h; 15 columns in the contract's order), at the
/// computed position `computed`. Nonzero only in the δp columns 0..3 (m/m) and the ψ columns
/// 6..9 (m/rad):
///
/// ```text
/// row w: [ e_wᵀ   0   −ρ e_hᵀ   0   0 ]
/// row h: [ e_hᵀ   0    ρ e_wᵀ   0   0 ]
/// ```
///
/// (e_w, e_h camera axes and ρ slant range of the computed line of sight). It does not depend
/// on the attitude, because the gimbal holds the image w axis horizontal in the computed NED
/// frame.
///
/// # Errors
/// The errors of [`crate::line_of_sight`] (degenerate or vertical line of sight, NaN input).
pub fn sighting_jacobian(
    computed: &Geodetic,
    landmark: &Landmark,
) -> Result<SMatrix<f64, 2, STATE_DIM>, SightingError> {
    let c_e_c = ned_from_ecef(computed.lat_rad, computed.lon_rad);
    let los = los_from_ecef(landmark, &c_e_c, &geodetic_to_ecef(computed))?;
    Ok(block_from_los(&los))
}

/// Measurement matrix of three landmarks, rows (w₀, h₀, w₁, h₁, w₂, h₂), matching
/// [`crate::sighting_offsets3_m`]. Fixed size, no allocation.
///
/// # Errors
/// As [`sighting_jacobian`], for the first landmark that fails.
pub fn sighting_jacobian3(
    computed: &Geodetic,
    landmarks: &[Landmark; 3],
) -> Result<SMatrix<f64, 6, STATE_DIM>, SightingError> {
    let c_e_c = ned_from_ecef(computed.lat_rad, computed.lon_rad);
    let x_c: Vector3<f64> = geodetic_to_ecef(computed);
    let mut h = SMatrix::<f64, 6, STATE_DIM>::zeros();
    for (i, landmark) in landmarks.iter().enumerate() {
        let los = los_from_ecef(landmark, &c_e_c, &x_c)?;
        h.fixed_view_mut::<2, STATE_DIM>(ROWS_PER_LANDMARK * i, 0)
            .copy_from(&block_from_los(&los));
    }
    Ok(h)
}
