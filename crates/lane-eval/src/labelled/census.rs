//! Where the ego label lanes are lost, stage by stage: a diagnostic for tuning the
//! initialisation (`cargo xtask eval-lanes --census`).
//!
//! On a frame where the tracker ran its joint initialisation, every scored ego label lane is put
//! in exactly one of five classes, by the TuSimple rule of [`super::score_frame`] (a lane is
//! matched when ≥ 85 % of its scored points are within the tolerance):
//!
//! 1. **matched** by the tracker's output lane of its side;
//! 2. **no candidate** matched it: none of the Hough candidate lines
//!    ([`lane_tracker::LaneTracker::init_candidates`], their least-squares parabolas, either
//!    angle band) — the edge evidence or the vote is missing;
//! 3. **not chosen**: a candidate matched it, but the one the ego-pair choice gave its side did
//!    not (or the choice left the side empty);
//! 4. **lost after the choice**: the chosen candidate matched it, the output does not (the
//!    least-squares refit, the windowed refinement or a gate moved or dropped it);
//!
//! and, among the matched ones, those **found by the refinement**: matched by the output but not
//! by the chosen candidate (the windows corrected a candidate that was off). A label lane whose
//! side kept the estimate tracked from the previous frame of its clip, or on a frame without a
//! joint initialisation (both lanes tracked, or the paper's one line per band,
//! `init.candidate_lines = 0`), is only counted as **not classified**.

use std::ops::Range;
use std::path::Path;

use serde::{Deserialize, Serialize};

use lane_tracker::{Estimator, Side, TrackerConfig};

use super::{
    LabelSet, LabelSide, ScoringRules, run_label_set, scored_points, tusimple_lane_accuracy,
};
use crate::EvalError;

/// Counts of scored ego label lanes by the stage where they are lost (module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct StageCensus {
    /// Scored ego label lanes classified: on a side the joint initialisation ran for (whether or
    /// not it found candidates).
    pub label_lanes: u64,
    /// Matched by the tracker's output.
    pub matched: u64,
    /// … of which the chosen candidate alone did not match (found by the refinement).
    pub found_by_refinement: u64,
    /// Not matched, and no Hough candidate matched either.
    pub no_candidate: u64,
    /// Not matched; a candidate matched but not the one chosen for the side.
    pub not_chosen: u64,
    /// Not matched; the chosen candidate matched.
    pub lost_after_choice: u64,
    /// Scored ego label lanes on a side that kept its tracked estimate, or on a frame without a
    /// joint initialisation (`init.candidate_lines = 0`): not classified.
    pub not_classified: u64,
}

impl StageCensus {
    /// Add another census.
    pub fn add(&mut self, o: &StageCensus) {
        self.label_lanes += o.label_lanes;
        self.matched += o.matched;
        self.found_by_refinement += o.found_by_refinement;
        self.no_candidate += o.no_candidate;
        self.not_chosen += o.not_chosen;
        self.lost_after_choice += o.lost_after_choice;
        self.not_classified += o.not_classified;
    }
}

/// The census of the frames at positions `frames` (in set order) of a labelled set, the tracker
/// run as [`super::track_label_set`] runs it (clip by clip, from the first frame of each clip).
///
/// # Errors
/// As [`super::track_label_set`]: a frame that cannot be read or has another size than the set
/// declares, or a configuration the tracker refuses.
pub fn census_set(
    dir: &Path,
    set: &LabelSet,
    cfg: &TrackerConfig,
    estimator: Estimator,
    frames: Range<usize>,
    rules: &ScoringRules,
) -> Result<StageCensus, EvalError> {
    let mut census = StageCensus::default();
    let y_top = rules.eval_top_fraction * set.height as f64;
    let tus_px = rules.tusimple_px_at_1280 * set.width as f64 / 1280.0;
    let joint = cfg.init.candidate_lines > 0;
    run_label_set(
        dir,
        set,
        cfg,
        estimator,
        frames.end,
        |position, labels, tracker, report| {
            if !frames.contains(&position) {
                return;
            }
            let candidates = tracker.init_candidates();
            for (k, (label_side, side)) in [
                (LabelSide::Left, Side::Left),
                (LabelSide::Right, Side::Right),
            ]
            .into_iter()
            .enumerate()
            {
                let pts = scored_points(labels, label_side, y_top);
                if pts.len() < 2 {
                    continue;
                }
                // Classified: a side the joint initialisation ran for on this frame (installed
                // now, or left without an estimate); a side that kept its tracked estimate is not.
                let lane = &report.lanes[k];
                let initialised_for = lane.initialised || lane.coeffs.is_none();
                if !(report.full_gradient && joint && initialised_for) {
                    census.not_classified += 1;
                    continue;
                }
                census.label_lanes += 1;
                let matches = |c: [f64; 3]| {
                    tusimple_lane_accuracy(&pts, c, tus_px, &mut 0.0)
                        >= rules.tusimple_match_fraction
                };
                let output = report.lanes[k].coeffs.is_some_and(matches);
                let chosen = candidates
                    .iter()
                    .any(|c| c.chosen == Some(side) && matches(c.coeffs));
                if output {
                    census.matched += 1;
                    census.found_by_refinement += u64::from(!chosen);
                } else if chosen {
                    census.lost_after_choice += 1;
                } else if candidates.iter().any(|c| matches(c.coeffs)) {
                    census.not_chosen += 1;
                } else {
                    census.no_candidate += 1;
                }
            }
        },
    )?;
    Ok(census)
}
