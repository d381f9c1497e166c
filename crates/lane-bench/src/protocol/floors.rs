//! The floors: per set and overall, the least TuSimple accuracy and Aly detection rate and the
//! most TuSimple false positives the default configuration may show on all of a set's frames
//! (`cargo xtask eval-lanes --check`, the gate's step, holds them in
//! `fixtures/expectations-lanes-real.json`). [`record`] writes them from a run: measured accuracy
//! − 3 points, measured false positives + 3 points.

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

/// The default's figures on every frame of set `name` (`overall` for all sets).
fn default_rates(summary: &Summary, name: &str) -> Option<LaneRates> {
    let results = if name == "overall" {
        &summary.overall
    } else {
        &summary.sets.iter().find(|s| s.set == name)?.results
    };
    results.get(DEFAULT_NAME).map(|r| r.all)
}

fn floor_of(r: &LaneRates) -> Floor {
    let round = |x: f64| (x * 1000.0).round() / 1000.0;
    Floor {
        tusimple_accuracy_min: round((r.tusimple_accuracy - FLOOR_MARGIN).max(0.0)),
        tusimple_fp_max: round((r.tusimple_fp + FLOOR_MARGIN).min(1.0)),
        aly_detection_rate_min: round((r.aly_detection_rate - FLOOR_MARGIN).max(0.0)),
    }
}

/// Write the floors of `summary`'s default run (every set and `overall`) to `path`.
pub fn record(summary: &Summary, path: &Path) -> Result<(), BenchError> {
    let names = summary.sets.iter().map(|s| s.set.as_str());
    let floors: BTreeMap<&str, Floor> = names
        .chain(["overall"])
        .filter_map(|name| Some((name, floor_of(&default_rates(summary, name)?))))
        .collect();
    let text = serde_json::to_string_pretty(&floors).map_err(|source| BenchError::Json {
        path: path.display().to_string(),
        source,
    })?;
    std::fs::write(path, text + "\n").map_err(|e| BenchError::io("write", path, e))
}

/// Check `summary`'s default run against the floors in `path`; returns how many held, or
/// [`BenchError::BelowFloors`] listing every one that did not (a set missing from the run too).
pub fn check(summary: &Summary, path: &Path) -> Result<usize, BenchError> {
    let text = std::fs::read_to_string(path).map_err(|e| BenchError::io("read", path, e))?;
    let floors: BTreeMap<String, Floor> =
        serde_json::from_str(&text).map_err(|source| BenchError::Json {
            path: path.display().to_string(),
            source,
        })?;
    let mut failures = Vec::new();
    for (name, floor) in &floors {
        let Some(rates) = default_rates(summary, name) else {
            failures.push(format!("{name}: set missing"));
            continue;
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
    if failures.is_empty() {
        Ok(floors.len())
    } else {
        Err(BenchError::BelowFloors(failures))
    }
}
