//! Merging shards of the statistics, and which run indices a shard or a merge covers.

use super::{FORMAT, Stats, order_key};
use crate::SimError;

/// Merges shard statistics (any order) into one. Checks that they describe the same scenario,
/// seed and total run count and that their run ranges are disjoint; sums in the order of the
/// ranges' starts.
pub fn merge(mut parts: Vec<Stats>) -> Result<Stats, SimError> {
    if parts.is_empty() {
        return Err(SimError::StatsEmpty);
    }
    parts.sort_by_key(|p| p.run_ranges.first().map_or(0, |r| r.0));
    let first = parts[0].clone();
    let differ = |what, a: String, b: String| SimError::StatsMismatch { what, a, b };
    for p in &parts {
        if p.format != FORMAT {
            return Err(SimError::StatsFormat {
                found: p.format.clone(),
            });
        }
        if p.scenario_fingerprint != first.scenario_fingerprint {
            return Err(differ(
                "scenarios",
                p.scenario_fingerprint.clone(),
                first.scenario_fingerprint.clone(),
            ));
        }
        if p.seed != first.seed {
            return Err(differ(
                "master seeds",
                p.seed.to_string(),
                first.seed.to_string(),
            ));
        }
        if p.runs_total != first.runs_total {
            return Err(differ(
                "total run counts",
                p.runs_total.to_string(),
                first.runs_total.to_string(),
            ));
        }
        let same_modes = p.modes.len() == first.modes.len()
            && p.modes
                .iter()
                .zip(&first.modes)
                .all(|(a, b)| a.mode == b.mode && a.bins.len() == b.bins.len());
        if !same_modes {
            let names = |s: &Stats| {
                s.modes
                    .iter()
                    .map(|m| format!("{} ({} s)", m.mode, m.bins.len().saturating_sub(1)))
                    .collect::<Vec<_>>()
                    .join(", ")
            };
            return Err(differ("modes or durations", names(p), names(&first)));
        }
    }
    let mut out = first;
    for p in &parts[1..] {
        for (a, b) in out.modes.iter_mut().zip(&p.modes) {
            a.merge(b);
        }
        out.run_ranges.extend_from_slice(&p.run_ranges);
        out.shards.extend_from_slice(&p.shards);
        out.exclusions.extend_from_slice(&p.exclusions);
        out.runs.extend_from_slice(&p.runs);
        out.wall_s += p.wall_s;
        out.core_s += p.core_s;
    }
    out.run_ranges.sort_unstable();
    for w in out.run_ranges.windows(2) {
        if w[1].0 < w[0].1 {
            return Err(SimError::StatsOverlap(w[0].0, w[0].1, w[1].0, w[1].1));
        }
    }
    out.shards.sort_by_key(|s| s.index);
    out.exclusions
        .sort_by_key(|a| order_key(a.mode, a.run_index));
    out.runs.sort_by_key(|a| order_key(a.mode, a.run_index));
    Ok(out)
}

/// Run indices of shard `index` (1-based) of `count` over `runs`: a contiguous slice, sizes
/// differing by at most one. [`SimError::StatsShard`] when `count` is 0 or `index` is not in
/// `1..=count`.
pub fn shard_range(runs: u64, index: u64, count: u64) -> Result<(u64, u64), SimError> {
    if count == 0 || !(1..=count).contains(&index) {
        return Err(SimError::StatsShard { index, count });
    }
    // In u128: `index · runs` cannot overflow.
    let at = |i: u64| (u128::from(i) * u128::from(runs) / u128::from(count)) as u64;
    Ok((at(index - 1), at(index)))
}

/// Missing run indices (as ranges) of a merged file.
pub fn missing_ranges(stats: &Stats) -> Vec<(u64, u64)> {
    let mut missing = Vec::new();
    let mut next = 0;
    for &(a, b) in &stats.run_ranges {
        if a > next {
            missing.push((next, a));
        }
        next = next.max(b);
    }
    if next < stats.runs_total {
        missing.push((next, stats.runs_total));
    }
    missing
}
