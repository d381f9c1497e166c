//! Where the ego label lanes are lost, stage by stage: a diagnostic for tuning the
//! initialisation (`nav-app eval-lanes --census`). [`census_lanes`] gives each lane's stage
//! ([`LaneStage`]; `frames.csv`'s `census_stage`), [`StageCensus::count`] their counts (the
//! `--census` table).
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
//! by the chosen candidate (the windows corrected a candidate that was off); among those with no
//! candidate, those with **no edge near the label**: on fewer than half of the label's scored
//! points in the ROI rows does the configuration's gradient stage (threshold and edge-angle band,
//! before stripe pairing; [`lane_tracker::GradientConfig::params`]) keep an edge pixel within
//! `r = t + gradient.stripe_max_width_px / 2` columns of the point, `t` the TuSimple tolerance at
//! this width (the edges of a mark up to a stripe width wide centred within `t` of the label).
//! The edges are read where the stages read them, on the tracker's working frame
//! ([`lane_tracker::LaneTracker::working_frame`]: an input of another width resampled to the working width), the label's
//! points and `t` mapped into its pixels (input `x` is working `(x − (f − 1)/2)/f`), so a set
//! enlarged `f` times is classified as the working frame is.
//! No mark detector fits a lane there: the label runs where the image shows nothing this
//! detector keeps (a lane boundary without paint, a mark worn away, hidden, or outside the
//! edge-angle band). It is a lower bound of such labels: clutter near a label counts as an edge.
//! A label lane whose side kept the estimate tracked from the previous frame of its clip, or on
//! a frame without a joint initialisation (both lanes tracked, or the paper's one line per band,
//! `init.candidate_lines = 0`), is only counted as **not classified**.

use std::ops::Range;
use std::path::Path;

use serde::{Deserialize, Serialize};

use lane_tracker::{Estimator, LaneTracker, Side, TrackerConfig};
use vision_gradient::{EdgeBuffer, GradientDetector, GreyImage, Region};

use super::{
    LabelSet, LabelSide, ScoringRules, run_label_set, scored_points, tusimple_lane_accuracy,
};
use crate::BenchError;

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
    /// … of which the gradient stage keeps no edge near the label on half of its scored ROI
    /// points or more (module docs).
    pub no_edge_near_label: u64,
    /// Not matched; a candidate matched but not the one chosen for the side.
    pub not_chosen: u64,
    /// Not matched; the chosen candidate matched.
    pub lost_after_choice: u64,
    /// Scored ego label lanes on a side that kept its tracked estimate, or on a frame without a
    /// joint initialisation (`init.candidate_lines = 0`): not classified.
    pub not_classified: u64,
}

/// The stage where one scored ego label lane is lost (module docs), as [`StageCensus`] counts
/// it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LaneStage {
    /// Matched by the output, and by the chosen candidate alone.
    Matched,
    /// Matched by the output, not by the chosen candidate (found by the refinement).
    FoundByRefinement,
    /// No Hough candidate matched it; the gradient stage keeps edges near the label.
    NoCandidate,
    /// No Hough candidate matched it, and no edge near the label either.
    NoEdgeNearLabel,
    /// A candidate matched it, not the one chosen for its side.
    NotChosen,
    /// The chosen candidate matched it, the output does not.
    LostAfterChoice,
    /// On a side that kept its tracked estimate, or on a frame without a joint initialisation.
    NotClassified,
}

impl LaneStage {
    /// Its name in reports (`snake_case`, as serialised).
    pub fn name(self) -> &'static str {
        match self {
            Self::Matched => "matched",
            Self::FoundByRefinement => "found_by_refinement",
            Self::NoCandidate => "no_candidate",
            Self::NoEdgeNearLabel => "no_edge_near_label",
            Self::NotChosen => "not_chosen",
            Self::LostAfterChoice => "lost_after_choice",
            Self::NotClassified => "not_classified",
        }
    }
}

