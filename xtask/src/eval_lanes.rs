//! `cargo xtask eval-lanes`: the lane tracker on real labelled frames (every set under the data
//! root, `--data DIR`, default `../shared/data/lanes`: third-party, never in the repository), scored
//! with the TuSimple and Aly rules of `lane_eval::labelled`, per set and overall, ego lanes.
//!
//! Every set is split once and for all: the first 70 % of its frames (in set order) are the
//! **development** part, the rest the **held-out** part; the tracker's defaults may be tuned on the
//! development part only, and the held-out figures are reported on their own. Scored: the ceiling (parabolas fitted to the labels over the ROI rows), the default
//! configuration (what `nav-app` runs with no `--config`), the presets, and the classic OpenCV
//! pipeline (`bench/opencv_peer.py`, in `target/opencv-venv`, made from PyPI on first use; `--no-peer`
//! leaves it out). The default's false positives are also split by what they lie on
//! (`lane_eval::labelled::FalsePositives`: a side without a label, another labelled marking, a
//! near miss, the rest). Writes
//! `summary.md`, `summary.json`, `worst_frames.png` (the worst frames of the default run:
//! labels green, nav-app red, the OpenCV peer blue) and `frames.csv` (the default run's outcome
//! per scored ego side of every frame, `lane_eval::labelled::score_sides`, and with `--census`
//! the stage where its label lane is lost, `lane_eval::labelled::census_lanes`; with
//! `--dev-only` the only file written, and of the development part alone). `--check` compares the default's figures with
//! the floors in `fixtures/expectations-lanes-real.json` and fails below them; `--record` writes
//! them (measured accuracy − 3 points, measured false positives + 3 points).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{Context, Result, bail};
use lane_eval::labelled::{
    EgoPrediction, LabelFrame, LabelSet, LabelSide, LaneCensus, LaneRates, LaneTotals,
    NEAR_MISS_FRACTION, ScoringRules, StageCensus, ceiling_prediction, census_lanes,
    choice_bound_set, score_sides, track_label_set,
};
use lane_tracker::{Estimator, TrackerConfig};
use serde::{Deserialize, Serialize};

use crate::paths::{resolve, workspace_root};

/// Arguments of `cargo xtask eval-lanes`.
#[derive(clap::Args, Debug)]
pub struct EvalLanesArgs {
    /// Directory of labelled sets (one sub-directory per set with a `labels.json`); relative
    /// paths are taken from the workspace root. Default: `lanes/` under the data root
    /// (`$ITA_NAV_DATA`, else `../shared/data`; `lane_eval::data`). Third-party data, never in
    /// the repository.
    #[arg(long = "data", alias = "sets")]
    data: Option<PathBuf>,
    /// Configurations scored beside the default: preset names or TOML files.
    #[arg(long = "config", default_values_t = ["outdoor".to_owned(), "indoor".to_owned()])]
    configs: Vec<String>,
    /// Output directory (relative paths are taken from the workspace root).
    #[arg(long, default_value = "target/eval-lanes")]
    out: PathBuf,
    /// Fail if the default configuration falls below the recorded floors.
    #[arg(long)]
    check: bool,
    /// Record the floors from this run (default configuration, all frames).
    #[arg(long)]
    record: bool,
    /// Print the development part only and write only its `frames.csv` (what tuning may look
    /// at).
    #[arg(long)]
    dev_only: bool,
    /// Do not run the OpenCV peer even if its venv exists.
    #[arg(long)]
    no_peer: bool,
    /// Also report where the default configuration loses the ego label lanes of the development
    /// part, stage by stage (`lane_eval::labelled::census_lanes`: no Hough candidate — and of
    /// those, no edge near the label — candidate not chosen, lost after the choice, found by the
    /// refinement).
    #[arg(long)]
    census: bool,
    /// Track each set's frames as one sequence, in set order, never reset between clips: a
    /// stress test of the tracking path (the labelled frames are stills seconds apart, so every
    /// frame is an abrupt change of scene the tracker has to notice), not an accuracy figure
    /// for video. Not with `--check` or `--record` (the floors are for the stills).
    #[arg(long)]
    one_sequence: bool,
}

