//! Mergeable Monte Carlo statistics: per mode, per 1 Hz time bin, per quantity the count, Σx
//! and Σx² over the runs that were kept.
//!
//! Sums are exactly associative up to floating-point round-off, so the statistics of shards
//! added together equal those of one run over all indices to round-off (tested). Within one
//! process the per-run records are folded in run-index order (see `driver`), so the result
//! does not depend on the thread count either (bit-identical, tested).

use serde::{Deserialize, Serialize};

use super::{Mode, Sample, SimError};

mod merge;
pub use merge::{merge, missing_ranges, shard_range};

/// Number of accumulated quantities per time bin.
pub const Q: usize = 14;

/// Index of each accumulated quantity in a bin.
pub mod qi {
    /// Position error N, m.
    pub const POS_N: usize = 0;
    /// Position error E, m.
    pub const POS_E: usize = 1;
    /// Position error D, m.
    pub const POS_D: usize = 2;
    /// Horizontal position error √(N² + E²), m.
    pub const POS_H: usize = 3;
    /// 3-D position error |δp|, m.
    pub const POS_3D: usize = 4;
    /// Velocity error N, m/s.
    pub const VEL_N: usize = 5;
    /// Velocity error E, m/s.
    pub const VEL_E: usize = 6;
    /// Velocity error D, m/s.
    pub const VEL_D: usize = 7;
    /// Misalignment ψ N, rad.
    pub const PSI_N: usize = 8;
    /// Misalignment ψ E, rad.
    pub const PSI_E: usize = 9;
    /// Misalignment ψ D (azimuth), rad.
    pub const PSI_D: usize = 10;
    /// True distance flown, m.
    pub const DIST: usize = 11;
    /// NEES (15 states), filters at SD epochs only.
    pub const NEES: usize = 12;
    /// NIS (6 measurements), filters at SD epochs only.
    pub const NIS: usize = 13;
}

/// Count, Σx and Σx² of one quantity in one time bin.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Moments {
    /// Number of values.
    pub n: u64,
    /// Σx.
    pub sum: f64,
    /// Σx².
    pub sum_sq: f64,
}

impl Moments {
    /// Adds one value.
    pub fn push(&mut self, x: f64) {
        self.n += 1;
        self.sum += x;
        self.sum_sq += x * x;
    }

    /// Adds another accumulator (merge).
    pub fn merge(&mut self, other: &Moments) {
        self.n += other.n;
        self.sum += other.sum;
        self.sum_sq += other.sum_sq;
    }

    /// Mean (NaN when empty).
    pub fn mean(&self) -> f64 {
        if self.n == 0 {
            f64::NAN
        } else {
            self.sum / self.n as f64
        }
    }

    /// Sample standard deviation over runs (divisor n − 1; 0 for one value, NaN when empty).
    /// Σx² − n·mean² is clamped at 0 against round-off.
    pub fn std_dev(&self) -> f64 {
        match self.n {
            0 => f64::NAN,
            1 => 0.0,
            n => {
                let n = n as f64;
                let m = self.sum / n;
                ((self.sum_sq - n * m * m).max(0.0) / (n - 1.0)).sqrt()
            }
        }
    }

    /// Root mean square √(Σx²/n) (NaN when empty).
    pub fn rms(&self) -> f64 {
        if self.n == 0 {
            f64::NAN
        } else {
            (self.sum_sq / self.n as f64).sqrt()
        }
    }
}

/// Statistics of one mode over the runs kept.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ModeStats {
    /// The mode (serialised as its name: `standalone`, `kf`, `akf`, …).
    pub mode: Mode,
    /// Runs kept (finite throughout).
    pub runs_used: u64,
    /// 100 Hz IMU/INS steps simulated by all runs that returned (kept or not). Read also from
    /// the `epochs` key of files written before the rename.
    #[serde(alias = "epochs")]
    pub steps: u64,
    /// Σ over runs of the run's own wall time, s.
    pub run_time_s: f64,
    /// Σ over runs of the CPU time of the thread that simulated it, s (0 where unavailable).
    #[serde(default)]
    pub run_cpu_s: f64,
    /// One entry per 1 Hz record (t = 0, 1, …, duration), quantities in [`qi`] order.
    pub bins: Vec<[Moments; Q]>,
}

