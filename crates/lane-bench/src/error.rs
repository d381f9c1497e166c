//! The crate's one error type.

use std::io;

/// What can go wrong in the benchmark: reading a labelled set or its frames, the tracker, the
/// files it writes, the floors. A variant shows its cause either in its own message or by
/// returning it as its source, never both: print the chain (`source()`) to see everything once.
#[derive(Debug, thiserror::Error)]
pub enum BenchError {
    /// A file or directory could not be read, written or created.
    #[error("cannot {action} {path}")]
    Io {
        /// What was done: `read`, `write`, `create`.
        action: &'static str,
        /// The file or directory.
        path: String,
        /// The operating-system error.
        #[source]
        source: io::Error,
    },
    /// An image could not be read or written.
    #[error("cannot {action} the image {path}")]
    Image {
        /// What was done: `read`, `write`.
        action: &'static str,
        /// The image file.
        path: String,
        /// What the codec said.
        #[source]
        source: image::ImageError,
    },
    /// A labelled set (`labels.json`, see [`crate::labelled`]) is malformed or does not match its
    /// frames.
    #[error("{path}: bad lane labels: {reason}")]
    Labels {
        /// The label file or frame concerned.
        path: String,
        /// What is wrong.
        reason: String,
    },
    /// A `labels.json` is not valid JSON or does not match the schema; serde_json locates it.
    #[error("{path}:{line}:{column}: bad lane labels: {reason}")]
    LabelsJson {
        /// The label file.
        path: String,
        /// Line of the error, 1-based.
        line: usize,
        /// Column of the error, 1-based.
        column: usize,
        /// What serde_json said, without its own location.
        reason: String,
    },
    /// Another JSON file (floors, a peer's predictions) is not valid JSON or not what it should be.
    #[error("{path}: bad JSON")]
    Json {
        /// The file.
        path: String,
        /// What serde_json said.
        #[source]
        source: serde_json::Error,
    },
    /// Third-party evaluation data is not where it was looked for (see [`crate::data`]).
    #[error(
        "{path}: missing evaluation data `{what}` (third-party, not in the repository: put the \
         shared data root beside the checkout as ../shared/data, or name it with ITA_NAV_DATA)"
    )]
    MissingData {
        /// Where it was looked for.
        path: String,
        /// What it is, relative to the data root.
        what: String,
    },
    /// The directory of labelled sets is missing or holds none.
    #[error("{dir}: {reason}")]
    NoSets {
        /// The directory.
        dir: String,
        /// What is missing.
        reason: String,
    },
    /// A run on one set (or one configuration) failed; the source says why.
    #[error("{what}")]
    Run {
        /// The set and configuration.
        what: String,
        /// Why.
        #[source]
        source: Box<BenchError>,
    },
    /// The figures fell below the recorded floors (each line one set and figure).
    #[error("below the floors:\n  {}", .0.join("\n  "))]
    BelowFloors(Vec<String>),
    /// A request that cannot be done as given (options that do not go together, an import with
    /// nothing to import, an output that would overwrite another set).
    #[error("{0}")]
    Refused(String),
    /// An import found no frame it could import; every record was skipped (listed here).
    #[error("no frame could be imported ({} records skipped)", .0.len())]
    NothingImported(Vec<crate::labelled::import::Skipped>),
    /// A frame source or a frame file failed (crate `lane-io`).
    #[error(transparent)]
    Source(#[from] lane_io::LaneIoError),
    /// The tracker refused its configuration or a frame (crate `lane-tracker`).
    #[error(transparent)]
    Tracker(#[from] lane_tracker::TrackerError),
    /// The census's edge detector refused its parameters or a frame (crate `vision-gradient`).
    #[error(transparent)]
    Gradient(#[from] vision_gradient::GradientError),
}

impl BenchError {
    /// [`BenchError::Io`] for `path`.
    pub(crate) fn io(action: &'static str, path: &std::path::Path, source: io::Error) -> Self {
        BenchError::Io {
            action,
            path: path.display().to_string(),
            source,
        }
    }

    /// This error as the cause of a failed run on `what`.
    pub(crate) fn during(self, what: impl Into<String>) -> Self {
        BenchError::Run {
            what: what.into(),
            source: Box::new(self),
        }
    }
}

/// The JSON error `e` of `path` as [`BenchError::LabelsJson`] (located once, in the prefix).
pub(crate) fn labels_json(path: &str, e: &serde_json::Error) -> BenchError {
    let msg = e.to_string();
    let reason = match msg.rfind(" at line ") {
        Some(i) => msg[..i].to_owned(),
        None => msg,
    };
    BenchError::LabelsJson {
        path: path.to_owned(),
        line: e.line(),
        column: e.column(),
        reason,
    }
}

/// `e` and its causes, one after another (`: ` between them): the text a skipped frame is
/// reported with (the frame loop's error names the frame; its causes the file and what failed).
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
