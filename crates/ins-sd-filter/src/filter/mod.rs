//! The online INS/SD filter object.

use akf::{AdaptiveQ, KalmanFilter, QProjection, SageHusaQ};
use ins_errors::error_model::Mat15;
use ins_errors::strapdown::{NavState, Strapdown};
use nalgebra::{Rotation3, SVector, Vector3};
use sighting_model::{LosFrame, NavPose};

use crate::FilterError;
use crate::config::{ErrorStateEstimator, InsSdFilterConfig};
use crate::interval::IntervalModel;
use crate::landmarks::LandmarkTable;

mod accessors;
mod update;

/// The 15-element error state (δp, δv, ψ, ∇, ε).
pub type Vec15 = SVector<f64, 15>;

/// Landmarks stacked into one batch measurement update; an epoch with more accepted sightings
/// is processed in batches of this size one after another (equivalent for independent noise).
pub const MAX_BATCH: usize = 8;

/// Feedback happens at epochs `t ≥ open_loop_until_s − FEEDBACK_TIME_TOL_S`.
const FEEDBACK_TIME_TOL_S: f64 = 1e-9;

/// Largest mean specific force an IMU sample may carry, m/s² (≈ 200 g, beyond the range of any
/// navigation accelerometer): a larger one is a corrupt record, refused with
/// [`FilterError::ImplausibleImu`].
pub const MAX_SPECIFIC_FORCE_MPS2: f64 = 2000.0;
/// Largest mean angular rate an IMU sample may carry, rad/s (≈ 5700 °/s).
pub const MAX_ANGULAR_RATE_RADPS: f64 = 100.0;

/// One landmark sighting: the landmark's offset from the image centre when the camera is
/// pointed at it with the filter's [`InsSdFilter::pointing_pose`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sighting {
    /// Id in the [`LandmarkTable`].
    pub landmark_id: u32,
    /// Offset along the image's horizontal axis (right), m at the landmark.
    pub w_m: f64,
    /// Offset along the image's vertical axis (down), m at the landmark.
    pub h_m: f64,
}

/// One sighting that carries its pointing: the direction in which the device saw the landmark,
/// resolved in body or local-level axes (`sighting_model::pointed`). Any filter predicts it from
/// its own state ([`InsSdFilter::update_pointed`]), whoever recorded it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointedSighting {
    /// Id in the [`LandmarkTable`].
    pub landmark_id: u32,
    /// The frame `los` is resolved in.
    pub frame: LosFrame,
    /// Measured line of sight to the landmark (any length > 0).
    pub los: Vector3<f64>,
}

/// What one [`InsSdFilter::update`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct UpdateReport {
    /// Sightings used in the update.
    pub used: usize,
    /// Sightings rejected by the χ² gate.
    pub rejected: usize,
    /// νᵀ S⁻¹ ν of the used sightings (sum over batches), `None` when none was used or there is
    /// no estimator. χ²(2·used) for a consistent filter.
    pub nis: Option<f64>,
    /// True when the prediction used the adaptive Q̂ (not the a-priori Q).
    pub adaptive_q: bool,
    /// True when the estimate was fed back into the INS at this epoch.
    pub fed_back: bool,
}

/// Running totals since construction.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FilterStatistics {
    /// IMU samples propagated.
    pub imu_samples: u64,
    /// Sighting epochs with at least one sighting.
    pub epochs: u64,
    /// Sightings used.
    pub sightings_used: u64,
    /// Sightings rejected by the gate.
    pub sightings_rejected: u64,
    /// Predictions made with the adaptive Q̂.
    pub adaptive_q_used: u64,
}

/// The adaptive part of the estimator (it lives inside the boxed [`Est`], so the variants'
/// size difference costs nothing).
#[derive(Clone, Debug)]
#[allow(clippy::large_enum_variant)]
enum Adaptive {
    None,
    MohamedSchwarz(AdaptiveQ<15>),
    SageHusa(SageHusaQ<15>),
}

