//! The nonlinear sighting-device model: geometry, camera frame, gimbal pointing, image offsets
//! (w, h) and their noise. See the crate documentation for the equations.

use ins_errors::earth::{Geodetic, ecef_to_geodetic, geodetic_to_ecef, ned_from_ecef};
use nalgebra::{Matrix3, Rotation3, SVector, Vector2, Vector3};
use rand::Rng;
use rand_distr::StandardNormal;

use crate::SightingError;

/// Table 1 of the paper: the three landmarks as (latitude °, longitude °, altitude m).
pub const PAPER_LANDMARKS_DEG_M: [(f64, f64, f64); 3] = [
    (-23.29, -45.80, 20.0),
    (-23.20, -45.85, 10.0),
    (-23.25, -45.89, 30.0),
];

/// Table 1 of the paper: sighting-device noise variance σ²_SD per image axis, m².
pub const PAPER_NOISE_VAR_M2: f64 = 40.0;

/// Slant ranges below this (metres) are rejected by every geometry function: the line of sight
/// has no direction. [`check_geometry`] applies the (much larger) configured minimum.
pub const DEGENERATE_RANGE_M: f64 = 1e-3;

/// A line of sight whose horizontal range is below this fraction of the slant range is treated
/// as vertical ([`SightingError::VerticalLineOfSight`]): the horizontal `w` axis is undefined.
pub const VERTICAL_LOS_FRACTION: f64 = 1e-9;

/// A navigation pose: geodetic position and attitude.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NavPose {
    /// Geodetic position (WGS-84; radians, radians, metres above the ellipsoid).
    pub position: Geodetic,
    /// Attitude C_b^n: body (FRD) → local-level NED at `position`.
    pub c_b_n: Rotation3<f64>,
}

/// A landmark of known position, with its ECEF coordinates cached.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Landmark {
    id: usize,
    position: Geodetic,
    ecef_m: Vector3<f64>,
}

impl Landmark {
    /// A landmark at `position`; `id` identifies it in errors (use its index in the
    /// configuration).
    ///
    /// # Errors
    /// [`SightingError::InvalidField`] (field `landmarks[id].lat_deg` / `lon_deg` / `alt_m`)
    /// when a coordinate is not finite or the latitude is outside ±90°.
    pub fn new(id: usize, position: Geodetic) -> Result<Self, SightingError> {
        let bad = |name: &str, value: f64, requirement: &'static str| {
            Err(SightingError::InvalidField {
                field: format!("landmarks[{id}].{name}"),
                value,
                requirement,
            })
        };
        let lat_deg = position.lat_rad.to_degrees();
        if !lat_deg.is_finite() || lat_deg.abs() > 90.0 {
            return bad(
                "lat_deg",
                lat_deg,
                "must be finite and within [-90, 90] degrees",
            );
        }
        if !position.lon_rad.is_finite() {
            return bad("lon_deg", position.lon_rad.to_degrees(), "must be finite");
        }
        if !position.alt_m.is_finite() {
            return bad("alt_m", position.alt_m, "must be finite");
        }
        Ok(Self {
            id,
            position,
            ecef_m: geodetic_to_ecef(&position),
        })
    }

    /// A landmark from degrees and metres (see [`Landmark::new`] for the errors).
    ///
    /// # Errors
    /// As [`Landmark::new`].
    pub fn from_deg(
        id: usize,
        lat_deg: f64,
        lon_deg: f64,
        alt_m: f64,
    ) -> Result<Self, SightingError> {
        Self::new(id, Geodetic::from_deg(lat_deg, lon_deg, alt_m))
    }

    /// The id given at construction (index in the configuration).
    pub fn id(&self) -> usize {
        self.id
    }

    /// Geodetic position.
    pub fn position(&self) -> Geodetic {
        self.position
    }

    /// ECEF position, metres.
    pub fn ecef_m(&self) -> Vector3<f64> {
        self.ecef_m
    }
}

/// The paper's three landmarks (Table 1), ids 0, 1, 2.
pub fn paper_landmarks() -> [Landmark; 3] {
    core::array::from_fn(|i| {
        let (lat_deg, lon_deg, alt_m) = PAPER_LANDMARKS_DEG_M[i];
        let position = Geodetic::from_deg(lat_deg, lon_deg, alt_m);
        Landmark {
            id: i,
            position,
            ecef_m: geodetic_to_ecef(&position),
        }
    })
}