/// One scored ego label lane of the census: where in the set, which side, and its stage.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct LaneCensus {
    /// The frame's position in the set.
    pub position: usize,
    /// [`LabelSide::Left`] or [`LabelSide::Right`].
    pub side: LabelSide,
    /// Where it is lost.
    pub stage: LaneStage,
}

impl StageCensus {
    /// The counts of per-lane classes: every lane in its class, and in
    /// [`StageCensus::label_lanes`] unless it is not classified (so the counts add up as the
    /// fields' docs say).
    pub fn count(lanes: &[LaneCensus]) -> Self {
        let mut c = Self::default();
        for l in lanes {
            c.label_lanes += u64::from(l.stage != LaneStage::NotClassified);
            match l.stage {
                LaneStage::Matched => c.matched += 1,
                LaneStage::FoundByRefinement => {
                    c.matched += 1;
                    c.found_by_refinement += 1;
                }
                LaneStage::NoCandidate => c.no_candidate += 1,
                LaneStage::NoEdgeNearLabel => {
                    c.no_candidate += 1;
                    c.no_edge_near_label += 1;
                }
                LaneStage::NotChosen => c.not_chosen += 1,
                LaneStage::LostAfterChoice => c.lost_after_choice += 1,
                LaneStage::NotClassified => c.not_classified += 1,
            }
        }
        c
    }

    /// Add another census.
    pub fn add(&mut self, o: &StageCensus) {
        self.label_lanes += o.label_lanes;
        self.matched += o.matched;
        self.found_by_refinement += o.found_by_refinement;
        self.no_candidate += o.no_candidate;
        self.no_edge_near_label += o.no_edge_near_label;
        self.not_chosen += o.not_chosen;
        self.lost_after_choice += o.lost_after_choice;
        self.not_classified += o.not_classified;
    }
}

/// Every scored ego label lane of the frames at positions `frames` (in set order) of a labelled
/// set with the stage where it is lost (module docs), in set order, left before right; the
/// tracker run as [`super::track_label_set`] runs it (clip by clip, from the first frame of each
/// clip).
///
/// # Errors
/// A configuration the tracker or the edge detector refuses (a frame that cannot be read or has
/// another size than the set declares is skipped, as by [`super::track_label_set`], and not
/// classified).
pub fn census_lanes(
    dir: &Path,
    set: &LabelSet,
    cfg: &TrackerConfig,
    estimator: Estimator,
    frames: Range<usize>,
    rules: &ScoringRules,
) -> Result<Vec<LaneCensus>, BenchError> {
    let mut census = Vec::new();
    let y_top = rules.eval_top_fraction * set.height as f64;
    let tus_px = rules.tusimple_px_at_1280 * set.width as f64 / 1280.0;
    let joint = cfg.init.candidate_lines > 0;
    // The edges are read where the tracker's stages read them: on its working frame (a wide
    // input resampled to `frame.working_width_px`), whose pixels the configuration's are.
    let (working_w, working_h, factor) = {
        let probe = LaneTracker::new(cfg, estimator, set.width, set.height)?;
        let (w, h) = probe.working_size();
        (w, h, probe.working_scale())
    };
    let (roi_top, roi_bottom) = cfg.roi_rows(working_h);
    let reach_px = tus_px / factor + 0.5 * f64::from(cfg.gradient.stripe_max_width_px);
    // Input pixel `x` is working pixel `(x − (f − 1)/2) / f`.
    let to_working = |v: f64| (v - 0.5 * (factor - 1.0)) / factor;
    let detector = GradientDetector::new(cfg.gradient.params())?;
    let mut edges = EdgeBuffer::with_capacity(working_w * (roi_bottom - roi_top));
    // Per working ROI pixel: does the gradient stage keep an edge there.
    let mut edge_at = vec![false; working_w * (roi_bottom - roi_top)];
    run_label_set(
        dir,
        set,
        cfg,
        estimator,
        frames.end,
        |position, labels, tracked| {
            // A skipped frame is not classified (the choice bound's run lists it).
            let Some(t) = tracked else { return Ok(()) };
            if !frames.contains(&position) {
                return Ok(());
            }
            let (tracker, report, frame) = (t.tracker, &t.report, t.frame);
            let mut edges_read = false;
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
                let mut put = |stage| {
                    census.push(LaneCensus {
                        position,
                        side: label_side,
                        stage,
                    });
                };
                if !(report.full_gradient && joint && initialised_for) {
                    put(LaneStage::NotClassified);
                    continue;
                }
                let matches = |c: [f64; 3]| {
                    tusimple_lane_accuracy(&pts, c, tus_px, &mut 0.0)
                        >= rules.tusimple_match_fraction
                };
                let output = report.lanes[k].coeffs.is_some_and(matches);
                let chosen = candidates
                    .iter()
                    .any(|c| c.chosen == Some(side) && matches(c.coeffs));
                if output {
                    put(if chosen {
                        LaneStage::Matched
                    } else {
                        LaneStage::FoundByRefinement
                    });
                } else if chosen {
                    put(LaneStage::LostAfterChoice);
                } else if candidates.iter().any(|c| matches(c.coeffs)) {
                    put(LaneStage::NotChosen);
                } else {
                    if !edges_read {
                        let image = match tracker.working_frame() {
                            Some((image, _)) => image,
                            None => {
                                let (w, h) = (frame.width(), frame.height());
                                GreyImage::new(frame.data(), w, h, w)?
                            }
                        };
                        mark_edges(
                            &detector,
                            &image,
                            (roi_top, roi_bottom),
                            &mut edges,
                            &mut edge_at,
                        )?;
                        edges_read = true;
                    }
                    let (mut in_roi, mut with_edge) = (0usize, 0usize);
                    for &[x, y] in &pts {
                        let (x, y) = (to_working(x), to_working(y));
                        let row = y.round();
                        if row >= roi_top as f64 && row < roi_bottom as f64 {
                            in_roi += 1;
                            let near = edge_near(&edge_at, working_w, roi_top, (x, y), reach_px);
                            with_edge += usize::from(near);
                        }
                    }
                    put(if 2 * with_edge < in_roi {
                        LaneStage::NoEdgeNearLabel
                    } else {
                        LaneStage::NoCandidate
                    });
                }
            }
            Ok(())
        },
    )?;
    Ok(census)
}

