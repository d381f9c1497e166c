//! A replay as a user asks for it (files, a filter file or preset, a start time, an alignment)
//! turned into [`ReplayInputs`]: what `nav-app ins` and the Python package both run.

use std::path::PathBuf;

use nalgebra::Matrix3;
use toml_config::TomlDoc;

use super::align::AlignLimits;
use super::asl::{asl_body_from_imu, asl_imu_file};
use super::imu::ImuLog;
use super::local::LocalFrame;
use super::read::read_initial;
use super::reference::{initial_from_reference, read_reference_in};
use super::replay::{ReplayInputs, SolutionRate};
use crate::filter_file::FilterFile;
use crate::{Mode, Scenario, SimError};

/// Where the filter settings come from.
#[derive(Clone, Debug)]
pub enum FilterSettings {
    /// A filter file (datasheet units) or preset: time stamps as logged, the IMU step
    /// estimated from the log, feedback counted from the start.
    File(FilterFile),
    /// A simulation scenario's `[filter]` (the older way; the scenario's IMU step and time-stamp
    /// tolerance are kept, so an exported run replays to round-off).
    Scenario(Box<Scenario>),
}

impl FilterSettings {
    /// The settings in a file: a simulation scenario (the older way) when the document has a
    /// top-level `trajectory` table (every scenario has one, no filter file may), else a filter
    /// file. The TOML is parsed once; `path` names the file in errors.
    ///
    /// # Errors
    /// [`SimError::LogToml`] for a TOML syntax error or a bad filter file,
    /// [`SimError::ScenarioFile`] for a bad scenario, each with its line and column.
    pub fn from_toml_named(path: &str, text: &str) -> Result<Self, SimError> {
        let doc = TomlDoc::parse(path, text).map_err(|error| SimError::LogToml {
            path: path.into(),
            error,
        })?;
        if doc.keys().any(|k| k == "trajectory") {
            Ok(Self::Scenario(Box::new(Scenario::from_doc(&doc)?)))
        } else {
            Ok(Self::File(FilterFile::from_doc(&doc, path)?))
        }
    }
}

/// Inputs in the data sets' own layouts (`nav-app ins --imu-to-body`, `--tum-origin`,
/// `--tum-frame`; [`super::asl`], [`super::local`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct InputLayouts {
    /// For an EuRoC/ASL folder's IMU: the rotation IMU axes → body axes, C_B^S (default: the
    /// folder's `sensor.yaml`); refused for other IMU logs.
    pub imu_to_body: Option<Matrix3<f64>>,
    /// The local frame of a TUM or ASL reference (required by them, refused for a CSV one).
    pub local_frame: Option<LocalFrame>,
}

/// A replay request ([`ReplayRequest::inputs`]).
#[derive(Clone, Debug)]
pub struct ReplayRequest {
    /// IMU log (CSV, or a ROS 2 bag).
    pub imu: PathBuf,
    /// With a bag: its IMU topic (default: the only one).
    pub imu_topic: Option<String>,
    /// Sightings log and landmark table (ignored for `Mode::Standalone`).
    pub sightings: Option<(PathBuf, PathBuf)>,
    /// Initial state file; without it, the reference at `start_s`.
    pub initial: Option<PathBuf>,
    /// Reference trajectory (metrics, and the initial state without `initial`).
    pub reference: Option<PathBuf>,
    /// Start of the replay when the initial state comes from the reference, s (default: its
    /// first row).
    pub start_s: Option<f64>,
    /// Filter settings.
    pub settings: FilterSettings,
    /// `Mode::Standalone` = unaided (a Kalman filter never updated, for its σ, with a filter
    /// file; no estimator with a scenario).
    pub mode: Mode,
    /// Overrides the gate probability (`Some(None)`: no gate).
    pub gate: Option<Option<f64>>,
    /// Static alignment at rest after the start, s (0: none); its rest check takes its limits
    /// from the filter file (the defaults with a scenario).
    pub align_s: f64,
    /// A filter run that used no sighting is refused unless this is set.
    pub allow_unaided: bool,
    /// Longest IMU gap bridged, s.
    pub max_gap_s: f64,
    /// When solution rows are written.
    pub rate: SolutionRate,
    /// Also write the results to this MCAP file.
    pub mcap_out: Option<PathBuf>,
    /// How inputs in the data sets' own layouts are read.
    pub layouts: InputLayouts,
}

