//! The scenario: every section of `configs/paper.toml` (trajectory, IMU, sighting device, filter,
//! Monte Carlo, mismatch), loaded through the workspace's TOML loader and validated as a whole, and
//! the step counts derived from it.

use ins_errors::InsError;
use ins_errors::config::{ImuConfig, TrajectoryConfig};
use ins_errors::trajectory::Trajectory;
use sighting_model::{SightingConfig, SightingError};

use crate::config::{
    self, AkfScheme, MeasurementJacobian, MismatchConfig, MonteCarloConfig, ScenarioFilterConfig,
};
use crate::{Mode, SimError, engine};

/// A complete scenario: the sections of `configs/paper.toml`.
#[derive(Clone, Debug, PartialEq)]
pub struct Scenario {
    /// `[trajectory]` (crate `ins-errors`): flight and 100 Hz step.
    pub trajectory: TrajectoryConfig,
    /// `[imu]` (crate `ins-errors`): sensor error statistics.
    pub imu: ImuConfig,
    /// `[sighting]` (crate `sighting-model`): landmarks, SD noise, update period.
    pub sighting: SightingConfig,
    /// `[filter]`: P₀, Q tuning, R, feedback switch, discretisation, AKF.
    pub filter: ScenarioFilterConfig,
    /// `[monte_carlo]`: runs and master seed.
    pub monte_carlo: MonteCarloConfig,
    /// `[mismatch]` (optional): how the simulated world departs from the filter's model.
    pub mismatch: MismatchConfig,
}

/// Step counts derived from a validated scenario.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Plan {
    pub step_s: f64,
    pub steps: usize,
    pub steps_per_update: usize,
    pub steps_per_sample: usize,
    pub samples: usize,
}

fn is_integer_multiple(x: f64, unit: f64) -> Option<usize> {
    let n = (x / unit).round();
    if n >= 1.0 && (x - n * unit).abs() <= 1e-9 * x.abs().max(1.0) {
        Some(n as usize)
    } else {
        None
    }
}

impl Scenario {
    /// Parses and validates a scenario document: [`Scenario::from_toml_named`] with the name
    /// `scenario`.
    pub fn from_toml_str(text: &str) -> Result<Scenario, SimError> {
        Self::from_toml_named("scenario", text)
    }

    /// Parses and validates the scenario document `text`, read from the file `path`. Unknown
    /// sections and keys are rejected. Every error is a [`SimError::ScenarioFile`] naming `path`,
    /// the line and the column of the offending key or value (a field out of range is located
    /// at its key), and its section or dotted field (`"filter.r_var_m2"`).
    pub fn from_toml_named(path: &str, text: &str) -> Result<Scenario, SimError> {
        let doc =
            toml_config::TomlDoc::parse(path, text).map_err(|error| SimError::ScenarioFile {
                field: "(document)".to_string(),
                error,
            })?;
        Self::from_doc(&doc)
    }

    /// A scenario from a parsed document ([`Scenario::from_toml_named`] after the parse; errors
    /// name the document's path).
    pub(crate) fn from_doc(doc: &toml_config::TomlDoc<'_>) -> Result<Scenario, SimError> {
        let f = config::parse(doc)?;
        let s = Scenario {
            trajectory: f.trajectory,
            imu: f.imu,
            sighting: f.sighting,
            filter: f.filter,
            monte_carlo: f.monte_carlo,
            mismatch: f.mismatch,
        };
        s.validate().map_err(|e| match e {
            SimError::ScenarioInvalid { ref field, .. } => SimError::ScenarioFile {
                error: doc.error_at(field, e.to_string()),
                field: field.clone(),
            },
            other => other,
        })?;
        Ok(s)
    }

    /// The scenario as a TOML document that [`Scenario::from_toml_str`] reads back unchanged.
    ///
    /// # Errors
    /// The serializer's (not expected for a validated scenario).
    pub fn to_toml_string(&self) -> Result<String, toml::ser::Error> {
        toml::to_string(&config::ScenarioFile {
            trajectory: self.trajectory.clone(),
            imu: self.imu.clone(),
            sighting: self.sighting.clone(),
            filter: self.filter.clone(),
            monte_carlo: self.monte_carlo.clone(),
            mismatch: self.mismatch.clone(),
        })
    }

