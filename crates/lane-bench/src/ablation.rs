//! The ablation: does each mechanism the default adds to the paper earn its place?
//!
//! Every mechanism beyond the paper ([`mechanisms`]) is switched off in turn (the default
//! otherwise) and tried at a few other values of its setting, on every labelled set. Each variant
//! is one run of the tracker over every set ([`run_variant`]); its frames are scored with the
//! TuSimple rule per set and part (development: the first 70 % of a set's frames; hold-out: the
//! rest), as `eval-lanes` scores them, and every set's frames are also tracked as one sequence
//! (the stress test of `eval-lanes --one-sequence`).
//!
//! Two gains per mechanism and set, in TuSimple accuracy points ([`render`]):
//!
//! - **ablation**: the default against the default with the mechanism off, on the set's
//!   development and hold-out parts;
//! - **leave-one-set-out** (LOSO, [`loso`]): the mechanism's value chosen on the *other* sets'
//!   development parts (the variant, off included, with the best accuracy over their label lanes
//!   together; a tie keeps it off), then its gain over off on the held set, all its frames.
//!
//! The mean of the LOSO gains over the sets (each set weighing alike, and pooled by label lanes)
//! is the mechanism's LOSO gain; issue 52 keeps a mechanism that gains at least 0.5 points there
//! or that a robustness test needs. `cargo xtask ablation` runs it;
//! `docs/results/ablation.md` is its output, checked in.

use std::collections::BTreeMap;
use std::path::PathBuf;

use lane_tracker::{Estimator, TrackerConfig};
use serde::Serialize;

use crate::BenchError;
use crate::labelled::{LabelSet, LaneTotals, ScoringRules, score_sides, track_label_set};
use crate::protocol::dev_count;

/// A setting of one mechanism: its label and how it changes the default.
pub struct Value {
    /// As the tables show it.
    pub label: &'static str,
    /// The change to the default.
    pub set: fn(&mut TrackerConfig),
}

/// A mechanism beyond the paper: its name, its configuration keys, its off value (the paper's
/// behaviour), and other values tried.
pub struct Mechanism {
    /// As the tables show it.
    pub name: &'static str,
    /// Its keys in `configs/default.toml`.
    pub keys: &'static str,
    /// The paper's behaviour.
    pub off: Value,
    /// Other values tried beside the default's.
    pub others: &'static [Value],
}

macro_rules! value {
    ($label:expr, |$c:ident| $body:expr) => {
        Value {
            label: $label,
            set: |$c: &mut TrackerConfig| {
                $body;
            },
        }
    };
}

