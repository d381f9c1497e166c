//! The **full rule**: the TuSimple benchmark's own rule, on every labelled row.
//!
//! The near band ([`super::score_side`]) scores only the label points below
//! `eval_top_fraction · height` and evaluates a prediction's parabola on each of them, however
//! far the tracker saw the lane. The full rule scores **every labelled row** of each ego label
//! lane (at least 2 points; fewer: neither the label nor a prediction on its side is scored):
//!
//! - the tolerance is TuSimple's, slope-corrected: `t = t₀·W/1280 / cos α`, `t₀ = 20 px`, `W`
//!   the image width and `α = atan k`, `k` the slope `dx/dy` of the least-squares line `x(y)`
//!   through all the lane's label points (the benchmark's `get_angle`);
//! - a label point `(x, y)` is correct when the prediction **reaches** its row — `y` within the
//!   prediction's row extent `[top, bottom]` ([`super::PredictedLane::rows_px`]) widened by
//!   `reach_px` at either end — and `|x_pred(y) − x| ≤ t`. A row the prediction does not reach
//!   is a wrong point: a tracker that reports a lane over the near field only is not credited
//!   with the far rows its parabola happens to cross;
//! - a label lane's accuracy is its fraction of correct points (0 with no prediction), matched
//!   at ≥ `tusimple_match_fraction` (0.85); accuracy = mean over label lanes, FP = unmatched
//!   predictions / predictions (a prediction on a side without a label lane is one), FN =
//!   unmatched label lanes / label lanes: as the near band counts them.
//!
//! `reach_px` is half a pixel of the tracker's working frame, `0.5·s` input pixels (`s` the
//! working scale, [`lane_tracker::LaneTracker::working_scale`]; 0.5 px at 320 px): the
//! reported extent is the rows of the points behind the estimate, pixel centres, so a label
//! row within half a working pixel of the extreme rows lies on a row the tracker read.
//! [`REACH_WORKING_PX`] holds it.
//!
//! Two departures from TuSimple's script, both kept from the near band: a point exactly at the
//! tolerance is correct (`≤`, the script has `<`); and only labelled rows count (the script
//! also counts as correct a sampled row where neither label nor prediction has a point).

use serde::{Deserialize, Serialize};

use super::{EgoPrediction, LabelFrame, LabelSide, PredictedLane, ScoringRules, fit_slope};

/// The full rule's reach tolerance, in pixels of the tracker's working frame (module docs).
pub const REACH_WORKING_PX: f64 = 0.5;

/// Totals of the full rule over one frame, one set or all sets (pooled counts).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct FullTotals {
    /// Frames scored.
    pub frames: u64,
    /// Label ego lanes scored.
    pub label_lanes: u64,
    /// Predictions scored.
    pub predicted_lanes: u64,
    /// Sum over label lanes of their point accuracy.
    pub acc_sum: f64,
    /// Label lanes matched.
    pub matched: u64,
    /// Label points of predicted lanes.
    pub points: u64,
    /// Those on rows their prediction does not reach.
    pub unreached_points: u64,
}

impl FullTotals {
    /// Add another total.
    pub fn add(&mut self, o: &FullTotals) {
        self.frames += o.frames;
        self.label_lanes += o.label_lanes;
        self.predicted_lanes += o.predicted_lanes;
        self.acc_sum += o.acc_sum;
        self.matched += o.matched;
        self.points += o.points;
        self.unreached_points += o.unreached_points;
    }

    /// The rates.
    pub fn summary(&self) -> FullRates {
        let ratio = |a: f64, b: u64| if b > 0 { a / b as f64 } else { 0.0 };
        FullRates {
            frames: self.frames,
            label_lanes: self.label_lanes,
            predicted_lanes: self.predicted_lanes,
            tusimple_accuracy: ratio(self.acc_sum, self.label_lanes),
            tusimple_fp: ratio(
                self.predicted_lanes.saturating_sub(self.matched) as f64,
                self.predicted_lanes,
            ),
            tusimple_fn: ratio(
                self.label_lanes.saturating_sub(self.matched) as f64,
                self.label_lanes,
            ),
            unreached_fraction: ratio(self.unreached_points as f64, self.points),
        }
    }
}

