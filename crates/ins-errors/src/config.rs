//! Serde configuration for the `[trajectory]` and `[imu]` sections of a scenario file
//! (e.g. `configs/paper.toml`). Every field carries its unit in its name; `validate()` returns an
//! [`InsError::InvalidConfig`] naming the offending field by its dotted TOML path.
//!
//! Defaults ([`TrajectoryConfig::paper`], [`ImuConfig::paper`], also the `Default` impls)
//! reproduce the paper's §6 / Table 1 scenario with the choices documented in the crate doc.

use serde::{Deserialize, Serialize, de::DeserializeOwned};

use crate::error::InsError;

/// One constant-acceleration manoeuvre segment of the truth trajectory.
///
/// Within a segment the speed V, the heading (course) χ and the flight-path angle γ change
/// linearly: V̇ = `along_accel_mps2`, χ̇ = `turn_rate_degps`, γ̇ = `path_angle_rate_degps`.
/// Resulting accelerations: along-track V̇, lateral V·χ̇·cosγ, normal V·γ̇.
/// A segment with all three rates zero is straight, level-or-constant-slope flight.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SegmentConfig {
    /// Segment duration, s; must be > 0 and an integer multiple of `trajectory.step_s`.
    pub duration_s: f64,
    /// Along-track acceleration dV/dt, m/s².
    #[serde(default)]
    pub along_accel_mps2: f64,
    /// Heading (course) rate dχ/dt, deg/s, positive = turn right (clockwise seen from above).
    #[serde(default)]
    pub turn_rate_degps: f64,
    /// Flight-path-angle rate dγ/dt, deg/s, positive = pitching up.
    #[serde(default)]
    pub path_angle_rate_degps: f64,
}

impl SegmentConfig {
    const fn new(duration_s: f64, along: f64, turn: f64, path: f64) -> Self {
        Self {
            duration_s,
            along_accel_mps2: along,
            turn_rate_degps: turn,
            path_angle_rate_degps: path,
        }
    }
}

/// `[trajectory]` section: start state, sampling step and manoeuvre segments.
/// After the last segment the vehicle flies straight (constant velocity) until `end_time_s`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TrajectoryConfig {
    /// Start geodetic latitude, degrees (paper: −23°12′).
    pub start_lat_deg: f64,
    /// Start longitude, degrees (paper: −45°52′).
    pub start_lon_deg: f64,
    /// Start height above the WGS-84 ellipsoid, m (paper: 6000 m).
    pub start_alt_m: f64,
    /// Start ground-relative speed, m/s (paper: about 30 m/s).
    pub start_speed_mps: f64,
    /// Start heading (course over ground), degrees from north, clockwise.
    pub start_heading_deg: f64,
    /// Start flight-path angle, degrees, positive = climbing.
    pub start_path_angle_deg: f64,
    /// Sampling step of the truth/IMU and of the INS, s (paper: 0.01 s = 100 Hz).
    pub step_s: f64,
    /// Simulation end time, s (paper: 900 s); must be ≥ the sum of the segment durations.
    pub end_time_s: f64,
    /// Manoeuvre segments, flown in order from t = 0.
    pub segments: Vec<SegmentConfig>,
}

/// How the per-run random-constant sensor errors are drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum BiasModel {
    /// Each axis ~ N(0, σ²), drawn once per run (default: "3 mg" and "2 °/h" read as the σ).
    #[default]
    GaussianRandomConstant,
    /// Each axis exactly ±σ with a random sign per axis and run.
    FixedMagnitudeRandomSign,
}

