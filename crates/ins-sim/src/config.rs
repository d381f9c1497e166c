//! The scenario file: `[trajectory]`, `[imu]` (crate `ins-errors`), `[sighting]` (crate
//! `sighting-model`), `[filter]` and `[monte_carlo]` (this module).

use akf::QProjection;
use ins_errors::config::{ImuConfig, TrajectoryConfig};
use ins_errors::imu::{DEGPH_TO_RADPS, MG_TO_MPS2};
use serde::{Deserialize, Serialize};
use sighting_model::SightingConfig;

use crate::SimError;

pub use ins_sd_filter::MeasurementJacobian;

/// `[filter]`: initial covariance, process-noise tuning, measurement noise, feedback switch
/// and the discretisation / adaptive-Q parameters of the INS/SD error-state filter.
///
/// The process noise is given as continuous white-noise densities on the sensor inputs
/// (body axes, equal on the three axes): accelerometer and gyro white noise, and the
/// random-walk densities of the bias/drift states. The white-noise figures use the same units
/// as `[imu]` (variance of one IMU sample at `trajectory.step_s`; PSD = variance · step_s), so
/// "true statistics" means copying the `[imu]` values and zero random walks.
///
/// The SD update period is not repeated here: it is `[sighting] update_period_s` (one source
/// of truth for the simulated device and the filter).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ScenarioFilterConfig {
    /// Initial σ of each position-error component, m (> 0).
    pub p0_pos_sigma_m: f64,
    /// Initial σ of each velocity-error component, m/s (> 0).
    pub p0_vel_sigma_mps: f64,
    /// Initial σ of each misalignment (ψ) component, mrad (> 0).
    pub p0_psi_sigma_mrad: f64,
    /// Initial σ of each accelerometer-bias component, mg (> 0).
    pub p0_accel_bias_sigma_mg: f64,
    /// Initial σ of each gyro-drift component, °/h (> 0).
    pub p0_gyro_drift_sigma_degph: f64,
    /// Filter's accelerometer white-noise variance per IMU sample, mg² (≥ 0).
    pub q_accel_noise_var_per_sample_mg2: f64,
    /// Filter's gyro white-noise variance per IMU sample, (°/h)² (≥ 0).
    pub q_gyro_noise_var_per_sample_degph2: f64,
    /// Random-walk PSD of the accelerometer-bias states, mg²/s (≥ 0; 0 = random constant).
    pub q_accel_bias_rw_psd_mg2_per_s: f64,
    /// Random-walk PSD of the gyro-drift states, (°/h)²/s (≥ 0; 0 = random constant).
    pub q_gyro_drift_rw_psd_degph2_per_s: f64,
    /// Filter's SD measurement-noise variance R (each of w, h), m² (> 0).
    pub r_var_m2: f64,
    /// Time until which the filter runs open loop, s (paper: 195); at the first SD update at or
    /// after this time and at every update afterwards the estimates are fed back. A value
    /// beyond the run's end keeps the filter open loop throughout.
    pub open_loop_until_s: f64,
    /// Number of equal sub-intervals per SD interval on which the error model A is averaged to
    /// build Φ and Q_d of the interval (1 ..= steps per interval; see the module doc).
    pub phi_subintervals: usize,
    /// AKF window N (Mohamed & Schwarz; paper: 10), 1 ..= `akf::DEFAULT_WINDOW_CAPACITY`.
    pub akf_window: usize,
    /// How the AKF's indefinite Q̂ is made PSD: `"eigen_clip"`, `"diagonal"` or `"structured"`
    /// (non-negative least squares onto the model's four noise inputs, Q̂ = Σ q̂_k B_k).
    pub akf_projection: QProjection,
    /// Floor of the projected Q̂ (eigenvalues or diagonal), state units² per SD interval (≥ 0).
    pub akf_min_variance: f64,
    /// Adaptive scheme of the `akf` configuration: `"mohamed_schwarz"` (paper eq. 19, window
    /// `akf_window`; the default when the key is absent) or `"sage_husa"` (forgetting factor
    /// `sage_husa_forgetting`, warm-up `akf_window` updates).
    #[serde(default)]
    pub akf_scheme: AkfScheme,
    /// Sage–Husa forgetting factor b, 0 < b ≤ 1 (memory ≈ 1/(1 − b) updates); default 0.95.
    #[serde(default = "default_forgetting")]
    pub sage_husa_forgetting: f64,
    /// χ² innovation gate of each sighting: rejection probability 1 − p under the model (e.g.
    /// 0.9999); absent = no gate (the paper's filter).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gate_probability: Option<f64>,
    /// Measurement matrix of the filter: `"verified"` (default when the key is absent),
    /// `"paper_printed"` (the printed eqs. 15–18) or `"paper_printed_elevation"` (printed, α₀
    /// repaired); the last two for comparison with the paper.
    #[serde(default)]
    pub measurement_jacobian: MeasurementJacobian,
}