impl ModeStats {
    /// Empty statistics for `mode` with `samples` time bins.
    pub fn new(mode: Mode, samples: usize) -> Self {
        Self {
            mode,
            runs_used: 0,
            steps: 0,
            run_time_s: 0.0,
            run_cpu_s: 0.0,
            bins: vec![[Moments::default(); Q]; samples],
        }
    }

    /// Adds one finite run's records (length = number of bins, checked by the caller).
    pub fn push_run(&mut self, samples: &[Sample]) {
        self.runs_used += 1;
        for (bin, s) in self.bins.iter_mut().zip(samples) {
            let [n, e, d] = s.pos_err_ned_m;
            let h = n.hypot(e);
            let values = [
                (qi::POS_N, n),
                (qi::POS_E, e),
                (qi::POS_D, d),
                (qi::POS_H, h),
                (qi::POS_3D, h.hypot(d)),
                (qi::VEL_N, s.vel_err_ned_mps[0]),
                (qi::VEL_E, s.vel_err_ned_mps[1]),
                (qi::VEL_D, s.vel_err_ned_mps[2]),
                (qi::PSI_N, s.misalignment_rad[0]),
                (qi::PSI_E, s.misalignment_rad[1]),
                (qi::PSI_D, s.misalignment_rad[2]),
                (qi::DIST, s.distance_m),
            ];
            for (i, x) in values {
                bin[i].push(x);
            }
            if let Some(x) = s.nees {
                bin[qi::NEES].push(x);
            }
            if let Some(x) = s.nis {
                bin[qi::NIS].push(x);
            }
        }
    }

    /// Adds another mode's statistics (same mode and bin count, checked by the caller).
    pub fn merge(&mut self, other: &ModeStats) {
        self.runs_used += other.runs_used;
        self.steps += other.steps;
        self.run_time_s += other.run_time_s;
        self.run_cpu_s += other.run_cpu_s;
        for (a, b) in self.bins.iter_mut().zip(&other.bins) {
            for (x, y) in a.iter_mut().zip(b) {
                x.merge(y);
            }
        }
    }
}

/// A run left out of the statistics of one mode, and why.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Exclusion {
    /// The mode.
    pub mode: Mode,
    /// Run index (0-based, over all shards).
    pub run_index: u64,
    /// Time at which the run failed or first held a non-finite record, s (if known).
    pub t_s: Option<f64>,
    /// What happened.
    pub reason: String,
}

/// One kept run in brief (robust statistics and the worst runs; merged by concatenation).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RunSummary {
    /// The mode.
    pub mode: Mode,
    /// Run index.
    pub run_index: u64,
    /// 3-D position error at the final time, m.
    pub final_pos_3d_m: f64,
    /// Largest 3-D position error over the 1 Hz records, m.
    pub peak_pos_3d_m: f64,
    /// When it occurred, s.
    pub peak_t_s: f64,
    /// Largest NEES over the SD epochs (filters only).
    pub peak_nees: Option<f64>,
}

impl RunSummary {
    /// Summarises one finite run.
    pub fn of(mode: Mode, run_index: u64, samples: &[Sample]) -> Self {
        let norm = |s: &Sample| {
            let [n, e, d] = s.pos_err_ned_m;
            (n * n + e * e + d * d).sqrt()
        };
        let (mut peak, mut peak_t) = (0.0, 0.0);
        for s in samples {
            let e = norm(s);
            if e > peak {
                peak = e;
                peak_t = s.t_s;
            }
        }
        let peak_nees = samples
            .iter()
            .filter_map(|s| s.nees)
            .fold(None, |m: Option<f64>, x| Some(m.map_or(x, |m| m.max(x))));
        Self {
            mode,
            run_index,
            final_pos_3d_m: samples.last().map_or(f64::NAN, norm),
            peak_pos_3d_m: peak,
            peak_t_s: peak_t,
            peak_nees,
        }
    }
}