/// The mechanisms, in the pipeline's order (and two groups of them off together).
pub fn mechanisms() -> Vec<Mechanism> {
    vec![
        Mechanism {
            name: "working resolution",
            keys: "frame.working_width_px",
            off: value!("0 (input size)", |c| c.frame.working_width_px = 0),
            others: &[],
        },
        Mechanism {
            name: "the road's bottom found",
            keys: "roi.road_bottom",
            off: value!("frame", |c| c.roi.road_bottom =
                lane_tracker::RoadBottom::Frame),
            others: &[],
        },
        Mechanism {
            name: "dark frames brightened",
            keys: "exposure.below_median_grey",
            off: value!("0 (never)", |c| c.exposure.below_median_grey = 0.0),
            others: &[
                value!("40 grey levels", |c| c.exposure.below_median_grey = 40.0),
                value!("60 grey levels", |c| c.exposure.below_median_grey = 60.0),
            ],
        },
        Mechanism {
            name: "noisy frames smoothed",
            keys: "denoise.above_noise_grey",
            off: value!("0 (never)", |c| c.denoise.above_noise_grey = 0.0),
            others: &[
                value!("3 grey levels", |c| c.denoise.above_noise_grey = 3.0),
                value!("6 grey levels", |c| c.denoise.above_noise_grey = 6.0),
            ],
        },
        Mechanism {
            name: "bright-stripe pairing",
            keys: "gradient.stripe_max_width_px, stripe_paired_votes",
            // (The kerb's foot and the stripe trace read up to the stripe width: off with it.)
            off: value!("width 0, no kerb foot, no trace", |c| {
                c.gradient.stripe_max_width_px = 0;
                c.init.kerb_foot = false;
                c.init.stripe_trace = false
            }),
            others: &[
                value!("votes 0 (unpaired dropped)", |c| c
                    .gradient
                    .stripe_paired_votes =
                    0),
                value!("votes 2", |c| c.gradient.stripe_paired_votes = 2),
                value!("votes 4", |c| c.gradient.stripe_paired_votes = 4),
                value!("width 8", |c| c.gradient.stripe_max_width_px = 8),
                value!("width 24", |c| c.gradient.stripe_max_width_px = 24),
            ],
        },
        Mechanism {
            name: "periodic stripes dropped",
            keys: "gradient.periodic_min_stripes, periodic_max_width_px",
            off: value!("0", |c| c.gradient.periodic_min_stripes = 0),
            others: &[
                value!("3", |c| c.gradient.periodic_min_stripes = 3),
                value!("6", |c| c.gradient.periodic_min_stripes = 6),
            ],
        },
        Mechanism {
            name: "second search (taller rows)",
            keys: "roi.fallback_top_row_fraction",
            off: value!("none", |c| c.roi.fallback_top_row_fraction = None),
            others: &[
                value!("0.2", |c| c.roi.fallback_top_row_fraction = Some(0.2)),
                value!("0.45", |c| c.roi.fallback_top_row_fraction = Some(0.45)),
            ],
        },
        Mechanism {
            name: "joint initialisation (candidates, ego pair)",
            keys: "init.candidate_lines, candidate_separation_*, [init.ego_pair]",
            off: value!("0 (paper: one line per band)", |c| c.init.candidate_lines =
                0),
            others: &[
                value!("4", |c| c.init.candidate_lines = 4),
                value!("6", |c| c.init.candidate_lines = 6),
            ],
        },
        Mechanism {
            name: "orientation-restricted Hough vote",
            keys: "init.orientation_tolerance_deg",
            off: value!("0", |c| c.init.orientation_tolerance_deg = 0.0),
            others: &[
                value!("10°", |c| c.init.orientation_tolerance_deg = 10.0),
                value!("25°", |c| c.init.orientation_tolerance_deg = 25.0),
            ],
        },
        Mechanism {
            name: "row coverage (candidates weighed by their parabola)",
            keys: "init.candidate_coverage",
            off: value!("false", |c| c.init.candidate_coverage = false),
            others: &[],
        },
        Mechanism {
            name: "ego pair may meet in the ROI's top rows",
            keys: "init.ego_pair.meet_top_frac",
            off: value!("0", |c| c.init.ego_pair.meet_top_frac = 0.0),
            others: &[value!("0.4", |c| c.init.ego_pair.meet_top_frac = 0.4)],
        },
        Mechanism {
            name: "refinement (wider window, passes)",
            keys: "track.refine_window_half_width_px, refine_passes",
            off: value!("window 0, 1 pass", |c| {
                c.track.refine_window_half_width_px = 0;
                c.track.refine_passes = 1
            }),
            others: &[
                value!("window 15", |c| c.track.refine_window_half_width_px = 15),
                value!("3 passes", |c| c.track.refine_passes = 3),
            ],
        },
        Mechanism {
            name: "stripe middles in the refinement",
            keys: "track.stripe_middles",
            off: value!("false", |c| c.track.stripe_middles = false),
            others: &[],
        },
        Mechanism {
            name: "stripe trace",
            keys: "init.stripe_trace",
            off: value!("false", |c| c.init.stripe_trace = false),
            others: &[],
        },
        Mechanism {
            name: "no turn back",
            keys: "init.no_turn_back",
            off: value!("false", |c| c.init.no_turn_back = false),
            others: &[],
        },
        Mechanism {
            name: "double line's middle",
            keys: "init.double_line_middle",
            off: value!("false", |c| c.init.double_line_middle = false),
            others: &[],
        },
        Mechanism {
            name: "kerb's foot",
            keys: "init.kerb_foot",
            off: value!("false", |c| c.init.kerb_foot = false),
            others: &[],
        },
        // The four below the bar one at a time, off together: they interact (measured).
        Mechanism {
            name: "together: the refinement's readings",
            keys: "init.no_turn_back, init.double_line_middle, init.kerb_foot",
            off: value!("all three false", |c| {
                c.init.no_turn_back = false;
                c.init.double_line_middle = false;
                c.init.kerb_foot = false
            }),
            others: &[],
        },
        Mechanism {
            name: "together: the readings and the refinement's window and passes",
            keys: "the three above, track.refine_window_half_width_px, refine_passes",
            off: value!("all off", |c| {
                c.init.no_turn_back = false;
                c.init.double_line_middle = false;
                c.init.kerb_foot = false;
                c.track.refine_window_half_width_px = 0;
                c.track.refine_passes = 1
            }),
            others: &[],
        },
        Mechanism {
            name: "orientation gate in the windows",
            keys: "track.orientation_tolerance_deg",
            off: value!("0", |c| c.track.orientation_tolerance_deg = 0.0),
            others: &[
                value!("10°", |c| c.track.orientation_tolerance_deg = 10.0),
                value!("30°", |c| c.track.orientation_tolerance_deg = 30.0),
            ],
        },
        Mechanism {
            name: "re-validation",
            keys: "track.revalidate_every_frames, revalidate_below_points, revalidate_keep_factor",
            off: value!("off", |c| {
                c.track.revalidate_every_frames = 0;
                c.track.revalidate_below_points = 0
            }),
            others: &[
                value!("every 5", |c| c.track.revalidate_every_frames = 5),
                value!("keep factor 2", |c| c.track.revalidate_keep_factor = 2.0),
            ],
        },
        Mechanism {
            name: "re-validation spread over its period",
            keys: "track.revalidate_spread",
            off: value!("whole", |c| c.track.revalidate_spread = false),
            others: &[],
        },
    ]
}