/// The line of sight from a vehicle position to a landmark, in the NED frame at the vehicle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LineOfSight {
    /// r = landmark − vehicle, resolved in NED at the vehicle, metres.
    pub los_ned_m: Vector3<f64>,
    /// Slant range ρ = |r|, metres.
    pub range_m: f64,
    /// Horizontal range d₀ = √(r_N² + r_E²), metres.
    pub horizontal_range_m: f64,
}

impl LineOfSight {
    /// Azimuth β of the line of sight, from north towards east, radians.
    pub fn azimuth_rad(&self) -> f64 {
        self.los_ned_m.y.atan2(self.los_ned_m.x)
    }

    /// Depression ε of the line of sight below the local horizontal, radians (positive when
    /// the landmark is below the vehicle; the paper's elevation α₀ = −ε).
    pub fn depression_rad(&self) -> f64 {
        self.los_ned_m.z.atan2(self.horizontal_range_m)
    }

    /// Camera axes resolved in the same NED frame, as the columns of C_cam^n =
    /// [e_w | e_h | b]: boresight b = r/ρ; image-right axis e_w = (−r_E, r_N, 0)/d₀ (horizontal,
    /// = (−sin β, cos β, 0)); image-down axis e_h = b × e_w = (−sin ε cos β, −sin ε sin β, cos ε).
    /// (e_w, e_h, b) is right-handed and orthonormal.
    pub fn camera_axes_ned(&self) -> Matrix3<f64> {
        let b = self.los_ned_m / self.range_m;
        let e_w = Vector3::new(-self.los_ned_m.y, self.los_ned_m.x, 0.0) / self.horizontal_range_m;
        let e_h = b.cross(&e_w);
        Matrix3::from_columns(&[e_w, e_h, b])
    }
}

/// Line of sight from the vehicle at ECEF `vehicle_ecef_m` (NED frame given by `c_e_n`).
pub(crate) fn los_from_ecef(
    landmark: &Landmark,
    c_e_n: &Matrix3<f64>,
    vehicle_ecef_m: &Vector3<f64>,
) -> Result<LineOfSight, SightingError> {
    let los_ned_m = c_e_n * (landmark.ecef_m - vehicle_ecef_m);
    let range_m = los_ned_m.norm();
    let horizontal_range_m = los_ned_m.x.hypot(los_ned_m.y);
    if !range_m.is_finite() {
        return Err(SightingError::NonFinite {
            what: "line of sight (vehicle or landmark position)",
        });
    }
    if range_m < DEGENERATE_RANGE_M {
        return Err(SightingError::RangeTooShort {
            landmark: landmark.id,
            range_m,
            min_range_m: DEGENERATE_RANGE_M,
        });
    }
    if horizontal_range_m <= VERTICAL_LOS_FRACTION * range_m {
        return Err(SightingError::VerticalLineOfSight {
            landmark: landmark.id,
            horizontal_range_m,
            range_m,
        });
    }
    Ok(LineOfSight {
        los_ned_m,
        range_m,
        horizontal_range_m,
    })
}

/// Line of sight from `vehicle` to `landmark`, resolved in NED at `vehicle`.
///
/// # Errors
/// [`SightingError::NonFinite`] for NaN/∞ positions, [`SightingError::RangeTooShort`] below
/// [`DEGENERATE_RANGE_M`], [`SightingError::VerticalLineOfSight`] when the landmark is straight
/// below/above.
pub fn line_of_sight(
    vehicle: &Geodetic,
    landmark: &Landmark,
) -> Result<LineOfSight, SightingError> {
    let c_e_n = ned_from_ecef(vehicle.lat_rad, vehicle.lon_rad);
    los_from_ecef(landmark, &c_e_n, &geodetic_to_ecef(vehicle))
}

