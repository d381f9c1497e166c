//! The crate's one error type.

use std::io;

/// What can go wrong while evaluating: reading a labelled set, a frame source or the tracker.
#[derive(Debug, thiserror::Error)]
pub enum EvalError {
    /// A file could not be read.
    #[error("{path}")]
    Io {
        /// The file.
        path: String,
        /// The operating-system error.
        #[source]
        source: io::Error,
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
    /// A `labels.json` is not valid JSON or does not match the schema; serde_json's error (its
    /// source) says where, by line and column, also kept here.
    #[error("{path}: bad lane labels")]
    LabelsJson {
        /// The label file.
        path: String,
        /// Line of the error, 1-based.
        line: usize,
        /// Column of the error, 1-based.
        column: usize,
        /// What serde_json said.
        source: serde_json::Error,
    },
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