/// `[imu]` section: inertial sensor error model.
///
/// Units: 1 mg = 9.80665·10⁻³ m/s²; 1 °/h = π/180/3600 rad/s. The white-noise figures are the
/// **variance of each 100 Hz sample** (per-sample σ² at `trajectory.step_s`), not a spectral
/// density; the equivalent one-sided PSD is σ²·step_s (see [`crate::imu`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ImuConfig {
    /// σ of the per-run random-constant accelerometer bias, per axis, mg (paper: 3 mg).
    pub accel_bias_sigma_mg: f64,
    /// σ of the per-run random-constant gyro drift, per axis, °/h (paper: 2 °/h).
    pub gyro_drift_sigma_degph: f64,
    /// Accelerometer white-noise variance per sample, mg² (paper: 1 mg²). 0 disables.
    pub accel_noise_var_per_sample_mg2: f64,
    /// Gyro white-noise variance per sample, (°/h)² (paper: 1 (°/h)²). 0 disables.
    pub gyro_noise_var_per_sample_degph2: f64,
    /// How the random constants are drawn.
    #[serde(default)]
    pub bias_model: BiasModel,
}

impl TrajectoryConfig {
    /// The default §6 flight: start −23°12′, −45°52′, 6000 m, 30 m/s heading 120°, fifteen
    /// 40 s manoeuvres to 600 s (|acceleration| ≤ 0.76 m/s², speed 30–36 m/s, ±1° climb and
    /// descent), straight at heading 40° to 900 s; ≈ 28.1 km flown, looping around the three
    /// landmarks of Table 1.
    pub fn paper() -> Self {
        let s = SegmentConfig::new;
        Self {
            start_lat_deg: -(23.0 + 12.0 / 60.0),
            start_lon_deg: -(45.0 + 52.0 / 60.0),
            start_alt_m: 6000.0,
            start_speed_mps: 30.0,
            start_heading_deg: 120.0,
            start_path_angle_deg: 0.0,
            step_s: 0.01,
            end_time_s: 900.0,
            segments: vec![
                s(40.0, 0.0, 0.0, 0.0),
                s(40.0, 0.0, 1.0, 0.0),
                s(40.0, 0.15, 0.0, 0.0),
                s(40.0, 0.0, 1.2, 0.0),
                s(40.0, -0.15, 0.0, 0.025),
                s(40.0, 0.0, -1.0, -0.025),
                s(40.0, 0.0, 0.0, 0.0),
                s(40.0, 0.0, 1.2, 0.0),
                s(40.0, 0.1, 0.0, 0.0),
                s(40.0, 0.0, 1.2, 0.0),
                s(40.0, 0.0, 0.0, -0.025),
                s(40.0, 0.0, 1.0, 0.025),
                s(40.0, -0.1, 0.0, 0.0),
                s(40.0, 0.0, 1.2, 0.0),
                s(40.0, 0.0, 1.2, 0.0),
            ],
        }
    }

    /// Checks every field; the error names the first offending one.
    pub fn validate(&self) -> Result<(), InsError> {
        let p = "trajectory.";
        finite_in(p, "start_lat_deg", self.start_lat_deg, -90.0, 90.0)?;
        finite(p, "start_lon_deg", self.start_lon_deg)?;
        finite_in(p, "start_alt_m", self.start_alt_m, -1.0e4, 1.0e6)?;
        finite_pos(p, "start_speed_mps", self.start_speed_mps)?;
        finite(p, "start_heading_deg", self.start_heading_deg)?;
        finite_in(
            p,
            "start_path_angle_deg",
            self.start_path_angle_deg,
            -80.0,
            80.0,
        )?;
        finite_pos(p, "step_s", self.step_s)?;
        finite_pos(p, "end_time_s", self.end_time_s)?;
        let mut t = 0.0;
        let mut v = self.start_speed_mps;
        let mut gam = self.start_path_angle_deg;
        for (i, seg) in self.segments.iter().enumerate() {
            let sp = format!("trajectory.segments[{i}].");
            finite_pos(&sp, "duration_s", seg.duration_s)?;
            let n = seg.duration_s / self.step_s;
            if (n - n.round()).abs() > 1e-6 {
                return Err(InsError::config(
                    format!("{sp}duration_s"),
                    "must be an integer multiple of trajectory.step_s",
                    seg.duration_s,
                ));
            }
            finite(&sp, "along_accel_mps2", seg.along_accel_mps2)?;
            finite(&sp, "turn_rate_degps", seg.turn_rate_degps)?;
            finite(&sp, "path_angle_rate_degps", seg.path_angle_rate_degps)?;
            t += seg.duration_s;
            v += seg.along_accel_mps2 * seg.duration_s;
            gam += seg.path_angle_rate_degps * seg.duration_s;
            if v <= 0.0 {
                return Err(InsError::config(
                    format!("{sp}along_accel_mps2"),
                    "must keep the speed > 0 at the segment end",
                    seg.along_accel_mps2,
                ));
            }
            if gam.abs() >= 80.0 {
                return Err(InsError::config(
                    format!("{sp}path_angle_rate_degps"),
                    "must keep |flight-path angle| < 80° at the segment end",
                    seg.path_angle_rate_degps,
                ));
            }
        }
        if self.end_time_s < t - 1e-9 {
            return Err(InsError::config(
                "trajectory.end_time_s",
                "must be ≥ the sum of the segment durations",
                self.end_time_s,
            ));
        }
        Ok(())
    }
}

