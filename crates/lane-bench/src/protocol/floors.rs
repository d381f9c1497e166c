//! The floors: per set and overall, the least TuSimple accuracy and Aly detection rate and the
//! most TuSimple false positives the default configuration may show on all of a set's frames
//! (near band); under the full rule, the least accuracy and most false positives of the
//! default on the held-out part of all sets; and under each perturbation of `--perturb`, the
//! least near-band accuracy of the default on the held-out part of all sets. `cargo xtask
//! eval-lanes --check` holds them in `fixtures/expectations-lanes-real.json`; [`record`] writes
//! them from a run: measured accuracy − 3 points, measured false positives + 3 points.
//!
//! The file is one JSON object: a [`Floor`] per set name and `overall`, plus two reserved keys,
//! `full_rule` ([`FullRuleFloor`]) and `perturbed` (a [`PerturbedFloor`] per perturbation
//! name); a file without them (written before they existed) checks the near band alone. A run
//! without `--perturb` checks no perturbation floor (it says how many it left) and records
//! none: [`record`] keeps those of the file it overwrites.

use std::collections::BTreeMap;
use std::path::Path;

use serde::{Deserialize, Serialize};

use super::{DEFAULT_NAME, Summary};
use crate::BenchError;
use crate::labelled::LaneRates;

/// Floors: measured accuracy minus this, measured false positives plus this.
pub const FLOOR_MARGIN: f64 = 0.03;

/// Floors of one set (default configuration, every frame).
#[derive(Debug, Clone, Copy, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Floor {
    /// Least TuSimple accuracy.
    pub tusimple_accuracy_min: f64,
    /// Most TuSimple false positives.
    pub tusimple_fp_max: f64,
    /// Least Aly detection rate.
    pub aly_detection_rate_min: f64,
}

/// The full rule's floors (default configuration, held-out part, all sets pooled).
#[derive(Debug, Clone, Copy, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FullRuleFloor {
    /// Least TuSimple accuracy.
    pub holdout_tusimple_accuracy_min: f64,
    /// Most TuSimple false positives.
    pub holdout_tusimple_fp_max: f64,
}

/// One perturbation's floor (default configuration, near band, held-out part, all sets
/// pooled).
#[derive(Debug, Clone, Copy, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PerturbedFloor {
    /// Least TuSimple accuracy.
    pub holdout_tusimple_accuracy_min: f64,
}

/// The floors file (module docs).
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
pub struct Floors {
    /// Per set name and `overall`: the near band's.
    #[serde(flatten)]
    pub sets: BTreeMap<String, Floor>,
    /// The full rule's.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub full_rule: Option<FullRuleFloor>,
    /// Per perturbation name.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub perturbed: BTreeMap<String, PerturbedFloor>,
}

/// What [`check`] found: the floors that held, and the perturbation floors it could not check
/// (a run without `--perturb`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Checked {
    /// Floors that held.
    pub held: usize,
    /// Perturbation floors not checked.
    pub not_run: usize,
}

/// The default's figures on every frame of set `name` (`overall` for all sets).
fn default_rates(summary: &Summary, name: &str) -> Option<LaneRates> {
    let results = if name == "overall" {
        &summary.overall
    } else {
        &summary.sets.iter().find(|s| s.set == name)?.results
    };
    results.get(DEFAULT_NAME).map(|r| r.all)
}

/// `x` rounded to 3 decimals.
fn round(x: f64) -> f64 {
    (x * 1000.0).round() / 1000.0
}

/// A least rate from measured `x`.
fn least(x: f64) -> f64 {
    round((x - FLOOR_MARGIN).max(0.0))
}

/// A most rate from measured `x`.
fn most(x: f64) -> f64 {
    round((x + FLOOR_MARGIN).min(1.0))
}

fn floor_of(r: &LaneRates) -> Floor {
    Floor {
        tusimple_accuracy_min: least(r.tusimple_accuracy),
        tusimple_fp_max: most(r.tusimple_fp),
        aly_detection_rate_min: least(r.aly_detection_rate),
    }
}

/// The floors file at `path`.
fn read(path: &Path) -> Result<Floors, BenchError> {
    let text = std::fs::read_to_string(path).map_err(|e| BenchError::io("read", path, e))?;
    serde_json::from_str(&text).map_err(|source| BenchError::Json {
        path: path.display().to_string(),
        source,
    })
}

/// Write the floors of `summary`'s default run (every set and `overall`, the full rule, and
/// the perturbations when it has them; else those of the file at `path`, if any) to `path`.
pub fn record(summary: &Summary, path: &Path) -> Result<(), BenchError> {
    let names = summary.sets.iter().map(|s| s.set.as_str());
    let sets = names
        .chain(["overall"])
        .filter_map(|name| Some((name.to_owned(), floor_of(&default_rates(summary, name)?))))
        .collect();
    let full_rule = summary
        .overall_full_rule
        .get(DEFAULT_NAME)
        .map(|r| FullRuleFloor {
            holdout_tusimple_accuracy_min: least(r.holdout.tusimple_accuracy),
            holdout_tusimple_fp_max: most(r.holdout.tusimple_fp),
        });
    let perturbed = if summary.perturbations.is_empty() {
        if path.is_file() {
            read(path)?.perturbed
        } else {
            BTreeMap::new()
        }
    } else {
        summary
            .perturbations
            .iter()
            .map(|p| {
                let floor = PerturbedFloor {
                    holdout_tusimple_accuracy_min: least(p.overall.holdout.tusimple_accuracy),
                };
                (p.perturbation.clone(), floor)
            })
            .collect()
    };
    let floors = Floors {
        sets,
        full_rule,
        perturbed,
    };
    let text = serde_json::to_string_pretty(&floors).map_err(|source| BenchError::Json {
        path: path.display().to_string(),
        source,
    })?;
    std::fs::write(path, text + "\n").map_err(|e| BenchError::io("write", path, e))
}

