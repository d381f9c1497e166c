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
//!    `w = r − l + 1 ≤ w_max`, and the estimate must lie on it (`l − ½ ≤ x̂(y) ≤ r + ½`; an
//!    estimate between the two lines is read by step 4);
//! 2. its partner on each side: after a valley below `h` that starts at the mark's edge, a run
//!    at or above `h` that starts within `2w + 2` px of that edge, of width in `[w/2, 2w + 1]`,
//!    whose peak reaches `h + (I(x_p) − h)/2` (about as bright as the mark);
//! 3. a row whose mark has a partner on exactly one side gives the middle of the pair relative
//!    to the estimate, `t(y) = (c₁ + c₂)/2 − x̂(y)`, `c₁ = (l + r)/2` and `c₂` the partner's
//!    centre, and its half gap `g(y) = |c₂ − c₁|/2`;
//! 4. a row whose estimate lies on no mark may lie in the valley between the two lines (the
//!    refinement's edge pixels of two narrow lines settle between them, and a lane there can
//!    still lean across the pair): the brightest pixel within `w_max/2` px on each side of
//!    `x̂(y)` (the nearest of equals), if both are at least [`MIN_CONTRAST`] above the darkest
//!    of the three pixels
//!    around `x̂(y)` (a valley under the estimate; most rows, a uniform road, end here), is
//!    read as in steps 1–3; if the left one is a mark whose single partner lies to its right,
//!    the right one a mark whose single partner lies to its left, and the two middles agree
//!    within [`VALLEY_AGREEMENT_PX`], the row gives their mean middle `t(y)` and half gap
//!    `g(y)` as an estimate between the lines.
//!
//! The lane is a double line if at least [`MIN_ROW_FRACTION`] of the rows searched where the
//! estimate lies inside the image (a lane leaving the image through its side shows the pair
//! on those rows only), and at least [`MIN_PAIR_ROWS`], give the pair, and the rows read from
//! one line are on the same side in
//! at least five of six (those read from between the lines count with the larger side). Its
//! estimate then moves to the middle of the pair: `t(y) ≈ α + β·y` by least squares over those
//! rows (the gap widens towards the camera, linearly in `y` on a straight road) and
//! `x(y) = x̂(y) + α + β·y`, i.e. `(a1, a2 + β, a3 + α)`; the filter restarts from it. Its
//! tracking windows then reach at least twice the half gap `g(y) ≈ γ + δ·y` (least squares
//! over the same rows; the larger of its values at the top and bottom rows searched) to each
//! side, so that they hold both lines: with
//! windows that clip the far edge of one line the estimate drifts onto the other within a few
//! frames (≈ 6 px off the middle on the rendered double line with ±10 px windows). No
//! allocation.
//!
//! Decisions and figures: `docs/lanes/history/double-line.md`; below the ablation's bar one at a
//! time, kept (`docs/lanes/history/README.md`).

use hough_init::Parabola;
use nalgebra::Vector3;
use vision_gradient::GreyImage;

use super::lane::{Health, Lane};
use super::report::Side;
use super::setup::{Rows, Setup};

/// Least mark contrast (grey levels) for a row to be read.
const MIN_CONTRAST: f64 = 20.0;
/// Least fraction of the rows searched, where the estimate lies inside the image, that must
/// show the pair.
const MIN_ROW_FRACTION: f64 = 0.3;
/// Least number of rows that must show the pair (a lane inside the image on a few rows only).
const MIN_PAIR_ROWS: usize = 8;
/// Read from between the lines, the middles found from the left and from the right line must
/// agree within this, px (the same pair).
const VALLEY_AGREEMENT_PX: f64 = 1.5;

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

    /// These rows and `other`'s.
    fn merged(self, other: Self) -> Self {
        Self {
            rows: self.rows + other.rows,
            y: self.y + other.y,
            yy: self.yy + other.yy,
            t: self.t + other.t,
            ty: self.ty + other.ty,
        }
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

/// Where a row's estimate lies on a double line (module docs, steps 3 and 4).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum PairSide {
    /// On one line, its partner to the left.
    PartnerLeft,
    /// On one line, its partner to the right.
    PartnerRight,
    /// Between the two lines.
    Between,
}

/// A row's reading of a double line (module docs, steps 3 and 4).
#[derive(Debug, Clone, Copy, PartialEq)]
struct PairRow {
    /// The pair's middle minus the estimate's column, px.
    middle_offset_px: f64,
    /// Half the distance between the two lines' centres, px.
    half_gap_px: f64,
    /// Where the estimate lies.
    side: PairSide,
}

