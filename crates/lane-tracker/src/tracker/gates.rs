//! The gates between the two lanes: the pair gate (a tracked pair that lost an ego lane's shape
//! is dropped and chosen again) and the crossing gate (lanes may not cross nor come too close;
//! the estimate that changed is undone).
//!
//! Decisions and figures: `docs/lanes/history/pair-gate.md`.

use hough_init::pair_shape_is_plausible;

use super::lane::{Health, Lanes};
use super::report::{LaneState, Side};
use super::setup::{Rows, Setup};

/// The pair gate (joint initialisation only, `init.candidate_lines > 0`): two tracked lanes
/// whose chords over the ROI rows no longer have the shape of an ego lane have lost at
/// least one boundary to something else — and which one cannot be told from the pair
/// alone. Both are dropped, and the joint initialisation that follows on the same frame
/// chooses the pair again among all candidates. The shape is
/// `hough_init::pair_shape_is_plausible` with [`Setup::tracked_pair_rules`] (the width at the
/// bottom ROI row, in order below the ROI's top `meet_top_frac`, not diverging upwards).
/// Returns whether the pair was dropped.
pub(super) fn pair_gate(lanes: &mut Lanes, rows: Rows, setup: &Setup, health: &mut Health) -> bool {
    if setup.cfg.init.candidate_lines == 0 {
        return false;
    }
    let [l, r] = lanes.pair();
    let (Some(lf), Some(rf)) = (l.filter.as_ref(), r.filter.as_ref()) else {
        return false;
    };
    if !(l.has_estimate() && r.has_estimate()) {
        return false;
    }
    let (top, bottom) = rows;
    let (yt, yb) = (top as f64, (bottom - 1) as f64);
    let (left, right) = (lf.chord(yt, yb, 0.0), rf.chord(yt, yb, 0.0));
    if pair_shape_is_plausible(
        &left,
        &right,
        setup.width as f64,
        &setup.tracked_pair_rules(),
    ) {
        return false;
    }
    health.counters.gated_pairs += 1;
    for lane in lanes.iter_mut() {
        lane.drop_estimate();
    }
    true
}

/// Left and right lanes may not cross below the top `init.ego_pair.meet_top_frac` of the ROI
/// rows (at the top row when it is 0: where the vanishing point may lie, as for the ego
/// pair's choice), nor come closer than `min_lane_separation_px` at the middle and bottom
/// ROI rows. The offending estimate is the one that changed on this
/// frame by initialisation, else the one backed by fewer points; it is undone. The gate
/// compares the edges the filters track: a kerb's offset (`init.kerb_foot`, at most
/// `gradient.stripe_max_width_px + 1` px towards the road) is not part of it.
pub(super) fn crossing_gate(lanes: &mut Lanes, rows: Rows, setup: &Setup, health: &mut Health) {
    let [l, r] = lanes.pair();
    let (Some(lf), Some(rf)) = (l.filter.as_ref(), r.filter.as_ref()) else {
        return;
    };
    if !(l.has_estimate() && r.has_estimate()) {
        return;
    }
    let (top, bottom) = rows;
    let sep = setup.cfg.track.min_lane_separation_px;
    // Lanes converge towards the horizon: at the row `meet_top_frac` of the ROI down (the top
    // row for 0) they need only be in order, at the middle and bottom rows `sep` apart.
    let meet = setup.cfg.init.ego_pair.meet_top_frac;
    let rows = [
        (top as f64 + meet * (bottom - 1 - top) as f64, 0.0),
        (0.5 * (top + bottom - 1) as f64, sep),
        ((bottom - 1) as f64, sep),
    ];
    let crossed = rows.iter().any(|&(y, s)| {
        (rf.col_at_row(y) - lf.col_at_row(y))
            .partial_cmp(&s)
            .is_none_or(|o| o.is_lt())
    });
    if !crossed {
        return;
    }
    let victim = match (l.initialised_now, r.initialised_now) {
        (true, false) => Side::Left,
        (false, true) => Side::Right,
        _ if r.points_now < l.points_now => Side::Right,
        _ => Side::Left,
    };
    let v = victim.index();
    let c = &mut health.counters;
    c.gated_crossings[v] += 1;
    let lane = &mut lanes[victim];
    if let Some(before) = lane.replaced.take() {
        // A switch to another candidate (re-validation), or a lane set aside and replaced
        // by the frame's searches: the tracked lane comes back as it was after this frame's
        // update (or miss).
        lane.restore(before);
        c.initialisations[v] = c.initialisations[v].saturating_sub(1);
        c.revalidation_switches[v] = c.revalidation_switches[v].saturating_sub(1);
    } else if lane.initialised_now {
        lane.initialised_now = false;
        lane.filter = None;
        lane.points_now = 0;
        lane.state = if c.initialisations[v] > 1 {
            LaneState::Lost
        } else {
            LaneState::Initialising
        };
        c.initialisations[v] -= 1;
    } else {
        if lane.predicted.is_some() {
            lane.filter.clone_from(&lane.predicted);
        }
        lane.miss(setup.cfg.track.lost_after_frames);
    }
}
