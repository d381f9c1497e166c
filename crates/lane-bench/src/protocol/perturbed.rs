//! The perturbation table (`eval-lanes --perturb`): the default configuration on every set's
//! frames changed as other cameras would give them ([`crate::perturb::TABLE`]), scored on the
//! near band — the rows that were the near band before the perturbation, mapped
//! ([`crate::perturb`]) — per set and overall, development and held-out parts, beside the
//! unperturbed run. From the same runs, the bound of the default's choice under each
//! perturbation ([`crate::labelled::choice_bound_set`]'s *best*: per side the best of its output
//! and its candidates, picked by the labels): where even that bound loses more than a target
//! allows, no choice among the candidates can meet it, and the loss is the detection's.
//!
//! Each set's frames are decoded once and kept; each perturbation's frames are made from them
//! one at a time as the frame loop asks for them (a frame source over memory, never a file),
//! the labels mapped beforehand. The noise of a frame is seeded with
//! [`crate::perturb::frame_seed`] of [`crate::perturb::TABLE_SEED`], its set and its position.
//! A frame the unperturbed run skips (its image cannot be read) is skipped here too.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use lane_io::{GreyFrame, LaneIoError};
use lane_tracker::{Estimator, TrackerConfig};
use serde::{Deserialize, Serialize};

use super::{DEFAULT_NAME, SetSummary, SplitRates, SplitTotals, Summary, dev_count};
use crate::BenchError;
use crate::labelled::{
    FileStills, LabelFrame, LabelSet, LaneRates, LaneTotals, ScoringRules, Stills,
    best_of_candidates, ego_of, near_top_px, run_stills, score_sides_from,
};
use crate::perturb::{Perturbation, TABLE, TABLE_SEED, frame_seed};

/// The default under one perturbation, in `summary.json`.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct PerturbedSummary {
    /// Its name ([`Perturbation::name`]).
    pub perturbation: String,
    /// What it does.
    pub description: String,
    /// Per set.
    pub sets: BTreeMap<String, SplitRates>,
    /// Pooled over every set.
    pub overall: SplitRates,
    /// The bound of the default's choice under the perturbation
    /// ([`super::CHOICE_BOUND_NAME`]: per side the best of its output and its candidates,
    /// picked by the labels), per set; absent from files written before it.
    #[serde(default)]
    pub best_of_candidates_sets: BTreeMap<String, SplitRates>,
    /// … pooled over every set.
    #[serde(default)]
    pub best_of_candidates: SplitRates,
}

/// The frames of one set under one perturbation, made in memory from the decoded originals.
struct PerturbedStills<'a> {
    dir: &'a Path,
    set: &'a str,
    /// Per position in the set, the decoded image (`None`: it does not decode).
    originals: &'a [Option<GreyFrame>],
    perturbation: Perturbation,
}

impl Stills for PerturbedStills<'_> {
    fn fill(
        &mut self,
        position: usize,
        frame: &LabelFrame,
        out: &mut GreyFrame,
    ) -> Result<(), LaneIoError> {
        let name = self.name(frame);
        let seed = frame_seed(TABLE_SEED, self.set, position);
        let perturbed = match self.originals.get(position).and_then(Option::as_ref) {
            Some(original) => self.perturbation.perturb_image(original, seed, &name),
            None => {
                // Read again for the error the unperturbed run reported.
                let mut decoded = GreyFrame::default();
                FileStills(self.dir).fill(position, frame, &mut decoded)?;
                self.perturbation.perturb_image(&decoded, seed, &name)
            }
        };
        *out = perturbed.map_err(|e| match e {
            BenchError::Image { source, .. } => LaneIoError::ImageDecode { path: name, source },
            other => LaneIoError::Io {
                path: name,
                source: std::io::Error::other(crate::error::with_causes(&other)),
            },
        })?;
        Ok(())
    }

    fn name(&self, frame: &LabelFrame) -> String {
        format!(
            "{} ({})",
            LabelSet::frame_path(self.dir, frame).display(),
            self.perturbation.name()
        )
    }

    fn describe(&self) -> String {
        format!(
            "{} (labelled frames, {})",
            self.dir.display(),
            self.perturbation.name()
        )
    }
}

/// A perturbation's name and its wall time over every set.
pub type PerturbTime = (String, Duration);

