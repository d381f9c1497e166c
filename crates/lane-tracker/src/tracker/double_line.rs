//! A double line as one boundary (an addition beyond the paper; `init.double_line_middle`).
//!
//! Markings draw some boundaries as two parallel bright lines a line width or two apart (a
//! double centre line). Lane labels put such a boundary on the middle of the pair (TuSimple and
//! CULane do; so do the labelled sets of `cargo xtask eval-lanes`), while the Hough line and
//! the windows lock onto one of its two lines. After a fresh initialisation and its refinement,
//! every row `y` of the rows searched is read across the lane's estimate `x̂(y)`, grey levels
//! `I(x)`:
//!
//! 1. the mark under the estimate: the brightest pixel `x_p` within ±2 px of `x̂(y)` and the
//!    darkest level `b` within `3·w_max` px of it (`w_max = gradient.stripe_max_width_px`); a
//!    row whose contrast `I(x_p) − b` is below [`MIN_CONTRAST`] is skipped. The mark is the
//!    run `[l, r]` around `x_p` at or above the half level `h = (I(x_p) + b)/2`, of width
//!    `w = r − l + 1 ≤ w_max`, and the estimate must lie on it (`l − ½ ≤ x̂(y) ≤ r + ½`: an
//!    estimate already between the two lines stays);
//! 2. its partner on each side: after a valley below `h` that starts at the mark's edge, a run
//!    at or above `h` that starts within `2w + 2` px of that edge, of width in `[w/2, 2w + 1]`,
//!    whose peak reaches `h + (I(x_p) − h)/2` (about as bright as the mark);
//! 3. a row whose mark has a partner on exactly one side gives the middle of the pair relative
//!    to the estimate, `t(y) = (c₁ + c₂)/2 − x̂(y)`, `c₁ = (l + r)/2` and `c₂` the partner's
//!    centre.
//!
//! The lane is a double line if at least [`MIN_ROW_FRACTION`] of the rows searched give a
//! partner, on the same side in at least five rows of six. Its estimate then moves to the
//! middle of the pair: `t(y) ≈ α + β·y` by least squares over the rows of that side (the gap
//! widens towards the camera, linearly in `y` on a straight road) and
//! `x(y) = x̂(y) + α + β·y`, i.e. `(a1, a2 + β, a3 + α)`; the filter restarts from it. Its
//! tracking windows then reach at least `2·max|α + β·y|` (twice the half gap at the widest
//! row) to each side, so that they hold both lines: with windows that clip the far edge of one
//! line the estimate drifts onto the other within a few frames (≈ 6 px off the middle on the
//! rendered double line with ±10 px windows). No allocation.

use hough_init::Parabola;
use nalgebra::Vector3;
use vision_gradient::GreyImage;

use super::LaneTracker;

/// Least mark contrast (grey levels) for a row to be read.
const MIN_CONTRAST: f64 = 20.0;
/// Least fraction of the rows searched that must show the pair.
const MIN_ROW_FRACTION: f64 = 0.3;

/// Least-squares sums of `t(y) = α + β·y` over rows (here those of one side of a double line;
/// the kerb's feet too).
#[derive(Default, Clone, Copy)]
pub(super) struct LineSums {
    pub(super) rows: usize,
    y: f64,
    yy: f64,
    t: f64,
    ty: f64,
}

impl LineSums {
    pub(super) fn add(&mut self, y: f64, t: f64) {
        self.rows += 1;
        self.y += y;
        self.yy += y * y;
        self.t += t;
        self.ty += t * y;
    }

    /// `(α, β)`, `None` if the rows do not determine them.
    pub(super) fn fit(&self) -> Option<(f64, f64)> {
        let n = self.rows as f64;
        let det = n * self.yy - self.y * self.y;
        if self.rows < 2 || det.abs() < 1e-9 {
            return None;
        }
        let beta = (n * self.ty - self.y * self.t) / det;
        Some(((self.t - beta * self.y) / n, beta))
    }
}

/// Row `y`'s mark under column `x_hat` and its partner (steps 1–3 of the module docs): the
/// middle of the pair minus `x_hat` and the partner's side (`+1` right, `−1` left), `None` if
/// the row shows no mark or no single partner.
fn pair_middle(row: &[u8], x_hat: f64, max_width_px: i64) -> Option<(f64, i64)> {
    let w = row.len() as i64;
    let at = |x: i64| (0..w).contains(&x).then(|| f64::from(row[x as usize]));
    // Far outside any row (or not a number): no mark under it. Within ±1e9 the integer
    // arithmetic below cannot overflow.
    if x_hat.is_nan() || x_hat.abs() > 1e9 {
        return None;
    }
    let x0 = x_hat.round() as i64;
    let mut xp = x0;
    for x in x0 - 2..=x0 + 2 {
        if at(x) > at(xp) {
            xp = x;
        }
    }
    let peak = at(xp)?;
    let span = 3 * max_width_px;
    // The darkest pixel within `span` of the peak (the row clipped to the image; `xp` is in it).
    let (lo, hi) = ((xp - span).max(0) as usize, (xp + span).min(w - 1) as usize);
    let background = row
        .get(lo..=hi)
        .and_then(|s| s.iter().copied().min())
        .map_or(peak, |v| f64::from(v).min(peak));
    if peak - background < MIN_CONTRAST {
        return None;
    }
    let half = 0.5 * (peak + background);
    let (mut l, mut r) = (xp, xp);
    while at(l - 1).is_some_and(|v| v >= half) {
        l -= 1;
    }
    while at(r + 1).is_some_and(|v| v >= half) {
        r += 1;
    }
    let width = r - l + 1;
    // The estimate must lie on the mark (not in the valley of a pair it already straddles).
    if width > max_width_px || x_hat < l as f64 - 0.5 || x_hat > r as f64 + 0.5 {
        return None;
    }
    let max_gap = 2 * width + 2;
    let partner = |dir: i64| -> Option<f64> {
        let edge = if dir > 0 { r } else { l };
        let mut x = edge + dir;
        let mut valley = false;
        while (x - edge).abs() <= max_gap {
            if at(x)? < half {
                valley = true;
            } else if valley {
                break;
            }
            x += dir;
        }
        if !valley || (x - edge).abs() > max_gap {
            return None;
        }
        let start = x;
        let mut top = half;
        while let Some(v) = at(x).filter(|&v| v >= half) {
            top = top.max(v);
            x += dir;
        }
        let partner_width = (x - start).abs();
        let ok = 2 * partner_width >= width
            && partner_width <= 2 * width + 1
            && top >= half + 0.5 * (peak - half);
        ok.then(|| 0.5 * (start + x - dir) as f64)
    };
    let centre = 0.5 * (l + r) as f64;
    let (c2, side) = match (partner(1), partner(-1)) {
        (Some(c), None) => (c, 1),
        (None, Some(c)) => (c, -1),
        _ => return None,
    };
    Some((0.5 * (centre + c2) - x_hat, side))
}

