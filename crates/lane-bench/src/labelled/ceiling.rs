//! The **ceiling** of the lane model: the label lanes themselves as parabolas, scored by the
//! same rules as the tracker — what a perfect tracker with this model would reach.
//!
//! Each ego label lane of a frame is replaced by the least-squares parabola
//! `x = a1·y² + a2·y + a3` of its points, fitted in the row coordinate `u = y − ȳ` centred on
//! the points' mean row `ȳ` (the 3×3 normal equations `Σ φφᵀ c = Σ φ x`, `φ = (u², u, 1)`,
//! solved by Cholesky) and expanded back in `y`:
//! `a1 = c0`, `a2 = c1 − 2·c0·ȳ`, `a3 = c0·ȳ² − c1·ȳ + c2`. Its row extent is that of the points
//! it was fitted on.
//!
//! - [`ceiling_prediction`] fits the points on the tracker's region-of-interest rows: the near
//!   band's ceiling (the `ceiling` rows of `eval-lanes`), what the model reaches on the rows the
//!   tracker looks at;
//! - [`whole_label_ceiling`] fits every point of the label: the full rule's ceiling
//!   (`ceiling-whole-label`), the model's own bound on the whole labelled lane (a parabola
//!   cannot follow a lane whose curvature changes along it; no row is cut).

use super::{EgoPrediction, LabelFrame, LabelSide, PredictedLane};

/// The near band's ceiling (module docs): for each ego label lane of `frame`, the
/// least-squares parabola of its points on the rows `[top, bottom)` (the tracker's region of
/// interest), its extent the rows of those points; `None` with fewer than 3 such points or a
/// degenerate fit. It says what a perfect tracker with this model and this ROI would reach:
/// the labels themselves, bent to a parabola and cut to the rows the tracker looks at.
pub fn ceiling_prediction(frame: &LabelFrame, (top, bottom): (usize, usize)) -> EgoPrediction {
    ego_fits(frame, |p| p[1] >= top as f64 && p[1] < bottom as f64)
}

/// The full rule's ceiling (module docs): for each ego label lane of `frame`, the
/// least-squares parabola of all its points, its extent their rows; `None` with fewer than 3
/// points or a degenerate fit.
pub fn whole_label_ceiling(frame: &LabelFrame) -> EgoPrediction {
    ego_fits(frame, |_| true)
}

/// Per ego side, the parabola of the first label lane of that side over its points that
/// `keep` accepts.
fn ego_fits(frame: &LabelFrame, keep: impl Fn(&[f64; 2]) -> bool + Copy) -> EgoPrediction {
    let mut out: EgoPrediction = [None, None];
    for (k, side) in [LabelSide::Left, LabelSide::Right].into_iter().enumerate() {
        let Some(lane) = frame.lanes.iter().find(|l| l.side == side) else {
            continue;
        };
        out[k] = fit_parabola(&lane.points, keep);
    }
    out
}

/// Least-squares parabola `x(y)` of the points `keep` accepts, centred on their mean row for
/// conditioning, with the rows of those points as its extent; `None` for fewer than 3 points
/// or a singular system.
fn fit_parabola(points: &[[f64; 2]], keep: impl Fn(&[f64; 2]) -> bool) -> Option<PredictedLane> {
    let inside = || points.iter().filter(|p| keep(p));
    let n = inside().count();
    if n < 3 {
        return None;
    }
    let yc = inside().map(|p| p[1]).sum::<f64>() / n as f64;
    let mut a = nalgebra::Matrix3::<f64>::zeros();
    let mut b = nalgebra::Vector3::<f64>::zeros();
    let mut rows_px = [f64::INFINITY, f64::NEG_INFINITY];
    for p in inside() {
        let u = p[1] - yc;
        let phi = nalgebra::Vector3::new(u * u, u, 1.0);
        a += phi * phi.transpose();
        b += phi * p[0];
        rows_px = [rows_px[0].min(p[1]), rows_px[1].max(p[1])];
    }
    let c = a.cholesky()?.solve(&b);
    // x = c0·(y − yc)² + c1·(y − yc) + c2, expanded in y.
    let coeffs = [
        c[0],
        c[1] - 2.0 * c[0] * yc,
        c[0] * yc * yc - c[1] * yc + c[2],
    ];
    coeffs
        .iter()
        .all(|v| v.is_finite())
        .then_some(PredictedLane {
            coeffs,
            rows_px,
            far: None,
        })
}