/// KF + adaptive estimator + what the Q̂ estimate needs between pushes.
#[derive(Clone, Debug)]
struct Est {
    kf: KalmanFilter<15>,
    adaptive: Adaptive,
    /// P⁺ at the last estimator push (P₀ at first).
    p_post_prev: Mat15,
    /// Φ accumulated since the last push (None = identity).
    phi_since_push: Option<Mat15>,
    /// Structured projection: the fitted noise densities (and Σ q̂_k B_k of the interval they
    /// were fitted on), once the estimator has an estimate.
    structured: bool,
    densities: Option<SVector<f64, 4>>,
    structured_q: Option<Mat15>,
}

impl Est {
    /// The projected estimate (structured: Σ q̂_k B_k of the last fitted interval).
    fn q_estimate(&self) -> Option<&Mat15> {
        if self.structured {
            return self.structured_q.as_ref();
        }
        match &self.adaptive {
            Adaptive::None => None,
            Adaptive::MohamedSchwarz(a) => a.estimate(),
            Adaptive::SageHusa(a) => a.estimate(),
        }
    }

    /// The raw (unprojected) estimate once the estimator offers one.
    fn raw_when_ready(&self) -> Option<&Mat15> {
        match &self.adaptive {
            Adaptive::None => None,
            Adaptive::MohamedSchwarz(a) => a.estimate().and(a.raw_estimate()),
            Adaptive::SageHusa(a) => a.estimate().and(a.raw_estimate()),
        }
    }

    /// The adaptive Q for the prediction over an interval with noise basis `basis` (`None`:
    /// use the model's): structured, Σ q̂_k B_k on this interval's basis.
    fn q_for_prediction(&self, basis: &[Mat15; 4]) -> Option<Mat15> {
        if self.structured {
            let d = self.densities?;
            let mut q = Mat15::zeros();
            for (k, b) in basis.iter().enumerate() {
                q += b * d[k];
            }
            return Some(q);
        }
        self.q_estimate().copied()
    }
}

/// Online INS/SD error-state filter (see the crate documentation for the model).
#[derive(Clone, Debug)]
pub struct InsSdFilter {
    config: InsSdFilterConfig,
    landmarks: LandmarkTable,
    ins: Strapdown,
    interval: IntervalModel,
    est: Option<Box<Est>>,
    t_s: f64,
    last_epoch_s: f64,
    gate_threshold: Option<f64>,
    stats: FilterStatistics,
    last_report: UpdateReport,
}

fn nav_finite(s: &NavState) -> bool {
    s.pos.lat_rad.is_finite()
        && s.pos.lon_rad.is_finite()
        && s.pos.alt_m.is_finite()
        && s.vel_ned_mps.iter().all(|x| x.is_finite())
        && s.att_b_to_n.coords.iter().all(|x| x.is_finite())
}

/// The camera pose of a navigation state.
pub fn nav_pose(s: &NavState) -> NavPose {
    NavPose {
        position: s.pos,
        c_b_n: Rotation3::from(s.att_b_to_n),
    }
}

