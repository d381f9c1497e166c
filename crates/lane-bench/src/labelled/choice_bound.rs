//! What a perfect choice among the tracker's own candidates would reach (`nav-app
//! eval-lanes`, the *best of its candidates* rows): a bound that tells the choice's losses from
//! the detection's.
//!
//! On every frame the tracker runs as [`super::track_label_set`] runs it; then, per ego side,
//! the **best** prediction is whichever of the tracker's output lane and the frame's Hough
//! candidates ([`lane_tracker::LaneTracker::init_candidates`]: their least-squares parabolas,
//! either angle band, as the choice weighed them) scores the highest TuSimple point accuracy
//! against that side's scored label lane — the output where none beats it (no lane counts as
//! accuracy 0), so the bound's accuracy is never below the tracker's. A side with no scored
//! label keeps the output. **Best or none** also reports nothing where that best lane has fewer
//! than [`super::NEAR_MISS_FRACTION`] of its label's points within the tolerance (a perfect
//! rejection of far lanes on top of a perfect choice). The labels pick, as for the ceiling:
//! upper bounds of any rule that chooses among these candidates (and of a refinement that only
//! improves its pick), not results.

use std::path::Path;

use lane_tracker::{Estimator, TrackerConfig};

use super::{
    EgoPrediction, LabelSet, LabelSide, NEAR_MISS_FRACTION, ScoringRules, run_label_set,
    scored_points, tusimple_lane_accuracy,
};
use crate::BenchError;

/// One run of the tracker over a labelled set, with the bounds of its choice (module docs); each
/// in set order.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ChoiceBound {
    /// The tracker's own output ([`super::track_label_set`]'s).
    pub output: Vec<EgoPrediction>,
    /// Per side, the best of the output and the candidates.
    pub best: Vec<EgoPrediction>,
    /// `best`, without the lanes below [`NEAR_MISS_FRACTION`] of their label's points.
    pub best_or_none: Vec<EgoPrediction>,
    /// The frames that could not be tracked (`[None, None]` in the three lists).
    pub skipped: Vec<super::SkippedFrame>,
}

/// The tracker's output and the bounds of its choice for every frame of a labelled set (module
/// docs), from one run.
///
/// # Errors
/// A configuration the tracker refuses (a frame that cannot be read or has another size than
/// the set declares is skipped and listed, as by [`super::track_label_set`]).
pub fn choice_bound_set(
    dir: &Path,
    set: &LabelSet,
    cfg: &TrackerConfig,
    estimator: Estimator,
    rules: &ScoringRules,
) -> Result<ChoiceBound, BenchError> {
    let y_top = rules.eval_top_fraction * set.height as f64;
    let tus_px = rules.tusimple_px_at_1280 * set.width as f64 / 1280.0;
    let n = set.frames.len();
    let mut out = ChoiceBound {
        output: Vec::with_capacity(n),
        best: Vec::with_capacity(n),
        best_or_none: Vec::with_capacity(n),
        skipped: Vec::new(),
    };
    out.skipped = run_label_set(dir, set, cfg, estimator, n, |_, labels, tracked| {
        let Some(t) = tracked else {
            // A skipped frame: no output, nothing to choose from.
            out.output.push([None, None]);
            out.best.push([None, None]);
            out.best_or_none.push([None, None]);
            return Ok(());
        };
        let (tracker, report) = (t.tracker, &t.report);
        let output: EgoPrediction = [report.lanes[0].coeffs, report.lanes[1].coeffs];
        let (mut best, mut best_or_none) = (output, output);
        for (k, side) in [LabelSide::Left, LabelSide::Right].into_iter().enumerate() {
            let pts = scored_points(labels, side, y_top);
            if pts.len() < 2 {
                continue;
            }
            let accuracy = |c: [f64; 3]| tusimple_lane_accuracy(&pts, c, tus_px, &mut 0.0);
            let mut top = output[k].map_or(0.0, accuracy);
            for c in tracker.init_candidates() {
                let a = accuracy(c.coeffs);
                if a > top {
                    top = a;
                    best[k] = Some(c.coeffs);
                }
            }
            best_or_none[k] = best[k].filter(|_| top >= NEAR_MISS_FRACTION);
        }
        out.output.push(output);
        out.best.push(best);
        out.best_or_none.push(best_or_none);
        Ok(())
    })?;
    Ok(out)
}
