//! The settings in force printed back as a filter file (`nav-app ins --print-config`).
//!
//! Every key is written, so the printed file does not depend on the preset it names: read back
//! with [`FilterFile::from_toml_str`] it gives the same [`FilterFile`] field for field, and a
//! replay with it gives the same solution byte for byte (`nav-app`'s `tests/ins_cli.rs`).
//! Floats are written with Rust's `{:?}`: the shortest decimal that reads back to the same
//! `f64`, always with a `.` or an exponent, which TOML reads as a float (never as an integer).

use super::FilterFile;

/// A section's name and its keys: (key, value as TOML, comment with the unit).
type Section = (&'static str, Vec<(&'static str, String, &'static str)>);

/// A float as TOML: the shortest round-tripping decimal (module documentation).
fn float(v: f64) -> String {
    format!("{v:?}")
}

impl FilterFile {
    /// The settings as a filter file in TOML, every key with its unit in a comment; `origin`
    /// says where they came from (a first comment line). The gate is written 0 when there is
    /// none.
    pub fn to_toml(&self, origin: &str) -> String {
        let f = float;
        let line = |k: &str, value: &str, comment: &str| {
            format!("{:<44} # {comment}\n", format!("{k} = {value}"))
        };
        let mut out = format!(
            "# The filter settings in force ({origin}), every key written;\n\
             # give this file back with `nav-app ins --config FILE` for the same run.\n"
        );
        out += &line(
            "preset",
            &format!("\"{}\"", self.preset),
            "the base; every key below overrides it",
        );
        let sections = {
            let v: [Section; 5] = [
                (
                    "imu",
                    vec![
                        (
                            "gyro_arw_deg_per_rt_h",
                            f(self.gyro_arw_deg_per_rt_h),
                            "gyro angle random walk, °/√h",
                        ),
                        (
                            "accel_vrw_mps_per_rt_h",
                            f(self.accel_vrw_mps_per_rt_h),
                            "accelerometer velocity random walk, m/s/√h",
                        ),
                        (
                            "gyro_bias_instability_deg_per_h",
                            f(self.gyro_bias_instability_deg_per_h),
                            "gyro bias instability, °/h (0: random constant)",
                        ),
                        (
                            "gyro_bias_corr_time_s",
                            f(self.gyro_bias_corr_time_s),
                            "its correlation time, s",
                        ),
                        (
                            "accel_bias_instability_mg",
                            f(self.accel_bias_instability_mg),
                            "accelerometer bias instability, mg (0: random constant)",
                        ),
                        (
                            "accel_bias_corr_time_s",
                            f(self.accel_bias_corr_time_s),
                            "its correlation time, s",
                        ),
                        (
                            "gyro_bias_initial_sigma_deg_per_h",
                            f(self.gyro_bias_initial_sigma_deg_per_h),
                            "turn-on gyro bias, 1σ, °/h",
                        ),
                        (
                            "accel_bias_initial_sigma_mg",
                            f(self.accel_bias_initial_sigma_mg),
                            "turn-on accelerometer bias, 1σ, mg",
                        ),
                    ],
                ),
                (
                    "initial",
                    vec![
                        (
                            "pos_sigma_m",
                            f(self.pos_sigma_m),
                            "initial position error, 1σ per axis, m",
                        ),
                        (
                            "vel_sigma_mps",
                            f(self.vel_sigma_mps),
                            "initial velocity error, 1σ per axis, m/s",
                        ),
                        (
                            "att_sigma_deg",
                            f(self.att_sigma_deg),
                            "initial attitude error, 1σ per axis, °",
                        ),
                    ],
                ),
                (
                    "sighting",
                    vec![
                        (
                            "sigma_m",
                            f(self.sighting_sigma_m),
                            "σ of w and h, m at the landmark",
                        ),
                        (
                            "gate_probability",
                            f(self.gate_probability.unwrap_or(0.0)),
                            "χ² gate probability per sighting (0: no gate)",
                        ),
                    ],
                ),
                (
                    "filter",
                    vec![
                        (
                            "update_period_s",
                            f(self.update_period_s),
                            "nominal time between sighting epochs, s",
                        ),
                        (
                            "phi_subintervals",
                            self.phi_subintervals.to_string(),
                            "Φ/Q sub-intervals per update period",
                        ),
                        (
                            "feedback_from_s",
                            f(self.feedback_from_s),
                            "open loop for this long after the start, then feedback, s",
                        ),
                        (
                            "akf_window",
                            self.akf_window.to_string(),
                            "Mohamed–Schwarz window, updates",
                        ),
                    ],
                ),
                (
                    "align",
                    vec![
                        (
                            "max_accel_spread_mps2",
                            f(self.align_max_accel_spread_mps2),
                            "--align-s rest check: accelerometer 1-s means, std, m/s²",
                        ),
                        (
                            "max_gyro_spread_deg_per_s",
                            f(self.align_max_gyro_spread_deg_per_s),
                            "the same for the gyro, °/s",
                        ),
                        (
                            "max_speed_mps",
                            f(self.align_max_speed_mps),
                            "the reference's largest speed over the window, m/s",
                        ),
                    ],
                ),
            ];
            v
        };
        for (name, keys) in sections {
            out += &format!("\n[{name}]\n");
            for (k, value, comment) in keys {
                out += &line(k, &value, comment);
            }
        }
        out
    }
}
