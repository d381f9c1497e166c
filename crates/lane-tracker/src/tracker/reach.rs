//! # How far up each lane is seen (an addition beyond the paper)
//!
//! The paper tracks each lane in a band of rows near the camera, and a lane's report said only
//! the rows of the points behind its estimate: the band's. Lane keeping needs the near field,
//! but the labels (and curvature, lane changes, anything ahead) run on towards the horizon; a
//! row the report does not reach is a row the lane is not given on. After the frame's update,
//! each lane that was updated or initialised on it is followed **upwards** from the top of its
//! points, row by row, along its parabola, as far as its mark is seen; the report's `rows`
//! then span its points and the marks found above them.
//!
//! On row `y` the mark is looked for within `±k` px of `x̂(y) + d` (`x̂` the lane's parabola,
//! `d` the offset the mark has drifted from it so far, `k = track.window_half_width_px`): a
//! column `c` brighter than both columns `m` px either side of it by at least [`MIN_CONTRAST`]
//! grey levels,
//!
//! ```text
//! I(c) − max(I(c − m), I(c + m)) ≥ MIN_CONTRAST,   m = max(2, ⌈w(y)/2⌉ + 1),
//! w(y) = gradient.stripe_max_width_px · (y − y_h)/(h − y_h),
//! ```
//!
//! the mark's width shrinking linearly towards the horizon row `y_h` (where the two lanes meet,
//! else the frame's top). The brightest such column moves `d` halfway to it (`|d| ≤ 2k`). The
//! walk stops at `y_h` (without one — the lanes do not close in upwards — at the top of the
//! second search's rows, `roi.fallback_top_row_fraction`), at the top of the rows the working
//! frame holds, or after [`MAX_GAP_FRACTION`] of the
//! height without a mark (a dash's gap is shorter); the lane's rows then start at the highest
//! row where a mark was seen, if at least [`MIN_MARK_ROWS`] were.
//!
//! The lane's coefficients are not changed: the reach says where the parabola of the near
//! field is backed by marks, and the near band's figures stay what they were.

use vision_gradient::GreyImage;

use super::lane::Lanes;
use super::report::Side;
use super::setup::{Rows, Setup};

/// Least step between a mark and the floor either side of it, grey levels.
pub(crate) const MIN_CONTRAST: i16 = 12;
/// Longest run of rows without a mark before the walk stops, as a fraction of the height.
pub(crate) const MAX_GAP_FRACTION: f64 = 0.1;
/// Fewest rows with a mark for a reach to count.
pub(crate) const MIN_MARK_ROWS: usize = 3;

/// Follow each lane updated or initialised on this frame upwards (module docs) on `image`,
/// valid on the working rows `rows`, no higher than `horizon_row` (working rows); extend its
/// rows' top to the highest mark found.
pub(super) fn reach_up(
    lanes: &mut Lanes,
    image: &GreyImage<'_>,
    rows: Rows,
    horizon_row: Option<f64>,
    setup: &Setup,
) {
    let (w, h) = (image.width(), image.height());
    // Without a horizon (the lanes do not close in upwards) no higher than the second search's
    // rows, or the ROI's.
    let unknown = setup.fallback_roi.unwrap_or(setup.roi).0 as f64;
    let y_h = horizon_row.unwrap_or(unknown).max(0.0);
    let limit = (y_h.ceil() as usize).max(rows.0).max(1);
    let k = setup.cfg.track.window_half_width_px as i64;
    let max_width = f64::from(setup.cfg.gradient.stripe_max_width_px).max(4.0);
    let max_gap = ((MAX_GAP_FRACTION * h as f64).ceil() as usize).max(4);
    for side in Side::BOTH {
        let lane = &mut lanes[side];
        if !(lane.updated_now || lane.initialised_now) || !lane.has_estimate() {
            continue;
        }
        let Some(filter) = lane.filter.as_ref() else {
            continue;
        };
        let start = lane.rows[0].floor();
        if !start.is_finite() || start <= limit as f64 {
            continue;
        }
        let mut drift = 0.0f64;
        let (mut marks, mut gap, mut top) = (0usize, 0usize, None);
        let mut y = start as usize;
        while y > limit && gap <= max_gap {
            y -= 1;
            let Some(line) = image.row(y) else { break };
            let depth = ((y as f64 - y_h) / (h as f64 - y_h)).clamp(0.0, 1.0);
            let m = ((max_width * depth / 2.0).ceil() as i64 + 1).max(2);
            let centre = filter.col_at_row(y as f64) + drift;
            if !centre.is_finite() {
                break;
            }
            let centre = centre.round() as i64;
            let mut best: Option<(i16, i64)> = None;
            for c in (centre - k).max(m)..=(centre + k).min(w as i64 - 1 - m) {
                let at = |x: i64| i16::from(line[x as usize]);
                let step = at(c) - at(c - m).max(at(c + m));
                if step >= MIN_CONTRAST && best.is_none_or(|(s, _)| step > s) {
                    best = Some((step, c));
                }
            }
            match best {
                Some((_, c)) => {
                    drift =
                        (drift + 0.5 * (c - centre) as f64).clamp(-2.0 * k as f64, 2.0 * k as f64);
                    marks += 1;
                    gap = 0;
                    top = Some(y as f64);
                }
                None => gap += 1,
            }
        }
        if let Some(top) = top.filter(|_| marks >= MIN_MARK_ROWS) {
            lane.rows[0] = lane.rows[0].min(top);
        }
    }
}