/// One variant's label-lane totals per set: development and hold-out parts as the stills are
/// (each clip tracked as its own sequence), and every frame of the set tracked as one sequence
/// (`eval-lanes --one-sequence`, the stress test: a scene cut between clips, on every frame).
#[derive(Debug, Clone, Default, Serialize)]
pub struct SetTotals {
    /// The development part.
    pub dev: LaneTotals,
    /// The hold-out part.
    pub holdout: LaneTotals,
    /// Every frame, the set tracked as one sequence.
    pub one_sequence: LaneTotals,
}

impl SetTotals {
    /// Both parts.
    pub fn all(&self) -> LaneTotals {
        let mut t = self.dev;
        t.add(&self.holdout);
        t
    }
}

/// One set's leave-one-set-out result for one mechanism.
#[derive(Debug, Clone, PartialEq)]
pub struct Loso<'a> {
    /// The value chosen on the other sets' development parts.
    pub chosen: &'a str,
    /// Its gain over off on the held set, all its frames, accuracy points.
    pub gain: f64,
    /// The held set's label lanes (its weight in the pooled mean).
    pub held_lanes: f64,
}

/// Leave `held` out: among `variants` (off first, then the default and the other values; each
/// a run's totals per set), the first with the best accuracy over the other sets' development
/// label lanes together (a later value must do strictly better: a tie keeps the mechanism off),
/// and its gain over off on `held`, all its frames. `None` if a run lacks the held set.
pub fn loso<'a>(
    variants: &[(&'a str, &BTreeMap<String, SetTotals>)],
    held: &str,
) -> Option<Loso<'a>> {
    let score_others = |r: &BTreeMap<String, SetTotals>| {
        let mut t = LaneTotals::default();
        for (s, st) in r {
            if s != held {
                t.add(&st.dev);
            }
        }
        acc(&t)
    };
    let (off_label, off) = variants.first()?;
    let mut chosen = (*off_label, *off);
    let mut best = score_others(off);
    for &(label, r) in variants.iter().skip(1) {
        let score = score_others(r);
        if score > best {
            (best, chosen) = (score, (label, r));
        }
    }
    let (c, o) = (chosen.1.get(held)?, off.get(held)?);
    Some(Loso {
        chosen: chosen.0,
        gain: acc(&c.all()) - acc(&o.all()),
        held_lanes: o.all().label_lanes as f64,
    })
}

/// TuSimple accuracy of `t`, %.
fn acc(t: &LaneTotals) -> f64 {
    100.0 * t.summary().tusimple_accuracy
}

/// Every set of `sets` as one sequence (one clip named after the set): the stress test's input.
pub fn as_one_sequence(sets: &[(PathBuf, LabelSet)]) -> Vec<LabelSet> {
    sets.iter()
        .map(|(_, set)| {
            let mut one = set.clone();
            let name = format!("{}-one-sequence", one.set);
            for f in &mut one.frames {
                f.clip.clone_from(&name);
            }
            one
        })
        .collect()
}

