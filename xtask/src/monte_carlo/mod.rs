//! `cargo xtask monte-carlo`: the paper's Monte Carlo experiment (Lustosa, Chagas & Waldmann,
//! §6, Figs. 1–6) over the closed loop `nav_app::ins_sd`, and `cargo xtask monte-carlo merge`.
//!
//! ```text
//! cargo xtask monte-carlo [--config configs/paper.toml] [--runs N] [--seed S] [--out DIR]
//!                         [--threads T] [--shard i/n] [--duration SECONDS]
//! cargo xtask monte-carlo merge DIR… [--out DIR] [--allow-partial]
//! ```
//!
//! With no arguments it runs `configs/paper.toml` (the built-in paper scenario if that file is
//! absent): 3 configurations (`standalone`, `kf`, `akf`) × `[monte_carlo] runs` (100) × 900 s
//! at 100 Hz, on all cores, and prints the output directory
//! (`target/monte-carlo/<config>-seed<S>-runs<N>/` by default).
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
//! `xtask/assets/` (licence beside it), so PNG and SVG carry the same labels.
//!
//! ## Beyond one machine: shards
//!
//! `--shard i/n` (1 ≤ i ≤ n) simulates only the i-th of n contiguous slices of the run indices
//! `0..runs` and writes just `stats.json`; `merge` checks that the shards share scenario
//! (fingerprint), seed and total run count and do not overlap, adds their sums and writes the
//! same outputs as one run over all indices (equal to round-off, tested). A merge with missing
//! slices is refused unless `--allow-partial` (then `summary.md` says which runs are missing).
//!
//! 10 000 runs as a Slurm job array of 100 tasks (build once on the shared file system with
//! `cargo build --release -p xtask`):
//!
//! ```text
//! #!/bin/bash
//! #SBATCH --array=1-100
//! #SBATCH --cpus-per-task=2
//! target/release/xtask monte-carlo --runs 10000 --seed 2009 --threads "$SLURM_CPUS_PER_TASK" \
//!     --shard "$SLURM_ARRAY_TASK_ID/100" --out "mc/shard-$SLURM_ARRAY_TASK_ID"
//! ```
//!
//! then, after the array (`sbatch --dependency=afterok:<array job id> …`):
//! `target/release/xtask monte-carlo merge mc/shard-* --out mc/all`.
//!
//! The same with GNU parallel over ssh hosts sharing the directory:
//!
//! ```text
//! seq 1 100 | parallel -S 2/host1,2/host2 --workdir "$PWD" \
//!     target/release/xtask monte-carlo --runs 10000 --threads 1 --shard {}/100 --out mc/shard-{}
//! target/release/xtask monte-carlo merge mc/shard-* --out mc/all
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
pub mod export;
pub mod plot;
pub mod report;
pub mod scenarios;
/// The mergeable statistics live in nav-app's INS half (`nav_app::ins_sd::stats`).
pub use nav_app::ins_sd::stats;
pub mod sweep;

#[cfg(test)]
mod tests;

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail, ensure};
use clap::{Args, Subcommand};
use nav_app::ins_sd::{self, Mode, Scenario};

use stats::{FORMAT, ShardInfo, Stats};

/// Arguments of `cargo xtask monte-carlo`.
#[derive(Args, Debug, Default)]
#[command(args_conflicts_with_subcommands = true)]
pub struct MonteCarloArgs {
    /// `merge DIR…`: combine shard statistics.
    #[command(subcommand)]
    pub cmd: Option<McCmd>,
    /// Options of a simulation run.
    #[command(flatten)]
    pub run: RunArgs,
}

/// Subcommands of `cargo xtask monte-carlo`.
#[derive(Subcommand, Debug)]
pub enum McCmd {
    /// Merge the `stats.json` of shard directories into the outputs of one run.
    Merge(MergeArgs),
    /// The matched case and every model-mismatch scenario of configs/mismatch/ (KF and AKF,
    /// same seeds) in one comparison table.
    Scenarios(Box<scenarios::ScenariosArgs>),
}

