//! The replay's filter file: the filter settings of `nav-app ins`, in the units of an IMU
//! datasheet, with presets compiled in.
//!
//! ```toml
//! preset = "mems"            # optional: "mems" (default) or "paper"; the keys below override it
//! [imu]
//! gyro_arw_deg_per_rt_h = 10.0            # angle random walk N_g, °/√h
//! accel_vrw_mps_per_rt_h = 1.0            # velocity random walk N_a, m/s/√h
//! gyro_bias_instability_deg_per_h = 20.0  # bias instability B_g, °/h (0: random constant)
//! gyro_bias_corr_time_s = 300.0           # its correlation time τ_g, s
//! accel_bias_instability_mg = 0.5         # B_a, mg (1 mg = 9.80665e-3 m/s²)
//! accel_bias_corr_time_s = 300.0          # τ_a, s
//! gyro_bias_initial_sigma_deg_per_h = 1800.0  # turn-on bias, 1σ
//! accel_bias_initial_sigma_mg = 50.0
//! [initial]
//! pos_sigma_m = 1.0          # initial 1σ of the position, velocity and attitude errors
//! vel_sigma_mps = 0.1
//! att_sigma_deg = 2.0
//! [sighting]
//! sigma_m = 1.0              # σ of w and h, m at the landmark
//! gate_probability = 0.9999  # χ² gate per sighting; 0 = no gate
//! [filter]
//! update_period_s = 1.0      # nominal time between sighting epochs (Φ/Q sub-interval length)
//! phi_subintervals = 2
//! feedback_from_s = 0.0      # open loop for this long after the start, then feedback
//! akf_window = 10            # Mohamed–Schwarz window N (updates)
//! [align]                    # the rest check of --align-s (defaults shown; no preset sets them)
//! max_accel_spread_mps2 = 0.05     # accelerometer: largest per-axis std of its 1-s means, m/s²
//! max_gyro_spread_deg_per_s = 0.25 # gyro: the same, °/s
//! max_speed_mps = 0.3              # the reference's largest speed over the window, m/s
//! ```
//!
//! ## The rest check of a static alignment (`[align]`)
//!
//! `--align-s S` takes the gyro bias (and without a reference attitude, roll and pitch) from the
//! first S seconds, which is right only if the vehicle is at rest then
//! ([`crate::logs::align_at_rest`]). The window is cut into 1-s blocks and the standard
//! deviation of the block means is taken per axis: a 1-s mean averages out the sensor's white
//! noise and the engine's or rotors' vibration (tens of hertz and up), which leave the mean
//! bias unchanged, and keeps what a moving vehicle does over seconds — turns, accelerating,
//! braking — which would be taken as bias and tilt. The defaults:
//!
//! - `max_accel_spread_mps2 = 0.05`: three times the σ of a 1-s mean of white noise at the `mems`
//!   preset's (ten-fold inflated) 1 m/s/√h, 1/60 m/s² = 0.017 m/s². Measured on the shared real
//!   logs: 0.007 m/s² (EuRoC MH_01 at rest, rotors stirring at the end) and 0.019 m/s² (a car at
//!   rest, engine running) over their alignment windows; 0.11–1.6 m/s² over any 10–30 s window
//!   of the car driving or the MAV flying.
//! - `max_gyro_spread_deg_per_s = 0.25`: 1.5 σ of a 1-s mean at the `mems` preset's
//!   10 °/√h (0.17 °/s), half the preset's turn-on bias σ (0.5 °/s): motion that moves the 1-s
//!   means by more than this would bias the estimate by as much as the filter's prior allows.
//!   Measured: 0.035 and 0.052 °/s at rest, 0.37–18 °/s driving or flying.
//! - `max_speed_mps = 0.3` (with a reference): three times a standard GNSS receiver's velocity
//!   noise (about 0.1 m/s 1σ); a fifth of walking pace. Measured at rest: 0.03 m/s (EuRoC's
//!   laser tracker), 0.055 m/s (RTK); the issue's moving car: 8–11 m/s.
//!
//! A vehicle that turns at a constant rate at constant speed passes the spread checks (its
//! 1-s means do not vary): without a reference nothing in the IMU alone tells that from a bias.
//! A vehicle that is moving at the start is not aligned: leave out `--align-s` and take the
//! initial attitude from the reference (its quaternion, or its course and grade).
//!
//! ## From datasheet figures to the filter's densities
//!
//! The filter's noise inputs are continuous white-noise densities on δv (accelerometer), ψ (gyro)
//! and the two bias states (`ins_sd_filter::ProcessNoisePsd`):
//!
//! ```text
//! q_a = (N_a / 60)²                 (m/s²)²/Hz      N_a in m/s/√h; 1 m/s/√h = 1/60 m/s/√s
//! q_g = (N_g · π/180 / 60)²         rad²/s          N_g in °/√h
//! q_∇ = 2 B_a² / τ_a                (m/s²)²/s       B_a in m/s²
//! q_ε = 2 B_g² / τ_g                (rad/s)²/s      B_g in rad/s
//! ```
//!
//! A bias with instability B and correlation time τ is a first-order Gauss–Markov process whose
//! driving density is 2B²/τ. The filter models the biases as random walks (no decay: the paper's
//! error model, and what keeps the Monte Carlo byte-equal), driven by that same density: over
//! times short against τ the two grow alike (σ² ≈ 2B²t/τ); over longer times the random walk is
//! the more cautious. The turn-on bias σ is the initial P of the bias states.
//!
//! The discrete Q over a sub-interval T follows from these densities by the filter's
//! discretisation (`ins_errors::error_model::discretize_fast`: series Φ, Simpson Q_d). For the
//! chain δṗ = δv, δv̇ = ∇ + w_a, ∇̇ = w_∇ the exact (Van Loan) result has the closed form
//!
//! ```text
//! Q_pp = q_a T³/3 + q_∇ T⁵/20     Q_pv = q_a T²/2 + q_∇ T⁴/8     Q_p∇ = q_∇ T³/6
//! Q_vv = q_a T + q_∇ T³/3         Q_v∇ = q_∇ T²/2                Q_∇∇ = q_∇ T
//! ```
//!
//! and `tests/ins_sd_filter_file.rs` checks Van Loan against it, and the filter's discretisation
//! against Van Loan, with the densities of both presets.