/// Format version of `summary.json`.
const SUMMARY_SCHEMA: u32 = 2;
/// Fraction of every set's frames (the first ones, in set order) in the development part.
const DEV_FRACTION: f64 = 0.7;
/// Floors: measured accuracy minus this, measured false positives plus this.
const FLOOR_MARGIN: f64 = 0.03;
/// Name of the default configuration in the reports.
const DEFAULT_NAME: &str = "default";
/// Name of the ceiling (parabolas fitted to the labels over the ROI rows) in the reports.
const CEILING_NAME: &str = "ceiling";
/// Name of the bound of the default's choice (`lane_eval::labelled::choice_bound_set`: per
/// side, the best of its output and its Hough candidates, picked by the labels).
const CHOICE_BOUND_NAME: &str = "best-of-candidates";
/// … and reporting nothing where that best lane has fewer than half its label's points within
/// the tolerance (`ChoiceBound::best_or_none`).
const CHOICE_BOUND_OR_NONE_NAME: &str = "best-of-candidates-or-none";
/// What the OpenCV peer's virtual environment (`target/opencv-venv`) holds, from PyPI.
const PEER_REQUIREMENTS: &[&str] = &["opencv-python-headless<5", "numpy"];
/// Name of the OpenCV peer in the reports.
const PEER_NAME: &str = "opencv-peer";
/// Tiles in the contact sheet.
const SHEET_TILES: usize = 12;

/// One configuration's figures on one set (or overall).
#[derive(Debug, Clone, Serialize, Deserialize)]
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
}

/// Floors of one set (default configuration, every frame).
#[derive(Debug, Clone, Copy, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct Floor {
    tusimple_accuracy_min: f64,
    tusimple_fp_max: f64,
    aly_detection_rate_min: f64,
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

/// The census table (`--census`): per set and overall, development part, default configuration.
fn render_census(censuses: &[(String, StageCensus)]) -> String {
    let mut md = String::from(
        "\n## Where the default loses the development part's ego lanes (`--census`)\n\n\
         Label lanes on frames with a joint initialisation, by the TuSimple rule \
         (`lane_eval::labelled::census_lanes`).\n\n\
         | set | label lanes | matched | … found by the refinement | no Hough candidate | \
         … no edge near the label | candidate not chosen | lost after the choice | \
         not classified |\n\
         |---|---|---|---|---|---|---|---|---|\n",
    );
    let mut total = StageCensus::default();
    let row = |name: &str, c: &StageCensus| {
        format!(
            "| {name} | {} | {} | {} | {} | {} | {} | {} | {} |\n",
            c.label_lanes,
            c.matched,
            c.found_by_refinement,
            c.no_candidate,
            c.no_edge_near_label,
            c.not_chosen,
            c.lost_after_choice,
            c.not_classified
        )
    };
    for (name, c) in censuses {
        md += &row(name, c);
        total.add(c);
    }
    md += &row("**overall**", &total);
    md
}

/// Frames `0..dev_count(n)` of a set of `n` are the development part.
pub(crate) fn dev_count(n: usize) -> usize {
    (DEV_FRACTION * n as f64).ceil() as usize
}

/// Header of `frames.csv` (one row per scored ego side of every frame, default configuration).
const FRAMES_CSV_HEADER: &str = "set,file,split,side,label,predicted,tusimple_accuracy,\
tusimple_matched,aly_matched,false_positive,mean_abs_error_px,census_stage\n";

