//! Stage II: Hough line → pixels near it → least-squares parabola.

use std::convert::Infallible;

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
    // Every intermediate parabola is accepted.
    match fit_around_line_checked(points, line, params, |_| Ok::<(), Infallible>(()))? {
        Ok(fit) => Ok(fit),
        Err(never) => match never {},
    }
}

/// [`fit_around_line`] on a subset of the points, when the caller can tell that it gives the
/// same result as on all of them. Each selection of the fit keeps the points within `h` columns
/// of a curve `c` — the line first (`c(y) = ρ/cos θ − y·tan θ`, `h = band_px / |cos θ|`,
/// equivalent to its perpendicular band), then each intermediate parabola (`h = band_px`) —
/// and before each one `complete(&c, h)` is asked whether `points` hold every point of the full
/// set within `h` of `c` (with a margin for rounding: the test here is on the perpendicular
/// distance for the line). If it says so each time, the sums run over the same points in the
/// same order as on the full set (`points` in their order there), and the result is equal bit
/// for bit; `Ok(None)` as soon as it does not (the caller fits the full set instead), and for a
/// line within [`MIN_WHERE_COS`] of horizontal in its normal's cosine (its columns per row are
/// too large for the test to be exact).
///
/// # Errors
/// As [`fit_around_line`] on the full set, but [`HoughError::NonFinitePoint`] is only found
/// among `points` (and indexed there).
pub fn fit_around_line_where<I, C>(
    points: I,
    line: HoughLine,
    params: &LaneInitParams,
    complete: C,
) -> Result<Option<LaneInit>, HoughError>
where
    I: IntoIterator + Clone,
    I::Item: PixelPoint,
    C: Fn(&Parabola, f64) -> bool,
{
    let Some((line_curve, cos_abs)) = line.columns(MIN_WHERE_COS) else {
        return Ok(None);
    };
    if !complete(&line_curve, params.band_px / cos_abs) {
        return Ok(None);
    }
    let accept = |p: &Parabola| complete(p, params.band_px).then_some(()).ok_or(());
    Ok(fit_around_line_checked(points, line, params, accept)?.ok())
}

/// Least `|cos θ|` of a line [`fit_around_line_where`] fits on a subset: nearer to horizontal,
/// the line's columns (`ρ/cos θ`, `y·tan θ`) carry rounding errors that the completeness
/// test's half-pixel margin may not cover.
pub const MIN_WHERE_COS: f64 = 1e-6;

