//! Real labelled frames (`<data root>/lanes/<set>/labels.json`, schema 1, documented in
//! `fixtures/real/README.md`; the data itself stays outside the repository) and the standard lane
//! scoring rules, ego lanes only.
//!
//! ## The label format
//! One directory per set: `labels.json` and `frames/NNNN.png` (8-bit grey). `labels.json`:
//!
//! ```text
//! { "schema": 1, "set": "…", "kind": "road" | "indoor", "source": "owner/repo (path)",
//!   "licence": "…", "width": 320, "height": 180,
//!   "frames": [ { "index": 0, "file": "frames/0000.png", "clip": "c01",
//!                 "lanes": [ { "side": "left" | "right" | "other",
//!                              "points": [[x_px, y_px], …] } ] } ] }
//! ```
//!
//! Points are in the stored image's pixels (x column, y row), sorted by increasing row. `left` and
//! `right` are the two boundaries of the ego lane; frames with one `clip` id are consecutive video
//! frames, run through one tracker in index order (the tracker is reset between clips).
//!
//! Sets labelled in TuSimple's or CULane's format are read into this schema by [`import`]
//! (`nav-app import-lanes`, [`crate::import_set`]).
//!
//! ## The rules ([`ScoringRules`])
//! Only the ego lanes are scored, each against the tracker's lane of the same side. The label
//! points scored are those at or below the evaluation row `eval_top_fraction · height` (the near
//! field where a lane tracker works; rows above it are the far field near the horizon); a label
//! lane with fewer than 2 points there is not scored, nor is a prediction on its side.
//!
//! - **TuSimple** (Pan et al., the TuSimple lane benchmark): a point is correct when the
//!   prediction's column at its row is within `t = t₀·W/1280 / cos α` of it, with `t₀ = 20 px`, `W`
//!   the image width and `α` the angle from the vertical of the straight-line fit `x(y)` of the
//!   label points (the benchmark's own slope correction). A label lane's accuracy is its fraction
//!   of correct points (0 with no prediction); it is *matched* when that is ≥ 0.85. Accuracy =
//!   mean over scored label lanes; FP = unmatched predictions / predictions; FN = unmatched label
//!   lanes / label lanes.
//! - **Aly** (Caltech Lanes, Aly 2008): the distance of a label point to the predicted curve is
//!   its Euclidean distance to the nearest point of the prediction sampled on every row of the
//!   scored band (extended by the tolerance); a label lane is matched when the median distance
//!   over its points is ≤ `d₀·W/640` with `d₀ = 20 px`. Detection rate = matched label lanes /
//!   label lanes; false detections = unmatched predictions, per label lane.
//!
//! Both are pooled over the lanes of a set (and over all sets for the overall figure), so a set
//! weighs by its number of labelled lanes. These are the **near band**'s rules; the **full
//! rule** ([`full_rule`]) scores every labelled row with TuSimple's rule and counts a row the
//! prediction does not reach ([`PredictedLane::rows_px`]) as a wrong point.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::BenchError;
use crate::error::labels_json;

/// Which boundary a labelled lane is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum LabelSide {
    /// Left boundary of the ego lane.
    Left,
    /// Right boundary of the ego lane.
    Right,
    /// Any other marking.
    Other,
}

/// One labelled lane marking.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LabelLane {
    /// Which boundary.
    pub side: LabelSide,
    /// `[x_px, y_px]`, sorted by increasing row.
    pub points: Vec<[f64; 2]>,
}

/// One labelled frame.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LabelFrame {
    /// Index in the set (frames are run in this order).
    pub index: u64,
    /// Image file, relative to the set's directory; an absolute path is taken as it is (what
    /// [`import`]'s sets hold: the user's images stay where they are).
    pub file: String,
    /// Clip id: frames with one id are consecutive video frames.
    pub clip: String,
    /// The labelled markings.
    pub lanes: Vec<LabelLane>,
}

/// Scene kind of a set.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "lowercase")]
pub enum SceneKind {
    /// Roads (highway, urban).
    Road,
    /// Indoor floors, corridors, small-robot tracks.
    Indoor,
}

/// A labelled set as stored in `labels.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LabelSet {
    /// Format version (1).
    pub schema: u32,
    /// Set name.
    pub set: String,
    /// Scene kind.
    pub kind: SceneKind,
    /// Where the frames and labels come from.
    pub source: String,
    /// Licence of the source.
    pub licence: String,
    /// Frame width, px.
    pub width: usize,
    /// Frame height, px.
    pub height: usize,
    /// The frames, in run order.
    pub frames: Vec<LabelFrame>,
}