/// The `frames.csv` rows of one frame from its sides' scores `sides` (left, right;
/// `lane_eval::labelled::score_sides`): one per ego side that the scorer scores (a label lane in
/// the scored rows, or a prediction on a side without one); empty fields where there is no label lane (accuracy, matches) or no
/// prediction (error); `false_positive` names the kind of an unmatched prediction
/// (`lane_eval::labelled::FalsePositives`), empty otherwise; `census_stage` the stage where the
/// side's label lane is lost (`lane_eval::labelled::LaneStage`) when `census` (the set's, with
/// `--census`: development part) classifies the frame at `position`, empty otherwise.
fn side_rows(
    set: &LabelSet,
    f: &LabelFrame,
    position: usize,
    dev: bool,
    sides: &[LaneTotals; 2],
    census: &[LaneCensus],
) -> String {
    let mut rows = String::new();
    for (k, (side, name)) in [(LabelSide::Left, "left"), (LabelSide::Right, "right")]
        .into_iter()
        .enumerate()
    {
        let t = &sides[k];
        if t.label_lanes + t.predicted_lanes == 0 {
            continue;
        }
        let fp = &t.false_positives;
        let kind = [
            (fp.unlabelled_side, "unlabelled_side"),
            (fp.other_marking, "other_marking"),
            (fp.near, "near"),
            (fp.far, "far"),
        ]
        .into_iter()
        .find(|(n, _)| *n > 0)
        .map_or("", |(_, kind)| kind);
        let labelled = t.label_lanes > 0;
        let on_label = |v: String| if labelled { v } else { String::new() };
        let error = if t.abs_err_points > 0 {
            format!("{:.2}", t.abs_err_sum_px / t.abs_err_points as f64)
        } else {
            String::new()
        };
        let stage = census
            .iter()
            .find(|c| c.position == position && c.side == side)
            .map_or("", |c| c.stage.name());
        rows += &format!(
            "{},{},{},{name},{},{},{},{},{},{kind},{error},{stage}\n",
            csv_field(&set.set),
            csv_field(&f.file),
            if dev { "dev" } else { "hold-out" },
            u8::from(labelled),
            t.predicted_lanes,
            on_label(format!("{:.4}", t.tusimple_acc_sum)),
            on_label(t.tusimple_matched.to_string()),
            on_label(t.aly_matched.to_string()),
        );
    }
    rows
}

/// `v` as one CSV field (RFC 4180): quoted, with its quotes doubled, when it holds a comma, a
/// quote or a line break.
fn csv_field(v: &str) -> std::borrow::Cow<'_, str> {
    if v.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", v.replace('"', "\"\"")).into()
    } else {
        v.into()
    }
}

