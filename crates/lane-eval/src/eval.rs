//! Scoring a tracker run against ground truth: lateral error at fixed rows, a TuSimple-style
//! accuracy, recovery time after the lanes reappear, initialisation count.

use serde::{Deserialize, Serialize};

use lane_io::FrameSource;
use lane_io::frame_loop::{FrameLoop, Step};
use lane_tracker::{Estimator, GreyFrame, LaneState, TrackReport, TrackerConfig, TrackerCounters};

use crate::EvalError;
use lane_scenes::SequenceTruth;

/// TuSimple's tolerance: a point is correct within 20 px at 1280 px width; scaled to the frame
/// width here (5 px at 320 px).
pub fn tusimple_tolerance_px(width_px: usize) -> f64 {
    20.0 * width_px as f64 / 1280.0
}

/// Scores of one sequence.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct SequenceScore {
    /// Mean |x_reported − x_true| over the evaluation rows of every frame where a visible lane is
    /// reported (tracking or coasting), px.
    pub mean_lateral_error_px: f64,
    /// Largest per-frame mean lateral error (over the evaluation rows) of a reported visible lane, px.
    pub max_frame_lateral_error_px: f64,
    /// Fraction of (frame, visible lane, evaluation row) points reported within
    /// [`tusimple_tolerance_px`]; a lane not reported counts all its points wrong.
    pub accuracy: f64,
    /// Frame-lanes where the lane was visible but nothing was reported.
    pub missed_lane_frames: u64,
    /// Frame-lanes where the lane was invisible but coefficients were reported.
    pub false_lane_frames: u64,
    /// Worst number of frames, after a lane becomes visible (sequence start included), before it
    /// is reported with ≥ 90 % of its points correct. 0 = on the first frame.
    pub max_recovery_frames: u64,
    /// Successful (re-)initialisations, both lanes, the first ones included.
    pub initialisations: u64,
}

/// Score a run: `reports[i]` is the tracker's report on frame `truth.frames[i]` (`None` for a
/// frame that could not be read).
pub fn score_sequence(truth: &SequenceTruth, reports: &[Option<TrackReport>]) -> SequenceScore {
    let tol = tusimple_tolerance_px(truth.width);
    let (mut err_sum, mut err_n, mut max_frame_err) = (0.0, 0u64, 0.0f64);
    let (mut correct, mut total) = (0u64, 0u64);
    let (mut missed, mut false_reports, mut inits) = (0u64, 0u64, 0u64);
    let mut max_recovery = 0u64;
    for side in 0..2 {
        let mut waiting_since: Option<u64> = None;
        let mut was_visible = false;
        for (i, tf) in truth.frames.iter().enumerate() {
            let gt = &tf.lanes[side];
            let rep = reports.get(i).copied().flatten().map(|r| r.lanes[side]);
            if rep.is_some_and(|r| r.initialised) {
                inits += 1;
            }
            let reported = rep.filter(|r| {
                r.coeffs.is_some() && matches!(r.state, LaneState::Tracking | LaneState::Coasting)
            });
            if !gt.visible {
                if reported.is_some() {
                    false_reports += 1;
                }
                was_visible = false;
                continue;
            }
            if !was_visible {
                waiting_since = Some(i as u64);
            }
            was_visible = true;
            let n_rows = truth.eval_rows.len() as u64;
            total += n_rows;
            let Some(r) = reported else {
                missed += 1;
                continue;
            };
            let (mut frame_err, mut frame_ok) = (0.0, 0u64);
            for &y in &truth.eval_rows {
                let e = (r.col_at_row(y).unwrap_or(f64::INFINITY) - gt.col_at_row(y)).abs();
                frame_err += e;
                if e <= tol {
                    frame_ok += 1;
                }
            }
            correct += frame_ok;
            let frame_err = frame_err / n_rows.max(1) as f64;
            err_sum += frame_err;
            err_n += 1;
            max_frame_err = max_frame_err.max(frame_err);
            if let Some(start) = waiting_since
                && frame_ok as f64 >= 0.9 * n_rows as f64
            {
                max_recovery = max_recovery.max(i as u64 - start);
                waiting_since = None;
            }
        }
        if let Some(start) = waiting_since {
            max_recovery = max_recovery.max(truth.frames.len() as u64 - start);
        }
    }
    SequenceScore {
        mean_lateral_error_px: if err_n > 0 {
            err_sum / err_n as f64
        } else {
            f64::INFINITY
        },
        max_frame_lateral_error_px: max_frame_err,
        accuracy: if total > 0 {
            correct as f64 / total as f64
        } else {
            1.0
        },
        missed_lane_frames: missed,
        false_lane_frames: false_reports,
        max_recovery_frames: max_recovery,
        initialisations: inits,
    }
}

