//! Stage III, prediction and windows: the filter's time update and the window of interest
//! `x̂(y) ± track.window_half_width_px` on every row searched (the ROI's, or the taller rows of
//! a lane the second search found, `Lane::tracked_tall`).

use hough_init::Parabola;
use vision_gradient::ColSpan;

use super::points::MAX_WINDOW_HALF_WIDTH;
use super::{LaneFilter, LaneState, LaneTracker};
use crate::error::FilterFailure;

impl LaneTracker {
    /// Lane `i`'s window half-width, px: `track.window_half_width_px` while tracking
    /// (`predict`); the refinement of a fresh initialisation may take a wider one
    /// (`track.refine_window_half_width_px`: the Hough line can sit a few pixels off the mark).
    /// A lane on the middle of a double line takes at least twice its half gap, so that its
    /// windows hold both lines (`double_line` module docs); at most
    /// `points::MAX_WINDOW_HALF_WIDTH`.
    pub(super) fn window_half_width(&self, i: usize, predict: bool) -> i64 {
        let base = if predict {
            self.cfg.track.window_half_width_px
        } else {
            self.cfg.track.refine_window_half_width()
        };
        let pair = (2.0 * self.lanes[i].pair_half_gap_px).ceil();
        let pair = if pair.is_finite() && pair > 0.0 {
            pair as usize
        } else {
            0
        };
        base.max(pair).min(MAX_WINDOW_HALF_WIDTH) as i64
    }

    /// Time update of lane `i` (KIF eq. 24 when `predict`; WRLS forgets once per frame in its
    /// update) and its windows for this frame. Returns the predicted coefficients, or `None` when
    /// the lane has no filter or its prediction failed (then counted, kept in
    /// [`LaneTracker::last_filter_error`], and the lane is lost).
    pub(super) fn predict_windows(&mut self, i: usize, predict: bool) -> Option<[f64; 3]> {
        let (top, bottom) = self.search_rows;
        let w = self.window_half_width(i, predict);
        let lane = &mut self.lanes[i];
        let filter = lane.filter.as_mut()?;
        let predicted = match filter {
            LaneFilter::Kif(k) if predict => k.predict(&self.q).map_err(FilterFailure::Kif),
            LaneFilter::Kif(_) | LaneFilter::Wrls(_) => Ok(()),
        };
        if let Err(e) = predicted {
            self.counters.filter_failures[i] += 1;
            self.last_failure[i] = Some(e);
            lane.state = LaneState::Lost;
            return None;
        }
        lane.predicted.clone_from(&lane.filter);
        let coeffs = lane.filter.as_ref()?.coeffs();
        for (row, span) in lane.spans.iter_mut().enumerate() {
            *span = if row >= top && row < bottom {
                let x = Parabola::from_coeffs(coeffs).col_at_row(row as f64);
                if x.is_finite() && x.abs() < 1e6 {
                    let c = x.round() as i64;
                    ColSpan::clamped(c - w, c + w + 1, self.width)
                } else {
                    ColSpan::EMPTY
                }
            } else {
                ColSpan::EMPTY
            };
        }
        Some(coeffs)
    }
}
