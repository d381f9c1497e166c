//! Sightings that carry their pointing: the measured line of sight as a direction, so that any
//! filter state can predict it.
//!
//! The paper's device is pointed by the INS that runs the filter, and measures the landmark's
//! offset (w, h) from the image centre. Such a record only means something to that one INS: the
//! camera axes it refers to are the ones that INS commanded. A *pointed* sighting instead records
//! the direction u in which the device saw the landmark (the gimbal angles and the image offset
//! combined), resolved in a frame the record names ([`LosFrame`]):
//!
//! * **body** (FRD) — a body-fixed or gimballed camera whose gimbal angles are read out: the
//!   direction depends on the true attitude, so the sighting observes position *and* attitude;
//! * **local level** (NED) — a device with its own level and north reference (a stabilised,
//!   north-referenced sight): the direction observes position only.
//!
//! A filter whose INS is at position x̃ with attitude C̃_b^n turns a pointed sighting back into
//! the paper's offsets ([`offsets_from_los`]): it resolves u in its own level frame
//! (u_n = C̃_b^n u for body directions), takes the camera axes C_cam^c = [e_w | e_h | b] of its
//! own computed line of sight r̃ (crate documentation), and projects u onto the image plane at
//! the computed slant range ρ̃ (a pinhole camera):
//!
//! ```text
//! c = C_cam^cᵀ u_n,    (w, h) = ρ̃ (c_x / c_z, c_y / c_z)        (c_z > 0: in front)
//! ```
//!
//! For a body direction measured by a device at the true pose, u_n = C̃_b^n C_b^tᵀ C_e^t (x_L − x)
//! / ρ, so c ∝ r_cam of the nonlinear model and (w, h) equals the paper's offsets up to the factor
//! ρ̃/(r_cam · b) = 1 + O(δp/ρ): the same measurement to first order, with the same Jacobian
//! [`crate::sighting_jacobian`] (checked by finite differences in `tests/pointed_fd.rs`). For a
//! local-level direction the attitude does not enter, and H is the same matrix with its ψ
//! columns zero ([`jacobian_for_frame`]).
//!
//! The inverse, [`los_from_offsets`], writes a paper-style measurement (offsets seen by a camera
//! pointed with a given pose) as a body direction: converting it back with the same pose returns
//! the same offsets to round-off, which is how a simulated run is exported as a log that any
//! filter can replay.
//!
//! [`los_from_truth`] synthesises a sighting from a reference pose: the true line of sight,
//! perturbed by independent offsets (n_w, n_h) in metres at the landmark along the true camera
//! axes, so that a filter at the true pose converts it back to exactly (n_w, n_h).

use nalgebra::{SMatrix, Vector2, Vector3};

use crate::SightingError;
use crate::jacobian::{PSI_COL, STATE_DIM, sighting_jacobian};
use crate::model::{Landmark, LineOfSight, NavPose, line_of_sight};

/// The frame a pointed sighting's direction is resolved in.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum LosFrame {
    /// Body axes, FRD (the device's gimbal angles read out): observes position and attitude.
    Body,
    /// Local-level NED at the vehicle (a stabilised, north-referenced device): observes position
    /// only.
    LocalLevel,
}

impl LosFrame {
    /// The name used in logs: `body` or `ned`.
    pub fn as_str(&self) -> &'static str {
        match self {
            LosFrame::Body => "body",
            LosFrame::LocalLevel => "ned",
        }
    }

    /// Parses [`LosFrame::as_str`]'s names.
    pub fn parse(text: &str) -> Option<Self> {
        match text {
            "body" => Some(LosFrame::Body),
            "ned" => Some(LosFrame::LocalLevel),
            _ => None,
        }
    }
}

fn finite3(v: &Vector3<f64>) -> bool {
    v.iter().all(|x| x.is_finite())
}

