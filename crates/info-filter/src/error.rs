//! The crate's error type.

use thiserror::Error;

/// Everything that can go wrong in this crate. Each variant says which input or which internal
/// matrix failed and where (pivot, row/column, point index).
#[derive(Debug, Clone, Copy, PartialEq, Error)]
#[non_exhaustive]
pub enum KifError {
    /// A Cholesky factorisation met a pivot that was not strictly positive (or not finite):
    /// the matrix is not symmetric positive definite.
    #[error("{matrix} is not positive definite: Cholesky pivot {pivot} is {value:e} (must be > 0)")]
    NotPositiveDefinite {
        /// Which matrix (`"P0"`, `"Q"`, `"R"`, `"Y"`, `"Y + Q^-1"`, …).
        matrix: &'static str,
        /// Zero-based index of the failing pivot.
        pivot: usize,
        /// The value the pivot would have had (before the square root).
        value: f64,
    },
    /// A matrix that must be symmetric is not (relative tolerance 1e-9 per entry pair).
    #[error(
        "{matrix} is not symmetric: entry ({row},{col}) = {upper:e} but ({col},{row}) = {lower:e}"
    )]
    NotSymmetric {
        /// Which matrix.
        matrix: &'static str,
        /// Row of the upper-triangle entry.
        row: usize,
        /// Column of the upper-triangle entry.
        col: usize,
        /// The (row, col) entry.
        upper: f64,
        /// The (col, row) entry.
        lower: f64,
    },
    /// A matrix entry is NaN or infinite.
    #[error("{matrix} has a non-finite entry at ({row},{col}): {value}")]
    NonFiniteMatrix {
        /// Which matrix.
        matrix: &'static str,
        /// Row of the entry.
        row: usize,
        /// Column of the entry.
        col: usize,
        /// The offending value.
        value: f64,
    },
    /// A vector entry is NaN or infinite.
    #[error("{vector} has a non-finite entry at index {index}: {value}")]
    NonFiniteVector {
        /// Which vector (`"theta0"`, `"x"`, …).
        vector: &'static str,
        /// Index of the entry.
        index: usize,
        /// The offending value.
        value: f64,
    },
    /// A variance is NaN, infinite, zero or negative.
    #[error("{name} must be finite and > 0, got {value}")]
    InvalidVariance {
        /// Which parameter (e.g. `"sigma2_px2"`).
        name: &'static str,
        /// The offending value.
        value: f64,
    },
    /// A measured pixel has a NaN or infinite coordinate.
    #[error("point {index} is not finite: (col_px, row_px) = ({col_px}, {row_px})")]
    NonFinitePoint {
        /// Index of the point in the caller's slice.
        index: usize,
        /// Column coordinate (x), pixels.
        col_px: f64,
        /// Row coordinate (y), pixels.
        row_px: f64,
    },
    /// All points were finite but the power sums overflowed (coordinates of order 1e77 or more).
    #[error("power sums overflowed (non-finite) although every point is finite")]
    PowerSumOverflow,
    /// A row-normalisation parameter is invalid.
    #[error("row normalisation field `{field}` is invalid: {value} ({reason})")]
    InvalidRowNorm {
        /// Field name (`"center_row_px"` or `"scale_px"`).
        field: &'static str,
        /// The offending value.
        value: f64,
        /// What is required.
        reason: &'static str,
    },
}
