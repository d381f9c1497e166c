//! The tracker's failure paths: a filter that refuses an update is counted, its typed error kept,
//! the lane coasts on its prediction, and none of it allocates.

use alloc_counter::{CountingAllocator, allocations_in};
use info_filter::KifError;
use vision_gradient::{EdgeClass, EdgePixel, GreyImage};
use wrls::WrlsError;

use super::init::counts_as;
use super::{Estimator, InitCandidate, LaneFilter, LaneState, LaneTracker, SavedEstimate, Side};
use crate::{FilterFailure, GreyFrame, TrackerConfig};
use hough_init::Parabola;
use nalgebra::Vector3;

#[global_allocator]
static ALLOC: CountingAllocator = CountingAllocator::new();

/// The centre of `two_marks`' left (`/`) mark at row `y`, px.
fn mark_left(y: f64) -> f64 {
    100.0 - 0.45 * (y - 239.0)
}

/// The centre of `two_marks`' right (`\`) mark at row `y`, px.
fn mark_right(y: f64) -> f64 {
    220.0 + 0.45 * (y - 239.0)
}

/// Two bright marks (`/` left, `\` right) 5 px wide on a dark floor.
fn two_marks(w: usize, h: usize) -> GreyFrame {
    let (left, right) = (mark_left, mark_right);
    let mut pixels = vec![60u8; w * h];
    for (i, p) in pixels.iter_mut().enumerate() {
        let (x, y) = ((i % w) as f64, (i / w) as f64);
        if (x - left(y)).abs() < 2.5 || (x - right(y)).abs() < 2.5 {
            *p = 200;
        }
    }
    GreyFrame::from_vec(w, h, pixels).expect("a whole frame")
}

#[test]
fn a_refused_kif_update_is_counted_kept_typed_and_does_not_allocate() {
    let cfg = TrackerConfig::default_preset().expect("the default preset");
    let frame = two_marks(320, 240);
    let mut tracker = LaneTracker::new(&cfg, Estimator::Kif, 320, 240).expect("a tracker");
    let first = tracker.track(&frame).expect("a frame of the right size");
    assert!(first.lanes.iter().all(|l| l.state == LaneState::Tracking));
    assert_eq!(tracker.last_filter_error(Side::Left), None);
    // A measurement variance no validated configuration holds: the KIF refuses every update.
    tracker.cfg.filter.r_sigma_px = 0.0;
    let (report, allocations) = allocations_in(|| tracker.track(&frame));
    let report = report.expect("a refused update is a miss, not an error");
    assert_eq!(allocations, 0, "the failure path allocated");
    assert_eq!(tracker.counters().filter_failures, [1, 1]);
    for side in [Side::Left, Side::Right] {
        assert!(
            matches!(
                tracker.last_filter_error(side),
                Some(FilterFailure::Kif(KifError::InvalidVariance { .. }))
            ),
            "{side:?}: {:?}",
            tracker.last_filter_error(side)
        );
    }
    // The lanes coast on their predictions, with coefficients.
    assert!(
        report
            .lanes
            .iter()
            .all(|l| l.state == LaneState::Coasting && l.coeffs.is_some())
    );
    tracker.reset();
    assert_eq!(tracker.last_filter_error(Side::Right), None);
}

#[test]
fn a_refused_wrls_set_up_is_counted_and_kept_typed() {
    let mut cfg = TrackerConfig::default_preset().expect("the default preset");
    // One initialisation a side on this frame (no second search).
    cfg.roi.fallback_top_row_fraction = None;
    let frame = two_marks(320, 240);
    let mut tracker = LaneTracker::new(&cfg, Estimator::Wrls, 320, 240).expect("a tracker");
    // A forgetting factor no validated configuration holds: WRLS refuses to start.
    tracker.cfg.filter.wrls_lambda = 0.0;
    let (report, allocations) = allocations_in(|| tracker.track(&frame));
    let report = report.expect("a refused initialisation is not an error");
    assert_eq!(allocations, 0, "the failure path allocated");
    assert!(report.lanes.iter().all(|l| l.coeffs.is_none()));
    assert_eq!(tracker.counters().filter_failures, [1, 1]);
    assert!(matches!(
        tracker.last_filter_error(Side::Left),
        Some(FilterFailure::Wrls(
            WrlsError::InvalidForgettingFactor { .. }
        ))
    ));
}

/// `two_marks` with a bright bar 5 px wide leaning the left mark's way but much flatter
/// (`dx/dy = −2.5`, 22° from the horizontal against the mark's 66°), crossing the left mark
/// around row 190: the same edge class, another direction (a crosswalk stripe, a car's rear).
fn two_marks_and_a_crossing_bar(w: usize, h: usize) -> GreyFrame {
    let clean = two_marks(w, h);
    let bar = |y: f64| 100.0 - 0.45 * (190.0 - 239.0) - 2.5 * (y - 190.0);
    let mut pixels = clean.data().to_vec();
    for (i, p) in pixels.iter_mut().enumerate() {
        let (x, y) = ((i % w) as f64, (i / w) as f64);
        if (x - bar(y)).abs() < 6.0 && (170.0..210.0).contains(&y) {
            *p = 200;
        }
    }
    GreyFrame::from_vec(w, h, pixels).expect("a whole frame")
}

#[test]
fn the_orientation_gate_keeps_a_crossing_bar_out_of_the_window_points() {
    let left = mark_left;
    let far_points = |cfg: &TrackerConfig| {
        let mut tracker = LaneTracker::new(cfg, Estimator::Kif, 320, 240).expect("a tracker");
        tracker.track(&two_marks(320, 240)).expect("a frame");
        tracker
            .track(&two_marks_and_a_crossing_bar(320, 240))
            .expect("a frame");
        let view = tracker.lane_view(Side::Left);
        assert!(!view.points.is_empty());
        view.points
            .iter()
            .filter(|(x, y)| (f64::from(*x) - left(f64::from(*y))).abs() > 4.0)
            .count()
    };
    let cfg = TrackerConfig::default_preset().expect("the default preset");
    assert!(cfg.track.orientation_tolerance_deg > 0.0);
    assert_eq!(far_points(&cfg), 0, "bar pixels passed the gate");
    let mut ungated = cfg;
    ungated.track.orientation_tolerance_deg = 0.0;
    assert!(far_points(&ungated) > 0, "the bar never reached the window");
}

#[test]
fn the_joint_initialisation_reports_its_candidates_and_the_chosen_pair() {
    let (left, right) = (mark_left, mark_right);
    let col = |c: [f64; 3], y: f64| c[0] * y * y + c[1] * y + c[2];
    let frame = two_marks(320, 240);
    let cfg = TrackerConfig::default_preset().expect("the default preset");
    let mut lines_only = cfg;
    lines_only.init.candidate_coverage = false;
    for cfg in [cfg, lines_only] {
        let mut tracker = LaneTracker::new(&cfg, Estimator::Kif, 320, 240).expect("a tracker");
        let (top, bottom) = tracker.roi;
        let (yt, yb) = (top as f64, (bottom - 1) as f64);
        let report = tracker.track(&frame).expect("a frame");
        let cands = tracker.init_candidates();
        assert!(!cands.is_empty() && cands.len() <= 2 * cfg.init.candidate_lines);
        for (side, truth) in [
            (Side::Left, &left as &dyn Fn(f64) -> f64),
            (Side::Right, &right),
        ] {
            let chosen: Vec<_> = cands.iter().filter(|c| c.chosen == Some(side)).collect();
            assert_eq!(chosen.len(), 1, "{side:?}: {cands:?}");
            let c = chosen[0];
            assert_eq!(c.band, side, "a straight mark votes in its own band");
            // A Hough line (1° steps) may sit on one side of the 5 px mark; its LS parabola on
            // the mark (the candidates of one mark tie on their row coverage, each row's cap
            // reached, and the pair's width term picks among them), and the lane reported after
            // the refinement on its middle.
            let tol_px = if cfg.init.candidate_coverage {
                2.5
            } else {
                5.0
            };
            let reported = report.lanes[side as usize]
                .coeffs
                .expect("a lane on each mark");
            for y in [yt, yb] {
                let err = (col(c.coeffs, y) - truth(y)).abs();
                assert!(err < tol_px, "{side:?} at row {y}: {err} px, {c:?}");
                let err = (col(reported, y) - truth(y)).abs();
                assert!(err < 1.0, "{side:?} reported at row {y}: {err} px");
            }
            assert!(c.support > 0.0);
            if !cfg.init.candidate_coverage {
                assert_eq!(
                    c.coeffs[0], 0.0,
                    "without coverage a candidate is its Hough line"
                );
            }
        }
        // A tracking frame runs no initialisation: no candidates.
        let (tracked, allocations) = allocations_in(|| tracker.track(&frame));
        assert!(
            tracked
                .expect("a frame")
                .lanes
                .iter()
                .all(|l| !l.initialised)
        );
        assert!(tracker.init_candidates().is_empty());
        assert_eq!(allocations, 0);
        // Re-initialising reports them again, without allocating.
        tracker.reset();
        let (again, allocations) = allocations_in(|| tracker.track(&frame));
        assert!(again.expect("a frame").lanes.iter().all(|l| l.initialised));
        assert_eq!(
            tracker
                .init_candidates()
                .iter()
                .filter(|c| c.chosen.is_some())
                .count(),
            2
        );
        assert_eq!(allocations, 0, "a joint initialisation allocated");
    }
}

/// Two bright marks 5 px wide on a dark floor, their vanishing point above the image, the right
/// one painted only on rows 80..140, above the default ROI (from row 148 at 240 rows): a dash
/// whose near field falls in the gap before the next one.
fn left(y: f64) -> f64 {
    60.0 - 0.3 * (y - 239.0)
}
fn right(y: f64) -> f64 {
    260.0 + 0.3 * (y - 239.0)
}
fn right_mark_above_the_roi(w: usize, h: usize) -> GreyFrame {
    right_dash_on_rows(w, h, 80.0..140.0)
}
fn right_dash_on_rows(w: usize, h: usize, rows: std::ops::Range<f64>) -> GreyFrame {
    right_dash_shifted(w, h, rows, 0.0)
}
/// [`right_dash_on_rows`] with the right mark `shift_px` to the right of `right`.
fn right_dash_shifted(w: usize, h: usize, rows: std::ops::Range<f64>, shift_px: f64) -> GreyFrame {
    let mut pixels = vec![60u8; w * h];
    for (i, p) in pixels.iter_mut().enumerate() {
        let (x, y) = ((i % w) as f64, (i / w) as f64);
        let on_right = (x - right(y) - shift_px).abs() < 2.5 && rows.contains(&y);
        if (x - left(y)).abs() < 2.5 || on_right {
            *p = 200;
        }
    }
    GreyFrame::from_vec(w, h, pixels).expect("a whole frame")
}

#[test]
fn a_side_missing_from_the_roi_is_found_by_the_second_search_over_the_taller_rows() {
    let frame = right_mark_above_the_roi(320, 240);
    let cfg = TrackerConfig::default_preset().expect("the default preset");
    let mut roi_only = cfg;
    roi_only.roi.fallback_top_row_fraction = None;
    let mut plain = LaneTracker::new(&roi_only, Estimator::Kif, 320, 240).expect("a tracker");
    let without = plain.track(&frame).expect("a frame");
    assert!(without.lanes[0].coeffs.is_some());
    assert_eq!(without.lanes[1].coeffs, None, "no right mark in the ROI");
    let first_search = plain.init_candidates().len();

    let mut tracker = LaneTracker::new(&cfg, Estimator::Kif, 320, 240).expect("a tracker");
    let (top, _) = tracker.roi;
    assert!(
        tracker
            .fallback_roi
            .is_some_and(|(t, _)| t < 80 && top > 140)
    );
    let (report, allocations) = allocations_in(|| tracker.track(&frame));
    let report = report.expect("a frame");
    assert_eq!(allocations, 0, "the second search allocated");
    // The side found in the ROI is the same lane, untouched by the second search.
    assert_eq!(report.lanes[0].coeffs, without.lanes[0].coeffs);
    let r = report.lanes[1];
    assert!(r.initialised && r.state == LaneState::Tracking);
    for y in [80.0, 110.0, 139.0] {
        let err = (r.col_at_row(y).expect("a right lane") - right(y)).abs();
        assert!(err < 1.5, "row {y}: {err} px off the right mark");
    }
    // Extrapolated 100 rows below the dash's 60.
    let err = (r.col_at_row(239.0).expect("a right lane") - right(239.0)).abs();
    assert!(err < 8.0, "bottom row: {err} px off the right mark's line");
    assert!(r.rows[1] < 140.0, "its points are the dash's: {:?}", r.rows);
    // Both searches' candidates are reported; the right one chosen is the second search's.
    let cands = tracker.init_candidates();
    assert!(cands.len() > first_search, "{cands:?}");
    let chosen: Vec<usize> = (0..cands.len())
        .filter(|&j| cands[j].chosen == Some(Side::Right))
        .collect();
    assert_eq!(chosen.len(), 1, "{cands:?}");
    assert!(chosen[0] >= first_search, "{cands:?}");
}

#[test]
fn a_lane_the_second_search_found_is_tracked_over_the_taller_rows() {
    // The right mark lies only above the ROI (a camera looking down, the far dash of a dashed
    // mark). The second search finds it; on the next frames the lane is tracked where its mark
    // is — over the taller rows — not searched for again: tracking on every frame, on the mark,
    // no new initialisation. Tracked over the ROI's rows alone its windows would be empty: a
    // miss, then a set-aside and a new initialisation every other frame.
    let frame = right_mark_above_the_roi(320, 240);
    let run = |tall_tracking: bool| {
        let cfg = TrackerConfig::default_preset().expect("the default preset");
        let mut tracker = LaneTracker::new(&cfg, Estimator::Kif, 320, 240).expect("a tracker");
        let first = tracker.track(&frame).expect("a frame");
        assert!(first.lanes[1].initialised, "found by the second search");
        let mut states = Vec::new();
        let mut worst_px = 0.0f64;
        // Past the default's periodic re-validation (every 10th frame): with no candidate for
        // its side in the ROI, the choice keeps it.
        for _ in 0..12 {
            if !tall_tracking {
                tracker.lanes[1].tracked_tall = false;
            }
            let r = tracker.track(&frame).expect("a frame").lanes[1];
            states.push((r.state, r.points));
            for y in [80.0, 110.0, 139.0] {
                let x = r.col_at_row(y).unwrap_or(f64::INFINITY);
                worst_px = worst_px.max((x - right(y)).abs());
            }
        }
        let counters = *tracker.counters();
        tracker.reset();
        assert!(
            tracker.lanes.iter().all(|l| !l.tracked_tall),
            "reset clears it"
        );
        (states, worst_px, counters)
    };
    let (states, worst_px, counters) = run(true);
    assert!(
        states
            .iter()
            .all(|&(s, points)| s == LaneState::Tracking && points >= 30),
        "{states:?}"
    );
    assert!(worst_px < 1.5, "{worst_px} px off the right mark");
    assert_eq!(counters.initialisations, [1, 1]);
    assert_eq!(counters.set_asides, [0, 0]);
    assert!(counters.revalidations >= 1, "{counters:?}");
    // Over the ROI's rows alone (the flag cleared before each frame), the lane is searched
    // for again and again.
    let (states, _, counters) = run(false);
    assert!(
        states.iter().any(|&(s, _)| s != LaneState::Tracking),
        "{states:?}"
    );
    assert!(counters.initialisations[1] > 2, "{counters:?}");
}