/// `[filter] akf_scheme`: the adaptive process-noise estimator of the `akf` configuration.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum AkfScheme {
    /// Mohamed & Schwarz (paper eq. 19), window `akf_window`.
    #[default]
    MohamedSchwarz,
    /// Sage–Husa with forgetting factor `sage_husa_forgetting`.
    SageHusa,
}

fn default_forgetting() -> f64 {
    0.95
}

impl Default for ScenarioFilterConfig {
    fn default() -> Self {
        Self::paper()
    }
}

impl ScenarioFilterConfig {
    /// The values of `configs/paper.toml` (the tuned KF, see the module doc).
    pub fn paper() -> Self {
        Self {
            p0_pos_sigma_m: 1.0,
            p0_vel_sigma_mps: 0.1,
            p0_psi_sigma_mrad: 1.0,
            p0_accel_bias_sigma_mg: 3.0,
            p0_gyro_drift_sigma_degph: 2.0,
            q_accel_noise_var_per_sample_mg2: 2.0,
            q_gyro_noise_var_per_sample_degph2: 2.0,
            q_accel_bias_rw_psd_mg2_per_s: 0.0,
            q_gyro_drift_rw_psd_degph2_per_s: 0.0,
            r_var_m2: 40.0,
            open_loop_until_s: 195.0,
            phi_subintervals: 2,
            akf_window: 10,
            akf_projection: QProjection::Diagonal,
            akf_min_variance: 0.0,
            akf_scheme: AkfScheme::MohamedSchwarz,
            sage_husa_forgetting: 0.95,
            gate_probability: None,
            measurement_jacobian: MeasurementJacobian::Verified,
        }
    }

    /// Checks what only the scenario knows: `open_loop_until_s` is a time of the flight (≥ 0).
    /// Every other limit is the online filter's (`ins_sd_filter::InsSdFilterConfig::validate`
    /// and the `akf` estimator configurations), checked once in their own units by
    /// [`super::Scenario::validate`] on the converted configuration, the error naming the
    /// `[filter]` key ([`ScenarioFilterConfig::toml_key`]).
    pub fn validate(&self) -> Result<(), SimError> {
        let v = self.open_loop_until_s;
        if !(v.is_finite() && v >= 0.0) {
            return Err(SimError::invalid(
                "filter.open_loop_until_s",
                "must be finite and >= 0",
                v,
            ));
        }
        Ok(())
    }

