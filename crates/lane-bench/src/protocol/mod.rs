//! The benchmark's protocol (`nav-app eval-lanes`, `cargo xtask eval-lanes`): the tracker on
//! every labelled set of a directory, scored with the TuSimple and Aly rules of
//! [`crate::labelled`], per set and overall, ego lanes.
//!
//! Every set is split once and for all: the first 70 % of its frames (in set order) are the
//! **development** part, the rest the **held-out** part; the tracker's defaults may be tuned on
//! the development part only, and the held-out figures are reported on their own. Scored: the
//! ceiling (parabolas fitted to the labels over the ROI rows), the best of the default's
//! candidates ([`crate::labelled::choice_bound_set`]), the default configuration (what `nav-app`
//! runs with no `--config`), the configurations given beside it, and a peer's predictions when
//! given ([`Options::peer`]: `cargo xtask eval-lanes` runs the classic OpenCV pipeline). The
//! default's false positives are also split by what they lie on
//! ([`crate::labelled::FalsePositives`]).
//!
//! Beside the near band, every configuration that reports row extents (the default, the
//! configurations beside it, the bounds of its choice, the ceilings; not a peer's file, which
//! has none) is scored under TuSimple's **full rule** ([`crate::labelled::full_rule`]: every
//! labelled row, a row the prediction does not reach a wrong point), with its own ceiling,
//! [`FULL_CEILING_NAME`]: the parabola of each whole label lane, the model's own bound. With
//! [`Options::perturb`], the default also runs on the frames changed as other cameras would
//! give them ([`perturbed`], [`crate::perturb`]).
//!
//! [`Evaluation::write`] writes `summary.md`, `summary.json`, `worst_frames.png` (the worst
//! frames of the default run: labels green, the tracker red, the peer blue) and `frames.csv`
//! (the default run's outcome per scored ego side of every frame,
//! [`crate::labelled::score_sides`], and with [`Options::census`] the stage where its label lane
//! is lost, [`crate::labelled::census_lanes`]; with [`Options::dev_only`] the only file written,
//! and of the development part alone). [`floors`] checks the default's figures against recorded
//! floors and records them.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use lane_tracker::{Estimator, LaneTracker, TrackerConfig};
use serde::{Deserialize, Serialize};

use crate::BenchError;
use crate::labelled::full_rule::REACH_WORKING_PX;
use crate::labelled::{
    EgoPrediction, FullRates, FullTotals, LabelSet, LaneRates, LaneTotals, PredictedLane,
    ScoringRules, SkippedFrame, StageCensus, ceiling_prediction, census_lanes, choice_bound_set,
    score_frame_full, score_sides, track_label_set, whole_label_ceiling,
};

pub mod floors;
pub mod perturbed;
mod report;
mod sheet;

pub use perturbed::PerturbedSummary;
pub use report::FRAMES_CSV_HEADER;

/// Format version of `summary.json` (3: the full rule, `full_rule` and `overall_full_rule`, and
/// the perturbation table, `perturbations`, were added; the near band's fields are as in 2. 4:
/// each perturbation's `best_of_candidates` and `best_of_candidates_sets`, the bound of the
/// default's choice under it, were added).
pub const SUMMARY_SCHEMA: u32 = 4;
/// Fraction of every set's frames (the first ones, in set order) in the development part.
pub const DEV_FRACTION: f64 = 0.7;
/// Name of the default configuration in the reports.
pub const DEFAULT_NAME: &str = "default";
/// Name of the ceiling (parabolas fitted to the labels over the ROI rows) in the reports.
pub const CEILING_NAME: &str = "ceiling";
/// Name of the bound of the default's choice ([`crate::labelled::choice_bound_set`]: per side,
/// the best of its output and its Hough candidates, picked by the labels).
pub const CHOICE_BOUND_NAME: &str = "best-of-candidates";
/// … and reporting nothing where that best lane has fewer than half its label's points within
/// the tolerance ([`crate::labelled::ChoiceBound::best_or_none`]).
pub const CHOICE_BOUND_OR_NONE_NAME: &str = "best-of-candidates-or-none";
/// Name of the peer (the OpenCV pipeline of `cargo xtask eval-lanes`) in the reports.
pub const PEER_NAME: &str = "opencv-peer";
/// Name of the full rule's ceiling: per ego label lane, the parabola of all its points
/// ([`crate::labelled::whole_label_ceiling`]). Under the full rule, [`CEILING_NAME`] is the
/// near band's ceiling (fitted on the ROI rows, reaching those rows only).
pub const FULL_CEILING_NAME: &str = "ceiling-whole-label";

