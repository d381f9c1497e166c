//! The crate's one error type, [`TrackerError`]. [`FilterFailure`] is the record of a lane's
//! filter refusing an update, kept per lane without allocating; as an error it is a
//! [`TrackerError::Kif`] or [`TrackerError::Wrls`].

/// Everything that can go wrong in the tracker: a configuration out of range, a frame of the
/// wrong size, or a component crate refusing its input. Each variant keeps the component's own
/// typed error: as its source, or as itself when the variant is only that error (shown as it is,
/// `transparent`).
#[derive(Debug, thiserror::Error)]
pub enum TrackerError {
    /// A configuration text is not valid TOML, does not match the schema (unknown, missing or
    /// mistyped key), or holds a field out of range: the error names the file, the line and the
    /// column of the offending key or value (see the `toml-config` crate).
    #[error(transparent)]
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
    /// A configuration field's value was refused by the gradient stage (crate
    /// `vision-gradient`), whose own error is the source.
    #[error("configuration field `{field}`")]
    ConfigGradient {
        /// Dotted field name, e.g. `gradient.min_edge_angle_deg`.
        field: &'static str,
        /// The component's error.
        #[source]
        source: vision_gradient::GradientError,
    },
    /// A configuration field's value was refused by the initialisation (crate `hough-init`),
    /// whose own error is the source.
    #[error("configuration field `{field}`")]
    ConfigHough {
        /// Dotted field name, e.g. `init.ego_pair.min_width_frac`.
        field: &'static str,
        /// The component's error.
        #[source]
        source: hough_init::HoughError,
    },
    /// A camera file's field was refused by the lane geometry (crate `lane-geometry`), whose
    /// own error is the source.
    #[error("camera field `{field}`")]
    ConfigGeometry {
        /// Dotted field name, e.g. `mounting.height_m`.
        field: &'static str,
        /// The component's error.
        #[source]
        source: lane_geometry::GeometryError,
    },
    /// A camera model was given frames of another size than its file's `image_size_px`.
    #[error(
        "camera file is for {expected_w}×{expected_h} frames (image_size_px), the input has \
         {got_w}×{got_h}"
    )]
    CameraFrameSize {
        /// `image_size_px[0]`, px.
        expected_w: usize,
        /// `image_size_px[1]`, px.
        expected_h: usize,
        /// Width received, px.
        got_w: usize,
        /// Height received, px.
        got_h: usize,
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
    #[error(transparent)]
    Gradient(#[from] vision_gradient::GradientError),
    /// The Hough + least-squares initialisation (crate `hough-init`) refused its parameters.
    #[error(transparent)]
    Hough(#[from] hough_init::HoughError),
    /// The information filter (crate `info-filter`) refused its set-up or an update.
    #[error(transparent)]
    Kif(#[from] info_filter::KifError),
    /// The WRLS estimator (crate `wrls`) refused its set-up or an update.
    #[error(transparent)]
    Wrls(#[from] wrls::WrlsError),
    /// The lane geometry (crate `lane-geometry`) refused a camera model.
    #[error(transparent)]
    Geometry(#[from] lane_geometry::GeometryError),
}

impl TrackerError {
    /// The dotted configuration field the error is about: a [`TrackerError::ConfigField`], or a
    /// component's refusal of a field's value ([`TrackerError::ConfigGradient`],
    /// [`TrackerError::ConfigHough`], [`TrackerError::ConfigGeometry`]); `None` otherwise (a
    /// [`TrackerError::ConfigFile`] names its field in its message, at its line).
    #[must_use]
    pub fn config_field(&self) -> Option<&'static str> {
        match self {
            Self::ConfigField { field, .. }
            | Self::ConfigGradient { field, .. }
            | Self::ConfigHough { field, .. }
            | Self::ConfigGeometry { field, .. } => Some(field),
            _ => None,
        }
    }
}

/// Why a lane's filter refused an update or an initialisation: the component's typed error,
/// kept without allocating (what [`crate::LaneTracker::last_filter_error`] reports).
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum FilterFailure {
    /// The Kalman information filter.
    #[error(transparent)]
    Kif(info_filter::KifError),
    /// The WRLS estimator.
    #[error(transparent)]
    Wrls(wrls::WrlsError),
}