/// Row `y`'s mark under column `x_hat` and its partner (steps 1–3 of the module docs), `None`
/// if the row shows no mark or no single partner.
fn pair_middle(row: &[u8], x_hat: f64, max_width_px: i64) -> Option<PairRow> {
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
    // The run, read no further than one pixel past the widest mark (a wider run is no mark:
    // a bright area can span the row).
    let (mut l, mut r) = (xp, xp);
    while r - l < max_width_px && at(l - 1).is_some_and(|v| v >= half) {
        l -= 1;
    }
    while r - l < max_width_px && at(r + 1).is_some_and(|v| v >= half) {
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
        // (Read no further than one pixel past the widest partner.)
        while (x - start).abs() <= 2 * width + 1
            && let Some(v) = at(x).filter(|&v| v >= half)
        {
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
        (Some(c), None) => (c, PairSide::PartnerRight),
        (None, Some(c)) => (c, PairSide::PartnerLeft),
        _ => return None,
    };
    Some(PairRow {
        middle_offset_px: 0.5 * (centre + c2) - x_hat,
        half_gap_px: 0.5 * (c2 - centre).abs(),
        side,
    })
}

/// Row `y` read from between the two lines of a double line (step 4 of the module docs): the
/// brightest pixel within `max_width_px / 2` on each side of column `x_hat` (the nearest of
/// equals) read as in steps 1–3, `None` unless they read the same pair.
fn valley_middle(row: &[u8], x_hat: f64, max_width_px: i64) -> Option<PairRow> {
    // Far outside any row (or not a number): nothing to read (as in `pair_middle`).
    if x_hat.is_nan() || x_hat.abs() > 1e9 {
        return None;
    }
    let w = row.len() as i64;
    let x0 = x_hat.round() as i64;
    let reach_px = (max_width_px / 2).max(1);
    // The brightest pixel `dir` of the estimate within the reach, inside the row (the nearest
    // of equals).
    let brightest = |dir: i64| {
        (1..=reach_px)
            .map(|k| x0 + dir * k)
            .filter(|x| (0..w).contains(x))
            .map(|x| (x, row[x as usize]))
            .fold(None, |best: Option<(i64, u8)>, (x, v)| match best {
                Some((_, b)) if b >= v => best,
                _ => Some((x, v)),
            })
    };
    let (left, left_peak) = brightest(-1)?;
    let (right, right_peak) = brightest(1)?;
    // A valley under the estimate, below both lines by the least contrast of a mark: else there
    // is no pair to read from here (most rows: a uniform road), and the two reads below are not
    // made.
    let valley_floor = (x0 - 1..=x0 + 1)
        .filter(|x| (0..w).contains(x))
        .map(|x| row[x as usize])
        .min()?;
    if f64::from(left_peak.min(right_peak)) - f64::from(valley_floor) < MIN_CONTRAST {
        return None;
    }
    let from_left =
        pair_middle(row, left as f64, max_width_px).filter(|p| p.side == PairSide::PartnerRight)?;
    let from_right =
        pair_middle(row, right as f64, max_width_px).filter(|p| p.side == PairSide::PartnerLeft)?;
    let (middle_left, middle_right) = (
        left as f64 + from_left.middle_offset_px,
        right as f64 + from_right.middle_offset_px,
    );
    ((middle_left - middle_right).abs() <= VALLEY_AGREEMENT_PX).then_some(PairRow {
        middle_offset_px: 0.5 * (middle_left + middle_right) - x_hat,
        half_gap_px: 0.5 * (from_left.half_gap_px + from_right.half_gap_px),
        side: PairSide::Between,
    })
}

/// The estimate of the lane on `side` moved to the middle of a double line, if `rows` show one
/// (module docs). Returns whether it moved (a filter refusing the new estimate is counted in
/// `health` and leaves the lane as it was).
pub(super) fn centre_on_double_line(
    lane: &mut Lane,
    side: Side,
    image: &GreyImage<'_>,
    rows: Rows,
    setup: &Setup,
    health: &mut Health,
) -> bool {
    let Some(c) = lane.filter.as_ref().map(|f| f.coeffs()) else {
        return false;
    };
    let p = Parabola::from_coeffs(c);
    let (top, bottom) = rows;
    let max_width_px = i64::from(setup.cfg.gradient.stripe_max_width_px.max(1));
    let image_width_px = setup.width as f64;
    // Middles read from a line with its partner on the left, on the right, from between
    // the lines; the half gaps read.
    let mut middles = [LineSums::default(); 3];
    let mut gaps = [LineSums::default(); 3];
    let mut inside = 0usize;
    for y in top..bottom {
        let Some(row) = image.row(y) else { continue };
        let x_hat = p.col_at_row(y as f64);
        inside += usize::from((0.0..image_width_px).contains(&x_hat));
        let Some(read) = pair_middle(row, x_hat, max_width_px)
            .or_else(|| valley_middle(row, x_hat, max_width_px))
        else {
            continue;
        };
        let k = match read.side {
            PairSide::PartnerLeft => 0,
            PairSide::PartnerRight => 1,
            PairSide::Between => 2,
        };
        middles[k].add(y as f64, read.middle_offset_px);
        gaps[k].add(y as f64, read.half_gap_px);
    }
    let (major, minor) = if middles[1].rows >= middles[0].rows {
        (1, 0)
    } else {
        (0, 1)
    };
    let (pair, pair_gaps) = (
        middles[major].merged(middles[2]),
        gaps[major].merged(gaps[2]),
    );
    if pair.rows < MIN_PAIR_ROWS
        || (pair.rows as f64) < MIN_ROW_FRACTION * inside as f64
        || 5 * middles[minor].rows > pair.rows
    {
        return false;
    }
    let (Some((alpha, beta)), Some((gamma, delta))) = (pair.fit(), pair_gaps.fit()) else {
        return false;
    };
    let theta = Vector3::new(p.a1, p.a2 + beta, p.a3 + alpha);
    let half_gap = |y: usize| (gamma + delta * y as f64).abs();
    let moved = lane.restart_filter(side, &theta, setup, health);
    if moved {
        lane.pair_half_gap_px = half_gap(top).max(half_gap(bottom - 1));
    }
    moved
}

#[cfg(test)]
mod tests {
    use super::{PairRow, PairSide, pair_middle, valley_middle};

    fn read(middle_offset_px: f64, half_gap_px: f64, side: PairSide) -> Option<PairRow> {
        Some(PairRow {
            middle_offset_px,
            half_gap_px,
            side,
        })
    }

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
        assert_eq!(
            pair_middle(&double, 42.0, 12),
            read(5.0, 5.0, PairSide::PartnerRight)
        );
        assert_eq!(
            pair_middle(&double, 52.0, 12),
            read(-5.0, 5.0, PairSide::PartnerLeft)
        );
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
        assert_eq!(
            pair_middle(&double, -0.4, 12),
            read(7.4, 5.0, PairSide::PartnerRight)
        );
        for x_hat in [1e19, f64::NAN, -1e10] {
            assert_eq!(valley_middle(&double, x_hat, 12), None, "{x_hat}");
        }
    }

    /// From between the two lines of a pair the row reads the pair's middle and half gap, from
    /// anywhere in the valley; not from beside a single line, between two lines that are not
    /// one pair (too far apart, or one of three), or on a line (step 1 reads that).
    #[test]
    fn a_row_reads_a_pair_from_between_its_lines() {
        // Marks on 40..45 and 50..55, centres 42 and 52: middle 47, half gap 5.
        let double = row(&[(40, 45), (50, 55)]);
        for x_hat in [45.6, 46.0, 47.0, 48.3, 49.0] {
            assert_eq!(
                valley_middle(&double, x_hat, 12),
                read(47.0 - x_hat, 5.0, PairSide::Between),
                "{x_hat}"
            );
        }
        // Unlike widths: each line's middle as `pair_middle` reads it, their mean.
        let unlike = row(&[(40, 43), (48, 53)]);
        assert_eq!(
            valley_middle(&unlike, 45.0, 12),
            read(0.5 * (41.0 + 50.0) - 45.0, 4.5, PairSide::Between)
        );
        assert_eq!(valley_middle(&row(&[(40, 45)]), 47.0, 12), None);
        assert_eq!(valley_middle(&row(&[(40, 45), (70, 75)]), 57.0, 12), None);
        assert_eq!(
            valley_middle(&row(&[(30, 35), (40, 45), (50, 55)]), 47.0, 12),
            None
        );
        // On a line the brightest pixels on either side are the line itself and the valley or
        // the other line: they do not read one pair from both sides.
        assert_eq!(valley_middle(&double, 42.0, 12), None);
        // A pair (10 px between its lines, within the partner's reach of 12) whose left line is
        // beyond w_max/2 = 6 px of the estimate: nothing.
        let wide = row(&[(40, 45), (55, 60)]);
        assert!(pair_middle(&wide, 42.0, 12).is_some());
        assert_eq!(valley_middle(&wide, 51.0, 12), None);
        // A valley less than the least mark contrast below the lines: the lines (90 on a road
        // of 60) read as a pair from either line, not from a valley of 72 between them.
        let mut shallow = row(&[(40, 45), (50, 55)]);
        shallow
            .iter_mut()
            .filter(|v| **v == 200)
            .for_each(|v| *v = 90);
        shallow[45..50].fill(72);
        assert_eq!(
            pair_middle(&shallow, 42.0, 12),
            read(5.0, 5.0, PairSide::PartnerRight)
        );
        assert_eq!(valley_middle(&shallow, 47.0, 12), None);
        shallow[45..50].fill(70);
        assert_eq!(
            valley_middle(&shallow, 47.0, 12),
            read(0.0, 5.0, PairSide::Between)
        );
        // The two reads see different pairs: the left line's read (its darkest level a dark
        // patch at columns 8–12, half level 110) takes a 120 shoulder into the right line
        // (middle 48.5), the right line's (the road's 60, half level 130) does not (middle
        // 46.5): 2 px apart, more than the 1.5 px agreement.
        let mut unlike = row(&[(38, 45), (50, 55)]);
        unlike[8..13].fill(20);
        unlike[55..63].fill(120);
        let (from_left, from_right) = (
            pair_middle(&unlike, 44.0, 12).expect("the left line's pair"),
            pair_middle(&unlike, 50.0, 12).expect("the right line's pair"),
        );
        assert_eq!(44.0 + from_left.middle_offset_px, 48.5);
        assert_eq!(50.0 + from_right.middle_offset_px, 46.5);
        assert_eq!(valley_middle(&unlike, 47.0, 12), None);
    }
}