/// A whole run of the tracker over a source.
#[derive(Debug)]
pub struct TrackRun {
    /// Report per frame index (`None` for a frame that was skipped as bad).
    pub reports: Vec<Option<TrackReport>>,
    /// Non-fatal frame errors (reported, counted, skipped), typed.
    pub bad_frames: Vec<lane_io::LaneIoError>,
    /// The tracker's counters at the end.
    pub counters: TrackerCounters,
}

/// Run a fresh tracker (built on the first frame's size) over `source`, at most `max_frames`,
/// through the one frame loop ([`lane_io::frame_loop`]). Fatal source errors and tracker errors
/// end the run with that error.
pub fn run_tracker(
    source: &mut dyn FrameSource,
    cfg: &TrackerConfig,
    estimator: Estimator,
    max_frames: Option<u64>,
) -> Result<TrackRun, EvalError> {
    let mut lanes = FrameLoop::new(*cfg, estimator);
    let mut reports = Vec::new();
    let mut bad_frames = Vec::new();
    let mut n = 0u64;
    while max_frames.is_none_or(|m| n < m) {
        let tracked = match lanes.step(source)? {
            Step::Tracked(t) => t,
            Step::Skipped(e) => {
                bad_frames.push(e);
                continue;
            }
            Step::End => break,
        };
        let i = usize::try_from(tracked.meta.index).unwrap_or(usize::MAX);
        if reports.len() <= i {
            reports.resize(i + 1, None);
        }
        if let Some(slot) = reports.get_mut(i) {
            *slot = Some(tracked.report);
        }
        n += 1;
    }
    let counters = lanes.tracker().map(|t| *t.counters()).unwrap_or_default();
    Ok(TrackRun {
        reports,
        bad_frames,
        counters,
    })
}

/// Continuity on an unlabelled real sequence.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct ContinuityScore {
    /// Frames read.
    pub frames: u64,
    /// Frames where both lanes were reported tracking (updated or initialised on that frame).
    pub frames_both_tracking: u64,
    /// Frames where both lanes had coefficients (tracking or coasting).
    pub frames_both_reported: u64,
    /// Median over frames and lanes of |x(t) − x(t−1)| at the scoring row, px.
    pub median_bottom_change_px: f64,
    /// Largest such change, px.
    pub max_bottom_change_px: f64,
    /// Successful (re-)initialisations, both lanes, the first ones included.
    pub initialisations: u64,
}

/// Continuity of the reported lanes at `row_px` (e.g. the bottom row).
pub fn continuity(reports: &[Option<TrackReport>], row_px: f64) -> ContinuityScore {
    let mut changes: Vec<f64> = Vec::with_capacity(2 * reports.len());
    let mut s = ContinuityScore::default();
    let mut prev: [Option<f64>; 2] = [None, None];
    for r in reports.iter().flatten() {
        s.frames += 1;
        if r.lanes.iter().all(|l| l.state == LaneState::Tracking) {
            s.frames_both_tracking += 1;
        }
        if r.lanes.iter().all(|l| l.coeffs.is_some()) {
            s.frames_both_reported += 1;
        }
        for (k, lane) in r.lanes.iter().enumerate() {
            if lane.initialised {
                s.initialisations += 1;
            }
            let x = lane.col_at_row(row_px);
            if let (Some(a), Some(b)) = (prev[k], x) {
                changes.push((b - a).abs());
            }
            prev[k] = x;
        }
    }
    changes.sort_by(f64::total_cmp);
    s.median_bottom_change_px = changes.get(changes.len() / 2).copied().unwrap_or(0.0);
    s.max_bottom_change_px = changes.last().copied().unwrap_or(0.0);
    s
}

/// TuSimple-style score of one labelled still frame (lanenet): the tracker's initialisation
/// (gradient → Hough → LS on a fresh tracker) against the two ego lanes of an instance label
/// image (one grey level per lane, 0 = background).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct LabelScore {
    /// Ground-truth points scored (rows of the two ego lanes where they are labelled).
    pub points: u64,
    /// Points within [`tusimple_tolerance_px`].
    pub correct: u64,
    /// `correct / points`.
    pub accuracy: f64,
    /// Mean |x_reported − x_label| over the points of reported lanes, px.
    pub mean_error_px: f64,
}