/// One configuration's figures under the full rule on one set (or overall).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct FullSplitRates {
    /// Every frame.
    pub all: FullRates,
    /// The development part.
    pub dev: FullRates,
    /// The held-out part.
    pub holdout: FullRates,
}

/// One configuration's figures on one set (or overall).
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
pub struct SplitRates {
    /// Every frame.
    pub all: LaneRates,
    /// The development part.
    pub dev: LaneRates,
    /// The held-out part.
    pub holdout: LaneRates,
}

/// One set in `summary.json`.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct SetSummary {
    /// Set name.
    pub set: String,
    /// `road` or `indoor`.
    pub kind: String,
    /// Where it comes from.
    pub source: String,
    /// Its licence.
    pub licence: String,
    /// Frame size, px.
    pub size_px: [usize; 2],
    /// Labelled frames.
    pub frames: usize,
    /// Longest run of consecutive labelled frames.
    pub longest_clip: usize,
    /// Per configuration (`default`, presets, `opencv-peer`).
    pub results: BTreeMap<String, SplitRates>,
    /// Per configuration under the full rule (every one with row extents, and
    /// [`FULL_CEILING_NAME`]).
    #[serde(default)]
    pub full_rule: BTreeMap<String, FullSplitRates>,
}

/// `summary.json`.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Summary {
    /// Format version.
    pub schema: u32,
    /// The scoring rules.
    pub rules: ScoringRules,
    /// Fraction of each set in the development part.
    pub dev_fraction: f64,
    /// The configuration `default` stands for.
    pub default_config: String,
    /// Per set.
    pub sets: Vec<SetSummary>,
    /// Pooled over every set, per configuration.
    pub overall: BTreeMap<String, SplitRates>,
    /// The full rule's tolerance on a prediction's row extent, px of the tracker's working
    /// frame ([`crate::labelled::full_rule`]).
    #[serde(default)]
    pub full_rule_reach_working_px: f64,
    /// Pooled over every set under the full rule, per configuration.
    #[serde(default)]
    pub overall_full_rule: BTreeMap<String, FullSplitRates>,
    /// The default under each perturbation ([`Options::perturb`]), in [`crate::perturb::TABLE`]'s
    /// order; empty (and absent from the file) without it.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub perturbations: Vec<PerturbedSummary>,
}

#[derive(Default, Clone, Copy)]
struct SplitTotals {
    all: LaneTotals,
    dev: LaneTotals,
    holdout: LaneTotals,
}

impl SplitTotals {
    fn add(&mut self, t: &LaneTotals, dev: bool) {
        self.all.add(t);
        if dev {
            self.dev.add(t);
        } else {
            self.holdout.add(t);
        }
    }
    fn merge(&mut self, o: &SplitTotals) {
        self.all.add(&o.all);
        self.dev.add(&o.dev);
        self.holdout.add(&o.holdout);
    }
    fn rates(&self) -> SplitRates {
        SplitRates {
            all: self.all.summary(),
            dev: self.dev.summary(),
            holdout: self.holdout.summary(),
        }
    }
}

/// [`SplitTotals`] under the full rule.
#[derive(Default, Clone, Copy)]
struct FullSplitTotals {
    all: FullTotals,
    dev: FullTotals,
    holdout: FullTotals,
}

impl FullSplitTotals {
    fn add(&mut self, t: &FullTotals, dev: bool) {
        self.all.add(t);
        if dev {
            self.dev.add(t);
        } else {
            self.holdout.add(t);
        }
    }
    fn merge(&mut self, o: &FullSplitTotals) {
        self.all.add(&o.all);
        self.dev.add(&o.dev);
        self.holdout.add(&o.holdout);
    }
    fn rates(&self) -> FullSplitRates {
        FullSplitRates {
            all: self.all.summary(),
            dev: self.dev.summary(),
            holdout: self.holdout.summary(),
        }
    }
}

/// Frames `0..dev_count(n)` of a set of `n` are the development part.
pub fn dev_count(n: usize) -> usize {
    (DEV_FRACTION * n as f64).ceil() as usize
}

