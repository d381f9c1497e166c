//! The filter's configuration, in SI units.

use akf::{AdaptiveQConfig, QProjection, SageHusaConfig};
use serde::{Deserialize, Serialize};

use crate::FilterError;

/// Which measurement matrix H the filter linearises a sighting with.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MeasurementJacobian {
    /// The verified H, [`sighting_model::sighting_jacobian`] (checked against finite
    /// differences of the nonlinear model). The default.
    #[default]
    Verified,
    /// The paper's eqs. 15–18 as printed (α₀ read as the depression: h rows × cos 2ε; printed
    /// H₃ kept), [`sighting_model::paper_printed_jacobian`]. For reproducing the paper only.
    PaperPrinted,
    /// The printed eqs. 15–18 with only α₀ repaired (read as the elevation): the verified H
    /// plus the printed H₃. Isolates the paper's other flaw.
    PaperPrintedElevation,
}

/// Initial one-sigma uncertainty of each component of the error state (the same on the three
/// axes of each block).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ErrorSigmas {
    /// Position error, m.
    pub pos_m: f64,
    /// Velocity error, m/s.
    pub vel_mps: f64,
    /// Misalignment ψ, rad.
    pub psi_rad: f64,
    /// Accelerometer bias, m/s².
    pub accel_bias_mps2: f64,
    /// Gyro drift, rad/s.
    pub gyro_drift_radps: f64,
}

impl ErrorSigmas {
    /// The variances (σ²) in block order δp, δv, ψ, ∇, ε.
    pub fn variances(&self) -> [f64; 5] {
        [
            self.pos_m.powi(2),
            self.vel_mps.powi(2),
            self.psi_rad.powi(2),
            self.accel_bias_mps2.powi(2),
            self.gyro_drift_radps.powi(2),
        ]
    }
}

/// Continuous process-noise densities of the filter's model (equal on the three body axes).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProcessNoisePsd {
    /// Accelerometer white noise, (m/s²)²/Hz (velocity random walk²).
    pub accel_white_m2ps3: f64,
    /// Gyro white noise, rad²/s (angle random walk²).
    pub gyro_white_rad2ps: f64,
    /// Random walk of the accelerometer-bias states, (m/s²)²/s (0 = random constant).
    pub accel_bias_rw_m2ps5: f64,
    /// Random walk of the gyro-drift states, (rad/s)²/s (0 = random constant).
    pub gyro_drift_rw_rad2ps3: f64,
}

impl ProcessNoisePsd {
    /// As the array `[accel, gyro, bias RW, drift RW]` of [`crate::interval::IntervalModel::new`].
    pub fn as_array(&self) -> [f64; 4] {
        [
            self.accel_white_m2ps3,
            self.gyro_white_rad2ps,
            self.accel_bias_rw_m2ps5,
            self.gyro_drift_rw_rad2ps3,
        ]
    }
}

/// The error-state estimator run on the INS.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ErrorStateEstimator {
    /// No estimator: the free (stand-alone) INS; sightings are checked and ignored.
    StandAlone,
    /// Kalman filter with the configured (a-priori) process noise.
    Kalman,
    /// Adaptive KF of Mohamed & Schwarz (paper eq. 19): Q̂ from a window of state corrections,
    /// used as the next interval's Q once the window is full (the a-priori Q before).
    MohamedSchwarz(AdaptiveQConfig),
    /// Sage–Husa with a forgetting factor ([`akf::SageHusaQ`]): the exponentially weighted mean
    /// of the single-update estimates, used once `warmup` updates have been seen.
    SageHusa(SageHusaConfig),
}

impl ErrorStateEstimator {
    /// The projection of the adaptive estimate (`None` for KF and stand-alone).
    pub fn projection(&self) -> Option<QProjection> {
        match self {
            ErrorStateEstimator::MohamedSchwarz(c) => Some(c.projection),
            ErrorStateEstimator::SageHusa(c) => Some(c.projection),
            _ => None,
        }
    }
}

