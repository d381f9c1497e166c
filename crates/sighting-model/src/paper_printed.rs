//! The paper's measurement matrix **as printed** (eqs. 15–18), kept for comparison runs only.
//!
//! The filter of this project uses the verified H ([`crate::sighting_jacobian3`]). The
//! functions here evaluate eqs. 15–18 literally so that a simulation can run the paper's
//! filter with the paper's H and show what the printed errors cost (`nav-app`, `[filter]
//! measurement_jacobian = "paper_printed"`). The crate documentation ("Comparison with the
//! printed eqs. 15–18") and `tests/paper_h.rs` establish every difference against the finite
//! differences of the nonlinear model.
//!
//! # What is literal
//!
//! With x, y, z the NED coordinates of the computed line of sight r̃ (landmark minus computed
//! vehicle position: x_L − x₀ = r̃_N, y_L − y₀ = r̃_E, z_L − z₀ = r̃_D), d₀ = √(r̃_N² + r̃_E²),
//! λ and H the computed geodetic latitude and altitude, R_N, R_E the WGS-84 radii:
//!
//! ```text
//! β₀ = atan2(y_L − y₀, x_L − x₀)              (printed tan⁻¹ of the ratio; quadrant kept)
//! α₀ = atan2(z_L − z₀, d₀)                     AS PRINTED: with z down this is the depression
//! d₁₁ = cos β₀ (z_L − z₀)        d₁₂ = sin β₀ (z_L − z₀)
//! d₁₃ = −(cos β₀ (x_L − x₀) + sin β₀ (y_L − y₀))
//! d₂₁ = sin β₀ sin α₀ (z_L − z₀) − cos α₀ (y_L − y₀)
//! d₂₂ = cos α₀ (x_L − x₀) − cos β₀ sin α₀ (z_L − z₀)
//! d_α₂ = cos β₀ cos α₀ (x_L − x₀) + sin β₀ cos α₀ (y_L − y₀) − sin α₀ (z_L − z₀)
//! d_β₁ = −cos β₀ (x_L − x₀) − sin β₀ (y_L − y₀)
//! α_x = −(z_L − z₀)(x_L − x₀) cos² α₀ / d₀³    α_y = −(z_L − z₀)(y_L − y₀) cos² α₀ / d₀³
//! α_z = cos² α₀ / d₀
//! β_x = sin 2β₀ / (2 (x_L − x₀))               β_y = −cos² β₀ / (x_L − x₀)
//!
//! H₂ = [ d_β₁ β_x   d_β₁ β_y   0        ]      H₄ = [ d₁₁  d₁₂  d₁₃ ]
//!      [ d_α₂ α_x   d_α₂ α_y   d_α₂ α_z ]           [ d₂₁  d₂₂  0   ]
//!
//! H₃ = [ d₁₂/(R_N + H)   −(d₁₁ + d₁₃ tan λ)/(R_E + H)   0 ]      AS PRINTED (+d₁₃ tan λ)
//!      [ d₂₂/(R_N + H)   −d₂₁/(R_E + H)                 0 ]
//!
//! H (2×15, this crate's state order) = [ H₂ + H₃ | 0 | H₄ | 0 | 0 ]
//! ```
//!
//! * **α₀ as printed.** Not replaced by the elevation −ε that the other entries need; the h row
//!   of H₂ and H₄ therefore comes out multiplied by cos 2ε (ε = depression): weakened below 45°,
//!   zero at 45°, sign-flipped beyond (the w row is unaffected).
//! * **H₃ as printed**, including its tan λ sign, and kept although the paper's state (and
//!   ours) is the ψ angle, for which H₃ must be dropped. Its entries are ≈ ρ/(R + H) of the δp
//!   entries, so in practice α₀ is the error that matters.
//! * **Sign map.** Eq. 15 multiplies [H₁ | H₄] by diag(1, −1, −1, 1, −1, −1): that maps the
//!   paper's (north, west, up) δp and ψ into NED, the frame in which H₁–H₄ are written
//!   (x north, y east, z down — the frame in which H₂ and H₄ with the elevation reading equal
//!   the verified H exactly). This crate's δp and ψ are already NED, so the map is the
//!   identity here and the blocks go into the δp (0..3) and ψ (6..9) columns unchanged.
//! * **Not literal** (extraction damage repaired, as the crate doc explains): β₀ uses atan2
//!   (the printed ratio loses the quadrant), β_x = sin 2β₀ / (2(x_L − x₀)) with the
//!   parentheses restored; the duplicate definition of d₁₃ is taken as written once (both
//!   definitions agree).
//!
//! β_x and β_y divide by x_L − x₀: a landmark exactly due east or west of the computed
//! position is rejected ([`SightingError::PrintedJacobianSingular`]); close to it the printed
//! product d_β₁ β_x stays finite and accurate (its limit is finite).

