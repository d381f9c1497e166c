//! What a perfect choice among the tracker's own candidates would reach (`cargo xtask
//! eval-lanes`, the *best of its candidates* row): a bound that tells the choice's losses from
//! the detection's.
//!
//! On every frame the tracker runs as [`super::track_label_set`] runs it; then, per ego side,
//! the prediction is whichever of the tracker's output lane and the frame's Hough candidates
//! ([`lane_tracker::LaneTracker::init_candidates`]: their least-squares parabolas, either angle
//! band, as the choice weighed them) scores the highest TuSimple point accuracy against that
//! side's scored label lane — the output where none beats it (no lane counts as accuracy 0),
//! so the bound's accuracy is never below the tracker's. A side with no scored label keeps the
//! output. The labels pick, as for the ceiling:
//! an upper bound of any rule that chooses among these candidates (and of a refinement that only
//! improves its pick), not a result.

use std::path::Path;

use lane_tracker::{Estimator, TrackerConfig};

use super::{
    EgoPrediction, LabelSet, LabelSide, ScoringRules, run_label_set, scored_points,
    tusimple_lane_accuracy,
};
use crate::EvalError;

/// The bound's prediction for every frame of a labelled set, in set order (module docs).
///
/// # Errors
/// As [`super::track_label_set`]: a frame that cannot be read or has another size than the set
/// declares, or a configuration the tracker refuses.
pub fn choice_bound_set(
    dir: &Path,
    set: &LabelSet,
    cfg: &TrackerConfig,
    estimator: Estimator,
    rules: &ScoringRules,
) -> Result<Vec<EgoPrediction>, EvalError> {
    let y_top = rules.eval_top_fraction * set.height as f64;
    let tus_px = rules.tusimple_px_at_1280 * set.width as f64 / 1280.0;
    let mut out = Vec::with_capacity(set.frames.len());
    run_label_set(
        dir,
        set,
        cfg,
        estimator,
        set.frames.len(),
        |_, labels, tracker, report, _| {
            let mut prediction: EgoPrediction = [report.lanes[0].coeffs, report.lanes[1].coeffs];
            for (k, side) in [LabelSide::Left, LabelSide::Right].into_iter().enumerate() {
                let pts = scored_points(labels, side, y_top);
                if pts.len() < 2 {
                    continue;
                }
                let accuracy = |c: [f64; 3]| tusimple_lane_accuracy(&pts, c, tus_px, &mut 0.0);
                let mut best = prediction[k].map_or(0.0, accuracy);
                for c in tracker.init_candidates() {
                    let a = accuracy(c.coeffs);
                    if a > best {
                        best = a;
                        prediction[k] = Some(c.coeffs);
                    }
                }
            }
            out.push(prediction);
            Ok(())
        },
    )?;
    Ok(out)
}
