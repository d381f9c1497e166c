//! The time spans of a replay's inputs ([`InputSpan`]) and the input rows a replay did not use
//! ([`UnusedRows`]): what the overlap checks of [`super::replay`] report.

use std::fmt;
use std::path::PathBuf;

/// One input file of a replay and its time span (first and last stamp of its rows).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct InputSpan {
    /// Which input: `IMU log`, `reference`, `sightings`.
    pub role: &'static str,
    /// The file.
    pub path: PathBuf,
    /// First and last stamp, s (`None`: no row).
    pub span_s: Option<[f64; 2]>,
    /// Rows read.
    pub rows: u64,
}

impl InputSpan {
    /// The spans as one line, `; `-separated.
    pub fn list(spans: &[InputSpan]) -> String {
        spans
            .iter()
            .map(ToString::to_string)
            .collect::<Vec<_>>()
            .join("; ")
    }
}

impl fmt::Display for InputSpan {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.span_s {
            Some([a, b]) => write!(
                f,
                "{} {}: t = {a:.3}–{b:.3} s ({} rows)",
                self.role,
                self.path.display(),
                self.rows
            ),
            None => write!(f, "{} {}: no rows", self.role, self.path.display()),
        }
    }
}

/// Input rows a replay did not use, by reason. The replay runs to the IMU log's last sample, so
/// no IMU row is after its end.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct UnusedRows {
    /// IMU samples at or before the start of the replay.
    pub imu_before_start: u64,
    /// Sightings at or before the start.
    pub sightings_before_start: u64,
    /// Sightings after the IMU log's last sample.
    pub sightings_after_end: u64,
    /// Reference rows before the start (not compared).
    pub reference_before_start: u64,
    /// Reference rows after the IMU log's last sample (not compared).
    pub reference_after_end: u64,
}

impl UnusedRows {
    /// Every unused row.
    pub fn total(&self) -> u64 {
        self.imu_before_start
            + self.sightings_before_start
            + self.sightings_after_end
            + self.reference_before_start
            + self.reference_after_end
    }
}
