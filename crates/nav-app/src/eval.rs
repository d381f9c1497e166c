//! Scoring a tracker run against ground truth: lateral error at fixed rows, a TuSimple-style
//! accuracy, recovery time after the lanes reappear, initialisation count.

use serde::{Deserialize, Serialize};

use crate::synth::SequenceTruth;
use crate::{LaneState, TrackReport};

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
            if let Some(start) = waiting_since {
                if frame_ok as f64 >= 0.9 * n_rows as f64 {
                    max_recovery = max_recovery.max(i as u64 - start);
                    waiting_since = None;
                }
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