/// The foot of `kerb_above_the_roi`'s kerb, whose top edge is `right(y)`: its face widens
/// from 5 px at row 76 to 8 px at row 146.
fn tall_kerb_foot_col(y: f64) -> f64 {
    right(y) - (5.0 + 3.0 * (y - 76.0) / 70.0)
}
/// On a road of level 55, the left mark of [`right_mark_above_the_roi`] on every row, and on
/// the right a kerb (`kerb_level`: top edge `right(y)`, foot `tall_kerb_foot_col(y)`) seen only
/// on rows 76..146, above the default ROI (from row 148): plain road below.
fn kerb_above_the_roi(w: usize, h: usize) -> GreyFrame {
    let mut pixels = vec![55u8; w * h];
    for (i, p) in pixels.iter_mut().enumerate() {
        let (x, y) = ((i % w) as f64, (i / w) as f64);
        if (x - left(y)).abs() < 2.5 {
            *p = 200;
        } else if (76.0..146.0).contains(&y) {
            *p = kerb_level(x, right(y), tall_kerb_foot_col(y), true);
        }
    }
    GreyFrame::from_vec(w, h, pixels).expect("a whole frame")
}

#[test]
fn a_kerb_the_second_search_found_is_read_again_over_the_taller_rows() {
    // The right boundary is a kerb seen only above the ROI. The second search finds its top
    // edge and the boundary is moved to its foot, read over the taller rows; tracked on, the
    // kerb is read again over the same rows, so the boundary stays on the foot. Read over the
    // ROI's rows (plain road) the kerb would be missed and its offset dropped after
    // `track.lost_after_frames` frames: the boundary back on the top edge, 5–8 px off.
    let frame = kerb_above_the_roi(320, 240);
    let cfg = TrackerConfig::default_preset().expect("the default preset");
    assert!(cfg.init.kerb_foot);
    let mut tracker = LaneTracker::new(&cfg, Estimator::Kif, 320, 240).expect("a tracker");
    let rows = [80.0, 110.0, 140.0];
    let off_foot = |r: &super::LaneReport| {
        rows.map(|y| r.col_at_row(y).unwrap_or(f64::INFINITY) - (tall_kerb_foot_col(y) - 0.5))
    };
    let first = tracker.track(&frame).expect("a frame").lanes[1];
    assert!(first.initialised && tracker.lanes[1].tracked_tall);
    assert_ne!(tracker.lanes[1].kerb_offset_px, [0.0; 2], "no kerb read");
    let d = off_foot(&first);
    assert!(d.iter().all(|d| d.abs() < 1.0), "{d:?} px off the foot");
    // The tracked edge is the top edge (the filter keeps what its windows measure).
    let tracked = tracker.lanes[1].filter.as_ref().map(LaneFilter::coeffs);
    let top = tracked.map(|c| Parabola::from_coeffs(c).col_at_row(110.0) - (right(110.0) - 0.5));
    assert!(
        top.is_some_and(|d| d.abs() < 1.0),
        "{top:?} px off the top edge"
    );
    let frames = 3 * cfg.track.lost_after_frames + 2;
    for frame_no in 0..frames {
        let r = tracker.track(&frame).expect("a frame").lanes[1];
        assert!(
            !r.initialised && r.state == LaneState::Tracking,
            "frame {frame_no}: {r:?}"
        );
        let d = off_foot(&r);
        assert!(
            d.iter().all(|d| d.abs() < 1.0),
            "frame {frame_no}: {d:?} px off the foot"
        );
    }
    assert_eq!(tracker.counters().initialisations, [1, 1]);
}

#[test]
fn a_weak_lane_the_revalidation_does_not_keep_is_searched_for_again_on_its_second_weak_frame() {
    // Both lanes tracked on their marks; then the right mark is gone from the ROI and a dash of
    // another one, 30 px farther right, lies above it (a lane ending, a camera pitched up over
    // a crest). The right window comes up empty, so each frame is re-validated
    // (`track.revalidate_below_points`); the choice keeps the left lane and has nothing for the
    // right one. On the first such frame it coasts (one weak frame may be a dropout); on the
    // second it is set aside while the second search looks for its side over the taller rows —
    // and finds the dash. With the period alone it coasts at its old place until it is lost.
    let cfg = TrackerConfig::default_preset().expect("the default preset");
    assert!(
        cfg.roi
            .fallback_top_row_fraction
            .is_some_and(|f| f < 80.0 / 240.0)
    );
    assert!(cfg.track.lost_after_frames > 2);
    let run = |cfg: &TrackerConfig| {
        let mut tracker = LaneTracker::new(cfg, Estimator::Kif, 320, 240).expect("a tracker");
        let (top, bottom) = tracker.roi;
        let both = right_dash_on_rows(320, 240, 0.0..240.0);
        for _ in 0..2 {
            let report = tracker.track(&both).expect("a frame");
            assert!(report.lanes.iter().all(|l| l.state == LaneState::Tracking));
        }
        let dash = right_dash_shifted(320, 240, 80.0..140.0, 30.0);
        // The right lane's distance from the dash at three of its rows, after each frame.
        let right_off = |report: &super::TrackReport| {
            [80.0, 110.0, 139.0].map(|y| {
                report.lanes[1]
                    .col_at_row(y)
                    .map_or(f64::INFINITY, |x| (x - right(y) - 30.0).abs())
            })
        };
        let first = tracker.track(&dash).expect("a frame");
        let (first_off, first_state) = (right_off(&first), first.lanes[1].state);
        let report = tracker.track(&dash).expect("a frame");
        let left_off = report.lanes[0].coeffs.map_or(f64::INFINITY, |c| {
            (top..bottom)
                .map(|y| (Parabola::from_coeffs(c).col_at_row(y as f64) - left(y as f64)).abs())
                .fold(0.0, f64::max)
        });
        (
            (first_off, first_state),
            left_off,
            right_off(&report),
            report.lanes[1],
            *tracker.counters(),
        )
    };
    let ((first_off, first_state), left_off, right_off, r, counters) = run(&cfg);
    assert_eq!(first_state, LaneState::Coasting, "the first weak frame");
    assert!(first_off.iter().all(|&e| e > 20.0), "{first_off:?} px");
    assert!(left_off < 1.5, "left lane {left_off} px off its mark");
    assert!(
        right_off.iter().all(|&e| e < 1.5),
        "right lane {right_off:?} px off the dash"
    );
    assert!(r.initialised && r.state == LaneState::Tracking, "{r:?}");
    assert_eq!(counters.revalidations, 2);
    assert_eq!(counters.initialisations, [1, 2]);
    assert_eq!(counters.revalidation_switches, [0, 1]);
    assert_eq!(
        counters.set_asides,
        [0, 1],
        "set aside on its second weak frame only"
    );
    let mut period_only = cfg;
    period_only.track.revalidate_below_points = 0;
    let (_, _, right_off, r, counters) = run(&period_only);
    assert!(right_off.iter().all(|&e| e > 20.0), "{right_off:?} px");
    assert_eq!(r.state, LaneState::Coasting);
    assert_eq!(counters.revalidations, 0);
}

#[test]
fn a_weak_lane_set_aside_coasts_on_when_nothing_replaces_it() {
    // Both lanes tracked; for two frames the right mark is gone everywhere (a car over it, a
    // glare). The right window comes up empty; on the second frame the right lane, weak twice,
    // is set aside, but the second search finds no right boundary: the lane is put back and
    // coasts on its prediction, then tracks the mark again when it returns — no
    // re-initialisation. (That a set-aside lane is searched for is
    // `a_weak_lane_the_revalidation_does_not_keep_is_searched_for_again_on_its_second_weak_frame`;
    // this one fails if the lane is not put back: it is then lost.)
    let cfg = TrackerConfig::default_preset().expect("the default preset");
    assert!(cfg.track.lost_after_frames > 2);
    let mut tracker = LaneTracker::new(&cfg, Estimator::Kif, 320, 240).expect("a tracker");
    let both = right_dash_on_rows(320, 240, 0.0..240.0);
    let mut before = None;
    for _ in 0..3 {
        before = tracker.track(&both).expect("a frame").lanes[1].coeffs;
    }
    let before = before.expect("a right lane");
    let gone = right_dash_on_rows(320, 240, 0.0..0.0);
    let mut report = None;
    for _ in 0..2 {
        report = Some(tracker.track(&gone).expect("a frame"));
    }
    let r = report.expect("two frames").lanes[1];
    assert_eq!(r.state, LaneState::Coasting, "{r:?}");
    let coasting = r.coeffs.expect("the right lane, coasting");
    let (top, bottom) = tracker.roi;
    for y in [top, bottom - 1] {
        let y = y as f64;
        let moved = Parabola::from_coeffs(coasting).col_at_row(y)
            - Parabola::from_coeffs(before).col_at_row(y);
        assert!(moved.abs() < 0.5, "row {y}: moved {moved} px");
    }
    let counters = *tracker.counters();
    assert_eq!(counters.revalidations, 2);
    assert_eq!(counters.revalidation_switches, [0, 0]);
    assert_eq!(counters.set_asides, [0, 1], "set aside, then put back");
    let report = tracker.track(&both).expect("a frame");
    assert!(report.lanes.iter().all(|l| l.state == LaneState::Tracking));
    assert_eq!(tracker.counters().initialisations, [1, 1]);
}

#[test]
fn a_lane_set_aside_stays_with_its_side_through_a_hand_over() {
    // The right lane, weak, is set aside while the second search looks for its side, and that
    // search hands the tracked left lane over to the right (the camera crossed it). The record
    // set aside belongs to the right side: after the searches it is what the lane now on the
    // right replaced (a switch the crossing gate may undo), and the left side is left without a
    // lane to initialise — not given the right lane's estimate back.
    let cfg = TrackerConfig::default_preset().expect("the default preset");
    let mut tracker = LaneTracker::new(&cfg, Estimator::Kif, 320, 240).expect("a tracker");
    let frame = two_marks(320, 240);
    for _ in 0..3 {
        tracker.track(&frame).expect("a frame");
    }
    let coeffs = |t: &LaneTracker, i: usize| t.lanes[i].filter.as_ref().map(LaneFilter::coeffs);
    let (left_before, right_before) = (coeffs(&tracker, 0), coeffs(&tracker, 1));
    assert!(left_before.is_some() && right_before.is_some());
    tracker.lanes[1].set_aside = tracker.lanes[1].take_estimate();
    tracker.hand_over(0, 1, true);
    let sides = tracker.lanes.each_ref().map(|l| (l.side, l.class));
    assert_eq!(
        sides,
        [
            (Side::Left, EdgeClass::LeftLane),
            (Side::Right, EdgeClass::RightLane)
        ]
    );
    assert_eq!(
        coeffs(&tracker, 1),
        left_before,
        "the left lane, handed over"
    );
    assert!(!tracker.lanes[0].has_estimate() && tracker.lanes[0].set_aside.is_none());
    let kept = tracker.lanes[1]
        .set_aside
        .as_ref()
        .map(|s| s.filter.coeffs());
    assert_eq!(
        kept, right_before,
        "the set-aside record moved with the lane"
    );
    tracker.settle_set_asides();
    let replaced = tracker.lanes[1]
        .replaced
        .as_ref()
        .map(|s| s.filter.coeffs());
    assert_eq!(replaced, right_before);
    assert_eq!(coeffs(&tracker, 1), left_before);
    assert!(
        !tracker.lanes[0].has_estimate(),
        "the right lane put back on the left"
    );
    assert_eq!(tracker.counters().revalidation_switches, [0, 1]);
}

/// The second search asks a lane for as many rows as the first one does (a quarter of the
/// ROI's rows: 23 of 91 at 240 rows), not a quarter of its own taller rows (42 of 168): a dash
/// of 30 rows above the ROI is found; one of 20 rows, a Hough candidate of the second search,
/// is refused for its span.
#[test]
fn the_second_search_accepts_a_dash_as_long_as_the_roi_would() {
    let cfg = TrackerConfig::default_preset().expect("the default preset");
    let mut tracker = LaneTracker::new(&cfg, Estimator::Kif, 320, 240).expect("a tracker");
    let (top, bottom) = tracker.roi;
    let (tall_top, _) = tracker.fallback_roi.expect("a second search");
    let min_span = 0.25 * (bottom - top) as f64;
    assert!(30.0 > min_span && 30.0 < 0.25 * (bottom - tall_top) as f64);
    let report = tracker
        .track(&right_dash_on_rows(320, 240, 110.0..140.0))
        .expect("a frame");
    let r = report.lanes[1];
    assert!(r.initialised, "the 30-row dash is refused: {r:?}");
    let err = (r.col_at_row(125.0).expect("a right lane") - right(125.0)).abs();
    assert!(err < 1.5, "{err} px off the dash");
    tracker.reset();
    let report = tracker
        .track(&right_dash_on_rows(320, 240, 120.0..140.0))
        .expect("a frame");
    assert!(20.0 < min_span);
    assert_eq!(report.lanes[1].coeffs, None, "a 20-row dash is accepted");
    // It was a candidate: the refusal is the span's, not the vote's.
    let on_dash = |c: &InitCandidate| {
        let x = c.coeffs[0] * 130.0 * 130.0 + c.coeffs[1] * 130.0 + c.coeffs[2];
        c.band == Side::Right && (x - right(130.0)).abs() < 2.0
    };
    assert!(
        tracker.init_candidates().iter().any(on_dash),
        "{:?}",
        tracker.init_candidates()
    );
}

/// `left(y) ± s(y)` for the two lines of a double line, `2·h(y)` wide, both growing towards
/// the camera as on a real road (`s` 3.3 → 7 px, `h` 1.5 → 2.5 px over the ROI), on the left
/// of `two_marks`' geometry, with its single right mark; `inner_only` paints only the line
/// `left(y) + s(y)`.
fn double_line_left(w: usize, h: usize, inner_only: bool) -> GreyFrame {
    double_line_shifted(w, h, inner_only, 0.0)
}