use ins_errors::earth::{Geodetic, geodetic_to_ecef, ned_from_ecef, radii_of_curvature_m};
use nalgebra::{Matrix2x3, SMatrix, Vector3};

use crate::SightingError;
use crate::jacobian::{POS_ERR_COL, PSI_COL, ROWS_PER_LANDMARK, STATE_DIM};
use crate::model::{Landmark, LineOfSight, los_from_ecef};

/// Which α₀ to put into eqs. 16–18.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PaperAlphaReading {
    /// α₀ = tan⁻¹((z_L − z₀)/d₀) as printed; with NED z (down) this is the depression ε.
    AsPrinted,
    /// α₀ = tan⁻¹((z₀ − z_L)/d₀) = −ε, the elevation: the reading with which H₂ and H₄ equal the
    /// verified H.
    Elevation,
}

/// The 2×3 blocks of eqs. 15–18 for one landmark, in NED coordinates (see the module doc).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PaperPrintedBlocks {
    /// H₂, the δp part (rows w, h; columns north, east, down), m/m.
    pub h2_pos: Matrix2x3<f64>,
    /// H₃ as printed (frame-tilt term, δp columns, including the printed +d₁₃ tan λ sign), m/m.
    pub h3_tilt: Matrix2x3<f64>,
    /// H₄, the attitude part (rows w, h; columns ψ north, east, down), m/rad.
    pub h4_att: Matrix2x3<f64>,
}

fn blocks_from_los(
    pos: &Geodetic,
    landmark: &Landmark,
    los: &LineOfSight,
    reading: PaperAlphaReading,
) -> Result<PaperPrintedBlocks, SightingError> {
    let r = los.los_ned_m;
    let (dx, dy, dz) = (r.x, r.y, r.z); // x_L − x₀, y_L − y₀, z_L − z₀
    if dx == 0.0 {
        return Err(SightingError::PrintedJacobianSingular {
            landmark: landmark.id(),
            north_offset_m: dx,
        });
    }
    let d0 = los.horizontal_range_m;
    let beta0 = dy.atan2(dx);
    let alpha0 = match reading {
        PaperAlphaReading::AsPrinted => dz.atan2(d0),
        PaperAlphaReading::Elevation => (-dz).atan2(d0),
    };
    let (sb, cb) = beta0.sin_cos();
    let (sa, ca) = alpha0.sin_cos();
    let d11 = cb * dz;
    let d12 = sb * dz;
    let d13 = -(cb * dx + sb * dy);
    let d21 = sb * sa * dz - ca * dy;
    let d22 = ca * dx - cb * sa * dz;
    let d_a2 = cb * ca * dx + sb * ca * dy - sa * dz;
    let d_b1 = -cb * dx - sb * dy;
    let alpha_x = -dz * dx * ca * ca / d0.powi(3);
    let alpha_y = -dz * dy * ca * ca / d0.powi(3);
    let alpha_z = ca * ca / d0;
    let beta_x = (2.0 * beta0).sin() / (2.0 * dx);
    let beta_y = -cb * cb / dx;
    let (r_n, r_e) = radii_of_curvature_m(pos.lat_rad);
    let (rn_h, re_h) = (r_n + pos.alt_m, r_e + pos.alt_m);
    let blocks = PaperPrintedBlocks {
        h2_pos: Matrix2x3::new(
            d_b1 * beta_x,
            d_b1 * beta_y,
            0.0,
            d_a2 * alpha_x,
            d_a2 * alpha_y,
            d_a2 * alpha_z,
        ),
        h3_tilt: Matrix2x3::new(
            d12 / rn_h,
            -(d11 + d13 * pos.lat_rad.tan()) / re_h,
            0.0,
            d22 / rn_h,
            -d21 / re_h,
            0.0,
        ),
        h4_att: Matrix2x3::new(d11, d12, d13, d21, d22, 0.0),
    };
    let finite = blocks.h2_pos.iter().all(|v| v.is_finite())
        && blocks.h3_tilt.iter().all(|v| v.is_finite())
        && blocks.h4_att.iter().all(|v| v.is_finite());
    if !finite {
        return Err(SightingError::NonFinite {
            what: "printed H (eqs. 16-18)",
        });
    }
    Ok(blocks)
}

