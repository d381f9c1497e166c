//! Least-squares parabola `x = a1·y² + a2·y + a3` (eq. 1) in normalised row coordinates.

use serde::{Deserialize, Serialize};

use crate::{HoughError, PixelPoint, PointSet};

/// Relative pivot threshold of the 3×3 Cholesky factorisation: pivot `k` fails when, after
/// elimination, it is `≤ MIN_RELATIVE_PIVOT ×` the diagonal entry it started from (a
/// reciprocal condition estimate of that column against the previous ones).
pub const MIN_RELATIVE_PIVOT: f64 = 1e-10;

const TERM_NAMES: [&str; 3] = [
    "constant term, y'^0",
    "linear term, y'^1",
    "quadratic term, y'^2",
];

/// A lane model, eq. 1 of the paper: `x = a1·y² + a2·y + a3`, with `x` the column and `y` the
/// row, both in pixels, origin at the centre of the top-left pixel.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Parabola {
    /// Quadratic coefficient, px⁻¹ (column pixels per row pixel²).
    pub a1: f64,
    /// Linear coefficient, dimensionless (column pixels per row pixel).
    pub a2: f64,
    /// Constant: the column at row 0, pixels.
    pub a3: f64,
}

impl Parabola {
    /// From `[a1, a2, a3]` (the order every lane report and filter uses).
    #[inline]
    #[must_use]
    pub const fn from_coeffs([a1, a2, a3]: [f64; 3]) -> Self {
        Parabola { a1, a2, a3 }
    }

    /// `[a1, a2, a3]`.
    #[inline]
    #[must_use]
    pub const fn coeffs(&self) -> [f64; 3] {
        [self.a1, self.a2, self.a3]
    }

    /// Column `x(y)` at row `row_px`, pixels: the workspace's one evaluation of a lane parabola
    /// in image pixels.
    #[inline]
    #[must_use]
    pub fn col_at_row(&self, row_px: f64) -> f64 {
        (self.a1 * row_px + self.a2) * row_px + self.a3
    }

    /// Slope `dx/dy` at row `row_px` (column pixels per row pixel).
    #[inline]
    #[must_use]
    pub fn slope_at_row(&self, row_px: f64) -> f64 {
        2.0 * self.a1 * row_px + self.a2
    }
}

/// Result of a least-squares parabola fit.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ParabolaFit {
    /// The fitted coefficients, pixel convention of eq. 1.
    pub parabola: Parabola,
    /// Number of points in the fit.
    pub points_used: usize,
    /// Root-mean-square horizontal residual `sqrt(Σ (x_i − x̂(y_i))² / n)`, pixels.
    pub rms_residual_px: f64,
    /// Smallest and largest row among the fitted points, pixels. The model is only supported
    /// on this span; extrapolate with care.
    pub rows_px: (f64, f64),
}

/// Ordinary least-squares fit of eq. 1 to all `points`.
///
/// The rows are normalised internally, `y' = (y − y0)/s` with `y0 = (y_min + y_max)/2` and
/// `s = (y_max − y_min)/2` (so `y' ∈ [−1, 1]`); the 3×3 normal equations in the basis
/// `(1, y', y'²)` are solved by Cholesky with the relative pivot test [`MIN_RELATIVE_PIVOT`],
/// and the coefficients are mapped back to the pixel convention:
/// `a1 = b2/s²`, `a2 = b1/s − 2·b2·y0/s²`, `a3 = b0 − b1·y0/s + b2·y0²/s²`.
///
/// # Errors
/// [`HoughError::NonFinitePoint`] for a NaN/∞ coordinate; [`HoughError::TooFewPoints`] for fewer
/// than 3 points; [`HoughError::SingleRow`] when all rows are equal;
/// [`HoughError::RankDeficient`] (naming the failed pivot) for fewer than three distinct rows or
/// a numerically singular system; [`HoughError::NonFiniteResult`] on overflow.
pub fn fit_parabola<I>(points: I) -> Result<ParabolaFit, HoughError>
where
    I: IntoIterator + Clone,
    I::Item: PixelPoint,
{
    fit_impl(points, |_, _| true, 3, PointSet::Fit)
}

/// [`fit_parabola`] restricted to the points for which `keep(col_px, row_px)` is true, without
/// copying them (e.g. the pixels in a window around a predicted parabola, for re-initialisation).
/// Every point is still checked for finiteness before `keep` sees it.
///
/// # Errors
/// As [`fit_parabola`], counting only the kept points.
pub fn fit_parabola_where<I, F>(points: I, keep: F) -> Result<ParabolaFit, HoughError>
where
    I: IntoIterator + Clone,
    I::Item: PixelPoint,
    F: Fn(f64, f64) -> bool,
{
    fit_impl(points, keep, 3, PointSet::Fit)
}

/// Shared implementation: three passes over `points` (range, normal equations, residuals),
/// no allocation.
pub(crate) fn fit_impl<I, F>(
    points: I,
    keep: F,
    min_points: usize,
    set: PointSet,
) -> Result<ParabolaFit, HoughError>
where
    I: IntoIterator + Clone,
    I::Item: PixelPoint,
    F: Fn(f64, f64) -> bool,
{
    let fit = fit_normalised(points.clone(), &keep, min_points, set)?;
    // Pass 3: residuals, evaluated in the normalised form (better conditioned).
    let mut ss = 0.0f64;
    for p in points {
        let (x, y) = (p.col_px(), p.row_px());
        if !keep(x, y) {
            continue;
        }
        let r = x - fit.col_at_row(y);
        ss += r * r;
    }
    let rms_residual_px = (ss * fit.inv_n).sqrt();
    let parabola = fit.parabola()?;
    if !rms_residual_px.is_finite() {
        return Err(HoughError::NonFiniteResult {
            what: "RMS residual",
        });
    }
    Ok(ParabolaFit {
        parabola,
        points_used: fit.count,
        rms_residual_px,
        rows_px: fit.rows_px,
    })
}