use akf::{AdaptiveQConfig, SageHusaConfig};
use ins_errors::imu::{DEGPH_TO_RADPS, MG_TO_MPS2};
use ins_sd_filter::{
    ErrorSigmas, ErrorStateEstimator, InsSdFilterConfig, MeasurementJacobian, ProcessNoisePsd,
};
use serde::Deserialize;
use toml_config::TomlDoc;

use crate::{Mode, ScenarioFilterConfig, SimError};

mod print;

/// The `mems` preset (the default): a consumer / industrial MEMS IMU.
pub const PRESET_MEMS: &str = include_str!("../../presets/mems.toml");
/// The `paper` preset: the paper's IMU and manually tuned KF.
pub const PRESET_PAPER: &str = include_str!("../../presets/paper.toml");

/// The preset names and texts.
pub const PRESETS: [(&str, &str); 2] = [("mems", PRESET_MEMS), ("paper", PRESET_PAPER)];

#[derive(Clone, Copy, Debug, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
struct ImuSection {
    gyro_arw_deg_per_rt_h: Option<f64>,
    accel_vrw_mps_per_rt_h: Option<f64>,
    gyro_bias_instability_deg_per_h: Option<f64>,
    gyro_bias_corr_time_s: Option<f64>,
    accel_bias_instability_mg: Option<f64>,
    accel_bias_corr_time_s: Option<f64>,
    gyro_bias_initial_sigma_deg_per_h: Option<f64>,
    accel_bias_initial_sigma_mg: Option<f64>,
}

#[derive(Clone, Copy, Debug, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
struct InitialSection {
    pos_sigma_m: Option<f64>,
    vel_sigma_mps: Option<f64>,
    att_sigma_deg: Option<f64>,
}

#[derive(Clone, Copy, Debug, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
struct SightingSection {
    sigma_m: Option<f64>,
    gate_probability: Option<f64>,
}

#[derive(Clone, Copy, Debug, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
struct FilterSection {
    update_period_s: Option<f64>,
    phi_subintervals: Option<usize>,
    feedback_from_s: Option<f64>,
    akf_window: Option<usize>,
}