/// One variant: the tracker with `cfg` over every set of `sets` (and over `one_sequence`, the
/// same sets as one sequence each), its label-lane totals per set. `Ok(None)` when the tracker
/// refuses `cfg` (a value the configuration does not accept).
pub fn run_variant(
    sets: &[(PathBuf, LabelSet)],
    one_sequence: &[LabelSet],
    cfg: &TrackerConfig,
) -> Result<Option<BTreeMap<String, SetTotals>>, BenchError> {
    if cfg.validate().is_err() {
        return Ok(None);
    }
    let rules = ScoringRules::default();
    let mut per_set = BTreeMap::new();
    for ((dir, set), one) in sets.iter().zip(one_sequence) {
        let preds = track_label_set(dir, set, cfg, Estimator::Kif)?.predictions;
        let stressed = track_label_set(dir, one, cfg, Estimator::Kif)?.predictions;
        let n_dev = dev_count(set.frames.len());
        let mut t = SetTotals::default();
        for (i, ((f, p), q)) in set.frames.iter().zip(&preds).zip(&stressed).enumerate() {
            let frame = LaneTotals::of_frame(&score_sides(f, set.width, set.height, p, &rules));
            if i < n_dev {
                t.dev.add(&frame);
            } else {
                t.holdout.add(&frame);
            }
            let frame = LaneTotals::of_frame(&score_sides(f, set.width, set.height, q, &rules));
            t.one_sequence.add(&frame);
        }
        per_set.insert(set.set.clone(), t);
    }
    Ok(Some(per_set))
}