impl Default for TrajectoryConfig {
    fn default() -> Self {
        Self::paper()
    }
}

impl ImuConfig {
    /// Table 1: 3 mg, 2 °/h random constants (as σ), 1 mg² and 1 (°/h)² per-sample variances.
    pub fn paper() -> Self {
        Self {
            accel_bias_sigma_mg: 3.0,
            gyro_drift_sigma_degph: 2.0,
            accel_noise_var_per_sample_mg2: 1.0,
            gyro_noise_var_per_sample_degph2: 1.0,
            bias_model: BiasModel::GaussianRandomConstant,
        }
    }

    /// A perfect IMU (all error sources disabled).
    pub fn perfect() -> Self {
        Self {
            accel_bias_sigma_mg: 0.0,
            gyro_drift_sigma_degph: 0.0,
            accel_noise_var_per_sample_mg2: 0.0,
            gyro_noise_var_per_sample_degph2: 0.0,
            bias_model: BiasModel::GaussianRandomConstant,
        }
    }

    /// Checks every field; the error names the first offending one.
    pub fn validate(&self) -> Result<(), InsError> {
        let p = "imu.";
        finite_nonneg(p, "accel_bias_sigma_mg", self.accel_bias_sigma_mg)?;
        finite_nonneg(p, "gyro_drift_sigma_degph", self.gyro_drift_sigma_degph)?;
        finite_nonneg(
            p,
            "accel_noise_var_per_sample_mg2",
            self.accel_noise_var_per_sample_mg2,
        )?;
        finite_nonneg(
            p,
            "gyro_noise_var_per_sample_degph2",
            self.gyro_noise_var_per_sample_degph2,
        )?;
        Ok(())
    }
}

impl Default for ImuConfig {
    fn default() -> Self {
        Self::paper()
    }
}

/// Parses section `section` (e.g. `"imu"`) of a TOML document into `T` and returns it
/// unvalidated, through the workspace's one TOML loader (crate `toml-config`). Unknown keys are
/// rejected (`deny_unknown_fields`) with the key named; the loader's error, kept as the source,
/// gives the line and column (`TOML text:12:1: unknown field …`).
pub fn parse_section<T: DeserializeOwned>(toml_text: &str, section: &str) -> Result<T, InsError> {
    let toml_err = |source| InsError::Toml {
        section: section.to_string(),
        source: Box::new(source),
    };
    toml_config::TomlDoc::parse("TOML text", toml_text)
        .map_err(toml_err)?
        .section(section)
        .map_err(toml_err)
}

fn finite(prefix: &str, name: &str, v: f64) -> Result<(), InsError> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(InsError::config(
            format!("{prefix}{name}"),
            "must be finite",
            v,
        ))
    }
}

fn finite_pos(prefix: &str, name: &str, v: f64) -> Result<(), InsError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(InsError::config(
            format!("{prefix}{name}"),
            "must be finite and > 0",
            v,
        ))
    }
}

fn finite_nonneg(prefix: &str, name: &str, v: f64) -> Result<(), InsError> {
    if v.is_finite() && v >= 0.0 {
        Ok(())
    } else {
        Err(InsError::config(
            format!("{prefix}{name}"),
            "must be finite and ≥ 0",
            v,
        ))
    }
}