#[derive(Clone, Copy, Debug, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
struct AlignSection {
    max_accel_spread_mps2: Option<f64>,
    max_gyro_spread_deg_per_s: Option<f64>,
    max_speed_mps: Option<f64>,
}

#[derive(Clone, Debug, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawFile {
    preset: Option<String>,
    #[serde(default)]
    imu: ImuSection,
    #[serde(default)]
    initial: InitialSection,
    #[serde(default)]
    sighting: SightingSection,
    #[serde(default)]
    filter: FilterSection,
    #[serde(default)]
    align: AlignSection,
}

macro_rules! overlay {
    ($base:expr, $over:expr, $($f:ident),+) => {
        $( if $over.$f.is_some() { $base.$f = $over.$f; } )+
    };
}

impl RawFile {
    fn overlay(&mut self, o: &RawFile) {
        overlay!(
            self.imu,
            o.imu,
            gyro_arw_deg_per_rt_h,
            accel_vrw_mps_per_rt_h,
            gyro_bias_instability_deg_per_h,
            gyro_bias_corr_time_s,
            accel_bias_instability_mg,
            accel_bias_corr_time_s,
            gyro_bias_initial_sigma_deg_per_h,
            accel_bias_initial_sigma_mg
        );
        overlay!(
            self.initial,
            o.initial,
            pos_sigma_m,
            vel_sigma_mps,
            att_sigma_deg
        );
        overlay!(self.sighting, o.sighting, sigma_m, gate_probability);
        overlay!(
            self.filter,
            o.filter,
            update_period_s,
            phi_subintervals,
            feedback_from_s,
            akf_window
        );
        overlay!(
            self.align,
            o.align,
            max_accel_spread_mps2,
            max_gyro_spread_deg_per_s,
            max_speed_mps
        );
    }
}

/// The replay's filter settings, validated, in datasheet units (module documentation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FilterFile {
    /// The preset the file's keys were laid over (`mems` when it names none).
    pub preset: &'static str,
    /// Angle random walk, °/√h.
    pub gyro_arw_deg_per_rt_h: f64,
    /// Velocity random walk, m/s/√h.
    pub accel_vrw_mps_per_rt_h: f64,
    /// Gyro bias instability, °/h (0: random constant).
    pub gyro_bias_instability_deg_per_h: f64,
    /// Its correlation time, s.
    pub gyro_bias_corr_time_s: f64,
    /// Accelerometer bias instability, mg (0: random constant).
    pub accel_bias_instability_mg: f64,
    /// Its correlation time, s.
    pub accel_bias_corr_time_s: f64,
    /// Initial (turn-on) gyro bias, 1σ, °/h.
    pub gyro_bias_initial_sigma_deg_per_h: f64,
    /// Initial accelerometer bias, 1σ, mg.
    pub accel_bias_initial_sigma_mg: f64,
    /// Initial position error, 1σ per axis, m.
    pub pos_sigma_m: f64,
    /// Initial velocity error, 1σ per axis, m/s.
    pub vel_sigma_mps: f64,
    /// Initial attitude error, 1σ per axis, °.
    pub att_sigma_deg: f64,
    /// Sighting noise σ of w and h, m at the landmark.
    pub sighting_sigma_m: f64,
    /// χ² gate probability per sighting (`None`: no gate; 0 in the file).
    pub gate_probability: Option<f64>,
    /// Nominal time between sighting epochs, s.
    pub update_period_s: f64,
    /// Sub-intervals of the Φ/Q discretisation per update period.
    pub phi_subintervals: usize,
    /// Open loop for this long after the start of the replay, then feedback, s.
    pub feedback_from_s: f64,
    /// Mohamed–Schwarz window, updates.
    pub akf_window: usize,
    /// Rest check of `--align-s`: largest per-axis standard deviation of the accelerometer's
    /// 1-s means, m/s² (module documentation).
    pub align_max_accel_spread_mps2: f64,
    /// Likewise for the gyro, °/s.
    pub align_max_gyro_spread_deg_per_s: f64,
    /// The reference's largest speed over the window, m/s.
    pub align_max_speed_mps: f64,
}

/// A gate probability the filter accepts (the file writes 0 for no gate).
fn gate_in_range(p: f64) -> bool {
    p > 0.0 && p < 1.0
}

