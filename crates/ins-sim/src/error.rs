//! The crate's one error type, [`SimError`].

use std::path::PathBuf;

use ins_errors::InsError;
use sighting_model::SightingError;

/// Everything that can fail in `ins-sim`: the scenario file ([`SimError::ScenarioFile`],
/// [`SimError::ScenarioInvalid`], [`SimError::ScenarioParse`]), one run ([`SimError::NonFinite`],
/// [`SimError::OutputLength`], [`SimError::Ins`], [`SimError::Sighting`], [`SimError::Filter`],
/// [`SimError::Online`]), the logs ([`SimError::LogIo`], [`SimError::LogParse`],
/// [`SimError::LogToml`], [`SimError::LogFilter`], [`SimError::LogWrite`],
/// [`SimError::ExportRun`]) and the statistics ([`SimError::StatsEmpty`] …
/// [`SimError::StatsShard`]). Each variant says where: the file, line and column, the dotted
/// field, the time of the run, or the statistics field; wrapped errors stay typed
/// (`#[source]`).
#[derive(Debug, thiserror::Error)]
pub enum SimError {
    // ---- scenario (`Scenario::from_toml_str`, `Scenario::validate`, `Scenario::truncated`) ----
    /// The text is not TOML, a section is missing or unknown, or a key is unknown or mistyped,
    /// without a location. The loader ([`crate::Scenario::from_toml_named`]) returns
    /// [`SimError::ScenarioFile`] instead; this variant remains for callers that parse
    /// sections of their own.
    #[error("scenario TOML, section [{section}]: {message}")]
    ScenarioParse {
        /// Section concerned (`"(document)"` for top-level problems).
        section: String,
        /// Parser message (names the offending key).
        message: String,
    },
    /// An error in a scenario text, located by the one TOML loader (crate `toml-config`):
    /// `error` names the file (or the name given to [`crate::Scenario::from_toml_named`]), the
    /// line and the column of the offending key or value, and says what is wrong. Every error
    /// of [`crate::Scenario::from_toml_str`] / [`crate::Scenario::from_toml_named`] is one of
    /// these. It displays as `error` itself (file, line and column first), which is therefore
    /// not also its source: shown once, as with `#[error(transparent)]`.
    #[error("{error}")]
    ScenarioFile {
        /// What [`SimError::ScenarioParse`] or [`SimError::ScenarioInvalid`] would name: the
        /// section (`"(document)"` for a syntax error) or the dotted field.
        field: String,
        /// The located error (a leaf: it has no source of its own).
        error: toml_config::TomlError,
    },
    /// A scenario field holds an invalid value (a scenario built or changed in code; from a
    /// text it is a [`SimError::ScenarioFile`] naming the file and line).
    #[error("{field}: {requirement} (got {value})")]
    ScenarioInvalid {
        /// Dotted path, e.g. `filter.open_loop_until_s`.
        field: String,
        /// What the field must satisfy.
        requirement: String,
        /// The value found (formatted).
        value: String,
    },