/// [`double_line_left`] with the double line `shift_px` further left.
fn double_line_shifted(w: usize, h: usize, inner_only: bool, shift_px: f64) -> GreyFrame {
    let (left, right) = (mark_left, mark_right);
    let mut pixels = vec![60u8; w * h];
    for (i, p) in pixels.iter_mut().enumerate() {
        let (x, y) = ((i % w) as f64, (i / w) as f64);
        let (s, half) = (3.0 + 4.0 * (y - 140.0) / 100.0, 1.5 + (y - 140.0) / 100.0);
        let d = x - left(y) + shift_px;
        let outer = !inner_only && (d + s).abs() < half;
        if (d - s).abs() < half || outer || (x - right(y)).abs() < 2.5 {
            *p = 200;
        }
    }
    GreyFrame::from_vec(w, h, pixels).expect("a whole frame")
}

/// A default tracker for 320 × 240 frames and its ROI's top, middle and bottom rows.
fn default_tracker_and_rows() -> (LaneTracker, [f64; 3]) {
    let cfg = TrackerConfig::default_preset().expect("the default preset");
    let tracker = LaneTracker::new(&cfg, Estimator::Kif, 320, 240).expect("a tracker");
    let (top, bottom) = tracker.roi;
    let rows = [top as f64, 0.5 * (top + bottom) as f64, (bottom - 1) as f64];
    (tracker, rows)
}

/// Lane `i`'s filter set to the straight line through `(row, col)` points `a` and `b`.
fn set_lane_line(tracker: &mut LaneTracker, i: usize, a: (f64, f64), b: (f64, f64)) {
    let slope = (b.1 - a.1) / (b.0 - a.0);
    let theta = Vector3::new(0.0, slope, a.1 - slope * a.0);
    tracker.lanes[i].filter = Some(tracker.new_filter(&theta).expect("a filter"));
}

#[test]
fn a_lane_on_one_line_of_a_double_line_is_moved_to_its_middle() {
    let left = mark_left;
    let (mut tracker, rows) = default_tracker_and_rows();
    // The lane on the inner line (the only one painted), then read across the double line.
    let single = double_line_left(320, 240, true);
    tracker.track(&single).expect("a frame");
    let before = tracker.lanes[0].filter.as_ref().map(LaneFilter::coeffs);
    let on_inner = |c: [f64; 3], y: f64| c[0] * y * y + c[1] * y + c[2] - left(y);
    for y in rows {
        let d = on_inner(before.expect("a left lane"), y);
        assert!(
            d > 2.5,
            "row {y}: the lane is not on the inner line ({d} px)"
        );
    }
    fn image(f: &GreyFrame) -> GreyImage<'_> {
        GreyImage::new(f.data(), 320, 240, 320).expect("an image")
    }
    // A single line is not a double line: nothing moves.
    assert!(!tracker.centre_on_double_line(0, &image(&single)));
    assert_eq!(
        tracker.lanes[0].filter.as_ref().map(LaneFilter::coeffs),
        before
    );
    let double = double_line_left(320, 240, false);
    let (moved, allocations) = allocations_in(|| tracker.centre_on_double_line(0, &image(&double)));
    assert!(moved);
    assert_eq!(allocations, 0);
    let after = tracker.lanes[0].filter.as_ref().map(LaneFilter::coeffs);
    for y in rows {
        let d = on_inner(after.expect("a left lane"), y);
        assert!(d.abs() < 1.0, "row {y}: {d} px off the middle");
    }
    // Tracked on, the lane stays near the middle: its windows reach both lines (with the
    // default ±10 px it drifts onto the outer line, ≈ 6 px off at the bottom row). Within 3 px:
    // the middle row sits 2–2.8 px outwards from the first tracked frame on (a curvature bias
    // of the windows' quartile gate with four edges in them; the end rows within 1.6 px).
    for frame in 0..10 {
        let report = tracker.track(&double).expect("a frame");
        assert!(!report.lanes[0].initialised);
        for y in rows {
            let d = on_inner(report.lanes[0].coeffs.expect("a left lane"), y);
            assert!(
                d.abs() < 3.0,
                "frame {frame}, row {y}: {d} px off the middle"
            );
        }
    }
}

#[test]
fn a_lane_leaning_across_a_double_line_from_between_its_lines_is_moved_to_its_middle() {
    let left = mark_left;
    let (mut tracker, rows) = default_tracker_and_rows();
    let double = double_line_left(320, 240, false);
    tracker.track(&double).expect("a frame");
    // The lane between the two lines but leaning across them: 1 px left of the middle at the
    // top row, 3 px right of it at the bottom (the valley is 3.5 px wide at the top, 9 px at
    // the bottom).
    let (y0, y1) = (rows[0], rows[2]);
    set_lane_line(&mut tracker, 0, (y0, left(y0) - 1.0), (y1, left(y1) + 3.0));
    let image = GreyImage::new(double.data(), 320, 240, 320).expect("an image");
    let (moved, allocations) = allocations_in(|| tracker.centre_on_double_line(0, &image));
    assert!(moved, "read from between the lines");
    assert_eq!(allocations, 0);
    let c = tracker.lanes[0]
        .filter
        .as_ref()
        .map(LaneFilter::coeffs)
        .expect("a left lane");
    for y in rows {
        let d = c[0] * y * y + c[1] * y + c[2] - left(y);
        assert!(d.abs() < 1.0, "row {y}: {d} px off the middle");
    }
    // Its windows reach both lines: at least twice the half gap at the widest row (7 px at the
    // bottom: s(y) = 3 + 4·(y − 140)/100).
    let half_gap = tracker.lanes[0].pair_half_gap_px;
    assert!((half_gap - 6.96).abs() < 1.0, "half gap {half_gap} px");
}

#[test]
fn a_double_line_leaving_the_image_is_read_on_the_rows_it_is_inside() {
    // The double line 128 px further left leaves the image through its left side: its middle
    // at row 176; the lane, on its inner line, is inside on rows 148–187 of the ROI's 148–239,
    // its outer line wholly only down to about row 164, enough of it to be read down to about
    // row 169. The pair shows on about 22 rows: more than 30 % of the 40 rows where the lane is
    // inside the image, fewer than 30 % of the ROI's 92.
    let shift = 128.0;
    let (mut tracker, rows) = default_tracker_and_rows();
    let double = double_line_shifted(320, 240, false, shift);
    tracker.track(&double).expect("a frame");
    let middle = |y: f64| mark_left(y) - shift;
    let inner = |y: f64| middle(y) + 3.0 + 4.0 * (y - 140.0) / 100.0;
    let (y0, y1) = (rows[0], rows[2]);
    assert!(middle(y0) > 10.0 && middle(175.0) > 0.0 && middle(177.0) < 0.0);
    // The lane on the inner line (a straight line through it at the top and bottom rows).
    set_lane_line(&mut tracker, 0, (y0, inner(y0)), (y1, inner(y1)));
    let image = GreyImage::new(double.data(), 320, 240, 320).expect("an image");
    assert!(
        tracker.centre_on_double_line(0, &image),
        "not read as a double line"
    );
    let c = tracker.lanes[0]
        .filter
        .as_ref()
        .map(LaneFilter::coeffs)
        .expect("a left lane");
    for y in [y0, 160.0, 170.0] {
        let d = c[0] * y * y + c[1] * y + c[2] - middle(y);
        assert!(d.abs() < 1.0, "row {y}: {d} px off the middle");
    }
}

/// A steep double line near the left border, `two_marks`' right mark on the right: lines 3 px
/// wide (bright 200 on a floor of 60, horizontal runs `|x − c| < 1.5`) at `middle(y) ± 3`,
/// `middle(y) = col_at_top_px − 2·(y − 148)` (2 px a row to the left going down: it leaves
/// the image through its left side within a few rows of the ROI's top row, 148).
fn steep_double_line(col_at_top_px: f64) -> GreyFrame {
    let (w, h) = (320usize, 240usize);
    let middle = |y: f64| col_at_top_px - 2.0 * (y - 148.0);
    let mut pixels = vec![60u8; w * h];
    for (i, p) in pixels.iter_mut().enumerate() {
        let (x, y) = ((i % w) as f64, (i / w) as f64);
        let d = x - middle(y);
        if (d - 3.0).abs() < 1.5 || (d + 3.0).abs() < 1.5 || (x - mark_right(y)).abs() < 2.5 {
            *p = 200;
        }
    }
    GreyFrame::from_vec(w, h, pixels).expect("a whole frame")
}

#[test]
fn a_double_line_seen_on_fewer_than_eight_rows_is_not_read() {
    // The lane on the inner line of a steep double line: both lines inside the image on the
    // ROI's first rows only, the inner one on a few rows more. With the middle at column 12,
    // 15, 17 or 22 on the top row the pair shows on 5, 7, 8 or 10 rows, each more than 30 % of
    // the 8, 10, 11 or 13 rows where the lane is inside the image (counts read with a probe
    // when the test was written): read from 8 rows (`MIN_PAIR_ROWS`) on. With the constant at
    // 0 the lane moves at 12 (tried).
    let read = |col_at_top_px: f64| {
        let (mut tracker, rows) = default_tracker_and_rows();
        let frame = steep_double_line(col_at_top_px);
        tracker.track(&frame).expect("a frame");
        let inner = |y: f64| col_at_top_px - 2.0 * (y - 148.0) + 3.0;
        set_lane_line(
            &mut tracker,
            0,
            (rows[0], inner(rows[0])),
            (rows[2], inner(rows[2])),
        );
        let image = GreyImage::new(frame.data(), 320, 240, 320).expect("an image");
        tracker.centre_on_double_line(0, &image)
    };
    assert!(!read(12.0), "read on 5 rows");
    assert!(!read(15.0), "read on 7 rows");
    assert!(read(17.0), "not read on 8 rows");
    assert!(read(22.0), "not read on 10 rows");
}

/// `two_marks`' left mark, and on the right a raised kerb: the road (55) up to a groove (45)
/// 2 px wide at the foot `kerb_foot_col(y)`, the face (55) from the foot to the top edge
/// `kerb_top(y)`, the pavement (100) beyond it, each pixel the area average of what it covers
/// (the levels and the soft edges of a real kerb: the groove's edges stay below the gradient
/// threshold); the face widens towards the camera as on a real kerb (5 → 9 px over the ROI),
/// `extra_px` wider still. `plain`: the same step with no face and no groove. Positions are
/// continuous, pixel `x` covering `[x, x + 1)`: an edge at `e` lies between the pixels
/// around `e − ½` in the tracker's column coordinates.
fn kerb_right(w: usize, h: usize, plain: bool, extra_px: f64) -> GreyFrame {
    let left = mark_left;
    let mut pixels = vec![55u8; w * h];
    for (i, p) in pixels.iter_mut().enumerate() {
        let (x, y) = ((i % w) as f64, (i / w) as f64);
        *p = if (x - left(y)).abs() < 2.5 {
            200
        } else {
            kerb_level(x, kerb_top(y), kerb_foot_col(y, extra_px), !plain)
        };
    }
    GreyFrame::from_vec(w, h, pixels).expect("a whole frame")
}
/// Pixel `x`'s level across a right-hand kerb whose top edge is at column `top` and foot at
/// `foot` (continuous, pixel `x` covering `[x, x + 1)`): road and face 55, the groove (45,
/// 2 px wide, ending at the foot) if `groove`, the pavement 100, each pixel the area average.
fn kerb_level(x: f64, top: f64, foot: f64, groove: bool) -> u8 {
    let overlap = |a: f64, b: f64| (b.min(x + 1.0) - a.max(x)).clamp(0.0, 1.0);
    let pavement = overlap(top, f64::INFINITY);
    let groove = if groove {
        overlap(foot - 2.0, foot)
    } else {
        0.0
    };
    (55.0 + 45.0 * pavement - 10.0 * groove).round() as u8
}
fn kerb_top(y: f64) -> f64 {
    230.0 + 0.45 * (y - 239.0)
}
/// The foot's column: the face starts there, the groove ends there.
fn kerb_foot_col(y: f64, extra_px: f64) -> f64 {
    kerb_top(y) - (5.0 + extra_px + 4.0 * (y - 140.0) / 100.0)
}

