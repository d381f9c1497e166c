//! Pinhole camera mounted above a flat ground plane.

use nalgebra::{Matrix3, Vector3};

use crate::{GeometryError, Homography};

/// Camera intrinsics: square pixels, no skew, no lens distortion.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Intrinsics {
    /// Focal length, px (> 0).
    pub focal_length_px: f64,
    /// Principal point `[column, row]`, px (finite; usually the image centre).
    pub principal_point_px: [f64; 2],
}

/// Camera mounting on the vehicle.
///
/// The vehicle ground frame has its origin on the ground directly below the camera's centre,
/// `X` forward, `Y` right, `Z` down (FRD, like the project's body frame); the ground is `Z = 0`
/// and the camera centre is at `(0, 0, −height_m)`. The camera's own forward/right/down axes
/// are rotated from the vehicle's by `R = Rz(yaw_rad)·Ry(−pitch_down_rad)·Rx(roll_rad)`
/// (yaw, then pitch, then roll; FRD signs: yaw positive to the right, roll positive right side
/// down), so `pitch_down_rad > 0` tilts the optical axis towards the ground.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Mounting {
    /// Height of the camera centre above the ground, m (> 0).
    pub height_m: f64,
    /// Tilt of the optical axis below the horizontal, rad (in (−π/2, π/2)).
    pub pitch_down_rad: f64,
    /// Rotation about the optical axis, rad, positive right side down (|roll| < π/2).
    pub roll_rad: f64,
    /// Pan of the optical axis from the vehicle's forward axis, rad, positive to the right
    /// (|yaw| < π/2).
    pub yaw_rad: f64,
}

/// A validated pinhole camera over the ground plane.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PinholeCamera {
    intrinsics: Intrinsics,
    mounting: Mounting,
    /// Rotation: columns are the camera's forward/right/down axes in the vehicle frame.
    r_vehicle_camera: Matrix3<f64>,
}

fn check(
    ok: bool,
    field: &'static str,
    value: f64,
    reason: &'static str,
) -> Result<(), GeometryError> {
    if ok {
        Ok(())
    } else {
        Err(GeometryError::InvalidParameter {
            field,
            value,
            reason,
        })
    }
}

/// `Rz(yaw)·Ry(pitch)·Rx(roll)` in FRD.
fn rotation_zyx(yaw: f64, pitch: f64, roll: f64) -> Matrix3<f64> {
    let (sy, cy) = yaw.sin_cos();
    let (sp, cp) = pitch.sin_cos();
    let (sr, cr) = roll.sin_cos();
    let rz = Matrix3::new(cy, -sy, 0.0, sy, cy, 0.0, 0.0, 0.0, 1.0);
    let ry = Matrix3::new(cp, 0.0, sp, 0.0, 1.0, 0.0, -sp, 0.0, cp);
    let rx = Matrix3::new(1.0, 0.0, 0.0, 0.0, cr, -sr, 0.0, sr, cr);
    rz * ry * rx
}

impl PinholeCamera {
    /// Validates the parameters and builds the camera.
    ///
    /// # Errors
    /// [`GeometryError::InvalidParameter`] naming the first parameter out of range.
    pub fn new(intrinsics: Intrinsics, mounting: Mounting) -> Result<Self, GeometryError> {
        let f = intrinsics.focal_length_px;
        check(
            f.is_finite() && f > 0.0,
            "focal_length_px",
            f,
            "must be finite and > 0",
        )?;
        let [cx, cy] = intrinsics.principal_point_px;
        check(
            cx.is_finite(),
            "principal_point_px[0]",
            cx,
            "must be finite",
        )?;
        check(
            cy.is_finite(),
            "principal_point_px[1]",
            cy,
            "must be finite",
        )?;
        let h = mounting.height_m;
        check(
            h.is_finite() && h > 0.0,
            "height_m",
            h,
            "must be finite and > 0",
        )?;
        let half_pi = std::f64::consts::FRAC_PI_2;
        for (field, v) in [
            ("pitch_down_rad", mounting.pitch_down_rad),
            ("roll_rad", mounting.roll_rad),
            ("yaw_rad", mounting.yaw_rad),
        ] {
            check(
                v.is_finite() && v.abs() < half_pi,
                field,
                v,
                "must be finite and in (−π/2, π/2)",
            )?;
        }
        Ok(Self {
            intrinsics,
            mounting,
            r_vehicle_camera: rotation_zyx(
                mounting.yaw_rad,
                -mounting.pitch_down_rad,
                mounting.roll_rad,
            ),
        })
    }

