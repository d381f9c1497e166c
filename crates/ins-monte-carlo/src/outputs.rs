//! The outputs of a Monte Carlo: its statistics ([`simulate_stats`], [`build_stats`],
//! [`merge_dirs`]) and the files made of them ([`render`], [`write_outputs`]).

use std::path::{Path, PathBuf};

use ins_sim::stats::{self, FORMAT, Stats, StatsFile};

use crate::options::Resolved;
use crate::{McError, Progress, driver, plot, report, summary};

/// Simulates the resolved plan with the real closed loop and returns its statistics.
pub fn simulate_stats(r: &Resolved, progress: &dyn Progress) -> Result<Stats, McError> {
    let samples = r.scenario.samples_per_run();
    let range = stats::shard_range(r.runs, r.shard.index, r.shard.count)?;
    let plan = driver::Plan {
        modes: r.modes.clone(),
        samples,
        range,
        threads: r.threads,
    };
    let sim = driver::simulate(
        &plan,
        ins_sim::runs::closed_loop(&r.scenario, r.seed),
        progress,
    )?;
    build_stats(r, range, sim)
}

/// Wraps a driver result into [`Stats`] (sorted and checked: [`StatsFile`] → [`Stats`]).
pub fn build_stats(
    r: &Resolved,
    range: (u64, u64),
    sim: driver::Simulated,
) -> Result<Stats, McError> {
    Ok(Stats::try_from(StatsFile {
        format: FORMAT.to_string(),
        scenario_fingerprint: stats::scenario_fingerprint(&r.scenario),
        scenario_source: r.source.clone(),
        assumptions: r.scenario.assumptions(),
        sd_noise_sigma_m: Some(r.scenario.sighting.noise_var_m2.sqrt()),
        duration_s: r.scenario.duration_s(),
        seed: r.seed,
        runs_total: r.runs,
        run_ranges: vec![range],
        shards: vec![r.shard],
        modes: sim.modes,
        exclusions: sim.exclusions,
        runs: sim.runs,
        wall_s: sim.wall_s,
        core_s: sim.wall_s * r.threads as f64,
    })?)
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
            total: merged.runs_total(),
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
        for m in stats.modes() {
            files.push((
                format!("timeseries_{}.csv", m.mode),
                report::timeseries_csv(m).into_bytes(),
            ));
        }
        files.extend(plot::figures(stats)?);
        // One computation: summary.md is rendered from the structure summary.json serialises.
        let summary = summary::summary(stats);
        files.push((
            "summary.json".to_string(),
            summary::summary_json(&summary)?.into_bytes(),
        ));
        files.push((
            "summary.md".to_string(),
            summary::summary_md(stats, &summary).into_bytes(),
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
