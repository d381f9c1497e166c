//! The crate's one error type.

use std::io;

/// What can go wrong while evaluating: reading a frame source, the tracker, a fixture.
#[derive(Debug, thiserror::Error)]
pub enum EvalError {
    /// A file could not be read.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// The operating-system error.
        #[source]
        source: io::Error,
    },
    /// A JSON file (a ground truth, the recorded expectations) is not valid JSON or not what it
    /// should be.
    #[error("{path}: bad JSON")]
    Json {
        /// The file.
        path: String,
        /// What serde_json said.
        #[source]
        source: serde_json::Error,
    },
    /// The benchmark's data root or files (crate `lane-bench`).
    #[error(transparent)]
    Bench(#[from] lane_bench::BenchError),
    /// A frame source or a frame file failed (crate `lane-io`).
    #[error(transparent)]
    Source(#[from] lane_io::LaneIoError),
    /// The tracker refused its configuration or a frame (crate `lane-tracker`).
    #[error(transparent)]
    Tracker(#[from] lane_tracker::TrackerError),
}