/// Geometry check for a configured landmark seen from `vehicle`: the line of sight must be
/// defined (see [`line_of_sight`]) and the slant range at least `min_range_m` metres.
///
/// # Errors
/// [`SightingError::RangeTooShort`] when the landmark is closer than `min_range_m` (e.g. at the
/// vehicle's position), [`SightingError::InvalidField`] (`min_range_m`) when `min_range_m` is
/// negative or not finite, plus the errors of [`line_of_sight`].
pub fn check_geometry(
    vehicle: &Geodetic,
    landmark: &Landmark,
    min_range_m: f64,
) -> Result<LineOfSight, SightingError> {
    if !(min_range_m.is_finite() && min_range_m >= 0.0) {
        return Err(SightingError::InvalidField {
            field: "min_range_m".to_owned(),
            value: min_range_m,
            requirement: "must be finite and >= 0 metres",
        });
    }
    let c_e_n = ned_from_ecef(vehicle.lat_rad, vehicle.lon_rad);
    let x = geodetic_to_ecef(vehicle);
    let range_m = (c_e_n * (landmark.ecef_m - x)).norm();
    if range_m < min_range_m {
        return Err(SightingError::RangeTooShort {
            landmark: landmark.id,
            range_m,
            min_range_m,
        });
    }
    los_from_ecef(landmark, &c_e_n, &x)
}

/// Quantities shared by all landmarks of one epoch.
struct EpochGeometry {
    /// C_e^c: ECEF → NED at the computed position.
    c_e_c: Matrix3<f64>,
    /// Computed position, ECEF, metres.
    computed_ecef_m: Vector3<f64>,
    /// True position, ECEF, metres.
    truth_ecef_m: Vector3<f64>,
    /// K = C̃_b^n (C_b^t)ᵀ C_e^t: ECEF → the frame in which the camera axes were commanded.
    k: Matrix3<f64>,
}

impl EpochGeometry {
    fn new(truth: &NavPose, computed: &NavPose) -> Self {
        let c_e_t = ned_from_ecef(truth.position.lat_rad, truth.position.lon_rad);
        let k = computed.c_b_n.matrix() * truth.c_b_n.matrix().transpose() * c_e_t;
        Self {
            c_e_c: ned_from_ecef(computed.position.lat_rad, computed.position.lon_rad),
            computed_ecef_m: geodetic_to_ecef(&computed.position),
            truth_ecef_m: geodetic_to_ecef(&truth.position),
            k,
        }
    }

    fn offset(&self, landmark: &Landmark) -> Result<Vector2<f64>, SightingError> {
        self.offset_to(landmark, &landmark.ecef_m)
    }

    /// The offset of a landmark that really is at `actual_ecef_m` when the camera is pointed
    /// at its surveyed position `pointed`.
    fn offset_to(
        &self,
        pointed: &Landmark,
        actual_ecef_m: &Vector3<f64>,
    ) -> Result<Vector2<f64>, SightingError> {
        let landmark = pointed;
        // Gimbal command: camera axes from the computed line of sight in the computed NED frame.
        let los = los_from_ecef(landmark, &self.c_e_c, &self.computed_ecef_m)?;
        let c_cam_c = los.camera_axes_ned();
        // True line of sight resolved in the camera axes as actually realised by the true
        // attitude: (C_b^t C̃_b^nᵀ C_cam^c)ᵀ C_e^t (x_L − x).
        let r_cam = c_cam_c.transpose() * (self.k * (actual_ecef_m - self.truth_ecef_m));
        if !(r_cam.x.is_finite() && r_cam.y.is_finite() && r_cam.z.is_finite()) {
            return Err(SightingError::NonFinite {
                what: "image offset (poses or attitudes)",
            });
        }
        if r_cam.z <= 0.0 {
            return Err(SightingError::BehindCamera {
                landmark: landmark.id,
                along_boresight_m: r_cam.z,
            });
        }
        Ok(Vector2::new(r_cam.x, r_cam.y))
    }
}

/// The noise-free sighting measurement (w, h) of one landmark, metres at the landmark.
///
/// The gimbal points the camera using the `computed` pose (INS solution); the camera really
/// sits at the `truth` pose. The result is the landmark's offset from the image centre on the
/// plane through the landmark normal to the boresight: w along image-right, h along image-down
/// (see the crate documentation for the frame and equations).
///
/// # Errors
/// The errors of [`line_of_sight`] for the computed line of sight,
/// [`SightingError::BehindCamera`] when the errors are so large that the landmark is behind
/// the image plane, [`SightingError::NonFinite`] for NaN/∞ inputs.
pub fn sighting_offset_m(
    truth: &NavPose,
    computed: &NavPose,
    landmark: &Landmark,
) -> Result<Vector2<f64>, SightingError> {
    EpochGeometry::new(truth, computed).offset(landmark)
}