/// A least-squares parabola in the normalised row `u = (y − y0)/s` over the kept points' rows:
/// `x = b0 + b1·u + b2·u²`.
pub(crate) struct NormalisedFit {
    b: [f64; 3],
    y0: f64,
    inv_s: f64,
    inv_n: f64,
    pub(crate) count: usize,
    pub(crate) rows_px: (f64, f64),
}

impl NormalisedFit {
    /// The fitted column at row `y`, evaluated in the normalised form.
    fn col_at_row(&self, y: f64) -> f64 {
        let u = (y - self.y0) * self.inv_s;
        (self.b[2] * u + self.b[1]) * u + self.b[0]
    }

    /// The coefficients in the pixel convention of eq. 1.
    ///
    /// # Errors
    /// [`HoughError::NonFiniteResult`] naming the first coefficient that overflowed.
    pub(crate) fn parabola(&self) -> Result<Parabola, HoughError> {
        let (b, y0, inv_s) = (self.b, self.y0, self.inv_s);
        let inv_s2 = inv_s * inv_s;
        let parabola = Parabola {
            a1: b[2] * inv_s2,
            a2: b[1] * inv_s - 2.0 * b[2] * y0 * inv_s2,
            a3: b[0] - b[1] * y0 * inv_s + b[2] * y0 * y0 * inv_s2,
        };
        for (what, v) in [
            ("coefficient a1", parabola.a1),
            ("coefficient a2", parabola.a2),
            ("coefficient a3", parabola.a3),
        ] {
            if !v.is_finite() {
                return Err(HoughError::NonFiniteResult { what });
            }
        }
        Ok(parabola)
    }
}

/// Passes 1–2 of [`fit_impl`] (range, normal equations), without the residuals: what a fit
/// that only selects the points of the next one needs.
pub(crate) fn fit_normalised<I, F>(
    points: I,
    keep: &F,
    min_points: usize,
    set: PointSet,
) -> Result<NormalisedFit, HoughError>
where
    I: IntoIterator + Clone,
    I::Item: PixelPoint,
    F: Fn(f64, f64) -> bool,
{
    let min_points = min_points.max(3);
    // Pass 1: finiteness, count, row span.
    let mut count = 0usize;
    let mut row_min = f64::INFINITY;
    let mut row_max = f64::NEG_INFINITY;
    for (index, p) in points.clone().into_iter().enumerate() {
        let (x, y) = (p.col_px(), p.row_px());
        if !(x.is_finite() && y.is_finite()) {
            return Err(HoughError::NonFinitePoint {
                index,
                col_px: x,
                row_px: y,
            });
        }
        if keep(x, y) {
            count += 1;
            row_min = row_min.min(y);
            row_max = row_max.max(y);
        }
    }
    if count < min_points {
        return Err(HoughError::TooFewPoints {
            set,
            found: count,
            required: min_points,
        });
    }
    if row_min == row_max {
        return Err(HoughError::SingleRow {
            row_px: row_min,
            count,
        });
    }
    let y0 = 0.5 * (row_min + row_max);
    let s = 0.5 * (row_max - row_min);
    let inv_s = 1.0 / s;

    // Pass 2: normal equations in (1, y', y'^2), averaged over the points.
    let mut sy = [0.0f64; 5]; // Σ y'^k, k = 0..4
    let mut sxy = [0.0f64; 3]; // Σ x·y'^k, k = 0..2
    for p in points.clone() {
        let (x, y) = (p.col_px(), p.row_px());
        if !keep(x, y) {
            continue;
        }
        let u = (y - y0) * inv_s;
        let u2 = u * u;
        sy[0] += 1.0;
        sy[1] += u;
        sy[2] += u2;
        sy[3] += u2 * u;
        sy[4] += u2 * u2;
        sxy[0] += x;
        sxy[1] += x * u;
        sxy[2] += x * u2;
    }
    let inv_n = 1.0 / sy[0];
    let m = [
        [sy[0] * inv_n, sy[1] * inv_n, sy[2] * inv_n],
        [sy[1] * inv_n, sy[2] * inv_n, sy[3] * inv_n],
        [sy[2] * inv_n, sy[3] * inv_n, sy[4] * inv_n],
    ];
    let rhs = [sxy[0] * inv_n, sxy[1] * inv_n, sxy[2] * inv_n];
    let b = solve_spd3(&m, &rhs)?;
    Ok(NormalisedFit {
        b,
        y0,
        inv_s,
        inv_n,
        count,
        rows_px: (row_min, row_max),
    })
}

/// Solve `m·b = rhs` for a symmetric positive-definite 3×3 `m` by the workspace's Cholesky
/// (`spd-linalg`) with the relative pivot test [`MIN_RELATIVE_PIVOT`].
fn solve_spd3(m: &[[f64; 3]; 3], rhs: &[f64; 3]) -> Result<[f64; 3], HoughError> {
    let mat = nalgebra::Matrix3::from_fn(|i, j| m[i][j]);
    let chol =
        spd_linalg::Cholesky::with_relative_floor(&mat, "normal equations", MIN_RELATIVE_PIVOT)
            .map_err(|e| HoughError::RankDeficient {
                pivot: e.pivot,
                term: TERM_NAMES[e.pivot.min(2)],
                value: e.value,
                threshold: e.floor,
            })?;
    let b = chol.solve(&nalgebra::Vector3::new(rhs[0], rhs[1], rhs[2]));
    Ok([b[0], b[1], b[2]])
}
