//! Parameter structs (serde, `deny_unknown_fields`, each with a `validate()` naming the field).

use serde::{Deserialize, Serialize};

use crate::HoughError;

/// Hough accumulator geometry and peak picking, fixed when a [`crate::HoughWorkspace`] is built.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct HoughParams {
    /// θ bin width, degrees. Range `[0.01, 10]`. Default `0.5`.
    pub theta_step_deg: f64,
    /// ρ bin width, pixels. Range `[0.1, 50]`. Default `1.0`.
    pub rho_step_px: f64,
    /// Pick the peak on the 3×3 box sum of the votes (inside the band) instead of the raw votes.
    /// `false` disables it. Default `true`.
    pub peak_smoothing: bool,
    /// Refine the peak to sub-bin precision by a parabola through the peak and its two
    /// neighbours, separately along θ and ρ (offset clamped to ±½ bin). `false` disables it.
    /// Default `true`.
    pub subbin_refinement: bool,
}

impl Default for HoughParams {
    fn default() -> Self {
        Self {
            theta_step_deg: 0.5,
            rho_step_px: 1.0,
            peak_smoothing: true,
            subbin_refinement: true,
        }
    }
}

impl HoughParams {
    /// Check every field against its documented range.
    ///
    /// # Errors
    /// [`HoughError::InvalidParam`] naming the first offending field.
    pub fn validate(&self) -> Result<(), HoughError> {
        check_range(
            "theta_step_deg",
            self.theta_step_deg,
            0.01,
            10.0,
            "must be in [0.01, 10] degrees",
        )?;
        check_range(
            "rho_step_px",
            self.rho_step_px,
            0.1,
            50.0,
            "must be in [0.1, 50] px",
        )?;
        Ok(())
    }
}

/// Parameters of [`crate::init_lane`] (the part after the Hough peak).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct LaneInitParams {
    /// Half-width of the band around the Hough line whose pixels are fitted, pixels of
    /// perpendicular distance `|x cos θ + y sin θ − ρ|`. Range `(0, 1000]`. Default `4.0`.
    /// Also the half-width (horizontal, `|x − x̂(y)|`) of the band around the parabola in
    /// refit iterations.
    pub band_px: f64,
    /// Minimum number of candidate pixels, and of pixels in the band, for an initialisation;
    /// fewer gives [`HoughError::TooFewPoints`]. At least 3. Default `10`.
    pub min_points: usize,
    /// Extra least-squares iterations: re-select the pixels within `band_px` (horizontally) of
    /// the fitted parabola and refit. `0` disables them (the paper's method). Range `[0, 10]`.
    /// Default `0`.
    pub refit_iterations: u32,
}

impl Default for LaneInitParams {
    fn default() -> Self {
        Self {
            band_px: 4.0,
            min_points: 10,
            refit_iterations: 0,
        }
    }
}

impl LaneInitParams {
    /// Check every field against its documented range.
    ///
    /// # Errors
    /// [`HoughError::InvalidParam`] naming the first offending field.
    pub fn validate(&self) -> Result<(), HoughError> {
        if !(self.band_px.is_finite() && self.band_px > 0.0 && self.band_px <= 1000.0) {
            return Err(HoughError::InvalidParam {
                field: "band_px",
                value: self.band_px,
                reason: "must be in (0, 1000] px",
            });
        }
        if self.min_points < 3 {
            return Err(HoughError::InvalidParam {
                field: "min_points",
                value: self.min_points as f64,
                reason: "must be at least 3 (a parabola has three coefficients)",
            });
        }
        if self.refit_iterations > 10 {
            return Err(HoughError::InvalidParam {
                field: "refit_iterations",
                value: f64::from(self.refit_iterations),
                reason: "must be in [0, 10]",
            });
        }
        Ok(())
    }
}

/// A lane's range of Hough normal angles θ, degrees (see the crate docs for the convention).
///
/// θ is the tilt of the line from the image vertical: `θ = 0` is a vertical line, `θ > 0` a line
/// whose top leans right (`/`, a left-lane mark seen from the vehicle, `dx/dy = −tan θ < 0`),
/// `θ < 0` a line whose top leans left (`\`, a right-lane mark). Bounds are inclusive and must
/// satisfy `−90 ≤ min_deg < max_deg ≤ 90`; the band must contain at least one θ bin.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AngleBand {
    /// Smallest θ, degrees.
    pub min_deg: f64,
    /// Largest θ, degrees.
    pub max_deg: f64,
}

impl AngleBand {
    /// Default left-lane band: θ ∈ [15°, 75°] (`/` marks, neither near-vertical nor near-horizontal).
    pub const LEFT_LANE: Self = Self {
        min_deg: 15.0,
        max_deg: 75.0,
    };
    /// Default right-lane band: θ ∈ [−75°, −15°] (`\` marks).
    pub const RIGHT_LANE: Self = Self {
        min_deg: -75.0,
        max_deg: -15.0,
    };

    /// A band `[min_deg, max_deg]`, degrees (not validated here; see [`AngleBand::validate`]).
    #[must_use]
    pub const fn new(min_deg: f64, max_deg: f64) -> Self {
        Self { min_deg, max_deg }
    }

    /// Whether `theta_deg` lies in the band (inclusive).
    #[must_use]
    pub fn contains_deg(&self, theta_deg: f64) -> bool {
        theta_deg >= self.min_deg && theta_deg <= self.max_deg
    }

    /// Check `−90 ≤ min_deg < max_deg ≤ 90`, both finite.
    ///
    /// # Errors
    /// [`HoughError::InvalidBand`] saying which condition failed.
    pub fn validate(&self) -> Result<(), HoughError> {
        let err = |reason| HoughError::InvalidBand {
            min_deg: self.min_deg,
            max_deg: self.max_deg,
            reason,
        };
        if !(self.min_deg.is_finite() && self.max_deg.is_finite()) {
            return Err(err("bounds must be finite"));
        }
        if self.min_deg < -90.0 || self.max_deg > 90.0 {
            return Err(err("bounds must lie in [-90, 90] degrees"));
        }
        if self.min_deg >= self.max_deg {
            return Err(err("min_deg must be smaller than max_deg"));
        }
        Ok(())
    }
}

fn check_range(
    field: &'static str,
    value: f64,
    lo: f64,
    hi: f64,
    reason: &'static str,
) -> Result<(), HoughError> {
    if value.is_finite() && value >= lo && value <= hi {
        Ok(())
    } else {
        Err(HoughError::InvalidParam {
            field,
            value,
            reason,
        })
    }
}
