//! Stage II: Hough line → pixels near it → least-squares parabola.

use serde::{Deserialize, Serialize};

use crate::parabola::{fit_impl, fit_normalised};
use crate::{
    AngleBand, HoughError, HoughLine, HoughWorkspace, LaneInitParams, Parabola, PixelPoint,
    PointSet,
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
    I::Item: PixelPoint,
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
    fit_around_line(points, line, params)
}

/// Steps 3–4 of [`init_lane`] for a given line (e.g. one of
/// [`HoughWorkspace::find_lines`]' candidates): the least-squares parabola of the pixels within
/// `band_px` of `line`, refitted `refit_iterations` times to the pixels within `band_px` of
/// the last fit. Allocation-free.
///
/// # Errors
/// Any [`HoughError`] from the parameters, too few points in the band, or a degenerate fit.
pub fn fit_around_line<I>(
    points: I,
    line: HoughLine,
    params: &LaneInitParams,
) -> Result<LaneInit, HoughError>
where
    I: IntoIterator + Clone,
    I::Item: PixelPoint,
{
    params.validate()?;
    let band_px = params.band_px;
    let (sin_t, cos_t) = line.theta_rad.sin_cos();
    let rho_px = line.rho_px;
    let near_line = |x: f64, y: f64| (x * cos_t + y * sin_t - rho_px).abs() <= band_px;
    // The fits that only select the next one's points skip the residual pass.
    let fit = if params.refit_iterations == 0 {
        fit_impl(
            points.clone(),
            near_line,
            params.min_points,
            PointSet::NearLine,
        )?
    } else {
        let mut p = fit_normalised(
            points.clone(),
            &near_line,
            params.min_points,
            PointSet::NearLine,
        )?
        .parabola()?;
        for _ in 1..params.refit_iterations {
            let near = |x: f64, y: f64| (x - p.col_at_row(y)).abs() <= band_px;
            p = fit_normalised(
                points.clone(),
                &near,
                params.min_points,
                PointSet::NearParabola,
            )?
            .parabola()?;
        }
        fit_impl(
            points.clone(),
            |x, y| (x - p.col_at_row(y)).abs() <= band_px,
            params.min_points,
            PointSet::NearParabola,
        )?
    };
    Ok(LaneInit {
        parabola: fit.parabola,
        line,
        points_used: fit.points_used,
        rms_residual_px: fit.rms_residual_px,
        rows_px: fit.rows_px,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{HoughParams, Point};

    /// `fit_around_line` on a chosen line fits only the pixels of that line: with two marks in
    /// the points, each line gives its own parabola, and `init_lane` equals it on the best line.
    #[test]
    fn fitting_around_a_given_line_keeps_to_that_line() {
        let a = |y: f64| 0.0005 * y * y - 0.8 * y + 250.0;
        let b = |y: f64| -0.4 * y + 120.0;
        let mut pts: Vec<Point> = (100..240)
            .map(|y| Point::new(a(f64::from(y)), f64::from(y)))
            .collect();
        pts.extend((120..200).map(|y| Point::new(b(f64::from(y)), f64::from(y))));
        let mut ws = HoughWorkspace::new(320, 240, HoughParams::default()).unwrap();
        let params = LaneInitParams {
            refit_iterations: 2,
            ..LaneInitParams::default()
        };
        let band = AngleBand::LEFT_LANE;
        let whole = init_lane(&pts, &band, &mut ws, &params).unwrap();
        let again = fit_around_line(&pts, whole.line, &params).unwrap();
        assert_eq!(whole, again);
        assert!((whole.parabola.col_at_row(200.0) - a(200.0)).abs() < 0.5);
        // The weaker line, given explicitly.
        let line_b = HoughLine {
            theta_rad: (0.4f64).atan(),
            rho_px: 120.0 * (0.4f64).atan().cos(),
            votes: 0,
        };
        let fit_b = fit_around_line(&pts, line_b, &params).unwrap();
        assert!(
            (fit_b.parabola.col_at_row(160.0) - b(160.0)).abs() < 0.5,
            "{fit_b:?}"
        );
        assert_eq!(fit_b.points_used, 80);
    }
}