/// Which slice of the run indices a statistics file covers.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct ShardInfo {
    /// Shard number, 1-based.
    pub index: u64,
    /// Number of shards.
    pub count: u64,
}

/// The raw form of `stats.json` (what serde reads and writes): no invariant is checked. Turn it
/// into [`Stats`] with `Stats::try_from`, which sorts the ranges, exclusions and runs and checks
/// the rest.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StatsFile {
    /// File format tag.
    pub format: String,
    /// FNV-1a hash of the scenario (shards must agree).
    pub scenario_fingerprint: String,
    /// Where the scenario came from (its file).
    pub scenario_source: String,
    /// `Scenario::assumptions()`.
    pub assumptions: Vec<String>,
    /// σ of the simulated sighting-device noise, m (`[sighting] noise_var_m2`, square-rooted), for
    /// the reports; absent in files written before it was recorded.
    #[serde(default)]
    pub sd_noise_sigma_m: Option<f64>,
    /// Flight duration, s.
    pub duration_s: f64,
    /// Master seed.
    pub seed: u64,
    /// Runs per mode over all shards.
    pub runs_total: u64,
    /// Run indices covered by the shards merged here: half-open ranges (sorted by [`Stats`]).
    pub run_ranges: Vec<(u64, u64)>,
    /// Shards merged into this file (one entry for a single run).
    pub shards: Vec<ShardInfo>,
    /// Per mode (in `Mode::EVERY` order, checked by [`Stats`]).
    pub modes: Vec<ModeStats>,
    /// Runs left out (sorted by mode then index by [`Stats`]).
    pub exclusions: Vec<Exclusion>,
    /// Every kept run in brief (sorted by mode then index by [`Stats`]).
    #[serde(default)]
    pub runs: Vec<RunSummary>,
    /// Σ over shards of the wall time of the simulation phase, s.
    pub wall_s: f64,
    /// Σ over shards of thread count × wall time, core·s.
    pub core_s: f64,
}

/// Everything needed to produce the reports: written as `stats.json` by every run (shard or
/// not) and read back by `merge`. The fields are private so that what the accessors document
/// holds: modes in `Mode::EVERY` order, each once, all with the same number of time bins, at least one; run
/// ranges sorted, disjoint and within `0..runs_total`; exclusions and kept runs sorted by mode
/// then run index, of modes present. A `stats.json` that breaks one is refused on load
/// ([`SimError::StatsInvalid`] names the field).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "StatsFile")]
pub struct Stats {
    /// File format tag.
    format: String,
    /// FNV-1a hash of the scenario (shards must agree).
    scenario_fingerprint: String,
    /// Where the scenario came from (its file).
    scenario_source: String,
    /// `Scenario::assumptions()`.
    assumptions: Vec<String>,
    /// σ of the simulated sighting-device noise, m (`[sighting] noise_var_m2`, square-rooted), for
    /// the reports; absent in files written before it was recorded.
    #[serde(default)]
    sd_noise_sigma_m: Option<f64>,
    /// Flight duration, s.
    duration_s: f64,
    /// Master seed.
    seed: u64,
    /// Runs per mode over all shards.
    runs_total: u64,
    /// Run indices covered by the shards merged here: half-open ranges (sorted by [`Stats`]).
    run_ranges: Vec<(u64, u64)>,
    /// Shards merged into this file (one entry for a single run).
    shards: Vec<ShardInfo>,
    /// Per mode (in `Mode::EVERY` order, checked by [`Stats`]).
    modes: Vec<ModeStats>,
    /// Runs left out (sorted by mode then index by [`Stats`]).
    exclusions: Vec<Exclusion>,
    /// Every kept run in brief (sorted by mode then index by [`Stats`]).
    #[serde(default)]
    runs: Vec<RunSummary>,
    /// Σ over shards of the wall time of the simulation phase, s.
    wall_s: f64,
    /// Σ over shards of thread count × wall time, core·s.
    core_s: f64,
}