fn finite_in(prefix: &str, name: &str, v: f64, lo: f64, hi: f64) -> Result<(), InsError> {
    if v.is_finite() && v >= lo && v <= hi {
        Ok(())
    } else {
        Err(InsError::InvalidConfig {
            field: format!("{prefix}{name}"),
            requirement: format!("must be finite and in [{lo}, {hi}]"),
            value: format!("{v:?}"),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_validate() {
        TrajectoryConfig::paper().validate().unwrap();
        ImuConfig::paper().validate().unwrap();
        ImuConfig::perfect().validate().unwrap();
    }

    #[test]
    fn nan_drift_names_field() {
        let mut c = ImuConfig::paper();
        c.gyro_drift_sigma_degph = f64::NAN;
        let e = c.validate().unwrap_err();
        assert_eq!(
            e.to_string(),
            "imu.gyro_drift_sigma_degph must be finite and ≥ 0, got NaN"
        );
    }

    #[test]
    fn negative_variance_names_field() {
        let mut c = ImuConfig::paper();
        c.accel_noise_var_per_sample_mg2 = -1.0;
        match c.validate().unwrap_err() {
            InsError::InvalidConfig { field, .. } => {
                assert_eq!(field, "imu.accel_noise_var_per_sample_mg2")
            }
            e => panic!("wrong error {e}"),
        }
    }

    #[test]
    fn zero_step_names_field() {
        let mut c = TrajectoryConfig::paper();
        c.step_s = 0.0;
        let e = c.validate().unwrap_err();
        assert!(
            e.to_string()
                .starts_with("trajectory.step_s must be finite and > 0"),
            "{e}"
        );
    }

    #[test]
    fn bad_segment_names_index() {
        let mut c = TrajectoryConfig::paper();
        c.segments[3].duration_s = 40.005;
        let e = c.validate().unwrap_err();
        assert!(
            e.to_string()
                .starts_with("trajectory.segments[3].duration_s"),
            "{e}"
        );
        let mut c = TrajectoryConfig::paper();
        c.segments[2].along_accel_mps2 = -1.0; // speed 30 → −10 m/s
        let e = c.validate().unwrap_err();
        assert!(
            e.to_string()
                .starts_with("trajectory.segments[2].along_accel_mps2"),
            "{e}"
        );
        let mut c = TrajectoryConfig::paper();
        c.end_time_s = 500.0;
        let e = c.validate().unwrap_err();
        assert!(e.to_string().starts_with("trajectory.end_time_s"), "{e}");
    }

    #[test]
    fn unknown_key_is_rejected_with_its_name() {
        let text = "[imu]\naccel_bias_sigma_mg = 3.0\ngyro_drift_sigma_degph = 2.0\n\
                    accel_noise_var_per_sample_mg2 = 1.0\ngyro_noise_var_per_sample_degph2 = 1.0\n\
                    gyro_noise_psd = 3.0\n";
        // The message names the section; the loader's error, its source, names the key.
        let e = parse_section::<ImuConfig>(text, "imu").unwrap_err();
        assert_eq!(e.to_string(), "TOML section [imu]");
        let InsError::Toml { source, .. } = &e else {
            panic!("{e:?}")
        };
        assert!(source.to_string().contains("gyro_noise_psd"), "{source}");
        let e = parse_section::<ImuConfig>("[trajectory]\n", "imu").unwrap_err();
        let InsError::Toml { source, .. } = &e else {
            panic!("{e:?}")
        };
        assert!(source.message.contains("section [imu] missing"), "{source}");
    }

    #[test]
    fn round_trip_through_toml() {
        let t = TrajectoryConfig::paper();
        let mut tab = toml::Table::new();
        tab.insert("trajectory".into(), toml::Value::try_from(&t).unwrap());
        let text = toml::to_string(&tab).unwrap();
        let back: TrajectoryConfig = parse_section(&text, "trajectory").unwrap();
        assert_eq!(back, t);
    }
}
