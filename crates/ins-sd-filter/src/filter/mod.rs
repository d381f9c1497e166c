//! The online INS/SD filter object.

use akf::{AdaptiveQ, KalmanFilter, QProjection, SageHusaQ};
use ins_errors::error_model::Mat15;
use ins_errors::strapdown::{NavState, Strapdown};
use nalgebra::{Matrix2, Rotation3, SMatrix, SVector, Vector2, Vector3};
use sighting_model::{Landmark, LosFrame, NavPose, PaperAlphaReading};

use crate::FilterError;
use crate::config::{ErrorStateEstimator, InsSdFilterConfig, MeasurementJacobian};
use crate::interval::IntervalModel;
use crate::landmarks::LandmarkTable;

mod accessors;

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

/// The sightings of one epoch, as the paper's offsets or as pointed directions.
#[derive(Clone, Copy)]
enum Epoch<'a> {
    Offsets(&'a [Sighting]),
    Pointed(&'a [PointedSighting]),
}

impl Epoch<'_> {
    fn len(&self) -> usize {
        match self {
            Epoch::Offsets(s) => s.len(),
            Epoch::Pointed(s) => s.len(),
        }
    }

    /// Sighting `i` as (landmark id, offsets z, frame of H), checked.
    fn get(
        &self,
        i: usize,
        t_s: f64,
        landmarks: &LandmarkTable,
        pose: &NavPose,
    ) -> Result<(u32, Vector2<f64>, LosFrame), FilterError> {
        let id = match self {
            Epoch::Offsets(s) => s[i].landmark_id,
            Epoch::Pointed(s) => s[i].landmark_id,
        };
        let Some(lm) = landmarks.get(id) else {
            return Err(FilterError::UnknownLandmark { t_s, id });
        };
        match self {
            Epoch::Offsets(s) => {
                let s = &s[i];
                if !(s.w_m.is_finite() && s.h_m.is_finite()) {
                    return Err(FilterError::NonFiniteInput {
                        what: "sighting w/h",
                        t_s,
                    });
                }
                Ok((id, Vector2::new(s.w_m, s.h_m), LosFrame::Body))
            }
            Epoch::Pointed(s) => {
                let s = &s[i];
                if !s.los.iter().all(|v| v.is_finite()) {
                    return Err(FilterError::NonFiniteInput {
                        what: "sighting direction",
                        t_s,
                    });
                }
                match sighting_model::offsets_from_los(pose, lm, s.frame, &s.los) {
                    Ok(z) => Ok((id, z, s.frame)),
                    // Seen from this INS the direction points away from the landmark: the
                    // INS is far off, or the record is wrong. Not a usable measurement:
                    // rejected like a gated outlier (NaN offsets).
                    Err(sighting_model::SightingError::BehindCamera { .. }) => {
                        Ok((id, Vector2::new(f64::NAN, f64::NAN), s.frame))
                    }
                    Err(source) => Err(FilterError::Sighting {
                        t_s,
                        landmark: id,
                        source,
                    }),
                }
            }
        }
    }
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

/// One landmark's accepted row pair.
#[derive(Clone, Copy)]
struct Row {
    h: SMatrix<f64, 2, 15>,
    z: Vector2<f64>,
}

fn batch_update<const M: usize>(
    kf: &mut KalmanFilter<15>,
    rows: &[Row],
    r_var_m2: f64,
) -> Result<f64, akf::AkfError> {
    let mut h = SMatrix::<f64, M, 15>::zeros();
    let mut z = SVector::<f64, M>::zeros();
    for (i, row) in rows.iter().enumerate() {
        h.fixed_view_mut::<2, 15>(2 * i, 0).copy_from(&row.h);
        z[2 * i] = row.z.x;
        z[2 * i + 1] = row.z.y;
    }
    let r = SMatrix::<f64, M, M>::identity() * r_var_m2;
    Ok(kf.update(&z, &h, &r)?.nis)
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

    /// Measurement update at epoch `t_s` (the INS time, within the time-stamp tolerance) with
    /// 0, 1 or more sightings: predicts over the interval since the last epoch (a-priori Q, or
    /// the adaptive Q̂), gates each sighting on its 2-dof NIS against the prior, updates with the
    /// accepted ones (batches of ≤ [`MAX_BATCH`] landmarks), pushes the correction to the
    /// adaptive estimator, and feeds back at or after `open_loop_until_s`. An empty slice does
    /// nothing (the interval continues). Allocation-free.
    ///
    /// # Errors
    /// Checked before anything changes: [`FilterError::OutOfOrder`] (epoch before the last
    /// one), [`FilterError::NotAtInsTime`], [`FilterError::UnknownLandmark`],
    /// [`FilterError::NonFiniteInput`]. During the update, after the prediction has been made
    /// (x̂ and P stay a valid prediction): [`FilterError::Sighting`] (geometry of a landmark,
    /// e.g. straight below the vehicle), [`FilterError::Akf`] (S not positive definite),
    /// [`FilterError::NonFiniteState`].
    pub fn update(
        &mut self,
        t_s: f64,
        sightings: &[Sighting],
    ) -> Result<UpdateReport, FilterError> {
        self.update_epoch(t_s, Epoch::Offsets(sightings))
    }

    /// As [`InsSdFilter::update`] with sightings that carry their pointing: each direction is
    /// turned into the offsets a camera pointed with this filter's INS would have seen
    /// (`sighting_model::offsets_from_los`), and linearised with H of its frame (ψ columns zero
    /// for local-level directions, `sighting_model::jacobian_for_frame`). Allocation-free.
    ///
    /// # Errors
    /// As [`InsSdFilter::update`]; also [`FilterError::NonFiniteInput`] for a NaN/∞ direction.
    /// A direction that points away from its landmark as seen from the INS (behind the camera)
    /// is not an error: it is counted as rejected, like a gated outlier.
    pub fn update_pointed(
        &mut self,
        t_s: f64,
        sightings: &[PointedSighting],
    ) -> Result<UpdateReport, FilterError> {
        self.update_epoch(t_s, Epoch::Pointed(sightings))
    }

    fn update_epoch(
        &mut self,
        t_s: f64,
        sightings: Epoch<'_>,
    ) -> Result<UpdateReport, FilterError> {
        if !t_s.is_finite() {
            return Err(FilterError::NonFiniteInput {
                what: "time stamp",
                t_s,
            });
        }
        if t_s < self.last_epoch_s {
            return Err(FilterError::OutOfOrder {
                what: "sighting epoch",
                t_s,
                previous_s: self.last_epoch_s,
            });
        }
        let tol = self.config.timestamp_tolerance_s.max(1e-9);
        if (t_s - self.t_s).abs() > tol {
            return Err(FilterError::NotAtInsTime {
                t_s,
                ins_time_s: self.t_s,
                tolerance_s: tol,
            });
        }
        let pose = nav_pose(self.ins.state());
        for i in 0..sightings.len() {
            sightings.get(i, t_s, &self.landmarks, &pose)?;
        }
        let mut report = UpdateReport::default();
        if sightings.len() == 0 {
            return Ok(report);
        }
        self.last_epoch_s = t_s;
        let Some(est) = self.est.as_deref_mut() else {
            return Ok(report);
        };
        let ae = |source| FilterError::Akf { t_s, source };
        let pos = self.ins.state().pos;
        let mut rows = [Row {
            h: SMatrix::zeros(),
            z: Vector2::zeros(),
        }; MAX_BATCH];
        // Predict over the interval.
        let (phi, q_model) = self.interval.take();
        let q = match est.q_for_prediction(self.interval.noise_basis()) {
            Some(q_hat) => {
                report.adaptive_q = true;
                q_hat
            }
            None => q_model,
        };
        est.kf.predict(&phi, &q).map_err(ae)?;
        est.phi_since_push = Some(match est.phi_since_push {
            None => phi,
            Some(prev) => phi * prev,
        });
        if report.adaptive_q {
            self.stats.adaptive_q_used += 1;
        }
        self.stats.epochs += 1;
        let x_prior = *est.kf.state();
        let p_prior = *est.kf.covariance();
        let r = self.config.r_var_m2;
        let mut n = 0usize;
        let mut nis_sum = 0.0;
        let mut any_used = false;
        for i in 0..sightings.len() {
            let (id, z, frame) = sightings.get(i, t_s, &self.landmarks, &pose)?;
            let Some(lm) = self.landmarks.get(id) else {
                continue; // checked above
            };
            let mut h = jacobian(self.config.jacobian, &pos, lm).map_err(|source| {
                FilterError::Sighting {
                    t_s,
                    landmark: id,
                    source,
                }
            })?;
            if frame == LosFrame::LocalLevel {
                h.fixed_view_mut::<2, 3>(0, sighting_model::PSI_COL)
                    .fill(0.0);
            }
            if z.x.is_nan() {
                // A pointed sighting behind the camera (Epoch::get).
                report.rejected += 1;
                continue;
            }
            if let Some(threshold) = self.gate_threshold {
                let nu = z - h * x_prior;
                let s2: Matrix2<f64> = h * p_prior * h.transpose() + Matrix2::identity() * r;
                let nis = s2
                    .try_inverse()
                    .map(|si| (nu.transpose() * si * nu)[(0, 0)])
                    .unwrap_or(f64::INFINITY);
                if nis.is_nan() || nis > threshold {
                    report.rejected += 1;
                    continue;
                }
            }
            rows[n] = Row { h, z };
            n += 1;
            report.used += 1;
            if n == MAX_BATCH {
                nis_sum += batch(&mut est.kf, &rows[..n], r).map_err(ae)?;
                any_used = true;
                n = 0;
            }
        }
        if n > 0 {
            nis_sum += batch(&mut est.kf, &rows[..n], r).map_err(ae)?;
            any_used = true;
        }
        self.stats.sightings_used += report.used as u64;
        self.stats.sightings_rejected += report.rejected as u64;
        if any_used {
            report.nis = Some(nis_sum);
            let dx = est.kf.state() - x_prior;
            let p_post = *est.kf.covariance();
            let phi_push = est.phi_since_push.take().unwrap_or_else(Mat15::identity);
            let pushed = match &mut est.adaptive {
                Adaptive::None => Ok(()),
                Adaptive::MohamedSchwarz(a) => a
                    .push(&dx, &p_post, &est.p_post_prev, &phi_push)
                    .map(|_| ()),
                Adaptive::SageHusa(a) => a
                    .push(&dx, &p_post, &est.p_post_prev, &phi_push)
                    .map(|_| ()),
            };
            pushed.map_err(ae)?;
            if est.structured
                && let Some(raw) = est.raw_when_ready()
            {
                // Fit on this interval's noise basis, residual scaled by the previous P⁺.
                let scale = est.p_post_prev.diagonal();
                let fit = akf::project_structured(raw, self.interval.noise_basis(), &scale)
                    .map_err(ae)?;
                est.densities = Some(fit.densities);
                est.structured_q = Some(fit.matrix);
            }
            est.p_post_prev = p_post;
        }
        if !est.kf.state().iter().all(|x| x.is_finite()) || !nis_sum.is_finite() {
            return Err(FilterError::NonFiniteState {
                what: "filter state",
                t_s,
            });
        }
        if t_s >= self.config.open_loop_until_s - FEEDBACK_TIME_TOL_S {
            self.feedback();
            report.fed_back = true;
        }
        self.last_report = report;
        Ok(report)
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

/// Dispatches a batch of 1..=MAX_BATCH landmarks to the fixed-size update.
fn batch(kf: &mut KalmanFilter<15>, rows: &[Row], r: f64) -> Result<f64, akf::AkfError> {
    match rows.len() {
        1 => batch_update::<2>(kf, rows, r),
        2 => batch_update::<4>(kf, rows, r),
        3 => batch_update::<6>(kf, rows, r),
        4 => batch_update::<8>(kf, rows, r),
        5 => batch_update::<10>(kf, rows, r),
        6 => batch_update::<12>(kf, rows, r),
        7 => batch_update::<14>(kf, rows, r),
        _ => batch_update::<16>(kf, &rows[..MAX_BATCH.min(rows.len())], r),
    }
}

/// H of one landmark (2×15) at the computed position.
fn jacobian(
    which: MeasurementJacobian,
    pos: &ins_errors::earth::Geodetic,
    lm: &Landmark,
) -> Result<SMatrix<f64, 2, 15>, sighting_model::SightingError> {
    match which {
        MeasurementJacobian::Verified => sighting_model::sighting_jacobian(pos, lm),
        MeasurementJacobian::PaperPrinted => sighting_model::paper_printed_jacobian(pos, lm),
        MeasurementJacobian::PaperPrintedElevation => {
            sighting_model::paper_eq15_jacobian(pos, lm, PaperAlphaReading::Elevation)
        }
    }
}