impl TryFrom<StatsFile> for Stats {
    type Error = SimError;

    /// Sorts the run ranges, exclusions and runs, then checks the invariants of [`Stats`].
    fn try_from(mut f: StatsFile) -> Result<Stats, SimError> {
        let invalid = |field, reason: String| SimError::StatsInvalid { field, reason };
        if f.format != FORMAT {
            return Err(SimError::StatsFormat { found: f.format });
        }
        for w in f.modes.windows(2) {
            if w[0].mode.order() >= w[1].mode.order() {
                return Err(invalid(
                    "modes",
                    format!(
                        "`{}` after `{}`: modes must be distinct and in the order {}",
                        w[1].mode,
                        w[0].mode,
                        Mode::EVERY.map(Mode::name).join(", ")
                    ),
                ));
            }
        }
        if let Some(first) = f.modes.first()
            && let Some(m) = f.modes.iter().find(|m| m.bins.len() != first.bins.len())
        {
            return Err(invalid(
                "modes",
                format!(
                    "`{}` has {} time bins, `{}` {}",
                    m.mode,
                    m.bins.len(),
                    first.mode,
                    first.bins.len()
                ),
            ));
        }
        // Every report reads the bin of a time (clamped to the last bin): none without one.
        if let Some(m) = f.modes.iter().find(|m| m.bins.is_empty()) {
            return Err(invalid(
                "modes",
                format!("`{}` has no time bins (at least one is needed)", m.mode),
            ));
        }
        f.run_ranges.sort_unstable();
        for &(a, b) in &f.run_ranges {
            if a > b || b > f.runs_total {
                return Err(invalid(
                    "run_ranges",
                    format!("{a}..{b} is not a range within 0..{}", f.runs_total),
                ));
            }
        }
        for w in f.run_ranges.windows(2) {
            if w[1].0 < w[0].1 {
                return Err(SimError::StatsOverlap(w[0].0, w[0].1, w[1].0, w[1].1));
            }
        }
        let known = |m: Mode| f.modes.iter().any(|x| x.mode == m);
        if let Some(e) = f.exclusions.iter().find(|e| !known(e.mode)) {
            return Err(invalid(
                "exclusions",
                format!(
                    "run {} of mode `{}`, which has no statistics",
                    e.run_index, e.mode
                ),
            ));
        }
        if let Some(r) = f.runs.iter().find(|r| !known(r.mode)) {
            return Err(invalid(
                "runs",
                format!(
                    "run {} of mode `{}`, which has no statistics",
                    r.run_index, r.mode
                ),
            ));
        }
        f.exclusions.sort_by_key(|a| order_key(a.mode, a.run_index));
        f.runs.sort_by_key(|a| order_key(a.mode, a.run_index));
        Ok(Stats {
            format: f.format,
            scenario_fingerprint: f.scenario_fingerprint,
            scenario_source: f.scenario_source,
            assumptions: f.assumptions,
            sd_noise_sigma_m: f.sd_noise_sigma_m,
            duration_s: f.duration_s,
            seed: f.seed,
            runs_total: f.runs_total,
            run_ranges: f.run_ranges,
            shards: f.shards,
            modes: f.modes,
            exclusions: f.exclusions,
            runs: f.runs,
            wall_s: f.wall_s,
            core_s: f.core_s,
        })
    }
}

/// The format tag of `stats.json`.
pub const FORMAT: &str = "ita-nav-monte-carlo-stats/1";

