//! A kerb's foot as the boundary (an addition beyond the paper; `init.kerb_foot`).
//!
//! Where a raised kerb bounds the road, the strongest edge across it is the kerb's top edge:
//! the pavement on one side, the kerb's face on the other. Seen from the road at a slant, the
//! face is a band a few pixels wide on the road side of that edge, darker or lighter than the
//! road, often with a dark groove at its foot. The road ends at the foot, and lane labels put
//! the boundary there, while the Hough line and the windows lock onto the top edge. After a
//! fresh initialisation and its refinement (and the double line's middle, when that did not
//! move it), every row `y` of the rows searched is read across the lane's estimate `x̂(y)`,
//! grey levels `I(x)`, with `d = −1` for the left lane and `+1` for the right one (the side
//! the road does not lie on) and the gradient towards that side `g(x) = I(x + d) − I(x − d)`:
//!
//! 1. the step: `x_s`, the column of the largest `|g|` within ±[`STEP_REACH_PX`] of `x̂(y)`;
//!    its outer level `o = I(x_s + 2d)` and inner level `n = I(x_s − 2d)` differ by at least
//!    [`MIN_STEP_CONTRAST`] grey levels; `h = (o + n)/2`, `σ = sign(o − n)`;
//! 2. not a mark: the outer side stays past `h` (`σ·(I − h) ≥ 0`) from `x_s + 2d` over
//!    `2·w_max` px (`w_max = gradient.stripe_max_width_px`) or up to the image's edge — a
//!    pavement, not a painted line or a tape;
//! 3. the foot: `x_f`, the column of the largest `σ·g` between `3` and `w_max` px on the road
//!    side of `x_s` (the same polarity as the step: the rise out of the groove, or from the
//!    road onto a lighter face), at least [`MIN_FOOT_GRADIENT`] grey levels and
//!    [`MIN_FOOT_RATIO`] of `|g(x_s)|`;
//! 4. the face: every pixel from `x_s − 2d` to `x_f` stays on the inner side of `h`;
//! 5. the row gives `t(y) = x_f − x̂(y)`.
//!
//! The lane is bounded by a kerb if at least [`MIN_ROW_FRACTION`] of its rows inside the image
//! give a foot that agrees with `t(y) ≈ α + β·y` (least squares, refitted twice on the rows
//! within [`INLIER_PX`] of the last fit: the face widens towards the camera, linearly in `y`
//! on a straight road). The lane's reported boundary then moves to the foot, `(a1, a2 + β,
//! a3 + α)`, while its filter keeps tracking the top edge — the edge its windows measure; a
//! filter restarted at the foot would be pulled back to it over the next frames — with the
//! offset kept until the lane's next initialisation. No allocation (the rows' offsets go to a
//! buffer of the image's height).
//!
//! On the labelled `f1tenth` set (a scale-model city with raised kerbs) the labels of a kerb
//! lie on its foot in most frames and on its top edge in some (no face visible to the
//! labeller); measured on the development part, the rule moves 20 lanes onto their labels and
//! 8 off them (README, "Lanes on real data").

use hough_init::Parabola;
use vision_gradient::GreyImage;

use super::LaneTracker;

/// How far from the estimate the step is looked for, px.
const STEP_REACH_PX: i64 = 3;
/// Least grey-level difference across the step.
const MIN_STEP_CONTRAST: f64 = 20.0;
/// Least gradient `σ·g` of the foot, grey levels.
const MIN_FOOT_GRADIENT: f64 = 6.0;
/// Least gradient of the foot relative to the step's.
const MIN_FOOT_RATIO: f64 = 0.15;
/// Least fraction of the rows inside the image whose foot agrees with the fit.
const MIN_ROW_FRACTION: f64 = 0.3;
/// A row's foot agrees with the fit within this many pixels.
const INLIER_PX: f64 = 1.5;

