//! The tracker's failure paths: a filter that refuses an update is counted, its typed error kept,
//! the lane coasts on its prediction, and none of it allocates.

use alloc_counter::{CountingAllocator, allocations_in};
use info_filter::KifError;
use wrls::WrlsError;

use super::{Estimator, LaneState, LaneTracker, Side};
use crate::{FilterFailure, GreyFrame, TrackerConfig};

#[global_allocator]
static ALLOC: CountingAllocator = CountingAllocator::new();

/// Two bright marks (`/` left, `\` right) 5 px wide on a dark floor.
fn two_marks(w: usize, h: usize) -> GreyFrame {
    let left = |y: f64| 100.0 - 0.45 * (y - 239.0);
    let right = |y: f64| 220.0 + 0.45 * (y - 239.0);
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
    let cfg = TrackerConfig::default_preset().expect("the default preset");
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
