//! The failure paths and limits: a filter that refuses an update is counted, its typed error kept,
//! the lane coasts on its prediction, none of it allocates; a frame too large is refused; the
//! window points' orientation gate.

use super::scenes::*;
use super::*;

#[test]
fn a_refused_kif_update_is_counted_kept_typed_and_does_not_allocate() {
    let cfg = TrackerConfig::default_preset().expect("the default preset");
    let frame = two_marks(320, 240);
    let mut tracker = LaneTracker::new(&cfg, Estimator::Kif, 320, 240).expect("a tracker");
    let first = tracker.track(&frame).expect("a frame of the right size");
    assert!(first.lanes.iter().all(|l| l.state == LaneState::Tracking));
    assert_eq!(tracker.last_filter_error(Side::Left), None);
    // A measurement variance no validated configuration holds: the KIF refuses every update.
    tracker.setup.cfg.filter.r_sigma_px = 0.0;
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
    tracker.setup.cfg.filter.wrls_lambda = 0.0;
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
