//! Stage III, measurement update and jump gate: the filter update with the points the windows
//! gave (KIF eqs. 6, 12 or WRLS eqs. 25–27), the jump gate against the prediction, and the
//! lane's state after it.

use super::lane::{Health, Lane, LaneFilter};
use super::points::{fit_profile, weighted_scatter};
use super::report::{LaneState, Side};
use super::setup::{Rows, Setup};
use crate::error::FilterFailure;

/// The measurement update of the lane on `side` with its selected points, then the jump gate
/// at the top and bottom of `rows` (the ROI's, or the taller rows of a lane tracked there).
/// `coeffs`: the prediction the points were selected about.
pub(super) fn update_and_gate(
    lane: &mut Lane,
    side: Side,
    coeffs: [f64; 3],
    rows: Rows,
    setup: &Setup,
    health: &mut Health,
) {
    let (top, bottom) = rows;
    let cfg = &setup.cfg;
    let mark_centres = cfg.track.mark_centres;
    let Some(filter) = lane.filter.as_mut() else {
        return;
    };
    // KIF with mark centres: R = s²·diag(1/w_i), the points' relative precisions w_i scaled
    // by this frame's weighted scatter s² about their own LS parabola (crate docs,
    // "Measurement noise"); the configured σ for every point when there are too few points
    // to estimate it, and always with edge pixels (the paper's R = σ²·I).
    let r_cfg = cfg.filter.r_sigma_px;
    let updated = match filter {
        LaneFilter::Kif(k) => {
            let row_norm = *k.row_norm();
            let measured = if mark_centres {
                weighted_scatter(&lane.points, &lane.weights, coeffs, &row_norm)
            } else {
                None
            };
            match measured {
                Some((sums, s2)) => k.update_sums(&sums, s2),
                None => k.update(&lane.points, r_cfg * r_cfg),
            }
            .map_err(FilterFailure::Kif)
        }
        LaneFilter::Wrls(wl) => wl.update(&lane.points).map_err(FilterFailure::Wrls),
    };
    if let Err(e) = updated {
        health.filter_failed(side, e);
        lane.filter.clone_from(&lane.predicted);
        lane.miss(cfg.track.lost_after_frames);
        return;
    }
    // Jump gate at the top and bottom rows searched.
    let (Some(new), Some(pred)) = (lane.filter.as_ref(), lane.predicted.as_ref()) else {
        return;
    };
    let jump = [top as f64, (bottom - 1) as f64]
        .iter()
        .map(|&y| (new.col_at_row(y) - pred.col_at_row(y)).abs())
        .fold(0.0f64, f64::max);
    // The first update after an initialisation corrects the LS fit (P0) and is not gated.
    let within = jump <= cfg.track.max_jump_px; // false for NaN too
    if !lane.fresh && !within {
        health.counters.gated_jumps[side.index()] += 1;
        lane.filter.clone_from(&lane.predicted);
        lane.miss(cfg.track.lost_after_frames);
        return;
    }
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for &(_, y) in &lane.points {
        lo = lo.min(f64::from(y));
        hi = hi.max(f64::from(y));
    }
    lane.rows = [lo, hi];
    lane.fit = fit_profile(&lane.points, &lane.weights, lane.rows);
    lane.points_now = lane.points.len();
    lane.state = LaneState::Tracking;
    lane.misses = 0;
    lane.updated_now = true;
    lane.fresh = false;
}
