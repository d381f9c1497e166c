//! # ins-monte-carlo — the paper's Monte Carlo as a library
//!
//! The paper's Monte Carlo experiment (Lustosa, Chagas & Waldmann, §6, Figs. 1–6) over the
//! closed loop of crate [`ins_sim`]: the driver on a rayon pool ([`driver`]; every run goes
//! through the one run loop `ins_sim::runs::run_range` and its exclusion rule, on the one pool
//! builder [`pool`]), the options ([`options`]) and outputs ([`outputs`]), the mergeable
//! statistics ([`stats`], in `ins-sim` so that the Python package shares them without rayon and
//! plotters), the reports ([`report`], [`summary`]), the figures ([`plot`]), the
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
//! Run i of every configuration uses `ins_sim::run_seed(S, i)`: seeds depend on the
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
//! The one exclusion rule (`ins_sim::runs`, the same in the sweeps, the scenario table and
//! Python): a run that returns `ins_sim::SimError` (non-finite state, a sighting or filter failure),
//! writes too few records, or whose records hold a NaN/∞, is excluded from its configuration's statistics, printed on stderr with
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
//! `crates/ins-plot/assets/` (licence beside it; crate `ins_plot` draws what these figures share
//! with the replay's), so PNG and SVG carry the same labels.
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
//! INS steps per second per core = Σ 100 Hz INS steps of all runs / Σ per-run wall time
//! (each run is single-threaded), printed and in `summary.md`; the aggregate rate over the
//! simulation's wall time is given beside it.

pub mod driver;
mod error;
pub mod export;
mod notes;
pub mod options;
pub mod outputs;
pub mod plot;
pub mod report;
pub mod scenarios;
pub mod summary;
pub mod sweep;

pub use driver::{Progress, Silent};
pub use error::McError;
/// The mergeable statistics live in `ins-sim` (`ins_sim::stats`), which the Python package uses
/// without this crate's rayon and plotters.
pub use ins_sim::stats;
pub use options::{
    Resolved, RunOptions, load_scenario, parse_filters, parse_shard, resolve, thread_count,
};
pub use outputs::{build_stats, merge_dirs, render, simulate_stats, write_outputs};

/// The one builder of the worker pool (driver, sweeps and the scenario table): `threads`
/// workers, or one per core ([`thread_count`]).
pub fn pool(threads: Option<usize>) -> Result<rayon::ThreadPool, McError> {
    Ok(rayon::ThreadPoolBuilder::new()
        .num_threads(thread_count(threads)?)
        .build()?)
}

#[cfg(test)]
mod tests;