    /// The online filter's configuration for `mode` (what [`crate::run`] and `nav-app ins` use).
    pub fn online_filter_config(&self, mode: Mode) -> ins_sd_filter::InsSdFilterConfig {
        engine::online_config(self, mode)
    }

    /// The paper's scenario, equal to `configs/paper.toml` (tested).
    pub fn paper_default() -> Scenario {
        Scenario {
            trajectory: TrajectoryConfig::paper(),
            imu: ImuConfig::paper(),
            sighting: SightingConfig::paper(),
            filter: ScenarioFilterConfig::paper(),
            monte_carlo: MonteCarloConfig::paper(),
            mismatch: MismatchConfig::default(),
        }
    }

    /// Checks every section and the cross-section constraints (integer seconds of flight, SD
    /// period a multiple of the INS step, three landmarks in view from the start).
    pub fn validate(&self) -> Result<(), SimError> {
        let ins = |e: InsError| match e {
            InsError::InvalidConfig {
                field,
                requirement,
                value,
            } => SimError::ScenarioInvalid {
                field,
                requirement,
                value,
            },
            other => SimError::ScenarioInvalid {
                field: "trajectory".to_string(),
                requirement: other.to_string(),
                value: String::new(),
            },
        };
        self.trajectory.validate().map_err(ins)?;
        self.imu.validate().map_err(ins)?;
        self.sighting.validate().map_err(sighting_err)?;
        self.sighting.landmarks3().map_err(sighting_err)?;
        self.filter.validate()?;
        self.validate_online_filter()?;
        self.monte_carlo.validate()?;
        self.mismatch.validate()?;
        let tr = Trajectory::new(&self.trajectory).map_err(ins)?;
        self.sighting
            .check_vehicle(&tr.start())
            .map_err(sighting_err)?;
        self.plan()?;
        Ok(())
    }

    /// The `[filter]` limits, checked once, by the online filter on the configuration each
    /// filtering mode converts to (Mohamed–Schwarz, Sage–Husa and the structured projection
    /// cover every estimator field); the error names the scenario key and its value as written.
    fn validate_online_filter(&self) -> Result<(), SimError> {
        let named = |field: &str, requirement: String, value: String| {
            let (key, written) = match self.filter.toml_key(field) {
                Some(k) => k,
                // `imu_step_s`, `timestamp_tolerance_s`, `update_period_s`: from other sections.
                None if field == "update_period_s" => (
                    "sighting.update_period_s",
                    format!("{:?}", self.sighting.update_period_s),
                ),
                None => ("trajectory.step_s", value),
            };
            SimError::ScenarioInvalid {
                field: key.to_string(),
                requirement,
                value: written,
            }
        };
        for mode in [Mode::Kf, Mode::Akf, Mode::AkfSageHusa, Mode::AkfStructured] {
            let config = engine::online_config(self, mode);
            match config.validate() {
                Ok(()) => {}
                Err(ins_sd_filter::FilterError::InvalidConfig {
                    field,
                    requirement,
                    value,
                }) => return Err(named(field, requirement.to_string(), value)),
                Err(ins_sd_filter::FilterError::InvalidEstimator {
                    source: akf::AkfError::InvalidParameter { field, reason },
                }) => return Err(named(&format!("estimator.{field}"), reason, String::new())),
                Err(other) => {
                    return Err(SimError::ScenarioInvalid {
                        field: "filter".to_string(),
                        requirement: other.to_string(),
                        value: String::new(),
                    });
                }
            }
        }
        Ok(())
    }

