//! `nav-app monte-carlo`: the INS/SD paper's Monte Carlo from the product binary — argument
//! parsing, the progress bar and the printed lines over `ins_monte_carlo`.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::Result;
use clap::{Args, Parser, Subcommand};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use ins_monte_carlo::{self as mc, Progress, RunOptions, report, scenarios, stats, sweep};
use ins_sim::Mode;

const AFTER_HELP: &str = "\
With no options: the scenario configs/paper.toml in the current directory (an error if it is not
there: pass --config), its [monte_carlo] runs and seed, the paper's three configurations on all
cores; outputs in ./monte-carlo/<config>-seed<S>-runs<N>/ (summary.md, summary.json, stats.json,
timeseries_<mode>.csv, fig1–fig8 as SVG and PNG). `cargo xtask monte-carlo` runs this on the
workspace's configs/paper.toml with outputs under target/monte-carlo/.

An option given twice takes its last value (a wrapper such as xtask puts its settings first).

A shard (--shard i/n) writes only stats.json; `nav-app monte-carlo merge DIR…` adds the shards'
sums and writes the outputs of one run over all indices.

Exit codes: 0 success; 1 error (the scenario file, an option, a run that could not start, an
output that could not be written — each named); 2 bad command line.";

/// `nav-app monte-carlo`.
#[derive(Parser, Debug)]
#[command(
    name = "nav-app monte-carlo",
    bin_name = "nav-app monte-carlo",
    about = "The INS/SD paper's Monte Carlo (stand-alone INS, KF, AKF): summaries, CSV, Figs. 1–8",
    after_help = AFTER_HELP,
    args_conflicts_with_subcommands = true,
    args_override_self = true
)]
pub struct McArgs {
    /// `merge DIR…` or `scenarios`.
    #[command(subcommand)]
    cmd: Option<McCmd>,
    #[command(flatten)]
    run: RunArgs,
}

#[derive(Subcommand, Debug)]
enum McCmd {
    /// Merge the stats.json of shard directories into the outputs of one run.
    #[command(args_override_self = true)]
    Merge(MergeArgs),
    /// The matched case and every model-mismatch scenario (KF and AKF, same seeds) in one table.
    #[command(args_override_self = true)]
    Scenarios(ScenarioArgs),
}

/// Options of a simulation run.
#[derive(Args, Debug, Clone)]
struct RunArgs {
    /// Scenario file (TOML).
    #[arg(long, value_name = "FILE", default_value = "configs/paper.toml")]
    config: PathBuf,
    /// Runs per configuration [default: the scenario's `[monte_carlo] runs`].
    #[arg(long)]
    runs: Option<u64>,
    /// Master seed [default: the scenario's `[monte_carlo] seed`].
    #[arg(long)]
    seed: Option<u64>,
    /// Output directory [default: OUT_ROOT/<config>-seed<S>-runs<N>[-<d>s][-shard-i-of-n]].
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
    /// Parent of the default output directory.
    #[arg(long, value_name = "DIR", default_value = "monte-carlo")]
    out_root: PathBuf,
    /// Worker threads [default: all cores].
    #[arg(long)]
    threads: Option<usize>,
    /// Simulate only slice i of n of the run indices (1-based, e.g. 3/10); writes stats.json.
    #[arg(long, value_name = "i/n", value_parser = mc::parse_shard)]
    shard: Option<stats::ShardInfo>,
    /// Cut the flight to its first SECONDS (quick looks and tests).
    #[arg(long, value_name = "SECONDS")]
    duration: Option<f64>,
    /// Also write run 0 of the KF and the AKF as IMU/sighting/truth logs into DIR/kf and
    /// DIR/akf, for `nav-app ins` (formats: ins_sim::logs).
    #[arg(long, value_name = "DIR")]
    export_logs: Option<PathBuf>,
    /// Configurations to simulate, comma-separated, on the same flights (common random
    /// numbers): standalone, kf, akf, akf_sage_husa, akf_structured [default: the paper's
    /// standalone,kf,akf].
    #[arg(long, value_name = "LIST", value_parser = parse_filter_list)]
    filters: Option<FilterList>,
    /// Sweep a scenario key over values on the same seeds instead of one Monte Carlo:
    /// `section.key[+section.key]=V1,V2,…` (e.g. `filter.akf_window=5,10,20,40`); KF and AKF
    /// unless --filters; writes sweep.md, sweep.csv and sweep_final_error.svg/png.
    #[arg(long, value_name = "KEY=V1,V2,…", value_parser = sweep::parse_sweep)]
    sweep: Option<sweep::Sweep>,
}

