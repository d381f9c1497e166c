//! The simulated world's departures from the filter's model (`[mismatch]`): IMU scale factor,
//! axis misalignment and Gauss–Markov bias instability; angular sighting noise, landmark survey
//! error, outliers, field of regard / maximum range, latency. Its random draws come from ChaCha
//! stream 2 of the run seed, so the IMU (stream 0) and sighting (stream 1) noise of a run are
//! those of the matched run.

use ins_errors::earth::{geodetic_to_ecef, ned_from_ecef};
use ins_errors::imu::{DEGPH_TO_RADPS, MG_TO_MPS2};
use ins_errors::strapdown::NavState;
use nalgebra::{Matrix3, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;
use sighting_model::Landmark;

use super::config::MismatchConfig;

/// One run's draw of the mismatch and its running state.
#[derive(Clone, Debug)]
pub(crate) struct World {
    cfg: MismatchConfig,
    rng: ChaCha8Rng,
    t_accel: Matrix3<f64>,
    t_gyro: Matrix3<f64>,
    gm_accel_mps2: Vector3<f64>,
    gm_gyro_radps: Vector3<f64>,
    gm_phi: f64,
    gm_q_accel: f64,
    gm_q_gyro: f64,
    /// Where the landmarks really are (ECEF m), per landmark in table order.
    pub(crate) actual_ecef_m: Vec<Vector3<f64>>,
    /// Latency in IMU steps.
    pub(crate) latency_steps: usize,
}

fn n(rng: &mut ChaCha8Rng) -> f64 {
    rng.sample(StandardNormal)
}

impl World {
    pub(crate) fn new(
        cfg: &MismatchConfig,
        seed: u64,
        landmarks: &[Landmark],
        step_s: f64,
    ) -> Self {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        rng.set_stream(2);
        let t = |sf_ppm: f64, mis_mrad: f64, rng: &mut ChaCha8Rng| {
            let mut m = Matrix3::identity();
            for i in 0..3 {
                m[(i, i)] += sf_ppm * 1e-6 * n(rng);
            }
            for i in 0..3 {
                for j in 0..3 {
                    if i != j {
                        m[(i, j)] = mis_mrad * 1e-3 * n(rng);
                    }
                }
            }
            m
        };
        let t_accel = t(
            cfg.accel_scale_factor_sigma_ppm,
            cfg.accel_misalignment_sigma_mrad,
            &mut rng,
        );
        let t_gyro = t(
            cfg.gyro_scale_factor_sigma_ppm,
            cfg.gyro_misalignment_sigma_mrad,
            &mut rng,
        );
        let sa = cfg.accel_bias_instability_sigma_mg * MG_TO_MPS2;
        let sg = cfg.gyro_bias_instability_sigma_degph * DEGPH_TO_RADPS;
        let gm_accel_mps2 = Vector3::from_fn(|_, _| sa * n(&mut rng));
        let gm_gyro_radps = Vector3::from_fn(|_, _| sg * n(&mut rng));
        let gm_phi = (-step_s / cfg.bias_correlation_time_s).exp();
        let k = (1.0 - gm_phi * gm_phi).sqrt();
        let actual_ecef_m = landmarks
            .iter()
            .map(|l| {
                let d_ned = Vector3::from_fn(|_, _| cfg.landmark_survey_sigma_m * n(&mut rng));
                let p = l.position();
                l.ecef_m() + ned_from_ecef(p.lat_rad, p.lon_rad).transpose() * d_ned
            })
            .collect();
        Self {
            cfg: cfg.clone(),
            rng,
            t_accel,
            t_gyro,
            gm_accel_mps2,
            gm_gyro_radps,
            gm_phi,
            gm_q_accel: sa * k,
            gm_q_gyro: sg * k,
            actual_ecef_m,
            latency_steps: (cfg.latency_s / step_s).round() as usize,
        }
    }

    /// The ideal sample as the sensor sees it before its constant bias and white noise:
    /// (I + S + M) f + b_GM; then the Gauss–Markov states step on.
    #[inline]
    pub(crate) fn corrupt(
        &mut self,
        f: &Vector3<f64>,
        w: &Vector3<f64>,
    ) -> (Vector3<f64>, Vector3<f64>) {
        let f2 = self.t_accel * f + self.gm_accel_mps2;
        let w2 = self.t_gyro * w + self.gm_gyro_radps;
        if self.gm_q_accel > 0.0 || self.gm_q_gyro > 0.0 {
            for i in 0..3 {
                self.gm_accel_mps2[i] =
                    self.gm_phi * self.gm_accel_mps2[i] + self.gm_q_accel * n(&mut self.rng);
                self.gm_gyro_radps[i] =
                    self.gm_phi * self.gm_gyro_radps[i] + self.gm_q_gyro * n(&mut self.rng);
            }
        }
        (f2, w2)
    }

    /// Whether landmark `i` is in the camera's field of regard and range from the true pose,
    /// and its slant range (m).
    pub(crate) fn visible(&self, i: usize, truth: &NavState) -> (bool, f64) {
        let x = geodetic_to_ecef(&truth.pos);
        let los_ned =
            ned_from_ecef(truth.pos.lat_rad, truth.pos.lon_rad) * (self.actual_ecef_m[i] - x);
        let range = los_ned.norm();
        let los_body = truth.att_b_to_n.inverse() * los_ned;
        let off_nadir_deg = (los_body.z / range).clamp(-1.0, 1.0).acos().to_degrees();
        let in_range = self.cfg.max_range_m == 0.0 || range <= self.cfg.max_range_m;
        (
            in_range && off_nadir_deg <= self.cfg.camera_max_off_nadir_deg,
            range,
        )
    }

    /// The extra sighting error of one landmark at `range_m`: angular noise and, with
    /// probability `outlier_fraction`, a gross error (always five draws, so the stream does not
    /// depend on visibility).
    pub(crate) fn sighting_error(&mut self, range_m: f64) -> (f64, f64) {
        let a = self.cfg.sighting_noise_mrad * 1e-3 * range_m;
        let (aw, ah) = (n(&mut self.rng), n(&mut self.rng));
        let u: f64 = self.rng.random();
        let (ow, oh) = (n(&mut self.rng), n(&mut self.rng));
        let gross = if u < self.cfg.outlier_fraction {
            self.cfg.outlier_sigma_m
        } else {
            0.0
        };
        (a * aw + gross * ow, a * ah + gross * oh)
    }
}