/// The default `cfg` on every set of `sets` under every perturbation of [`TABLE`] (module
/// docs), with each perturbation's wall time over all sets.
pub(super) fn perturbation_table(
    sets: &[(PathBuf, LabelSet)],
    cfg: &TrackerConfig,
    rules: &ScoringRules,
) -> Result<(Vec<PerturbedSummary>, Vec<PerturbTime>), BenchError> {
    for p in &TABLE {
        p.validate()?;
    }
    let mut per_set: Vec<BTreeMap<String, SplitRates>> = vec![BTreeMap::new(); TABLE.len()];
    let mut overall = vec![SplitTotals::default(); TABLE.len()];
    let mut best_per_set: Vec<BTreeMap<String, SplitRates>> = vec![BTreeMap::new(); TABLE.len()];
    let mut best_overall = vec![SplitTotals::default(); TABLE.len()];
    let mut times = vec![Duration::ZERO; TABLE.len()];
    for (dir, set) in sets {
        let originals: Vec<Option<GreyFrame>> = set
            .frames
            .iter()
            .enumerate()
            .map(|(i, f)| {
                let mut frame = GreyFrame::default();
                FileStills(dir).fill(i, f, &mut frame).ok().map(|()| frame)
            })
            .collect();
        let n_dev = dev_count(set.frames.len());
        for (k, p) in TABLE.iter().enumerate() {
            let start = Instant::now();
            let (width, height) = p.size(set.width, set.height);
            let y_top = p.map_row(near_top_px(rules, set.height), set.width, set.height);
            let mapped = LabelSet {
                width,
                height,
                frames: set
                    .frames
                    .iter()
                    .map(|f| p.map_labels(f, set.width, set.height))
                    .collect(),
                ..set.clone()
            };
            let mut stills = PerturbedStills {
                dir,
                set: &set.set,
                originals: &originals,
                perturbation: *p,
            };
            let mut totals = SplitTotals::default();
            let mut best_totals = SplitTotals::default();
            let tus_px = rules.tusimple_px_at_1280 * width as f64 / 1280.0;
            let n = mapped.frames.len();
            run_stills(
                &mut stills,
                &mapped,
                cfg,
                Estimator::Kif,
                n,
                |i, labels, t| {
                    let prediction = t.map_or([None, None], |t| ego_of(&t.report));
                    let best = t.map_or([None, None], |t| {
                        best_of_candidates(t.tracker, &prediction, labels, y_top, tus_px).0
                    });
                    let score = |p| {
                        let sides = score_sides_from(labels, width, height, p, rules, y_top);
                        LaneTotals::of_frame(&sides)
                    };
                    totals.add(&score(&prediction), i < n_dev);
                    best_totals.add(&score(&best), i < n_dev);
                    Ok(())
                },
            )
            .map_err(|e| e.during(format!("set {} under {}", set.set, p.name())))?;
            overall[k].merge(&totals);
            per_set[k].insert(set.set.clone(), totals.rates());
            best_overall[k].merge(&best_totals);
            best_per_set[k].insert(set.set.clone(), best_totals.rates());
            times[k] += start.elapsed();
        }
    }
    let summaries = TABLE
        .iter()
        .zip(per_set.into_iter().zip(&overall))
        .zip(best_per_set.into_iter().zip(&best_overall))
        .map(
            |((p, (sets, all)), (best_sets, best_all))| PerturbedSummary {
                perturbation: p.name(),
                description: p.describe(),
                sets,
                overall: all.rates(),
                best_of_candidates_sets: best_sets,
                best_of_candidates: best_all.rates(),
            },
        )
        .collect();
    let times = TABLE.iter().map(Perturbation::name).zip(times).collect();
    Ok((summaries, times))
}

/// Percent with one decimal.
fn pct(x: f64) -> String {
    format!("{:.1}", 100.0 * x)
}

/// A signed difference in points.
fn delta(now: f64, before: f64) -> String {
    format!("{:+.1}", 100.0 * (now - before))
}

/// Which part of a set's figures a table shows.
type Pick = fn(&SplitRates) -> &LaneRates;