/// `--filters`' value, the configurations in order. (A `Vec` field would tell clap to parse each
/// value as one `Mode`, and its parser returns the whole list: clap panicked on every
/// `--filters`.)
#[derive(Debug, Clone)]
struct FilterList(Vec<Mode>);

/// `--filters`' parser: `mc::parse_filters`.
fn parse_filter_list(text: &str) -> Result<FilterList, mc::McError> {
    mc::parse_filters(text).map(FilterList)
}

/// Options of `merge`.
#[derive(Args, Debug, Clone)]
struct MergeArgs {
    /// Shard output directories (each holding a stats.json).
    #[arg(required = true)]
    dirs: Vec<PathBuf>,
    /// Output directory [default: OUT_ROOT/merged-seed<S>-runs<N>].
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
    /// Parent of the default output directory.
    #[arg(long, value_name = "DIR", default_value = "monte-carlo")]
    out_root: PathBuf,
    /// Write the outputs even if some run indices are missing (marked partial).
    #[arg(long)]
    allow_partial: bool,
}

/// Options of `scenarios`.
#[derive(Args, Debug, Clone)]
struct ScenarioArgs {
    /// Directory of model-mismatch scenario files (every *.toml is a row).
    #[arg(long, value_name = "DIR", default_value = "configs/mismatch")]
    dir: PathBuf,
    /// The matched scenario (the first rows).
    #[arg(long, value_name = "FILE", default_value = "configs/paper.toml")]
    matched: PathBuf,
    /// Runs per scenario and filter.
    #[arg(long, default_value_t = 100)]
    runs: u64,
    /// Output directory [default: OUT_ROOT/scenarios-runs<N>].
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
    /// Parent of the default output directory.
    #[arg(long, value_name = "DIR", default_value = "monte-carlo")]
    out_root: PathBuf,
    /// Worker threads [default: all cores].
    #[arg(long)]
    threads: Option<usize>,
    /// Cut every flight to its first SECONDS (tests).
    #[arg(long, value_name = "SECONDS")]
    duration: Option<f64>,
}

/// A progress bar on stderr when it is a terminal; the notes (excluded runs, table rows) go to
/// stderr either way, above the bar.
struct Bar(ProgressBar);

impl Bar {
    fn new() -> Self {
        Bar(if std::io::stderr().is_terminal() {
            ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr())
        } else {
            ProgressBar::hidden()
        })
    }
}

impl Progress for Bar {
    fn start(&self, total: u64) {
        self.0.set_length(total);
        if let Ok(style) =
            ProgressStyle::with_template("{elapsed_precise} [{bar:40}] {pos}/{len} runs, ETA {eta}")
        {
            self.0.set_style(style);
        }
    }
    fn run_done(&self) {
        self.0.inc(1);
    }
    fn note(&self, line: &str) {
        self.0.suspend(|| eprintln!("{line}"));
    }
    fn finish(&self) {
        self.0.finish_and_clear();
    }
}

/// `nav-app monte-carlo …` (`args` from the subcommand's name on); returns the exit code.
pub fn main(args: impl IntoIterator<Item = std::ffi::OsString>) -> ExitCode {
    let args = McArgs::parse_from(args);
    match run(args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!(
                "nav-app monte-carlo: error: {}",
                crate::error_chain(e.as_ref())
            );
            ExitCode::from(1)
        }
    }
}

