//! No turn back between a lane's evidence and the camera (an addition beyond the paper;
//! `init.no_turn_back`).
//!
//! The lane model `x = a1·y² + a2·y + a3` has its vertex — the row where its image tangent is
//! vertical, `x′(y) = 2·a1·y + a2 = 0` — at
//!
//! ```text
//!     y_v = −a2 / (2·a1)        (a1 ≠ 0)
//! ```
//!
//! and on either side of it the lane runs back the way it came. A forward camera sees a lane
//! turn like that where the road bends ahead of it: a vertex among the rows of the lane's
//! points, or above them, is a bend the image shows. Below the lowest row of the points
//! (`y_max`) and down to the bottom row searched, nothing was measured: a vertex there, inside
//! the image's columns, is the parabola carrying the curvature of its evidence on into a hook
//! that the image does not show — on the development part, a dash or a line seen over the
//! upper rows whose parabola bends back below it, on the near misses among such lanes 5–39 px
//! off its tangent at the bottom row, where the labelled lane runs on along its course
//! (`docs/lanes/history/no-turn-back.md`).
//!
//! After an initialisation's windowed refinement, a lane whose vertex lies in `(y_max, y_b]`
//! (`y_b` the bottom row searched) at a column inside the image is therefore replaced by the
//! least-squares line through the refinement's points (and, with `init.stripe_trace`, the
//! stripe's middles traced after it, each weighing as in the trace's update, `w_i = 4`; the
//! edge pixels `w_i = 1`; `y_max` their lowest row), which carries the evidence on along its
//! course:
//!
//! ```text
//!     x = x̄ + β·(y − ȳ),    β = Σ w_i (y_i − ȳ)(x_i − x̄) / Σ w_i (y_i − ȳ)²
//! ```
//!
//! (`x̄`, `ȳ` the weighted means of the points), i.e. `(a1, a2, a3) = (0, β, x̄ − β·ȳ)`; the filter
//! restarts from it with `P0`, as after the double line's middle. A vertex beyond the bottom
//! row, outside the image's columns (the lane has left the image before it turns) or at or
//! above the lowest point leaves the lane as it is. Tracked frames keep the filter's estimate
//! (the paper's).

use nalgebra::Vector3;

use super::lane::{Health, Lane};
use super::report::{LaneState, Side};
use super::setup::{Rows, Setup};

/// The least-squares line `(a2, a3)` of `x = a2·y + a3` through `points` (`(col, row)`, px;
/// point `i` weighing `weights[i]`, 1 where `weights` has none, as in the lane's row profile)
/// when the parabola `coeffs = [a1, a2, a3]` turns back below them: its vertex lies below the
/// lowest point's row and at or above `bottom_row_px`, at a column in `[0, width_px)` (module
/// docs). `None` when it does not, or when the points span a single row (no line through
/// them), are not finite or weigh nothing.
pub(super) fn turn_back_line(
    coeffs: [f64; 3],
    points: &[(f32, f32)],
    weights: &[f64],
    bottom_row_px: f64,
    width_px: f64,
) -> Option<(f64, f64)> {
    let [a1, a2, a3] = coeffs;
    // A straight estimate has no vertex. (A non-finite `a1` needs no test of its own: its
    // vertex row is 0 or NaN, never below the points' rows.)
    if a1 == 0.0 {
        return None;
    }
    let lowest_row_px = points
        .iter()
        .map(|p| f64::from(p.1))
        .fold(f64::NEG_INFINITY, f64::max);
    let vertex_row_px = -a2 / (2.0 * a1);
    let vertex_col_px = (a1 * vertex_row_px + a2) * vertex_row_px + a3;
    // (False for NaN: a non-finite vertex or point leaves the lane as it is.)
    let turns = vertex_row_px > lowest_row_px
        && vertex_row_px <= bottom_row_px
        && vertex_col_px >= 0.0
        && vertex_col_px < width_px;
    if !turns {
        return None;
    }
    let weight = |i: usize| weights.get(i).copied().unwrap_or(1.0);
    let total: f64 = (0..points.len()).map(weight).sum();
    let (mean_x, mean_y) = points
        .iter()
        .enumerate()
        .fold((0.0, 0.0), |(sx, sy), (i, p)| {
            let w = weight(i) / total;
            (sx + w * f64::from(p.0), sy + w * f64::from(p.1))
        });
    let (mut syy, mut sxy) = (0.0, 0.0);
    for (i, p) in points.iter().enumerate() {
        let (dx, dy) = (f64::from(p.0) - mean_x, f64::from(p.1) - mean_y);
        syy += weight(i) * dy * dy;
        sxy += weight(i) * dx * dy;
    }
    // (False for NaN too: points on one row, or not finite, determine no line.)
    (syy > 0.0)
        .then(|| {
            let slope = sxy / syy;
            (slope, mean_x - slope * mean_y)
        })
        .filter(|(slope, col_at_row_0)| slope.is_finite() && col_at_row_0.is_finite())
}