/// `edge_at[(r − top)·W + c]` = the gradient stage keeps an edge pixel at row `r`, column `c`
/// of `image`, for the rows `[top, bottom)`.
fn mark_edges(
    detector: &GradientDetector,
    image: &GreyImage<'_>,
    (top, bottom): (usize, usize),
    edges: &mut EdgeBuffer,
    edge_at: &mut [bool],
) -> Result<(), BenchError> {
    let w = image.width();
    detector.detect(
        image,
        Region::Rows {
            row_start_px: top,
            row_end_px: bottom,
        },
        edges,
        None,
    )?;
    edge_at.fill(false);
    for p in edges.pixels() {
        let r = usize::from(p.row_px);
        if let Some(cell) = r
            .checked_sub(top)
            .and_then(|dr| edge_at.get_mut(dr * w + usize::from(p.col_px)))
        {
            *cell = true;
        }
    }
    Ok(())
}

/// Whether `edge_at` (rows from `top`, `width` columns) holds an edge on the row of `(x, y)`
/// within `reach_px` columns of `x`.
fn edge_near(
    edge_at: &[bool],
    width: usize,
    top: usize,
    (x, y): (f64, f64),
    reach_px: f64,
) -> bool {
    let (lo, hi) = ((x - reach_px).ceil(), (x + reach_px).floor());
    if !(lo.is_finite() && hi.is_finite()) || hi < 0.0 || lo > (width - 1) as f64 {
        return false;
    }
    let (lo, hi) = (lo.max(0.0) as usize, hi.min((width - 1) as f64) as usize);
    let Some(row) = (y.round() as usize)
        .checked_sub(top)
        .and_then(|dr| edge_at.get(dr * width..(dr + 1) * width))
    else {
        return false;
    };
    row.get(lo..=hi).is_some_and(|cols| cols.iter().any(|&e| e))
}