/// What [`evaluate`] runs beside the default configuration.
#[derive(Debug, Clone, Default)]
pub struct Options {
    /// Configurations scored beside the default, each with its name in the reports.
    pub configs: Vec<(String, TrackerConfig)>,
    /// Only the development part goes into `frames.csv` (and the reports show only it).
    pub dev_only: bool,
    /// Classify where the default loses the development part's ego label lanes.
    pub census: bool,
    /// Track each set's frames as one sequence, never reset between clips (a stress test of the
    /// tracking path, not an accuracy figure: the floors are for the stills).
    pub one_sequence: bool,
    /// A directory with a peer's predictions, `peer-<set>.json` per set (`{"frames": [{"index":
    /// i, "lanes": [left, right]}]}`, each lane `[a1, a2, a3]` or `null`), scored as
    /// [`PEER_NAME`] (near band only: the file gives no row extents).
    pub peer: Option<PathBuf>,
    /// Also run the default on every perturbation of [`crate::perturb::TABLE`] ([`perturbed`]).
    pub perturb: bool,
}

/// A scored frame of the default run, for the contact sheet.
struct FrameRank {
    set: usize,
    frame: usize,
    accuracy: f64,
    false_positives: u64,
}

/// What [`evaluate`] measured: the summary and what the reports are made from.
pub struct Evaluation {
    /// `summary.json`.
    pub summary: Summary,
    /// The census per set (with [`Options::census`]).
    pub censuses: Vec<(String, StageCensus)>,
    /// `frames.csv`.
    pub frames_csv: String,
    /// The frames skipped (set name, frame), each listed once.
    pub skipped: Vec<(String, SkippedFrame)>,
    /// Wall time of each perturbation of the table, over every set (with
    /// [`Options::perturb`]).
    pub perturb_times: Vec<perturbed::PerturbTime>,
    dev_only: bool,
    sets: Vec<(PathBuf, LabelSet)>,
    ranks: Vec<FrameRank>,
    /// Per set: the default's predictions and the peer's.
    drawn: Vec<(Vec<EgoPrediction>, Option<Vec<EgoPrediction>>)>,
}

/// The labelled sets under `dir` (each a sub-directory with a `labels.json`), sorted by name.
pub fn find_sets(dir: &Path) -> Result<Vec<(PathBuf, LabelSet)>, BenchError> {
    let mut dirs: Vec<PathBuf> = std::fs::read_dir(dir)
        .map_err(|e| BenchError::io("read", dir, e))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.join("labels.json").is_file())
        .collect();
    dirs.sort();
    if dirs.is_empty() {
        return Err(BenchError::NoSets {
            dir: dir.display().to_string(),
            reason: "no labelled set (no */labels.json)".to_owned(),
        });
    }
    dirs.into_iter()
        .map(|d| {
            let set = LabelSet::load(&d)?;
            Ok((d, set))
        })
        .collect()
}

/// The peer's predictions file.
#[derive(Deserialize)]
struct PeerFile {
    frames: Vec<PeerFrame>,
}
#[derive(Deserialize)]
struct PeerFrame {
    index: u64,
    lanes: [Option<[f64; 3]>; 2],
}

/// The peer's predictions of `set` from `dir/peer-<set>.json`, one per frame in set order.
fn read_peer(dir: &Path, set: &LabelSet) -> Result<Vec<EgoPrediction>, BenchError> {
    let path = dir.join(format!("peer-{}.json", set.set));
    let text = std::fs::read_to_string(&path).map_err(|e| BenchError::io("read", &path, e))?;
    let file: PeerFile = serde_json::from_str(&text).map_err(|source| BenchError::Json {
        path: path.display().to_string(),
        source,
    })?;
    let same = file.frames.len() == set.frames.len()
        && file
            .frames
            .iter()
            .zip(&set.frames)
            .all(|(p, f)| p.index == f.index);
    if !same {
        return Err(BenchError::Refused(format!(
            "{}: the peer's frames do not match set {}",
            path.display(),
            set.set
        )));
    }
    Ok(file
        .frames
        .into_iter()
        .map(|f| f.lanes.map(|lane| lane.map(PredictedLane::without_extent)))
        .collect())
}