    // ---- one run (`run`, `runs::run_range`) ----
    /// The INS or the filter state became NaN/∞.
    #[error("run became non-finite at t = {t_s} s: {what}")]
    NonFinite {
        /// Time of detection, s.
        t_s: f64,
        /// Which quantity.
        what: &'static str,
    },
    /// `out` has the wrong length.
    #[error("output buffer holds {got} samples, the run needs {expected} (duration + 1)")]
    OutputLength {
        /// Required length.
        expected: usize,
        /// Length passed.
        got: usize,
    },
    /// `ins-errors` rejected an input (trajectory, IMU parameters, initial state).
    #[error("ins-errors")]
    Ins(#[source] InsError),
    /// The SD model failed (e.g. a landmark behind the camera because the errors exploded).
    #[error("sighting model at t = {t_s} s")]
    Sighting {
        /// Time, s.
        t_s: f64,
        /// The model's error.
        #[source]
        source: SightingError,
    },
    /// The filter rejected a matrix (non-finite, S not positive definite, …).
    #[error("filter at t = {t_s} s")]
    Filter {
        /// Time, s.
        t_s: f64,
        /// The filter's error.
        #[source]
        source: akf::AkfError,
    },
    /// The online filter rejected its input (time stamps, landmark ids; not expected from the
    /// simulator).
    #[error("online filter at t = {t_s} s")]
    Online {
        /// Time, s (NaN when unknown).
        t_s: f64,
        /// The filter's error.
        #[source]
        source: ins_sd_filter::FilterError,
    },

    // ---- logs (`logs`: read, write/export, replay) ----
    /// A log file could not be opened, read or written.
    #[error("{}", path.display())]
    LogIo {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        #[source]
        source: std::io::Error,
    },
    /// A malformed, missing or out-of-range field of a CSV log.
    #[error("{}:{line}:{column}: {message}", path.display())]
    LogParse {
        /// The file.
        path: PathBuf,
        /// Line, 1-based.
        line: usize,
        /// Column of the field's first character, 1-based.
        column: usize,
        /// What is wrong.
        message: String,
    },
    /// A TOML log file (landmark table, initial state) or a filter file is malformed or holds a
    /// bad value: `error` names the file, the line and the column (crate `toml-config`). It
    /// displays as `error` itself (file, line and column first), which is therefore not also
    /// its source: shown once, as with `#[error(transparent)]`.
    #[error("{error}")]
    LogToml {
        /// The file.
        path: PathBuf,
        /// The located error (a leaf: it has no source of its own).
        error: toml_config::TomlError,
    },
    /// A ROS 2 bag could not be read (file, container, topic, message).
    #[error(transparent)]
    Bag {
        /// The bag reader's error.
        #[from]
        source: ros_bag::BagError,
    },
    /// A replay's message (`--mcap-out`, `--foxglove`) could not be encoded as JSON.
    #[error("topic {topic}: cannot encode the message as JSON")]
    Encode {
        /// The channel's topic.
        topic: &'static str,
        /// The encoder's error.
        #[source]
        source: serde_json::Error,
    },
    /// A replay needs the reference trajectory at a time it does not cover.
    #[error("reference trajectory at t = {t_s} s: {what}")]
    ReferenceSpan {
        /// The time asked for, s.
        t_s: f64,
        /// What was needed.
        what: &'static str,
    },
    /// A static alignment (`--align-s`) over a window where the vehicle is not at rest
    /// ([`crate::logs::align_at_rest`]): the measured quantity and the filter file's limit.
    #[error(
        "{}: the vehicle is not at rest over the alignment window t = {t0_s:.3}–{t1_s:.3} s: {quantity} {measured:.4} {unit}, above the filter file's align.{field} = {limit} {unit}; align on a period at rest, or start moving without --align-s (the initial attitude from the reference)",
        path.display()
    )]
    NotAtRest {
        /// The IMU log.
        path: PathBuf,
        /// Start of the window, s.
        t0_s: f64,
        /// End of the window, s.
        t1_s: f64,
        /// What was measured (`the gyro's spread … is`).
        quantity: &'static str,
        /// Its value, in `unit`.
        measured: f64,
        /// The limit, in `unit`.
        limit: f64,
        /// The filter file's key in `[align]`.
        field: &'static str,
        /// The unit of `measured` and `limit`.
        unit: &'static str,
    },
    /// The inputs of a replay do not overlap in time, or a filter applied no sighting: what is
    /// wrong, and each input file with its time span ([`crate::logs::replay`]).
    #[error("{problem}; {}", crate::logs::InputSpan::list(spans))]
    InputSpans {
        /// What is wrong.
        problem: String,
        /// The inputs: the IMU log, the reference, the sightings.
        spans: Vec<crate::logs::InputSpan>,
    },
    /// The settings of a filter file make a filter configuration the filter refuses
    /// ([`crate::filter_file::FilterFile::filter_config`]).
    #[error("filter file")]
    FilterFileConfig {
        /// The filter's error.
        #[source]
        source: ins_sd_filter::FilterError,
    },
    /// The filter rejected the record of this line of a log.
    #[error("{}:{line}", path.display())]
    LogFilter {
        /// The file.
        path: PathBuf,
        /// Line, 1-based.
        line: usize,
        /// The filter's error.
        #[source]
        source: ins_sd_filter::FilterError,
    },
    /// A TOML log file (landmarks, initial state, scenario) could not be serialised.
    #[error("{}: cannot serialise", path.display())]
    LogWrite {
        /// The file.
        path: PathBuf,
        /// The serialiser's error.
        #[source]
        source: toml::ser::Error,
    },
    /// The simulation of an exported run failed ([`crate::logs::export_run`]).
    #[error("simulating the run to export")]
    ExportRun {
        /// The run's error.
        #[source]
        source: Box<SimError>,
    },

    // ---- statistics (`stats`: load, merge, shards) ----
    /// Nothing to merge.
    #[error("merge: no statistics to merge")]
    StatsEmpty,
    /// A statistics file of another format.
    #[error("merge: format `{found}` is not `{}`", crate::stats::FORMAT)]
    StatsFormat {
        /// The format found.
        found: String,
    },
    /// The shards disagree on what they simulated.
    #[error("merge: shards come from different {what} ({a} vs {b})")]
    StatsMismatch {
        /// Which property (`scenarios`, `master seeds`, `total run counts`, `modes or durations`).
        what: &'static str,
        /// One value.
        a: String,
        /// The other.
        b: String,
    },
    /// Two shards cover the same runs: run ranges `.0..​.1` and `.2..​.3`.
    #[error("merge: run ranges {0}..{1} and {2}..{3} overlap (the same shard given twice?)")]
    StatsOverlap(u64, u64, u64, u64),
    /// A statistics file breaks an invariant of [`crate::stats::Stats`] (its field named).
    #[error("stats: {field}: {reason}")]
    StatsInvalid {
        /// The field, e.g. `modes` or `run_ranges`.
        field: &'static str,
        /// What is wrong with it.
        reason: String,
    },
    /// A shard is not a slice of the runs: `count` is 0 or `index` is not in `1..=count`.
    #[error(
        "shard {index}/{count}: the shard number must be within 1..={count} and the count at least 1"
    )]
    StatsShard {
        /// Shard number given (1-based).
        index: u64,
        /// Number of shards given.
        count: u64,
    },
}