/// A scored frame of the default run, for the contact sheet.
struct FrameRank {
    set: usize,
    frame: usize,
    accuracy: f64,
    false_positives: u64,
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

/// The labelled sets under `dir`, sorted by name.
pub(crate) fn find_sets(dir: &Path) -> Result<Vec<(PathBuf, LabelSet)>> {
    let mut dirs: Vec<PathBuf> = std::fs::read_dir(dir)
        .with_context(|| format!("cannot read {}", dir.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.join("labels.json").is_file())
        .collect();
    dirs.sort();
    if dirs.is_empty() {
        bail!("{}: no labelled set (no */labels.json)", dir.display());
    }
    dirs.into_iter()
        .map(|d| {
            let set = LabelSet::load(&d)?;
            Ok((d, set))
        })
        .collect()
}

/// The peer's `(frame index, prediction)` per frame (its virtual environment made on first use).
fn run_peer(root: &Path, set_dir: &Path, out: &Path) -> Result<Option<Vec<(u64, EgoPrediction)>>> {
    let python = crate::python::ensure_venv_with(
        root,
        "opencv-venv",
        PEER_REQUIREMENTS,
        "import cv2, numpy",
        None,
    )?;
    let status = Command::new(&python)
        .arg(root.join("bench/opencv_peer.py"))
        .arg("--predict-set")
        .arg(set_dir)
        .arg("--out")
        .arg(out)
        .status()
        .with_context(|| format!("cannot start {}", python.display()))?;
    if !status.success() {
        bail!("opencv peer failed on {} ({status})", set_dir.display());
    }
    let text =
        std::fs::read_to_string(out).with_context(|| format!("cannot read {}", out.display()))?;
    let file: PeerFile =
        serde_json::from_str(&text).with_context(|| format!("{}: bad JSON", out.display()))?;
    Ok(Some(
        file.frames
            .into_iter()
            .map(|f| (f.index, f.lanes))
            .collect(),
    ))
}

/// Run `cargo xtask eval-lanes`.
pub fn run(args: EvalLanesArgs) -> Result<()> {
    let root = workspace_root();
    let sets_dir = match &args.data {
        Some(dir) => resolve(&root, dir),
        None => lane_eval::data::data_root().join(lane_eval::data::LANE_SETS),
    };
    if !sets_dir.is_dir() {
        bail!(
            "{}: missing the labelled lane sets (third-party evaluation data, not in the \
             repository): put the shared data root beside the checkout as ../shared/data, name it \
             with ITA_NAV_DATA, or pass --data DIR",
            sets_dir.display()
        );
    }
    let out = resolve(&root, &args.out);
    std::fs::create_dir_all(&out).with_context(|| format!("cannot create {}", out.display()))?;
    if args.one_sequence && (args.check || args.record) {
        bail!("--one-sequence is a stress test: the floors (--check, --record) are for the stills");
    }
    let mut sets = find_sets(&sets_dir)?;
    if args.one_sequence {
        for (_, set) in &mut sets {
            let one = format!("{}-one-sequence", set.set);
            for f in &mut set.frames {
                f.clip.clone_from(&one);
            }
        }
    }
    let rules = ScoringRules::default();

    let mut configs: Vec<(String, TrackerConfig)> =
        vec![(DEFAULT_NAME.to_owned(), TrackerConfig::default_preset()?)];
    for c in &args.configs {
        configs.push((c.clone(), lane_io::config::load_tracker_config(c)?));
    }

    let mut summaries = Vec::new();
    let mut censuses: Vec<(String, StageCensus)> = Vec::new();
    let mut overall: BTreeMap<String, SplitTotals> = BTreeMap::new();
    let mut ranks = Vec::new();
    let mut drawn: Vec<(Vec<EgoPrediction>, Option<Vec<EgoPrediction>>)> = Vec::new();
    let mut frames_csv = String::from(FRAMES_CSV_HEADER);
    for (si, (dir, set)) in sets.iter().enumerate() {
        let n_dev = dev_count(set.frames.len());
        let lanes_census = if args.census {
            let lanes = census_lanes(dir, set, &configs[0].1, Estimator::Kif, 0..n_dev, &rules)
                .with_context(|| format!("census of set {}", set.set))?;
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
        let bound = choice_bound_set(dir, set, &configs[0].1, Estimator::Kif, &rules)
            .with_context(|| format!("set {} with config {DEFAULT_NAME}", set.set))?;
        runs.push((DEFAULT_NAME.to_owned(), bound.output));
        for (name, cfg) in configs.iter().skip(1) {
            let preds = track_label_set(dir, set, cfg, Estimator::Kif)
                .with_context(|| format!("set {} with config {name}", set.set))?;
            runs.push((name.clone(), preds));
        }
        let peer = if args.no_peer {
            None
        } else {
            run_peer(&root, dir, &out.join(format!("peer-{}.json", set.set)))?
        };
        let peer: Option<Vec<EgoPrediction>> = match peer {
            Some(p) => {
                let same = p.len() == set.frames.len()
                    && p.iter().zip(&set.frames).all(|((i, _), f)| *i == f.index);
                if !same {
                    bail!("opencv peer's frames do not match set {}", set.set);
                }
                let p: Vec<EgoPrediction> = p.into_iter().map(|(_, l)| l).collect();
                runs.push((PEER_NAME.to_owned(), p.clone()));
                Some(p)
            }
            None => None,
        };
        // The ceiling: a parabola fitted to the labels themselves over the default's ROI rows
        // (the tracker's, in this set's pixels: a wide frame's working rows mapped back),
        // scored by the same rules (what the lane model can reach on this set).
        let roi =
            lane_tracker::LaneTracker::new(&configs[0].1, Estimator::Kif, set.width, set.height)
                .with_context(|| {
                    format!("{}: no tracker for {}×{}", set.set, set.width, set.height)
                })?
                .roi_rows();
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
                if name == DEFAULT_NAME && (i < n_dev || !args.dev_only) {
                    frames_csv += &side_rows(set, f, i, i < n_dev, &sides, &lanes_census);
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
        });
    }
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
    };

    let mut md = render_markdown(&summary, args.dev_only);
    if args.census {
        md += &render_census(&censuses);
    }
    print!("{md}");
    let frames_path = out.join("frames.csv");
    std::fs::write(&frames_path, &frames_csv)
        .with_context(|| format!("cannot write {}", frames_path.display()))?;
    if !args.dev_only {
        std::fs::write(out.join("summary.md"), &md)?;
        std::fs::write(
            out.join("summary.json"),
            serde_json::to_string_pretty(&summary)? + "\n",
        )?;
        ranks.sort_by(|a, b| {
            a.accuracy
                .total_cmp(&b.accuracy)
                .then(b.false_positives.cmp(&a.false_positives))
        });
        ranks.truncate(SHEET_TILES);
        let sheet = out.join("worst_frames.png");
        contact_sheet(&sets, &drawn, &ranks, &rules, &sheet)?;
        let mut list =
            String::from("\nWorst frames of the default run (worst_frames.png, row by row):\n");
        for (k, r) in ranks.iter().enumerate() {
            let (_, set) = &sets[r.set];
            list += &format!(
                "{k:2}. {} {} (TuSimple {:.0} %, {} false positive{})\n",
                set.set,
                set.frames[r.frame].file,
                100.0 * r.accuracy,
                r.false_positives,
                if r.false_positives == 1 { "" } else { "s" }
            );
        }
        print!("{list}");
        std::fs::write(out.join("summary.md"), md + &list)?;
        println!("eval-lanes: wrote {}", out.display());
    }

    let floors_path = root.join("fixtures/expectations-lanes-real.json");
    if args.record {
        let mut floors = BTreeMap::new();
        for s in &summary.sets {
            let r = &s.results[DEFAULT_NAME].all;
            floors.insert(s.set.clone(), floor_of(r));
        }
        floors.insert(
            "overall".to_owned(),
            floor_of(&summary.overall[DEFAULT_NAME].all),
        );
        std::fs::write(&floors_path, serde_json::to_string_pretty(&floors)? + "\n")?;
        println!("eval-lanes: recorded {}", floors_path.display());
    }
    if args.check {
        let text = std::fs::read_to_string(&floors_path)
            .with_context(|| format!("cannot read {}", floors_path.display()))?;
        let floors: BTreeMap<String, Floor> = serde_json::from_str(&text)
            .with_context(|| format!("{}: bad floors", floors_path.display()))?;
        let mut failures = Vec::new();
        for (name, floor) in &floors {
            let rates = if name == "overall" {
                summary.overall[DEFAULT_NAME].all
            } else {
                match summary.sets.iter().find(|s| &s.set == name) {
                    Some(s) => s.results[DEFAULT_NAME].all,
                    None => {
                        failures.push(format!("{name}: set missing"));
                        continue;
                    }
                }
            };
            if rates.tusimple_accuracy < floor.tusimple_accuracy_min {
                failures.push(format!(
                    "{name}: TuSimple accuracy {:.3} < floor {:.3}",
                    rates.tusimple_accuracy, floor.tusimple_accuracy_min
                ));
            }
            if rates.tusimple_fp > floor.tusimple_fp_max {
                failures.push(format!(
                    "{name}: false positives {:.3} > ceiling {:.3}",
                    rates.tusimple_fp, floor.tusimple_fp_max
                ));
            }
            if rates.aly_detection_rate < floor.aly_detection_rate_min {
                failures.push(format!(
                    "{name}: Aly detection rate {:.3} < floor {:.3}",
                    rates.aly_detection_rate, floor.aly_detection_rate_min
                ));
            }
        }
        if !failures.is_empty() {
            bail!("eval-lanes: below the floors:\n  {}", failures.join("\n  "));
        }
        println!("eval-lanes: {} floors held", floors.len());
    }
    Ok(())
}

fn floor_of(r: &LaneRates) -> Floor {
    let round = |x: f64| (x * 1000.0).round() / 1000.0;
    Floor {
        tusimple_accuracy_min: round((r.tusimple_accuracy - FLOOR_MARGIN).max(0.0)),
        tusimple_fp_max: round((r.tusimple_fp + FLOOR_MARGIN).min(1.0)),
        aly_detection_rate_min: round((r.aly_detection_rate - FLOOR_MARGIN).max(0.0)),
    }
}

fn pct(x: f64) -> String {
    format!("{:.1}", 100.0 * x)
}

/// Which part of a set's figures a table row shows.
type Pick = fn(&SplitRates) -> &LaneRates;

fn render_markdown(s: &Summary, dev_only: bool) -> String {
    let mut md = String::new();
    md += "# Lane tracker on real labelled frames (`cargo xtask eval-lanes`)\n\n";
    md += &format!(
        "Ego lanes; label points below {:.0} % of the height. TuSimple: point within {} px at 1280 px \
         width (scaled, slope-corrected), lane matched at ≥ {:.0} % of its points; accuracy, FP and FN \
         in %. Aly: median nearest-point distance ≤ {} px at 640 px width; detection rate and false \
         detections per label lane in %. dev = first {:.0} % of each set's frames, hold-out = the rest \
         (never used for tuning).\n\n",
        100.0 * s.rules.eval_top_fraction,
        s.rules.tusimple_px_at_1280,
        100.0 * s.rules.tusimple_match_fraction,
        s.rules.aly_px_at_640,
        100.0 * s.dev_fraction
    );
    let splits: &[(&str, Pick)] = if dev_only {
        &[("dev", |r| &r.dev)]
    } else {
        &[
            ("all", |r| &r.all),
            ("dev", |r| &r.dev),
            ("hold-out", |r| &r.holdout),
        ]
    };
    md += "| set | kind | frames (longest clip) | config | split | lanes | TuSimple acc | FP | FN | Aly det. | Aly false/label | mean err px |\n";
    md += "|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    let row = |md: &mut String,
               set: &str,
               kind: &str,
               frames: &str,
               cfg: &str,
               split: &str,
               r: &LaneRates| {
        *md += &format!(
            "| {set} | {kind} | {frames} | {cfg} | {split} | {} | {} | {} | {} | {} | {} | {:.2} |\n",
            r.label_lanes,
            pct(r.tusimple_accuracy),
            pct(r.tusimple_fp),
            pct(r.tusimple_fn),
            pct(r.aly_detection_rate),
            pct(r.aly_false_per_label),
            r.mean_abs_error_px
        );
    };
    for set in &s.sets {
        for (cfg, rates) in &set.results {
            for (split, pick) in splits {
                row(
                    &mut md,
                    &set.set,
                    &set.kind,
                    &format!("{} ({})", set.frames, set.longest_clip),
                    cfg,
                    split,
                    pick(rates),
                );
            }
        }
    }
    let frames: usize = s.sets.iter().map(|x| x.frames).sum();
    for (cfg, rates) in &s.overall {
        for (split, pick) in splits {
            row(
                &mut md,
                "**overall**",
                "",
                &frames.to_string(),
                cfg,
                split,
                pick(rates),
            );
        }
    }
    md += &render_false_positives(s, splits);
    md
}

/// The default's unmatched predictions by kind (`lane_eval::labelled::FalsePositives`), per set
/// and overall, for each of `splits`.
fn render_false_positives(s: &Summary, splits: &[(&str, Pick)]) -> String {
    let mut md = format!(
        "\nFalse positives of the default (TuSimple: predictions not matched) by what they lie on: \
         a side with no label lane; another labelled marking (the other side's label or an unscored \
         one: a neighbour's mark, or the sides swapped); near (≥ {:.0} % of the label's points within \
         the tolerance); far (the rest).\n\n\
         | set | split | predictions | false positives | no label on the side | another marking | near | far |\n\
         |---|---|---|---|---|---|---|---|\n",
        100.0 * NEAR_MISS_FRACTION
    );
    let named = s
        .sets
        .iter()
        .filter_map(|set| Some((set.set.as_str(), set.results.get(DEFAULT_NAME)?)))
        .chain(s.overall.get(DEFAULT_NAME).map(|r| ("**overall**", r)));
    for (name, rates) in named {
        for (split, pick) in splits {
            let r = pick(rates);
            let k = r.false_positives;
            md += &format!(
                "| {name} | {split} | {} | {} | {} | {} | {} | {} |\n",
                r.predicted_lanes,
                k.total(),
                k.unlabelled_side,
                k.other_marking,
                k.near,
                k.far
            );
        }
    }
    md
}

/// Draw `ranks` (worst first) as a 4-column grid of 320×240 tiles: label points (ego green,
/// others dark green), nav-app's default lanes red, the peer's blue.
fn contact_sheet(
    sets: &[(PathBuf, LabelSet)],
    drawn: &[(Vec<EgoPrediction>, Option<Vec<EgoPrediction>>)],
    ranks: &[FrameRank],
    rules: &ScoringRules,
    path: &Path,
) -> Result<()> {
    const TW: u32 = 320;
    const TH: u32 = 240;
    const COLS: u32 = 4;
    let rows = (ranks.len() as u32).div_ceil(COLS).max(1);
    let mut sheet = image::RgbImage::new(TW * COLS, TH * rows);
    for (k, r) in ranks.iter().enumerate() {
        let (dir, set) = &sets[r.set];
        let f: &LabelFrame = &set.frames[r.frame];
        let grey = image::open(LabelSet::frame_path(dir, f))
            .with_context(|| format!("cannot read {}", f.file))?
            .to_luma8();
        let (ox, oy) = ((k as u32 % COLS) * TW, (k as u32 / COLS) * TH);
        let mut put = |x: f64, y: f64, c: [u8; 3]| {
            if x >= 0.0 && y >= 0.0 && x < f64::from(TW) && y < f64::from(TH) {
                sheet.put_pixel(ox + x as u32, oy + y as u32, image::Rgb(c));
            }
        };
        for (x, y, p) in grey.enumerate_pixels() {
            if x < TW && y < TH {
                put(f64::from(x), f64::from(y), [p[0]; 3]);
            }
        }
        let y_top = rules.eval_top_fraction * set.height as f64;
        // A dotted line marks the top of the scored band.
        for x in (0..set.width).step_by(4) {
            put(x as f64, y_top, [255, 255, 0]);
        }
        for lane in &f.lanes {
            let c = if lane.side == LabelSide::Other {
                [0, 120, 0]
            } else {
                [0, 255, 0]
            };
            for &[x, y] in &lane.points {
                for (dx, dy) in [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)] {
                    put(x + dx, y + dy, c);
                }
            }
        }
        let (ours, peer) = &drawn[r.set];
        let mut curves: Vec<([f64; 3], [u8; 3])> = Vec::new();
        for c in ours[r.frame].iter().flatten() {
            curves.push((*c, [255, 40, 40]));
        }
        if let Some(p) = peer {
            for c in p[r.frame].iter().flatten() {
                curves.push((*c, [60, 120, 255]));
            }
        }
        for ([a1, a2, a3], col) in curves {
            let y0 = (0.4 * set.height as f64) as usize;
            for y in y0..set.height {
                let yf = y as f64;
                put((a1 * yf + a2) * yf + a3, yf, col);
            }
        }
    }
    sheet
        .save(path)
        .with_context(|| format!("cannot write {}", path.display()))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use lane_eval::labelled::{
        LabelFrame, LabelLane, LabelSet, LabelSide, LaneCensus, LaneStage, SceneKind, ScoringRules,
    };