#[test]
fn a_lane_on_a_kerbs_top_edge_is_reported_on_its_foot_and_stays_there() {
    let mut cfg = TrackerConfig::default_preset().expect("the default preset");
    assert!(cfg.init.kerb_foot, "the default reads kerbs");
    cfg.init.kerb_foot = false;
    let mut tracker = LaneTracker::new(&cfg, Estimator::Kif, 320, 240).expect("a tracker");
    let (top, bottom) = tracker.roi;
    let rows = [top as f64, 0.5 * (top + bottom) as f64, (bottom - 1) as f64];
    let tracked = |t: &LaneTracker| t.lanes[1].filter.as_ref().map(LaneFilter::coeffs);
    let reported = |t: &LaneTracker| t.lanes[1].report().coeffs;
    let col = |c: Option<[f64; 3]>, y: f64| {
        let c = c.expect("a right lane");
        c[0] * y * y + c[1] * y + c[2]
    };
    let off_foot = |c: Option<[f64; 3]>, y: f64| col(c, y) - (kerb_foot_col(y, 0.0) - 0.5);
    fn image(f: &GreyFrame) -> GreyImage<'_> {
        GreyImage::new(f.data(), 320, 240, 320).expect("an image")
    }
    // Without the rule the lane lies on the top edge (within a pixel of `kerb_top − ½`), off
    // the foot.
    let kerb = kerb_right(320, 240, false, 0.0);
    tracker.track(&kerb).expect("a frame");
    let on_top = tracked(&tracker);
    assert_eq!(reported(&tracker), on_top);
    for y in rows {
        let d = col(on_top, y) - (kerb_top(y) - 0.5);
        assert!(
            d.abs() < 1.0,
            "row {y}: the lane is {d} px off the top edge"
        );
    }
    // A plain step is not a kerb: nothing moves.
    let plain = kerb_right(320, 240, true, 0.0);
    assert!(!tracker.onto_kerb_foot(1, &image(&plain)));
    assert_eq!(reported(&tracker), on_top);
    // Read across the kerb, the boundary reported moves to its foot (the rise out of the
    // groove, between foot − 1 and foot), without allocating; the filter keeps the edge its
    // windows measure.
    let (moved, allocations) = allocations_in(|| tracker.onto_kerb_foot(1, &image(&kerb)));
    assert!(moved);
    assert_eq!(allocations, 0);
    assert_eq!(tracked(&tracker), on_top);
    for y in rows {
        let d = off_foot(reported(&tracker), y);
        assert!(d.abs() < 1.0, "row {y}: {d} px off the foot");
    }
    // Tracked on: the boundary stays on the foot (a filter restarted there would be pulled
    // back to the top edge by its windows).
    for frame in 0..10 {
        let report = tracker.track(&kerb).expect("a frame");
        assert!(!report.lanes[1].initialised);
        for y in rows {
            let d = off_foot(report.lanes[1].coeffs, y);
            assert!(d.abs() < 1.0, "frame {frame}, row {y}: {d} px off the foot");
        }
    }
    // The default does it after its initialisation; the left lane (a mark) stays.
    let default = TrackerConfig::default_preset().expect("the default preset");
    let mut tracker = LaneTracker::new(&default, Estimator::Kif, 320, 240).expect("a tracker");
    let report = tracker.track(&kerb).expect("a frame");
    for y in rows {
        let d = off_foot(report.lanes[1].coeffs, y);
        assert!(d.abs() < 1.0, "row {y}: {d} px off the foot");
        let l = report.lanes[0].col_at_row(y).expect("a left lane") - mark_left(y);
        assert!(l.abs() < 1.5, "row {y}: the left lane {l} px off its mark");
    }
    // Tracked on while the face widens by 2 px: the kerb is read again and the offset follows.
    let wider = kerb_right(320, 240, false, 2.0);
    for frame in 0..3 {
        let report = tracker.track(&wider).expect("a frame");
        assert!(!report.lanes[1].initialised);
        for y in rows {
            let d = report.lanes[1].col_at_row(y).expect("a right lane")
                - (kerb_foot_col(y, 2.0) - 0.5);
            assert!(
                d.abs() < 1.5,
                "frame {frame}, row {y}: {d} px off the wider foot"
            );
        }
    }
    // The kerb ends (a plain step): the offset outlasts a gap shorter than
    // `track.lost_after_frames`, then goes, and the lane is reported on the edge it tracks.
    let lost_after = default.track.lost_after_frames;
    assert!(lost_after >= 2, "a gap shorter than the drop is tested");
    let bottom_row = rows[2];
    for frame in 1..=lost_after {
        let report = tracker.track(&plain).expect("a frame");
        assert!(!report.lanes[1].initialised);
        let d = report.lanes[1]
            .col_at_row(bottom_row)
            .expect("a right lane")
            - (kerb_top(bottom_row) - 0.5);
        if frame < lost_after {
            assert!(
                d < -5.0,
                "frame {frame}: {d} px from the step, the offset dropped early"
            );
        } else {
            assert!(d.abs() < 1.5, "frame {frame}: {d} px off the plain step");
        }
    }
    // A new initialisation reads its own kerb (the last one's offset does not survive it):
    // initialised on the kerb, then lost (as after `lost_after_frames` misses), re-initialised
    // on the plain step.
    tracker.reset();
    let report = tracker.track(&kerb).expect("a frame");
    assert!(report.lanes[1].initialised);
    assert_ne!(tracker.lanes[1].kerb_offset_px, [0.0; 2]);
    tracker.lanes[1].state = LaneState::Lost;
    let report = tracker.track(&plain).expect("a frame");
    assert!(report.lanes[1].initialised);
    for y in rows {
        let d = report.lanes[1].col_at_row(y).expect("a right lane") - (kerb_top(y) - 0.5);
        assert!(d.abs() < 1.5, "row {y}: {d} px off the plain step");
    }
    // Mirrored (a left-hand kerb, the mark on the right): the left lane is reported on the
    // kerb's foot, column c mapping to 319 − c.
    let mirrored = GreyFrame::from_vec(
        320,
        240,
        kerb.data()
            .chunks(320)
            .flat_map(|row| row.iter().rev().copied())
            .collect(),
    )
    .expect("a whole frame");
    let mut tracker = LaneTracker::new(&default, Estimator::Kif, 320, 240).expect("a tracker");
    let report = tracker.track(&mirrored).expect("a frame");
    for y in rows {
        let d = report.lanes[0].col_at_row(y).expect("a left lane")
            - (319.0 - (kerb_foot_col(y, 0.0) - 0.5));
        assert!(
            d.abs() < 1.0,
            "row {y}: the left lane {d} px off the mirrored foot"
        );
    }
}

#[test]
fn a_chosen_lines_fit_on_the_pixels_near_it_equals_the_fit_on_all_of_them() {
    // The fit of a chosen line reads only the candidate pixels near the line
    // (`fit_chosen_line`); it must be the fit on all of them, bit for bit, and leave the same
    // pixels of the line's band for `install`. Lines swept across frames with clutter (a
    // crosswalk, a kerb) take both paths: the pixels near the line, and the full set where a
    // refit reaches a pixel left out.
    let cfg = TrackerConfig::default_preset().expect("the default preset");
    let frames = [
        two_marks(320, 240),
        crosswalk(320, 240, true),
        kerb_right(320, 240, false, 0.0),
    ];
    let (mut near, mut full) = (0, 0);
    for frame in &frames {
        let mut tracker = LaneTracker::new(&cfg, Estimator::Kif, 320, 240).expect("a tracker");
        tracker.track(frame).expect("a frame");
        // The buffers hold the last search's pixels; search those rows again.
        tracker.search_rows = tracker.roi;
        tracker
            .initialise_in_roi(&image_of(frame), [true, true], false)
            .expect("a search");
        let params = tracker.init_params;
        let (top, bottom) = tracker.roi;
        let mid = 0.5 * (top + bottom) as f64;
        let in_band = |t: &LaneTracker, line: &hough_init::HoughLine| -> Vec<(f32, f32)> {
            let (s, c) = line.theta_rad.sin_cos();
            t.candidates
                .iter()
                .copied()
                .filter(|&(x, y)| {
                    (f64::from(x) * c + f64::from(y) * s - line.rho_px).abs() <= params.band_px
                })
                .collect()
        };
        for class in [EdgeClass::LeftLane, EdgeClass::RightLane] {
            for theta_deg in (-60..=60).step_by(4) {
                for col in (20..320).step_by(12) {
                    let theta_rad = f64::from(theta_deg).to_radians();
                    let line = hough_init::HoughLine {
                        rho_px: f64::from(col) * theta_rad.cos() + mid * theta_rad.sin(),
                        theta_rad,
                        votes: 0,
                    };
                    let fit = tracker.fit_chosen_line(class, line);
                    let kept = in_band(&tracker, &line);
                    let took_near =
                        matches!(tracker.fit_chosen_line_near(class, line), Ok(Some(_)));
                    tracker.fill_candidates(class);
                    let all = hough_init::fit_around_line(&tracker.candidates, line, &params);
                    assert_eq!(fit, all, "class {class:?}, θ {theta_deg}°, column {col}");
                    if fit.is_ok() {
                        assert_eq!(kept, in_band(&tracker, &line));
                        if took_near {
                            near += 1;
                        } else {
                            full += 1;
                        }
                    }
                }
            }
        }
    }
    assert!(
        near > 100 && full > 5,
        "fits on the pixels near the line {near}, on all {full}"
    );
}

/// `has_candidates` says what `fill_candidates` would give — at least `min` pixels that count
/// as the class — without filling: both classes, `min` on both sides of the filled count, the
/// paired pixels counted 0–4 times (`gradient.stripe_paired_votes`), on frames with stripes,
/// a crosswalk and a kerb.
#[test]
fn has_candidates_agrees_with_the_candidates_filled() {
    let frames = [
        two_marks(320, 240),
        crosswalk(320, 240, true),
        kerb_right(320, 240, false, 0.0),
    ];
    let mut paired_counted = 0;
    for votes in 0..=4u8 {
        let mut cfg = TrackerConfig::default_preset().expect("the default preset");
        cfg.gradient.stripe_paired_votes = votes;
        for frame in &frames {
            let mut tracker = LaneTracker::new(&cfg, Estimator::Kif, 320, 240).expect("a tracker");
            tracker
                .initialise_in_roi(&image_of(frame), [true, true], false)
                .expect("a search");
            for class in [EdgeClass::LeftLane, EdgeClass::RightLane] {
                tracker.fill_candidates(class);
                let n = tracker.candidates.len();
                let edges_alone = tracker
                    .edges
                    .pixels()
                    .iter()
                    .filter(|p| counts_as(p, class, tracker.near_vertical_either_class()))
                    .count();
                paired_counted += usize::from(n > edges_alone);
                for min in [
                    0,
                    1,
                    edges_alone,
                    edges_alone + 1,
                    n.saturating_sub(1),
                    n,
                    n + 1,
                    2 * n + 5,
                ] {
                    assert_eq!(
                        tracker.has_candidates(class, min),
                        n >= min,
                        "votes {votes}, {class:?}, {n} candidates, min {min}"
                    );
                }
            }
        }
    }
    assert!(
        paired_counted >= 12,
        "paired pixels added candidates {paired_counted} times"
    );
}

/// A frame as the tracker's image type.
fn image_of(f: &GreyFrame) -> GreyImage<'_> {
    GreyImage::new(f.data(), f.width(), f.height(), f.width()).expect("an image")
}

/// The branch-free append of one class's pixels keeps exactly those pixels, in their order,
/// after the points already there, and within the room it documents (`pixels.len() + 1`
/// beyond the points held) it does not allocate.
#[test]
fn the_branch_free_append_keeps_one_class_in_order_without_allocating() {
    use vision_gradient::{EdgeClass, EdgePixel};
    let mut state = 0x9E37_79B9_u32;
    let pixels: Vec<EdgePixel> = (0..200u16)
        .map(|i| {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            EdgePixel {
                col_px: i,
                row_px: 239 - i / 40,
                magnitude: 100,
                class: if state.is_multiple_of(3) {
                    EdgeClass::LeftLane
                } else {
                    EdgeClass::RightLane
                },
                gx: 50,
            }
        })
        .collect();
    for class in [EdgeClass::LeftLane, EdgeClass::RightLane] {
        let want: Vec<(f32, f32)> = [(-1.0, -1.0)]
            .into_iter()
            .chain(
                pixels
                    .iter()
                    .filter(|p| p.class == class)
                    .map(|p| (f32::from(p.col_px), f32::from(p.row_px))),
            )
            .collect();
        assert!(want.len() > 40 && want.len() < 160, "both classes drawn");
        let mut points = Vec::with_capacity(1 + pixels.len() + 1);
        points.push((-1.0, -1.0));
        let (_, allocations) =
            allocations_in(|| super::init::extend_with_class(&mut points, &pixels, class, 0));
        assert_eq!(allocations, 0);
        assert_eq!(points, want);
    }
}

#[test]
fn unpaired_pixels_count_one_steps_worth_a_row_in_the_row_coverage() {
    // The row table filled by hand around the vertical curve x = 100 over the ROI rows: each
    // row holds `pixels` as (column, weight), weight 3 = a paired pixel (the default's
    // `stripe_paired_votes`), 1 = an unpaired one.
    let cfg = TrackerConfig::default_preset().expect("the default preset");
    assert_eq!(cfg.gradient.stripe_paired_votes, 3);
    let mut tracker = LaneTracker::new(&cfg, Estimator::Kif, 320, 240).expect("a tracker");
    let (top, bottom) = tracker.search_rows;
    let rows = (bottom - top) as f64;
    let line = Parabola {
        a1: 0.0,
        a2: 0.0,
        a3: 100.0,
    };
    let mut coverage = |pixels: &[(u16, u16)]| {
        tracker.by_row.clear();
        tracker.row_start.fill(0);
        for r in 0..tracker.height {
            if (top..bottom).contains(&r) {
                tracker.by_row.extend_from_slice(pixels);
            }
            tracker.row_start[r + 1] = tracker.by_row.len() as u32;
        }
        tracker.row_coverage(&line)
    };
    // A bright stripe: its two paired sides, 6 a row (the row cap).
    assert_eq!(coverage(&[(98, 3), (102, 3)]), 6.0 * rows);
    // A single step: one unpaired pixel a row.
    assert_eq!(coverage(&[(100, 1)]), rows);
    // Texture on the curve: five unpaired pixels a row count as two (they counted 5 before).
    assert_eq!(
        coverage(&[(98, 1), (99, 1), (100, 1), (101, 1), (102, 1)]),
        2.0 * rows
    );
    // A stripe with unpaired texture around it keeps its 6; texture beside the curve (12 px
    // off, the background bands) is capped alike: 4 unpaired a side count 2, and the stripe
    // keeps 6 − (2 + 2)/2 = 4 a row (6 − (4 + 4)/2 = 2 before).
    assert_eq!(
        coverage(&[(97, 1), (98, 3), (102, 3), (103, 1)]),
        6.0 * rows
    );
    let beside = [
        (86, 1),
        (87, 1),
        (88, 1),
        (89, 1),
        (98, 3),
        (102, 3),
        (111, 1),
        (112, 1),
        (113, 1),
        (114, 1),
    ];
    assert_eq!(coverage(&beside), 4.0 * rows);
}

/// A bright road between the outer edges of `two_marks`' marks on a dark floor: the same
/// rising and falling edge pixels as those marks' outer sides, but each the side of a region
/// far wider than a mark (no stripe pairs them).
fn road_between_marks(w: usize, h: usize) -> GreyFrame {
    let (left, right) = (mark_left, mark_right);
    let mut pixels = vec![60u8; w * h];
    for (i, p) in pixels.iter_mut().enumerate() {
        let (x, y) = ((i % w) as f64, (i / w) as f64);
        if x > left(y) - 2.5 && x < right(y) + 2.5 {
            *p = 200;
        }
    }
    GreyFrame::from_vec(w, h, pixels).expect("a whole frame")
}

#[test]
fn one_frames_stripe_pairs_do_not_weigh_the_next_frames_pixels() {
    // The paired pixels of a frame are marked in a bit mask for the initialisation's weights
    // and the mask is cleared after use; a bit left set would count an unpaired pixel at the
    // same place on a later frame as paired (3 votes, not a step's share) and change its
    // candidates' support.
    let cfg = TrackerConfig::default_preset().expect("the default preset");
    assert!(cfg.gradient.stripe_paired_votes > 1);
    let (marks, road) = (two_marks(320, 240), road_between_marks(320, 240));
    let candidates_on_road = |tracker: &mut LaneTracker| {
        tracker.reset();
        tracker.track(&road).expect("a frame");
        tracker.init_candidates().to_vec()
    };
    let mut fresh = LaneTracker::new(&cfg, Estimator::Kif, 320, 240).expect("a tracker");
    let alone = candidates_on_road(&mut fresh);
    assert!(!alone.is_empty(), "the road's edges give candidates");
    let mut used = LaneTracker::new(&cfg, Estimator::Kif, 320, 240).expect("a tracker");
    used.track(&marks).expect("a frame");
    assert!(
        used.init_candidates().iter().any(|c| c.chosen.is_some()),
        "the marks were initialised (their sides paired)"
    );
    let after_marks = candidates_on_road(&mut used);
    assert_eq!(after_marks, alone);
    // And again, with the marks' frame in between.
    used.reset();
    used.track(&marks).expect("a frame");
    assert_eq!(candidates_on_road(&mut used), alone);
}