/// Row `row`'s kerb foot relative to `x_hat` for a boundary whose outer side is towards `dir`
/// (`±1`), steps 1–5 of the module docs; `None` if the row shows no kerb.
pub(super) fn kerb_foot(row: &[u8], x_hat: f64, dir: i64, max_width_px: i64) -> Option<f64> {
    let w = row.len() as i64;
    let at = |x: i64| (0..w).contains(&x).then(|| f64::from(row[x as usize]));
    let g = |x: i64| Some(at(x + dir)? - at(x - dir)?);
    let x0 = x_hat.round();
    if !x0.is_finite() {
        return None;
    }
    let x0 = x0 as i64;
    let (mut xs, mut gs) = (None, 0.0f64);
    for x in x0 - STEP_REACH_PX..=x0 + STEP_REACH_PX {
        if let Some(v) = g(x).filter(|v| v.abs() > gs.abs()) {
            (xs, gs) = (Some(x), v);
        }
    }
    let xs = xs?;
    let (outer, inner) = (at(xs + 2 * dir)?, at(xs - 2 * dir)?);
    if (outer - inner).abs() < MIN_STEP_CONTRAST {
        return None;
    }
    let half = 0.5 * (outer + inner);
    let sign = (outer - inner).signum();
    // 2. A pavement, not a mark: the outer side stays past the half level.
    for k in 2..=2 * max_width_px {
        match at(xs + k * dir) {
            Some(v) if (v - half) * sign < 0.0 => return None,
            Some(_) => {}
            None => break,
        }
    }
    // 3. The foot: the strongest gradient of the step's polarity on the road side.
    let (mut xf, mut gf) = (None, 0.0f64);
    for k in 3..=max_width_px {
        let x = xs - k * dir;
        let v = g(x)? * sign;
        if v > gf {
            (xf, gf) = (Some(x), v);
        }
    }
    let xf = xf?;
    if gf < MIN_FOOT_GRADIENT || gf < MIN_FOOT_RATIO * gs.abs() {
        return None;
    }
    // 4. The face stays on the inner side of the half level.
    let mut x = xs - 2 * dir;
    while x != xf {
        if (at(x)? - half) * sign > 0.0 {
            return None;
        }
        x -= dir;
    }
    Some(xf as f64 - x_hat)
}

/// `(α, β)` of `t ≈ α + β·y` by least squares over `rows` `(y, t)` within `INLIER_PX` of
/// `fit` (all of them without one), and how many there were; `None` if they do not
/// determine it.
fn line_fit(rows: &[(f64, f64)], fit: Option<(f64, f64)>) -> Option<((f64, f64), usize)> {
    let (mut n, mut sy, mut syy, mut st, mut sty) = (0usize, 0.0, 0.0, 0.0, 0.0);
    for &(y, t) in rows {
        if fit.is_some_and(|(a, b)| (t - a - b * y).abs() > INLIER_PX) {
            continue;
        }
        n += 1;
        sy += y;
        syy += y * y;
        st += t;
        sty += t * y;
    }
    let nf = n as f64;
    let det = nf * syy - sy * sy;
    if n < 2 || det.abs() < 1e-9 {
        return None;
    }
    let beta = (nf * sty - sy * st) / det;
    Some((((st - beta * sy) / nf, beta), n))
}

impl LaneTracker {
    /// Lane `i`'s reported boundary moved to the foot of a kerb, if its rows show one (module
    /// docs; the filter keeps the top edge); over the rows `self.search_rows`. Returns whether
    /// it moved.
    pub(super) fn onto_kerb_foot(&mut self, i: usize, image: &GreyImage<'_>) -> bool {
        let Some(c) = self.lanes[i].filter.as_ref().map(|f| f.coeffs()) else {
            return false;
        };
        let p = Parabola::from_coeffs(c);
        let (top, bottom) = self.search_rows;
        let max_width_px = i64::from(self.cfg.gradient.stripe_max_width_px.max(1));
        let dir = if i == 0 { -1 } else { 1 };
        let feet = &mut self.kerb_rows;
        feet.clear();
        let mut inside = 0usize;
        for y in top..bottom {
            let Some(row) = image.row(y) else { continue };
            let x = p.col_at_row(y as f64);
            if !(0.0..row.len() as f64).contains(&x) {
                continue;
            }
            inside += 1;
            if let Some(t) = kerb_foot(row, x, dir, max_width_px)
                && feet.len() < feet.capacity()
            {
                feet.push((y as f64, t));
            }
        }
        let enough = |n: usize| n > 0 && n as f64 >= MIN_ROW_FRACTION * inside as f64;
        let mut fit = None;
        for _ in 0..3 {
            match line_fit(feet, fit) {
                Some((f, n)) if enough(n) => fit = Some(f),
                _ => return false,
            }
        }
        let Some((alpha, beta)) = fit else {
            return false;
        };
        self.lanes[i].kerb_offset_px = [alpha, beta];
        true
    }
}

