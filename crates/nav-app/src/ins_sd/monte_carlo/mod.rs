//! The paper's Monte Carlo experiment (Lustosa, Chagas & Waldmann, §6, Figs. 1–6) over the
//! closed loop [`crate::ins_sd`], as a library (feature `monte-carlo`): the driver on a rayon
//! pool ([`driver`]), the mergeable statistics ([`stats`], in the `ins` half so that the Python
//! package shares them), the reports ([`report`], [`summary`]), the figures ([`plot`]), the
//! model-mismatch table ([`scenarios`]), the sweeps ([`sweep`]) and the log export ([`export`]).
//! The product binary runs it:
//!
//! ```text
//! nav-app monte-carlo [--config configs/paper.toml] [--runs N] [--seed S] [--out DIR]
//!                     [--threads T] [--shard i/n] [--duration SECONDS] [--filters LIST]
//!                     [--sweep KEY=V1,…] [--export-logs DIR]
//! nav-app monte-carlo merge DIR… [--out DIR] [--allow-partial]
//! nav-app monte-carlo scenarios [--dir configs/mismatch] [--matched configs/paper.toml] …
//! ```
//!
//! and `cargo xtask monte-carlo` (the README's main job) drives that binary on the workspace's
//! `configs/paper.toml`: 3 configurations (`standalone`, `kf`, `akf`) × `[monte_carlo] runs`
//! (100) × 900 s at 100 Hz, on all cores. The scenario is always read from a file: a missing
//! file is an error ([`McError::Io`]), never a silent fall-back to a built-in scenario.
//!
//! ## Randomness and reproducibility
//!
//! Run i of every configuration uses `nav_app::ins_sd::run_seed(S, mode, i)`: seeds depend on the
//! master seed and the run index only, and the closed loop ignores the mode for the draw, so
//! the three configurations of one run index fly the same truth with the same IMU errors and
//! noise (common random numbers: the comparisons are paired). The records of a block of runs
//! are folded into the statistics in run-index order, so the statistics are bit-identical for
//! any `--threads` (tested).
//!
//! ## Statistics
//!
//! Per configuration, per 1 Hz time bin and per quantity (position error N/E/D, horizontal and
//! 3-D; velocity error; misalignment ψ N/E/D; distance flown; NEES; NIS): the count, Σx and Σx²
//! over the runs kept (`stats.json`). Mean = Σx/n, σ = √((Σx² − n·mean²)/(n − 1)) (sample σ
//! over runs), RMS = √(Σx²/n). These sums merge exactly (up to round-off) across shards.
//!
//! * `final_position_error_m` = RMS over runs of |δp| (3-D) at the final time;
//!   `final_horizontal_error_m` likewise with √(δN² + δE²).
//! * NEES (n = 15) and NIS (m = 6) are recorded at SD epochs. For M runs kept, M·(average) ~
//!   χ²(M·n) if the filter is consistent, so the two-sided 95 % band for the run average is
//!   [χ²_{0.025}(Mn), χ²_{0.975}(Mn)]/M, computed by `akf::average_band` (exact χ² quantiles, statrs;
//!   M = 100, n = 15 → [13.95, 16.09], matching docs/ins-sd.md, tested). `summary.md` reports the
//!   overall average and the fraction of epochs whose run average lies inside, above (the filter
//!   is over-confident) or below (under-confident) its band.
//!
//! ## Failure
//!
//! A run that returns `RunError` (non-finite state, a sighting or filter failure), or whose
//! records hold a NaN/∞, is excluded from its configuration's statistics, printed on stderr with
//! its index and time, and listed and counted in `summary.md` / `summary.json`; it is never
//! averaged in. An invalid config names the field (from `Scenario::from_toml_str`). Every
//! output file is written under a temporary name (`.NAME.partial`) and renamed at the end,
//! `summary.md` last (an older `summary.md` is removed first): an interrupted run leaves no
//! summary presented as complete.
//!
//! ## Outputs
//!
//! `summary.md`, `summary.json`, `stats.json` (mergeable), `timeseries_<mode>.csv` (1 Hz: mean
//! and σ of each component, 3-D RMS, distance, NEES/NIS averages and bands) and
//! `fig1_standalone_mean`, `fig2_akf_mean`, `fig3_kf_mean`, `fig4_standalone_sigma`,
//! `fig5_akf_sigma`, `fig6_kf_sigma` in `.svg` and `.png` (the paper's numbering; each figure has
//! the position error N/E/D in m above the misalignment N/E/D in mrad), plus two of ours:
//! `fig7_nees_nis` (run-averaged NEES and NIS of the filters vs time, log scale, with their 95 %
//! bands dashed) and `fig8_position_rms` (RMS over runs of the 3-D position error, every
//! configuration, log scale). Text in the figures uses DejaVu Sans bundled under
//! `crates/nav-app/assets/` (licence beside it), so PNG and SVG carry the same labels.
//! `summary.json` is [`summary::SummaryJson`], a serde structure with a `schema` version
//! ([`summary::SUMMARY_SCHEMA`]).
//!
//! ## Beyond one machine: shards
//!
//! `--shard i/n` (1 ≤ i ≤ n) simulates only the i-th of n contiguous slices of the run indices
//! `0..runs` and writes just `stats.json`; `merge` checks that the shards share scenario
//! (fingerprint), seed and total run count and do not overlap, adds their sums and writes the
//! same outputs as one run over all indices (equal to round-off, tested). A merge with missing
//! slices is refused unless `--allow-partial` (then `summary.md` says which runs are missing).
//!
//! 10 000 runs as a Slurm job array of 100 tasks (build the product binary once on the shared
//! file system with `cargo build --release -p nav-app`; it needs nothing of the source tree but
//! the scenario file):
//!
//! ```text
//! #!/bin/bash
//! #SBATCH --array=1-100
//! #SBATCH --cpus-per-task=2
//! target/release/nav-app monte-carlo --config configs/paper.toml --runs 10000 --seed 2009 \
//!     --threads "$SLURM_CPUS_PER_TASK" --shard "$SLURM_ARRAY_TASK_ID/100" \
//!     --out "mc/shard-$SLURM_ARRAY_TASK_ID"
//! ```
//!
//! then, after the array (`sbatch --dependency=afterok:<array job id> …`):
//! `target/release/nav-app monte-carlo merge mc/shard-* --out mc/all`.
//!
//! The same with GNU parallel over ssh hosts sharing the directory:
//!
//! ```text
//! seq 1 100 | parallel -S 2/host1,2/host2 --workdir "$PWD" target/release/nav-app monte-carlo \
//!     --config configs/paper.toml --runs 10000 --threads 1 --shard {}/100 --out mc/shard-{}
//! target/release/nav-app monte-carlo merge mc/shard-* --out mc/all
//! ```
//!
//! A failed task is simply re-run with the same `--shard`: the shard's output depends only on
//! (config, seed, runs, i, n).
//!
//! ## Throughput
//!
//! Filter epochs per second per core = Σ 100 Hz INS epochs of all runs / Σ per-run wall time
//! (each run is single-threaded), printed and in `summary.md`; the aggregate rate over the
//! simulation's wall time is given beside it.