/// Score the default configuration and `options`' on every set of `sets` (module docs).
pub fn evaluate(
    mut sets: Vec<(PathBuf, LabelSet)>,
    options: &Options,
) -> Result<Evaluation, BenchError> {
    if options.one_sequence {
        for (_, set) in &mut sets {
            let one = format!("{}-one-sequence", set.set);
            for f in &mut set.frames {
                f.clip.clone_from(&one);
            }
        }
    }
    let rules = ScoringRules::default();
    let default = TrackerConfig::default_preset()?;
    let mut summaries = Vec::new();
    let mut censuses: Vec<(String, StageCensus)> = Vec::new();
    let mut overall: BTreeMap<String, SplitTotals> = BTreeMap::new();
    let mut overall_full: BTreeMap<String, FullSplitTotals> = BTreeMap::new();
    let mut ranks = Vec::new();
    let mut drawn = Vec::new();
    let mut skipped = Vec::new();
    let mut frames_csv = String::from(FRAMES_CSV_HEADER);
    for (si, (dir, set)) in sets.iter().enumerate() {
        let n_dev = dev_count(set.frames.len());
        let lanes_census = if options.census {
            let lanes = census_lanes(dir, set, &default, Estimator::Kif, 0..n_dev, &rules)
                .map_err(|e| e.during(format!("census of set {}", set.set)))?;
            censuses.push((set.set.clone(), StageCensus::count(&lanes)));
            lanes
        } else {
            Vec::new()
        };
        let mut results = BTreeMap::new();
        let mut runs: Vec<(String, Vec<EgoPrediction>)> = Vec::new();
        // The default's run also gives the bounds of its choice: what a perfect choice among
        // its own candidates would reach (the labels pick), to tell the choice's losses from
        // the detection's; scored after the other configurations.
        let bound = choice_bound_set(dir, set, &default, Estimator::Kif, &rules)
            .map_err(|e| e.during(format!("set {} with config {DEFAULT_NAME}", set.set)))?;
        skipped.extend(bound.skipped.iter().map(|s| (set.set.clone(), s.clone())));
        runs.push((DEFAULT_NAME.to_owned(), bound.output));
        for (name, cfg) in &options.configs {
            let tracked = track_label_set(dir, set, cfg, Estimator::Kif)
                .map_err(|e| e.during(format!("set {} with config {name}", set.set)))?;
            runs.push((name.clone(), tracked.predictions));
        }
        let peer = match &options.peer {
            Some(peer_dir) => {
                let p = read_peer(peer_dir, set)?;
                runs.push((PEER_NAME.to_owned(), p.clone()));
                Some(p)
            }
            None => None,
        };
        // The ceiling: a parabola fitted to the labels themselves over the default's ROI rows
        // (the tracker's, in this set's pixels: a wide frame's working rows mapped back),
        // scored by the same rules (what the lane model can reach on this set).
        let probe =
            LaneTracker::new(&default, Estimator::Kif, set.width, set.height).map_err(|e| {
                BenchError::from(e).during(format!(
                    "{}: no tracker for {}×{}",
                    set.set, set.width, set.height
                ))
            })?;
        let roi = probe.roi_rows();
        // The full rule's reach: half a working pixel, in this set's pixels.
        let reach_px = REACH_WORKING_PX * probe.working_scale();
        runs.push((CHOICE_BOUND_NAME.to_owned(), bound.best));
        runs.push((CHOICE_BOUND_OR_NONE_NAME.to_owned(), bound.best_or_none));
        runs.push((
            CEILING_NAME.to_owned(),
            set.frames
                .iter()
                .map(|f| ceiling_prediction(f, roi))
                .collect(),
        ));
        for (name, preds) in &runs {
            let mut totals = SplitTotals::default();
            for (i, (f, p)) in set.frames.iter().zip(preds).enumerate() {
                let sides = score_sides(f, set.width, set.height, p, &rules);
                let t = LaneTotals::of_frame(&sides);
                totals.add(&t, i < n_dev);
                if name == DEFAULT_NAME && (i < n_dev || !options.dev_only) {
                    frames_csv += &report::side_rows(set, f, i, i < n_dev, &sides, &lanes_census);
                }
                if name == DEFAULT_NAME && t.label_lanes + t.predicted_lanes > 0 {
                    ranks.push(FrameRank {
                        set: si,
                        frame: i,
                        accuracy: if t.label_lanes > 0 {
                            t.tusimple_acc_sum / t.label_lanes as f64
                        } else {
                            1.0
                        },
                        false_positives: t.predicted_lanes - t.tusimple_matched,
                    });
                }
            }
            overall.entry(name.clone()).or_default().merge(&totals);
            results.insert(name.clone(), totals.rates());
        }
        // The full rule: every run with row extents (not the peer's), and its own ceiling.
        let whole_label: Vec<EgoPrediction> = set.frames.iter().map(whole_label_ceiling).collect();
        let mut full_rule = BTreeMap::new();
        let with_extents = runs
            .iter()
            .filter(|(name, _)| name != PEER_NAME)
            .map(|(name, preds)| (name.as_str(), preds))
            .chain([(FULL_CEILING_NAME, &whole_label)]);
        for (name, preds) in with_extents {
            let mut totals = FullSplitTotals::default();
            for (i, (f, p)) in set.frames.iter().zip(preds).enumerate() {
                totals.add(
                    &score_frame_full(f, set.width, p, &rules, reach_px),
                    i < n_dev,
                );
            }
            overall_full
                .entry(name.to_owned())
                .or_default()
                .merge(&totals);
            full_rule.insert(name.to_owned(), totals.rates());
        }
        drawn.push((runs.swap_remove(0).1, peer));
        summaries.push(SetSummary {
            set: set.set.clone(),
            kind: format!("{:?}", set.kind).to_lowercase(),
            source: set.source.clone(),
            licence: set.licence.clone(),
            size_px: [set.width, set.height],
            frames: set.frames.len(),
            longest_clip: set.longest_clip(),
            results,
            full_rule,
        });
    }
    let (perturbations, perturb_times) = if options.perturb {
        perturbed::perturbation_table(&sets, &default, &rules)?
    } else {
        (Vec::new(), Vec::new())
    };
    let summary = Summary {
        schema: SUMMARY_SCHEMA,
        rules,
        dev_fraction: DEV_FRACTION,
        default_config: "configs/default.toml".to_owned(),
        sets: summaries,
        overall: overall
            .iter()
            .map(|(k, v)| (k.clone(), v.rates()))
            .collect(),
        full_rule_reach_working_px: REACH_WORKING_PX,
        overall_full_rule: overall_full
            .iter()
            .map(|(k, v)| (k.clone(), v.rates()))
            .collect(),
        perturbations,
    };
    Ok(Evaluation {
        summary,
        censuses,
        frames_csv,
        skipped,
        perturb_times,
        dev_only: options.dev_only,
        sets,
        ranks,
        drawn,
    })
}