#[cfg(test)]
mod tests {
    use super::{kerb_foot, line_fit};

    /// A row of 60 columns seen across a right-hand kerb: road (level 55) up to column 30, a
    /// groove (44) on 30..32, the face (55) on 32..40, the pavement (100) from 40 on.
    fn kerb_row() -> Vec<u8> {
        let mut r = vec![55u8; 60];
        r[30..32].fill(44);
        r[40..].fill(100);
        r
    }

    #[test]
    fn a_row_reads_the_foot_of_a_kerb_and_nothing_else() {
        // The step lies between 39 and 40; the foot, the rise out of the groove, between
        // 31 and 32 (the largest g = I(x + 1) − I(x − 1) of the step's sign is at 32).
        let kerb = kerb_row();
        assert_eq!(kerb_foot(&kerb, 39.5, 1, 12), Some(32.0 - 39.5));
        // Mirrored: a left-hand kerb, the road to the right.
        let mirrored: Vec<u8> = kerb.iter().rev().copied().collect();
        assert_eq!(kerb_foot(&mirrored, 19.5, -1, 12), Some(27.0 - 19.5));
        // A lighter face (no groove) rising from a darker road: the foot is that rise.
        let mut face = vec![85u8; 60];
        face[32..40].fill(104);
        face[40..].fill(150);
        assert_eq!(kerb_foot(&face, 39.5, 1, 12), Some(32.0 - 39.5));
        // A plain step (no face), a painted mark 8 px wide, a tape 20 px wide (< 2·w_max)
        // with a groove beside it, a low step, a face as bright as the pavement: no kerb.
        let mut step = vec![55u8; 60];
        step[40..].fill(100);
        assert_eq!(kerb_foot(&step, 39.5, 1, 12), None);
        let mut mark = kerb_row();
        mark[48..].fill(55);
        assert_eq!(kerb_foot(&mark, 39.5, 1, 12), None);
        let mut tape = vec![55u8; 80];
        tape[30..32].fill(44);
        tape[40..60].fill(200);
        assert_eq!(kerb_foot(&tape, 39.5, 1, 12), None);
        let mut low = kerb_row();
        low[40..].fill(70);
        assert_eq!(kerb_foot(&low, 39.5, 1, 12), None);
        let mut lit = kerb_row();
        lit[32..40].fill(90);
        assert_eq!(kerb_foot(&lit, 39.5, 1, 12), None);
        // A foot farther than w_max from the step is not this kerb's.
        assert_eq!(kerb_foot(&kerb, 39.5, 1, 6), None);
        // A bright mark on the road side of a pavement's edge is no face (the face stays on
        // the inner side of the step's half level), whatever its edges' gradient.
        let mut beside = step.clone();
        beside[33..36].fill(100);
        assert_eq!(kerb_foot(&beside, 39.5, 1, 12), None);
        // A faint seam beside a strong step: its edge is below the ratio to the step's.
        let mut strong = kerb_row();
        strong[40..].fill(200);
        assert_eq!(kerb_foot(&strong, 39.5, 1, 12), None);
    }

    #[test]
    fn the_feet_are_fitted_on_the_rows_that_agree() {
        // t = 1 + 0.1·y on ten rows, one row's foot 6 px off.
        let mut rows: Vec<(f64, f64)> = (0..10)
            .map(|k| (f64::from(k), 1.0 + 0.1 * f64::from(k)))
            .collect();
        rows[4].1 += 6.0;
        let ((a, b), n) = line_fit(&rows, None).expect("a fit");
        assert_eq!(n, 10);
        assert!((a - 1.0).abs() > 0.1, "the first fit takes every row");
        let ((a, b2), n) = line_fit(&rows, Some((a, b))).expect("a fit");
        assert_eq!(n, 9, "the row 6 px off is dropped");
        assert!(
            (a - 1.0).abs() < 1e-9 && (b2 - 0.1).abs() < 1e-9,
            "{a} {b2}"
        );
        assert_eq!(
            line_fit(&rows[..1], None),
            None,
            "one row does not fix a line"
        );
    }
}
