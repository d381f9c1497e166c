//! The stripe traced row by row (`init.stripe_trace`), an addition beyond the paper: after the
//! windowed refinement that follows an initialisation, the bright stripe under the lane is
//! followed up and down the rows from the lane's own evidence, and the stripe's middles enter
//! the filter as one more measurement update.
//!
//! ## Why
//! The refinement keeps the window pixels near the predicted parabola (the window, the
//! orientation gate, the inlier band about each row band's midhinge). Where the first fit was
//! pulled off the mark over some rows — the texture of a floor beside a tape near the camera, a
//! tape that runs on straight below the rows the first fit held — those rows measure the
//! texture, and the parabola leaves the mark there: a near miss, right on most rows and
//! 10–20 px off at the bottom ones. A mark is a continuous bright stripe; from a row where the
//! estimate lies on it, it can be followed to the next rows by continuity alone, whatever the
//! parabola says there.
//!
//! ## A stripe on one row
//! On image row `y` with grey levels `I(x)`, the central difference `d(x) = I(x+1) − I(x−1)`
//! (columns `1 ..= W−2`). A rising edge is a column `l` with `d(l) ≥ t` and `d` not larger at
//! `l ± 1`; the stripe it opens closes at the first falling edge `r` after it (`d(r) ≤ −t`, `d`
//! not smaller at `r ± 1`) with `r − l ≤ w_max`. Each edge is placed at the vertex of the
//! parabola through `d` at its column and the two beside it, `c + ½·(d₋ − d₊)/(d₋ − 2d + d₊)`
//! (within half a pixel; a sharp edge between two columns gives them equal differences and is
//! placed between them), and the middle is halfway between the two edges. `w_max =
//! gradient.stripe_max_width_px` (the pairing's widest mark) and `t = max(1,
//! gradient.magnitude_threshold / 4)` grey levels (`min_step_grey`): a vertical step of `h`
//! grey levels has the Sobel L1 magnitude `4h` and the central difference `h`, so a stripe edge
//! is one the detector would keep, read without the orientation band (the trace follows the
//! stripe wherever it turns). Of the stripes whose middle lies within a reach of the column
//! looked for, the nearest is taken ([`stripe_middle_near`]).
//!
//! ## The trace
//! 1. **Start.** From the row of the refinement's middle point (the points are in row order)
//!    outwards, up to [`START_ROWS`] rows each way: the first row with a stripe whose middle
//!    lies within `w_max/2` of the estimate `x̂(y)` (the estimate lies on the stripe, at worst
//!    on one of its edges). None: nothing is traced (a kerb, a road's edge: a step, no
//!    stripe).
//! 2. **Follow**, down to the bottom row searched and up to the top one, from the start's
//!    middle `m₀` with the estimate's slope `s = x̂′(y₀) = 2·a1·y₀ + a2` (px a row): the
//!    next row's column is looked for at `x + s` (`x − s` going up) within
//!    [`FOLLOW_REACH_STRIPES`]` · w_max` (2 px at the default's 16, at least
//!    [`MIN_FOLLOW_REACH_PX`]); a middle `m` found there becomes `x`, and the slope follows the
//!    stripe slowly, `s ← (1 − α)·s + α·Δ` with `Δ` the step just measured and
//!    `α =` [`SLOPE_SMOOTHING`] (a tape's bend is followed, one noisy middle does not turn the
//!    trace); a row without one carries `x` on by `s`. Up to [`MAX_GAP_ROWS`] rows in a row
//!    without a middle are bridged; the next one ends the trace (the end of a dash, a stripe
//!    leaving the image, an occlusion).
//! 3. **Update.** The middles `(mₖ, yₖ)`, one a row, are one more measurement update of the
//!    lane's KIF with `R = (σ/2)²·I`, `σ = filter.r_sigma_px` (one middle weighs as four
//!    edge pixels, [`MIDDLE_WEIGHT`]: the two edges a row of a mark gives the window, each one
//!    or two pixels thick under the 3×3 Sobel; the lane's row profile,
//!    `LaneTracker::lane_fit_rows`, counts it so too). The refinement's estimate is the
//!    prior, so a trace that only confirms the points changes little, and one that runs on
//!    where the points stopped or went astray pulls the parabola back onto the stripe there.
//!    The middles are appended to the lane's points with their weight (overlays, its rows,
//!    its row profile, and no turn back, which runs next: the trace's middles are evidence as
//!    far down as it reached).
//!
//! Not traced: a lane found by the second search (its points lie above the ROI and its
//! parabola is carried down over the ROI's rows; a far stripe's trace would bend that
//! extrapolation), a lane refined with mark centres (`track.mark_centres`: each row already
//! measures its mark's middle) and a WRLS lane (the paper's comparison, one update a frame
//! under its forgetting factor). Tracked frames keep the paper's measurement.
//!
//! Measured (development part of the real labelled stills, default configuration otherwise;
//! `docs/lanes/history/stripe-trace.md`): `seame`'s near misses on a
//! straight tape beside the mats' texture become matched lanes; lanes whose trace ends at the
//! image's side or runs onto a neighbouring stripe move by a pixel or two.