/// Options of a simulation run.
#[derive(Args, Debug, Default, Clone)]
pub struct RunArgs {
    /// Scenario file [default: configs/paper.toml, or the built-in paper scenario if absent].
    #[arg(long)]
    pub config: Option<PathBuf>,
    /// Runs per configuration [default: the scenario's `[monte_carlo] runs`].
    #[arg(long)]
    pub runs: Option<usize>,
    /// Master seed [default: the scenario's `[monte_carlo] seed`].
    #[arg(long)]
    pub seed: Option<u64>,
    /// Output directory [default: target/monte-carlo/<config>-seed<S>-runs<N>[-shard-i-of-n]].
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Worker threads [default: all cores].
    #[arg(long)]
    pub threads: Option<usize>,
    /// Simulate only slice i of n of the run indices (1-based, e.g. 3/10); writes stats.json.
    #[arg(long, value_name = "i/n")]
    pub shard: Option<String>,
    /// Cut the flight to its first SECONDS (quick looks and tests).
    #[arg(long, value_name = "SECONDS")]
    pub duration: Option<f64>,
    /// Also write run 0 of the KF and the AKF as IMU/sighting/truth logs into DIR/kf and
    /// DIR/akf, for `nav-app ins` (formats: nav_app::ins_sd::logs).
    #[arg(long, value_name = "DIR")]
    pub export_logs: Option<PathBuf>,
    /// Configurations to simulate, comma-separated, on the same flights (common random
    /// numbers): standalone, kf, akf, akf_sage_husa, akf_structured [default: the paper's
    /// standalone,kf,akf].
    #[arg(long, value_name = "LIST")]
    pub filters: Option<String>,
    /// Sweep a scenario key over values on the same seeds instead of one Monte Carlo:
    /// `section.key[+section.key]=V1,V2,…` (e.g. `filter.akf_window=5,10,20,40`); KF and AKF
    /// unless --filters; writes sweep.md, sweep.csv and sweep_final_error.svg/png.
    #[arg(long, value_name = "KEY=V1,V2,…")]
    pub sweep: Option<String>,
}

/// Options of `merge`.
#[derive(Args, Debug, Clone)]
pub struct MergeArgs {
    /// Shard output directories (each holding a stats.json).
    #[arg(required = true)]
    pub dirs: Vec<PathBuf>,
    /// Output directory [default: target/monte-carlo/merged-seed<S>-runs<N>].
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Write the outputs even if some run indices are missing (marked partial).
    #[arg(long)]
    pub allow_partial: bool,
}

/// Entry point of the subcommand.
pub fn run(args: MonteCarloArgs) -> Result<()> {
    match args.cmd {
        Some(McCmd::Merge(m)) => merge(&m).map(|_| ()),
        Some(McCmd::Scenarios(a)) => {
            scenarios::run(&a, &workspace_root(), &target_dir()).map(|_| ())
        }
        None => simulate(&args.run).map(|_| ()),
    }
}

fn workspace_root() -> PathBuf {
    let manifest = Path::new(env!("CARGO_MANIFEST_DIR"));
    manifest.parent().unwrap_or(manifest).to_path_buf()
}

fn target_dir() -> PathBuf {
    std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| workspace_root().join("target"))
}

/// Parses `i/n` (1 ≤ i ≤ n).
pub fn parse_shard(text: &str) -> Result<ShardInfo> {
    let (i, n) = text
        .split_once('/')
        .with_context(|| format!("--shard `{text}`: expected i/n, e.g. 2/10"))?;
    let index: u64 = i
        .trim()
        .parse()
        .with_context(|| format!("--shard `{text}`: shard number `{i}` is not an integer"))?;
    let count: u64 = n
        .trim()
        .parse()
        .with_context(|| format!("--shard `{text}`: shard count `{n}` is not an integer"))?;
    ensure!(
        count >= 1,
        "--shard `{text}`: the shard count must be at least 1"
    );
    ensure!(
        (1..=count).contains(&index),
        "--shard `{text}`: the shard number must be between 1 and {count} (1-based)"
    );
    Ok(ShardInfo { index, count })
}

/// Loads the scenario named by `--config` (or the default) and applies `--duration`.
/// Returns it with a description of its source.
pub fn load_scenario(args: &RunArgs) -> Result<(Scenario, String)> {
    let (scenario, source) = match &args.config {
        Some(path) => {
            let text = std::fs::read_to_string(path)
                .with_context(|| format!("cannot read the scenario {}", path.display()))?;
            // The error names the file, line and column itself.
            let s = Scenario::from_toml_named(&path.display().to_string(), &text)?;
            (s, path.display().to_string())
        }
        None => {
            let path = workspace_root().join("configs/paper.toml");
            match std::fs::read_to_string(&path) {
                Ok(text) => (
                    Scenario::from_toml_named(&path.display().to_string(), &text)?,
                    "configs/paper.toml".to_string(),
                ),
                Err(_) => (
                    Scenario::paper_default(),
                    "built-in paper default".to_string(),
                ),
            }
        }
    };
    match args.duration {
        None => Ok((scenario, source)),
        Some(d) => {
            ensure!(
                d.is_finite() && d >= 1.0 && d <= scenario.duration_s(),
                "--duration {d}: must be between 1 and the scenario's {} s",
                scenario.duration_s()
            );
            let s = scenario
                .truncated(d)
                .with_context(|| format!("--duration {d}"))?;
            Ok((s, format!("{source}, first {d} s")))
        }
    }
}