    pub(crate) fn plan(&self) -> Result<Plan, SimError> {
        let step_s = self.trajectory.step_s;
        let steps = is_integer_multiple(self.trajectory.end_time_s, step_s).ok_or_else(|| {
            SimError::invalid(
                "trajectory.end_time_s",
                "must be a positive multiple of trajectory.step_s",
                self.trajectory.end_time_s,
            )
        })?;
        let end = self.trajectory.end_time_s;
        if (end - end.round()).abs() > 1e-9 || end < 1.0 {
            return Err(SimError::invalid(
                "trajectory.end_time_s",
                "must be a whole number of seconds >= 1 (1 Hz records)",
                end,
            ));
        }
        let steps_per_sample = is_integer_multiple(1.0, step_s).ok_or_else(|| {
            SimError::invalid(
                "trajectory.step_s",
                "must divide 1 s (1 Hz records)",
                step_s,
            )
        })?;
        let steps_per_update = is_integer_multiple(self.sighting.update_period_s, step_s)
            .ok_or_else(|| {
                SimError::invalid(
                    "sighting.update_period_s",
                    "must be a positive multiple of trajectory.step_s",
                    self.sighting.update_period_s,
                )
            })?;
        let lat = self.mismatch.latency_s / step_s;
        if (lat - lat.round()).abs() > 1e-6 || lat.round() as usize >= steps_per_update {
            return Err(SimError::invalid(
                "mismatch.latency_s",
                "must be a multiple of trajectory.step_s below sighting.update_period_s",
                self.mismatch.latency_s,
            ));
        }
        if self.filter.phi_subintervals > steps_per_update {
            return Err(SimError::invalid(
                "filter.phi_subintervals",
                "must not exceed the INS steps per SD interval",
                self.filter.phi_subintervals,
            ));
        }
        Ok(Plan {
            step_s,
            steps,
            steps_per_update,
            steps_per_sample,
            samples: end.round() as usize + 1,
        })
    }

    /// Flight duration, s (`trajectory.end_time_s`).
    pub fn duration_s(&self) -> f64 {
        self.trajectory.end_time_s
    }

    /// Length of the `out` buffer of [`crate::run`]: duration + 1 records (t = 0, 1, …, duration).
    pub fn samples_per_run(&self) -> usize {
        self.trajectory.end_time_s.round().max(0.0) as usize + 1
    }

    /// Runs per mode from `[monte_carlo]`.
    pub fn default_runs(&self) -> usize {
        self.monte_carlo.runs
    }

    /// The same scenario cut to its first `duration_s` seconds (manoeuvre segments that
    /// start after it are dropped, the last one shortened). For fast tests and `--duration`.
    /// Errors (naming `trajectory.end_time_s`) when longer than the scenario or not a whole
    /// number of seconds.
    pub fn truncated(&self, duration_s: f64) -> Result<Scenario, SimError> {
        if !(duration_s.is_finite() && duration_s <= self.trajectory.end_time_s) {
            return Err(SimError::invalid(
                "trajectory.end_time_s",
                "a truncated scenario must not be longer than the original",
                duration_s,
            ));
        }
        let mut s = self.clone();
        let mut t = 0.0;
        let mut keep = Vec::new();
        for seg in &self.trajectory.segments {
            if t >= duration_s - 1e-9 {
                break;
            }
            let mut seg = seg.clone();
            if t + seg.duration_s > duration_s {
                seg.duration_s = duration_s - t;
            }
            t += seg.duration_s;
            keep.push(seg);
        }
        s.trajectory.segments = keep;
        s.trajectory.end_time_s = duration_s;
        s.validate()?;
        Ok(s)
    }