    /// The scenario key (dotted, as in the TOML file) and its value as written, of a field of
    /// the online filter's configuration (`ins_sd_filter::FilterError::InvalidConfig::field`) or
    /// of an `akf` estimator configuration (`akf::AkfError::InvalidParameter::field`, given as
    /// `estimator.<field>`). `None` for a field the scenario does not set.
    pub fn toml_key(&self, filter_field: &str) -> Option<(&'static str, String)> {
        let v = |x: f64| format!("{x:?}");
        Some(match filter_field {
            "phi_subintervals" => ("filter.phi_subintervals", self.phi_subintervals.to_string()),
            "p0_sigma.pos_m" => ("filter.p0_pos_sigma_m", v(self.p0_pos_sigma_m)),
            "p0_sigma.vel_mps" => ("filter.p0_vel_sigma_mps", v(self.p0_vel_sigma_mps)),
            "p0_sigma.psi_rad" => ("filter.p0_psi_sigma_mrad", v(self.p0_psi_sigma_mrad)),
            "p0_sigma.accel_bias_mps2" => (
                "filter.p0_accel_bias_sigma_mg",
                v(self.p0_accel_bias_sigma_mg),
            ),
            "p0_sigma.gyro_drift_radps" => (
                "filter.p0_gyro_drift_sigma_degph",
                v(self.p0_gyro_drift_sigma_degph),
            ),
            "r_var_m2" => ("filter.r_var_m2", v(self.r_var_m2)),
            "process_noise.accel_white_m2ps3" => (
                "filter.q_accel_noise_var_per_sample_mg2",
                v(self.q_accel_noise_var_per_sample_mg2),
            ),
            "process_noise.gyro_white_rad2ps" => (
                "filter.q_gyro_noise_var_per_sample_degph2",
                v(self.q_gyro_noise_var_per_sample_degph2),
            ),
            "process_noise.accel_bias_rw_m2ps5" => (
                "filter.q_accel_bias_rw_psd_mg2_per_s",
                v(self.q_accel_bias_rw_psd_mg2_per_s),
            ),
            "process_noise.gyro_drift_rw_rad2ps3" => (
                "filter.q_gyro_drift_rw_psd_degph2_per_s",
                v(self.q_gyro_drift_rw_psd_degph2_per_s),
            ),
            "open_loop_until_s" => ("filter.open_loop_until_s", v(self.open_loop_until_s)),
            "gate_probability" => (
                "filter.gate_probability",
                format!("{:?}", self.gate_probability),
            ),
            "estimator.window" | "estimator.warmup" => {
                ("filter.akf_window", self.akf_window.to_string())
            }
            "estimator.min_variance" => ("filter.akf_min_variance", v(self.akf_min_variance)),
            "estimator.forgetting" => ("filter.sage_husa_forgetting", v(self.sage_husa_forgetting)),
            _ => return None,
        })
    }

    /// Initial σ in state units (m, m/s, rad, m/s², rad/s).
    pub(crate) fn p0_sigmas(&self) -> [f64; 5] {
        [
            self.p0_pos_sigma_m,
            self.p0_vel_sigma_mps,
            self.p0_psi_sigma_mrad * 1e-3,
            self.p0_accel_bias_sigma_mg * MG_TO_MPS2,
            self.p0_gyro_drift_sigma_degph * DEGPH_TO_RADPS,
        ]
    }

    /// Continuous PSDs (accelerometer (m/s²)²/Hz, gyro rad²/s, bias RW (m/s²)²/s, drift RW
    /// (rad/s)²/s) for an IMU sample step `step_s`.
    pub(crate) fn psd(&self, step_s: f64) -> [f64; 4] {
        [
            self.q_accel_noise_var_per_sample_mg2 * MG_TO_MPS2.powi(2) * step_s,
            self.q_gyro_noise_var_per_sample_degph2 * DEGPH_TO_RADPS.powi(2) * step_s,
            self.q_accel_bias_rw_psd_mg2_per_s * MG_TO_MPS2.powi(2),
            self.q_gyro_drift_rw_psd_degph2_per_s * DEGPH_TO_RADPS.powi(2),
        ]
    }
}