use vision_gradient::GreyImage;

use super::lane::{Health, Lane, LaneFilter};
use super::report::{LaneState, Side};
use super::setup::Rows;
use crate::TrackerConfig;
use crate::error::FilterFailure;

/// Rows looked at each way from the refinement's middle point for the stripe the trace starts
/// on.
pub(super) const START_ROWS: usize = 10;
/// How far from the column carried on from the row before a stripe's middle may lie, as a
/// fraction of the widest stripe (`gradient.stripe_max_width_px`: 2 px at the default's 16 px,
/// scaled with it), at least [`MIN_FOLLOW_REACH_PX`].
pub(super) const FOLLOW_REACH_STRIPES: f64 = 0.125;
/// The smallest reach of the trace from one row to the next, px.
pub(super) const MIN_FOLLOW_REACH_PX: f64 = 1.0;
/// Weight of each measured step in the trace's slope (module docs, step 2).
pub(super) const SLOPE_SMOOTHING: f64 = 0.1;
/// Rows in a row without a middle the trace bridges (one more ends it).
pub(super) const MAX_GAP_ROWS: usize = 3;
/// How many edge pixels one middle weighs as (module docs, step 3): its `R` is the edge
/// pixels' `σ²` over this, and the lane's row profile (`LaneTracker::lane_fit_rows`) counts it
/// this many times.
pub(super) const MIDDLE_WEIGHT: f64 = 4.0;