    /// Human-readable list of the modelling choices (for summary.md).
    pub fn assumptions(&self) -> Vec<String> {
        let f = &self.filter;
        let t = &self.trajectory;
        vec![
            format!(
                "Flight: start {:.4}°, {:.4}°, {} m, {} m/s heading {}°; {} manoeuvre segments, straight to {} s (ins-errors [trajectory]).",
                t.start_lat_deg,
                t.start_lon_deg,
                t.start_alt_m,
                t.start_speed_mps,
                t.start_heading_deg,
                t.segments.len(),
                t.end_time_s
            ),
            format!(
                "INS starts at the true position, velocity and attitude; step {} s ({} Hz).",
                t.step_s,
                (1.0 / t.step_s).round()
            ),
            format!(
                "IMU: random constants per run and axis, σ = {} mg (accelerometer), {} °/h (gyro), {:?}; white noise variance per sample {} mg², {} (°/h)².",
                self.imu.accel_bias_sigma_mg,
                self.imu.gyro_drift_sigma_degph,
                self.imu.bias_model,
                self.imu.accel_noise_var_per_sample_mg2,
                self.imu.gyro_noise_var_per_sample_degph2
            ),
            format!(
                "SD: {} landmarks, all always in view, noise variance {} m² on each of w and h, update every {} s; simulated with the nonlinear gimbal/camera model of sighting-model.",
                self.sighting.landmarks.len(),
                self.sighting.noise_var_m2,
                self.sighting.update_period_s
            ),
            format!(
                "Filter: P0 σ = {} m, {} m/s, {} mrad, {} mg, {} °/h; R = {} m²·I6; open loop until {} s, then feedback with reset (P kept); measurement matrix H: {}.",
                f.p0_pos_sigma_m,
                f.p0_vel_sigma_mps,
                f.p0_psi_sigma_mrad,
                f.p0_accel_bias_sigma_mg,
                f.p0_gyro_drift_sigma_degph,
                f.r_var_m2,
                f.open_loop_until_s,
                match f.measurement_jacobian {
                    MeasurementJacobian::Verified =>
                        "verified (sighting-model, checked against finite differences)",
                    MeasurementJacobian::PaperPrinted =>
                        "the paper's eqs. 15–18 AS PRINTED (α₀ = depression, printed H₃; comparison run)",
                    MeasurementJacobian::PaperPrintedElevation =>
                        "the paper's eqs. 15–18 as printed but α₀ = elevation (verified H + printed H₃; comparison run)",
                }
            ),
            format!(
                "KF Q (continuous, per body axis): accelerometer white {} mg² per sample, gyro white {} (°/h)² per sample, bias random walk {} mg²/s, drift random walk {} (°/h)²/s.",
                f.q_accel_noise_var_per_sample_mg2,
                f.q_gyro_noise_var_per_sample_degph2,
                f.q_accel_bias_rw_psd_mg2_per_s,
                f.q_gyro_drift_rw_psd_degph2_per_s
            ),
            format!(
                "Φ and Q over each {} s SD interval from A averaged on {} sub-intervals (series Φ, Simpson Q), not propagated at 100 Hz.",
                self.sighting.update_period_s, f.phi_subintervals
            ),
            format!(
                "AKF: {} Q̂ with window/warm-up N = {}, projection {:?} (floor {}), used directly as the next interval's Q; the KF's a-priori Q until the window is full. Comparison configurations (--filters): akf_sage_husa = Sage–Husa, forgetting factor {}, same projection; akf_structured = Mohamed–Schwarz with the structured NNLS projection onto the four noise inputs.",
                match f.akf_scheme {
                    AkfScheme::MohamedSchwarz => "Mohamed–Schwarz",
                    AkfScheme::SageHusa => "Sage–Husa",
                },
                f.akf_window,
                f.akf_projection,
                f.akf_min_variance,
                f.sage_husa_forgetting
            ),
            "Common random numbers: the three modes of one run index share truth, IMU error draw and IMU noise.".to_string(),
            format!(
                "Monte Carlo: {} runs per mode, master seed {}.",
                self.monte_carlo.runs, self.monte_carlo.seed
            ),
        ]
    }
}

fn sighting_err(e: SightingError) -> SimError {
    match e {
        SightingError::InvalidField {
            field,
            value,
            requirement,
        } => SimError::ScenarioInvalid {
            field: format!("sighting.{field}"),
            requirement: requirement.to_string(),
            value: format!("{value:?}"),
        },
        SightingError::LandmarkCount { expected, found } => SimError::ScenarioInvalid {
            field: "sighting.landmarks".to_string(),
            requirement: format!("must hold exactly {expected} landmarks"),
            value: found.to_string(),
        },
        other => SimError::ScenarioInvalid {
            field: "sighting.landmarks".to_string(),
            requirement: other.to_string(),
            value: String::new(),
        },
    }
}