/// `[mismatch]` (optional; all off by default): how the simulated world departs from the
/// filter's model. The filter is not told (its `[filter]` stays as it is), which is the point:
/// each `configs/mismatch/*.toml` turns one of these on. Random draws for the mismatch come
/// from their own ChaCha stream (2) of the run's seed, so the IMU and sighting noise are the
/// matched run's (common random numbers).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct MismatchConfig {
    /// σ of each accelerometer scale-factor error, ppm (random constant per run and axis).
    pub accel_scale_factor_sigma_ppm: f64,
    /// σ of each gyro scale-factor error, ppm.
    pub gyro_scale_factor_sigma_ppm: f64,
    /// σ of each accelerometer axis-misalignment (off-diagonal) entry, mrad.
    pub accel_misalignment_sigma_mrad: f64,
    /// σ of each gyro axis-misalignment (off-diagonal) entry, mrad.
    pub gyro_misalignment_sigma_mrad: f64,
    /// Steady-state σ of a first-order Gauss–Markov accelerometer bias added to the random
    /// constant, mg.
    pub accel_bias_instability_sigma_mg: f64,
    /// Steady-state σ of a first-order Gauss–Markov gyro drift added to the random constant, °/h.
    pub gyro_bias_instability_sigma_degph: f64,
    /// Correlation time of both Gauss–Markov processes, s (> 0).
    pub bias_correlation_time_s: f64,
    /// Angular sighting noise σ, mrad: adds N(0, (σ·range)²) m to w and h (metric noise grows
    /// with the range), on top of `[sighting] noise_var_m2`.
    pub sighting_noise_mrad: f64,
    /// σ of each NED component of every landmark's survey error, m (per run): the filter's
    /// table holds the surveyed positions, the landmarks are elsewhere.
    pub landmark_survey_sigma_m: f64,
    /// Fraction of sightings with a gross error (0–1).
    pub outlier_fraction: f64,
    /// σ of the gross error added to w and h of an outlier, m.
    pub outlier_sigma_m: f64,
    /// Field of regard of the gimballed camera: largest angle between the body down axis and
    /// the line of sight, degrees (180 = no limit). Landmarks outside are not sighted.
    pub camera_max_off_nadir_deg: f64,
    /// Largest slant range at which a landmark is sighted, m (0 = no limit).
    pub max_range_m: f64,
    /// Sighting latency, s (a multiple of the IMU step, < the SD period): the image is taken
    /// this long before the epoch at which the filter processes it as current.
    pub latency_s: f64,
}

impl Default for MismatchConfig {
    fn default() -> Self {
        Self {
            accel_scale_factor_sigma_ppm: 0.0,
            gyro_scale_factor_sigma_ppm: 0.0,
            accel_misalignment_sigma_mrad: 0.0,
            gyro_misalignment_sigma_mrad: 0.0,
            accel_bias_instability_sigma_mg: 0.0,
            gyro_bias_instability_sigma_degph: 0.0,
            bias_correlation_time_s: 300.0,
            sighting_noise_mrad: 0.0,
            landmark_survey_sigma_m: 0.0,
            outlier_fraction: 0.0,
            outlier_sigma_m: 300.0,
            camera_max_off_nadir_deg: 180.0,
            max_range_m: 0.0,
            latency_s: 0.0,
        }
    }
}

impl MismatchConfig {
    /// True when every mismatch is off (the simulated world is the filter's model).
    pub fn is_matched(&self) -> bool {
        *self
            == Self {
                bias_correlation_time_s: self.bias_correlation_time_s,
                outlier_sigma_m: self.outlier_sigma_m,
                ..Self::default()
            }
    }

