//! The refinement's stripe trace (module `stripe_trace`).

use super::scenes::*;
use super::*;

#[test]
fn a_lane_bent_off_a_stripe_is_traced_back_onto_it() {
    // A straight 8-px line over the whole frame; the lane on it at the top row and 12 px off
    // at the bottom one. The trace starts at the points' middle row (3 px off, within half
    // the widest stripe), follows the line over every ROI row, and its middles pull the
    // bottom of the lane back onto it.
    let frame = left_line(0.0..240.0, 4.0, false);
    let image = GreyImage::new(frame.data(), 320, 240, 320).expect("an image");
    let mut tracker = lane_bent_off_the_line(12.0);
    let (top, bottom) = tracker.setup.roi;
    let bottom_row = (bottom - 1) as f64;
    let before = left_offset(&tracker, bottom_row);
    assert!((before - 12.0).abs() < 0.5, "{before}");
    let points_before = tracker.lanes[Side::Left].points.len();
    let traced = trace_stripe(&mut tracker, Side::Left, &image);
    assert_eq!(traced, bottom - top, "one middle a row");
    // Measured 2.4 px: the 92 refined points at σ = 2 px (on the bent parabola) against the 92
    // middles at σ/2 = 1 px (on the line) weigh 1 : 4, 12/(1 + 4) = 2.4 px.
    let after = left_offset(&tracker, bottom_row);
    assert!(after.abs() < 3.0, "{after} px off at the bottom row");
    let lane = &tracker.lanes[Side::Left];
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
    let top = tracker.setup.roi.0;
    let points_before = tracker.lanes[Side::Left].points.len();
    let traced = trace_stripe(&mut tracker, Side::Left, &image);
    assert_eq!(traced, 210 - top, "the line's rows in the ROI");
    assert!(
        tracker.lanes[Side::Left].points[points_before..]
            .iter()
            .all(|&(_, y)| y < 210.0)
    );
    // A step where the line was (the floor right of it as bright): no stripe, no change.
    let step = left_line(0.0..240.0, 4.0, true);
    let image = GreyImage::new(step.data(), 320, 240, 320).expect("an image");
    let mut tracker = lane_bent_off_the_line(12.0);
    let before = tracker.lanes[Side::Left]
        .filter
        .as_ref()
        .map(LaneFilter::coeffs);
    assert_eq!(trace_stripe(&mut tracker, Side::Left, &image), 0);
    assert_eq!(
        tracker.lanes[Side::Left]
            .filter
            .as_ref()
            .map(LaneFilter::coeffs),
        before
    );
    // Nor is a lane traced that its refinement did not update, nor a WRLS lane.
    let frame = left_line(0.0..240.0, 4.0, false);
    let image = GreyImage::new(frame.data(), 320, 240, 320).expect("an image");
    let mut tracker = lane_bent_off_the_line(12.0);
    tracker.lanes[Side::Left].updated_now = false;
    assert_eq!(trace_stripe(&mut tracker, Side::Left, &image), 0);
    // Nor one the second search found (its parabola is carried down from above the ROI), nor
    // one measured by mark centres; the same lane otherwise is traced.
    let mut tracker = lane_bent_off_the_line(12.0);
    tracker.lanes[Side::Left].tracked_tall = true;
    assert_eq!(trace_stripe(&mut tracker, Side::Left, &image), 0);
    let mut tracker = lane_bent_off_the_line(12.0);
    tracker.setup.cfg.track.mark_centres = true;
    assert_eq!(trace_stripe(&mut tracker, Side::Left, &image), 0);
    let mut tracker = lane_bent_off_the_line(12.0);
    assert!(trace_stripe(&mut tracker, Side::Left, &image) > 0);
    let cfg = TrackerConfig::default_preset().expect("the default preset");
    let mut wrls = LaneTracker::new(&cfg, Estimator::Wrls, 320, 240).expect("a tracker");
    wrls.track(&frame).expect("a frame");
    assert!(
        wrls.lanes[Side::Left].updated_now,
        "the WRLS lane was refined"
    );
    assert_eq!(trace_stripe(&mut wrls, Side::Left, &image), 0);
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
    let (top, bottom) = tracker.setup.roi;
    let points_before = tracker.lanes[Side::Left].points.len();
    let traced = trace_stripe(&mut tracker, Side::Left, &image);
    assert_eq!(traced, bottom - top, "every ROI row");
    let middles = &tracker.lanes[Side::Left].points[points_before..];
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
    let top = tracker.setup.roi.0;
    let points_before = tracker.lanes[Side::Left].points.len();
    let traced = trace_stripe(&mut tracker, Side::Left, &image);
    let rows: Vec<f32> = tracker.lanes[Side::Left].points[points_before..]
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
        tracker.lanes[Side::Left].filter =
            Some(tracker.setup.new_filter(&vertex).expect("a filter"));
        let lane = &mut tracker.lanes[Side::Left];
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
            lane.weights
                .push(crate::tracker::stripe_trace::MIDDLE_WEIGHT);
        }
        lane.state = LaneState::Tracking;
        lane.updated_now = true;
    };
    set_up(&mut tracker, 200);
    assert!(
        straighten_turn_back(&mut tracker, Side::Left),
        "middles to row 199, vertex at 215"
    );
    let c = tracker.lanes[Side::Left]
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
    let (a2, a3) =
        crate::tracker::turn_back::turn_back_line(vertex_coeffs, &repeated, &[], 239.0, 320.0)
            .expect("turns back");
    assert!(
        (c[1] - a2).abs() < 1e-9 && (c[2] - a3).abs() < 1e-6,
        "{c:?} against {a2} {a3}"
    );
    set_up(&mut tracker, 240);
    assert!(
        !straighten_turn_back(&mut tracker, Side::Left),
        "middles to the bottom row"
    );
}