/// H₂, H₃ (as printed) and H₄ of eqs. 16–18 for one landmark at the computed position, with α₀
/// read as `reading` (module doc: what is literal).
///
/// # Errors
/// The errors of [`crate::line_of_sight`], and
/// [`SightingError::PrintedJacobianSingular`] when the landmark is exactly due east or west
/// (the printed β_x, β_y divide by x_L − x₀ = 0).
pub fn paper_printed_blocks(
    computed: &Geodetic,
    landmark: &Landmark,
    reading: PaperAlphaReading,
) -> Result<PaperPrintedBlocks, SightingError> {
    let c_e_c = ned_from_ecef(computed.lat_rad, computed.lon_rad);
    let los = los_from_ecef(landmark, &c_e_c, &geodetic_to_ecef(computed))?;
    blocks_from_los(computed, landmark, &los, reading)
}

fn place<const R: usize>(
    blocks: &PaperPrintedBlocks,
    h: &mut SMatrix<f64, R, STATE_DIM>,
    row: usize,
) {
    h.fixed_view_mut::<2, 3>(row, POS_ERR_COL)
        .copy_from(&(blocks.h2_pos + blocks.h3_tilt));
    h.fixed_view_mut::<2, 3>(row, PSI_COL)
        .copy_from(&blocks.h4_att);
}

/// The paper's measurement matrix for one landmark **as printed**: [H₂ + H₃ | 0 | H₄ | 0 | 0]
/// with α₀ as printed (the depression) and H₃ as printed, in this crate's NED state order (the
/// printed diag(1, −1, −1, 1, −1, −1) sign map is the identity for NED states; module doc).
/// For comparison runs only: [`crate::sighting_jacobian`] is the verified H.
///
/// ```
/// use sighting_model::{
///     Geodetic, PSI_COL, line_of_sight, paper_landmarks, paper_printed_jacobian,
///     sighting_jacobian,
/// };
/// let pos = Geodetic::from_deg(-23.2, -45.8667, 6000.0);
/// let landmark = paper_landmarks()[1]; // seen steeply, ≈ 74° below the horizon
/// let printed = paper_printed_jacobian(&pos, &landmark)?;
/// let verified = sighting_jacobian(&pos, &landmark)?;
/// let eps = line_of_sight(&pos, &landmark)?.depression_rad();
/// // The h row's attitude entries are the verified ones times cos 2ε (< 0 here: sign flipped).
/// let k = (2.0 * eps).cos();
/// assert!(k < -0.5);
/// let d = printed[(1, PSI_COL)] - k * verified[(1, PSI_COL)];
/// assert!(d.abs() < 1e-6 * verified.amax());
/// # Ok::<(), sighting_model::SightingError>(())
/// ```
///
/// # Errors
/// As [`paper_printed_blocks`].
pub fn paper_printed_jacobian(
    computed: &Geodetic,
    landmark: &Landmark,
) -> Result<SMatrix<f64, 2, STATE_DIM>, SightingError> {
    let blocks = paper_printed_blocks(computed, landmark, PaperAlphaReading::AsPrinted)?;
    let mut h = SMatrix::<f64, 2, STATE_DIM>::zeros();
    place(&blocks, &mut h, 0);
    Ok(h)
}

