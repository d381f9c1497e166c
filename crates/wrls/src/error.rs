//! The crate's error type.

use info_filter::KifError;
use thiserror::Error;

/// Everything that can go wrong in this crate.
#[derive(Debug, Clone, Copy, PartialEq, Error)]
#[non_exhaustive]
pub enum WrlsError {
    /// The forgetting factor is outside `(0, 1]` (or NaN).
    #[error("forgetting factor `{field}` must be in (0, 1], got {value}")]
    InvalidForgettingFactor {
        /// Field name (`"lambda"`).
        field: &'static str,
        /// The offending value.
        value: f64,
    },
    /// The `N×N` matrix `λI + φᵀPφ` of eq. (26) failed its Cholesky factorisation.
    #[error(
        "lambda*I + phi^T P phi ({n}x{n}) is not positive definite: Cholesky pivot {pivot} failed"
    )]
    InnovationNotPositiveDefinite {
        /// Number of points this frame (`N`).
        n: usize,
        /// Zero-based failing pivot.
        pivot: usize,
    },
    /// An input or internal check from the shared filter machinery failed: non-finite point
    /// (with its index), invalid row normalisation, `P0` not symmetric positive definite (with
    /// the pivot), or the updated information/covariance matrix losing positive definiteness.
    #[error(transparent)]
    Filter(#[from] KifError),
}