/// The fraction of pixel `(x, y)` that `inside` covers, sampled on a 4×4 grid: a painted shape
/// anti-aliased as a lens and sensor blur its edges.
fn cover(inside: &dyn Fn(f64, f64) -> bool, x: f64, y: f64) -> f64 {
    (0..16)
        .filter(|s| {
            inside(
                x - 0.375 + 0.25 * f64::from(s % 4),
                y - 0.375 + 0.25 * f64::from(s / 4),
            )
        })
        .count() as f64
        / 16.0
}

/// A crosswalk across the near rows (165..225) of a dark floor, right of the camera: five
/// bright stripes along the road (towards a vanishing point at (160, 100)), 14 px wide and 16 px
/// apart at the bottom row from column 185, narrowing with distance, anti-aliased; with `marks`,
/// over `two_marks` (painted over the right mark, as a real crosswalk is). Every stripe leans
/// (≥ 10° from the vertical): a vertical stripe's edges have no lean and are no edge pixels, so
/// it would leave the chain (the module docs of `vision_gradient::drop_periodic_stripes`).
fn crosswalk(w: usize, h: usize, marks: bool) -> GreyFrame {
    let mut pixels = if marks {
        two_marks(w, h).data().to_vec()
    } else {
        vec![60u8; w * h]
    };
    // Column scaled back to the bottom row, where the stripes start every 30 px from 185.
    let on_stripe = |x: f64, y: f64| {
        let x_bottom = 160.0 + (x - 160.0) * 139.0 / (y - 100.0);
        let k = ((x_bottom - 185.0) / 30.0).floor();
        (0.0..5.0).contains(&k) && x_bottom - (185.0 + 30.0 * k) < 14.0
    };
    for (i, p) in pixels.iter_mut().enumerate() {
        let (x, y) = ((i % w) as f64, (i / w) as f64);
        if !(165.0..225.0).contains(&y) {
            continue;
        }
        let cover = cover(&on_stripe, x, y);
        *p = (f64::from(*p) + cover * (220.0 - f64::from(*p))).round() as u8;
    }
    GreyFrame::from_vec(w, h, pixels).expect("a whole frame")
}

#[test]
fn a_crosswalk_is_not_reported_as_a_lane_and_marks_across_it_are() {
    let marks = [mark_left, mark_right];
    // Largest distance of each reported lane from its mark over the ROI rows (`None`: no lane).
    let errors = |cfg: &TrackerConfig, frame: &GreyFrame| {
        let mut tracker = LaneTracker::new(cfg, Estimator::Kif, 320, 240).expect("a tracker");
        let report = tracker.track(frame).expect("a frame");
        let (top, bottom) = tracker.roi;
        [0, 1].map(|k| {
            report.lanes[k].coeffs.map(|c| {
                (top..bottom)
                    .map(|y| {
                        let y = y as f64;
                        (Parabola::from_coeffs(c).col_at_row(y) - marks[k](y)).abs()
                    })
                    .fold(0.0, f64::max)
            })
        })
    };
    let cfg = TrackerConfig::default_preset().expect("the default preset");
    assert!(cfg.gradient.periodic_min_stripes > 0);
    let mut off = cfg;
    off.gradient.periodic_min_stripes = 0;
    // The crosswalk alone: no lane; without the rule its stripes are taken for lanes.
    let alone = crosswalk(320, 240, false);
    assert_eq!(errors(&cfg, &alone), [None, None], "with the rule");
    let found = errors(&off, &alone);
    assert!(
        found.iter().any(Option::is_some),
        "without the rule: {found:?}"
    );
    // Marks running through the crosswalk are still found, within 5 px over the ROI.
    let on = errors(&cfg, &crosswalk(320, 240, true));
    assert!(
        on.iter().all(|e| e.is_some_and(|e| e < 5.0)),
        "marks through the crosswalk: {on:?} px"
    );
}

