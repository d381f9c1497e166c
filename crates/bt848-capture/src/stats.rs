//! The capture counters.

/// Running counters of a capture since it was opened (`Capture::open`, feature `v4l`).
/// Declared without the feature so that callers can hold and report them in any build.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
pub struct CaptureStats {
    /// Frames delivered to the caller.
    pub frames: u64,
    /// Buffers dropped because the driver flagged them `V4L2_BUF_FLAG_ERROR` or they were short.
    pub errored_dropped: u64,
    /// Frames missing from the sequence numbering (the driver dropped them).
    pub sequence_gaps: u64,
    /// Timeouts (no frame within `timeout_ms`).
    pub timeouts: u64,
    /// Stream restarts (after timeouts).
    pub restarts: u64,
    /// Delivered frames taken while the input reported signal loss.
    pub signal_lost_frames: u64,
}
