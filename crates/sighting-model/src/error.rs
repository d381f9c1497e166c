//! The crate's error type.

/// Everything that can go wrong in this crate. Geometry variants carry the landmark's `id`
/// (its index in the configuration) and the offending numbers; configuration variants carry
/// the field path inside the `[sighting]` section.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SightingError {
    /// The slant range from the vehicle (computed position) to the landmark is below the
    /// required minimum: the landmark is (almost) at the vehicle's position.
    #[error(
        "landmark {landmark}: slant range {range_m} m from the vehicle is below the minimum {min_range_m} m"
    )]
    RangeTooShort {
        /// Landmark id (index in the configuration).
        landmark: usize,
        /// Slant range found, metres.
        range_m: f64,
        /// Minimum slant range required, metres.
        min_range_m: f64,
    },
    /// The line of sight is (numerically) vertical, so the horizontal image axis `w` is
    /// undefined (the landmark is straight below or above the vehicle).
    #[error(
        "landmark {landmark}: line of sight is vertical (horizontal range {horizontal_range_m} m at slant range {range_m} m), the image w axis is undefined"
    )]
    VerticalLineOfSight {
        /// Landmark id (index in the configuration).
        landmark: usize,
        /// Horizontal range, metres.
        horizontal_range_m: f64,
        /// Slant range, metres.
        range_m: f64,
    },
    /// The landmark lies behind the camera's image plane (errors so large that the camera,
    /// pointed with the computed state, looks away from it).
    #[error(
        "landmark {landmark}: landmark is behind the camera (component along the boresight {along_boresight_m} m)"
    )]
    BehindCamera {
        /// Landmark id (index in the configuration).
        landmark: usize,
        /// Component of the true line of sight along the boresight, metres (≤ 0).
        along_boresight_m: f64,
    },
    /// A NaN or infinity in an input (pose, landmark or error vector) made the result
    /// non-finite.
    #[error("non-finite value in {what}")]
    NonFinite {
        /// Which input or result was not finite.
        what: &'static str,
    },
    /// The paper's printed H (eqs. 16–18) is undefined: its β_x, β_y divide by the north
    /// component x_L − x₀ of the line of sight, which is zero (landmark exactly due east or
    /// west of the computed position).
    #[error(
        "landmark {landmark}: printed H (eq. 18) undefined, north offset x_L - x0 = {north_offset_m} m"
    )]
    PrintedJacobianSingular {
        /// Landmark id (index in the configuration).
        landmark: usize,
        /// North component of the computed line of sight, metres (0).
        north_offset_m: f64,
    },
    /// The measurement-noise variance passed to the noise generator is negative or not finite.
    #[error("noise variance must be finite and >= 0 m², got {noise_var_m2}")]
    InvalidNoiseVariance {
        /// The variance given, m².
        noise_var_m2: f64,
    },
    /// A configuration field holds an invalid value.
    #[error("[sighting] field `{field}` = {value}: {requirement}")]
    InvalidField {
        /// Path of the field inside the `[sighting]` section, e.g. `landmarks[2].lat_deg`.
        field: String,
        /// The value found.
        value: f64,
        /// What the field must satisfy.
        requirement: &'static str,
    },
    /// The configuration holds the wrong number of landmarks for a fixed-size API.
    #[error("[sighting] field `landmarks`: expected {expected} landmarks, found {found}")]
    LandmarkCount {
        /// Number required.
        expected: usize,
        /// Number found.
        found: usize,
    },
}
