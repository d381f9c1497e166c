//! Sage–Husa process-noise estimation with a forgetting factor.
//!
//! Sage & Husa (1969), in the fading-memory form used for INS integration (e.g. Yang & Gao's
//! reading, Narasimhappa et al. 2019): with the per-update innovation-based estimate
//!
//! ```text
//! q_k = Δx_k Δx_kᵀ + P_k⁺ − Φ P_{k−1}⁺ Φᵀ,   Δx_k = x̂_k⁺ − x̂_k⁻ = K_k ν_k
//! ```
//!
//! (the single-sample term of Mohamed–Schwarz eq. 19), the estimate is the weighted recursion
//!
//! ```text
//! Q̂_k = (1 − d_k) Q̂_{k−1} + d_k q_k,   d_k = (1 − b) / (1 − b^{k+1}),   k = 0, 1, …
//! ```
//!
//! with the forgetting factor 0 < b ≤ 1: d_0 = 1 (the first estimate is q_0), and Q̂_k is the
//! exponentially weighted mean Σ b^{k−j} q_j / Σ b^{k−j}. At b = 1, d_k = 1/(k+1) and Q̂_k is
//! the plain running average of q_0 … q_k (the limit b → 1 of the formula; tested). Memory
//! ≈ 1/(1 − b) updates. The estimate is symmetrised and projected like [`crate::AdaptiveQ`]'s.

use nalgebra::{SMatrix, SVector};
use serde::{Deserialize, Serialize};

use crate::AkfError;
use crate::adaptive::{Projected, QProjection, apply_projection, check_push_inputs};
use crate::linalg::symmetrise_in_place;

/// Configuration of [`SageHusaQ`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SageHusaConfig {
    /// Forgetting factor b, 0 < b ≤ 1 (1 = running average over all updates).
    pub forgetting: f64,
    /// Updates before the estimate is offered (≥ 1): the first estimates average one or two
    /// samples only.
    pub warmup: usize,
    /// Projection of the (generally indefinite) estimate.
    pub projection: QProjection,
    /// Floor of the projection (state units² per interval, ≥ 0).
    pub min_variance: f64,
}

impl SageHusaConfig {
    /// Checks every field; the error names it.
    pub fn validate(&self) -> Result<(), AkfError> {
        if !(self.forgetting > 0.0 && self.forgetting <= 1.0) {
            return Err(AkfError::InvalidParameter {
                field: "forgetting",
                reason: format!("{} must be within (0, 1]", self.forgetting),
            });
        }
        if self.warmup == 0 {
            return Err(AkfError::InvalidParameter {
                field: "warmup",
                reason: "must be >= 1".to_string(),
            });
        }
        if !(self.min_variance.is_finite() && self.min_variance >= 0.0) {
            return Err(AkfError::InvalidParameter {
                field: "min_variance",
                reason: format!("{} must be finite and ≥ 0", self.min_variance),
            });
        }
        Ok(())
    }
}

/// The Sage–Husa estimator (module doc). Allocation-free.
#[derive(Debug, Clone)]
pub struct SageHusaQ<const N: usize> {
    config: SageHusaConfig,
    count: u64,
    raw: Option<SMatrix<f64, N, N>>,
    projected: Option<Projected<N>>,
}

impl<const N: usize> SageHusaQ<N> {
    /// An estimator with no data.
    pub fn new(config: SageHusaConfig) -> Result<Self, AkfError> {
        config.validate()?;
        Ok(Self {
            config,
            count: 0,
            raw: None,
            projected: None,
        })
    }

    /// The weight d_k of update k (0-based): (1 − b)/(1 − b^{k+1}), 1/(k+1) at b = 1.
    pub fn weight(&self, k: u64) -> f64 {
        let b = self.config.forgetting;
        if b >= 1.0 {
            1.0 / (k as f64 + 1.0)
        } else {
            (1.0 - b) / (1.0 - b.powf(k as f64 + 1.0))
        }
    }

    /// Updates pushed so far.
    pub fn count(&self) -> u64 {
        self.count
    }

    /// Pushes one update (see [`crate::AdaptiveQ::push`] for the arguments) and returns the
    /// projected estimate once `warmup` updates have been seen.
    pub fn push(
        &mut self,
        dx: &SVector<f64, N>,
        p_post: &SMatrix<f64, N, N>,
        p_post_prev: &SMatrix<f64, N, N>,
        phi_interval: &SMatrix<f64, N, N>,
    ) -> Result<Option<&SMatrix<f64, N, N>>, AkfError> {
        check_push_inputs(dx, p_post, p_post_prev, phi_interval)?;
        let q =
            dx * dx.transpose() + p_post - phi_interval * p_post_prev * phi_interval.transpose();
        let d = self.weight(self.count);
        let mut raw = match &self.raw {
            None => q,
            Some(prev) => prev * (1.0 - d) + q * d,
        };
        symmetrise_in_place(&mut raw);
        self.count += 1;
        let projected = apply_projection(
            &raw,
            self.config.projection,
            self.config.min_variance,
            &SVector::repeat(self.config.min_variance),
        )?;
        self.raw = Some(raw);
        self.projected = Some(projected);
        Ok(self.estimate())
    }

    /// The projected estimate, after the warm-up.
    pub fn estimate(&self) -> Option<&SMatrix<f64, N, N>> {
        if self.count < self.config.warmup as u64 {
            return None;
        }
        self.projected.as_ref().map(|p| &p.matrix)
    }

    /// The symmetrised, unprojected estimate (from the first push on).
    pub fn raw_estimate(&self) -> Option<&SMatrix<f64, N, N>> {
        self.raw.as_ref()
    }
}
