//! Forgetting-factor configuration.

use serde::{Deserialize, Serialize};

use crate::WrlsError;

/// WRLS configuration.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WrlsConfig {
    /// Forgetting factor λ ∈ (0, 1], dimensionless, applied once per frame: frame `t` of `T`
    /// carries weight `λ^{T−t}`. `1.0` disables forgetting (ordinary recursive least squares).
    /// The paper found `0.70` best.
    pub lambda: f64,
}

impl Default for WrlsConfig {
    /// The paper's λ = 0.70.
    fn default() -> Self {
        Self {
            lambda: PAPER_LAMBDA,
        }
    }
}

/// The paper's best forgetting factor (§IV), λ = 0.70.
pub const PAPER_LAMBDA: f64 = 0.70;

impl WrlsConfig {
    /// Checks `lambda ∈ (0, 1]`.
    ///
    /// # Errors
    /// [`WrlsError::InvalidForgettingFactor`] naming `"lambda"`.
    pub fn validate(&self) -> Result<(), WrlsError> {
        validate_lambda(self.lambda)
    }
}

pub(crate) fn validate_lambda(lambda: f64) -> Result<(), WrlsError> {
    if lambda > 0.0 && lambda <= 1.0 {
        Ok(())
    } else {
        Err(WrlsError::InvalidForgettingFactor {
            field: "lambda",
            value: lambda,
        })
    }
}