    /// The intrinsics.
    pub fn intrinsics(&self) -> &Intrinsics {
        &self.intrinsics
    }

    /// The mounting.
    pub fn mounting(&self) -> &Mounting {
        &self.mounting
    }

    /// `K` (3×3 upper-triangular intrinsic matrix).
    pub fn k_matrix(&self) -> Matrix3<f64> {
        let f = self.intrinsics.focal_length_px;
        let [cx, cy] = self.intrinsics.principal_point_px;
        Matrix3::new(f, 0.0, cx, 0.0, f, cy, 0.0, 0.0, 1.0)
    }

    /// Rotation from vehicle axes to optical axes (x right, y down, z along the optical axis):
    /// `p_optical = A · (p_vehicle − c)`.
    pub fn vehicle_to_optical(&self) -> Matrix3<f64> {
        // Optical (right, down, forward) from camera-body (forward, right, down).
        let perm = Matrix3::new(0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0);
        perm * self.r_vehicle_camera.transpose()
    }

    /// Projects a 3-D point of the vehicle frame (`[X fwd, Y right, Z down]`, m) to the image,
    /// `[column, row]` px; `None` when the point is not in front of the camera.
    pub fn project(&self, p_vehicle_m: [f64; 3]) -> Option<[f64; 2]> {
        let d = Vector3::new(
            p_vehicle_m[0],
            p_vehicle_m[1],
            p_vehicle_m[2] + self.mounting.height_m,
        );
        let p = self.vehicle_to_optical() * d;
        if p.z.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            return None;
        }
        let f = self.intrinsics.focal_length_px;
        let [cx, cy] = self.intrinsics.principal_point_px;
        Some([cx + f * p.x / p.z, cy + f * p.y / p.z])
    }

    /// The viewing ray of a pixel in the vehicle frame (unit vector, not normalised to the ground).
    pub fn ray(&self, pixel_px: [f64; 2]) -> Vector3<f64> {
        let f = self.intrinsics.focal_length_px;
        let [cx, cy] = self.intrinsics.principal_point_px;
        let d_opt = Vector3::new((pixel_px[0] - cx) / f, (pixel_px[1] - cy) / f, 1.0);
        (self.vehicle_to_optical().transpose() * d_opt).normalize()
    }

    /// The ground-plane homography `H = K·A·diag(1, 1, height_m)` mapping ground points
    /// `(X, Y, 1)` (m) to image points `w·(column, row, 1)` (px), with `w` the depth along the
    /// optical axis (> 0 in front of the camera).
    ///
    /// # Errors
    /// [`GeometryError::DegenerateHomography`] if the camera looks parallel to the ground plane
    /// so that the map is singular (not reachable with a validated mounting).
    pub fn homography(&self) -> Result<Homography, GeometryError> {
        let s = Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, self.mounting.height_m));
        Homography::from_ground_to_image(&(self.k_matrix() * self.vehicle_to_optical() * s))
    }

    /// The row of the horizon at `column_px` (where the ground plane meets the sky), px.
    pub fn horizon_row_px(&self, column_px: f64) -> f64 {
        // Vanishing points of ground directions satisfy n_opt · K⁻¹(u, v, 1) = 0 with n_opt the
        // ground normal in optical axes.
        let n = self.vehicle_to_optical() * Vector3::new(0.0, 0.0, 1.0);
        let f = self.intrinsics.focal_length_px;
        let [cx, cy] = self.intrinsics.principal_point_px;
        // n.x (u − cx)/f + n.y (v − cy)/f + n.z = 0.
        cy - (n.x * (column_px - cx) / f + n.z) * f / n.y
    }
}