/// Everything resolved from [`RunArgs`] before simulating.
#[derive(Debug, Clone)]
pub struct Resolved {
    /// The scenario.
    pub scenario: Scenario,
    /// Its source, for the reports.
    pub source: String,
    /// Runs per configuration over all shards.
    pub runs: u64,
    /// Master seed.
    pub seed: u64,
    /// Threads.
    pub threads: usize,
    /// Shard (1/1 when not sharded).
    pub shard: ShardInfo,
    /// Whether `--shard` was given.
    pub sharded: bool,
    /// Output directory.
    pub out: PathBuf,
    /// Configurations simulated, in report order.
    pub modes: Vec<Mode>,
}

/// Parses `--filters a,b,…` into modes in report order.
pub fn parse_filters(text: &str) -> Result<Vec<Mode>> {
    let mut modes = Vec::new();
    for name in text.split(',').map(str::trim).filter(|s| !s.is_empty()) {
        let m = Mode::from_name(name).with_context(|| {
            format!(
                "--filters: `{name}` is not one of {}",
                Mode::EVERY.map(Mode::name).join(", ")
            )
        })?;
        if !modes.contains(&m) {
            modes.push(m);
        }
    }
    ensure!(!modes.is_empty(), "--filters: no configuration given");
    modes.sort_by_key(|m| Mode::EVERY.iter().position(|x| x == m));
    Ok(modes)
}

/// Checks and resolves the arguments (clear errors for bad values).
pub fn resolve(args: &RunArgs) -> Result<Resolved> {
    if let Some(0) = args.runs {
        bail!("--runs 0: at least one run is needed");
    }
    if let Some(0) = args.threads {
        bail!("--threads 0: at least one thread is needed");
    }
    let shard = args.shard.as_deref().map(parse_shard).transpose()?;
    let (scenario, source) = load_scenario(args)?;
    let runs = args.runs.unwrap_or_else(|| scenario.default_runs()) as u64;
    ensure!(runs >= 1, "the scenario's [monte_carlo] runs is 0");
    if let Some(sh) = shard {
        ensure!(
            sh.count <= runs,
            "--shard {}/{}: more shards than runs ({runs})",
            sh.index,
            sh.count
        );
    }
    let seed = args.seed.unwrap_or(scenario.monte_carlo.seed);
    let threads = args.threads.unwrap_or_else(|| {
        std::thread::available_parallelism()
            .map(|n| n.get())
            .unwrap_or(1)
    });
    let stem = args
        .config
        .as_ref()
        .and_then(|p| p.file_stem())
        .map_or_else(|| "paper".to_string(), |s| s.to_string_lossy().into_owned());
    let out = args.out.clone().unwrap_or_else(|| {
        let mut name = format!("{stem}-seed{seed}-runs{runs}");
        if let Some(d) = args.duration {
            name.push_str(&format!("-{d}s"));
        }
        if let Some(sh) = shard {
            name.push_str(&format!("-shard-{}-of-{}", sh.index, sh.count));
        }
        target_dir().join("monte-carlo").join(name)
    });
    let modes = match &args.filters {
        Some(f) => parse_filters(f)?,
        None => Mode::ALL.to_vec(),
    };
    Ok(Resolved {
        modes,
        scenario,
        source,
        runs,
        seed,
        threads,
        shard: shard.unwrap_or(ShardInfo { index: 1, count: 1 }),
        sharded: shard.is_some(),
        out,
    })
}

