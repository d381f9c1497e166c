//! Parameters (serde-loadable) and their validation.

use serde::{Deserialize, Serialize};

use crate::{GradientError, MAX_MAGNITUDE};

/// Parameters of the directional gradient.
///
/// Angles are the **edge angle from the image horizontal**, `α ∈ [0°, 90°]`, with
/// `tan α = |gx| / |gy|` (see the crate docs). A pixel is a lane candidate only if
/// `min_edge_angle_deg ≤ α ≤ max_edge_angle_deg`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GradientParams {
    /// Lower edge-angle limit in degrees, drops near-horizontal edges. `0.0` disables the limit.
    /// Range `[0, 90)`, must be below `max_edge_angle_deg`.
    pub min_edge_angle_deg: f64,
    /// Upper edge-angle limit in degrees, drops near-vertical edges. `90.0` disables the limit.
    /// Range `(0, 90]`, must be above `min_edge_angle_deg`.
    pub max_edge_angle_deg: f64,
    /// Magnitude threshold rule.
    pub threshold: Threshold,
}

/// How the magnitude threshold is chosen. Magnitudes are `|gx| + |gy|` of the 3×3 Sobel
/// responses, in grey levels, range `0..=2040` ([`MAX_MAGNITUDE`]); an ideal 45° step of `h`
/// grey levels gives `6h`, an axis-aligned step `4h`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "mode", rename_all = "snake_case", deny_unknown_fields)]
pub enum Threshold {
    /// Keep pixels with `magnitude >= min_magnitude`. `0` disables the threshold.
    Fixed {
        /// Threshold, in magnitude units (`0..=2040`).
        min_magnitude: u16,
    },
    /// Per-frame threshold: the `(1 - keep_fraction)` quantile of the magnitudes of all pixels in
    /// the region that pass the orientation band, never below `min_magnitude`. See the crate docs.
    Adaptive {
        /// Fraction of in-band pixels to keep, in `(0, 1]` (`1.0` keeps all of them).
        keep_fraction: f64,
        /// Floor of the threshold, in magnitude units (`0..=2040`); `0` disables the floor.
        min_magnitude: u16,
    },
}

impl Default for GradientParams {
    /// Band 15°..80°, fixed threshold 120 (a 45° step of 20 grey levels).
    fn default() -> Self {
        Self {
            min_edge_angle_deg: 15.0,
            max_edge_angle_deg: 80.0,
            threshold: Threshold::Fixed { min_magnitude: 120 },
        }
    }
}

impl GradientParams {
    /// Checks every field against its documented range.
    ///
    /// # Errors
    /// [`GradientError::InvalidParam`] naming the first offending field.
    pub fn validate(&self) -> Result<(), GradientError> {
        let lo = self.min_edge_angle_deg;
        let hi = self.max_edge_angle_deg;
        if !lo.is_finite() || !(0.0..90.0).contains(&lo) {
            return Err(GradientError::InvalidParam {
                field: "min_edge_angle_deg",
                value: lo,
                requirement: "finite, 0 <= value < 90 (0 disables the limit)",
            });
        }
        if !hi.is_finite() || hi <= 0.0 || hi > 90.0 {
            return Err(GradientError::InvalidParam {
                field: "max_edge_angle_deg",
                value: hi,
                requirement: "finite, 0 < value <= 90 (90 disables the limit)",
            });
        }
        if hi <= lo {
            return Err(GradientError::InvalidParam {
                field: "max_edge_angle_deg",
                value: hi,
                requirement: "must be greater than min_edge_angle_deg",
            });
        }
        match self.threshold {
            Threshold::Fixed { min_magnitude } | Threshold::Adaptive { min_magnitude, .. }
                if min_magnitude > MAX_MAGNITUDE =>
            {
                Err(GradientError::InvalidParam {
                    field: "threshold.min_magnitude",
                    value: f64::from(min_magnitude),
                    requirement: "0 <= value <= 2040 (the largest Sobel L1 magnitude)",
                })
            }
            Threshold::Adaptive { keep_fraction, .. }
                if !keep_fraction.is_finite() || keep_fraction <= 0.0 || keep_fraction > 1.0 =>
            {
                Err(GradientError::InvalidParam {
                    field: "threshold.keep_fraction",
                    value: keep_fraction,
                    requirement: "finite, 0 < value <= 1",
                })
            }
            _ => Ok(()),
        }
    }
}
