//! Tracking behaviour on rendered sequences with exact ground truth, and on the real udacity
//! clip (read from the data root, `lane_bench::data`; missing, it fails these tests under CI and
//! skips them, saying so, elsewhere).
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use lane_eval::eval::{SequenceScore, continuity, run_tracker, score_sequence};
use lane_io::y4m::Y4mSource;
use lane_scenes::{SCENES, SceneRenderer, SceneSpec};
use lane_tracker::{
    Estimator, GreyFrame, LaneState, LaneTracker, Side, TrackReport, TrackerConfig, TrackerError,
};

fn run_scene(
    spec: SceneSpec,
    estimator: Estimator,
    w: usize,
    h: usize,
) -> (Vec<Option<TrackReport>>, lane_scenes::SequenceTruth) {
    let cfg = lane_io::config::load_tracker_config(spec.config).unwrap();
    run_scene_with(spec, &cfg, estimator, w, h)
}

/// [`run_scene`] with a given configuration.
fn run_scene_with(
    spec: SceneSpec,
    cfg: &TrackerConfig,
    estimator: Estimator,
    w: usize,
    h: usize,
) -> (Vec<Option<TrackReport>>, lane_scenes::SequenceTruth) {
    // The presets' pixel parameters are for 320-px-wide frames: a wider frame is tracked on
    // itself resampled to 320 px wide (`frame.working_width_px`), reported in its own pixels.
    let mut renderer = SceneRenderer::new(spec, w, h);
    let mut tracker = LaneTracker::new(cfg, estimator, w, h).unwrap();
    let mut frame = GreyFrame::default();
    let reports = (0..spec.frames)
        .map(|i| {
            renderer.render(i, &mut frame);
            Some(tracker.track(&frame).unwrap())
        })
        .collect();
    (reports, renderer.sequence_truth())
}

fn scene(name: &str) -> SceneSpec {
    SCENES.iter().find(|s| s.name == name).copied().unwrap()
}