/// The estimate of the lane on `side` replaced by the least-squares line through its
/// refinement's points (and traced middles) when it turns back below them (module docs); the
/// bottom of `rows` is the lowest row searched. Returns whether it was replaced. Only a lane
/// whose last refinement pass updated it (tracking: a pass that misses leaves it coasting or
/// lost) is read, so its points are that update's and, with `init.stripe_trace`, the stripe's
/// middles traced after it, weighing as in the trace's update (module `stripe_trace`): evidence
/// as far down as the trace reached.
pub(super) fn straighten_turn_back(
    lane: &mut Lane,
    side: Side,
    rows: Rows,
    setup: &Setup,
    health: &mut Health,
) -> bool {
    if lane.state != LaneState::Tracking || !lane.updated_now {
        return false;
    }
    let Some(coeffs) = lane.filter.as_ref().map(|f| f.coeffs()) else {
        return false;
    };
    let bottom_row_px = rows.1.saturating_sub(1) as f64;
    let Some((a2, a3)) = turn_back_line(
        coeffs,
        &lane.points,
        &lane.weights,
        bottom_row_px,
        setup.width as f64,
    ) else {
        return false;
    };
    lane.restart_filter(side, &Vector3::new(0.0, a2, a3), setup, health)
}

#[cfg(test)]
mod tests {
    use super::turn_back_line;

    /// Points along `x = col(y)` on rows `rows`.
    fn along(col: impl Fn(f64) -> f64, rows: std::ops::Range<u16>) -> Vec<(f32, f32)> {
        rows.map(|y| (col(f64::from(y)) as f32, f32::from(y)))
            .collect()
    }

    /// A parabola through points on rows 100–139 whose vertex falls at row 160 (inside the
    /// image, above the bottom row 179) is replaced by the least-squares line through the
    /// points; the points of a straight mark give that line back exactly.
    #[test]
    fn a_parabola_turning_back_below_its_points_becomes_their_line() {
        // x = 0.05·(y − 160)² + 100: vertex (160, 100).
        let coeffs = [0.05, -16.0, 0.05 * 160.0 * 160.0 + 100.0];
        let straight = along(|y| 300.0 - 1.5 * y, 100..140);
        let (a2, a3) = turn_back_line(coeffs, &straight, &[], 179.0, 320.0).expect("turns back");
        assert!(
            (a2 + 1.5).abs() < 1e-9 && (a3 - 300.0).abs() < 1e-6,
            "{a2} {a3}"
        );
        // Noisy points: the line is their least-squares line (normal equations, uncentred).
        let noisy: Vec<(f32, f32)> = straight
            .iter()
            .enumerate()
            .map(|(k, &(x, y))| (x + [0.5, -0.5, 1.0, -1.0][k % 4], y))
            .collect();
        let (a2, a3) = turn_back_line(coeffs, &noisy, &[], 179.0, 320.0).expect("turns back");
        let n = noisy.len() as f64;
        let (sx, sy, syy, sxy) = noisy.iter().fold((0.0, 0.0, 0.0, 0.0), |s, &(x, y)| {
            let (x, y) = (f64::from(x), f64::from(y));
            (s.0 + x, s.1 + y, s.2 + y * y, s.3 + x * y)
        });
        let slope = (n * sxy - sx * sy) / (n * syy - sy * sy);
        let icpt = (sx - slope * sy) / n;
        assert!((a2 - slope).abs() < 1e-9 && (a3 - icpt).abs() < 1e-6);
    }

    /// The parabola is kept where its vertex is a bend the points show or one beyond what is
    /// searched or seen: among or above the points' rows, below the bottom row, or outside
    /// the image's columns; a straight estimate has no vertex.
    #[test]
    fn a_vertex_among_above_or_beyond_the_rows_searched_or_outside_the_image_is_kept() {
        let points = along(|y| 300.0 - 1.5 * y, 100..140);
        let vertex_at = |row: f64, col: f64| [0.05, -0.1 * row, 0.05 * row * row + col];
        for (row, col, why) in [
            (120.0, 100.0, "among the points"),
            (139.0, 100.0, "at the lowest point"),
            (90.0, 100.0, "above the points"),
            (185.0, 100.0, "below the bottom row"),
            (160.0, -3.0, "left of the image"),
            (160.0, 320.0, "right of the image"),
        ] {
            assert_eq!(
                turn_back_line(vertex_at(row, col), &points, &[], 179.0, 320.0),
                None,
                "{why}"
            );
        }
        assert_eq!(
            turn_back_line([0.0, -1.5, 300.0], &points, &[], 179.0, 320.0),
            None
        );
        // Just inside each bound, it turns back.
        for (row, col) in [(139.5, 100.0), (179.0, 100.0), (160.0, 0.0), (160.0, 319.9)] {
            assert!(
                turn_back_line(vertex_at(row, col), &points, &[], 179.0, 320.0).is_some(),
                "vertex ({row}, {col})"
            );
        }
    }

    /// Points on one row determine no line; a non-finite point or estimate changes nothing.
    #[test]
    fn points_on_one_row_or_not_finite_leave_the_lane_as_it_is() {
        let vertex_160 = [0.05, -16.0, 0.05 * 160.0 * 160.0 + 100.0];
        let one_row: Vec<(f32, f32)> = (0..20).map(|k| (100.0 + k as f32, 120.0)).collect();
        assert_eq!(
            turn_back_line(vertex_160, &one_row, &[], 179.0, 320.0),
            None
        );
        let mut bad = along(|y| 300.0 - 1.5 * y, 100..140);
        bad[3].0 = f32::NAN;
        assert_eq!(turn_back_line(vertex_160, &bad, &[], 179.0, 320.0), None);
        let points = along(|y| 300.0 - 1.5 * y, 100..140);
        assert_eq!(
            turn_back_line([f64::NAN, -16.0, 1380.0], &points, &[], 179.0, 320.0),
            None
        );
        assert_eq!(turn_back_line(vertex_160, &[], &[], 179.0, 320.0), None);
    }
}