/// Rates of a [`FullTotals`] (fractions in [0, 1]).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct FullRates {
    /// Frames scored.
    pub frames: u64,
    /// Label ego lanes scored.
    pub label_lanes: u64,
    /// Predictions scored.
    pub predicted_lanes: u64,
    /// Mean over label lanes of the fraction of correct points.
    pub tusimple_accuracy: f64,
    /// Unmatched predictions / predictions.
    pub tusimple_fp: f64,
    /// Unmatched label lanes / label lanes.
    pub tusimple_fn: f64,
    /// Of the label points of predicted lanes, the fraction on rows their prediction does not
    /// reach (each a wrong point).
    pub unreached_fraction: f64,
}

/// Score one frame's ego prediction under the full rule (module docs); `reach_px` is the
/// tolerance on the prediction's row extent, input pixels.
pub fn score_frame_full(
    labels: &LabelFrame,
    width: usize,
    prediction: &EgoPrediction,
    rules: &ScoringRules,
    reach_px: f64,
) -> FullTotals {
    let mut t = FullTotals {
        frames: 1,
        ..FullTotals::default()
    };
    for (side, p) in [LabelSide::Left, LabelSide::Right]
        .into_iter()
        .zip(prediction)
    {
        t.add(&score_side_full(labels, width, side, *p, rules, reach_px));
    }
    t
}

