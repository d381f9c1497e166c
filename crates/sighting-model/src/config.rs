//! The `[sighting]` configuration section.
//!
//! ```toml
//! [sighting]
//! noise_var_m2 = 40.0      # σ²_SD per image axis, m² (0 disables the simulated noise)
//! update_period_s = 1.0    # T_SD, seconds between sightings (> 0)
//! min_range_m = 100.0      # reject landmarks closer than this to the vehicle, metres (>= 0)
//! landmarks = [
//!   { lat_deg = -23.29, lon_deg = -45.80, alt_m = 20.0 },
//!   { lat_deg = -23.20, lon_deg = -45.85, alt_m = 10.0 },
//!   { lat_deg = -23.25, lon_deg = -45.89, alt_m = 30.0 },
//! ]
//! ```

use ins_errors::earth::Geodetic;
use serde::{Deserialize, Serialize};

use crate::SightingError;
use crate::model::{
    Landmark, LineOfSight, PAPER_LANDMARKS_DEG_M, PAPER_NOISE_VAR_M2, check_geometry,
};

/// One landmark in the configuration (WGS-84 geodetic).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LandmarkConfig {
    /// Geodetic latitude, degrees (north positive), within [−90, 90].
    pub lat_deg: f64,
    /// Longitude, degrees (east positive), finite.
    pub lon_deg: f64,
    /// Height above the WGS-84 ellipsoid, metres, finite.
    pub alt_m: f64,
}

/// The `[sighting]` section: landmarks, noise and update rate of the sighting device.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SightingConfig {
    /// Landmarks with known positions (at least one; the fixed-size APIs need exactly three).
    pub landmarks: Vec<LandmarkConfig>,
    /// Measurement-noise variance σ²_SD of w and of h, m² (paper: 40). 0 disables the
    /// simulated noise (a filter then still needs R > 0 or a positive-definite HPHᵀ).
    pub noise_var_m2: f64,
    /// Time between sighting updates T_SD, seconds (paper: 1), > 0.
    pub update_period_s: f64,
    /// Minimum slant range between vehicle and landmark accepted by
    /// [`SightingConfig::check_vehicle`], metres (not in the paper; 100 m in `configs/paper.toml`).
    pub min_range_m: f64,
}

impl Default for SightingConfig {
    fn default() -> Self {
        Self::paper()
    }
}

impl SightingConfig {
    /// The paper's values (Table 1, §6): three landmarks, σ²_SD = 40 m², T_SD = 1 s; the
    /// minimum range (100 m) is this crate's choice.
    pub fn paper() -> Self {
        Self {
            landmarks: PAPER_LANDMARKS_DEG_M
                .iter()
                .map(|&(lat_deg, lon_deg, alt_m)| LandmarkConfig {
                    lat_deg,
                    lon_deg,
                    alt_m,
                })
                .collect(),
            noise_var_m2: PAPER_NOISE_VAR_M2,
            update_period_s: 1.0,
            min_range_m: 100.0,
        }
    }

    /// Checks every field; the error names the first offending one.
    ///
    /// # Errors
    /// [`SightingError::InvalidField`] naming `noise_var_m2`, `update_period_s`, `min_range_m`
    /// or `landmarks[i].lat_deg|lon_deg|alt_m`; [`SightingError::LandmarkCount`] when the list
    /// is empty.
    pub fn validate(&self) -> Result<(), SightingError> {
        let bad = |field: &str, value: f64, requirement: &'static str| {
            Err(SightingError::InvalidField {
                field: field.to_owned(),
                value,
                requirement,
            })
        };
        if !(self.noise_var_m2.is_finite() && self.noise_var_m2 >= 0.0) {
            return bad(
                "noise_var_m2",
                self.noise_var_m2,
                "must be finite and >= 0 m²",
            );
        }
        if !(self.update_period_s.is_finite() && self.update_period_s > 0.0) {
            return bad(
                "update_period_s",
                self.update_period_s,
                "must be finite and > 0 s",
            );
        }
        if !(self.min_range_m.is_finite() && self.min_range_m >= 0.0) {
            return bad("min_range_m", self.min_range_m, "must be finite and >= 0 m");
        }
        if self.landmarks.is_empty() {
            return Err(SightingError::LandmarkCount {
                expected: 1,
                found: 0,
            });
        }
        for (i, l) in self.landmarks.iter().enumerate() {
            Landmark::from_deg(i, l.lat_deg, l.lon_deg, l.alt_m)?;
        }
        Ok(())
    }

    /// The landmarks (ids = list indices), after [`SightingConfig::validate`].
    ///
    /// # Errors
    /// As [`SightingConfig::validate`].
    pub fn landmarks(&self) -> Result<Vec<Landmark>, SightingError> {
        self.validate()?;
        self.landmarks
            .iter()
            .enumerate()
            .map(|(i, l)| Landmark::from_deg(i, l.lat_deg, l.lon_deg, l.alt_m))
            .collect()
    }

    /// Exactly three landmarks, for [`crate::sighting_offsets3_m`] and
    /// [`crate::sighting_jacobian3`].
    ///
    /// # Errors
    /// As [`SightingConfig::validate`], and [`SightingError::LandmarkCount`] when the list does
    /// not hold three landmarks.
    pub fn landmarks3(&self) -> Result<[Landmark; 3], SightingError> {
        let v = self.landmarks()?;
        let found = v.len();
        <[Landmark; 3]>::try_from(v)
            .map_err(|_| SightingError::LandmarkCount { expected: 3, found })
    }

    /// Geometry check of every landmark from the vehicle position `vehicle` (e.g. the start of
    /// the trajectory): each must be at least `min_range_m` away and not straight below/above.
    /// Returns the first landmark's failure.
    ///
    /// # Errors
    /// As [`SightingConfig::validate`] and [`check_geometry`].
    pub fn check_vehicle(&self, vehicle: &Geodetic) -> Result<Vec<LineOfSight>, SightingError> {
        self.landmarks()?
            .iter()
            .map(|l| check_geometry(vehicle, l, self.min_range_m))
            .collect()
    }
}