/// The label schema this reader takes.
pub const LABEL_SCHEMA: u32 = 1;

impl LabelSet {
    /// Read and check `dir/labels.json`: schema, sizes, sorted indices, points inside the frame
    /// and sorted by row. The error names the file and what is wrong.
    pub fn load(dir: &Path) -> Result<Self, BenchError> {
        let path = dir.join("labels.json");
        let text = std::fs::read_to_string(&path).map_err(|e| BenchError::io("read", &path, e))?;
        Self::from_json_str(&path.display().to_string(), &text)
    }

    /// Parse and check a `labels.json` text; `name` is used in errors.
    pub fn from_json_str(name: &str, text: &str) -> Result<Self, BenchError> {
        let bad = |reason: String| BenchError::Labels {
            path: name.to_owned(),
            reason,
        };
        let set: LabelSet = serde_json::from_str(text).map_err(|e| labels_json(name, &e))?;
        if set.schema != LABEL_SCHEMA {
            return Err(bad(format!(
                "schema {} (this reader takes {LABEL_SCHEMA})",
                set.schema
            )));
        }
        if set.width == 0 || set.height == 0 {
            return Err(bad(format!("zero frame size {}×{}", set.width, set.height)));
        }
        // Refused here, before anything is sized from it (the census's buffers, the tracker).
        let side_max = hough_init::MAX_IMAGE_SIDE_PX;
        if set.width > side_max || set.height > side_max {
            return Err(bad(format!(
                "frame size {}×{} above the tracker's {side_max} px a side",
                set.width, set.height
            )));
        }
        let mut last: Option<u64> = None;
        for f in &set.frames {
            if last.is_some_and(|l| f.index <= l) {
                return Err(bad(format!("frame index {} is not increasing", f.index)));
            }
            last = Some(f.index);
            for (k, lane) in f.lanes.iter().enumerate() {
                let mut prev_y = f64::NEG_INFINITY;
                for &[x, y] in &lane.points {
                    let inside = x.is_finite()
                        && y.is_finite()
                        && (-0.5..set.width as f64).contains(&x)
                        && (-0.5..set.height as f64).contains(&y);
                    if !inside {
                        return Err(bad(format!(
                            "frame {} lane {k}: point ({x}, {y}) outside the {}×{} frame",
                            f.index, set.width, set.height
                        )));
                    }
                    if y < prev_y {
                        return Err(bad(format!(
                            "frame {} lane {k}: points not sorted by row",
                            f.index
                        )));
                    }
                    prev_y = y;
                }
            }
        }
        Ok(set)
    }

    /// Path of a frame's image under the set directory `dir`.
    pub fn frame_path(dir: &Path, frame: &LabelFrame) -> PathBuf {
        dir.join(&frame.file)
    }

    /// Frames grouped into clips, each a run of consecutive entries with one clip id.
    pub fn clips(&self) -> Vec<&[LabelFrame]> {
        let mut out = Vec::new();
        let mut start = 0;
        for i in 1..=self.frames.len() {
            if i == self.frames.len() || self.frames[i].clip != self.frames[start].clip {
                if i > start {
                    out.push(&self.frames[start..i]);
                }
                start = i;
            }
        }
        out
    }

    /// Number of consecutive labelled frames in the longest clip.
    pub fn longest_clip(&self) -> usize {
        self.clips().iter().map(|c| c.len()).max().unwrap_or(0)
    }
}

/// Parameters of the scoring rules (module doc). Pixel tolerances are given at a reference width
/// and scaled to the image width.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ScoringRules {
    /// Label points above `eval_top_fraction · height` (rows) are not scored, in [0, 1).
    pub eval_top_fraction: f64,
    /// TuSimple point tolerance at 1280 px width, px (benchmark: 20).
    pub tusimple_px_at_1280: f64,
    /// TuSimple: a label lane is matched when at least this fraction of its points is correct
    /// (benchmark: 0.85).
    pub tusimple_match_fraction: f64,
    /// Aly: median nearest-point distance for a match at 640 px width, px.
    pub aly_px_at_640: f64,
}

impl Default for ScoringRules {
    fn default() -> Self {
        ScoringRules {
            eval_top_fraction: 0.6,
            tusimple_px_at_1280: 20.0,
            tusimple_match_fraction: 0.85,
            aly_px_at_640: 20.0,
        }
    }
}