impl InsSdFilter {
    /// A filter whose INS starts at `initial` at time `t0_s` (s, any time base) with the
    /// error-state covariance of `config.p0_sigma` and x̂ = 0.
    ///
    /// # Errors
    /// [`FilterError::InvalidConfig`] for a bad configuration, [`FilterError::Ins`] for a
    /// non-finite or polar initial state, [`FilterError::NonFiniteInput`] for a non-finite
    /// `t0_s`.
    pub fn new(
        config: InsSdFilterConfig,
        landmarks: LandmarkTable,
        initial: NavState,
        t0_s: f64,
    ) -> Result<Self, FilterError> {
        config.validate()?;
        if !t0_s.is_finite() {
            return Err(FilterError::NonFiniteInput {
                what: "time stamp",
                t_s: t0_s,
            });
        }
        let ins = Strapdown::new(initial, config.imu_step_s).map_err(FilterError::Ins)?;
        let mut interval = IntervalModel::new(
            config.steps_per_update(),
            config.phi_subintervals,
            config.imu_step_s,
            config.process_noise.as_array(),
        );
        let structured = config.estimator.projection() == Some(QProjection::Structured);
        if structured {
            interval.enable_noise_basis();
        }
        let est = match config.estimator {
            ErrorStateEstimator::StandAlone => None,
            ErrorStateEstimator::Kalman
            | ErrorStateEstimator::MohamedSchwarz(_)
            | ErrorStateEstimator::SageHusa(_) => {
                let mut p0 = Mat15::zeros();
                for (b, v) in config.p0_sigma.variances().iter().enumerate() {
                    for i in 0..3 {
                        p0[(3 * b + i, 3 * b + i)] = *v;
                    }
                }
                let kf = KalmanFilter::new(Vec15::zeros(), p0)
                    .map_err(|source| FilterError::Akf { t_s: t0_s, source })?;
                let ae = |source| FilterError::Akf { t_s: t0_s, source };
                let adaptive = match config.estimator {
                    ErrorStateEstimator::MohamedSchwarz(c) => {
                        Adaptive::MohamedSchwarz(AdaptiveQ::new(c).map_err(ae)?)
                    }
                    ErrorStateEstimator::SageHusa(c) => {
                        Adaptive::SageHusa(SageHusaQ::new(c).map_err(ae)?)
                    }
                    _ => Adaptive::None,
                };
                Some(Box::new(Est {
                    kf,
                    adaptive,
                    p_post_prev: p0,
                    phi_since_push: None,
                    structured,
                    densities: None,
                    structured_q: None,
                }))
            }
        };
        Ok(Self {
            gate_threshold: config.gate_threshold(),
            config,
            landmarks,
            ins,
            interval,
            est,
            t_s: t0_s,
            last_epoch_s: f64::NEG_INFINITY,
            stats: FilterStatistics::default(),
            last_report: UpdateReport::default(),
        })
    }

    /// Propagates with one IMU sample of integrated increments over (previous time, `t_s`]:
    /// Δv (body, m/s; ∫ f̃_b dt) and Δθ (body, rad; ∫ ω̃_ib dt). Mechanised as the mean rates
    /// Δv/Δt, Δθ/Δt over Δt.
    ///
    /// # Errors
    /// [`FilterError::OutOfOrder`] if `t_s` is not after the previous sample,
    /// [`FilterError::NonFiniteInput`] for NaN/∞ input, [`FilterError::ImuGap`] for a sample more
    /// than one update interval after the previous one, [`FilterError::ImplausibleImu`] for a
    /// mean specific force above [`MAX_SPECIFIC_FORCE_MPS2`] or rate above
    /// [`MAX_ANGULAR_RATE_RADPS`] (filter unchanged);
    /// [`FilterError::NonFiniteState`] if the navigation solution overflowed.
    pub fn propagate(
        &mut self,
        t_s: f64,
        delta_v_body_mps: &Vector3<f64>,
        delta_theta_body_rad: &Vector3<f64>,
    ) -> Result<(), FilterError> {
        let dt = self.check_imu(t_s, delta_v_body_mps, delta_theta_body_rad, true)?;
        self.advance(
            t_s,
            dt,
            &(delta_v_body_mps / dt),
            &(delta_theta_body_rad / dt),
        )
    }

    /// As [`InsSdFilter::propagate`] with the sample given as mean rates over the interval:
    /// specific force f̃_b (body, m/s²) and angular rate ω̃_ib (body, rad/s).
    ///
    /// # Errors
    /// As [`InsSdFilter::propagate`].
    pub fn propagate_rates(
        &mut self,
        t_s: f64,
        specific_force_body_mps2: &Vector3<f64>,
        ang_rate_ib_body_radps: &Vector3<f64>,
    ) -> Result<(), FilterError> {
        let dt = self.check_imu(t_s, specific_force_body_mps2, ang_rate_ib_body_radps, false)?;
        self.advance(t_s, dt, specific_force_body_mps2, ang_rate_ib_body_radps)
    }