/// Score `report` against `label` (`width × height` instance image). Rows are scored every
/// `row_step_px` from `first_row_px` down (TuSimple: 160, 170, … on 720-row frames); the label x
/// of a lane at a row is the mean column of its pixels there. The ego lanes are, on each side of
/// the image centre, the labelled lane whose pixels in the lower 40 % of the frame lie nearest it.
pub fn score_against_instance_label(
    report: &TrackReport,
    label: &GreyFrame,
    first_row_px: usize,
    row_step_px: usize,
) -> LabelScore {
    let (w, h) = (label.width(), label.height());
    let tol = tusimple_tolerance_px(w);
    // Per instance grey level: mean column of its pixels in the lower 40 % of the frame (lanes
    // that end higher up are not ego lanes).
    let mut sums = [(0.0f64, 0u64); 256];
    for y in (h * 3 / 5)..h {
        for (x, &v) in label.data()[y * w..(y + 1) * w].iter().enumerate() {
            if v != 0 {
                sums[usize::from(v)].0 += x as f64;
                sums[usize::from(v)].1 += 1;
            }
        }
    }
    let centre = w as f64 / 2.0;
    type Ego = Option<(u8, f64)>;
    let (mut left, mut right): (Ego, Ego) = (None, None);
    for (v, &(sx, n)) in sums.iter().enumerate().skip(1) {
        if n == 0 {
            continue;
        }
        let x = sx / n as f64;
        let d = (x - centre).abs();
        let slot = if x < centre { &mut left } else { &mut right };
        if slot.is_none_or(|(_, best)| d < best) {
            *slot = Some((v as u8, d));
        }
    }
    let mut s = LabelScore::default();
    let (mut err_sum, mut err_n) = (0.0, 0u64);
    for (k, ego) in [left, right].iter().enumerate() {
        let Some((level, _)) = ego else { continue };
        let mut y = first_row_px;
        while y < h {
            let row = &label.data()[y * w..(y + 1) * w];
            let (mut sx, mut n) = (0.0, 0u32);
            for (x, &v) in row.iter().enumerate() {
                if v == *level {
                    sx += x as f64;
                    n += 1;
                }
            }
            if n > 0 {
                let x_label = sx / f64::from(n);
                s.points += 1;
                if let Some(x) = report.lanes[k].col_at_row(y as f64) {
                    let e = (x - x_label).abs();
                    err_sum += e;
                    err_n += 1;
                    if e <= tol {
                        s.correct += 1;
                    }
                }
            }
            y += row_step_px.max(1);
        }
    }
    s.accuracy = if s.points > 0 {
        s.correct as f64 / s.points as f64
    } else {
        0.0
    };
    s.mean_error_px = if err_n > 0 {
        err_sum / err_n as f64
    } else {
        f64::NAN
    };
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use lane_scenes::{SequenceTruth, TruthFrame, TruthLane};
    use lane_tracker::{LaneReport, Side, TrackReport};

    fn truth(frames: usize, visible: impl Fn(usize) -> bool) -> SequenceTruth {
        let lane = |v, a3| TruthLane {
            visible: v,
            coeffs: [0.001, -0.5, a3],
        };
        SequenceTruth {
            name: "t".into(),
            description: String::new(),
            config: "outdoor".into(),
            width: 320,
            height: 240,
            eval_rows: vec![150.0, 200.0, 239.0],
            frames: (0..frames)
                .map(|f| TruthFrame {
                    frame: f as u64,
                    lanes: [lane(visible(f), 100.0), lane(visible(f), 250.0)],
                })
                .collect(),
        }
    }

    fn report(dx: f64, tracked: bool) -> TrackReport {
        let lane = |side, a3: f64| LaneReport {
            side,
            state: if tracked {
                LaneState::Tracking
            } else {
                LaneState::Lost
            },
            coeffs: tracked.then_some([0.001, -0.5, a3 + dx]),
            rows: [150.0, 239.0],
            points: 100,
            initialised: false,
            far: None,
        };
        TrackReport {
            lanes: [lane(Side::Left, 100.0), lane(Side::Right, 250.0)],
            full_gradient: false,
            road: lane_tracker::RoadReport {
                bottom_row_px: 240.0,
                search_rows_px: [148.0, 240.0],
                horizon_row_px: None,
                refused: None,
            },
        }
    }

    #[test]
    fn a_perfect_run_scores_zero_error_and_full_accuracy() {
        let t = truth(5, |_| true);
        let s = score_sequence(&t, &vec![Some(report(0.0, true)); 5]);
        assert_eq!(s.mean_lateral_error_px, 0.0);
        assert_eq!(s.accuracy, 1.0);
        assert_eq!(s.max_recovery_frames, 0);
        assert_eq!(tusimple_tolerance_px(320), 5.0);
    }

    #[test]
    fn a_constant_offset_is_the_lateral_error_and_the_tolerance_decides_accuracy() {
        let t = truth(4, |_| true);
        let s = score_sequence(&t, &vec![Some(report(3.0, true)); 4]);
        assert!((s.mean_lateral_error_px - 3.0).abs() < 1e-9);
        assert_eq!(s.accuracy, 1.0, "3 px < 5 px tolerance at 320 px");
        let s = score_sequence(&t, &vec![Some(report(-6.0, true)); 4]);
        assert!((s.mean_lateral_error_px - 6.0).abs() < 1e-9);
        assert_eq!(s.accuracy, 0.0, "6 px > 5 px tolerance");
    }

    #[test]
    fn missing_reports_lower_accuracy_and_recovery_counts_frames_after_reappearance() {
        // Visible, invisible on frames 2..4, visible again from 4; tracked again from frame 6.
        let t = truth(8, |f| !(2..4).contains(&f));
        let reps: Vec<_> = (0..8)
            .map(|f| Some(report(0.0, !(4..6).contains(&f))))
            .collect();
        let s = score_sequence(&t, &reps);
        assert_eq!(s.missed_lane_frames, 4, "frames 4 and 5, two lanes");
        assert_eq!(
            s.false_lane_frames, 4,
            "frames 2 and 3 reported while invisible"
        );
        assert_eq!(s.max_recovery_frames, 2);
        assert!((s.accuracy - 4.0 / 6.0).abs() < 1e-12);
    }

    #[test]
    fn continuity_measures_frame_to_frame_bottom_row_changes() {
        let reps: Vec<_> = [0.0, 1.0, 3.0, 3.0]
            .iter()
            .map(|&dx| Some(report(dx, true)))
            .collect();
        let c = continuity(&reps, 239.0);
        assert_eq!(c.frames, 4);
        assert_eq!(c.frames_both_reported, 4);
        // Changes per lane: 1, 2, 0 → sorted over both lanes 0,0,1,1,2,2.
        assert_eq!(c.median_bottom_change_px, 1.0);
        assert_eq!(c.max_bottom_change_px, 2.0);
    }

    #[test]
    fn label_scoring_picks_the_ego_lanes_and_counts_points_within_tolerance() {
        // 1280×720 label: ego lanes at x = 400 and 900 (vertical, grey 10 and 20), an outer lane
        // at 100 (grey 30) that must not be chosen.
        let (w, h) = (1280usize, 720usize);
        let mut label = GreyFrame::new(w, h);
        for y in 300..h {
            for (x, v) in [(400usize, 10u8), (900, 20), (100, 30)] {
                label.data_mut()[y * w + x] = v;
                label.data_mut()[y * w + x + 1] = v;
            }
        }
        let lane = |side, a3: f64| LaneReport {
            side,
            state: LaneState::Tracking,
            coeffs: Some([0.0, 0.0, a3]),
            rows: [300.0, 719.0],
            points: 100,
            initialised: true,
            far: None,
        };
        // Left lane 10 px off (correct at 20 px tolerance), right lane 30 px off (wrong).
        let r = TrackReport {
            lanes: [lane(Side::Left, 410.5), lane(Side::Right, 930.5)],
            full_gradient: true,
            road: lane_tracker::RoadReport {
                bottom_row_px: 240.0,
                search_rows_px: [148.0, 240.0],
                horizon_row_px: None,
                refused: None,
            },
        };
        let s = score_against_instance_label(&r, &label, 300, 10);
        assert_eq!(s.points, 2 * 42);
        assert_eq!(s.correct, 42);
        assert!((s.accuracy - 0.5).abs() < 1e-12);
        assert!((s.mean_error_px - 20.0).abs() < 1e-9);
    }
}