/// The middle of the stripe on `row` nearest to column `col_px` within `reach_px` of it
/// (module docs, "A stripe on one row"): a rising edge with a central difference of at least
/// `min_step_grey` grey levels (a local maximum) closed by the first falling one (a local
/// minimum, at most `-min_step_grey`) at most `max_width_px` columns after it, each edge placed
/// at the vertex of the parabola through its difference and its neighbours'. `None` without
/// one (or for a row narrower than 3 columns, or a non-finite `col_px`).
pub(super) fn stripe_middle_near(
    row: &[u8],
    col_px: f64,
    reach_px: f64,
    max_width_px: u16,
    min_step_grey: i16,
) -> Option<f64> {
    if !col_px.is_finite() || row.len() < 3 {
        return None;
    }
    let last = row.len() as i64 - 2;
    let w = i64::from(max_width_px);
    // A middle within the reach (each edge placed within half a pixel of its column) has its
    // rising edge at most half the widest stripe left of the reach and at most at its right
    // end. (`as` saturates; far-off columns give an empty range.)
    let (near, far) = (col_px - reach_px - 0.5, col_px + reach_px + 0.5);
    let lo = ((near - 0.5 * w as f64).floor() as i64).max(1);
    let hi = (far.ceil() as i64).min(last);
    let d = |c: i64| -> Option<i32> {
        let (a, b) = (
            row.get(usize::try_from(c - 1).ok()?)?,
            row.get(usize::try_from(c + 1).ok()?)?,
        );
        Some(i32::from(*b) - i32::from(*a))
    };
    // The local extremum test (by `sign`: 1 a maximum, −1 a minimum), and the edge's place:
    // the vertex of the parabola through `d` at `c − 1, c, c + 1` (half a pixel at most from
    // `c`; two equal differences, a sharp edge between two columns, put it between them).
    let peak = |c: i64, dc: i32, sign: i32| {
        [c - 1, c + 1]
            .iter()
            .all(|&n| d(n).is_none_or(|dn| sign * dn <= sign * dc))
    };
    let place = |c: i64, dc: i32| -> f64 {
        let (Some(before), Some(after)) = (d(c - 1), d(c + 1)) else {
            return c as f64;
        };
        let curvature = f64::from(before - 2 * dc + after);
        if curvature == 0.0 {
            return c as f64;
        }
        c as f64 + (0.5 * f64::from(before - after) / curvature).clamp(-0.5, 0.5)
    };
    let min_step = i32::from(min_step_grey);
    let mut best: Option<(f64, f64)> = None;
    for l in lo..=hi {
        let Some(dl) = d(l) else { continue };
        if dl < min_step || !peak(l, dl, 1) {
            continue;
        }
        // The first falling edge closes the stripe; one beyond `2·far − l + 1` puts the middle
        // out of reach.
        let r_max = (l + w).min(last).min((2.0 * far).ceil() as i64 - l + 1);
        let closing = ((l + 1)..=r_max).find_map(|r| {
            let dr = d(r)?;
            (dr <= -min_step && peak(r, dr, -1)).then_some((r, dr))
        });
        let Some((r, dr)) = closing else { continue };
        let middle = 0.5 * (place(l, dl) + place(r, dr));
        let off = (middle - col_px).abs();
        if off <= reach_px && best.is_none_or(|(_, b)| off < b) {
            best = Some((middle, off));
        }
    }
    best.map(|(middle, _)| middle)
}

/// The stripe tracer: follows a lane's stripe row by row (its buffer of middles sized once).
#[derive(Debug)]
pub(super) struct StripeTracer {
    /// The middles of the stripe followed, one a row (capacity: the height).
    traced: Vec<(f32, f32)>,
}

impl StripeTracer {
    /// A tracer for frames `height_px` rows tall.
    pub(super) fn new(height_px: usize) -> Self {
        StripeTracer {
            traced: Vec::with_capacity(height_px),
        }
    }