/// Simulates the resolved plan with the real closed loop and returns its statistics.
pub fn simulate_stats(r: &Resolved, progress: bool) -> Result<Stats> {
    let samples = r.scenario.samples_per_run();
    let range = stats::shard_range(r.runs, r.shard.index, r.shard.count);
    let plan = driver::Plan {
        modes: r.modes.clone(),
        samples,
        range,
        threads: r.threads,
        progress,
    };
    let scenario = &r.scenario;
    let seed = r.seed;
    let sim = driver::simulate(&plan, |mode, index, out| {
        ins_sd::run(scenario, mode, ins_sd::run_seed(seed, mode, index), out)
    })?;
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

/// `cargo xtask monte-carlo`: simulate, write, print. Returns the output directory.
pub fn simulate(args: &RunArgs) -> Result<PathBuf> {
    let r = resolve(args)?;
    if let Some(text) = &args.sweep {
        let sw = sweep::parse_sweep(text)?;
        let modes = match &args.filters {
            Some(_) => r.modes.clone(),
            None => vec![Mode::Kf, Mode::Akf],
        };
        let out = args.out.clone().unwrap_or_else(|| {
            let keys: Vec<String> = sw.keys.iter().map(|(s, k)| format!("{s}.{k}")).collect();
            target_dir().join("monte-carlo").join(format!(
                "sweep-{}-runs{}",
                keys.join("+"),
                r.runs
            ))
        });
        sweep::run_sweep(&r.scenario, &sw, &modes, r.runs, r.threads, &out)?;
        return Ok(out);
    }
    let (lo, hi) = stats::shard_range(r.runs, r.shard.index, r.shard.count);
    eprintln!(
        "monte-carlo: {} runs{} × {} configurations × {} s, seed {}, {} thread(s), scenario {}",
        hi - lo,
        if r.sharded {
            format!(
                " (indices {lo}..{hi}, shard {}/{} of {})",
                r.shard.index, r.shard.count, r.runs
            )
        } else {
            String::new()
        },
        r.modes.len(),
        r.scenario.duration_s(),
        r.seed,
        r.threads,
        r.source
    );
    let stats = simulate_stats(&r, true)?;
    write_outputs(&r.out, &stats, !r.sharded)?;
    print_done(&r.out, &stats, !r.sharded);
    if let Some(dir) = &args.export_logs {
        export::export_logs(&r, dir)?;
    }
    Ok(r.out)
}

fn print_done(out: &Path, stats: &Stats, full: bool) {
    let (epochs, per_core, per_wall) = report::throughput(stats);
    println!(
        "monte-carlo: {epochs} epochs in {:.2} s wall: {per_core:.0} epochs/s per core, {per_wall:.0} epochs/s aggregate",
        stats.wall_s
    );
    if full {
        for m in &stats.modes {
            if let Some(last) = m.bins.last() {
                println!(
                    "monte-carlo: {:<10} final 3-D RMS {:.1} m, horizontal RMS {:.1} m ({} runs used)",
                    m.mode,
                    last[stats::qi::POS_3D].rms(),
                    last[stats::qi::POS_H].rms(),
                    m.runs_used
                );
            }
        }
        if !stats.exclusions.is_empty() {
            println!(
                "monte-carlo: {} run(s) excluded (see summary.md)",
                stats.exclusions.len()
            );
        }
        println!("monte-carlo: wrote {}", out.join("summary.md").display());
    } else {
        println!(
            "monte-carlo: wrote {} (merge the shards with `cargo xtask monte-carlo merge DIR…`)",
            out.join("stats.json").display()
        );
    }
}

/// `cargo xtask monte-carlo merge`. Returns the output directory.
pub fn merge(args: &MergeArgs) -> Result<PathBuf> {
    let mut parts = Vec::new();
    for dir in &args.dirs {
        let path = dir.join("stats.json");
        let text = std::fs::read_to_string(&path)
            .with_context(|| format!("cannot read {}", path.display()))?;
        let s: Stats = serde_json::from_str(&text)
            .with_context(|| format!("{} is not a Monte Carlo stats file", path.display()))?;
        parts.push(s);
    }
    let merged = stats::merge(parts)?;
    let missing = stats::missing_ranges(&merged);
    if !missing.is_empty() && !args.allow_partial {
        bail!(
            "merge: {} of {} runs present; missing run indices {} (pass --allow-partial to write a partial summary)",
            merged.runs_covered(),
            merged.runs_total,
            missing
                .iter()
                .map(|(a, b)| format!("{a}..{b}"))
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    let out = args.out.clone().unwrap_or_else(|| {
        target_dir().join("monte-carlo").join(format!(
            "merged-seed{}-runs{}",
            merged.seed, merged.runs_total
        ))
    });
    write_outputs(&out, &merged, true)?;
    print_done(&out, &merged, true);
    Ok(out)
}

/// All output files of `stats`: `(name, bytes)`, summary.md last.
pub fn render(stats: &Stats, full: bool) -> Result<Vec<(String, Vec<u8>)>> {
    let mut files = vec![(
        "stats.json".to_string(),
        serde_json::to_vec(stats).context("serialising stats.json")?,
    )];
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
            report::summary_json(stats)?.into_bytes(),
        ));
        files.push((
            "summary.md".to_string(),
            report::summary_md(stats).into_bytes(),
        ));
    }
    Ok(files)
}

/// Writes the outputs into `dir`: each file under `.NAME.partial`, then renamed, `summary.md`
/// last; an older `summary.md` is removed before the renames.
pub fn write_outputs(dir: &Path, stats: &Stats, full: bool) -> Result<()> {
    let files = render(stats, full)?;
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let partial = |name: &str| dir.join(format!(".{name}.partial"));
    for (name, bytes) in &files {
        std::fs::write(partial(name), bytes)
            .with_context(|| format!("cannot write {}", partial(name).display()))?;
    }
    let summary = dir.join("summary.md");
    if summary.exists() {
        std::fs::remove_file(&summary)
            .with_context(|| format!("cannot remove the old {}", summary.display()))?;
    }
    for (name, _) in &files {
        std::fs::rename(partial(name), dir.join(name))
            .with_context(|| format!("cannot rename into {}", dir.join(name).display()))?;
    }
    Ok(())
}