/// The direction `los` (any length > 0, resolved in `frame`) as the offsets (w, h) in metres at
/// the landmark that a camera pointed with `pose` at `landmark` would see (module documentation).
///
/// # Errors
/// [`SightingError::NonFinite`] for a NaN/∞ or zero direction, [`SightingError::BehindCamera`]
/// when the direction points away from the landmark as seen from `pose` (c_z ≤ 0), and the
/// errors of [`line_of_sight`] for the computed line of sight.
pub fn offsets_from_los(
    pose: &NavPose,
    landmark: &Landmark,
    frame: LosFrame,
    los: &Vector3<f64>,
) -> Result<Vector2<f64>, SightingError> {
    let norm = los.norm();
    if !(finite3(los) && norm > 0.0) {
        return Err(SightingError::NonFinite {
            what: "pointed sighting direction (NaN, infinite or zero)",
        });
    }
    let computed = line_of_sight(&pose.position, landmark)?;
    let u_n = match frame {
        LosFrame::Body => pose.c_b_n * los,
        LosFrame::LocalLevel => *los,
    };
    let c = computed.camera_axes_ned().transpose() * u_n;
    // Below this the direction is (numerically) perpendicular to the boresight.
    if c.z <= 1e-12 * norm {
        return Err(SightingError::BehindCamera {
            landmark: landmark.id(),
            along_boresight_m: c.z / norm * computed.range_m,
        });
    }
    Ok(Vector2::new(
        computed.range_m * c.x / c.z,
        computed.range_m * c.y / c.z,
    ))
}

/// The body-axes unit direction that [`offsets_from_los`] turns back into `offsets_m` for the
/// same `pose` (to round-off): the offsets a camera pointed with `pose` saw, as a record any
/// filter can replay.
///
/// # Errors
/// [`SightingError::NonFinite`] for NaN/∞ offsets, and the errors of [`line_of_sight`].
pub fn los_from_offsets(
    pose: &NavPose,
    landmark: &Landmark,
    offsets_m: &Vector2<f64>,
) -> Result<Vector3<f64>, SightingError> {
    if !(offsets_m.x.is_finite() && offsets_m.y.is_finite()) {
        return Err(SightingError::NonFinite {
            what: "sighting offsets (w, h)",
        });
    }
    let computed = line_of_sight(&pose.position, landmark)?;
    let v_cam = Vector3::new(offsets_m.x, offsets_m.y, computed.range_m);
    let u_n = computed.camera_axes_ned() * v_cam;
    let u_b = pose.c_b_n.inverse() * u_n;
    Ok(u_b / u_b.norm())
}

/// A synthetic pointed sighting of `landmark` from the reference pose `truth`: the true line of
/// sight displaced by `noise_m` = (n_w, n_h) metres at the landmark along the true camera's image
/// axes, as a unit vector in `frame`. A filter at exactly `truth` converts it back to (n_w, n_h).
///
/// # Errors
/// [`SightingError::NonFinite`] for NaN/∞ noise, and the errors of [`line_of_sight`].
pub fn los_from_truth(
    truth: &NavPose,
    landmark: &Landmark,
    frame: LosFrame,
    noise_m: &Vector2<f64>,
) -> Result<Vector3<f64>, SightingError> {
    if !(noise_m.x.is_finite() && noise_m.y.is_finite()) {
        return Err(SightingError::NonFinite {
            what: "sighting noise",
        });
    }
    let los: LineOfSight = line_of_sight(&truth.position, landmark)?;
    let axes = los.camera_axes_ned();
    let v_n = los.los_ned_m + axes.column(0) * noise_m.x + axes.column(1) * noise_m.y;
    let u = match frame {
        LosFrame::Body => truth.c_b_n.inverse() * v_n,
        LosFrame::LocalLevel => v_n,
    };
    Ok(u / u.norm())
}

/// The measurement matrix of a pointed sighting in `frame` at the computed position of `pose`:
/// [`sighting_jacobian`] for body directions; the same with the ψ columns zero for local-level
/// directions (the attitude does not enter the measurement).
/// For local-level directions H leaves out the tilt δθ ≈ δp/R between the device's level frame
/// (at the truth) and the filter's (at the computed position): an error of about
/// ρ(1 + |tan φ|)/R in the position columns (1e-5 at 50 m, 6e-3 at 40 km; `tests/pointed_fd.rs`).
///
/// # Errors
/// As [`sighting_jacobian`].
pub fn jacobian_for_frame(
    pose: &NavPose,
    landmark: &Landmark,
    frame: LosFrame,
) -> Result<SMatrix<f64, 2, STATE_DIM>, SightingError> {
    let mut h = sighting_jacobian(&pose.position, landmark)?;
    if frame == LosFrame::LocalLevel {
        h.fixed_view_mut::<2, 3>(0, PSI_COL).fill(0.0);
    }
    Ok(h)
}