    /// The stripe of the lane on `side` traced row by row over `rows` and its middles one more
    /// measurement update (module docs). Only a KIF lane updated by its refinement on this
    /// frame, not found by the second search, with edge pixels as measurements. Returns how
    /// many middles were traced into it (0: unchanged), appended to its points after the
    /// refinement's (for overlays and the row profile; every one while the points' buffer, the
    /// tracker's largest, has room). A failed update leaves the lane as it was and is counted
    /// in `health` as a filter failure.
    pub(super) fn trace(
        &mut self,
        lane: &mut Lane,
        side: Side,
        image: &GreyImage<'_>,
        rows: Rows,
        cfg: &TrackerConfig,
        health: &mut Health,
    ) -> usize {
        let (top, bottom) = rows;
        let w_max = cfg.gradient.stripe_max_width_px;
        // (At most 2040 / 4: an i16.)
        let min_step_grey = (cfg.gradient.magnitude_threshold / 4).max(1) as i16;
        let r_sigma_px = cfg.filter.r_sigma_px;
        let follow_reach_px = (FOLLOW_REACH_STRIPES * f64::from(w_max)).max(MIN_FOLLOW_REACH_PX);
        if lane.state != LaneState::Tracking
            || !lane.updated_now
            || lane.tracked_tall
            || cfg.track.mark_centres
            || w_max < 2
        {
            return 0;
        }
        let Some(filter @ LaneFilter::Kif(_)) = lane.filter.as_ref() else {
            return 0;
        };
        let Some(&(_, mid_row)) = lane.points.get(lane.points.len() / 2) else {
            return 0;
        };
        let [a1, a2, a3] = filter.coeffs();
        let col = |y: f64| (a1 * y + a2) * y + a3;
        let row_px = |r: usize| image.row(r);
        // 1. Start: the nearest row to the middle point with a stripe under the estimate.
        let mid = (mid_row.max(0.0) as usize)
            .min(bottom.saturating_sub(1))
            .max(top);
        let start = (0..=START_ROWS)
            .flat_map(|k| [Some(mid + k), mid.checked_sub(k).filter(|_| k > 0)])
            .flatten()
            .filter(|r| (top..bottom).contains(r))
            .find_map(|r| {
                let x = col(r as f64);
                stripe_middle_near(row_px(r)?, x, f64::from(w_max) / 2.0, w_max, min_step_grey)
                    .map(|m| (r, m))
            });
        let Some((start_row, start_col)) = start else {
            return 0;
        };
        self.traced.clear();
        self.traced.push((start_col as f32, start_row as f32));
        // 2. Follow the stripe down, then up.
        let slope0 = 2.0 * a1 * start_row as f64 + a2;
        for step in [1i64, -1] {
            let (mut x, mut slope, mut gap) = (start_col, slope0, 0);
            let mut r = start_row as i64;
            loop {
                r += step;
                let Some(row) = usize::try_from(r)
                    .ok()
                    .filter(|r| (top..bottom).contains(r))
                    .and_then(row_px)
                else {
                    break;
                };
                let from = x;
                x += slope * step as f64;
                match stripe_middle_near(row, x, follow_reach_px, w_max, min_step_grey) {
                    Some(m) => {
                        let measured = (m - from) * step as f64;
                        slope = (1.0 - SLOPE_SMOOTHING) * slope + SLOPE_SMOOTHING * measured;
                        x = m;
                        gap = 0;
                        if self.traced.len() < self.traced.capacity() {
                            self.traced.push((m as f32, r as f32));
                        }
                    }
                    None => {
                        gap += 1;
                        if gap > MAX_GAP_ROWS {
                            break;
                        }
                    }
                }
            }
        }
        // 3. One more measurement update with the middles.
        let Some(LaneFilter::Kif(kif)) = lane.filter.as_mut() else {
            return 0;
        };
        if let Err(e) = kif.update(&self.traced, r_sigma_px * r_sigma_px / MIDDLE_WEIGHT) {
            health.filter_failed(side, FilterFailure::Kif(e));
            return 0;
        }
        // The row profile weighs the refinement's edge pixels 1 and the middles as in the
        // update (the weights, empty with edge pixels, hold as many as the points).
        lane.weights.clear();
        lane.weights.resize(lane.points.len(), 1.0);
        let room = lane
            .points
            .capacity()
            .min(lane.weights.capacity())
            .saturating_sub(lane.points.len());
        let appended = self.traced.len().min(room);
        lane.points.extend(self.traced.iter().take(appended));
        lane.weights.resize(lane.points.len(), MIDDLE_WEIGHT);
        for &(_, y) in &self.traced {
            let y = f64::from(y);
            lane.rows = [lane.rows[0].min(y), lane.rows[1].max(y)];
        }
        lane.fit = super::points::fit_profile(&lane.points, &lane.weights, lane.rows);
        lane.points_now += self.traced.len();
        appended
    }
}

#[cfg(test)]
mod tests {
    use super::stripe_middle_near;

