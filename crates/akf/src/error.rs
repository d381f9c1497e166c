//! The crate's single error type.

use thiserror::Error;

/// Everything that can go wrong in this crate. Every variant says which input (`what`) and, where
/// it applies, which entry or Cholesky pivot failed.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum AkfError {
    /// An input or a computed matrix contains NaN or ±∞.
    #[error("{what} has a non-finite entry at (row {row}, col {col})")]
    NonFinite {
        /// Which matrix/vector (e.g. `"z"`, `"h"`, `"r"`, `"phi"`, `"q_d"`).
        what: &'static str,
        /// Row of the first offending entry (0-based).
        row: usize,
        /// Column of the first offending entry (0-based; 0 for vectors).
        col: usize,
    },
    /// A matrix that must be symmetric is not (beyond round-off).
    #[error(
        "{what} is not symmetric: |a[{row},{col}] - a[{col},{row}]| = {difference:e} > tolerance {tolerance:e}"
    )]
    NotSymmetric {
        /// Which matrix.
        what: &'static str,
        /// Row of the worst asymmetric pair.
        row: usize,
        /// Column of the worst asymmetric pair.
        col: usize,
        /// The absolute difference found.
        difference: f64,
        /// The tolerance it was compared with (relative tolerance × largest |entry|).
        tolerance: f64,
    },
    /// Cholesky factorisation failed: the matrix is not (numerically) positive definite.
    #[error(
        "{what} is not positive definite: Cholesky pivot {pivot} (0-based) is {pivot_value:e}, must be > 0"
    )]
    NotPositiveDefinite {
        /// Which matrix (`"r"`, `"innovation covariance S"`, `"covariance"`).
        what: &'static str,
        /// Index of the failing pivot (0-based): the leading `pivot × pivot` block is PD, the
        /// leading `(pivot+1) × (pivot+1)` block is not.
        pivot: usize,
        /// The Schur complement found at that pivot (≤ 0 or NaN).
        pivot_value: f64,
    },
    /// A covariance that must be positive semi-definite has a negative eigenvalue (or diagonal).
    #[error("{what} is not positive semi-definite: {detail} = {value:e}")]
    NotPositiveSemiDefinite {
        /// Which matrix.
        what: &'static str,
        /// What was checked (e.g. `"smallest eigenvalue"`, `"diagonal entry 3"`).
        detail: &'static str,
        /// The offending value.
        value: f64,
    },
    /// A configuration field or scalar argument is out of its valid range.
    #[error("invalid {field}: {reason}")]
    InvalidParameter {
        /// Name of the field/argument, as spelled in the config or signature.
        field: &'static str,
        /// Why it is rejected.
        reason: String,
    },
    /// An iterative algorithm did not reach its tolerance.
    #[error("{algorithm} did not converge in {iterations} iterations (residual {residual:e})")]
    NotConverged {
        /// Which algorithm (`"Jacobi eigenvalue sweeps"`, `"per-step Q Richardson iteration"`).
        algorithm: &'static str,
        /// Iterations performed.
        iterations: usize,
        /// Relative residual reached.
        residual: f64,
    },
}
