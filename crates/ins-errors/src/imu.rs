//! Inertial sensor error model: per-run random constants plus per-sample white noise.
//!
//! Measurement model (body axes, per sample k of period T_s):
//!
//! ```text
//! f̃_b[k] = f_b[k] + ∇ + w_a[k],   w_a[k] ~ N(0, σ_a² I)   (σ_a = per-sample σ, m/s²)
//! ω̃_ib[k] = ω_ib[k] + ε + w_g[k], w_g[k] ~ N(0, σ_g² I)   (σ_g = per-sample σ, rad/s)
//! ```
//!
//! ∇ and ε are random constants drawn once per run ([`crate::config::BiasModel`]). The noise
//! figures are per-sample σ (the paper's "σ²_acc = 1 mg²", "σ²_gyro = 1 (°/h)²" read as the
//! variance of each 100 Hz sample). For the continuous-time error model the equivalent white
//! noise has one-sided power spectral density q = σ²·T_s (so that the mean of the continuous
//! noise over one sample has variance q/T_s = σ²): accelerometer q_a = (9.80665e-3)²·0.01 ≈
//! 9.6·10⁻⁷ (m/s²)²/Hz (velocity random walk ≈ 9.8·10⁻⁴ m/s/√s), gyro q_g = (4.848e-6)²·0.01 ≈
//! 2.35·10⁻¹³ rad²/s (angle random walk ≈ 4.8·10⁻⁷ rad/√s). See [`ImuErrors::noise_psd`].

use nalgebra::Vector3;
use rand::Rng;
use rand_distr::StandardNormal;

use crate::config::{BiasModel, ImuConfig};
use crate::error::InsError;

/// Standard gravity used to convert mg to m/s², m/s².
pub const STANDARD_GRAVITY_MPS2: f64 = 9.806_65;
/// 1 mg in m/s².
pub const MG_TO_MPS2: f64 = STANDARD_GRAVITY_MPS2 * 1e-3;
/// 1 °/h in rad/s.
pub const DEGPH_TO_RADPS: f64 = std::f64::consts::PI / 180.0 / 3600.0;

/// The sensor error parameters in SI units (from [`ImuConfig`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImuErrorParams {
    /// σ of the random-constant accelerometer bias per axis, m/s².
    pub accel_bias_sigma_mps2: f64,
    /// σ of the random-constant gyro drift per axis, rad/s.
    pub gyro_drift_sigma_radps: f64,
    /// Per-sample σ of the accelerometer white noise, m/s².
    pub accel_noise_sigma_per_sample_mps2: f64,
    /// Per-sample σ of the gyro white noise, rad/s.
    pub gyro_noise_sigma_per_sample_radps: f64,
    /// How the random constants are drawn.
    pub bias_model: BiasModel,
}

impl ImuErrorParams {
    /// Converts a validated [`ImuConfig`] (mg, °/h, variances) to SI σ values.
    pub fn from_config(c: &ImuConfig) -> Result<Self, InsError> {
        c.validate()?;
        Ok(Self {
            accel_bias_sigma_mps2: c.accel_bias_sigma_mg * MG_TO_MPS2,
            gyro_drift_sigma_radps: c.gyro_drift_sigma_degph * DEGPH_TO_RADPS,
            accel_noise_sigma_per_sample_mps2: c.accel_noise_var_per_sample_mg2.sqrt() * MG_TO_MPS2,
            gyro_noise_sigma_per_sample_radps: c.gyro_noise_var_per_sample_degph2.sqrt()
                * DEGPH_TO_RADPS,
            bias_model: c.bias_model,
        })
    }
}

/// One run's sensor errors: the drawn random constants and the noise σ.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImuErrors {
    /// Accelerometer bias ∇, body axes, m/s².
    pub accel_bias_body_mps2: Vector3<f64>,
    /// Gyro drift ε, body axes, rad/s.
    pub gyro_drift_body_radps: Vector3<f64>,
    /// Per-sample σ of the accelerometer white noise, m/s².
    pub accel_noise_sigma_per_sample_mps2: f64,
    /// Per-sample σ of the gyro white noise, rad/s.
    pub gyro_noise_sigma_per_sample_radps: f64,
}

impl ImuErrors {
    /// Error-free sensors.
    pub fn perfect() -> Self {
        Self {
            accel_bias_body_mps2: Vector3::zeros(),
            gyro_drift_body_radps: Vector3::zeros(),
            accel_noise_sigma_per_sample_mps2: 0.0,
            gyro_noise_sigma_per_sample_radps: 0.0,
        }
    }

    /// Draws the per-run random constants from `rng` (seeded by the caller).
    pub fn draw<R: Rng + ?Sized>(p: &ImuErrorParams, rng: &mut R) -> Self {
        let mut draw3 = |sigma: f64| -> Vector3<f64> {
            Vector3::from_fn(|_, _| match p.bias_model {
                BiasModel::GaussianRandomConstant => sigma * rng.sample::<f64, _>(StandardNormal),
                BiasModel::FixedMagnitudeRandomSign => {
                    if rng.random::<bool>() {
                        sigma
                    } else {
                        -sigma
                    }
                }
            })
        };
        let accel_bias_body_mps2 = draw3(p.accel_bias_sigma_mps2);
        let gyro_drift_body_radps = draw3(p.gyro_drift_sigma_radps);
        Self {
            accel_bias_body_mps2,
            gyro_drift_body_radps,
            accel_noise_sigma_per_sample_mps2: p.accel_noise_sigma_per_sample_mps2,
            gyro_noise_sigma_per_sample_radps: p.gyro_noise_sigma_per_sample_radps,
        }
    }