fn toml_err(path: &str, error: toml_config::TomlError) -> SimError {
    SimError::LogToml {
        path: path.into(),
        error,
    }
}

impl FilterFile {
    /// A compiled-in preset by name (`mems`, `paper`).
    ///
    /// # Errors
    /// [`SimError::LogToml`] (key `preset`) for an unknown name.
    pub fn preset(name: &str) -> Result<Self, SimError> {
        Self::from_toml_str(&format!("preset = \"{name}\"\n"), "--preset")
    }

    /// Parses a filter file (`path` names it in errors): its `preset` (default `mems`), then its
    /// keys over the preset's; every value checked.
    ///
    /// # Errors
    /// [`SimError::LogToml`] naming the file, line and column of a TOML error, an unknown key or
    /// preset, or a value out of range.
    pub fn from_toml_str(text: &str, path: &str) -> Result<Self, SimError> {
        let doc = TomlDoc::parse(path.to_owned(), text).map_err(|e| toml_err(path, e))?;
        Self::from_doc(&doc, path)
    }

    /// A filter file from a parsed document (`path` names it in errors; as
    /// [`FilterFile::from_toml_str`] after the parse).
    pub(crate) fn from_doc(doc: &TomlDoc<'_>, path: &str) -> Result<Self, SimError> {
        let user: RawFile = doc.deserialize().map_err(|e| toml_err(path, e))?;
        let name = user.preset.as_deref().unwrap_or("mems");
        let Some(&(preset, preset_text)) = PRESETS.iter().find(|(n, _)| *n == name) else {
            return Err(toml_err(
                path,
                doc.error_at(
                    "preset",
                    format!("unknown preset `{name}` (known: mems, paper)"),
                ),
            ));
        };
        let preset_doc =
            TomlDoc::parse(format!("preset {name}"), preset_text).map_err(|e| toml_err(path, e))?;
        let mut raw: RawFile = preset_doc.deserialize().map_err(|e| toml_err(path, e))?;
        raw.overlay(&user);
        let missing = |key: &str| {
            toml_err(
                path,
                doc.error_at(key, format!("`{key}` is missing (also from the preset)")),
            )
        };
        let get = |v: Option<f64>, key: &'static str| v.ok_or_else(|| missing(key));
        let (i, n, s, f, a) = (raw.imu, raw.initial, raw.sighting, raw.filter, raw.align);
        let defaults = crate::logs::AlignLimits::default();
        let out = FilterFile {
            preset,
            gyro_arw_deg_per_rt_h: get(i.gyro_arw_deg_per_rt_h, "imu.gyro_arw_deg_per_rt_h")?,
            accel_vrw_mps_per_rt_h: get(i.accel_vrw_mps_per_rt_h, "imu.accel_vrw_mps_per_rt_h")?,
            gyro_bias_instability_deg_per_h: get(
                i.gyro_bias_instability_deg_per_h,
                "imu.gyro_bias_instability_deg_per_h",
            )?,
            gyro_bias_corr_time_s: get(i.gyro_bias_corr_time_s, "imu.gyro_bias_corr_time_s")?,
            accel_bias_instability_mg: get(
                i.accel_bias_instability_mg,
                "imu.accel_bias_instability_mg",
            )?,
            accel_bias_corr_time_s: get(i.accel_bias_corr_time_s, "imu.accel_bias_corr_time_s")?,
            gyro_bias_initial_sigma_deg_per_h: get(
                i.gyro_bias_initial_sigma_deg_per_h,
                "imu.gyro_bias_initial_sigma_deg_per_h",
            )?,
            accel_bias_initial_sigma_mg: get(
                i.accel_bias_initial_sigma_mg,
                "imu.accel_bias_initial_sigma_mg",
            )?,
            pos_sigma_m: get(n.pos_sigma_m, "initial.pos_sigma_m")?,
            vel_sigma_mps: get(n.vel_sigma_mps, "initial.vel_sigma_mps")?,
            att_sigma_deg: get(n.att_sigma_deg, "initial.att_sigma_deg")?,
            sighting_sigma_m: get(s.sigma_m, "sighting.sigma_m")?,
            gate_probability: Some(get(s.gate_probability, "sighting.gate_probability")?)
                .filter(|p| *p != 0.0),
            update_period_s: get(f.update_period_s, "filter.update_period_s")?,
            phi_subintervals: f
                .phi_subintervals
                .ok_or_else(|| missing("filter.phi_subintervals"))?,
            feedback_from_s: get(f.feedback_from_s, "filter.feedback_from_s")?,
            akf_window: f.akf_window.ok_or_else(|| missing("filter.akf_window"))?,
            align_max_accel_spread_mps2: a
                .max_accel_spread_mps2
                .unwrap_or(defaults.max_accel_spread_mps2),
            align_max_gyro_spread_deg_per_s: a
                .max_gyro_spread_deg_per_s
                .unwrap_or(defaults.max_gyro_spread_deg_per_s),
            align_max_speed_mps: a.max_speed_mps.unwrap_or(defaults.max_speed_mps),
        };
        let bad = |key: &str, requirement: &str, value: String| {
            toml_err(
                path,
                doc.error_at(key, format!("`{key}` = {value}: {requirement}")),
            )
        };
        for (key, v, strictly) in [
            (
                "imu.gyro_arw_deg_per_rt_h",
                out.gyro_arw_deg_per_rt_h,
                false,
            ),
            (
                "imu.accel_vrw_mps_per_rt_h",
                out.accel_vrw_mps_per_rt_h,
                false,
            ),
            (
                "imu.gyro_bias_instability_deg_per_h",
                out.gyro_bias_instability_deg_per_h,
                false,
            ),
            ("imu.gyro_bias_corr_time_s", out.gyro_bias_corr_time_s, true),
            (
                "imu.accel_bias_instability_mg",
                out.accel_bias_instability_mg,
                false,
            ),
            (
                "imu.accel_bias_corr_time_s",
                out.accel_bias_corr_time_s,
                true,
            ),
            (
                "imu.gyro_bias_initial_sigma_deg_per_h",
                out.gyro_bias_initial_sigma_deg_per_h,
                true,
            ),
            (
                "imu.accel_bias_initial_sigma_mg",
                out.accel_bias_initial_sigma_mg,
                true,
            ),
            ("initial.pos_sigma_m", out.pos_sigma_m, true),
            ("initial.vel_sigma_mps", out.vel_sigma_mps, true),
            ("initial.att_sigma_deg", out.att_sigma_deg, true),
            ("sighting.sigma_m", out.sighting_sigma_m, true),
            ("filter.update_period_s", out.update_period_s, true),
            ("filter.feedback_from_s", out.feedback_from_s, false),
            (
                "align.max_accel_spread_mps2",
                out.align_max_accel_spread_mps2,
                true,
            ),
            (
                "align.max_gyro_spread_deg_per_s",
                out.align_max_gyro_spread_deg_per_s,
                true,
            ),
            ("align.max_speed_mps", out.align_max_speed_mps, true),
        ] {
            let ok = v.is_finite() && if strictly { v > 0.0 } else { v >= 0.0 };
            if !ok {
                let req = if strictly {
                    "must be finite and > 0"
                } else {
                    "must be finite and >= 0"
                };
                return Err(bad(key, req, format!("{v}")));
            }
        }
        if let Some(p) = out.gate_probability
            && !gate_in_range(p)
        {
            return Err(bad(
                "sighting.gate_probability",
                "must be within (0, 1), or 0 for no gate",
                format!("{p}"),
            ));
        }
        if out.phi_subintervals == 0 {
            return Err(bad("filter.phi_subintervals", "must be >= 1", "0".into()));
        }
        if out.akf_window < 2 || out.akf_window > akf::DEFAULT_WINDOW_CAPACITY {
            return Err(bad(
                "filter.akf_window",
                "must be within 2..=the adaptive filter's window capacity",
                format!("{}", out.akf_window),
            ));
        }
        Ok(out)
    }

