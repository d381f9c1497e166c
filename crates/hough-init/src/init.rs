//! Stage II: Hough line → pixels near it → least-squares parabola.

use serde::{Deserialize, Serialize};

use crate::parabola::fit_impl;
use crate::{
    AngleBand, EdgePoint, HoughError, HoughLine, HoughWorkspace, LaneInitParams, Parabola, PointSet,
};

/// A lane initialisation: the parabola of eq. 1 fitted to the pixels near the Hough line.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LaneInit {
    /// Fitted coefficients, pixel convention of eq. 1.
    pub parabola: Parabola,
    /// The Hough peak line the fitted pixels were selected around.
    pub line: HoughLine,
    /// Number of pixels in the (last) least-squares fit.
    pub points_used: usize,
    /// RMS horizontal residual of the fit, pixels.
    pub rms_residual_px: f64,
    /// Smallest and largest fitted row, pixels.
    pub rows_px: (f64, f64),
}

/// Initialise one lane from its candidate edge pixels.
///
/// 1. at least `params.min_points` candidates are required;
/// 2. [`HoughWorkspace::find_line`] over `band` gives the line `ρ = x cos θ + y sin θ`;
/// 3. the pixels with `|x cos θ + y sin θ − ρ| ≤ band_px` (at least `min_points` of them) are
///    fitted by [`crate::fit_parabola`]'s least squares;
/// 4. optionally (`refit_iterations`), the pixels with `|x − x̂(y)| ≤ band_px` around the
///    fitted parabola are refitted.
///
/// Allocation-free once `workspace` exists.
///
/// # Errors
/// Any [`HoughError`] from the parameters, the band, the points (non-finite, outside the
/// workspace's image), too few points at any stage, or a degenerate fit.
pub fn init_lane<I>(
    points: I,
    band: &AngleBand,
    workspace: &mut HoughWorkspace,
    params: &LaneInitParams,
) -> Result<LaneInit, HoughError>
where
    I: IntoIterator + Clone,
    I::Item: EdgePoint,
{
    params.validate()?;
    let count = points.clone().into_iter().count();
    if count < params.min_points {
        return Err(HoughError::TooFewPoints {
            set: PointSet::Candidates,
            found: count,
            required: params.min_points,
        });
    }
    let line = workspace.find_line(points.clone(), band)?;
    let band_px = params.band_px;
    let (sin_t, cos_t) = line.theta_rad.sin_cos();
    let rho_px = line.rho_px;
    let mut fit = fit_impl(
        points.clone(),
        |x, y| (x * cos_t + y * sin_t - rho_px).abs() <= band_px,
        params.min_points,
        PointSet::NearLine,
    )?;
    for _ in 0..params.refit_iterations {
        let p = fit.parabola;
        fit = fit_impl(
            points.clone(),
            |x, y| (x - p.col_at_row(y)).abs() <= band_px,
            params.min_points,
            PointSet::NearParabola,
        )?;
    }
    Ok(LaneInit {
        parabola: fit.parabola,
        line,
        points_used: fit.points_used,
        rms_residual_px: fit.rms_residual_px,
        rows_px: fit.rows_px,
    })
}