impl SimError {
    pub(crate) fn invalid(field: &str, requirement: &str, value: impl std::fmt::Debug) -> Self {
        Self::ScenarioInvalid {
            field: field.to_string(),
            requirement: requirement.to_string(),
            value: format!("{value:?}"),
        }
    }

    /// The scenario field or section an error of the scenario names (`"filter.r_var_m2"`,
    /// `"(document)"`), `None` for other errors.
    pub fn scenario_field(&self) -> Option<&str> {
        match self {
            SimError::ScenarioParse { section, .. } => Some(section),
            SimError::ScenarioFile { field, .. } | SimError::ScenarioInvalid { field, .. } => {
                Some(field)
            }
            _ => None,
        }
    }

    /// `true` for the errors that are not a property of one run but of its setup (an invalid
    /// scenario, a wrong record buffer): [`crate::runs::run_range`] stops on them instead of
    /// excluding the run.
    pub fn is_setup(&self) -> bool {
        matches!(
            self,
            SimError::ScenarioParse { .. }
                | SimError::ScenarioFile { .. }
                | SimError::ScenarioInvalid { .. }
                | SimError::OutputLength { .. }
        )
    }

    /// The time of the run at which a run error happened, s (`None` for errors without one).
    pub fn run_time_s(&self) -> Option<f64> {
        match self {
            SimError::NonFinite { t_s, .. }
            | SimError::Sighting { t_s, .. }
            | SimError::Filter { t_s, .. }
            | SimError::Online { t_s, .. } => Some(*t_s),
            _ => None,
        }
    }
}

/// `e` and its causes as one line of text, `e: cause: cause's cause…`, for a reason kept as text
/// (an excluded run's, a located TOML message). Each error of the workspace displays only its own
/// message and keeps its cause as its source, so each cause appears once.
pub(crate) fn with_causes(e: &(dyn std::error::Error + 'static)) -> String {
    let mut text = e.to_string();
    let mut next = e.source();
    while let Some(cause) = next {
        text.push_str(": ");
        text.push_str(&cause.to_string());
        next = cause.source();
    }
    text
}
