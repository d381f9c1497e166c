//! The period's re-validation spread over its frames (module `revalidation`).

use super::scenes::*;
use super::*;
use crate::tracker::revalidation::{STEPS, steps_by};

#[test]
fn each_frame_of_a_period_does_at_most_its_share_of_the_steps_and_only_the_last_chooses() {
    for every in 2..=40u64 {
        let share = STEPS.div_ceil(every as usize);
        let mut before = 0;
        for position in 0..every {
            let done = steps_by(position, every);
            assert!(done >= before, "P = {every}, frame {position}");
            assert!(
                done - before <= share,
                "P = {every}, frame {position}: {before} → {done}"
            );
            // The choice (the last step) on the period's last frame only.
            assert_eq!(
                done == STEPS,
                position == every - 1,
                "P = {every}, frame {position}"
            );
            before = done;
        }
    }
}

/// A default tracker (with `track.revalidate_spread` as given) that tracked `frame` once.
fn tracker_on(frame: &GreyFrame, spread: bool) -> LaneTracker {
    let mut cfg = TrackerConfig::default_preset().expect("the default preset");
    assert!(cfg.track.revalidate_spread, "the default spreads");
    cfg.track.revalidate_spread = spread;
    let mut tracker = LaneTracker::new(&cfg, Estimator::Kif, 320, 240).expect("a tracker");
    let first = tracker.track(frame).expect("a frame");
    assert!(first.full_gradient && first.lanes.iter().all(|l| l.coeffs.is_some()));
    tracker
}

#[test]
fn a_steady_pair_is_revalidated_every_period_without_a_whole_revalidation() {
    // Three anti-aliased marks: both windows keep enough points (the weak-evidence trigger does
    // not fire). Spread, every period ends with the choice keeping the pair, and no frame after
    // the first goes through the whole re-validation (nor reports candidates); whole, every
    // 10th frame does. Neither allocates.
    let frame = three_marks_shifted(320, 240, 0.0);
    for spread in [true, false] {
        let mut tracker = tracker_on(&frame, spread);
        let every = u64::from(tracker.config().track.revalidate_every_frames);
        let mut whole = Vec::new();
        for n in 1..=3 * every {
            let (report, allocations) = allocations_in(|| tracker.track(&frame));
            let report = report.expect("a frame");
            assert_eq!(allocations, 0, "frame {n}");
            if report.full_gradient {
                whole.push(n);
                assert!(!tracker.init_candidates().is_empty());
            } else {
                assert!(tracker.init_candidates().is_empty(), "frame {n}");
            }
        }
        let counters = tracker.counters();
        assert_eq!(counters.revalidations, 3, "spread {spread}: {counters:?}");
        assert_eq!(counters.revalidation_switches, [0, 0]);
        assert_eq!(counters.initialisations, [1, 1]);
        let expected: Vec<u64> = if spread {
            vec![]
        } else {
            vec![every, 2 * every, 3 * every]
        };
        assert_eq!(whole, expected, "spread {spread}");
    }
}

#[test]
fn a_lane_on_a_faint_line_is_moved_on_the_same_frame_with_and_without_the_spread() {
    // The left lane put on a faint line beside its mark: the period's choice (spread: on the
    // edges of the period's first frame) would move it, so the whole re-validation runs on the
    // period's last frame and moves it — the frame the whole re-validation alone moves it on.
    // The scene does not change: both give the same lanes on every frame.
    let frame = two_marks_and_a_faint_dashed_line(320, 240);
    let line = nalgebra::Vector3::new(0.0, -0.45, faint_line(0.0));
    let mut runs = [true, false].map(|spread| {
        let mut tracker = tracker_on(&frame, spread);
        tracker.lanes[Side::Left].filter = Some(tracker.setup.new_filter(&line).expect("a filter"));
        tracker
    });
    let every = u64::from(runs[0].config().track.revalidate_every_frames);
    for n in 1..=2 * every {
        let [spread, whole] = &mut runs;
        let (a, b) = (
            spread.track(&frame).expect("a frame"),
            whole.track(&frame).expect("a frame"),
        );
        assert_eq!(a.lanes, b.lanes, "frame {n}");
        assert_eq!(a.full_gradient, n == every, "frame {n}");
        assert_eq!(b.full_gradient, n % every == 0, "frame {n}");
    }
    for tracker in &runs {
        let counters = tracker.counters();
        assert_eq!(counters.revalidation_switches, [1, 0], "{counters:?}");
        assert_eq!(counters.revalidations, 2, "{counters:?}");
    }
    let (top, bottom) = runs[0].setup.roi;
    let c = runs[0]
        .lane_view(Side::Left)
        .report
        .coeffs
        .expect("a left lane");
    let off = (top..bottom)
        .map(|y| (Parabola::from_coeffs(c).col_at_row(y as f64) - mark_left(y as f64)).abs())
        .fold(0.0, f64::max);
    assert!(off < 2.0, "{off} px from the mark");
}

#[test]
fn a_whole_revalidation_mid_period_starts_the_spread_period_again() {
    // A 40-px jump on frame 4 empties both windows: the weak-evidence trigger re-validates
    // whole at once (and moves the pair), and the spread period starts again from the next
    // frame, its choice 10 frames later — not on frame 10, where the first period would have
    // ended.
    let mut tracker = tracker_on(&three_marks_shifted(320, 240, 0.0), true);
    let every = u64::from(tracker.config().track.revalidate_every_frames);
    let jump = 4;
    let mut revalidated = Vec::new();
    for n in 1..=jump + 2 * every {
        let shift = if n < jump { 0.0 } else { 40.0 };
        let before = tracker.counters().revalidations;
        let report = tracker
            .track(&three_marks_shifted(320, 240, shift))
            .expect("a frame");
        if tracker.counters().revalidations > before {
            revalidated.push((n, report.full_gradient));
        }
    }
    assert_eq!(
        revalidated,
        [
            (jump, true),
            (jump + every, false),
            (jump + 2 * every, false)
        ]
    );
    assert_eq!(tracker.counters().revalidation_switches, [1, 1]);
}