/// Everything the online filter needs besides the landmark table and the initial state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InsSdFilterConfig {
    /// Nominal IMU sample period, s (> 0).
    pub imu_step_s: f64,
    /// An IMU interval within this many seconds of `imu_step_s` is taken as exactly
    /// `imu_step_s` (clock jitter and round-off of time stamps); longer or shorter intervals
    /// are mechanised with their own length. 0 ≤ tolerance < `imu_step_s` / 2.
    pub timestamp_tolerance_s: f64,
    /// Nominal time between sighting epochs, s (≥ `imu_step_s`): sets the sub-interval length
    /// of the Φ/Q discretisation (`update_period_s / phi_subintervals`).
    pub update_period_s: f64,
    /// Sub-intervals per nominal update period on which A is averaged (≥ 1).
    pub phi_subintervals: usize,
    /// Initial error-state uncertainty.
    pub p0_sigma: ErrorSigmas,
    /// Process noise of the filter's model.
    pub process_noise: ProcessNoisePsd,
    /// Measurement-noise variance of each of w and h, m² (> 0).
    pub r_var_m2: f64,
    /// Open loop before this time (x̂ propagated and updated, the INS runs free); at every
    /// sighting epoch at or after it, feedback (INS corrected, x̂ ← 0, P kept). s; +∞ = never.
    pub open_loop_until_s: f64,
    /// χ² innovation gate: a sighting whose 2-dof NIS against the prior exceeds the
    /// `gate_probability` quantile (−2 ln(1 − p)) is rejected. `None` = no gate.
    pub gate_probability: Option<f64>,
    /// KF, adaptive KF or none.
    pub estimator: ErrorStateEstimator,
    /// Measurement matrix.
    pub jacobian: MeasurementJacobian,
}

impl InsSdFilterConfig {
    /// Checks every field; the error names the first offending one.
    ///
    /// # Errors
    /// [`FilterError::InvalidConfig`].
    pub fn validate(&self) -> Result<(), FilterError> {
        fn bad(field: &'static str, requirement: &'static str, value: f64) -> FilterError {
            FilterError::InvalidConfig {
                field,
                requirement,
                value: format!("{value:?}"),
            }
        }
        if !(self.imu_step_s.is_finite() && self.imu_step_s > 0.0) {
            return Err(bad("imu_step_s", "must be finite and > 0", self.imu_step_s));
        }
        let tol = self.timestamp_tolerance_s;
        if !(tol.is_finite() && tol >= 0.0 && tol < 0.5 * self.imu_step_s) {
            return Err(bad(
                "timestamp_tolerance_s",
                "must be >= 0 and below imu_step_s / 2",
                tol,
            ));
        }
        if !(self.update_period_s.is_finite() && self.update_period_s >= self.imu_step_s) {
            return Err(bad(
                "update_period_s",
                "must be finite and >= imu_step_s",
                self.update_period_s,
            ));
        }
        if self.phi_subintervals == 0 || self.phi_subintervals > self.steps_per_update() {
            return Err(bad(
                "phi_subintervals",
                "must be within 1..=update_period_s/imu_step_s",
                self.phi_subintervals as f64,
            ));
        }
        let s = &self.p0_sigma;
        for (field, v) in [
            ("p0_sigma.pos_m", s.pos_m),
            ("p0_sigma.vel_mps", s.vel_mps),
            ("p0_sigma.psi_rad", s.psi_rad),
            ("p0_sigma.accel_bias_mps2", s.accel_bias_mps2),
            ("p0_sigma.gyro_drift_radps", s.gyro_drift_radps),
            ("r_var_m2", self.r_var_m2),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(bad(field, "must be finite and > 0", v));
            }
        }
        let q = &self.process_noise;
        for (field, v) in [
            ("process_noise.accel_white_m2ps3", q.accel_white_m2ps3),
            ("process_noise.gyro_white_rad2ps", q.gyro_white_rad2ps),
            ("process_noise.accel_bias_rw_m2ps5", q.accel_bias_rw_m2ps5),
            (
                "process_noise.gyro_drift_rw_rad2ps3",
                q.gyro_drift_rw_rad2ps3,
            ),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(bad(field, "must be finite and >= 0", v));
            }
        }
        if self.open_loop_until_s.is_nan() {
            return Err(bad(
                "open_loop_until_s",
                "must not be NaN",
                self.open_loop_until_s,
            ));
        }
        if let Some(p) = self.gate_probability
            && !(p > 0.0 && p < 1.0)
        {
            return Err(bad("gate_probability", "must be within (0, 1)", p));
        }
        let checked = match &self.estimator {
            ErrorStateEstimator::MohamedSchwarz(c) => c.validate(akf::DEFAULT_WINDOW_CAPACITY),
            ErrorStateEstimator::SageHusa(c) => c.validate(),
            _ => Ok(()),
        };
        checked.map_err(|source| FilterError::InvalidEstimator { source })?;
        Ok(())
    }

    /// IMU steps per nominal update period (≥ 1).
    pub fn steps_per_update(&self) -> usize {
        ((self.update_period_s / self.imu_step_s).round() as usize).max(1)
    }

    /// The gate threshold on the 2-dof NIS of one sighting, if gated: −2 ln(1 − p) (exact χ²₂
    /// quantile).
    pub fn gate_threshold(&self) -> Option<f64> {
        self.gate_probability.map(|p| -2.0 * (1.0 - p).ln())
    }
}
