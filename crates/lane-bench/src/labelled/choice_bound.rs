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
//!
//! **Row extents** (what the full rule, [`super::full_rule`], scores a lane's reach by): the
//! output's lanes carry the tracker's own (the rows of the points behind each estimate); a
//! candidate carries the rows of the search that found it, `[top, bottom − 1]` of the region
//! searched, in input pixels. A candidate ([`lane_tracker::InitCandidate`]) does not say which
//! of the joint initialisation's two searches found it — the ROI's rows or, with
//! `roi.fallback_top_row_fraction`, the taller rows of the second search — so every candidate
//! gets the taller extent when there is a second search: generous to the ROI's candidates,
//! which keeps the bound a bound.

use std::path::Path;

use lane_tracker::{Estimator, TrackerConfig};

use super::{
    EgoPrediction, LabelSet, LabelSide, NEAR_MISS_FRACTION, PredictedLane, ScoringRules,
    run_label_set, scored_points, tusimple_lane_accuracy,
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
    let y_top = super::near_top_px(rules, set.height);
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
        let output: EgoPrediction = super::run::ego_of(&t.report);
        let (best, best_or_none) = best_of_candidates(t.tracker, &output, labels, y_top, tus_px);
        out.output.push(output);
        out.best.push(best);
        out.best_or_none.push(best_or_none);
        Ok(())
    })?;
    Ok(out)
}

/// Per side, the best of `output` and `tracker`'s candidates against `labels`' points below
/// `y_top` (TuSimple point accuracy at `tus_px`), and that best without the lanes under
/// [`NEAR_MISS_FRACTION`]: the [`ChoiceBound`]'s `best` and `best_or_none` of one frame
/// (module docs). A side with fewer than two scored label points keeps the output.
pub(crate) fn best_of_candidates(
    tracker: &lane_tracker::LaneTracker,
    output: &EgoPrediction,
    labels: &super::LabelFrame,
    y_top: f64,
    tus_px: f64,
) -> (EgoPrediction, EgoPrediction) {
    let searched = candidate_rows_px(tracker);
    let (mut best, mut best_or_none) = (*output, *output);
    for (k, side) in [LabelSide::Left, LabelSide::Right].into_iter().enumerate() {
        let pts = scored_points(labels, side, y_top);
        if pts.len() < 2 {
            continue;
        }
        let accuracy = |c: [f64; 3]| tusimple_lane_accuracy(&pts, c, tus_px, &mut 0.0);
        let mut top = output[k].map_or(0.0, |p| accuracy(p.coeffs));
        for c in tracker.init_candidates() {
            let a = accuracy(c.coeffs);
            if a > top {
                top = a;
                best[k] = Some(PredictedLane {
                    coeffs: c.coeffs,
                    rows_px: searched,
                    far: None,
                });
            }
        }
        best_or_none[k] = best[k].filter(|_| top >= NEAR_MISS_FRACTION);
    }
    (best, best_or_none)
}

/// The row extent given to `tracker`'s candidates (module docs): `[top, bottom − 1]` of the
/// taller rows of the second search when the configuration has one, else of the ROI, input
/// pixels.
fn candidate_rows_px(tracker: &lane_tracker::LaneTracker) -> [f64; 2] {
    let (roi_top, roi_bottom) = tracker.roi_rows();
    let top = tracker
        .second_search_rows()
        .map_or(roi_top, |(top, _)| top.min(roi_top));
    [top as f64, roi_bottom.saturating_sub(1) as f64]
}
