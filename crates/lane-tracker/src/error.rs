//! The crate's one error type.

/// Everything that can go wrong in the tracker: a configuration out of range, a frame of the
/// wrong size, or a component crate refusing its input. Each variant keeps the component's own
/// typed error as its source.
#[derive(Debug, thiserror::Error)]
pub enum TrackerError {
    /// A configuration text is not valid TOML, does not match the schema (unknown, missing or
    /// mistyped key), or holds a field out of range: the error names the file, the line and the
    /// column of the offending key or value (see the `toml-config` crate).
    #[error("{0}")]
    ConfigFile(toml_config::TomlError),
    /// A configuration field holds a value outside its valid range (a configuration built in
    /// code; from a text it is a [`TrackerError::ConfigFile`] naming the file and line).
    #[error("configuration field `{field}` = {value}: {reason}")]
    ConfigField {
        /// Dotted field name, e.g. `track.window_half_width_px`.
        field: &'static str,
        /// The value found.
        value: String,
        /// The valid range.
        reason: String,
    },
    /// The tracker was asked for frames smaller than 3×3.
    #[error("tracker: frame size {width}×{height} is too small (at least 3×3)")]
    ZeroSize {
        /// Width asked for, px.
        width: usize,
        /// Height asked for, px.
        height: usize,
    },
    /// The frame given to the tracker does not match the size it was built for.
    #[error("tracker built for {expected_w}×{expected_h} frames, got {got_w}×{got_h}")]
    FrameSize {
        /// Expected width, px.
        expected_w: usize,
        /// Expected height, px.
        expected_h: usize,
        /// Width received, px.
        got_w: usize,
        /// Height received, px.
        got_h: usize,
    },
    /// The gradient stage (crate `vision-gradient`) refused its input or parameters.
    #[error("gradient: {0}")]
    Gradient(#[from] vision_gradient::GradientError),
    /// The Hough + least-squares initialisation (crate `hough-init`) refused its parameters.
    #[error("hough: {0}")]
    Hough(#[from] hough_init::HoughError),
    /// The information filter (crate `info-filter`) refused its set-up or an update.
    #[error("kif: {0}")]
    Kif(#[from] info_filter::KifError),
    /// The WRLS estimator (crate `wrls`) refused its set-up or an update.
    #[error("wrls: {0}")]
    Wrls(#[from] wrls::WrlsError),
    /// The lane geometry (crate `lane-geometry`) refused a camera model.
    #[error("camera: {0}")]
    Geometry(#[from] lane_geometry::GeometryError),
}

/// Why a lane's filter refused an update or an initialisation: the component's typed error,
/// kept without allocating (what [`crate::LaneTracker::last_filter_error`] reports).
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum FilterFailure {
    /// The Kalman information filter.
    #[error("kif: {0}")]
    Kif(info_filter::KifError),
    /// The WRLS estimator.
    #[error("wrls: {0}")]
    Wrls(wrls::WrlsError),
}
