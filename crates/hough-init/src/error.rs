//! The crate's error type.

use core::fmt;

/// Which set of points was too small.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PointSet {
    /// The candidate edge pixels given to the Hough transform / [`crate::init_lane`].
    Candidates,
    /// The pixels within `band_px` of the Hough line (input of the least-squares fit).
    NearLine,
    /// The pixels within `band_px` of the previous parabola (refit iterations).
    NearParabola,
    /// The points given to [`crate::fit_parabola`] / kept by the predicate of
    /// [`crate::fit_parabola_where`].
    Fit,
}

impl fmt::Display for PointSet {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::Candidates => "candidate",
            Self::NearLine => "near-Hough-line",
            Self::NearParabola => "near-parabola",
            Self::Fit => "fit",
        })
    }
}

/// Everything that can go wrong in this crate. Each variant says what failed and where.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum HoughError {
    /// A numeric parameter is out of its documented range.
    #[error("parameter `{field}` = {value} is invalid: {reason}")]
    InvalidParam {
        /// Field name, as spelled in the parameter struct.
        field: &'static str,
        /// The offending value (integers converted to `f64`).
        value: f64,
        /// What the valid range is.
        reason: &'static str,
    },
    /// The image size given to [`crate::HoughWorkspace::new`] is unusable.
    #[error("image size {width_px}x{height_px} px is invalid: {reason}")]
    InvalidImageSize {
        /// Image width, pixels.
        width_px: usize,
        /// Image height, pixels.
        height_px: usize,
        /// Why.
        reason: &'static str,
    },
    /// The accumulator would be unreasonably large (resolution too fine for the image).
    #[error(
        "Hough accumulator of {theta_bins} x {rho_bins} cells exceeds the limit of {limit} cells"
    )]
    AccumulatorTooLarge {
        /// Number of θ bins over [−90°, 90°).
        theta_bins: usize,
        /// Number of ρ bins.
        rho_bins: usize,
        /// The limit, cells.
        limit: usize,
    },
    /// The lane's angle band is unusable.
    #[error("angle band [{min_deg}°, {max_deg}°] is invalid: {reason}")]
    InvalidBand {
        /// Lower bound of θ, degrees.
        min_deg: f64,
        /// Upper bound of θ, degrees.
        max_deg: f64,
        /// Why.
        reason: &'static str,
    },
    /// An input point has a NaN or infinite coordinate.
    #[error("point {index} has a non-finite coordinate (col_px = {col_px}, row_px = {row_px})")]
    NonFinitePoint {
        /// Index of the point in the input slice.
        index: usize,
        /// Its column, pixels.
        col_px: f64,
        /// Its row, pixels.
        row_px: f64,
    },
    /// An input point lies outside the image the workspace was built for.
    #[error(
        "point {index} at (col {col_px}, row {row_px}) px lies outside the {width_px}x{height_px} image"
    )]
    PointOutsideImage {
        /// Index of the point in the input slice.
        index: usize,
        /// Its column, pixels.
        col_px: f64,
        /// Its row, pixels.
        row_px: f64,
        /// Image width, pixels.
        width_px: usize,
        /// Image height, pixels.
        height_px: usize,
    },
    /// An oriented point's normal angle is not a finite angle in `[−90°, 90°)`.
    #[error("point {index} has normal angle {normal_deg}°, not a finite angle in [-90°, 90°)")]
    InvalidNormal {
        /// Index of the point in the input.
        index: usize,
        /// The angle it carried, degrees.
        normal_deg: f64,
    },
    /// Not enough points to go on.
    #[error("too few {set} points: {found} < {required}")]
    TooFewPoints {
        /// Which set was too small.
        set: PointSet,
        /// How many there were.
        found: usize,
        /// How many are required.
        required: usize,
    },
    /// More points than the `u32` vote counters can hold (with the 3×3 peak smoothing, a third
    /// of `u32::MAX`).
    #[error("{found} points exceed the limit of {limit} per Hough call")]
    TooManyPoints {
        /// How many there were.
        found: usize,
        /// The limit.
        limit: usize,
    },
    /// More votes in all than the `u32` vote counters can hold (weighted points,
    /// [`crate::OrientedPoint::votes`]; a third of `u32::MAX`).
    #[error("{found} votes exceed the limit of {limit} per Hough call")]
    TooManyVotes {
        /// How many there were.
        found: u64,
        /// The limit.
        limit: u64,
    },
    /// All fitted points lie on one image row: `x(y)` is undetermined.
    #[error("all {count} fitted points lie on row {row_px} px; x(y) is undetermined")]
    SingleRow {
        /// The common row, pixels.
        row_px: f64,
        /// Number of points.
        count: usize,
    },
    /// The 3×3 normal equations (normalised rows) are numerically singular, e.g. only two
    /// distinct rows.
    #[error(
        "normal equations rank deficient: Cholesky pivot {pivot} ({term}) = {value:e} <= {threshold:e}"
    )]
    RankDeficient {
        /// Pivot index: 0 = constant term, 1 = linear term, 2 = quadratic term.
        pivot: usize,
        /// Name of the regressor the pivot belongs to.
        term: &'static str,
        /// Pivot value after elimination (normalised units, per point).
        value: f64,
        /// Threshold it failed: `MIN_RELATIVE_PIVOT` × the diagonal entry before elimination.
        threshold: f64,
    },
    /// The fit produced a non-finite coefficient (coordinates too large for `f64`).
    #[error("the fit produced a non-finite {what}")]
    NonFiniteResult {
        /// Which quantity.
        what: &'static str,
    },
}
