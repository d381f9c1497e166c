//! The crate's error type.

use akf::AkfError;
use ins_errors::InsError;
use sighting_model::SightingError;

/// Every failure of the online filter. A call that returns an error leaves the filter as it
/// was before the call (inputs are checked before anything changes), except
/// [`FilterError::NonFiniteState`], which reports that the navigation solution itself has
/// overflowed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FilterError {
    /// A configuration value is out of its domain.
    #[error("filter configuration: {field} {requirement}, got {value}")]
    InvalidConfig {
        /// Field name (as in [`crate::InsSdFilterConfig`]).
        field: &'static str,
        /// What it must satisfy.
        requirement: &'static str,
        /// The value found (formatted).
        value: String,
    },
    /// The adaptive-Q estimator's configuration (`estimator`: window, forgetting factor, …) is
    /// out of its domain; the estimator's own error names the field.
    #[error("filter configuration: estimator")]
    InvalidEstimator {
        /// The estimator's error ([`AkfError::InvalidParameter`]).
        #[source]
        source: AkfError,
    },
    /// A time stamp does not advance: IMU samples must be strictly increasing, sightings
    /// non-decreasing.
    #[error("{what} at t = {t_s} s is not after the previous one at {previous_s} s")]
    OutOfOrder {
        /// `"IMU sample"` or `"sighting epoch"`.
        what: &'static str,
        /// The time stamp given, s.
        t_s: f64,
        /// The previous time stamp, s.
        previous_s: f64,
    },
    /// An IMU sample more than one update interval after the previous one (missing data).
    #[error("IMU sample at t = {t_s} s is {gap} s after the previous one ({previous_s} s): more than the update interval {max_s} s", gap = t_s - previous_s)]
    ImuGap {
        /// The time stamp given, s.
        t_s: f64,
        /// The previous time stamp, s.
        previous_s: f64,
        /// The largest gap taken, s (the update interval).
        max_s: f64,
    },
    /// An IMU sample whose mean specific force or angular rate is beyond any navigation IMU's
    /// range (a corrupt record).
    #[error(
        "IMU sample at t = {t_s} s is implausible: specific force {specific_force_mps2:e} m/s², angular rate {angular_rate_radps:e} rad/s (limits 2000 m/s², 100 rad/s)"
    )]
    ImplausibleImu {
        /// The time stamp, s.
        t_s: f64,
        /// Mean specific force over the sample, m/s².
        specific_force_mps2: f64,
        /// Mean angular rate over the sample, rad/s.
        angular_rate_radps: f64,
    },
    /// Sightings must be applied at the INS time: propagate the IMU up to the sighting epoch
    /// first.
    #[error(
        "sighting epoch t = {t_s} s is not at the INS time {ins_time_s} s (tolerance {tolerance_s} s): propagate to the sighting time first"
    )]
    NotAtInsTime {
        /// The sighting epoch, s.
        t_s: f64,
        /// The INS time, s.
        ins_time_s: f64,
        /// Accepted difference, s.
        tolerance_s: f64,
    },
    /// A sighting names a landmark that is not in the table.
    #[error("sighting at t = {t_s} s: unknown landmark id {id}")]
    UnknownLandmark {
        /// Epoch, s.
        t_s: f64,
        /// The id given.
        id: u32,
    },
    /// The landmark table lists an id twice.
    #[error("landmark table: id {id} appears twice")]
    DuplicateLandmark {
        /// The repeated id.
        id: u32,
    },
    /// NaN or ±∞ in an input.
    #[error("non-finite input at t = {t_s} s: {what}")]
    NonFiniteInput {
        /// Which input (`"time stamp"`, `"delta_v"`, `"delta_theta"`, `"sighting w/h"`).
        what: &'static str,
        /// Time stamp of the call (NaN when the time stamp itself is the problem).
        t_s: f64,
    },
    /// The navigation solution or the filter state became NaN/∞ (sensor data far outside the
    /// model, or a diverged filter).
    #[error("non-finite {what} at t = {t_s} s")]
    NonFiniteState {
        /// Which quantity.
        what: &'static str,
        /// Time, s.
        t_s: f64,
    },
    /// The INS rejected its initial state or step.
    #[error("INS")]
    Ins(#[source] InsError),
    /// The sighting model failed for a landmark (geometry: too close, vertical, NaN).
    #[error("sighting of landmark {landmark} at t = {t_s} s")]
    Sighting {
        /// Epoch, s.
        t_s: f64,
        /// Landmark id.
        landmark: u32,
        /// The model's error.
        source: SightingError,
    },
    /// The Kalman filter rejected a matrix (non-finite, S not positive definite, …).
    #[error("Kalman filter at t = {t_s} s")]
    Akf {
        /// Time, s.
        t_s: f64,
        /// The filter's error.
        source: AkfError,
    },
}