/// [`fit_around_line`] with `accept` asked about each intermediate parabola before the pixels
/// near it are selected: `Ok(Err(e))` as soon as it refuses one with `e`.
fn fit_around_line_checked<I, A, E>(
    points: I,
    line: HoughLine,
    params: &LaneInitParams,
    accept: A,
) -> Result<Result<LaneInit, E>, HoughError>
where
    I: IntoIterator + Clone,
    I::Item: PixelPoint,
    A: Fn(&Parabola) -> Result<(), E>,
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
            if let Err(e) = accept(&p) {
                return Ok(Err(e));
            }
            let near = |x: f64, y: f64| (x - p.col_at_row(y)).abs() <= band_px;
            p = fit_normalised(
                points.clone(),
                &near,
                params.min_points,
                PointSet::NearParabola,
            )?
            .parabola()?;
        }
        if let Err(e) = accept(&p) {
            return Ok(Err(e));
        }
        fit_impl(
            points.clone(),
            |x, y| (x - p.col_at_row(y)).abs() <= band_px,
            params.min_points,
            PointSet::NearParabola,
        )?
    };
    Ok(Ok(LaneInit {
        parabola: fit.parabola,
        line,
        points_used: fit.points_used,
        rms_residual_px: fit.rms_residual_px,
        rows_px: fit.rows_px,
    }))
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

    /// `fit_around_line_where` on the points within a reach of the line, asked about each
    /// selection against the points left out, equals `fit_around_line` on all points bit for
    /// bit whenever it gives a result; it gives none when a selection would reach a point left
    /// out; and with nothing left out it always gives one. Seeded random scenes: a curved mark,
    /// a second mark, uniform clutter, lines near the mark.
    #[test]
    fn a_fit_on_the_points_near_its_line_equals_the_fit_on_all_of_them() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let params = LaneInitParams {
            refit_iterations: 2,
            min_points: 10,
            ..LaneInitParams::default()
        };
        let (mut subset_fits, mut refused) = (0, 0);
        for _ in 0..300 {
            let (a1, a2, a3) = (
                rng.random_range(-0.002..0.002),
                rng.random_range(-1.0..1.0),
                rng.random_range(60.0..260.0),
            );
            let mark = |y: f64| a1 * (y - 190.0) * (y - 190.0) + a2 * (y - 190.0) + a3;
            let mut pts: Vec<Point> = Vec::new();
            for y in 140..240 {
                let y = f64::from(y);
                if rng.random_bool(0.7) {
                    pts.push(Point::new(
                        (mark(y) + rng.random_range(-1.5..1.5)).round(),
                        y,
                    ));
                }
                if rng.random_bool(0.3) {
                    pts.push(Point::new((mark(y) + 9.0).round(), y)); // a second edge
                }
                for _ in 0..3 {
                    pts.push(Point::new(f64::from(rng.random_range(0..320u16)), y));
                }
            }
            // A line through the mark at rows 160 and 220, perturbed.
            let (y0, y1) = (160.0, 220.0);
            let (x0, x1) = (
                mark(y0) + rng.random_range(-3.0..3.0),
                mark(y1) + rng.random_range(-3.0..3.0),
            );
            let tan = (x1 - x0) / (y1 - y0); // x = x0 + tan·(y − y0)
            let theta = (-tan).atan(); // normal angle: x cos θ + y sin θ = ρ
            let rho = x0 * theta.cos() + y0 * theta.sin();
            let line = HoughLine {
                rho_px: rho,
                theta_rad: theta,
                votes: 0,
            };
            let line_col = |y: f64| (rho - y * theta.sin()) / theta.cos();
            let reach = params.band_px / theta.cos().abs() + rng.random_range(0.0..30.0);
            let (near, left_out): (Vec<Point>, Vec<Point>) = pts
                .iter()
                .partition(|p| (p.col_px - line_col(p.row_px)).abs() <= reach);
            let complete = |c: &Parabola, h: f64| {
                left_out
                    .iter()
                    .all(|p| (p.col_px - c.col_at_row(p.row_px)).abs() > h + 0.5)
            };
            let full = fit_around_line(&pts, line, &params);
            match fit_around_line_where(&near, line, &params, complete) {
                Ok(Some(fit)) => {
                    assert_eq!(Ok(fit), full);
                    subset_fits += 1;
                }
                Ok(None) => refused += 1,
                Err(e) => assert_eq!(Err(e), full),
            }
            // With nothing left out, every selection is complete.
            let all = fit_around_line_where(&pts, line, &params, |_, _| true);
            assert_eq!(all.map(|f| f.ok_or(())), full.map(Ok));
        }
        assert!(
            subset_fits > 100 && refused > 10,
            "{subset_fits} / {refused}"
        );
    }

    /// The completeness test is asked about the line first, with its band in columns, then
    /// about each intermediate parabola with `band_px`; a refusal at any of them gives no fit.
    #[test]
    fn the_completeness_test_is_asked_before_each_selection() {
        let pts: Vec<Point> = (100..200)
            .map(|y| Point::new(150.0 - 0.5 * f64::from(y - 100), f64::from(y)))
            .collect();
        let theta = 0.5f64.atan(); // x = 150 − 0.5·(y − 100) ⟺ x cos θ + y sin θ = ρ
        let line = HoughLine {
            rho_px: 150.0 * theta.cos() + 100.0 * theta.sin(),
            theta_rad: theta,
            votes: 0,
        };
        let params = LaneInitParams {
            refit_iterations: 2,
            ..LaneInitParams::default()
        };
        let asked = std::cell::RefCell::new(Vec::new());
        let fit = fit_around_line_where(&pts, line, &params, |c, h| {
            asked.borrow_mut().push((c.col_at_row(100.0), h));
            true
        });
        assert!(matches!(fit, Ok(Some(_))));
        let asked = asked.into_inner();
        assert_eq!(asked.len(), 1 + params.refit_iterations as usize);
        assert!((asked[0].0 - 150.0).abs() < 1e-9);
        assert!((asked[0].1 - params.band_px / theta.cos()).abs() < 1e-12);
        assert!(asked[1..].iter().all(|&(_, h)| h == params.band_px));
        // A horizontal line (cos θ = 6e-17): no subset fit, whatever the test says.
        let flat = HoughLine {
            rho_px: 150.0,
            theta_rad: std::f64::consts::FRAC_PI_2,
            votes: 0,
        };
        assert_eq!(
            fit_around_line_where(&pts, flat, &params, |_, _| true),
            Ok(None)
        );
        for refuse_at in 0..=params.refit_iterations {
            let calls = std::cell::Cell::new(0);
            let fit = fit_around_line_where(&pts, line, &params, |_, _| {
                calls.set(calls.get() + 1);
                calls.get() <= refuse_at
            });
            assert_eq!(fit, Ok(None), "refused at call {refuse_at}");
        }
    }
}
