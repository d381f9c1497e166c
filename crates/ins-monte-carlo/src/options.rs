//! What `nav-app monte-carlo` is asked to simulate ([`RunOptions`]), the parsers of its
//! arguments, and their checked form ([`Resolved`]).

use std::path::{Path, PathBuf};

use ins_sim::stats::ShardInfo;
use ins_sim::{Mode, Scenario};

use crate::McError;

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