impl ReplayRequest {
    /// Reads the reference and the initial state, estimates the IMU step, and builds the
    /// filter configuration.
    ///
    /// # Errors
    /// The readers' errors (file, line, column), [`SimError::ReferenceSpan`] for a start
    /// outside the reference, [`SimError::ScenarioInvalid`] for a request without an initial
    /// state or sightings for a filter, [`SimError::FilterFileConfig`].
    pub fn inputs(&self) -> Result<ReplayInputs, SimError> {
        if !(self.align_s.is_finite() && self.align_s >= 0.0) {
            return Err(SimError::invalid(
                "align_s",
                "must be a time >= 0 s",
                self.align_s,
            ));
        }
        if !(self.max_gap_s.is_finite() && self.max_gap_s > 0.0) {
            return Err(SimError::invalid(
                "max_gap_s",
                "must be a time > 0 s",
                self.max_gap_s,
            ));
        }
        if let SolutionRate::Hz(hz) = self.rate
            && !(hz.is_finite() && hz > 0.0)
        {
            return Err(SimError::invalid("rate", "must be a rate > 0 Hz", hz));
        }
        // An ASL folder's IMU rotation, resolved once: its IMU and its ground truth use it.
        let body_from_imu = match asl_imu_file(&self.imu) {
            Some(file) => Some(asl_body_from_imu(&file, self.layouts.imu_to_body)?),
            None => self.layouts.imu_to_body,
        };
        let reference = match &self.reference {
            Some(path) => Some((
                path.clone(),
                read_reference_in(
                    path,
                    self.layouts.local_frame.as_ref(),
                    body_from_imu.as_ref(),
                )?,
            )),
            None => None,
        };
        let mut level = false;
        let initial = match (&self.initial, &reference) {
            (Some(path), _) => read_initial(path)?,
            (None, Some((_, rows))) => {
                let start = self
                    .start_s
                    .unwrap_or_else(|| rows.first().map_or(0.0, |r| r.t_s));
                level = rows.iter().any(|r| r.att_b_to_n.is_none());
                initial_from_reference(rows, start, 1.0)?
            }
            (None, None) => {
                return Err(SimError::invalid(
                    "initial",
                    "an initial state file, or a reference to take it from",
                    "none",
                ));
            }
        };
        // The log is opened here once; what the nominal step reads is kept for the replay.
        let mut imu =
            ImuLog::new(self.imu.clone(), self.imu_topic.clone()).with_body_from_imu(body_from_imu);
        let mut config = match &self.settings {
            FilterSettings::File(f) => {
                f.filter_config(self.mode, imu.nominal_step_s()?, initial.t_s)?
            }
            FilterSettings::Scenario(s) => s.online_filter_config(self.mode),
        };
        let align_limits = match &self.settings {
            FilterSettings::File(f) => f.align_limits(),
            FilterSettings::Scenario(_) => AlignLimits::default(),
        };
        if let Some(gate) = self.gate {
            config.gate_probability = gate;
        }
        let sightings = match (&self.sightings, self.mode) {
            (_, Mode::Standalone) => None,
            (Some(pair), _) => Some(pair.clone()),
            (None, _) => {
                return Err(SimError::invalid(
                    "sightings",
                    "a filter needs a sightings log and a landmark table (or the unaided mode)",
                    self.mode.name(),
                ));
            }
        };
        Ok(ReplayInputs {
            imu,
            sightings,
            initial,
            config,
            max_gap_s: self.max_gap_s,
            rate: self.rate,
            reference,
            align_s: self.align_s,
            align_limits,
            allow_unaided: self.allow_unaided,
            level,
            mcap_out: self.mcap_out.clone(),
        })
    }
}