/// Tiles in the contact sheet.
const SHEET_TILES: usize = 12;

impl Evaluation {
    /// The tables of `summary.md` (with the census's when it was run); `command` is named in
    /// the title.
    pub fn markdown(&self, command: &str) -> String {
        let mut md = report::render_markdown(&self.summary, self.dev_only, command);
        if !self.censuses.is_empty() {
            md += &report::render_census(&self.censuses);
        }
        md += &report::render_full_rule(&self.summary, self.dev_only);
        if !self.summary.perturbations.is_empty() {
            md += &perturbed::render(&self.summary, self.dev_only);
        }
        md
    }

    /// Write the reports into `out` (created if needed): `frames.csv`, and unless
    /// [`Options::dev_only`] `summary.md`, `summary.json` and `worst_frames.png`. Returns the
    /// text of `summary.md` (the tables, then the list of the worst frames; the tables alone
    /// with `dev_only`).
    pub fn write(&self, out: &Path, command: &str) -> Result<String, BenchError> {
        std::fs::create_dir_all(out).map_err(|e| BenchError::io("create", out, e))?;
        let write = |name: &str, text: &str| {
            let path = out.join(name);
            std::fs::write(&path, text).map_err(|e| BenchError::io("write", &path, e))
        };
        let md = self.markdown(command);
        write("frames.csv", &self.frames_csv)?;
        if self.dev_only {
            return Ok(md);
        }
        let json =
            serde_json::to_string_pretty(&self.summary).map_err(|source| BenchError::Json {
                path: out.join("summary.json").display().to_string(),
                source,
            })?;
        write("summary.json", &(json + "\n"))?;
        let mut ranks: Vec<&FrameRank> = self.ranks.iter().collect();
        ranks.sort_by(|a, b| {
            a.accuracy
                .total_cmp(&b.accuracy)
                .then(b.false_positives.cmp(&a.false_positives))
        });
        ranks.truncate(SHEET_TILES);
        sheet::contact_sheet(
            &self.sets,
            &self.drawn,
            &ranks,
            &self.summary.rules,
            &out.join("worst_frames.png"),
        )?;
        let mut list =
            String::from("\nWorst frames of the default run (worst_frames.png, row by row):\n");
        for (k, r) in ranks.iter().enumerate() {
            let (_, set) = &self.sets[r.set];
            list += &format!(
                "{k:2}. {} {} (TuSimple {:.0} %, {} false positive{})\n",
                set.set,
                set.frames[r.frame].file,
                100.0 * r.accuracy,
                r.false_positives,
                if r.false_positives == 1 { "" } else { "s" }
            );
        }
        let md = md + &list;
        write("summary.md", &md)?;
        Ok(md)
    }
}