/// One predicted ego lane: its parabola and the rows it reaches.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PredictedLane {
    /// `[a1, a2, a3]` of `x = a1·y² + a2·y + a3` (x column, y row, input pixels).
    pub coeffs: [f64; 3],
    /// `[top_px, bottom_px]`: the rows the prediction stands on, input pixels, `top ≤ bottom`
    /// (the tracker's: the row extent of the points behind its estimate,
    /// [`lane_tracker::LaneReport::rows`]). The near band ignores it; the full rule
    /// ([`full_rule`]) counts a label row outside it as a wrong point.
    pub rows_px: [f64; 2],
    /// The far segment above the near parabola's rows ([`lane_tracker::FarSegment`]:
    /// `[a1, a2, a3]` and the row it joins at), which the full rule reads above that row; the
    /// near band never does (its rows are the near parabola's).
    pub far: Option<([f64; 3], f64)>,
}

impl PredictedLane {
    /// A lane reaching every row: for predictions that report no extent (a peer's file), which
    /// only the near band scores.
    pub fn without_extent(coeffs: [f64; 3]) -> Self {
        PredictedLane {
            coeffs,
            rows_px: [f64::NEG_INFINITY, f64::INFINITY],
            far: None,
        }
    }

    /// The tracker's lane of one report (`None` where it reports no coefficients), with the row
    /// extent it reports.
    pub fn from_report(report: &lane_tracker::LaneReport) -> Option<Self> {
        report.coeffs.map(|coeffs| PredictedLane {
            coeffs,
            rows_px: report.rows,
            far: report.far.map(|f| (f.coeffs, f.rows[1])),
        })
    }

    /// Its column at `row_px`: the far segment's above the row it joins at, the near
    /// parabola's elsewhere.
    pub fn col_at_row(&self, row_px: f64) -> f64 {
        match self.far {
            Some((far, join_px)) if row_px < join_px => eval_parabola(far, row_px),
            _ => eval_parabola(self.coeffs, row_px),
        }
    }

    /// Whether row `row_px` lies within the extent, `tolerance_px` beyond either end allowed.
    pub fn reaches(&self, row_px: f64, tolerance_px: f64) -> bool {
        row_px >= self.rows_px[0] - tolerance_px && row_px <= self.rows_px[1] + tolerance_px
    }
}

/// The predicted ego lanes of one frame per side (left, right), `None` where nothing is
/// reported.
pub type EgoPrediction = [Option<PredictedLane>; 2];

/// Totals of one frame, one set, or all sets (pooled counts; see [`LaneTotals::summary`]).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct LaneTotals {
    /// Frames scored.
    pub frames: u64,
    /// Label ego lanes scored.
    pub label_lanes: u64,
    /// Predictions scored (on a side with a scored label lane, or with none labelled).
    pub predicted_lanes: u64,
    /// Sum over label lanes of their TuSimple point accuracy.
    pub tusimple_acc_sum: f64,
    /// Label lanes matched under TuSimple's rule.
    pub tusimple_matched: u64,
    /// Label lanes matched under Aly's rule.
    pub aly_matched: u64,
    /// Sum of |x_pred − x_label| over the label points of predicted lanes, px.
    pub abs_err_sum_px: f64,
    /// Points in `abs_err_sum_px`.
    pub abs_err_points: u64,
    /// The predictions not matched under TuSimple's rule, by what they lie on.
    #[serde(default)]
    pub false_positives: FalsePositives,
}

/// The predictions a frame, a set or all sets got wrong under TuSimple's rule (`predicted −
/// matched` of [`LaneTotals`]), by what they lie on: a prediction on a side with no label lane
/// (a side labelled only in the far field is not scored, nor its prediction); one that meets
/// the rule against another labelled marking of the frame (the other ego side's label lane or
/// an `Other` one: a neighbour's mark, or the two sides swapped); one with at least half its
/// label lane's points within the tolerance (the right mark, off by a little: one edge of a
/// wide mark, a bent end); the rest. The four add up to the unmatched predictions.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct FalsePositives {
    /// On a side with no label lane.
    pub unlabelled_side: u64,
    /// Off its side's label lane but matching another labelled marking of the frame.
    pub other_marking: u64,
    /// At least [`NEAR_MISS_FRACTION`] of its label lane's points within the tolerance, and on
    /// no other labelled marking.
    pub near: u64,
    /// Fewer than [`NEAR_MISS_FRACTION`] of its label lane's points within the tolerance, and on
    /// no other labelled marking.
    pub far: u64,
}