pub mod driver;
mod error;
pub mod export;
pub mod plot;
pub mod report;
pub mod scenarios;
pub mod summary;
pub mod sweep;

/// The mergeable statistics live in the INS half (`crate::ins_sd::stats`), which the Python
/// package uses without this module's rayon and plotters.
pub use super::stats;
pub use driver::{Progress, Silent};
pub use error::McError;

#[cfg(test)]
mod tests;

use std::path::{Path, PathBuf};

use super::{Mode, Scenario};
use stats::{FORMAT, ShardInfo, Stats};

/// What `nav-app monte-carlo` was asked to simulate, before it is checked ([`resolve`]).
#[derive(Debug, Clone)]
pub struct RunOptions {
    /// Scenario file (TOML, `configs/paper.toml` for the paper); a missing file is an error.
    pub config: PathBuf,
    /// Runs per configuration over all shards [None: the scenario's `[monte_carlo] runs`].
    pub runs: Option<u64>,
    /// Master seed [None: the scenario's `[monte_carlo] seed`].
    pub seed: Option<u64>,
    /// Output directory [None: `out_root/<config stem>-seed<S>-runs<N>[-<d>s][-shard-i-of-n]`].
    pub out: Option<PathBuf>,
    /// Parent of the default output directory.
    pub out_root: PathBuf,
    /// Worker threads [None: all cores].
    pub threads: Option<usize>,
    /// Simulate only this slice of the run indices.
    pub shard: Option<ShardInfo>,
    /// Cut the flight to its first seconds [None: the whole flight].
    pub duration_s: Option<f64>,
    /// Configurations, in any order [None: the paper's standalone, kf, akf].
    pub filters: Option<Vec<Mode>>,
}