    /// A row of grey 40 with bright (200) stripes `[left, right)`.
    fn row_with(stripes: &[(usize, usize)]) -> Vec<u8> {
        let mut row = vec![40u8; 80];
        for &(l, r) in stripes {
            row[l..r].fill(200);
        }
        row
    }

    /// A stripe's middle is read between its edges: columns `[20, 30)` rise between columns
    /// 19 and 20 and fall between 29 and 30, the central difference equal at 19 and 20 and at
    /// 29 and 30 — each edge placed between its two columns, the middle at 24.5 (the pixel
    /// centre of the stripe's columns 20..=29) exactly, from anywhere within the reach. An
    /// anti-aliased edge is placed between its columns by its grey levels.
    #[test]
    fn a_stripe_is_read_at_its_middle_from_within_the_reach() {
        let row = row_with(&[(20, 30)]);
        for x in [22.5, 24.5, 26.5] {
            let m = stripe_middle_near(&row, x, 2.0, 16, 15).expect("found");
            assert_eq!(m, 24.5, "from {x}");
        }
        // Columns 20.25 .. 30.25 covered: 20 at three quarters, 30 at a quarter.
        let mut shifted = row_with(&[(21, 30)]);
        shifted[20] = 160;
        shifted[30] = 80;
        let m = stripe_middle_near(&shifted, 24.5, 2.0, 16, 15).expect("found");
        assert!((m - 24.75).abs() < 0.1, "{m}");
        assert_eq!(
            stripe_middle_near(&row, 21.0, 2.0, 16, 15),
            None,
            "beyond the reach"
        );
    }

    /// Of two stripes within the reach the nearer is taken; a stripe wider than the limit, a
    /// step (no falling edge) and a stripe below the contrast are not stripes.
    #[test]
    fn the_nearest_stripe_within_the_width_and_contrast_limits_is_taken() {
        let two = row_with(&[(20, 24), (28, 32)]);
        let m = stripe_middle_near(&two, 25.0, 5.0, 16, 15).expect("found");
        assert_eq!(m, 21.5);
        let m = stripe_middle_near(&two, 26.0, 5.0, 16, 15).expect("found");
        assert_eq!(m, 29.5);
        let wide = row_with(&[(20, 40)]);
        assert_eq!(
            stripe_middle_near(&wide, 29.5, 4.0, 16, 15),
            None,
            "too wide"
        );
        assert!(stripe_middle_near(&wide, 29.5, 4.0, 24, 15).is_some());
        let mut step = vec![40u8; 80];
        step[30..].fill(200);
        assert_eq!(stripe_middle_near(&step, 30.0, 4.0, 16, 15), None, "a step");
        let faint: Vec<u8> = row_with(&[(20, 30)])
            .iter()
            .map(|&g| if g > 40 { 50 } else { 40 })
            .collect();
        assert_eq!(
            stripe_middle_near(&faint, 24.5, 2.0, 16, 15),
            None,
            "10 levels"
        );
        assert!(stripe_middle_near(&faint, 24.5, 2.0, 16, 10).is_some());
    }

    /// The row's ends, a non-finite column and a row too short to differentiate give `None`
    /// or a stripe inside the row, never a read outside it.
    #[test]
    fn the_rows_ends_and_bad_columns_are_refused() {
        let at_end = row_with(&[(74, 80)]);
        assert_eq!(
            stripe_middle_near(&at_end, 77.0, 4.0, 16, 15),
            None,
            "no falling edge"
        );
        let at_start = row_with(&[(0, 5)]);
        assert_eq!(
            stripe_middle_near(&at_start, 2.0, 4.0, 16, 15),
            None,
            "no rising edge"
        );
        let row = row_with(&[(20, 30)]);
        for x in [f64::NAN, f64::INFINITY, -1e12, 1e12] {
            assert_eq!(stripe_middle_near(&row, x, 2.0, 16, 15), None, "{x}");
        }
        assert_eq!(stripe_middle_near(&[200, 40], 0.5, 2.0, 16, 15), None);
    }
}