/// One ego side of a frame under the full rule (`frames` 0).
fn score_side_full(
    labels: &LabelFrame,
    width: usize,
    side: LabelSide,
    prediction: Option<PredictedLane>,
    rules: &ScoringRules,
    reach_px: f64,
) -> FullTotals {
    let mut t = FullTotals::default();
    let pts: Vec<[f64; 2]> = labels
        .lanes
        .iter()
        .filter(|l| l.side == side)
        .flat_map(|l| l.points.iter().copied())
        .collect();
    let labelled = !pts.is_empty();
    if labelled && pts.len() < 2 {
        return t;
    }
    t.predicted_lanes = u64::from(prediction.is_some());
    if !labelled {
        return t;
    }
    t.label_lanes = 1;
    let Some(p) = prediction else { return t };
    let tol_px = rules.tusimple_px_at_1280 * width as f64 / 1280.0 / fit_slope(&pts).atan().cos();
    let mut correct = 0u64;
    for &[x, y] in &pts {
        if !p.reaches(y, reach_px) {
            t.unreached_points += 1;
        } else if (p.col_at_row(y) - x).abs() <= tol_px {
            correct += 1;
        }
    }
    t.points = pts.len() as u64;
    let acc = correct as f64 / pts.len() as f64;
    t.acc_sum = acc;
    t.matched = u64::from(acc >= rules.tusimple_match_fraction);
    t
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::labelled::LabelLane;

    /// A frame with a vertical left label `x = 100` on rows 20..240 (one point a row).
    fn frame() -> LabelFrame {
        LabelFrame {
            index: 0,
            file: String::new(),
            clip: "c".into(),
            lanes: vec![LabelLane {
                side: LabelSide::Left,
                points: (20..240).map(|y| [100.0, f64::from(y)]).collect(),
            }],
        }
    }

    fn lane(rows_px: [f64; 2]) -> Option<PredictedLane> {
        Some(PredictedLane {
            coeffs: [0.0, 0.0, 100.0],
            rows_px,
            far: None,
        })
    }

    #[test]
    fn every_labelled_row_counts_and_rows_the_prediction_does_not_reach_are_wrong() {
        let rules = ScoringRules::default();
        let f = frame();
        // Reaching every labelled row: all correct, matched.
        let t = score_frame_full(&f, 320, &[lane([20.0, 239.0]), None], &rules, 0.5);
        assert_eq!((t.label_lanes, t.predicted_lanes, t.matched), (1, 1, 1));
        assert_eq!(t.acc_sum, 1.0);
        assert_eq!(t.unreached_points, 0);
        // Reaching rows 130..239 only: the 110 rows above are wrong although the parabola
        // lies on them; 50 % correct, not matched, so a false positive and a false negative.
        let t = score_frame_full(&f, 320, &[lane([130.0, 239.0]), None], &rules, 0.5);
        assert_eq!(t.unreached_points, 110);
        assert!((t.acc_sum - 0.5).abs() < 1e-12, "{t:?}");
        let r = t.summary();
        assert_eq!((r.tusimple_fp, r.tusimple_fn), (1.0, 1.0));
        assert!((r.unreached_fraction - 0.5).abs() < 1e-12);
        // The reach tolerance: row 129 is 0.5 px above an extent starting at 129.5.
        let t = score_frame_full(&f, 320, &[lane([129.5, 239.0]), None], &rules, 0.5);
        assert_eq!(t.unreached_points, 109);
        let t = score_frame_full(&f, 320, &[lane([129.5, 239.0]), None], &rules, 0.4);
        assert_eq!(t.unreached_points, 110);
        // The near band scores the same short prediction as perfect (rows ≥ 144 only).
        let near =
            crate::labelled::score_frame(&f, 320, 240, &[lane([130.0, 239.0]), None], &rules);
        assert_eq!(near.tusimple_matched, 1);
    }

    #[test]
    fn the_far_segment_is_read_above_the_row_it_joins_at() {
        // The label is x = 100 on rows 20..239. A near parabola on it and a far segment 30 px
        // off above row 130: the far rows are wrong; the same far segment on the label: right.
        let rules = ScoringRules::default();
        let f = frame();
        let with_far = |far_a3: f64| PredictedLane {
            coeffs: [0.0, 0.0, 100.0],
            rows_px: [20.0, 239.0],
            far: Some(([0.0, 0.0, far_a3], 130.0)),
        };
        let off = score_frame_full(&f, 320, &[Some(with_far(130.0)), None], &rules, 0.5);
        assert!((off.acc_sum - 0.5).abs() < 1e-12, "{off:?}");
        let on = score_frame_full(&f, 320, &[Some(with_far(100.0)), None], &rules, 0.5);
        assert_eq!(on.acc_sum, 1.0);
        // The near band never reads it.
        let near =
            crate::labelled::score_frame(&f, 320, 240, &[Some(with_far(130.0)), None], &rules);
        assert_eq!(near.tusimple_matched, 1);
    }

    #[test]
    fn the_tolerance_is_slope_corrected_from_the_whole_label() {
        // A 45° label x = y: 5 px at 320 px, / cos 45° = 7.07 px.
        let mut f = frame();
        f.lanes[0].points = (20..240).map(|y| [f64::from(y), f64::from(y)]).collect();
        let rules = ScoringRules::default();
        let at = |offset: f64| {
            let p = PredictedLane {
                coeffs: [0.0, 1.0, offset],
                rows_px: [0.0, 239.0],
                far: None,
            };
            score_frame_full(&f, 320, &[Some(p), None], &rules, 0.5).matched
        };
        assert_eq!((at(7.0), at(7.2)), (1, 0));
    }

    #[test]
    fn sides_without_labels_give_false_positives_and_single_points_are_not_scored() {
        let rules = ScoringRules::default();
        let f = frame();
        let t = score_frame_full(&f, 320, &[None, lane([0.0, 239.0])], &rules, 0.5);
        assert_eq!((t.label_lanes, t.predicted_lanes, t.matched), (1, 1, 0));
        assert_eq!(t.summary().tusimple_fp, 1.0);
        let mut one = frame();
        one.lanes[0].points.truncate(1);
        let t = score_frame_full(&one, 320, &[lane([0.0, 239.0]), None], &rules, 0.5);
        assert_eq!((t.frames, t.label_lanes, t.predicted_lanes), (1, 0, 0));
    }
}