    /// Corrupts one ideal sample: returns (f̃_b m/s², ω̃_ib^b rad/s). No allocation.
    #[inline]
    pub fn measure<R: Rng + ?Sized>(
        &self,
        specific_force_body_mps2: &Vector3<f64>,
        ang_rate_ib_body_radps: &Vector3<f64>,
        rng: &mut R,
    ) -> (Vector3<f64>, Vector3<f64>) {
        let mut f = specific_force_body_mps2 + self.accel_bias_body_mps2;
        let mut w = ang_rate_ib_body_radps + self.gyro_drift_body_radps;
        if self.accel_noise_sigma_per_sample_mps2 > 0.0 {
            for i in 0..3 {
                f[i] +=
                    self.accel_noise_sigma_per_sample_mps2 * rng.sample::<f64, _>(StandardNormal);
            }
        }
        if self.gyro_noise_sigma_per_sample_radps > 0.0 {
            for i in 0..3 {
                w[i] +=
                    self.gyro_noise_sigma_per_sample_radps * rng.sample::<f64, _>(StandardNormal);
            }
        }
        (f, w)
    }

    /// Equivalent continuous white-noise one-sided PSDs for a sample period `step_s`:
    /// (accelerometer (m/s²)²/Hz = (m/s)²/s, gyro rad²/s), q = σ²·T_s.
    pub fn noise_psd(&self, step_s: f64) -> (f64, f64) {
        (
            self.accel_noise_sigma_per_sample_mps2.powi(2) * step_s,
            self.gyro_noise_sigma_per_sample_radps.powi(2) * step_s,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn unit_conversions() {
        let p = ImuErrorParams::from_config(&ImuConfig::paper()).unwrap();
        assert!((p.accel_bias_sigma_mps2 - 0.029_419_95).abs() < 1e-9);
        assert!((p.gyro_drift_sigma_radps - 9.696_273_6e-6).abs() < 1e-12);
        assert!((p.accel_noise_sigma_per_sample_mps2 - 9.806_65e-3).abs() < 1e-12);
        assert!((p.gyro_noise_sigma_per_sample_radps - 4.848_136_8e-6).abs() < 1e-12);
    }

    #[test]
    fn bias_and_noise_statistics_match_config() {
        let p = ImuErrorParams::from_config(&ImuConfig::paper()).unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        // Random constants over many runs: sample σ within 5 % of the configured σ.
        let n = 4000;
        let (mut sa, mut sg) = (0.0, 0.0);
        for _ in 0..n {
            let e = ImuErrors::draw(&p, &mut rng);
            sa += e.accel_bias_body_mps2.norm_squared();
            sg += e.gyro_drift_body_radps.norm_squared();
        }
        let sa = (sa / (3 * n) as f64).sqrt();
        let sg = (sg / (3 * n) as f64).sqrt();
        assert!((sa / p.accel_bias_sigma_mps2 - 1.0).abs() < 0.05, "{sa}");
        assert!((sg / p.gyro_drift_sigma_radps - 1.0).abs() < 0.05, "{sg}");
        // White noise: per-sample σ and mean = bias.
        let e = ImuErrors::draw(&p, &mut rng);
        let (mut m, mut s2) = (Vector3::zeros(), 0.0);
        let k = 20_000;
        for _ in 0..k {
            let (f, _) = e.measure(&Vector3::zeros(), &Vector3::zeros(), &mut rng);
            m += f;
            s2 += (f - e.accel_bias_body_mps2).norm_squared();
        }
        m /= k as f64;
        let s = (s2 / (3 * k) as f64).sqrt();
        assert!(
            (s / p.accel_noise_sigma_per_sample_mps2 - 1.0).abs() < 0.02,
            "{s}"
        );
        assert!((m - e.accel_bias_body_mps2).norm() < 5.0 * 9.8e-3 / (k as f64).sqrt() * 1.8);
    }

    #[test]
    fn fixed_magnitude_mode_has_exact_magnitude() {
        let mut c = ImuConfig::paper();
        c.bias_model = BiasModel::FixedMagnitudeRandomSign;
        let p = ImuErrorParams::from_config(&c).unwrap();
        let e = ImuErrors::draw(&p, &mut ChaCha8Rng::seed_from_u64(1));
        for i in 0..3 {
            assert!((e.accel_bias_body_mps2[i].abs() - 3.0 * MG_TO_MPS2).abs() < 1e-15);
            assert!((e.gyro_drift_body_radps[i].abs() - 2.0 * DEGPH_TO_RADPS).abs() < 1e-18);
        }
    }
}
