//! The Monte Carlo's one error type.

use std::path::PathBuf;

use ins_sim::SimError;

/// Everything that can stop a Monte Carlo, a merge, a sweep or the scenario table. Each variant
/// names what failed: the file, the option and its value, the run, or the figure. (A run that
/// fails on its own — a non-finite state, a landmark behind the camera — does not stop the
/// Monte Carlo: it is excluded and counted, see [`super::stats::Exclusion`].)
#[derive(Debug, thiserror::Error)]
pub enum McError {
    /// A file or directory could not be read, created or written.
    #[error("{}", path.display())]
    Io {
        /// The file or directory.
        path: PathBuf,
        /// The operating-system error.
        #[source]
        source: std::io::Error,
    },
    /// The simulation library refused: the scenario file is invalid (the error names the file,
    /// line and column, and the field), statistics cannot be merged (other scenario, seed or
    /// run count, or overlapping), a `stats.json` breaks an invariant, or a shard is not a slice
    /// of the runs. See [`SimError`].
    #[error(transparent)]
    Sim(#[from] SimError),
    /// An option holds a value outside its range.
    #[error("{flag} {value}: {reason}")]
    Argument {
        /// The option, e.g. `--shard`.
        flag: &'static str,
        /// The value given.
        value: String,
        /// What is wrong with it.
        reason: String,
    },
    /// A `stats.json` given to `merge` is not a Monte Carlo statistics file.
    #[error("{}: not a Monte Carlo stats file", path.display())]
    StatsFile {
        /// The file.
        path: PathBuf,
        /// The JSON error (line and column).
        #[source]
        source: serde_json::Error,
    },
    /// A merge lacks some run indices and `--allow-partial` was not given.
    #[error(
        "merge: {present} of {total} runs present; missing run indices {missing} (pass \
         --allow-partial to write a partial summary)"
    )]
    MissingRuns {
        /// Runs the shards cover.
        present: u64,
        /// Runs the Monte Carlo was for.
        total: u64,
        /// The missing half-open ranges, `a..b, …`.
        missing: String,
    },
    /// A run could not start (the scenario is not runnable or the record buffer is wrong): not a
    /// property of one run, so the whole Monte Carlo stops.
    #[error("run {index} ({mode}) could not start")]
    RunSetup {
        /// Run index.
        index: u64,
        /// Configuration.
        mode: ins_sim::Mode,
        /// The closed loop's error.
        #[source]
        source: Box<SimError>,
    },
    /// The worker pool could not be built.
    #[error("cannot start the worker threads")]
    ThreadPool(#[from] rayon::ThreadPoolBuildError),
    /// A figure could not be drawn or encoded (the error names the figure).
    #[error(transparent)]
    Plot(#[from] ins_plot::PlotError),
    /// Serialising a report failed.
    #[error("cannot serialise a report")]
    Json(#[from] serde_json::Error),
    /// Writing the log export failed (its error names the file).
    #[error("exporting run 0 ({mode}) to {}", dir.display())]
    Export {
        /// Configuration exported.
        mode: &'static str,
        /// Directory.
        dir: PathBuf,
        /// The log writer's error.
        #[source]
        source: Box<SimError>,
    },
}