/// The perturbation tables of `summary.md`: overall, then per set; hold-out and development
/// parts (the development part alone with `dev_only`).
pub(super) fn render(s: &Summary, dev_only: bool) -> String {
    let parts: &[(&str, Pick)] = if dev_only {
        &[("dev", |r| &r.dev)]
    } else {
        &[("hold-out", |r| &r.holdout), ("dev", |r| &r.dev)]
    };
    let mut md = String::from(
        "\n## The default under perturbations (`--perturb`)\n\n\
         The default configuration on the frames changed as other cameras would give them \
         (`lane_bench::perturb`; labels mapped with the content), scored on the near band as it \
         was before the perturbation (mapped; what leaves the frame is not scored). TuSimple \
         accuracy and FP in %; Δ: perturbed − unperturbed, points.\n\n",
    );
    let Some(base) = s.overall.get(DEFAULT_NAME) else {
        return md;
    };
    md += "| perturbation | what |";
    for (part, _) in parts {
        md += &format!(" {part} lanes | {part} acc | Δ | {part} FP | Δ |");
    }
    md += "\n|---|---|";
    md += &"---|---|---|---|---|".repeat(parts.len());
    md += "\n| none | the frames as they are |";
    for (_, pick) in parts {
        let r = pick(base);
        md += &format!(
            " {} | {} | | {} | |",
            r.label_lanes,
            pct(r.tusimple_accuracy),
            pct(r.tusimple_fp)
        );
    }
    md += "\n";
    for p in &s.perturbations {
        md += &format!("| {} | {} |", p.perturbation, p.description);
        for (_, pick) in parts {
            let (r, b) = (pick(&p.overall), pick(base));
            md += &format!(
                " {} | {} | {} | {} | {} |",
                r.label_lanes,
                pct(r.tusimple_accuracy),
                delta(r.tusimple_accuracy, b.tusimple_accuracy),
                pct(r.tusimple_fp),
                delta(r.tusimple_fp, b.tusimple_fp)
            );
        }
        md += "\n";
    }
    md += &render_choice_bound(s, parts, base);
    for (part, pick) in parts {
        md +=
            &format!("\nPer set, {part} part: TuSimple accuracy / FP, % (Δ accuracy, points).\n\n");
        md += &per_set_header(s);
        md += &per_set_row(s, "none", |set| {
            let r = pick(set.results.get(DEFAULT_NAME)?);
            Some(format!(
                "{} / {}",
                pct(r.tusimple_accuracy),
                pct(r.tusimple_fp)
            ))
        });
        for p in &s.perturbations {
            md += &per_set_row(s, &p.perturbation, |set| {
                let (r, b) = (
                    pick(p.sets.get(&set.set)?),
                    pick(set.results.get(DEFAULT_NAME)?),
                );
                Some(format!(
                    "{} / {} ({})",
                    pct(r.tusimple_accuracy),
                    pct(r.tusimple_fp),
                    delta(r.tusimple_accuracy, b.tusimple_accuracy)
                ))
            });
        }
    }
    md
}

/// The bound of the default's choice under each perturbation: what the best of its candidates
/// reaches there, its change, and how far the default could at best stay from its unperturbed
/// figure with a perfect choice among those candidates.
fn render_choice_bound(s: &Summary, parts: &[(&str, Pick)], base: &SplitRates) -> String {
    let Some(base_best) = s.overall.get(super::CHOICE_BOUND_NAME) else {
        return String::new();
    };
    let mut md = format!(
        "\nThe bound of the default's choice under each perturbation ({}: per side the best of \
         its output and its candidates, picked by the labels; near band, TuSimple accuracy in \
         %). Δ: against the bound on the frames as they are; *bound on the default's Δ*: the \
         bound under the perturbation − the default on the frames as they are, the least any \
         choice among these candidates loses (a loss beyond the target there is the detection's, \
         not the choice's).\n\n| perturbation |",
        super::CHOICE_BOUND_NAME
    );
    for (part, _) in parts {
        md += &format!(" {part} best | Δ | bound on the default's Δ |");
    }
    md += "\n|---|";
    md += &"---|---|---|".repeat(parts.len());
    md += "\n| none |";
    for (_, pick) in parts {
        md += &format!(" {} | | |", pct(pick(base_best).tusimple_accuracy));
    }
    md += "\n";
    for p in &s.perturbations {
        md += &format!("| {} |", p.perturbation);
        for (_, pick) in parts {
            let (r, b, d) = (pick(&p.best_of_candidates), pick(base_best), pick(base));
            md += &format!(
                " {} | {} | {} |",
                pct(r.tusimple_accuracy),
                delta(r.tusimple_accuracy, b.tusimple_accuracy),
                delta(r.tusimple_accuracy, d.tusimple_accuracy)
            );
        }
        md += "\n";
    }
    for (part, pick) in parts {
        md += &format!(
            "\nPer set, {part} part: the default / the bound of its choice under each \
             perturbation, % (the bound − the default on the frames as they are, points).\n\n"
        );
        md += &per_set_header(s);
        for p in &s.perturbations {
            md += &per_set_row(s, &p.perturbation, |set| {
                let r = pick(p.sets.get(&set.set)?);
                let b = pick(p.best_of_candidates_sets.get(&set.set)?);
                let d = pick(set.results.get(DEFAULT_NAME)?);
                Some(format!(
                    "{} / {} ({})",
                    pct(r.tusimple_accuracy),
                    pct(b.tusimple_accuracy),
                    delta(b.tusimple_accuracy, d.tusimple_accuracy)
                ))
            });
        }
    }
    md
}

/// The head of a per-set table: a column per set of `s`.
fn per_set_header(s: &Summary) -> String {
    let mut md = String::from("| perturbation |");
    for set in &s.sets {
        md += &format!(" {} |", set.set);
    }
    md += "\n|---|";
    md += &"---|".repeat(s.sets.len());
    md + "\n"
}

/// One row of a per-set table: `name`, then `cell` of each set of `s` (blank where `None`).
fn per_set_row(s: &Summary, name: &str, cell: impl Fn(&SetSummary) -> Option<String>) -> String {
    let mut md = format!("| {name} |");
    for set in &s.sets {
        md += &format!(" {} |", cell(set).unwrap_or_default());
    }
    md + "\n"
}