impl RunOptions {
    /// The paper's run of the scenario in `config`: every option at its default, outputs under
    /// `out_root`.
    pub fn new(config: impl Into<PathBuf>, out_root: impl Into<PathBuf>) -> Self {
        RunOptions {
            config: config.into(),
            runs: None,
            seed: None,
            out: None,
            out_root: out_root.into(),
            threads: None,
            shard: None,
            duration_s: None,
            filters: None,
        }
    }
}

/// Parses `i/n` (1 ≤ i ≤ n), the `--shard` argument.
pub fn parse_shard(text: &str) -> Result<ShardInfo, McError> {
    let bad = |reason: String| McError::Argument {
        flag: "--shard",
        value: text.to_string(),
        reason,
    };
    let (i, n) = text
        .split_once('/')
        .ok_or_else(|| bad("expected i/n, e.g. 2/10".to_string()))?;
    let index: u64 = i
        .trim()
        .parse()
        .map_err(|_| bad(format!("shard number `{i}` is not an integer")))?;
    let count: u64 = n
        .trim()
        .parse()
        .map_err(|_| bad(format!("shard count `{n}` is not an integer")))?;
    if count < 1 {
        return Err(bad("the shard count must be at least 1".to_string()));
    }
    if !(1..=count).contains(&index) {
        return Err(bad(format!(
            "the shard number must be between 1 and {count} (1-based)"
        )));
    }
    Ok(ShardInfo { index, count })
}

/// Parses `--filters a,b,…` into modes in report order (`Mode::EVERY`'s).
pub fn parse_filters(text: &str) -> Result<Vec<Mode>, McError> {
    let mut modes = Vec::new();
    for name in text.split(',').map(str::trim).filter(|s| !s.is_empty()) {
        let m = Mode::from_name(name).ok_or_else(|| McError::Argument {
            flag: "--filters",
            value: text.to_string(),
            reason: format!(
                "`{name}` is not one of {}",
                Mode::EVERY.map(Mode::name).join(", ")
            ),
        })?;
        if !modes.contains(&m) {
            modes.push(m);
        }
    }
    if modes.is_empty() {
        return Err(McError::Argument {
            flag: "--filters",
            value: text.to_string(),
            reason: "no configuration given".to_string(),
        });
    }
    sort_modes(&mut modes);
    Ok(modes)
}

fn sort_modes(modes: &mut [Mode]) {
    modes.sort_by_key(|m| Mode::EVERY.iter().position(|x| x == m));
}