/// Least TuSimple point accuracy of a near miss ([`FalsePositives::near`]).
pub const NEAR_MISS_FRACTION: f64 = 0.5;

impl FalsePositives {
    /// All of them.
    pub fn total(&self) -> u64 {
        self.unlabelled_side + self.other_marking + self.near + self.far
    }

    /// Add another count.
    pub fn add(&mut self, o: &FalsePositives) {
        self.unlabelled_side += o.unlabelled_side;
        self.other_marking += o.other_marking;
        self.near += o.near;
        self.far += o.far;
    }
}

impl LaneTotals {
    /// One frame's totals from its two sides' ([`score_sides`]): their sum, counted as one frame.
    pub fn of_frame(sides: &[LaneTotals; 2]) -> Self {
        let mut t = Self {
            frames: 1,
            ..Self::default()
        };
        t.add(&sides[0]);
        t.add(&sides[1]);
        t
    }

    /// Add another total.
    pub fn add(&mut self, o: &LaneTotals) {
        self.frames += o.frames;
        self.label_lanes += o.label_lanes;
        self.predicted_lanes += o.predicted_lanes;
        self.tusimple_acc_sum += o.tusimple_acc_sum;
        self.tusimple_matched += o.tusimple_matched;
        self.aly_matched += o.aly_matched;
        self.abs_err_sum_px += o.abs_err_sum_px;
        self.abs_err_points += o.abs_err_points;
        self.false_positives.add(&o.false_positives);
    }

    /// The rates.
    pub fn summary(&self) -> LaneRates {
        let ratio = |a: f64, b: u64| if b > 0 { a / b as f64 } else { 0.0 };
        // A prediction is matched when the label lane of its side is.
        LaneRates {
            frames: self.frames,
            label_lanes: self.label_lanes,
            predicted_lanes: self.predicted_lanes,
            tusimple_accuracy: ratio(self.tusimple_acc_sum, self.label_lanes),
            tusimple_fp: ratio(
                (self.predicted_lanes - self.tusimple_matched.min(self.predicted_lanes)) as f64,
                self.predicted_lanes,
            ),
            tusimple_fn: ratio(
                self.label_lanes.saturating_sub(self.tusimple_matched) as f64,
                self.label_lanes,
            ),
            aly_detection_rate: ratio(self.aly_matched as f64, self.label_lanes),
            aly_false_per_label: ratio(
                (self.predicted_lanes - self.aly_matched.min(self.predicted_lanes)) as f64,
                self.label_lanes,
            ),
            mean_abs_error_px: if self.abs_err_points > 0 {
                self.abs_err_sum_px / self.abs_err_points as f64
            } else {
                f64::NAN
            },
            false_positives: self.false_positives,
        }
    }
}

/// Rates of a [`LaneTotals`] (fractions in [0, 1]).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct LaneRates {
    /// Frames scored.
    pub frames: u64,
    /// Label ego lanes scored.
    pub label_lanes: u64,
    /// Predictions scored.
    pub predicted_lanes: u64,
    /// TuSimple accuracy: mean over label lanes of the fraction of correct points.
    pub tusimple_accuracy: f64,
    /// TuSimple false positives: unmatched predictions / predictions.
    pub tusimple_fp: f64,
    /// TuSimple false negatives: unmatched label lanes / label lanes.
    pub tusimple_fn: f64,
    /// Aly: matched label lanes / label lanes.
    pub aly_detection_rate: f64,
    /// Aly: unmatched predictions per label lane.
    pub aly_false_per_label: f64,
    /// Mean |x_pred − x_label| over the label points of predicted lanes, px (NaN if none).
    pub mean_abs_error_px: f64,
    /// The unmatched predictions by kind (counts).
    #[serde(default)]
    pub false_positives: FalsePositives,
}

fn eval_parabola(coeffs: [f64; 3], y: f64) -> f64 {
    hough_init::Parabola::from_coeffs(coeffs).col_at_row(y)
}

/// The points of `labels`' lanes on `side` at or below row `y_top` (the scored ones).
fn scored_points(labels: &LabelFrame, side: LabelSide, y_top: f64) -> Vec<[f64; 2]> {
    labels
        .lanes
        .iter()
        .filter(|l| l.side == side)
        .flat_map(|l| lane_scored_points(l, y_top))
        .collect()
}

