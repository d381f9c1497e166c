//! Stage III, prediction and windows: the filter's time update and the window of interest
//! `x̂(y) ± track.window_half_width_px` on every row searched (the ROI's, or the taller rows of
//! a lane the second search found, `Lane::tracked_tall`).

use hough_init::Parabola;
use vision_gradient::ColSpan;

use super::lane::{Health, Lane, LaneFilter};
use super::report::{LaneState, Side};
use super::setup::{Pass, Rows, Setup};
use crate::error::FilterFailure;

/// Time update of the lane on `side` (KIF eq. 24 on a tracked frame; WRLS forgets once per
/// frame in its update; none in a refinement) and its windows over `rows` for this frame.
/// Returns the predicted coefficients, or `None` when the lane has no filter or its
/// prediction failed (then counted and kept in `health`, and the lane is lost).
pub(super) fn predict_windows(
    lane: &mut Lane,
    side: Side,
    pass: Pass,
    rows: Rows,
    setup: &Setup,
    health: &mut Health,
) -> Option<[f64; 3]> {
    let (top, bottom) = rows;
    let w = setup.window_half_width(lane, pass);
    let filter = lane.filter.as_mut()?;
    let predicted = match filter {
        LaneFilter::Kif(k) if pass == Pass::Tracking => {
            k.predict(&setup.q).map_err(FilterFailure::Kif)
        }
        LaneFilter::Kif(_) | LaneFilter::Wrls(_) => Ok(()),
    };
    if let Err(e) = predicted {
        health.filter_failed(side, e);
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
                ColSpan::clamped(c - w, c + w + 1, setup.width)
            } else {
                ColSpan::EMPTY
            }
        } else {
            ColSpan::EMPTY
        };
    }
    Some(coeffs)
}