    /// Checks every field; the error names it as `mismatch.<field>`.
    pub fn validate(&self) -> Result<(), SimError> {
        for (f, v) in [
            (
                "mismatch.accel_scale_factor_sigma_ppm",
                self.accel_scale_factor_sigma_ppm,
            ),
            (
                "mismatch.gyro_scale_factor_sigma_ppm",
                self.gyro_scale_factor_sigma_ppm,
            ),
            (
                "mismatch.accel_misalignment_sigma_mrad",
                self.accel_misalignment_sigma_mrad,
            ),
            (
                "mismatch.gyro_misalignment_sigma_mrad",
                self.gyro_misalignment_sigma_mrad,
            ),
            (
                "mismatch.accel_bias_instability_sigma_mg",
                self.accel_bias_instability_sigma_mg,
            ),
            (
                "mismatch.gyro_bias_instability_sigma_degph",
                self.gyro_bias_instability_sigma_degph,
            ),
            ("mismatch.sighting_noise_mrad", self.sighting_noise_mrad),
            (
                "mismatch.landmark_survey_sigma_m",
                self.landmark_survey_sigma_m,
            ),
            ("mismatch.outlier_sigma_m", self.outlier_sigma_m),
            ("mismatch.max_range_m", self.max_range_m),
            ("mismatch.latency_s", self.latency_s),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(SimError::invalid(f, "must be finite and >= 0", v));
            }
        }
        if !(self.bias_correlation_time_s.is_finite() && self.bias_correlation_time_s > 0.0) {
            return Err(SimError::invalid(
                "mismatch.bias_correlation_time_s",
                "must be finite and > 0",
                self.bias_correlation_time_s,
            ));
        }
        if !(0.0..=1.0).contains(&self.outlier_fraction) {
            return Err(SimError::invalid(
                "mismatch.outlier_fraction",
                "must be within [0, 1]",
                self.outlier_fraction,
            ));
        }
        if !(self.camera_max_off_nadir_deg > 0.0 && self.camera_max_off_nadir_deg <= 180.0) {
            return Err(SimError::invalid(
                "mismatch.camera_max_off_nadir_deg",
                "must be within (0, 180]",
                self.camera_max_off_nadir_deg,
            ));
        }
        Ok(())
    }
}

/// `[monte_carlo]`: how many runs and the master seed.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MonteCarloConfig {
    /// Runs per mode (paper: not stated; we use 100), ≥ 1.
    pub runs: usize,
    /// Master seed; run i uses [`super::run_seed`]`(seed, i)`.
    pub seed: u64,
}

impl Default for MonteCarloConfig {
    fn default() -> Self {
        Self::paper()
    }
}

impl MonteCarloConfig {
    /// 100 runs, seed 2009 (the values of `configs/paper.toml`).
    pub fn paper() -> Self {
        Self {
            runs: 100,
            seed: 2009,
        }
    }

    /// Checks every field; the error names it as `monte_carlo.<field>`.
    pub fn validate(&self) -> Result<(), SimError> {
        if self.runs == 0 {
            return Err(SimError::invalid(
                "monte_carlo.runs",
                "must be >= 1",
                self.runs,
            ));
        }
        Ok(())
    }
}

/// The whole scenario document, as deserialised (unknown sections are rejected).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct ScenarioFile {
    pub trajectory: TrajectoryConfig,
    pub imu: ImuConfig,
    pub sighting: SightingConfig,
    pub filter: ScenarioFilterConfig,
    pub monte_carlo: MonteCarloConfig,
    #[serde(default, skip_serializing_if = "MismatchConfig::is_matched")]
    pub mismatch: MismatchConfig,
}

const SECTIONS: [&str; 6] = [
    "trajectory",
    "imu",
    "sighting",
    "filter",
    "monte_carlo",
    "mismatch",
];

/// Parses the document section by section (through the workspace's one TOML loader,
/// `toml_config::TomlDoc`) so that an error names its section, file, line and column.
pub(crate) fn parse(doc: &toml_config::TomlDoc<'_>) -> Result<ScenarioFile, SimError> {
    let located = |field: &str| {
        let field = field.to_string();
        move |error| SimError::ScenarioFile { field, error }
    };
    doc.allow_only(&SECTIONS)
        .map_err(|error| SimError::ScenarioFile {
            field: doc
                .keys()
                .find(|k| !SECTIONS.contains(k))
                .unwrap_or("(document)")
                .to_string(),
            error,
        })?;
    Ok(ScenarioFile {
        trajectory: doc.section("trajectory").map_err(located("trajectory"))?,
        imu: doc.section("imu").map_err(located("imu"))?,
        sighting: doc.section("sighting").map_err(located("sighting"))?,
        filter: doc.section("filter").map_err(located("filter"))?,
        monte_carlo: doc.section("monte_carlo").map_err(located("monte_carlo"))?,
        mismatch: if doc.keys().any(|k| k == "mismatch") {
            doc.section("mismatch").map_err(located("mismatch"))?
        } else {
            MismatchConfig::default()
        },
    })
}