    /// Checks an IMU sample; returns the step to mechanise (the nominal step within the
    /// time-stamp tolerance).
    fn check_imu(
        &self,
        t_s: f64,
        a: &Vector3<f64>,
        b: &Vector3<f64>,
        increments: bool,
    ) -> Result<f64, FilterError> {
        if !t_s.is_finite() {
            return Err(FilterError::NonFiniteInput {
                what: "time stamp",
                t_s,
            });
        }
        if t_s <= self.t_s {
            return Err(FilterError::OutOfOrder {
                what: "IMU sample",
                t_s,
                previous_s: self.t_s,
            });
        }
        if !a.iter().all(|x| x.is_finite()) {
            return Err(FilterError::NonFiniteInput {
                what: "specific force / delta_v",
                t_s,
            });
        }
        if !b.iter().all(|x| x.is_finite()) {
            return Err(FilterError::NonFiniteInput {
                what: "angular rate / delta_theta",
                t_s,
            });
        }
        let dt = t_s - self.t_s;
        // A gap longer than one update interval is missing IMU data the strapdown cannot bridge
        // (and the interval model is built on at most one interval of samples).
        if dt > self.config.update_period_s + self.config.timestamp_tolerance_s {
            return Err(FilterError::ImuGap {
                t_s,
                previous_s: self.t_s,
                max_s: self.config.update_period_s,
            });
        }
        let step = self.config.imu_step_s;
        let per = if increments { dt } else { 1.0 };
        let (f_norm, w_norm) = (a.norm() / per, b.norm() / per);
        if f_norm > MAX_SPECIFIC_FORCE_MPS2 || w_norm > MAX_ANGULAR_RATE_RADPS {
            return Err(FilterError::ImplausibleImu {
                t_s,
                specific_force_mps2: f_norm,
                angular_rate_radps: w_norm,
            });
        }
        Ok(if (dt - step).abs() <= self.config.timestamp_tolerance_s {
            step
        } else {
            dt
        })
    }

    #[inline]
    fn advance(
        &mut self,
        t_s: f64,
        dt: f64,
        f: &Vector3<f64>,
        w: &Vector3<f64>,
    ) -> Result<(), FilterError> {
        self.ins.step_with_dt(f, w, dt);
        self.t_s = t_s;
        self.stats.imu_samples += 1;
        if !nav_finite(self.ins.state()) {
            return Err(FilterError::NonFiniteState {
                what: "INS navigation state",
                t_s,
            });
        }
        if self.est.is_some() {
            self.interval.push_dt(&self.ins.linearization_point(), dt);
        }
        Ok(())
    }

    /// Replaces the INS's sensor corrections (accelerometer bias, body m/s², and gyro bias,
    /// body rad/s, subtracted from every IMU sample): e.g. biases measured during a static
    /// alignment before the replay. The filter's bias states keep estimating what is left.
    ///
    /// # Errors
    /// [`FilterError::NonFiniteInput`] for a NaN/∞ component (nothing changes).
    pub fn set_sensor_corrections(
        &mut self,
        accel_bias_body_mps2: &Vector3<f64>,
        gyro_bias_body_radps: &Vector3<f64>,
    ) -> Result<(), FilterError> {
        if !(accel_bias_body_mps2.iter().all(|v| v.is_finite())
            && gyro_bias_body_radps.iter().all(|v| v.is_finite()))
        {
            return Err(FilterError::NonFiniteInput {
                what: "sensor corrections",
                t_s: self.t_s,
            });
        }
        self.ins
            .set_sensor_corrections(accel_bias_body_mps2, gyro_bias_body_radps);
        Ok(())
    }

    /// Feedback now: the estimated δp, δv, ψ are removed from the INS, ∇̂, ε̂ added to its
    /// sensor corrections, x̂ ← 0 (P kept). Done automatically by [`InsSdFilter::update`] at
    /// epochs at or after `open_loop_until_s`.
    pub fn feedback(&mut self) {
        let Some(est) = self.est.as_deref_mut() else {
            return;
        };
        let x = *est.kf.state();
        let v = |i: usize| Vector3::new(x[i], x[i + 1], x[i + 2]);
        self.ins.apply_correction(&v(0), &v(3), &v(6));
        self.ins.add_sensor_corrections(&v(9), &v(12));
        est.kf.reset_error_state();
    }
}