impl LaneTracker {
    /// Lane `i`'s estimate moved to the middle of a double line, if its rows show one (module
    /// docs); over the rows `self.search_rows`. Returns whether it moved.
    pub(super) fn centre_on_double_line(&mut self, i: usize, image: &GreyImage<'_>) -> bool {
        let Some(c) = self.lanes[i].filter.as_ref().map(|f| f.coeffs()) else {
            return false;
        };
        let p = Parabola::from_coeffs(c);
        let (top, bottom) = self.search_rows;
        let max_width_px = i64::from(self.cfg.gradient.stripe_max_width_px.max(1));
        let mut sides = [LineSums::default(); 2];
        for y in top..bottom {
            let Some(row) = image.row(y) else { continue };
            let y = y as f64;
            if let Some((t, side)) = pair_middle(row, p.col_at_row(y), max_width_px) {
                sides[usize::from(side > 0)].add(y, t);
            }
        }
        let (major, minor) = if sides[1].rows >= sides[0].rows {
            (sides[1], sides[0])
        } else {
            (sides[0], sides[1])
        };
        if (major.rows as f64) < MIN_ROW_FRACTION * (bottom - top) as f64
            || 5 * minor.rows > major.rows
        {
            return false;
        }
        let Some((alpha, beta)) = major.fit() else {
            return false;
        };
        let theta = Vector3::new(p.a1, p.a2 + beta, p.a3 + alpha);
        let half_gap = |y: usize| (alpha + beta * y as f64).abs();
        let moved = self.restart_filter(i, &theta);
        if moved {
            self.lanes[i].pair_half_gap_px = half_gap(top).max(half_gap(bottom - 1));
        }
        moved
    }
}

#[cfg(test)]
mod tests {
    use super::pair_middle;

    /// A row of grey 60 with bright (200) runs `[start, end)`.
    fn row(runs: &[(usize, usize)]) -> Vec<u8> {
        let mut r = vec![60u8; 120];
        for &(a, b) in runs {
            r[a..b].fill(200);
        }
        r
    }

    #[test]
    fn a_row_reads_the_middle_of_a_pair_and_nothing_else() {
        // A double line: marks on 40..45 and 50..55, centres 42 and 52.
        let double = row(&[(40, 45), (50, 55)]);
        assert_eq!(pair_middle(&double, 42.0, 12), Some((5.0, 1)));
        assert_eq!(pair_middle(&double, 52.0, 12), Some((-5.0, -1)));
        // A single mark, a mark whose neighbour is a lane away, a mark between two others, a
        // wide bright area, a faint mark: no pair.
        assert_eq!(pair_middle(&row(&[(40, 45)]), 42.0, 12), None);
        assert_eq!(pair_middle(&row(&[(40, 45), (90, 95)]), 42.0, 12), None);
        assert_eq!(
            pair_middle(&row(&[(30, 35), (40, 45), (50, 55)]), 42.0, 12),
            None
        );
        assert_eq!(pair_middle(&row(&[(20, 60)]), 42.0, 12), None);
        let mut faint = row(&[(40, 45), (50, 55)]);
        faint
            .iter_mut()
            .filter(|v| **v == 200)
            .for_each(|v| *v = 75);
        assert_eq!(pair_middle(&faint, 42.0, 12), None);
        // A partner much narrower or much dimmer than the mark is not its pair.
        assert_eq!(pair_middle(&row(&[(40, 47), (52, 53)]), 43.0, 12), None);
        let mut dim = row(&[(40, 45), (50, 55)]);
        dim[50..55].fill(140);
        assert_eq!(pair_middle(&dim, 42.0, 12), None);
    }

    /// An estimate far off the row or not a number reads nothing, without overflow (a
    /// diverged estimate must not panic the reading); one just past an end still reads the
    /// mark at that end.
    #[test]
    fn an_estimate_off_the_row_reads_nothing() {
        let double = row(&[(0, 5), (10, 15)]);
        for x_hat in [
            1e19,
            -1e19,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
            1e9 + 1.0,
        ] {
            assert_eq!(pair_middle(&double, x_hat, 12), None, "{x_hat}");
        }
        assert_eq!(pair_middle(&double, -0.4, 12), Some((7.4, 1)));
    }
}