/// A mark straight ahead of the camera (vertical, columns 141..147) and a `\` mark on the right
/// (centre `220 + 0.45·(y − 239)`), both 6 px wide and grey 200, anti-aliased, on a floor of
/// grey 60 with a deterministic texture of ±3 grey levels: along the vertical mark's edges
/// `gy` is that texture, so its sign — the pixel's class — is random.
fn mark_straight_ahead(w: usize, h: usize) -> GreyFrame {
    let on_mark = |x: f64, y: f64| (141.0..147.0).contains(&x) || (x - mark_right(y)).abs() < 3.0;
    let pixels = (0..w * h)
        .map(|i| {
            let (x, y) = ((i % w) as f64, (i / w) as f64);
            // A splitmix64 finaliser of the pixel index: no pattern along rows or columns.
            let mut hash = (i as u64).wrapping_add(0x9E37_79B9_7F4A_7C15);
            hash = (hash ^ (hash >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            hash = (hash ^ (hash >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            hash = (hash ^ (hash >> 31)) % 7;
            let floor = 60.0 + hash as f64 - 3.0;
            (floor + cover(&on_mark, x, y) * (200.0 - floor)).round() as u8
        })
        .collect();
    GreyFrame::from_vec(w, h, pixels).expect("a whole frame")
}

#[test]
fn a_mark_straight_ahead_votes_with_all_its_edges_in_the_initialisation() {
    // A near-vertical edge pixel counts in both classes; a leaning one, or any with the rule
    // off, in its own.
    let pixel = |gx: i16, gy: i16| {
        let magnitude = (gx.abs() + gy.abs()) as u16;
        let class = if (gx ^ gy) < 0 {
            EdgeClass::RightLane
        } else {
            EdgeClass::LeftLane
        };
        EdgePixel {
            col_px: 10,
            row_px: 10,
            magnitude,
            class,
            gx,
        }
    };
    // The tracking windows' near-vertical slope (≈ tan 10°) in 2^14 fixed point, as the
    // default's joint initialisation uses it.
    let cfg = TrackerConfig::default_preset().expect("the default preset");
    let tan_10 = LaneTracker::new(&cfg, Estimator::Kif, 320, 240)
        .expect("a tracker")
        .near_vertical_either_class();
    assert_eq!(
        tan_10,
        (super::points::NEAR_VERTICAL_SLOPE * 16384.0).round() as i32
    );
    for (gx, gy, both) in [
        (200, 3, true),
        (-200, 3, true),
        (200, -35, true),
        (200, 36, false),
    ] {
        let p = pixel(gx, gy);
        let other = if p.class == EdgeClass::LeftLane {
            EdgeClass::RightLane
        } else {
            EdgeClass::LeftLane
        };
        assert!(counts_as(&p, p.class, tan_10) && counts_as(&p, p.class, 0));
        assert_eq!(counts_as(&p, other, tan_10), both, "gx {gx}, gy {gy}");
        assert!(!counts_as(&p, other, 0), "gx {gx}, gy {gy}: the rule off");
    }
    // The mark straight ahead is a candidate (within 4 px: on either edge of the 6 px mark, or
    // between them) with most of the support of the leaning mark (same width, contrast and
    // rows): 77 % of it (the detector keeps no pixel where the texture leaves `gy = 0`), against
    // 43 % when each pixel counts in its own class only. The pair is reported on both marks.
    let mut tracker = LaneTracker::new(&cfg, Estimator::Kif, 320, 240).expect("a tracker");
    let (top, bottom) = tracker.roi;
    let report = tracker
        .track(&mark_straight_ahead(320, 240))
        .expect("a frame");
    let marks = [|_: f64| 143.5, mark_right];
    let col = |c: [f64; 3], y: f64| Parabola::from_coeffs(c).col_at_row(y);
    let worst = |c: [f64; 3], k: usize| {
        (top..bottom)
            .map(|y| (col(c, y as f64) - marks[k](y as f64)).abs())
            .fold(0.0, f64::max)
    };
    let best_support = |k: usize| {
        tracker
            .init_candidates()
            .iter()
            .filter(|c| worst(c.coeffs, k) < 4.0)
            .map(|c| c.support)
            .fold(0.0, f64::max)
    };
    let (straight, leaning) = (best_support(0), best_support(1));
    assert!(
        straight >= 0.7 * leaning && leaning > 0.0,
        "support: straight ahead {straight}, leaning {leaning}"
    );
    for k in 0..2 {
        let c = report.lanes[k].coeffs.expect("a lane on each mark");
        assert!(worst(c, k) < 1.5, "lane {k}: {} px", worst(c, k));
    }
}

/// Two marks 5 px wide on a dark floor meeting at the vanishing point `(160, meet_row)`, from
/// columns 60 and 260 at the bottom row; nothing is painted above that row.
fn marks_meeting_at(w: usize, h: usize, meet_row: f64) -> GreyFrame {
    let mark = |bottom_col: f64, y: f64| {
        160.0 + (bottom_col - 160.0) * (y - meet_row) / (239.0 - meet_row)
    };
    let mut pixels = vec![60u8; w * h];
    for (i, p) in pixels.iter_mut().enumerate() {
        let (x, y) = ((i % w) as f64, (i / w) as f64);
        if y > meet_row && ((x - mark(60.0, y)).abs() < 2.5 || (x - mark(260.0, y)).abs() < 2.5) {
            *p = 200;
        }
    }
    GreyFrame::from_vec(w, h, pixels).expect("a whole frame")
}

#[test]
fn a_vanishing_point_inside_the_roi_still_gives_the_pair_and_keeps_it() {
    let cfg = TrackerConfig::default_preset().expect("the default preset");
    let tracker = LaneTracker::new(&cfg, Estimator::Kif, 320, 240).expect("a tracker");
    let (top, bottom) = tracker.roi;
    // The marks meet a tenth of the ROI's rows below its top: crossed at the top row.
    let meet_row = top as f64 + 0.1 * (bottom - 1 - top) as f64;
    let frame = marks_meeting_at(320, 240, meet_row);
    let marks = [60.0, 260.0]
        .map(|b: f64| move |y: f64| 160.0 + (b - 160.0) * (y - meet_row) / (239.0 - meet_row));
    // Largest distance of each reported lane from its mark over the rows 10 below the meeting
    // row to the bottom (`None`: no lane), on each of `frames` frames.
    let errors = |cfg: &TrackerConfig, frames: usize| {
        let mut tracker = LaneTracker::new(cfg, Estimator::Kif, 320, 240).expect("a tracker");
        (0..frames)
            .map(|_| {
                let report = tracker.track(&frame).expect("a frame");
                [0, 1].map(|k| {
                    report.lanes[k].coeffs.map(|c| {
                        ((meet_row as usize + 10)..bottom)
                            .map(|y| {
                                let y = y as f64;
                                (Parabola::from_coeffs(c).col_at_row(y) - marks[k](y)).abs()
                            })
                            .fold(0.0, f64::max)
                    })
                })
            })
            .collect::<Vec<_>>()
    };
    assert!(cfg.init.ego_pair.meet_top_frac >= 0.1);
    // The pair on the first frame, kept by the crossing gate on the next ones.
    for (n, frame_errors) in errors(&cfg, 5).iter().enumerate() {
        assert!(
            frame_errors.iter().all(|e| e.is_some_and(|e| e < 2.0)),
            "frame {n}: {frame_errors:?} px"
        );
    }
    // Meeting only above the ROI: no pair.
    let mut above = cfg;
    above.init.ego_pair.meet_top_frac = 0.0;
    let first = errors(&above, 1)[0];
    assert!(
        !first.iter().all(|e| e.is_some_and(|e| e < 2.0)),
        "without the rule: {first:?}"
    );
}

/// `two_marks` with a bright bar 5 px wide left of the left mark, leaning outwards upwards
/// (column 80 at the bottom row, 30 at row 148): with the right mark it would make a lane
/// wider at the top of the ROI than at its bottom.
fn two_marks_and_an_outward_bar(w: usize, h: usize) -> GreyFrame {
    let mut pixels = two_marks(w, h).data().to_vec();
    for (i, p) in pixels.iter_mut().enumerate() {
        let (x, y) = ((i % w) as f64, (i / w) as f64);
        if (x - outward_bar(y)).abs() < 2.5 {
            *p = 200;
        }
    }
    GreyFrame::from_vec(w, h, pixels).expect("a whole frame")
}

fn outward_bar(y: f64) -> f64 {
    80.0 + 50.0 / 91.0 * (y - 239.0)
}

#[test]
fn a_tracked_pair_that_diverges_upwards_is_initialised_again() {
    let cfg = TrackerConfig::default_preset().expect("the default preset");
    let frame = two_marks_and_an_outward_bar(320, 240);
    let marks = [mark_left, mark_right];
    let mut tracker = LaneTracker::new(&cfg, Estimator::Kif, 320, 240).expect("a tracker");
    let (top, bottom) = tracker.roi;
    // Largest distance of each lane from `truth[k]` over the ROI rows (infinite: no lane).
    let worst = |report: &super::TrackReport, truth: [&dyn Fn(f64) -> f64; 2]| {
        [0, 1].map(|k| {
            report.lanes[k].coeffs.map_or(f64::INFINITY, |c| {
                (top..bottom)
                    .map(|y| {
                        (Parabola::from_coeffs(c).col_at_row(y as f64) - truth[k](y as f64)).abs()
                    })
                    .fold(0.0, f64::max)
            })
        })
    };
    for n in 0..3 {
        let report = tracker.track(&frame).expect("a frame");
        let e = worst(&report, [&marks[0], &marks[1]]);
        assert!(e.iter().all(|&e| e < 2.0), "frame {n}: {e:?} px");
    }
    // The left lane loses its mark to the bar (as a lane pulled over by clutter would): it
    // follows the bar from now on, and the pair widens upwards.
    let bar = nalgebra::Vector3::new(0.0, 50.0 / 91.0, outward_bar(0.0));
    tracker.lanes[0].filter = Some(tracker.new_filter(&bar).expect("a filter"));
    let report = tracker.track(&frame).expect("a frame");
    let e = worst(&report, [&marks[0], &marks[1]]);
    assert!(e.iter().all(|&e| e < 2.0), "after the gate: {e:?} px");
    assert_eq!(tracker.counters().gated_pairs, 1);
    // Once the pair is the ego lane again the gate stays quiet.
    for _ in 0..3 {
        tracker.track(&frame).expect("a frame");
    }
    assert_eq!(tracker.counters().gated_pairs, 1);
}

#[test]
fn a_tracked_pair_as_wide_at_the_top_as_a_camera_looking_down_sees_it_is_kept() {
    // Marks 5 px wide from columns 60 and 260 at the bottom row to 65 and 255 at the ROI's
    // top: a top/bottom width ratio of 0.95, which the choice among candidates refuses
    // (`max_top_width_ratio` 0.9) but labelled ego pairs reach (0.92 on `seame`). Tracked, the
    // pair is kept: the gate asks only that it does not diverge upwards, and a re-validation
    // (whose choice holds a tracked pair to the same bound) keeps both lanes.
    let cfg = TrackerConfig::default_preset().expect("the default preset");
    assert!(cfg.init.ego_pair.max_top_width_ratio < 0.95);
    let mut tracker = LaneTracker::new(&cfg, Estimator::Kif, 320, 240).expect("a tracker");
    let (top, bottom) = tracker.roi;
    let (yt, yb) = (top as f64, (bottom - 1) as f64);
    let line = |bottom_col: f64, top_col: f64| {
        let slope = (bottom_col - top_col) / (yb - yt);
        nalgebra::Vector3::new(0.0, slope, bottom_col - slope * yb)
    };
    let marks = [line(60.0, 65.0), line(260.0, 255.0)];
    let col = |m: &nalgebra::Vector3<f64>, y: f64| m[1] * y + m[2];
    let mut pixels = vec![60u8; 320 * 240];
    for (i, p) in pixels.iter_mut().enumerate() {
        let (x, y) = ((i % 320) as f64, (i / 320) as f64);
        if marks.iter().any(|m| (x - col(m, y)).abs() < 2.5) {
            *p = 200;
        }
    }
    let frame = GreyFrame::from_vec(320, 240, pixels).expect("a whole frame");
    // Both lanes start on their marks, as if tracked there.
    for (k, mark) in marks.iter().enumerate() {
        tracker.lanes[k].filter = Some(tracker.new_filter(mark).expect("a filter"));
        tracker.lanes[k].state = LaneState::Tracking;
    }
    // Over two re-validations too: the choice among candidates holds the pair to the same bound.
    let frames = 2 * cfg.track.revalidate_every_frames + 1;
    for n in 0..frames {
        let report = tracker.track(&frame).expect("a frame");
        for (k, mark) in marks.iter().enumerate() {
            let c = report.lanes[k].coeffs.expect("both lanes");
            let e = (top..bottom)
                .map(|y| {
                    (Parabola::from_coeffs(c).col_at_row(y as f64) - col(mark, y as f64)).abs()
                })
                .fold(0.0, f64::max);
            assert!(e < 1.5, "frame {n}, lane {k}: {e} px");
        }
    }
    let counters = tracker.counters();
    assert_eq!(counters.gated_pairs, 0);
    // At least the period's two (these noise-free marks near the vertical give edge pixels
    // only where their rasterisation steps, fewer than `revalidate_below_points`, so the
    // weak-evidence trigger adds more); the pair is kept each time.
    assert!(counters.revalidations >= 2, "{counters:?}");
    assert_eq!(counters.revalidation_switches, [0, 0]);
    assert_eq!(counters.initialisations, [0, 0]);
}

/// `two_marks` with a faint dashed line 25 px left of the left mark and parallel to it: 2 px
/// wide, 30 grey levels above the floor, dashes 6 rows long every 24 rows (a seam, a worn
/// line): enough edge pixels to hold a tracked lane, a quarter of a mark's row coverage.
fn two_marks_and_a_faint_dashed_line(w: usize, h: usize) -> GreyFrame {
    let mut pixels = two_marks(w, h).data().to_vec();
    for (i, p) in pixels.iter_mut().enumerate() {
        let (x, y) = ((i % w) as f64, (i / w) as f64);
        if (x - faint_line(y)).abs() < 1.0 && (i / w) % 24 < 6 {
            *p = 90;
        }
    }
    GreyFrame::from_vec(w, h, pixels).expect("a whole frame")
}

fn faint_line(y: f64) -> f64 {
    75.0 - 0.45 * (y - 239.0)
}

#[test]
fn a_lane_left_on_a_faint_line_is_moved_to_the_mark_by_the_next_revalidation() {
    let cfg = TrackerConfig::default_preset().expect("the default preset");
    let every = cfg.track.revalidate_every_frames;
    assert!(every > 0 && cfg.track.revalidate_keep_factor < 4.0);
    let frame = two_marks_and_a_faint_dashed_line(320, 240);
    let mark = mark_left;
    // Largest distance of the left lane from `truth` over the ROI rows after `frames` more
    // frames, the left lane having been put on the faint line first.
    let left_after = |cfg: &TrackerConfig, frames: u32, truth: &dyn Fn(f64) -> f64| {
        let mut tracker = LaneTracker::new(cfg, Estimator::Kif, 320, 240).expect("a tracker");
        let (top, bottom) = tracker.roi;
        tracker.track(&frame).expect("a frame");
        let line = nalgebra::Vector3::new(0.0, -0.45, faint_line(0.0));
        tracker.lanes[0].filter = Some(tracker.new_filter(&line).expect("a filter"));
        let mut report = None;
        for _ in 0..frames {
            report = Some(tracker.track(&frame).expect("a frame"));
        }
        let c = report.and_then(|r| r.lanes[0].coeffs).expect("a left lane");
        let worst = (top..bottom)
            .map(|y| (Parabola::from_coeffs(c).col_at_row(y as f64) - truth(y as f64)).abs())
            .fold(0.0, f64::max);
        (worst, *tracker.counters())
    };
    // The first initialisation found the mark (the faint line is no candidate for the pair).
    let (on_mark, counters) = left_after(&cfg, every, &mark);
    assert!(
        on_mark < 2.0,
        "after {every} frames: {on_mark} px from the mark"
    );
    assert_eq!(counters.revalidation_switches, [1, 0]);
    assert_eq!(counters.revalidations, 1);
    assert_eq!(counters.gated_pairs, 0);
    // Without re-validation the lane stays on the faint line: it keeps enough points.
    let mut never = cfg;
    never.track.revalidate_every_frames = 0;
    never.track.revalidate_below_points = 0;
    let (on_line, counters) = left_after(&never, 3 * every, &faint_line);
    assert!(on_line < 2.0, "without: {on_line} px from the faint line");
    assert_eq!(counters.revalidations, 0);
}

/// Three marks 5 px wide towards a vanishing point (`mark_towards_vp`), 160 px apart at the
/// bottom row, at bottom columns 80, 240 and 400 less `shift_px` (the camera moved right).
/// Anti-aliased (`cover`): a mark near the vertical still has edge pixels that lean.
fn three_marks_shifted(w: usize, h: usize, shift_px: f64) -> GreyFrame {
    let on_mark = |x: f64, y: f64| {
        y > 100.0
            && [80.0, 240.0, 400.0]
                .iter()
                .any(|&b| (x - mark_towards_vp(b - shift_px, y)).abs() < 2.5)
    };
    let mut pixels = vec![60u8; w * h];
    for (i, p) in pixels.iter_mut().enumerate() {
        let (x, y) = ((i % w) as f64, (i / w) as f64);
        *p = (60.0 + 140.0 * cover(&on_mark, x, y)).round() as u8;
    }
    GreyFrame::from_vec(w, h, pixels).expect("a whole frame")
}

/// Column at row `y` of a mark through `bottom_col` at row 239 and the vanishing point (150, 100)
/// (off the middle column: a mark crossing it is never exactly vertical, which the gradient
/// does not see).
fn mark_towards_vp(bottom_col: f64, y: f64) -> f64 {
    150.0 + (bottom_col - 150.0) * (y - 100.0) / 139.0
}

#[test]
fn a_lane_change_hands_the_crossed_boundary_to_the_other_side() {
    // The camera moves right 4 px a frame over a three-lane road: the right boundary of the
    // first ego lane crosses the image's middle column at frame 20 and is the new ego lane's
    // left boundary from then on, the third mark its right one.
    let cfg = TrackerConfig::default_preset().expect("the default preset");
    let mut tracker = LaneTracker::new(&cfg, Estimator::Kif, 320, 240).expect("a tracker");
    let (top, bottom) = tracker.roi;
    let worst = |c: Option<[f64; 3]>, bottom_col: f64| {
        c.map_or(f64::INFINITY, |c| {
            (top..bottom)
                .map(|y| {
                    let y = y as f64;
                    (Parabola::from_coeffs(c).col_at_row(y) - mark_towards_vp(bottom_col, y)).abs()
                })
                .fold(0.0, f64::max)
        })
    };
    let every = u64::from(cfg.track.revalidate_every_frames);
    for n in 0..60u64 {
        let shift = 4.0 * n as f64;
        let report = tracker
            .track(&three_marks_shifted(320, 240, shift))
            .expect("a frame");
        let [l, r] = [report.lanes[0].coeffs, report.lanes[1].coeffs];
        if n < 15 {
            let e = [worst(l, 80.0 - shift), worst(r, 240.0 - shift)];
            assert!(e.iter().all(|&e| e < 3.0), "frame {n}: first lane {e:?} px");
        }
        // Within a re-validation's period of the crossing (with a margin of 5 frames).
        if n >= 25 + every {
            let e = [worst(l, 240.0 - shift), worst(r, 400.0 - shift)];
            assert!(e.iter().all(|&e| e < 3.0), "frame {n}: next lane {e:?} px");
        }
    }
    // The old right boundary was handed over (not found again as a new lane).
    assert_eq!(tracker.counters().lane_changes, 1);
    assert_eq!(tracker.counters().initialisations, [1, 2]);
}

#[test]
fn a_pair_whose_marks_left_its_windows_is_revalidated_on_that_frame() {
    // The camera jumps 40 px right between two frames (a cut in the video, a jolt): both
    // marks leave the tracking windows (±10 px). With `track.revalidate_below_points` the
    // frame on which the windows come up empty is re-validated and the pair moves onto the
    // marks at once; with the period alone the lanes coast at their old places until the next
    // period's frame or until they are lost.
    let cfg = TrackerConfig::default_preset().expect("the default preset");
    assert!(cfg.track.revalidate_below_points > cfg.track.reinit_min_points);
    assert!(cfg.track.revalidate_every_frames > 3);
    let run = |cfg: &TrackerConfig| {
        let mut tracker = LaneTracker::new(cfg, Estimator::Kif, 320, 240).expect("a tracker");
        let (top, bottom) = tracker.roi;
        // The marks move least at the ROI's top row (they meet at row 100): beyond the window
        // and the marks' half-width there too.
        let shift_at_top = mark_towards_vp(40.0, top as f64) - mark_towards_vp(0.0, top as f64);
        assert!((cfg.track.window_half_width_px as f64) + 2.5 < shift_at_top);
        for _ in 0..2 {
            tracker
                .track(&three_marks_shifted(320, 240, 0.0))
                .expect("a frame");
        }
        let report = tracker
            .track(&three_marks_shifted(320, 240, 40.0))
            .expect("a frame");
        let worst = [40.0, 200.0].map(|bottom_col| {
            let k = usize::from(bottom_col > 160.0);
            report.lanes[k].coeffs.map_or(f64::INFINITY, |c| {
                (top..bottom)
                    .map(|y| {
                        let y = y as f64;
                        let truth = mark_towards_vp(bottom_col, y);
                        (Parabola::from_coeffs(c).col_at_row(y) - truth).abs()
                    })
                    .fold(0.0, f64::max)
            })
        });
        (worst, *tracker.counters())
    };
    let (worst, counters) = run(&cfg);
    assert!(
        worst.iter().all(|&e| e < 3.0),
        "{worst:?} px from the marks"
    );
    assert_eq!(counters.revalidations, 1);
    assert_eq!(counters.revalidation_switches, [1, 1]);
    let mut period_only = cfg;
    period_only.track.revalidate_below_points = 0;
    let (worst, counters) = run(&period_only);
    assert!(
        worst.iter().all(|&e| e > 20.0),
        "{worst:?} px from the marks"
    );
    assert_eq!(counters.revalidations, 0);
}

#[test]
fn a_tracked_lane_on_a_faint_line_competes_when_the_other_side_is_initialised_again() {
    // The right lane is lost while the left one sits on the faint line beside its mark: the
    // initialisation that looks for the right lane weighs the left one against the candidates
    // (re-validation on) and moves it to its mark on the same frame; with re-validation off
    // the left lane is locked into the pair and stays where it was.
    let cfg = TrackerConfig::default_preset().expect("the default preset");
    assert!(cfg.track.revalidate_every_frames > 1);
    let frame = two_marks_and_a_faint_dashed_line(320, 240);
    let marks = [mark_left, mark_right];
    let run = |cfg: &TrackerConfig| {
        let mut tracker = LaneTracker::new(cfg, Estimator::Kif, 320, 240).expect("a tracker");
        let (top, bottom) = tracker.roi;
        tracker.track(&frame).expect("a frame");
        let line = nalgebra::Vector3::new(0.0, -0.45, faint_line(0.0));
        tracker.lanes[0].filter = Some(tracker.new_filter(&line).expect("a filter"));
        tracker.lanes[1].filter = None;
        tracker.lanes[1].state = LaneState::Lost;
        let report = tracker.track(&frame).expect("a frame");
        let worst = |k: usize, truth: &dyn Fn(f64) -> f64| {
            report.lanes[k].coeffs.map_or(f64::INFINITY, |c| {
                (top..bottom)
                    .map(|y| {
                        (Parabola::from_coeffs(c).col_at_row(y as f64) - truth(y as f64)).abs()
                    })
                    .fold(0.0, f64::max)
            })
        };
        (
            [
                worst(0, &marks[0]),
                worst(0, &faint_line),
                worst(1, &marks[1]),
            ],
            *tracker.counters(),
        )
    };
    let ([left_on_mark, _, right_on_mark], counters) = run(&cfg);
    assert!(
        left_on_mark < 2.0 && right_on_mark < 2.0,
        "left {left_on_mark} px, right {right_on_mark} px from their marks"
    );
    assert_eq!(counters.revalidation_switches, [1, 0]);
    assert_eq!(
        counters.revalidations, 0,
        "a re-initialisation, not a re-validation"
    );
    let mut locked = cfg;
    locked.track.revalidate_every_frames = 0;
    locked.track.revalidate_below_points = 0;
    let ([_, left_on_line, _], counters) = run(&locked);
    assert!(
        left_on_line < 2.0,
        "locked: left {left_on_line} px from the faint line"
    );
    assert_eq!(counters.revalidation_switches, [0, 0]);
}

#[test]
fn the_crossing_gate_undoes_a_switch_by_restoring_the_lane_it_replaced() {
    // A switch (a tracked lane replaced by another candidate) that crosses the other lane is
    // undone by the crossing gate: the tracked estimate comes back as it was after this frame's
    // miss or update, not a lost lane — whether it had missed (coasting, one miss) or been
    // updated with a few points (a weak lane), and whether it was tracked over the taller rows.
    let cfg = TrackerConfig::default_preset().expect("the default preset");
    for (state, misses, points, tall) in [
        (LaneState::Coasting, 1, 0, false),
        (LaneState::Tracking, 0, 20, true),
    ] {
        let mut tracker = LaneTracker::new(&cfg, Estimator::Kif, 320, 240).expect("a tracker");
        let (top, bottom) = tracker.roi;
        let frame = two_marks(320, 240);
        for _ in 0..3 {
            tracker.track(&frame).expect("a frame");
        }
        let tracked = tracker.lanes[0].filter.clone().expect("a left lane");
        let tracked_fit = tracker.lanes[0].fit;
        let (yt, yb) = (top as f64, (bottom - 1) as f64);
        // The switch put the left lane right of the right one (crossed at every row), as an
        // installation does: a fresh filter (its first update not jump-gated), over the ROI's
        // rows, with the candidate's rows, row profile and points.
        let crossing = nalgebra::Vector3::new(0.0, 0.0, 300.0);
        let lane = &mut tracker.lanes[0];
        lane.initialised_now = true;
        lane.kerb_offset_px = [0.0; 2];
        lane.fresh = true;
        lane.tracked_tall = false;
        lane.rows = [200.0, 239.0];
        lane.fit = lane_geometry::FitRows {
            rows_px: [220.0; lane_geometry::FIT_SAMPLES],
            weights: [1.0; lane_geometry::FIT_SAMPLES],
        };
        lane.points_now = 40;
        lane.replaced = Some(SavedEstimate {
            filter: tracked.clone(),
            predicted: Some(tracked.clone()),
            state,
            misses,
            kerb_offset_px: [1.5, 0.0],
            kerb_misses: 0,
            pair_half_gap_px: 0.0,
            fresh: false,
            tracked_tall: tall,
            rows: [150.0, 239.0],
            fit: tracked_fit,
            points_now: points,
        });
        tracker.lanes[0].filter = Some(tracker.new_filter(&crossing).expect("a filter"));
        tracker.counters.initialisations[0] += 1;
        tracker.counters.revalidation_switches[0] += 1;
        let before = *tracker.counters();
        tracker.crossing_gate();
        let lane = &tracker.lanes[0];
        let restored = lane.filter.as_ref().expect("the tracked lane back");
        for y in [yt, yb] {
            assert!((restored.col_at_row(y) - tracked.col_at_row(y)).abs() < 1e-9);
        }
        // As it was: its state and misses (a miss counts towards `lost_after_frames`), its
        // offsets and rows; its next update jump-gated again; the report describes its own
        // update, not the candidate's (the next frame counts it weak or not by these points).
        assert_eq!((lane.state, lane.misses), (state, misses));
        assert_eq!(lane.kerb_offset_px, [1.5, 0.0]);
        assert!(!lane.initialised_now && lane.replaced.is_none());
        assert!(!lane.fresh, "a restored lane's next update is gated");
        assert_eq!(lane.tracked_tall, tall);
        assert_eq!(lane.rows, [150.0, 239.0]);
        assert_eq!(lane.fit, tracked_fit);
        assert_eq!(lane.report().points, points);
        let after = tracker.counters();
        assert_eq!(after.initialisations[0], before.initialisations[0] - 1);
        assert_eq!(after.revalidation_switches, [0, 0]);
        assert_eq!(after.gated_crossings, [1, 0]);
        assert!(
            tracker.lanes[1].has_estimate(),
            "the right lane is untouched"
        );
    }
}

/// `two_marks`' geometry with a wide left mark, as a tape beside a small robot's camera: `2·h(y)`
/// px wide, 6 px at row 140 growing to 15 px at the bottom row (the default's widest stripe is
/// 16 px), each pixel the area average of what it covers (grey 60 floor, 200 mark).
fn wide_left_mark(w: usize, h: usize) -> GreyFrame {
    let (left, right) = (mark_left, mark_right);
    let mut pixels = vec![60u8; w * h];
    for (i, p) in pixels.iter_mut().enumerate() {
        let (x, y) = ((i % w) as f64, (i / w) as f64);
        let half = 3.0 + 4.5 * (y - 140.0).max(0.0) / 99.0;
        let (lo, hi) = (left(y) - half, left(y) + half);
        let cover = ((x + 0.5).min(hi) - (x - 0.5).max(lo)).clamp(0.0, 1.0);
        let right_cover =
            ((x + 0.5).min(right(y) + 2.5) - (x - 0.5).max(right(y) - 2.5)).clamp(0.0, 1.0);
        *p = (60.0 + 140.0 * cover.max(right_cover)).round() as u8;
    }
    GreyFrame::from_vec(w, h, pixels).expect("a whole frame")
}

/// A default tracker (with `track.stripe_middles` and `init.stripe_trace` as given) after its
/// first frame of `wide_left_mark` — the initialisation and its refinements on the same frame
/// — and the reported left lane's largest offset from the mark's middle at the ROI's top,
/// middle and bottom rows, px.
fn initialised_on_wide_mark(frame: &GreyFrame, middles: bool, trace: bool) -> (LaneTracker, f64) {
    let mut cfg = TrackerConfig::default_preset().expect("the default preset");
    cfg.track.stripe_middles = middles;
    cfg.init.stripe_trace = trace;
    let mut tracker = LaneTracker::new(&cfg, Estimator::Kif, 320, 240).expect("a tracker");
    let (top, bottom) = tracker.roi;
    let report = tracker.track(frame).expect("a frame");
    assert!(report.lanes[0].initialised);
    let c = report.lanes[0].coeffs.expect("a left lane");
    let off = [top as f64, 0.5 * (top + bottom) as f64, (bottom - 1) as f64]
        .iter()
        .map(|&y| (c[0] * y * y + c[1] * y + c[2] - mark_left(y)).abs())
        .fold(0.0, f64::max);
    (tracker, off)
}

#[test]
fn a_wide_mark_is_initialised_on_its_middle_not_on_one_edge() {
    let frame = wide_left_mark(320, 240);
    let mut off = [0.0f64; 2];
    for (k, middles) in [true, false].into_iter().enumerate() {
        // (The stripe trace, which measures middles too, is the next test's.)
        let (mut tracker, lane_off) = initialised_on_wide_mark(&frame, middles, false);
        off[k] = lane_off;
        // The refinement's points include middles between two columns; a tracked frame's
        // are the paper's edge pixels, whole columns.
        let halves = |t: &LaneTracker| t.lanes[0].points.iter().any(|&(x, _)| x.fract() != 0.0);
        assert_eq!(halves(&tracker), middles);
        let report = tracker.track(&frame).expect("a frame");
        assert!(!report.lanes[0].initialised && report.lanes[0].points > 0);
        assert!(!halves(&tracker), "middles measured on a tracked frame");
    }
    assert!(off[0] < 0.5, "stripe middles: {} px off the middle", off[0]);
    // The paper's edge pixels: the refinement keeps the edge the Hough line found.
    assert!(off[1] > 3.0, "edge pixels: {} px off the middle", off[1]);
    // With mark centres (which measure the middle themselves) the setting changes nothing.
    let with_mark_centres = |middles: bool| {
        let mut cfg = TrackerConfig::default_preset().expect("the default preset");
        cfg.track.mark_centres = true;
        cfg.track.stripe_middles = middles;
        let mut tracker = LaneTracker::new(&cfg, Estimator::Kif, 320, 240).expect("a tracker");
        tracker.track(&frame).expect("a frame").lanes[0].coeffs
    };
    assert_eq!(with_mark_centres(true), with_mark_centres(false));
}

#[test]
fn a_double_line_of_narrow_lines_is_initialised_between_them_with_stripe_middles() {
    // Each line at most 5 px wide (narrower than the inlier half-width): the refinement keeps
    // their edge pixels, whose band settles between the lines, and the double-line reading
    // then centres the lane on the pair.
    let cfg = TrackerConfig::default_preset().expect("the default preset");
    assert!(cfg.track.stripe_middles);
    let mut tracker = LaneTracker::new(&cfg, Estimator::Kif, 320, 240).expect("a tracker");
    let (top, bottom) = tracker.roi;
    let double = double_line_left(320, 240, false);
    let report = tracker.track(&double).expect("a frame");
    assert!(report.lanes[0].initialised);
    let c = report.lanes[0].coeffs.expect("a left lane");
    for y in [top as f64, 0.5 * (top + bottom) as f64, (bottom - 1) as f64] {
        let d = c[0] * y * y + c[1] * y + c[2] - mark_left(y);
        // Measured within 2.1 px, bound 3 px (the middle row: the quartile gate with four
        // edges, as in `a_lane_on_one_line_of_a_double_line_is_moved_to_its_middle`); with
        // every stripe measuring its middle the two lines' middles leave the band at the bottom
        // rows and the lane bends onto one line, 4.3 px off there (tried).
        assert!(d.abs() < 3.0, "row {y}: {d} px off the pair's middle");
    }
}

/// The centre of `curved_dash_left`'s dash at row `y`: a parabola whose vertex (vertical
/// tangent) lies at row 225, px.
fn curved_dash_col(y: f64) -> f64 {
    0.01 * (y - 225.0) * (y - 225.0) + 90.0
}

/// A left dash 5 px wide drawn on rows 150–199 only, along [`curved_dash_col`] (it bends
/// towards the vertical at its lower end), and `two_marks`' straight right mark.
fn curved_dash_left(w: usize, h: usize) -> GreyFrame {
    let mut pixels = vec![60u8; w * h];
    for (i, p) in pixels.iter_mut().enumerate() {
        let (x, y) = ((i % w) as f64, (i / w) as f64);
        let dash = (150.0..200.0).contains(&y) && (x - curved_dash_col(y)).abs() < 2.5;
        if dash || (x - mark_right(y)).abs() < 2.5 {
            *p = 200;
        }
    }
    GreyFrame::from_vec(w, h, pixels).expect("a whole frame")
}

#[test]
fn a_lane_turning_back_below_its_evidence_is_reported_as_the_line_through_it() {
    let frame = curved_dash_left(320, 240);
    // The least-squares line through the dash's centre, rows 150–199.
    let rows: Vec<f64> = (150..200).map(f64::from).collect();
    let n = rows.len() as f64;
    let (mean_y, mean_x) = (
        rows.iter().sum::<f64>() / n,
        rows.iter().map(|&y| curved_dash_col(y)).sum::<f64>() / n,
    );
    let slope = rows
        .iter()
        .map(|&y| (y - mean_y) * (curved_dash_col(y) - mean_x))
        .sum::<f64>()
        / rows
            .iter()
            .map(|&y| (y - mean_y) * (y - mean_y))
            .sum::<f64>();
    let line = |y: f64| mean_x + slope * (y - mean_y);
    for no_turn_back in [true, false] {
        let mut cfg = TrackerConfig::default_preset().expect("the default preset");
        cfg.init.no_turn_back = no_turn_back;
        let mut tracker = LaneTracker::new(&cfg, Estimator::Kif, 320, 240).expect("a tracker");
        let bottom = (tracker.roi.1 - 1) as f64;
        let report = tracker.track(&frame).expect("a frame");
        assert!(report.lanes[0].initialised && report.lanes[1].initialised);
        let c = report.lanes[0].coeffs.expect("a left lane");
        let col = |y: f64| (c[0] * y + c[1]) * y + c[2];
        if no_turn_back {
            // Straight, along the dash's line: at its rows and on below them.
            assert_eq!(c[0], 0.0, "{c:?}");
            for y in [150.0, 199.0, bottom] {
                let d = col(y) - line(y);
                assert!(d.abs() < 2.0, "row {y}: {d} px off the dash's line");
            }
        } else {
            // The refined parabola turns back between the dash and the bottom row: the case
            // the setting is for arises here.
            let vertex = -c[1] / (2.0 * c[0]);
            assert!(
                vertex > 199.0 && vertex <= bottom,
                "vertex at row {vertex}: {c:?}"
            );
            assert!(col(bottom) - line(bottom) > 20.0, "{c:?}");
        }
    }
}

#[test]
fn tracked_frames_keep_the_filters_estimate_where_it_turns_back() {
    // No turn back acts on an initialisation only. The lane initialised on the curved dash
    // starts straight; set then to the dash's own parabola, whose vertex lies between the
    // dash and the bottom row, it is tracked on with the paper's update, vertex and all (the
    // jump gate refuses the 12+ px bend from the straight start at the bottom row, so the
    // filter is set to the bend rather than left to find it).
    let frame = curved_dash_left(320, 240);
    let (mut tracker, [.., bottom_row_px]) = default_tracker_and_rows();
    assert!(tracker.cfg.init.no_turn_back);
    let first = tracker.track(&frame).expect("a frame");
    assert!(first.lanes[0].initialised);
    assert_eq!(first.lanes[0].coeffs.map(|c| c[0]), Some(0.0));
    // x = 0.01·(y − 225)² + 90 (`curved_dash_col`).
    let dash = Vector3::new(0.01, -4.5, 0.01 * 225.0 * 225.0 + 90.0);
    tracker.lanes[0].filter = Some(tracker.new_filter(&dash).expect("a filter"));
    for frame_index in 1..4 {
        let report = tracker.track(&frame).expect("a frame");
        let lane = &report.lanes[0];
        assert!(
            lane.state == LaneState::Tracking && !lane.initialised && lane.points > 0,
            "frame {frame_index}: {lane:?}"
        );
    }
    let lane = &tracker.lanes[0];
    let c = lane
        .filter
        .as_ref()
        .map(LaneFilter::coeffs)
        .expect("a left lane");
    // Still bent, and still turning back below its points: an initialisation would have
    // straightened it.
    assert!(c[0] > 0.005, "{c:?}");
    assert!(
        super::turn_back::turn_back_line(c, &lane.points, &lane.weights, bottom_row_px, 320.0)
            .is_some(),
        "{c:?}"
    );
}

#[test]
fn a_frame_size_beyond_the_limit_is_refused_before_anything_is_sized() {
    // A width whose region of interest would overflow `width × rows` (a panic in a debug
    // build when the buffers were sized first) is an error naming the size.
    let cfg = TrackerConfig::default_preset().expect("the default preset");
    for (width, height) in [(usize::MAX / 2, 240), (320, usize::MAX / 2), (16385, 240)] {
        let Err(e) = LaneTracker::new(&cfg, Estimator::Kif, width, height) else {
            panic!("{width}×{height} accepted");
        };
        assert!(e.to_string().contains(&width.to_string()), "{e}");
    }
}

/// A frame of grey 60 with `mark_left`'s line drawn 200 bright and `2·half_px` wide (area
/// average) on the rows `rows`, and, when `step`, the floor right of the line 200 bright as
/// well (a step, not a stripe).
fn left_line(rows: std::ops::Range<f64>, half_px: f64, step: bool) -> GreyFrame {
    line_frame(mark_left, half_px, |y| rows.contains(&y), step)
}

/// A frame of grey 60 with a line 200 bright and `2·half_px` wide (area average) along each
/// row's `col(y)`, on the rows for which `drawn(y)` holds; when `step`, the floor right of the
/// line as bright as well (a step, not a stripe).
fn line_frame(
    col: impl Fn(f64) -> f64,
    half_px: f64,
    drawn: impl Fn(f64) -> bool,
    step: bool,
) -> GreyFrame {
    let (w, h) = (320, 240);
    let mut pixels = vec![60u8; w * h];
    for (i, p) in pixels.iter_mut().enumerate() {
        let (x, y) = ((i % w) as f64, (i / w) as f64);
        if !drawn(y) {
            continue;
        }
        let (lo, hi) = (col(y) - half_px, col(y) + if step { 1e9 } else { half_px });
        let cover = ((x + 0.5).min(hi) - (x - 0.5).max(lo)).clamp(0.0, 1.0);
        *p = (60.0 + 140.0 * cover).round() as u8;
    }
    GreyFrame::from_vec(w, h, pixels).expect("a whole frame")
}

/// Lane 0 of a default tracker as a refinement that was pulled off `mark_left` would leave
/// it: updated on this frame with points on a parabola that follows the line at the ROI's
/// top row and bends `bend_px` off it at the bottom row.
fn lane_bent_off_the_line(bend_px: f64) -> LaneTracker {
    let (mut tracker, _) = default_tracker_and_rows();
    let (top, bottom) = tracker.roi;
    let (t, b) = (top as f64, (bottom - 1) as f64);
    let c = bend_px / ((b - t) * (b - t));
    // x = mark_left(y) + c·(y − t)²
    let bent = Vector3::new(c, -0.45 - 2.0 * c * t, 100.0 + 0.45 * 239.0 + c * t * t);
    tracker.lanes[0].filter = Some(tracker.new_filter(&bent).expect("a filter"));
    let lane = &mut tracker.lanes[0];
    lane.points.clear();
    for r in top..bottom {
        let y = r as f64;
        lane.points
            .push(((mark_left(y) + c * (y - t) * (y - t)) as f32, y as f32));
    }
    let Some(LaneFilter::Kif(kif)) = lane.filter.as_mut() else {
        panic!("a KIF lane")
    };
    kif.update(&lane.points, 4.0).expect("an update");
    lane.state = LaneState::Tracking;
    lane.updated_now = true;
    lane.rows = [t, b];
    tracker
}

/// The lane's offset from `mark_left` at row `y`, px.
fn left_offset(tracker: &LaneTracker, y: f64) -> f64 {
    let c = tracker.lanes[0]
        .filter
        .as_ref()
        .map(LaneFilter::coeffs)
        .expect("a left lane");
    c[0] * y * y + c[1] * y + c[2] - mark_left(y)
}

#[test]
fn a_lane_bent_off_a_stripe_is_traced_back_onto_it() {
    // A straight 8-px line over the whole frame; the lane on it at the top row and 12 px off
    // at the bottom one. The trace starts at the points' middle row (3 px off, within half
    // the widest stripe), follows the line over every ROI row, and its middles pull the
    // bottom of the lane back onto it.
    let frame = left_line(0.0..240.0, 4.0, false);
    let image = GreyImage::new(frame.data(), 320, 240, 320).expect("an image");
    let mut tracker = lane_bent_off_the_line(12.0);
    let (top, bottom) = tracker.roi;
    let bottom_row = (bottom - 1) as f64;
    let before = left_offset(&tracker, bottom_row);
    assert!((before - 12.0).abs() < 0.5, "{before}");
    let points_before = tracker.lanes[0].points.len();
    let traced = tracker.trace_stripe(0, &image);
    assert_eq!(traced, bottom - top, "one middle a row");
    // Measured 2.4 px: the 92 refined points at σ = 2 px (on the bent parabola) against the 92
    // middles at σ/2 = 1 px (on the line) weigh 1 : 4, 12/(1 + 4) = 2.4 px.
    let after = left_offset(&tracker, bottom_row);
    assert!(after.abs() < 3.0, "{after} px off at the bottom row");
    let lane = &tracker.lanes[0];
    assert_eq!(
        lane.points.len(),
        points_before + traced,
        "the middles kept for overlays"
    );
    // The row profile weighs them as the update did: four edge pixels each.
    let profile: f64 = lane.fit.weights.iter().sum();
    assert_eq!(profile, (points_before + 4 * traced) as f64);
    assert!(
        lane.points[points_before..]
            .iter()
            .all(|&(x, y)| (f64::from(x) - mark_left(f64::from(y))).abs() <= 0.5),
        "the middles lie on the line"
    );
}

#[test]
fn the_trace_ends_with_its_stripe_and_reads_nothing_from_a_step() {
    // The line ends 30 rows above the bottom row: the trace ends there.
    let dash = left_line(0.0..210.0, 4.0, false);
    let image = GreyImage::new(dash.data(), 320, 240, 320).expect("an image");
    let mut tracker = lane_bent_off_the_line(12.0);
    let top = tracker.roi.0;
    let points_before = tracker.lanes[0].points.len();
    let traced = tracker.trace_stripe(0, &image);
    assert_eq!(traced, 210 - top, "the line's rows in the ROI");
    assert!(
        tracker.lanes[0].points[points_before..]
            .iter()
            .all(|&(_, y)| y < 210.0)
    );
    // A step where the line was (the floor right of it as bright): no stripe, no change.
    let step = left_line(0.0..240.0, 4.0, true);
    let image = GreyImage::new(step.data(), 320, 240, 320).expect("an image");
    let mut tracker = lane_bent_off_the_line(12.0);
    let before = tracker.lanes[0].filter.as_ref().map(LaneFilter::coeffs);
    assert_eq!(tracker.trace_stripe(0, &image), 0);
    assert_eq!(
        tracker.lanes[0].filter.as_ref().map(LaneFilter::coeffs),
        before
    );
    // Nor is a lane traced that its refinement did not update, nor a WRLS lane.
    let frame = left_line(0.0..240.0, 4.0, false);
    let image = GreyImage::new(frame.data(), 320, 240, 320).expect("an image");
    let mut tracker = lane_bent_off_the_line(12.0);
    tracker.lanes[0].updated_now = false;
    assert_eq!(tracker.trace_stripe(0, &image), 0);
    // Nor one the second search found (its parabola is carried down from above the ROI), nor
    // one measured by mark centres; the same lane otherwise is traced.
    let mut tracker = lane_bent_off_the_line(12.0);
    tracker.lanes[0].tracked_tall = true;
    assert_eq!(tracker.trace_stripe(0, &image), 0);
    let mut tracker = lane_bent_off_the_line(12.0);
    tracker.cfg.track.mark_centres = true;
    assert_eq!(tracker.trace_stripe(0, &image), 0);
    let mut tracker = lane_bent_off_the_line(12.0);
    assert!(tracker.trace_stripe(0, &image) > 0);
    let cfg = TrackerConfig::default_preset().expect("the default preset");
    let mut wrls = LaneTracker::new(&cfg, Estimator::Wrls, 320, 240).expect("a tracker");
    wrls.track(&frame).expect("a frame");
    assert!(wrls.lanes[0].updated_now, "the WRLS lane was refined");
    assert_eq!(wrls.trace_stripe(0, &image), 0);
}

#[test]
fn the_initialisation_of_a_wide_mark_is_traced_onto_its_middle() {
    // `wide_left_mark` with the paper's edge pixels in the refinement: the lane stays on the
    // edge the Hough line found (the test above); the trace's middles bring it to the middle.
    let frame = wide_left_mark(320, 240);
    let off = [false, true].map(|trace| initialised_on_wide_mark(&frame, false, trace).1);
    assert!(off[0] > 3.0, "without the trace: {} px off", off[0]);
    // Measured 4.9 and 1.5 px.
    assert!(
        off[1] < off[0] / 2.0,
        "traced: {} px off (without: {})",
        off[1],
        off[0]
    );
}

/// Lane 0 of a default tracker updated on this frame with points on rows `rows` of `col`,
/// its filter the straight line tangent to `col` at `row`.
fn lane_tangent_at(
    col: impl Fn(f64) -> f64,
    row: f64,
    rows: std::ops::Range<usize>,
) -> LaneTracker {
    let (mut tracker, _) = default_tracker_and_rows();
    let slope = col(row + 0.5) - col(row - 0.5);
    set_lane_line(
        &mut tracker,
        0,
        (row, col(row)),
        (row + 1.0, col(row) + slope),
    );
    let lane = &mut tracker.lanes[0];
    lane.points.clear();
    for r in rows {
        lane.points.push((col(r as f64) as f32, r as f32));
    }
    lane.state = LaneState::Tracking;
    lane.updated_now = true;
    tracker
}

#[test]
fn the_trace_follows_a_bending_stripe_with_its_slope() {
    // x = 160 + 0.03·(y − 194)²: vertical at row 194, 2.8 px a row at the ROI's ends. The
    // trace starts on the tangent at row 194 (slope 0) and the slope follows the steps
    // (weight 0.1: it lags by 0.06/0.1 = 0.6 px a row); with a fixed slope the stripe leaves
    // the 2-px reach after about 34 rows each way, and with the wrong sign for the steps
    // measured going up it turns away at once.
    let col = |y: f64| 160.0 + 0.03 * (y - 194.0) * (y - 194.0);
    let frame = line_frame(col, 3.0, |_| true, false);
    let image = GreyImage::new(frame.data(), 320, 240, 320).expect("an image");
    let mut tracker = lane_tangent_at(col, 194.0, 190..199);
    let (top, bottom) = tracker.roi;
    let points_before = tracker.lanes[0].points.len();
    let traced = tracker.trace_stripe(0, &image);
    assert_eq!(traced, bottom - top, "every ROI row");
    let middles = &tracker.lanes[0].points[points_before..];
    assert!(
        middles
            .iter()
            .all(|&(x, y)| (f64::from(x) - col(f64::from(y))).abs() < 0.5),
        "on the stripe"
    );
}

#[test]
fn the_trace_bridges_three_rows_without_a_middle_and_ends_at_the_fourth() {
    // A straight line with its rows 200–202 blank (bridged) and 215–218 blank (the end).
    let gaps = |y: f64| !(200.0..203.0).contains(&y) && !(215.0..219.0).contains(&y);
    let frame = line_frame(mark_left, 3.0, gaps, false);
    let image = GreyImage::new(frame.data(), 320, 240, 320).expect("an image");
    let mut tracker = lane_tangent_at(mark_left, 180.0, 170..190);
    let top = tracker.roi.0;
    let points_before = tracker.lanes[0].points.len();
    let traced = tracker.trace_stripe(0, &image);
    let rows: Vec<f32> = tracker.lanes[0].points[points_before..]
        .iter()
        .map(|&(_, y)| y)
        .collect();
    assert_eq!(traced, 215 - top - 3, "rows {top}..215 but 200–202");
    assert_eq!(rows.iter().copied().fold(0.0f32, f32::max), 214.0);
    assert!(rows.contains(&203.0) && !rows.contains(&201.0));
}

#[test]
fn no_turn_back_counts_the_traced_middles_as_evidence() {
    // A parabola turning back at row 215, below the refinement's points (rows 150–189) and
    // above the bottom row. Middles traced on down to row 200 are evidence above the vertex:
    // the lane is straightened, on the line through the points and the middles weighed as
    // the trace's update weighs them (4 edge pixels each). Traced on to the bottom row, they
    // reach past the vertex: the parabola is kept.
    let (mut tracker, _) = default_tracker_and_rows();
    let vertex = Vector3::new(0.01, -0.02 * 215.0, 0.01 * 215.0 * 215.0 + 60.0);
    let on_line = |y: f64| 150.0 - 0.5 * y;
    let set_up = |tracker: &mut LaneTracker, traced_to: u16| {
        tracker.lanes[0].filter = Some(tracker.new_filter(&vertex).expect("a filter"));
        let lane = &mut tracker.lanes[0];
        lane.points.clear();
        lane.weights.clear();
        // The refinement's points on one line, the middles on another (1 px to the right).
        for r in 150..190u16 {
            lane.points
                .push((on_line(f64::from(r)) as f32, f32::from(r)));
            lane.weights.push(1.0);
        }
        for r in 190..traced_to {
            lane.points
                .push((on_line(f64::from(r)) as f32 + 1.0, f32::from(r)));
            lane.weights.push(super::stripe_trace::MIDDLE_WEIGHT);
        }
        lane.state = LaneState::Tracking;
        lane.updated_now = true;
    };
    set_up(&mut tracker, 200);
    assert!(
        tracker.straighten_turn_back(0),
        "middles to row 199, vertex at 215"
    );
    let c = tracker.lanes[0]
        .filter
        .as_ref()
        .map(LaneFilter::coeffs)
        .expect("a lane");
    // The same line through the points with each middle repeated 4 times.
    let mut repeated: Vec<(f32, f32)> = (150..190u16)
        .map(|r| (on_line(f64::from(r)) as f32, f32::from(r)))
        .collect();
    for r in 190..200u16 {
        for _ in 0..4 {
            repeated.push((on_line(f64::from(r)) as f32 + 1.0, f32::from(r)));
        }
    }
    let vertex_coeffs = [vertex[0], vertex[1], vertex[2]];
    let (a2, a3) = super::turn_back::turn_back_line(vertex_coeffs, &repeated, &[], 239.0, 320.0)
        .expect("turns back");
    assert!(
        (c[1] - a2).abs() < 1e-9 && (c[2] - a3).abs() < 1e-6,
        "{c:?} against {a2} {a3}"
    );
    set_up(&mut tracker, 240);
    assert!(
        !tracker.straighten_turn_back(0),
        "middles to the bottom row"
    );
}