/// The real udacity clip; `None` (skipped, said on stderr) when it is missing outside CI, a
/// failure naming it under CI.
fn udacity_clip() -> Option<std::path::PathBuf> {
    lane_bench::data::test_data_file(lane_bench::data::UDACITY_CLIP)
        .unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn every_synthetic_scene_meets_the_acceptance_bounds_with_kif() {
    // Issue 4 §4: mean lateral error ≤ 1.5 px at 320×240, accuracy ≥ 98 %, regained ≤ 3 frames.
    for spec in SCENES {
        let (reports, truth) = run_scene(*spec, Estimator::Kif, 320, 240);
        let s = score_sequence(&truth, &reports);
        assert!(s.mean_lateral_error_px <= 1.5, "{}: {s:?}", spec.name);
        assert!(s.accuracy >= 0.98, "{}: {s:?}", spec.name);
        assert!(s.max_recovery_frames <= 3, "{}: {s:?}", spec.name);
    }
}

#[test]
fn coefficients_are_in_the_input_image_pixel_convention_at_other_sizes() {
    // The same scene at 640×480: the reported parabola must match the truth in 640×480 pixels
    // (tolerance 10 px at 640 px width; a report in 320×240 or normalised units would be off by
    // tens of pixels).
    let (reports, truth) = run_scene(scene("curve_left_dashed"), Estimator::Kif, 640, 480);
    let s = score_sequence(&truth, &reports);
    assert!(s.accuracy >= 0.98, "{s:?}");
    assert!(s.mean_lateral_error_px <= 3.0, "{s:?}");
}

#[test]
fn a_wide_frame_is_tracked_at_the_working_width_and_reported_in_its_own_pixels() {
    // Every rendered scene at 1280×960 (f = 4, worked on at 320×240): the bounds of 320×240
    // scaled by 4, the coefficients in 1280×960 pixels (the truth's): a report left in working
    // pixels would be off by hundreds of pixels. (The exact mapping: the next test.)
    for spec in SCENES {
        let (reports, truth) = run_scene(*spec, Estimator::Kif, 1280, 960);
        let s = score_sequence(&truth, &reports);
        assert!(s.mean_lateral_error_px <= 4.0 * 1.5, "{}: {s:?}", spec.name);
        assert!(s.accuracy >= 0.98, "{}: {s:?}", spec.name);
        assert!(s.max_recovery_frames <= 3, "{}: {s:?}", spec.name);
    }
}

#[test]
fn a_frame_of_any_width_is_tracked_at_the_working_width_by_a_fractional_scale() {
    // Every rendered scene at widths that are no whole multiple of 320 (s = 1.6, 2.5 down and
    // 0.8 up): worked on at 320 px wide, the bounds of 320×240 scaled by s, the coefficients in
    // the input's pixels (a report left in working pixels is off by tens of px). Rounding s to
    // a whole number, as before (512 → 256 px), fails the working size (tried); the rendered
    // marks are wide enough to be tracked at 256 px too — the cost of that rounding on real
    // frames is in `eval-lanes --perturb`.
    for (w, h) in [(512usize, 384usize), (800, 600), (256, 192)] {
        let s = w as f64 / 320.0;
        for spec in SCENES {
            let (reports, truth) = run_scene(*spec, Estimator::Kif, w, h);
            let score = score_sequence(&truth, &reports);
            let what = format!("{} at {w}×{h}: {score:?}", spec.name);
            assert!(score.mean_lateral_error_px <= s.max(1.0) * 1.5, "{what}");
            assert!(score.accuracy >= 0.98, "{what}");
            assert!(score.max_recovery_frames <= 3, "{what}");
        }
        let cfg = TrackerConfig::default_preset().unwrap();
        let t = LaneTracker::new(&cfg, Estimator::Kif, w, h).unwrap();
        assert_eq!(t.working_size(), (320, 240), "{w}×{h}");
        assert_eq!(t.working_scale(), s, "{w}×{h}");
    }
}

/// `frame` box-averaged over `f × f` blocks, each mean rounded to the nearest grey level: the
/// working frame the tracker's module `working` defines, written here independently.
fn box_average(frame: &GreyFrame, f: usize) -> GreyFrame {
    let (w, h) = (frame.width() / f, frame.height() / f);
    let mut out = vec![0u8; w * h];
    for r in 0..h {
        for c in 0..w {
            let mut sum = 0u32;
            for j in 0..f {
                for i in 0..f {
                    sum += u32::from(frame.data()[(f * r + j) * frame.width() + f * c + i]);
                }
            }
            let area = (f * f) as u32;
            out[r * w + c] = ((sum + area / 2) / area) as u8;
        }
    }
    GreyFrame::from_vec(w, h, out).unwrap()
}

#[test]
fn a_wide_frame_reports_the_working_frames_lanes_mapped_to_its_pixels() {
    // A 1280×960 render tracked directly, and its box average (computed here) tracked by a
    // 320×240 tracker: the same working frame, so every output of the wide tracker must be the
    // small one's mapped by `x = 4·x' + 1.5`, `y = 4·y' + 1.5` — columns, points, windows,
    // candidates and the variance of a lane's column (f² times the small one's). Fails with
    // the offset 1.5 left out of the mapping, or the factor's power wrong in `a1` (tried).
    let spec = scene("curve_left_dashed");
    let cfg = lane_io::config::load_tracker_config(spec.config).unwrap();
    let (f, o) = (4usize, 1.5f64);
    let mut renderer = SceneRenderer::new(spec, 1280, 960);
    let mut wide = LaneTracker::new(&cfg, Estimator::Kif, 1280, 960).unwrap();
    let mut small = LaneTracker::new(&cfg, Estimator::Kif, 320, 240).unwrap();
    assert_eq!(wide.working_size(), (320, 240));
    assert_eq!(wide.working_scale(), f as f64);
    assert_eq!(wide.frame_size(), (1280, 960));
    let mut frame = GreyFrame::default();
    let mut compared = 0;
    for i in 0..spec.frames.min(40) {
        renderer.render(i, &mut frame);
        let rw = wide.track(&frame).unwrap();
        let averaged = box_average(&frame, f);
        let rs = small.track(&averaged).unwrap();
        // What the stages read: the box average on the rows they read.
        let (work, (first, end)) = wide.working_frame().unwrap();
        assert!(first < end && end <= 240, "frame {i}: rows {first}..{end}");
        for r in first..end {
            assert_eq!(work.row(r), averaged.row(r), "frame {i}: working row {r}");
        }
        for (k, side) in [Side::Left, Side::Right].into_iter().enumerate() {
            let (a, b) = (rw.lanes[k], rs.lanes[k]);
            assert_eq!(a.state, b.state, "frame {i}");
            assert_eq!(a.points, b.points, "frame {i}");
            for (yw, ys) in a.rows.iter().zip(b.rows) {
                assert!((yw - (f as f64 * ys + o)).abs() < 1e-9, "frame {i}: rows");
            }
            let (Some(_), Some(_)) = (a.coeffs, b.coeffs) else {
                assert_eq!(a.coeffs.is_some(), b.coeffs.is_some(), "frame {i}");
                continue;
            };
            let (fw, fs) = (
                wide.lane_fit_rows(side).unwrap(),
                small.lane_fit_rows(side).unwrap(),
            );
            assert_eq!(fw.weights, fs.weights, "frame {i}");
            for (yw, ys) in fw.rows_px.iter().zip(fs.rows_px) {
                assert!(
                    (yw - (f as f64 * ys + o)).abs() < 1e-9,
                    "frame {i}: fit rows"
                );
            }
            for y_w in [150.0, 180.5, 239.0] {
                let want = f as f64 * b.col_at_row(y_w).unwrap() + o;
                let got = a.col_at_row(f as f64 * y_w + o).unwrap();
                assert!(
                    (got - want).abs() < 1e-6,
                    "frame {i} row {y_w}: {got} vs {want}"
                );
                // Var(x(y)) = gᵀ·P·g with g = (y², y, 1): f² times the working one.
                let g = |y: f64| nalgebra::Vector3::new(y * y, y, 1.0);
                let (pw, ps) = (
                    wide.lane_covariance_px(side).unwrap(),
                    small.lane_covariance_px(side).unwrap(),
                );
                let y_in = f as f64 * y_w + o;
                let var_in = (g(y_in).transpose() * pw * g(y_in))[(0, 0)];
                let var_w = (g(y_w).transpose() * ps * g(y_w))[(0, 0)];
                let want_var = (f * f) as f64 * var_w;
                assert!(
                    (var_in - want_var).abs() <= 1e-6 * want_var.abs().max(1e-12),
                    "frame {i}: variance {var_in} vs {want_var}"
                );
            }
            let (vw, vs) = (wide.lane_view(side), small.lane_view(side));
            assert_eq!(vw.points.len(), vs.points.len());
            for (&(xw, yw), &(xs, ys)) in vw.points.iter().zip(vs.points) {
                assert!((f64::from(xw) - (4.0 * f64::from(xs) + o)).abs() < 1e-3);
                assert!((f64::from(yw) - (4.0 * f64::from(ys) + o)).abs() < 1e-3);
            }
            assert_eq!(vw.spans.len(), 960);
            for (y, span) in vw.spans.iter().enumerate() {
                let sw = vs.spans[y / f];
                assert_eq!(
                    (span.col_start_px, span.col_end_px),
                    (4 * sw.col_start_px, 4 * sw.col_end_px),
                    "frame {i} row {y}"
                );
            }
            compared += 1;
        }
        assert_eq!(wide.init_candidates().len(), small.init_candidates().len());
        for (cw, cs) in wide.init_candidates().iter().zip(small.init_candidates()) {
            let x = |c: [f64; 3], y: f64| c[0] * y * y + c[1] * y + c[2];
            let want = f as f64 * x(cs.coeffs, 200.0) + o;
            assert!((x(cw.coeffs, f as f64 * 200.0 + o) - want).abs() < 1e-6);
            assert_eq!(
                (cw.support, cw.chosen, cw.band),
                (cs.support, cs.chosen, cs.band)
            );
        }
    }
    assert!(compared > 40, "{compared} lanes compared");
    let (top, bottom) = small.roi_rows();
    assert_eq!(wide.roi_rows(), (f * top, f * bottom));
    // After a reset the wide tracker hands out nothing of the last frame, as the small one.
    wide.reset();
    small.reset();
    assert!(wide.init_candidates().is_empty());
    for side in [Side::Left, Side::Right] {
        let (vw, vs) = (wide.lane_view(side), small.lane_view(side));
        let r = |v: &lane_tracker::LaneView<'_>| (v.report.state, v.report.coeffs, v.report.points);
        assert_eq!(r(&vw), r(&vs));
        assert!(vw.points.is_empty());
        assert!(vw.spans.iter().all(|s| s.col_end_px == s.col_start_px));
    }
}

#[test]
fn working_width_zero_tracks_at_the_input_size_with_scaled_pixels() {
    // `frame.working_width_px = 0`: no resampling, the pixel fields scaled by hand (the way
    // before the working width): the 640×480 scene still meets its bounds.
    let spec = scene("curve_left_dashed");
    let mut cfg = lane_io::config::load_tracker_config(spec.config).unwrap();
    cfg.frame.working_width_px = 0;
    cfg.scale_pixels(2.0);
    let tracker = LaneTracker::new(&cfg, Estimator::Kif, 640, 480).unwrap();
    assert_eq!(tracker.working_size(), (640, 480));
    assert_eq!(tracker.working_scale(), 1.0);
    assert!(tracker.working_frame().is_none());
    let (reports, truth) = run_scene_with(spec, &cfg, Estimator::Kif, 640, 480);
    let s = score_sequence(&truth, &reports);
    assert!(s.accuracy >= 0.98, "{s:?}");
    assert!(s.mean_lateral_error_px <= 3.0, "{s:?}");
}

#[test]
fn a_lost_lane_is_reported_lost_without_coefficients_and_recovers() {
    let spec = scene("wall_recovery");
    let (wall_start, wall_end) = spec.wall.unwrap();
    let (reports, _) = run_scene(spec, Estimator::Kif, 320, 240);
    let cfg = TrackerConfig::outdoor().unwrap();
    let lost_from = wall_start + u64::from(cfg.track.lost_after_frames) - 1;
    for f in lost_from..wall_end {
        for lane in reports[f as usize].unwrap().lanes {
            assert_eq!(lane.state, LaneState::Lost, "frame {f}: {lane:?}");
            assert_eq!(
                lane.coeffs, None,
                "frame {f}: a lost lane must not report its last value"
            );
        }
    }
    // Coasting frames between the wall's start and the loss keep a prediction.
    for f in wall_start..lost_from {
        for lane in reports[f as usize].unwrap().lanes {
            assert_eq!(lane.state, LaneState::Coasting, "frame {f}");
            assert_eq!(lane.points, 0);
            assert!(
                lane.coeffs.is_some(),
                "frame {f}: a coasting lane reports its prediction"
            );
        }
    }
    let back = reports[wall_end as usize].unwrap();
    for lane in back.lanes {
        assert_eq!(lane.state, LaneState::Tracking);
        assert!(
            lane.initialised,
            "re-initialised on the first frame the road is back"
        );
    }
}

#[test]
fn reported_lanes_never_cross_and_keep_left_left() {
    for spec in SCENES {
        let (reports, truth) = run_scene(*spec, Estimator::Kif, 320, 240);
        for r in reports.iter().flatten() {
            if let (Some(l), Some(rr)) =
                (r.lanes[0].col_at_row(239.0), r.lanes[1].col_at_row(239.0))
            {
                assert!(l < rr, "{}: left {l} right {rr}", spec.name);
            }
            assert_eq!(r.lanes[0].side, Side::Left);
            assert_eq!(r.lanes[1].side, Side::Right);
        }
        assert_eq!(truth.frames.len(), reports.len());
    }
}

#[test]
fn at_most_max_points_per_lane_are_used_on_tracking_frames() {
    let mut cfg = TrackerConfig::outdoor().unwrap();
    cfg.track.max_points_per_lane = 40;
    let spec = scene("straight_solid");
    let mut renderer = SceneRenderer::new(spec, 320, 240);
    let mut tracker = LaneTracker::new(&cfg, Estimator::Kif, 320, 240).unwrap();
    let mut frame = GreyFrame::default();
    for i in 0..10 {
        renderer.render(i, &mut frame);
        let r = tracker.track(&frame).unwrap();
        if i > 0 {
            for lane in r.lanes {
                assert!(
                    lane.points <= 40 && lane.points >= 20,
                    "frame {i}: {lane:?}"
                );
            }
            // Spread over the rows: the points cover most of the window's rows.
            let view = tracker.lane_view(Side::Left);
            let (lo, hi) = view
                .points
                .iter()
                .fold((f32::MAX, f32::MIN), |(a, b), p| (a.min(p.1), b.max(p.1)));
            let (top, bottom) = tracker.roi_rows();
            assert!(
                hi - lo >= 0.6 * (bottom - top) as f32,
                "rows {lo}..{hi} of {top}..{bottom}"
            );
        }
    }
}

#[test]
fn tracking_frames_use_the_windows_only() {
    let spec = scene("straight_solid");
    let (reports, _) = run_scene(spec, Estimator::Kif, 320, 240);
    assert!(
        reports[0].unwrap().full_gradient,
        "the first frame initialises"
    );
    assert!(reports[1..].iter().all(|r| !r.unwrap().full_gradient));
}

#[test]
fn wrls_estimator_tracks_the_straight_scene() {
    let (reports, truth) = run_scene(scene("straight_solid"), Estimator::Wrls, 320, 240);
    let s = score_sequence(&truth, &reports);
    // λ = 0.70 remembers ~3 frames: it lags a swaying lane more than the KIF, but holds it.
    assert_eq!(s.missed_lane_frames, 0, "{s:?}");
    assert!(s.mean_lateral_error_px <= 4.0, "{s:?}");
}

#[test]
fn a_frame_of_the_wrong_size_is_a_typed_error() {
    let cfg = TrackerConfig::outdoor().unwrap();
    let mut tracker = LaneTracker::new(&cfg, Estimator::Kif, 320, 240).unwrap();
    let err = tracker.track(&GreyFrame::new(321, 240)).unwrap_err();
    assert!(
        matches!(err, TrackerError::FrameSize { got_w: 321, .. }),
        "{err}"
    );
    let err = LaneTracker::new(&cfg, Estimator::Kif, 0, 240).unwrap_err();
    assert!(matches!(err, TrackerError::ZeroSize { .. }), "{err}");
}

#[test]
fn blank_frames_report_initialising_without_coefficients() {
    let cfg = TrackerConfig::outdoor().unwrap();
    let mut tracker = LaneTracker::new(&cfg, Estimator::Kif, 64, 48).unwrap();
    let frame = GreyFrame::from_vec(64, 48, vec![128; 64 * 48]).unwrap();
    for _ in 0..3 {
        let r = tracker.track(&frame).unwrap();
        for lane in r.lanes {
            assert_eq!(lane.state, LaneState::Initialising);
            assert_eq!(lane.coeffs, None);
        }
    }
}

#[test]
fn the_real_udacity_clip_keeps_both_lanes_in_its_first_30_frames() {
    let Some(path) = udacity_clip() else {
        return;
    };
    let file = std::io::BufReader::new(std::fs::File::open(&path).unwrap());
    let mut source = Y4mSource::new(file, path.display().to_string()).unwrap();
    let cfg = TrackerConfig::outdoor().unwrap();
    let run = run_tracker(&mut source, &cfg, Estimator::Kif, Some(30)).unwrap();
    let c = continuity(&run.reports, 239.0);
    assert_eq!(c.frames, 30);
    assert_eq!(c.frames_both_reported, 30, "{c:?}");
    assert!(c.median_bottom_change_px <= 3.0, "{c:?}");
    assert_eq!(
        c.initialisations, 2,
        "no unexplained re-initialisation: {c:?}"
    );
}

/// A dark floor with two bright 4-px marks, both leaning `\` (a right-hand curve seen from inside
/// the lane): the left boundary from column 100 (bottom) to 40 (row 150), the right one from 290
/// to 160.
fn curve_pair_frame() -> GreyFrame {
    let (w, h) = (320usize, 240usize);
    let mut data = vec![40u8; w * h];
    for y in 0..h {
        let t = (239.0 - y as f64) / 89.0;
        for (bottom, top) in [(100.0, 40.0), (290.0, 160.0)] {
            let centre = bottom + (top - bottom) * t;
            for x in 0..w {
                if (x as f64 - centre).abs() <= 2.0 {
                    data[y * w + x] = 200;
                }
            }
        }
    }
    let mut frame = GreyFrame::default();
    frame.reshape(w, h).unwrap();
    frame.data_mut().copy_from_slice(&data);
    frame
}

#[test]
fn the_default_joint_initialisation_sides_lanes_by_position_on_a_curve() {
    // The paper's initialisation takes the best `/` line as the left lane: there is none, and
    // the right lane's class holds both marks. The default's joint choice finds the pair.
    let frame = curve_pair_frame();
    let cfg = TrackerConfig::default_preset().unwrap();
    let mut tracker = LaneTracker::new(&cfg, Estimator::Kif, 320, 240).unwrap();
    let report = tracker.track(&frame).unwrap();
    let [left, right] = report.lanes;
    let at = |l: &lane_tracker::LaneReport, y: f64| l.col_at_row(y).unwrap();
    assert_eq!(left.state, LaneState::Tracking);
    assert_eq!(right.state, LaneState::Tracking);
    assert!(
        (at(&left, 230.0) - (100.0 - 60.0 * 9.0 / 89.0)).abs() < 2.0,
        "{left:?}"
    );
    assert!(
        (at(&right, 230.0) - (290.0 - 130.0 * 9.0 / 89.0)).abs() < 2.0,
        "{right:?}"
    );
    // Tracking the next (identical) frame keeps both: rows take the class of the predicted slope.
    let report = tracker.track(&frame).unwrap();
    assert!(report.lanes.iter().all(|l| l.state == LaneState::Tracking));
    assert!(!report.full_gradient);

    let mut paper = cfg;
    paper.init.candidate_lines = 0;
    let mut tracker = LaneTracker::new(&paper, Estimator::Kif, 320, 240).unwrap();
    let report = tracker.track(&frame).unwrap();
    assert!(report.lanes[0].coeffs.is_none(), "{:?}", report.lanes[0]);
}

/// A rendered scene at 320×240 tracked with `cfg` (KIF), scored against its truth.
fn score_with(cfg: &TrackerConfig, spec: &SceneSpec) -> SequenceScore {
    let mut renderer = SceneRenderer::new(*spec, 320, 240);
    let mut tracker = LaneTracker::new(cfg, Estimator::Kif, 320, 240).unwrap();
    let mut frame = GreyFrame::default();
    let reports: Vec<Option<TrackReport>> = (0..spec.frames)
        .map(|i| {
            renderer.render(i, &mut frame);
            Some(tracker.track(&frame).unwrap())
        })
        .collect();
    score_sequence(&renderer.sequence_truth(), &reports)
}

#[test]
fn the_noise_scene_is_tracked_at_every_centre_weight_of_the_ego_pair() {
    // On `noise`'s first frame a continuous road edge (a step) gathers noise pixels as the dashed
    // left mark gathers paired ones; with the unpaired pixels of a row counted one step's worth
    // (lane-tracker, `row_coverage`) the mark wins on coverage alone, not by the pair's centre
    // and width terms: the choice holds whatever the centre weight (without that cap every
    // weight below 0.9 took the road edge: mean error 17.6 px, accuracy 0.50).
    let spec = scene("noise");
    for centre_weight in [0.0, 0.3, 0.5, 0.7, 1.0] {
        let mut cfg = TrackerConfig::default_preset().unwrap();
        cfg.init.ego_pair.centre_weight = centre_weight;
        let s = score_with(&cfg, &spec);
        assert!(s.mean_lateral_error_px <= 1.5, "{centre_weight}: {s:?}");
        assert!(s.accuracy >= 0.98, "{centre_weight}: {s:?}");
    }
}

#[test]
fn every_synthetic_scene_is_tracked_with_the_default_configuration() {
    // The default configuration (joint initialisation, stripe pairing, threshold 60, the
    // orientation gate on the window pixels) on the rendered sequences: the presets' acceptance
    // bounds on every scene. On `noise` (σ = 8 grey levels: about a third of the pixels pass the
    // threshold) the gate keeps the noise pixels out of the windows; the figures with and without
    // it are printed (`cargo test -p lane-eval --test tracking every_synthetic -- --nocapture`).
    let cfg = TrackerConfig::default_preset().unwrap();
    for spec in SCENES {
        let s = score_with(&cfg, spec);
        println!(
            "{}: mean lateral error {:.2} px, accuracy {:.3}",
            spec.name, s.mean_lateral_error_px, s.accuracy
        );
        assert!(s.mean_lateral_error_px <= 1.5, "{}: {s:?}", spec.name);
        assert!(s.accuracy >= 0.98, "{}: {s:?}", spec.name);
        assert!(s.max_recovery_frames <= 3, "{}: {s:?}", spec.name);
    }
    let mut ungated = cfg;
    ungated.track.orientation_tolerance_deg = 0.0;
    let s = score_with(&ungated, &scene("noise"));
    println!(
        "noise without the orientation gate: mean lateral error {:.2} px, accuracy {:.3}",
        s.mean_lateral_error_px, s.accuracy
    );
}

#[test]
fn every_real_udacity_frame_initialised_alone_gives_both_lanes_with_the_default() {
    // A still-image check of the initialisation on a real highway with a dashed left mark: a
    // fresh tracker per frame, so nothing is carried over from the previous frame.
    let Some(path) = udacity_clip() else {
        return;
    };
    let file = std::io::BufReader::new(std::fs::File::open(&path).unwrap());
    let mut source = Y4mSource::new(file, path.display().to_string()).unwrap();
    let cfg = TrackerConfig::default_preset().unwrap();
    let mut frame = GreyFrame::default();
    let (mut frames, mut both) = (0, 0);
    while lane_io::FrameSource::next_frame(&mut source, &mut frame)
        .unwrap()
        .is_some()
    {
        let mut tracker =
            LaneTracker::new(&cfg, Estimator::Kif, frame.width(), frame.height()).unwrap();
        let r = tracker.track(&frame).unwrap();
        frames += 1;
        both += usize::from(r.lanes.iter().all(|l| l.coeffs.is_some()));
    }
    assert_eq!(frames, 221);
    // Measured 220/221 (the paper's initialisation: 221); a few frames of margin.
    assert!(both >= 215, "both lanes on {both} of {frames} stills");
}

#[test]
fn the_real_udacity_clip_as_an_mp4_keeps_both_lanes_on_every_frame() {
    // Encoded with ffmpeg (MPEG-4 part 2, q 2) from the y4m clip and read back through ffmpeg
    // (`lane_io::video`): the default configuration tracks both lanes on all 221 frames, as on
    // the y4m.
    let ffmpeg_ok = std::process::Command::new("ffmpeg")
        .arg("-version")
        .output()
        .is_ok_and(|o| o.status.success());
    if !ffmpeg_ok {
        assert!(
            std::env::var_os("CI").is_none(),
            "ffmpeg is missing under CI"
        );
        eprintln!("SKIPPED: ffmpeg is not installed");
        return;
    }
    let Some(clip) = udacity_clip() else {
        return;
    };
    let mp4 = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("udacity.mp4");
    let out = std::process::Command::new("ffmpeg")
        .args(["-hide_banner", "-v", "error", "-y", "-i"])
        .arg(&clip)
        .args(["-c:v", "mpeg4", "-q:v", "2", "-pix_fmt", "yuv420p"])
        .arg(&mp4)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let mut source = lane_io::sources::open_input(&mp4, 0.0).unwrap();
    let cfg = TrackerConfig::default_preset().unwrap();
    let run = run_tracker(&mut source, &cfg, Estimator::Kif, None).unwrap();
    let c = continuity(&run.reports, 239.0);
    assert_eq!(c.frames, 221, "{c:?}");
    assert_eq!(c.frames_both_reported, 221, "{c:?}");
}

#[test]
fn a_short_wide_frame_keeps_a_working_frame_of_three_rows() {
    // 1280×8: s is held to a third of the height (8/3: a 480×3 working frame), not 4 (320×2,
    // too small); 1280×5 likewise (5/3: 768×3). Both track a blank frame without an error.
    let cfg = TrackerConfig::default_preset().unwrap();
    for (h, working) in [(8, (480, 3)), (5, (768, 3))] {
        let mut t = LaneTracker::new(&cfg, Estimator::Kif, 1280, h).unwrap();
        assert_eq!(t.working_size(), working);
        let frame = GreyFrame::from_vec(1280, h, vec![100; 1280 * h]).unwrap();
        let r = t.track(&frame).unwrap();
        assert!(r.lanes.iter().all(|l| l.coeffs.is_none()));
    }
}