/// The tables of `ablation.md`.
pub fn render(
    mechanisms: &[Mechanism],
    runs: &BTreeMap<String, BTreeMap<String, SetTotals>>,
    sets: &[String],
) -> String {
    let Some(default) = runs.get("default") else {
        return String::from("no default run\n");
    };
    let mut md = String::from(
        "# Does each mechanism earn its place? (`cargo xtask ablation`)\n\n\
         TuSimple accuracy points on the labelled real stills (ego lanes, the near band), default \
         configuration otherwise. **Off − default** per set and part: what switching the \
         mechanism off costs (negative: it helps). **LOSO**: the mechanism's value chosen on the \
         other sets' development parts (a tie keeps it off: the other sets must show a gain), \
         its gain over off on the held set (all its frames); the value chosen in brackets. Mean: \
         the sets alike; pooled: weighed by each set's label lanes. **Stress**: every set's frames tracked as one sequence (a scene cut \
         between clips, on every frame: `eval-lanes --one-sequence`), all sets pooled, off − \
         default.\n\n",
    );
    let mut header = vec!["mechanism".to_owned(), "keys".to_owned(), "off".to_owned()];
    for s in sets {
        header.push(format!("{s} dev"));
        header.push(format!("{s} hold-out"));
    }
    header.push("stress, all sets".to_owned());
    for s in sets {
        header.push(format!("LOSO {s}"));
    }
    header.push("LOSO mean".to_owned());
    header.push("LOSO pooled".to_owned());
    md += &format!(
        "| {} |\n|{}\n",
        header.join(" | "),
        "---|".repeat(header.len())
    );
    for m in mechanisms {
        let key = |label: &str| format!("{} = {}", m.name, label);
        let Some(off) = runs.get(&key(m.off.label)) else {
            continue;
        };
        let mut row = vec![
            m.name.to_owned(),
            format!("`{}`", m.keys),
            m.off.label.to_owned(),
        ];
        for s in sets {
            match (default.get(s), off.get(s)) {
                (Some(d), Some(o)) => {
                    row.push(format!("{:+.1}", acc(&o.dev) - acc(&d.dev)));
                    row.push(format!("{:+.1}", acc(&o.holdout) - acc(&d.holdout)));
                }
                _ => row.extend([String::new(), String::new()]),
            }
        }
        let pooled = |r: &BTreeMap<String, SetTotals>| {
            let mut t = LaneTotals::default();
            for st in r.values() {
                t.add(&st.one_sequence);
            }
            acc(&t)
        };
        row.push(format!("{:+.1}", pooled(off) - pooled(default)));
        // The candidates of the choice: off first (a tie keeps the mechanism off: the other
        // sets must show a gain for it to be chosen), the default, and the other values.
        let mut variants: Vec<(&str, &BTreeMap<String, SetTotals>)> =
            vec![(m.off.label, off), ("default", default)];
        for v in m.others {
            if let Some(r) = runs.get(&key(v.label)) {
                variants.push((v.label, r));
            }
        }
        // (gain, the held set's label lanes)
        let mut gains = Vec::new();
        for held in sets {
            match loso(&variants, held) {
                Some(g) => {
                    row.push(format!("{:+.1} ({})", g.gain, g.chosen));
                    gains.push((g.gain, g.held_lanes));
                }
                None => row.push(String::new()),
            }
        }
        let mean = gains.iter().map(|g| g.0).sum::<f64>() / gains.len().max(1) as f64;
        let lanes: f64 = gains.iter().map(|g| g.1).sum();
        let pooled = gains.iter().map(|g| g.0 * g.1).sum::<f64>() / lanes.max(1.0);
        row.push(format!("**{mean:+.1}**"));
        row.push(format!("{pooled:+.1}"));
        md += &format!("| {} |\n", row.join(" | "));
    }
    md += "\n`cargo xtask ablation` writes this file to `target/ablation/ablation.md`; \
           `docs/results/ablation.md` is a copy of it.\n";
    md
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Totals of `lanes` label lanes with accuracy `acc` (0–1) each, in a part.
    fn totals(lanes: u64, acc: f64) -> LaneTotals {
        LaneTotals {
            label_lanes: lanes,
            tusimple_acc_sum: acc * lanes as f64,
            ..LaneTotals::default()
        }
    }

    /// A run: per set (name, development accuracy, hold-out accuracy), 10 label lanes a part.
    fn run(sets: &[(&str, f64, f64)]) -> BTreeMap<String, SetTotals> {
        sets.iter()
            .map(|&(name, dev, holdout)| {
                let t = SetTotals {
                    dev: totals(10, dev),
                    holdout: totals(10, holdout),
                    one_sequence: LaneTotals::default(),
                };
                (name.to_owned(), t)
            })
            .collect()
    }

    #[test]
    fn the_value_is_chosen_on_the_other_sets_and_scored_on_the_held_one() {
        let off = run(&[("a", 0.5, 0.5), ("b", 0.5, 0.5), ("c", 0.5, 0.5)]);
        // The default helps a and b, and hurts c.
        let on = run(&[("a", 0.7, 0.7), ("b", 0.6, 0.6), ("c", 0.4, 0.4)]);
        let variants = [("off", &off), ("default", &on)];
        // Held c: chosen on a and b (the default), it loses 10 points on c.
        let c = loso(&variants, "c").expect("every set in every run");
        assert_eq!(c.chosen, "default");
        assert!((c.gain + 10.0).abs() < 1e-9, "{c:?}");
        assert_eq!(c.held_lanes, 20.0);
        // Held a: b (+10) and c (−10) tie: the mechanism stays off and gains nothing.
        let a = loso(&variants, "a").expect("every set in every run");
        assert_eq!((a.chosen, a.gain), ("off", 0.0));
    }

    #[test]
    fn a_tie_keeps_the_mechanism_off_and_a_later_value_must_do_strictly_better() {
        let off = run(&[("a", 0.5, 0.5), ("b", 0.5, 0.5)]);
        // Neutral on b, helps a: held a, b cannot choose it.
        let on = run(&[("a", 0.9, 0.9), ("b", 0.5, 0.5)]);
        let same_as_on = run(&[("a", 0.1, 0.1), ("b", 0.5, 0.5)]);
        let better = run(&[("a", 0.6, 0.6), ("b", 0.55, 0.55)]);
        let tie = [("off", &off), ("default", &on), ("other", &same_as_on)];
        let a = loso(&tie, "a").expect("every set in every run");
        assert_eq!((a.chosen, a.gain), ("off", 0.0));
        let strictly = [("off", &off), ("default", &on), ("better", &better)];
        let a = loso(&strictly, "a").expect("every set in every run");
        assert_eq!(a.chosen, "better");
        assert!((a.gain - 10.0).abs() < 1e-9, "{a:?}");
    }

    #[test]
    fn a_run_without_the_held_set_gives_no_result() {
        let off = run(&[("a", 0.5, 0.5), ("b", 0.5, 0.5)]);
        let on = run(&[("b", 0.6, 0.6)]);
        assert_eq!(loso(&[("off", &off), ("default", &on)], "a"), None);
    }
}