fn run(args: McArgs) -> Result<()> {
    match args.cmd {
        Some(McCmd::Merge(m)) => merge(&m),
        Some(McCmd::Scenarios(s)) => run_scenarios(&s),
        None => simulate(&args.run),
    }
}

fn simulate(a: &RunArgs) -> Result<()> {
    let opts = RunOptions {
        runs: a.runs,
        seed: a.seed,
        out: a.out.clone(),
        threads: a.threads,
        shard: a.shard,
        duration_s: a.duration,
        filters: a.filters.clone().map(|f| f.0),
        ..RunOptions::new(&a.config, &a.out_root)
    };
    let r = mc::resolve(&opts)?;
    if let Some(sw) = &a.sweep {
        let modes = match &a.filters {
            Some(_) => r.modes.clone(),
            None => vec![Mode::Kf, Mode::Akf],
        };
        let out = a.out.clone().unwrap_or_else(|| {
            let keys: Vec<String> = sw.keys.iter().map(|(s, k)| format!("{s}.{k}")).collect();
            a.out_root
                .join(format!("sweep-{}-runs{}", keys.join("+"), r.runs))
        });
        sweep::run_sweep(
            &r.scenario,
            sw,
            &modes,
            r.runs,
            r.threads,
            &out,
            &Bar::new(),
        )?;
        println!(
            "sweep: wrote {}/sweep.md, sweep.csv, sweep_final_error.svg/png",
            out.display()
        );
        return Ok(());
    }
    let (lo, hi) = stats::shard_range(r.runs, r.shard.index, r.shard.count)?;
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
    let st = mc::simulate_stats(&r, &Bar::new())?;
    mc::write_outputs(&r.out, &st, !r.sharded)?;
    print_done(&r.out, &st, !r.sharded);
    if let Some(dir) = &a.export_logs {
        for e in mc::export::export_logs(&r, dir)? {
            println!(
                "monte-carlo: exported run 0 ({}, {} s, seed {}) to {}; replay with:\n  {}",
                e.mode.name(),
                e.duration_s,
                e.seed,
                e.dir.display(),
                e.replay_command()
            );
        }
    }
    Ok(())
}

fn print_done(out: &Path, st: &stats::Stats, full: bool) {
    let (steps, per_core, per_wall) = report::throughput(st);
    println!(
        "monte-carlo: {steps} INS steps in {:.2} s wall: {per_core:.0} steps/s per core, {per_wall:.0} steps/s aggregate",
        st.wall_s()
    );
    if full {
        for m in st.modes() {
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
        if !st.exclusions().is_empty() {
            println!(
                "monte-carlo: {} run(s) excluded (see summary.md)",
                st.exclusions().len()
            );
        }
        println!("monte-carlo: wrote {}", out.join("summary.md").display());
    } else {
        println!(
            "monte-carlo: wrote {} (merge the shards with `nav-app monte-carlo merge DIR…`)",
            out.join("stats.json").display()
        );
    }
}

fn merge(a: &MergeArgs) -> Result<()> {
    let merged = mc::merge_dirs(&a.dirs, a.allow_partial)?;
    let out = a.out.clone().unwrap_or_else(|| {
        a.out_root.join(format!(
            "merged-seed{}-runs{}",
            merged.seed(),
            merged.runs_total()
        ))
    });
    mc::write_outputs(&out, &merged, true)?;
    print_done(&out, &merged, true);
    Ok(())
}

fn run_scenarios(a: &ScenarioArgs) -> Result<()> {
    let opts = scenarios::ScenarioOptions {
        dir: a.dir.clone(),
        matched: a.matched.clone(),
        runs: a.runs,
        out: a
            .out
            .clone()
            .unwrap_or_else(|| a.out_root.join(format!("scenarios-runs{}", a.runs))),
        threads: a.threads,
        duration_s: a.duration,
    };
    let start = std::time::Instant::now();
    let (_, path) = scenarios::run(&opts, &Bar::new())?;
    println!(
        "scenarios: wrote {} ({:.1} s)",
        path.display(),
        start.elapsed().as_secs_f64()
    );
    Ok(())
}
