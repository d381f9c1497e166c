//! Configuration and camera files: a preset name or a TOML file path, read here and parsed and
//! validated by `lane-tracker` (errors name the file, the line and the column).

use std::path::Path;

use lane_tracker::TrackerConfig;
use lane_tracker::camera::CameraConfig;

use crate::LaneIoError;

/// The text of a configuration file; the error names the file and its OS error once.
fn read_config_file(path: &str) -> Result<String, LaneIoError> {
    std::fs::read_to_string(Path::new(path)).map_err(|e| LaneIoError::io(path.to_owned(), e))
}

/// `default` / `indoor` / `outdoor` name a tracker preset ([`TrackerConfig::preset`]); anything
/// else is a TOML file path.
///
/// # Errors
/// [`LaneIoError::Io`] for an unreadable file; [`LaneIoError::Tracker`] holding
/// `TrackerError::ConfigFile` (file, line, column) for a bad text.
pub fn load_tracker_config(name_or_path: &str) -> Result<TrackerConfig, LaneIoError> {
    match TrackerConfig::preset(name_or_path) {
        Some(preset) => Ok(preset?),
        None => Ok(TrackerConfig::from_toml_str(
            name_or_path,
            &read_config_file(name_or_path)?,
        )?),
    }
}

/// `robot` / `highway` name a camera preset ([`CameraConfig::preset`]); anything else is a TOML
/// file path.
///
/// # Errors
/// As [`load_tracker_config`].
pub fn load_camera_config(name_or_path: &str) -> Result<CameraConfig, LaneIoError> {
    match CameraConfig::preset(name_or_path) {
        Some(preset) => Ok(preset?),
        None => Ok(CameraConfig::from_toml_str(
            name_or_path,
            &read_config_file(name_or_path)?,
        )?),
    }
}