    /// These settings with the gate probability replaced (`nav-app ins --gate P`; 0 = no gate),
    /// so that [`FilterFile::to_toml`] prints the settings in force.
    ///
    /// # Errors
    /// [`SimError::ScenarioInvalid`] (field `gate`) for a probability outside (0, 1) other than 0.
    pub fn with_gate(self, gate_probability: f64) -> Result<Self, SimError> {
        if gate_probability != 0.0 && !gate_in_range(gate_probability) {
            return Err(SimError::invalid(
                "gate",
                "must be within (0, 1), or 0 for no gate",
                gate_probability,
            ));
        }
        Ok(Self {
            gate_probability: (gate_probability != 0.0).then_some(gate_probability),
            ..self
        })
    }

    /// The rest check of `--align-s` (section `[align]`).
    pub fn align_limits(&self) -> crate::logs::AlignLimits {
        crate::logs::AlignLimits {
            max_accel_spread_mps2: self.align_max_accel_spread_mps2,
            max_gyro_spread_deg_per_s: self.align_max_gyro_spread_deg_per_s,
            max_speed_mps: self.align_max_speed_mps,
        }
    }

    /// The continuous densities (module documentation).
    pub fn process_noise(&self) -> ProcessNoisePsd {
        let gm = |b: f64, tau: f64| 2.0 * b * b / tau;
        ProcessNoisePsd {
            accel_white_m2ps3: (self.accel_vrw_mps_per_rt_h / 60.0).powi(2),
            gyro_white_rad2ps: (self.gyro_arw_deg_per_rt_h.to_radians() / 60.0).powi(2),
            accel_bias_rw_m2ps5: gm(
                self.accel_bias_instability_mg * MG_TO_MPS2,
                self.accel_bias_corr_time_s,
            ),
            gyro_drift_rw_rad2ps3: gm(
                self.gyro_bias_instability_deg_per_h * DEGPH_TO_RADPS,
                self.gyro_bias_corr_time_s,
            ),
        }
    }