/// [`sighting_offset_m`] for a landmark whose surveyed position (`surveyed`, where the camera
/// is pointed) differs from where it really is (`actual_ecef_m`, ECEF m): simulates a landmark
/// survey error. Equals [`sighting_offset_m`] when `actual_ecef_m` is `surveyed.ecef_m()`.
///
/// # Errors
/// As [`sighting_offset_m`].
pub fn sighting_offset_surveyed_m(
    truth: &NavPose,
    computed: &NavPose,
    surveyed: &Landmark,
    actual_ecef_m: &Vector3<f64>,
) -> Result<Vector2<f64>, SightingError> {
    EpochGeometry::new(truth, computed).offset_to(surveyed, actual_ecef_m)
}

/// [`sighting_offset_m`] for three landmarks at once, stacked as (w₀, h₀, w₁, h₁, w₂, h₂);
/// the Earth-frame quantities are computed once. No allocation.
///
/// # Errors
/// As [`sighting_offset_m`], for the first landmark that fails.
pub fn sighting_offsets3_m(
    truth: &NavPose,
    computed: &NavPose,
    landmarks: &[Landmark; 3],
) -> Result<SVector<f64, 6>, SightingError> {
    let geometry = EpochGeometry::new(truth, computed);
    let mut z = SVector::<f64, 6>::zeros();
    for (i, landmark) in landmarks.iter().enumerate() {
        let wh = geometry.offset(landmark)?;
        z[2 * i] = wh.x;
        z[2 * i + 1] = wh.y;
    }
    Ok(z)
}

/// Adds independent zero-mean Gaussian noise of variance `noise_var_m2` (m², per image axis;
/// the paper's σ²_SD = [`PAPER_NOISE_VAR_M2`]) to every entry of `offsets_m`.
/// `noise_var_m2 = 0` disables the noise (the values are left unchanged).
///
/// # Errors
/// [`SightingError::InvalidNoiseVariance`] when `noise_var_m2` is negative or not finite
/// (then `offsets_m` is left unchanged).
pub fn add_sighting_noise<const N: usize, R: Rng + ?Sized>(
    offsets_m: &mut SVector<f64, N>,
    noise_var_m2: f64,
    rng: &mut R,
) -> Result<(), SightingError> {
    if !(noise_var_m2.is_finite() && noise_var_m2 >= 0.0) {
        return Err(SightingError::InvalidNoiseVariance { noise_var_m2 });
    }
    let sigma_m = noise_var_m2.sqrt();
    for v in offsets_m.iter_mut() {
        let n: f64 = rng.sample(StandardNormal);
        *v += sigma_m * n;
    }
    Ok(())
}

/// The true pose that a `computed` pose has for given errors, inverting the shared contract's
/// definitions:
/// the position with `pos_err_ned_m(computed, truth) = pos_err_ned_m` (δp = computed − truth,
/// NED at the truth, metres; solved by fixed-point iteration, exact to ≪ 1 µm for errors up to
/// kilometres), and the attitude with C̃_b^n = exp(−[ψ×]) C_b^c, C_b^c = C_t^c C_b^t
/// (C_t^c = C_e^c C_e^tᵀ exactly), i.e. C_b^t = C_e^t C_e^cᵀ exp([ψ×]) C̃_b^n. The rotation
/// exp(−[ψ×]) equals the contract's I − [ψ×] to first order and keeps the DCM orthonormal.
///
/// Used to simulate a truth for given errors and to finite-difference the measurement model.
/// NaN inputs give NaN outputs (the measurement functions then report
/// [`SightingError::NonFinite`]).
pub fn true_pose_from_errors(
    computed: &NavPose,
    pos_err_ned_m: &Vector3<f64>,
    psi_rad: &Vector3<f64>,
) -> NavPose {
    let computed_ecef_m = geodetic_to_ecef(&computed.position);
    let mut truth = computed.position;
    for _ in 0..4 {
        let c_e_t = ned_from_ecef(truth.lat_rad, truth.lon_rad);
        truth = ecef_to_geodetic(&(computed_ecef_m - c_e_t.transpose() * pos_err_ned_m));
    }
    let c_e_c = ned_from_ecef(computed.position.lat_rad, computed.position.lon_rad);
    let c_e_t = ned_from_ecef(truth.lat_rad, truth.lon_rad);
    let c_c_t = Rotation3::from_matrix_unchecked(c_e_t * c_e_c.transpose());
    let c_b_c = Rotation3::new(*psi_rad) * computed.c_b_n;
    NavPose {
        position: truth,
        c_b_n: c_c_t * c_b_c,
    }
}