/// The points of one label lane at or below row `y_top`.
fn lane_scored_points(lane: &LabelLane, y_top: f64) -> impl Iterator<Item = [f64; 2]> + '_ {
    lane.points.iter().copied().filter(move |p| p[1] >= y_top)
}

/// TuSimple accuracy of prediction `c` on the scored label points `pts` (at least 2), with the
/// point tolerance `tus_px` (at this width) slope-corrected from the straight fit `x(y)` of the
/// points. Adds each point's |x_pred − x_label| (px) to `abs_err_sum_px`.
fn tusimple_lane_accuracy(
    pts: &[[f64; 2]],
    c: [f64; 3],
    tus_px: f64,
    abs_err_sum_px: &mut f64,
) -> f64 {
    let tol = tus_px / fit_slope(pts).atan().cos();
    let mut correct = 0usize;
    for &[x, y] in pts {
        let e = (eval_parabola(c, y) - x).abs();
        *abs_err_sum_px += e;
        if e <= tol {
            correct += 1;
        }
    }
    correct as f64 / pts.len() as f64
}

/// Whether prediction `c`, made for `side`, meets TuSimple's rule against another labelled
/// marking of `labels`: the other ego side's label lane, or any one `Other` lane, each on its
/// scored points (at least 2).
fn on_another_marking(
    labels: &LabelFrame,
    side: LabelSide,
    y_top: f64,
    c: [f64; 3],
    tus_px: f64,
    rules: &ScoringRules,
) -> bool {
    let mut unused_err_px = 0.0;
    let mut meets = |pts: &[[f64; 2]]| {
        pts.len() >= 2
            && tusimple_lane_accuracy(pts, c, tus_px, &mut unused_err_px)
                >= rules.tusimple_match_fraction
    };
    let other_side = match side {
        LabelSide::Left => LabelSide::Right,
        _ => LabelSide::Left,
    };
    meets(&scored_points(labels, other_side, y_top))
        || labels
            .lanes
            .iter()
            .filter(|l| l.side == LabelSide::Other)
            .any(|l| meets(&lane_scored_points(l, y_top).collect::<Vec<_>>()))
}

/// Score one frame's ego prediction against its labels under `rules`: its two sides
/// ([`score_sides`]) as one frame ([`LaneTotals::of_frame`]).
pub fn score_frame(
    labels: &LabelFrame,
    width: usize,
    height: usize,
    prediction: &EgoPrediction,
    rules: &ScoringRules,
) -> LaneTotals {
    LaneTotals::of_frame(&score_sides(labels, width, height, prediction, rules))
}

/// [`score_side`] of the left and of the right side of one frame's ego prediction.
pub fn score_sides(
    labels: &LabelFrame,
    width: usize,
    height: usize,
    prediction: &EgoPrediction,
    rules: &ScoringRules,
) -> [LaneTotals; 2] {
    score_sides_from(
        labels,
        width,
        height,
        prediction,
        rules,
        near_top_px(rules, height),
    )
}

/// The top row of the near band of a frame `height` rows high: `eval_top_fraction · height`.
pub fn near_top_px(rules: &ScoringRules, height: usize) -> f64 {
    rules.eval_top_fraction * height as f64
}

/// [`score_sides`] with the near band's top row given (`y_top`, px) instead of
/// [`ScoringRules::eval_top_fraction`]: a perturbed frame ([`crate::perturb`]) is scored on
/// the rows that were its near band before the perturbation.
pub fn score_sides_from(
    labels: &LabelFrame,
    width: usize,
    height: usize,
    prediction: &EgoPrediction,
    rules: &ScoringRules,
    y_top: f64,
) -> [LaneTotals; 2] {
    let side = |side, p| score_side_from(labels, width, height, side, p, rules, y_top);
    [
        side(LabelSide::Left, prediction[0]),
        side(LabelSide::Right, prediction[1]),
    ]
}

/// Score one ego side of a frame (`side` [`LabelSide::Left`] or [`LabelSide::Right`]; `Other`
/// has no prediction and scores nothing): its prediction `prediction` against that side's label
/// lane under `rules`. At most one label lane and one prediction; `frames` is 0 (a side is not
/// a frame). A side labelled only above the scored rows scores nothing, its prediction
/// included; a prediction on a side with no label is a false positive
/// ([`FalsePositives::unlabelled_side`]).
pub fn score_side(
    labels: &LabelFrame,
    width: usize,
    height: usize,
    side: LabelSide,
    prediction: Option<PredictedLane>,
    rules: &ScoringRules,
) -> LaneTotals {
    let y_top = near_top_px(rules, height);
    score_side_from(labels, width, height, side, prediction, rules, y_top)
}