/// FNV-1a 64 of a string, as 16 hex digits.
pub fn fingerprint(text: &str) -> String {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in text.bytes() {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    format!("{h:016x}")
}

/// The fingerprint of a scenario that `stats.json` records and `merge` compares: FNV-1a of its
/// `Debug` text. The `[filter]` section's type was called `FilterConfig` when the format was
/// fixed; its text is kept under that name, so fingerprints (and shards written before the
/// rename to [`crate::ScenarioFilterConfig`]) stay the same.
pub fn scenario_fingerprint(scenario: &crate::Scenario) -> String {
    let text = format!("{scenario:?}").replacen(
        "filter: ScenarioFilterConfig {",
        "filter: FilterConfig {",
        1,
    );
    fingerprint(&text)
}

impl Stats {
    /// File format tag ([`FORMAT`]).
    pub fn format(&self) -> &str {
        &self.format
    }
    /// FNV-1a hash of the scenario (shards must agree).
    pub fn scenario_fingerprint(&self) -> &str {
        &self.scenario_fingerprint
    }
    /// Where the scenario came from (its file).
    pub fn scenario_source(&self) -> &str {
        &self.scenario_source
    }
    /// `Scenario::assumptions()`.
    pub fn assumptions(&self) -> &[String] {
        &self.assumptions
    }
    /// σ of the simulated sighting-device noise, m (absent in older files).
    pub fn sd_noise_sigma_m(&self) -> Option<f64> {
        self.sd_noise_sigma_m
    }
    /// Flight duration, s.
    pub fn duration_s(&self) -> f64 {
        self.duration_s
    }
    /// Master seed.
    pub fn seed(&self) -> u64 {
        self.seed
    }
    /// Runs per mode over all shards.
    pub fn runs_total(&self) -> u64 {
        self.runs_total
    }
    /// Run indices covered: half-open ranges, sorted and disjoint.
    pub fn run_ranges(&self) -> &[(u64, u64)] {
        &self.run_ranges
    }
    /// Shards merged into this file, by shard number.
    pub fn shards(&self) -> &[ShardInfo] {
        &self.shards
    }
    /// Per mode, in `Mode::EVERY` order, each mode once.
    pub fn modes(&self) -> &[ModeStats] {
        &self.modes
    }
    /// Runs left out, sorted by mode (`Mode::EVERY` order) then index.
    pub fn exclusions(&self) -> &[Exclusion] {
        &self.exclusions
    }
    /// Every kept run in brief, sorted by mode then index.
    pub fn runs(&self) -> &[RunSummary] {
        &self.runs
    }
    /// Σ over shards of the wall time of the simulation phase, s.
    pub fn wall_s(&self) -> f64 {
        self.wall_s
    }
    /// Σ over shards of thread count × wall time, core·s.
    pub fn core_s(&self) -> f64 {
        self.core_s
    }

    /// Statistics of one mode.
    pub fn mode(&self, mode: Mode) -> Option<&ModeStats> {
        self.modes.iter().find(|m| m.mode == mode)
    }

    /// Runs covered (Σ of the range lengths).
    pub fn runs_covered(&self) -> u64 {
        self.run_ranges.iter().map(|(a, b)| b - a).sum()
    }
}

/// Sort key: mode in `Mode::EVERY` order, then run index.
pub fn order_key(mode: Mode, run_index: u64) -> (usize, u64) {
    (mode.order(), run_index)
}

/// First record holding a non-finite value, with the field's name (a run with one is left out
/// of the statistics).
pub fn first_non_finite(samples: &[Sample]) -> Option<(f64, &'static str)> {
    for s in samples {
        let checks: [(&'static str, bool); 6] = [
            (
                "position error",
                s.pos_err_ned_m.iter().all(|x| x.is_finite()),
            ),
            (
                "velocity error",
                s.vel_err_ned_mps.iter().all(|x| x.is_finite()),
            ),
            (
                "misalignment",
                s.misalignment_rad.iter().all(|x| x.is_finite()),
            ),
            ("distance", s.distance_m.is_finite()),
            ("NEES", s.nees.is_none_or(f64::is_finite)),
            ("NIS", s.nis.is_none_or(f64::is_finite)),
        ];
        if let Some((what, _)) = checks.iter().find(|(_, ok)| !ok) {
            return Some((s.t_s, what));
        }
    }
    None
}

#[cfg(test)]
mod tests;