    use lane_eval::labelled::{EgoPrediction, score_sides};

    use super::{FRAMES_CSV_HEADER, side_rows};

    /// `frames.csv`'s rows of frame `f` at `position` for prediction `p`, scored as `eval-lanes`
    /// scores it.
    fn rows(
        f: &LabelFrame,
        position: usize,
        dev: bool,
        p: &EgoPrediction,
        census: &[LaneCensus],
    ) -> String {
        let set = set();
        let sides = score_sides(f, set.width, set.height, p, &ScoringRules::default());
        side_rows(&set, f, position, dev, &sides, census)
    }

    fn set() -> LabelSet {
        LabelSet {
            schema: 1,
            set: "my,set".into(),
            kind: SceneKind::Road,
            source: String::new(),
            licence: String::new(),
            width: 320,
            height: 240,
            frames: Vec::new(),
        }
    }

    #[test]
    fn frame_rows_give_one_row_per_scored_side_with_its_outcome() {
        // Left label x = 100 on rows 150..240, right label only in the far field (not scored).
        let f = LabelFrame {
            index: 3,
            file: "frames/a\"b.png".into(),
            clip: "c".into(),
            lanes: vec![
                LabelLane {
                    side: LabelSide::Left,
                    points: (150..240).map(|y| [100.0, f64::from(y)]).collect(),
                },
                LabelLane {
                    side: LabelSide::Right,
                    points: (0..40).map(|y| [250.0, f64::from(y)]).collect(),
                },
            ],
        };
        let columns = FRAMES_CSV_HEADER.trim_end().split(',').count();
        // On the label: matched; the far-field right side gives no row.
        let got = rows(
            &f,
            3,
            true,
            &[Some([0.0, 0.0, 101.0]), Some([0.0, 0.0, 0.0])],
            &[],
        );
        assert_eq!(
            got,
            "\"my,set\",\"frames/a\"\"b.png\",dev,left,1,1,1.0000,1,1,,1.00,\n"
        );
        // The census's stage of this frame's side, not of another frame's or side's.
        let census = |position, side, stage| LaneCensus {
            position,
            side,
            stage,
        };
        let stages = [
            census(2, LabelSide::Left, LaneStage::NotChosen),
            census(3, LabelSide::Right, LaneStage::NoCandidate),
            census(3, LabelSide::Left, LaneStage::FoundByRefinement),
        ];
        let got = rows(&f, 3, true, &[Some([0.0, 0.0, 101.0]), None], &stages);
        assert!(got.ends_with(",1.00,found_by_refinement\n"), "{got}");
        let got = rows(&f, 2, true, &[None, None], &stages);
        assert!(got.ends_with(",,not_chosen\n"), "{got}");
        // 40 px off: a far false positive; no prediction: a missed label with no error.
        let got = rows(&f, 3, false, &[Some([0.0, 0.0, 140.0]), None], &[]);
        assert_eq!(
            got,
            "\"my,set\",\"frames/a\"\"b.png\",hold-out,left,1,1,0.0000,0,0,far,40.00,\n"
        );
        let got = rows(&f, 3, false, &[None, None], &[]);
        assert!(got.ends_with(",hold-out,left,1,0,0.0000,0,0,,,\n"), "{got}");
        // Only the left label: a right prediction is scored on its own row, unlabelled.
        let mut left_only = f.clone();
        left_only.lanes.truncate(1);
        let got = rows(&left_only, 3, true, &[None, Some([0.0, 0.0, 250.0])], &[]);
        let lines: Vec<&str> = got.lines().collect();
        assert_eq!(lines.len(), 2);
        assert!(
            lines[1].ends_with(",dev,right,0,1,,,,unlabelled_side,,"),
            "{got}"
        );
        // Every row has the header's columns (the quoted fields hold commas).
        for l in lines {
            let unquoted = l.replace("\"my,set\"", "s");
            assert_eq!(unquoted.split(',').count(), columns, "{l}");
        }
    }
}