/// [`score_side`] with the near band's top row `y_top` (px) given ([`score_sides_from`]).
fn score_side_from(
    labels: &LabelFrame,
    width: usize,
    height: usize,
    side: LabelSide,
    prediction: Option<PredictedLane>,
    rules: &ScoringRules,
    y_top: f64,
) -> LaneTotals {
    let mut t = LaneTotals::default();
    if side == LabelSide::Other {
        return t;
    }
    let tus_px = rules.tusimple_px_at_1280 * width as f64 / 1280.0;
    let aly_px = rules.aly_px_at_640 * width as f64 / 640.0;
    let pts = scored_points(labels, side, y_top);
    let labelled = labels.lanes.iter().any(|l| l.side == side);
    if labelled && pts.len() < 2 {
        // Labelled only in the far field: neither the label nor a prediction is scored.
        return t;
    }
    if prediction.is_some() {
        t.predicted_lanes += 1;
    }
    if pts.is_empty() {
        // No label on this side: a prediction there is a false positive.
        t.false_positives.unlabelled_side += u64::from(prediction.is_some());
        return t;
    }
    t.label_lanes += 1;
    let Some(PredictedLane { coeffs: c, .. }) = prediction else {
        return t;
    };
    let acc = tusimple_lane_accuracy(&pts, c, tus_px, &mut t.abs_err_sum_px);
    t.abs_err_points += pts.len() as u64;
    t.tusimple_acc_sum += acc;
    if acc >= rules.tusimple_match_fraction {
        t.tusimple_matched += 1;
    } else if on_another_marking(labels, side, y_top, c, tus_px, rules) {
        t.false_positives.other_marking += 1;
    } else if acc >= NEAR_MISS_FRACTION {
        t.false_positives.near += 1;
    } else {
        t.false_positives.far += 1;
    }
    // Aly: median nearest-point distance to the prediction sampled on every row.
    let y_lo = (y_top - aly_px).max(0.0).floor() as i64;
    let y_hi = (height as f64 - 1.0 + aly_px).ceil() as i64;
    let mut d: Vec<f64> = pts
        .iter()
        .map(|&[x, y]| {
            (y_lo..=y_hi)
                .map(|r| {
                    let r = r as f64;
                    let dx = eval_parabola(c, r) - x;
                    let dy = r - y;
                    dx * dx + dy * dy
                })
                .fold(f64::INFINITY, f64::min)
                .sqrt()
        })
        .collect();
    d.sort_by(f64::total_cmp);
    let median = if d.len() % 2 == 1 {
        d[d.len() / 2]
    } else {
        0.5 * (d[d.len() / 2 - 1] + d[d.len() / 2])
    };
    if median <= aly_px {
        t.aly_matched += 1;
    }
    t
}

/// Slope `dx/dy` of the least-squares line `x = k·y + b` through the points (0 if degenerate).
fn fit_slope(pts: &[[f64; 2]]) -> f64 {
    let n = pts.len() as f64;
    let (sx, sy) = pts
        .iter()
        .fold((0.0, 0.0), |(a, b), p| (a + p[0], b + p[1]));
    let (mx, my) = (sx / n, sy / n);
    let (mut sxy, mut syy) = (0.0, 0.0);
    for &[x, y] in pts {
        sxy += (x - mx) * (y - my);
        syy += (y - my) * (y - my);
    }
    if syy > 0.0 { sxy / syy } else { 0.0 }
}

mod ceiling;
mod census;
mod choice_bound;
pub mod full_rule;
pub mod import;
mod run;
#[cfg(test)]
mod tests;

pub use ceiling::{ceiling_prediction, whole_label_ceiling};
pub use census::{LaneCensus, LaneStage, StageCensus, census_lanes};
pub(crate) use choice_bound::best_of_candidates;
pub use choice_bound::{ChoiceBound, choice_bound_set};
pub use full_rule::{FullRates, FullTotals, score_frame_full};
pub(crate) use run::{FileStills, Stills, ego_of, run_label_set, run_stills};
pub use run::{SkippedFrame, TrackedSet, track_label_set};