    /// The online filter's configuration for `mode` on an IMU of nominal step `imu_step_s`
    /// whose replay starts at `t0_s` (feedback from `t0_s + feedback_from_s`). Time stamps are
    /// used as logged (no snapping to the nominal step). `Mode::Standalone` gives a Kalman
    /// filter that is never updated (the free INS with its growing σ).
    ///
    /// # Errors
    /// [`SimError::FilterFileConfig`] when the result is refused by
    /// [`InsSdFilterConfig::validate`] (e.g. an update period shorter than the IMU step).
    pub fn filter_config(
        &self,
        mode: Mode,
        imu_step_s: f64,
        t0_s: f64,
    ) -> Result<InsSdFilterConfig, SimError> {
        let paper = ScenarioFilterConfig::paper();
        let ms = |projection| {
            ErrorStateEstimator::MohamedSchwarz(AdaptiveQConfig {
                window: self.akf_window,
                projection,
                min_variance: paper.akf_min_variance,
            })
        };
        let estimator = match mode {
            Mode::Standalone | Mode::Kf => ErrorStateEstimator::Kalman,
            Mode::Akf => ms(paper.akf_projection),
            Mode::AkfSageHusa => ErrorStateEstimator::SageHusa(SageHusaConfig {
                forgetting: paper.sage_husa_forgetting,
                warmup: self.akf_window,
                projection: paper.akf_projection,
                min_variance: paper.akf_min_variance,
            }),
            Mode::AkfStructured => ms(akf::QProjection::Structured),
        };
        let subintervals = {
            let steps = ((self.update_period_s / imu_step_s).round() as usize).max(1);
            self.phi_subintervals.min(steps)
        };
        let config = InsSdFilterConfig {
            imu_step_s,
            timestamp_tolerance_s: 0.0,
            update_period_s: self.update_period_s.max(imu_step_s),
            phi_subintervals: subintervals,
            p0_sigma: ErrorSigmas {
                pos_m: self.pos_sigma_m,
                vel_mps: self.vel_sigma_mps,
                psi_rad: self.att_sigma_deg.to_radians(),
                accel_bias_mps2: self.accel_bias_initial_sigma_mg * MG_TO_MPS2,
                gyro_drift_radps: self.gyro_bias_initial_sigma_deg_per_h * DEGPH_TO_RADPS,
            },
            process_noise: self.process_noise(),
            r_var_m2: self.sighting_sigma_m.powi(2),
            open_loop_until_s: t0_s + self.feedback_from_s,
            gate_probability: self.gate_probability,
            estimator,
            jacobian: MeasurementJacobian::Verified,
        };
        config
            .validate()
            .map_err(|source| SimError::FilterFileConfig { source })?;
        Ok(config)
    }
}
