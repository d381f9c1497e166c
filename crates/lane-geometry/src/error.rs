//! The crate's error type.

use thiserror::Error;

/// Everything that can go wrong in this crate. Each variant names the parameter, the point or the
/// matrix concerned.
#[derive(Debug, Clone, Copy, PartialEq, Error)]
#[non_exhaustive]
pub enum GeometryError {
    /// A parameter is NaN, infinite or outside its valid range.
    #[error("`{field}` = {value}: {reason}")]
    InvalidParameter {
        /// Parameter name with its unit, e.g. `height_m`.
        field: &'static str,
        /// The value given.
        value: f64,
        /// The valid range.
        reason: &'static str,
    },
    /// The homography is singular or not finite (e.g. four point pairs with three collinear).
    #[error("degenerate homography: {reason}")]
    DegenerateHomography {
        /// What is wrong.
        reason: &'static str,
    },
    /// An image point maps to the ground behind the camera (at or above the horizon), or a ground
    /// point projects behind the image plane.
    #[error("{what} at ({x}, {y}) is at or beyond the horizon (behind the camera)")]
    BeyondHorizon {
        /// Which point (`"left lane sample"`, `"look-ahead point"`, …).
        what: &'static str,
        /// First coordinate (column px, or forward m).
        x: f64,
        /// Second coordinate (row px, or right m).
        y: f64,
    },
    /// The lane coefficients or their covariance hold NaN or infinite values.
    #[error("{what} is not finite")]
    NonFinite {
        /// Which input.
        what: &'static str,
    },
    /// The ground-plane fit is singular: the sample points do not span enough range.
    #[error("ground-plane lane fit is singular (pivot {pivot} = {value:e})")]
    SingularFit {
        /// Zero-based pivot of the 4×4 Cholesky factorisation.
        pivot: usize,
        /// Its value.
        value: f64,
    },
}