/// Check `summary`'s default run against the floors in `path`; returns how many held and how
/// many perturbation floors were left unchecked (no perturbation table in `summary`), or
/// [`BenchError::BelowFloors`] listing every one that did not hold (a set or perturbation
/// missing from the run too).
pub fn check(summary: &Summary, path: &Path) -> Result<Checked, BenchError> {
    let floors = read(path)?;
    let mut failures = Vec::new();
    let mut held = 0;
    for (name, floor) in &floors.sets {
        let Some(rates) = default_rates(summary, name) else {
            failures.push(format!("{name}: set missing"));
            continue;
        };
        let (acc, fp, aly) = (
            rates.tusimple_accuracy,
            rates.tusimple_fp,
            rates.aly_detection_rate,
        );
        let (acc_min, fp_max, aly_min) = (
            floor.tusimple_accuracy_min,
            floor.tusimple_fp_max,
            floor.aly_detection_rate_min,
        );
        let ok = acc >= acc_min && fp <= fp_max && aly >= aly_min;
        if acc < acc_min {
            failures.push(format!(
                "{name}: TuSimple accuracy {acc:.3} < floor {acc_min:.3}"
            ));
        }
        if fp > fp_max {
            failures.push(format!(
                "{name}: false positives {fp:.3} > ceiling {fp_max:.3}"
            ));
        }
        if aly < aly_min {
            failures.push(format!(
                "{name}: Aly detection rate {aly:.3} < floor {aly_min:.3}"
            ));
        }
        held += usize::from(ok);
    }
    let mut expect = |failures: &mut Vec<String>, ok: bool, failure: String| {
        if ok {
            held += 1;
        } else {
            failures.push(failure);
        }
    };
    if let Some(floor) = floors.full_rule {
        match summary.overall_full_rule.get(DEFAULT_NAME) {
            Some(r) => {
                let (acc, fp) = (r.holdout.tusimple_accuracy, r.holdout.tusimple_fp);
                let (acc_min, fp_max) = (
                    floor.holdout_tusimple_accuracy_min,
                    floor.holdout_tusimple_fp_max,
                );
                expect(
                    &mut failures,
                    acc >= acc_min,
                    format!("full rule, hold-out: TuSimple accuracy {acc:.3} < floor {acc_min:.3}"),
                );
                expect(
                    &mut failures,
                    fp <= fp_max,
                    format!("full rule, hold-out: false positives {fp:.3} > ceiling {fp_max:.3}"),
                );
            }
            None => failures.push("full rule: not in the run".to_owned()),
        }
    }
    let mut not_run = 0;
    for (name, floor) in &floors.perturbed {
        if summary.perturbations.is_empty() {
            not_run += 1;
            continue;
        }
        let Some(p) = summary
            .perturbations
            .iter()
            .find(|p| &p.perturbation == name)
        else {
            failures.push(format!("{name}: perturbation missing"));
            continue;
        };
        let (acc, acc_min) = (
            p.overall.holdout.tusimple_accuracy,
            floor.holdout_tusimple_accuracy_min,
        );
        expect(
            &mut failures,
            acc >= acc_min,
            format!("{name}, hold-out: TuSimple accuracy {acc:.3} < floor {acc_min:.3}"),
        );
    }
    if failures.is_empty() {
        Ok(Checked { held, not_run })
    } else {
        Err(BenchError::BelowFloors(failures))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_floors_file_without_the_new_keys_reads_and_the_reserved_keys_are_not_sets() {
        let old = r#"{"culane": {"tusimple_accuracy_min": 0.6, "tusimple_fp_max": 0.5,
            "aly_detection_rate_min": 0.6}}"#;
        let f: Floors = serde_json::from_str(old).unwrap();
        assert_eq!(f.sets.len(), 1);
        assert!(f.full_rule.is_none() && f.perturbed.is_empty());
        let new = r#"{"overall": {"tusimple_accuracy_min": 0.7, "tusimple_fp_max": 0.3,
            "aly_detection_rate_min": 0.7},
            "full_rule": {"holdout_tusimple_accuracy_min": 0.5, "holdout_tusimple_fp_max": 0.6},
            "perturbed": {"blur-7": {"holdout_tusimple_accuracy_min": 0.7}}}"#;
        let f: Floors = serde_json::from_str(new).unwrap();
        assert_eq!(f.sets.keys().collect::<Vec<_>>(), ["overall"]);
        assert_eq!(f.full_rule.unwrap().holdout_tusimple_fp_max, 0.6);
        assert_eq!(f.perturbed["blur-7"].holdout_tusimple_accuracy_min, 0.7);
        // Written back, the same file.
        let again: Floors = serde_json::from_str(&serde_json::to_string(&f).unwrap()).unwrap();
        assert_eq!(again.perturbed.len(), 1);
        assert!(again.full_rule.is_some());
        // A misspelt field of a floor is refused.
        let bad = new.replace("holdout_tusimple_fp_max", "holdout_fp_max");
        assert!(serde_json::from_str::<Floors>(&bad).is_err());
    }

    #[test]
    fn floors_are_the_measured_figures_less_the_margin() {
        assert_eq!(least(0.805), 0.775);
        assert_eq!(most(0.311), 0.341);
        assert_eq!((least(0.01), most(0.99)), (0.0, 1.0));
    }
}