/// Reads a scenario file (errors name the file, line and column) and cuts it to `duration_s`.
pub fn load_scenario(path: &Path, duration_s: Option<f64>) -> Result<Scenario, McError> {
    let text = std::fs::read_to_string(path).map_err(|source| McError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let scenario = Scenario::from_toml_named(&path.display().to_string(), &text)?;
    match duration_s {
        None => Ok(scenario),
        Some(d) => {
            if !(d.is_finite() && d >= 1.0 && d <= scenario.duration_s()) {
                return Err(McError::Argument {
                    flag: "--duration",
                    value: d.to_string(),
                    reason: format!(
                        "must be between 1 and the scenario's {} s",
                        scenario.duration_s()
                    ),
                });
            }
            Ok(scenario.truncated(d)?)
        }
    }
}

/// Everything resolved from [`RunOptions`] before simulating.
#[derive(Debug, Clone)]
pub struct Resolved {
    /// The scenario.
    pub scenario: Scenario,
    /// Its source, for the reports (the file, and the cut).
    pub source: String,
    /// Runs per configuration over all shards.
    pub runs: u64,
    /// Master seed.
    pub seed: u64,
    /// Threads.
    pub threads: usize,
    /// Shard (1/1 when not sharded).
    pub shard: ShardInfo,
    /// Whether a shard was asked for.
    pub sharded: bool,
    /// Output directory.
    pub out: PathBuf,
    /// Configurations simulated, in report order.
    pub modes: Vec<Mode>,
}

/// Worker threads: `threads`, or every core.
pub fn thread_count(threads: Option<usize>) -> Result<usize, McError> {
    match threads {
        Some(0) => Err(McError::Argument {
            flag: "--threads",
            value: "0".to_string(),
            reason: "at least one thread is needed".to_string(),
        }),
        Some(t) => Ok(t),
        None => Ok(std::thread::available_parallelism()
            .map(|n| n.get())
            .unwrap_or(1)),
    }
}

/// Checks and resolves the options (an error names the option or the scenario field).
pub fn resolve(opts: &RunOptions) -> Result<Resolved, McError> {
    if let Some(0) = opts.runs {
        return Err(McError::Argument {
            flag: "--runs",
            value: "0".to_string(),
            reason: "at least one run is needed".to_string(),
        });
    }
    let threads = thread_count(opts.threads)?;
    let scenario = load_scenario(&opts.config, opts.duration_s)?;
    let mut source = opts.config.display().to_string();
    if let Some(d) = opts.duration_s {
        source.push_str(&format!(", first {d} s"));
    }
    let runs = opts.runs.unwrap_or_else(|| scenario.default_runs() as u64);
    if runs == 0 {
        return Err(McError::Argument {
            flag: "--runs",
            value: "(the scenario's [monte_carlo] runs) 0".to_string(),
            reason: "at least one run is needed".to_string(),
        });
    }
    if let Some(sh) = opts.shard
        && sh.count > runs
    {
        return Err(McError::Argument {
            flag: "--shard",
            value: format!("{}/{}", sh.index, sh.count),
            reason: format!("more shards than runs ({runs})"),
        });
    }
    let seed = opts.seed.unwrap_or(scenario.monte_carlo.seed);
    let stem = opts.config.file_stem().map_or_else(
        || "scenario".to_string(),
        |s| s.to_string_lossy().into_owned(),
    );
    let out = opts.out.clone().unwrap_or_else(|| {
        let mut name = format!("{stem}-seed{seed}-runs{runs}");
        if let Some(d) = opts.duration_s {
            name.push_str(&format!("-{d}s"));
        }
        if let Some(sh) = opts.shard {
            name.push_str(&format!("-shard-{}-of-{}", sh.index, sh.count));
        }
        opts.out_root.join(name)
    });
    let modes = match &opts.filters {
        Some(f) if f.is_empty() => {
            return Err(McError::Argument {
                flag: "--filters",
                value: String::new(),
                reason: "no configuration given".to_string(),
            });
        }
        Some(f) => {
            let mut m = f.clone();
            m.dedup();
            sort_modes(&mut m);
            m.dedup();
            m
        }
        None => Mode::ALL.to_vec(),
    };
    Ok(Resolved {
        modes,
        scenario,
        source,
        runs,
        seed,
        threads,
        shard: opts.shard.unwrap_or(ShardInfo { index: 1, count: 1 }),
        sharded: opts.shard.is_some(),
        out,
    })
}

/// Simulates the resolved plan with the real closed loop and returns its statistics.
pub fn simulate_stats(r: &Resolved, progress: &dyn Progress) -> Result<Stats, McError> {
    let samples = r.scenario.samples_per_run();
    let range = stats::shard_range(r.runs, r.shard.index, r.shard.count);
    let plan = driver::Plan {
        modes: r.modes.clone(),
        samples,
        range,
        threads: r.threads,
    };
    let scenario = &r.scenario;
    let seed = r.seed;
    let sim = driver::simulate(
        &plan,
        |mode, index, out| super::run(scenario, mode, super::run_seed(seed, mode, index), out),
        progress,
    )?;
    Ok(build_stats(r, range, sim))
}

/// Wraps a driver result into [`Stats`].
pub fn build_stats(r: &Resolved, range: (u64, u64), sim: driver::Simulated) -> Stats {
    let mut exclusions = sim.exclusions;
    exclusions.sort_by_key(|a| stats::order_key(&a.mode, a.run_index));
    let mut runs = sim.runs;
    runs.sort_by_key(|a| stats::order_key(&a.mode, a.run_index));
    Stats {
        format: FORMAT.to_string(),
        scenario_fingerprint: stats::fingerprint(&format!("{:?}", r.scenario)),
        scenario_source: r.source.clone(),
        assumptions: r.scenario.assumptions(),
        sd_noise_sigma_m: Some(r.scenario.sighting.noise_var_m2.sqrt()),
        duration_s: r.scenario.duration_s(),
        seed: r.seed,
        runs_total: r.runs,
        run_ranges: vec![range],
        shards: vec![r.shard],
        modes: sim.modes,
        exclusions,
        runs,
        wall_s: sim.wall_s,
        core_s: sim.wall_s * r.threads as f64,
    }
}

/// Reads the `stats.json` of each shard directory and merges them. With `allow_partial` false,
/// missing run indices are an error ([`McError::MissingRuns`]).
pub fn merge_dirs(dirs: &[PathBuf], allow_partial: bool) -> Result<Stats, McError> {
    let mut parts = Vec::new();
    for dir in dirs {
        let path = dir.join("stats.json");
        let text = std::fs::read_to_string(&path).map_err(|source| McError::Io {
            path: path.clone(),
            source,
        })?;
        let s: Stats =
            serde_json::from_str(&text).map_err(|source| McError::StatsFile { path, source })?;
        parts.push(s);
    }
    let merged = stats::merge(parts)?;
    let missing = stats::missing_ranges(&merged);
    if !missing.is_empty() && !allow_partial {
        return Err(McError::MissingRuns {
            present: merged.runs_covered(),
            total: merged.runs_total,
            missing: missing
                .iter()
                .map(|(a, b)| format!("{a}..{b}"))
                .collect::<Vec<_>>()
                .join(", "),
        });
    }
    Ok(merged)
}

/// All output files of `stats`: `(name, bytes)`, summary.md last. `full` false: `stats.json`
/// only (a shard).
pub fn render(stats: &Stats, full: bool) -> Result<Vec<(String, Vec<u8>)>, McError> {
    let mut files = vec![("stats.json".to_string(), serde_json::to_vec(stats)?)];
    if full {
        for m in &stats.modes {
            files.push((
                format!("timeseries_{}.csv", m.mode),
                report::timeseries_csv(m).into_bytes(),
            ));
        }
        files.extend(plot::figures(stats)?);
        files.push((
            "summary.json".to_string(),
            summary::summary_json(stats)?.into_bytes(),
        ));
        files.push((
            "summary.md".to_string(),
            summary::summary_md(stats).into_bytes(),
        ));
    }
    Ok(files)
}

/// Writes the outputs into `dir`: each file under `.NAME.partial`, then renamed, `summary.md`
/// last; an older `summary.md` is removed before the renames, so an interrupted run leaves no
/// summary presented as complete.
pub fn write_outputs(dir: &Path, stats: &Stats, full: bool) -> Result<(), McError> {
    let files = render(stats, full)?;
    let io = |path: PathBuf| move |source| McError::Io { path, source };
    std::fs::create_dir_all(dir).map_err(io(dir.to_path_buf()))?;
    let partial = |name: &str| dir.join(format!(".{name}.partial"));
    for (name, bytes) in &files {
        std::fs::write(partial(name), bytes).map_err(io(partial(name)))?;
    }
    let summary = dir.join("summary.md");
    if summary.exists() {
        std::fs::remove_file(&summary).map_err(io(summary.clone()))?;
    }
    for (name, _) in &files {
        std::fs::rename(partial(name), dir.join(name)).map_err(io(dir.join(name)))?;
    }
    Ok(())
}