/// Eq. 15 for one landmark with α₀ read as `reading`: rows (w, h), as one landmark's rows of
/// [`paper_eq15_jacobian3`] (the same operations, so the two agree bit for bit).
///
/// # Errors
/// As [`paper_printed_blocks`].
pub fn paper_eq15_jacobian(
    computed: &Geodetic,
    landmark: &Landmark,
    reading: PaperAlphaReading,
) -> Result<SMatrix<f64, 2, STATE_DIM>, SightingError> {
    let c_e_c = ned_from_ecef(computed.lat_rad, computed.lon_rad);
    let x_c: Vector3<f64> = geodetic_to_ecef(computed);
    let los = los_from_ecef(landmark, &c_e_c, &x_c)?;
    let blocks = blocks_from_los(computed, landmark, &los, reading)?;
    let mut h = SMatrix::<f64, 2, STATE_DIM>::zeros();
    place(&blocks, &mut h, 0);
    Ok(h)
}

/// [`paper_printed_jacobian`] for three landmarks, rows (w₀, h₀, w₁, h₁, w₂, h₂) as
/// [`crate::sighting_jacobian3`]. Fixed size, no allocation.
///
/// # Errors
/// As [`paper_printed_blocks`], for the first landmark that fails.
pub fn paper_printed_jacobian3(
    computed: &Geodetic,
    landmarks: &[Landmark; 3],
) -> Result<SMatrix<f64, 6, STATE_DIM>, SightingError> {
    paper_eq15_jacobian3(computed, landmarks, PaperAlphaReading::AsPrinted)
}

/// Eq. 15 for three landmarks, [H₂ + H₃ | 0 | H₄ | 0 | 0] with H₃ as printed and α₀ read as
/// `reading`: [`PaperAlphaReading::AsPrinted`] gives [`paper_printed_jacobian3`];
/// [`PaperAlphaReading::Elevation`] gives the printed H with only α₀ repaired, i.e. the
/// verified H plus the printed H₃ (the paper's other flaw in isolation). Fixed size, no
/// allocation.
///
/// # Errors
/// As [`paper_printed_blocks`], for the first landmark that fails.
pub fn paper_eq15_jacobian3(
    computed: &Geodetic,
    landmarks: &[Landmark; 3],
    reading: PaperAlphaReading,
) -> Result<SMatrix<f64, 6, STATE_DIM>, SightingError> {
    let c_e_c = ned_from_ecef(computed.lat_rad, computed.lon_rad);
    let x_c: Vector3<f64> = geodetic_to_ecef(computed);
    let mut h = SMatrix::<f64, 6, STATE_DIM>::zeros();
    for (i, landmark) in landmarks.iter().enumerate() {
        let los = los_from_ecef(landmark, &c_e_c, &x_c)?;
        let blocks = blocks_from_los(computed, landmark, &los, reading)?;
        place(&blocks, &mut h, ROWS_PER_LANDMARK * i);
    }
    Ok(h)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn landmark_exactly_due_east_is_rejected_with_its_id() {
        let pos = Geodetic::from_deg(-23.2, -45.9, 6000.0);
        let landmark = crate::paper_landmarks()[1];
        let los_ned_m = Vector3::new(0.0, 8_000.0, 5_000.0);
        let los = LineOfSight {
            los_ned_m,
            range_m: los_ned_m.norm(),
            horizontal_range_m: 8_000.0,
        };
        let err = blocks_from_los(&pos, &landmark, &los, PaperAlphaReading::AsPrinted);
        assert_eq!(
            err,
            Err(SightingError::PrintedJacobianSingular {
                landmark: 1,
                north_offset_m: 0.0
            })
        );
        // A hair off due east is accepted.
        let los = LineOfSight {
            los_ned_m: Vector3::new(1e-6, 8_000.0, 5_000.0),
            ..los
        };
        assert!(blocks_from_los(&pos, &landmark, &los, PaperAlphaReading::AsPrinted).is_ok());
    }
}
