//! One Monte Carlo run of the INS/SD loop (see the module doc of [`super`]).

use akf::{AdaptiveKalmanFilter, AdaptiveQConfig, KalmanFilter};
use ins_errors::error_model::{self, Mat15};
use ins_errors::imu::{ImuErrorParams, ImuErrors};
use ins_errors::strapdown::{NavState, Strapdown};
use ins_errors::trajectory::{Trajectory, TruthSample};
use nalgebra::{Rotation3, SMatrix, SVector, Vector3};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use sighting_model::{Landmark, NavPose};

use super::MeasurementJacobian;
use super::interval::IntervalModel;
use super::{Mode, RunError, RunOutcome, Sample, Scenario};

type Vec15 = SVector<f64, 15>;

/// The error-state filter of a run.
pub(crate) enum Filter {
    /// Stand-alone INS: no filter.
    None,
    /// Manually tuned KF (boxed: the filter holds a 15×15 P).
    Kf(Box<KalmanFilter<15>>),
    /// Adaptive KF (boxed: P, Φ and the Δx window).
    Akf(Box<AdaptiveKalmanFilter<15>>),
}

impl Filter {
    fn state(&self) -> Vec15 {
        match self {
            Filter::None => Vec15::zeros(),
            Filter::Kf(f) => *f.state(),
            Filter::Akf(f) => *f.filter().state(),
        }
    }

    fn covariance(&self) -> Option<&Mat15> {
        match self {
            Filter::None => None,
            Filter::Kf(f) => Some(f.covariance()),
            Filter::Akf(f) => Some(f.filter().covariance()),
        }
    }

    fn reset(&mut self) {
        match self {
            Filter::None => {}
            Filter::Kf(f) => f.reset_error_state(),
            Filter::Akf(f) => f.reset_error_state(),
        }
    }
}

/// Everything a run carries from step to step (built once, no allocation in the loop).
pub(crate) struct Loop {
    pub(crate) ins: Strapdown,
    pub(crate) imu: ImuErrors,
    pub(crate) filter: Filter,
    pub(crate) interval: IntervalModel,
    pub(crate) landmarks: [Landmark; 3],
    pub(crate) r: SMatrix<f64, 6, 6>,
    pub(crate) sd_noise_var_m2: f64,
    pub(crate) rng_imu: ChaCha8Rng,
    pub(crate) rng_sd: ChaCha8Rng,
    pub(crate) open_loop_until_s: f64,
    /// Which H the filter uses (`[filter] measurement_jacobian`).
    pub(crate) jacobian: MeasurementJacobian,
    /// Diagnostic: how many SD updates used the AKF's Q̂ rather than the a-priori Q.
    pub(crate) adaptive_q_used: usize,
}

pub(crate) fn nav_state(s: &TruthSample) -> NavState {
    s.nav_state()
}

fn pose(s: &NavState) -> NavPose {
    NavPose {
        position: s.pos,
        c_b_n: Rotation3::from(s.att_b_to_n),
    }
}

fn nav_finite(s: &NavState) -> bool {
    s.pos.lat_rad.is_finite()
        && s.pos.lon_rad.is_finite()
        && s.pos.alt_m.is_finite()
        && s.vel_ned_mps.iter().all(|x| x.is_finite())
        && s.att_b_to_n.coords.iter().all(|x| x.is_finite())
}

/// Initial covariance from `[filter]`.
pub(crate) fn initial_covariance(scenario: &Scenario) -> Mat15 {
    let d = scenario.filter.p0_diagonal();
    let mut p = Mat15::zeros();
    for (b, v) in d.iter().enumerate() {
        for i in 0..3 {
            p[(3 * b + i, 3 * b + i)] = *v;
        }
    }
    p
}

impl Loop {
    /// Sets up a run: the IMU error draw and IMU noise come from `ChaCha8Rng::seed_from_u64(seed)`
    /// exactly as in a stand-alone `ins-errors` run; the SD noise from the same seed on ChaCha
    /// stream 1 (so the IMU stream is identical in every mode: common random numbers).
    pub(crate) fn new(
        scenario: &Scenario,
        mode: Mode,
        seed: u64,
        first: &TruthSample,
        step_s: f64,
        steps_per_update: usize,
    ) -> Result<Self, RunError> {
        let params = ImuErrorParams::from_config(&scenario.imu).map_err(RunError::Ins)?;
        let mut rng_imu = ChaCha8Rng::seed_from_u64(seed);
        let imu = ImuErrors::draw(&params, &mut rng_imu);
        let mut rng_sd = ChaCha8Rng::seed_from_u64(seed);
        rng_sd.set_stream(1);
        let ins = Strapdown::new(nav_state(first), step_s).map_err(RunError::Ins)?;
        let landmarks = scenario
            .sighting
            .landmarks3()
            .map_err(|source| RunError::Sighting { t_s: 0.0, source })?;
        let p0 = initial_covariance(scenario);
        let f = &scenario.filter;
        let filter = match mode {
            Mode::Standalone => Filter::None,
            Mode::Kf => Filter::Kf(Box::new(
                KalmanFilter::new(Vec15::zeros(), p0)
                    .map_err(|source| RunError::Filter { t_s: 0.0, source })?,
            )),
            Mode::Akf => Filter::Akf(Box::new(
                AdaptiveKalmanFilter::new(
                    Vec15::zeros(),
                    p0,
                    AdaptiveQConfig {
                        window: f.akf_window,
                        projection: f.akf_projection,
                        min_variance: f.akf_min_variance,
                    },
                )
                .map_err(|source| RunError::Filter { t_s: 0.0, source })?,
            )),
        };
        Ok(Self {
            ins,
            imu,
            filter,
            interval: IntervalModel::new(
                steps_per_update,
                f.phi_subintervals,
                step_s,
                f.psd(step_s),
            ),
            landmarks,
            r: SMatrix::<f64, 6, 6>::identity() * f.r_var_m2,
            sd_noise_var_m2: scenario.sighting.noise_var_m2,
            rng_imu,
            rng_sd,
            open_loop_until_s: f.open_loop_until_s,
            jacobian: f.measurement_jacobian,
            adaptive_q_used: 0,
        })
    }

    /// Current error-state estimate x̂.
    #[cfg(test)]
    pub(crate) fn filter_state(&self) -> Vec15 {
        self.filter.state()
    }

    /// Current covariance P (None in stand-alone mode).
    #[cfg(test)]
    pub(crate) fn filter_covariance(&self) -> Option<&Mat15> {
        self.filter.covariance()
    }

    /// One 100 Hz step: corrupt the ideal IMU sample of the interval just flown, mechanize,
    /// feed the interval model.
    #[inline]
    pub(crate) fn step(&mut self, ideal: &TruthSample) {
        let (f, w) = self.imu.measure(
            &ideal.specific_force_body_mps2,
            &ideal.ang_rate_ib_body_radps,
            &mut self.rng_imu,
        );
        self.ins.step(&f, &w);
        if !matches!(self.filter, Filter::None) {
            self.interval.push(&self.ins.linearization_point());
        }
    }

    /// The full true error of the INS (15 states): δp, δv, ψ of the INS against `truth`,
    /// then the residual sensor errors (true ∇, ε minus the corrections applied so far).
    pub(crate) fn true_error(&self, truth: &NavState) -> Vec15 {
        let e9 = error_model::error_state(truth, self.ins.state());
        let (acc_corr, gyro_corr) = self.ins.sensor_corrections();
        let mut e = Vec15::zeros();
        e.fixed_rows_mut::<9>(0).copy_from(&e9);
        e.fixed_rows_mut::<3>(9)
            .copy_from(&(self.imu.accel_bias_body_mps2 - acc_corr));
        e.fixed_rows_mut::<3>(12)
            .copy_from(&(self.imu.gyro_drift_body_radps - gyro_corr));
        e
    }

    /// SD update at time `t_s` against the truth `truth`: predict over the interval with
    /// (Φ_T, Q_T) (AKF: Q̂ once available), measure the three landmarks with the nonlinear
    /// model plus noise, update, and (after `open_loop_until_s`) feed back and reset.
    /// Returns the NIS.
    pub(crate) fn sd_update(&mut self, t_s: f64, truth: &NavState) -> Result<f64, RunError> {
        let (phi, q_model) = self.interval.take();
        let fe = |source| RunError::Filter { t_s, source };
        let computed = *self.ins.state();
        let mut z =
            sighting_model::sighting_offsets3_m(&pose(truth), &pose(&computed), &self.landmarks)
                .map_err(|source| RunError::Sighting { t_s, source })?;
        sighting_model::add_sighting_noise(&mut z, self.sd_noise_var_m2, &mut self.rng_sd)
            .map_err(|source| RunError::Sighting { t_s, source })?;
        let h = match self.jacobian {
            MeasurementJacobian::Verified => {
                sighting_model::sighting_jacobian3(&computed.pos, &self.landmarks)
            }
            MeasurementJacobian::PaperPrinted => {
                sighting_model::paper_printed_jacobian3(&computed.pos, &self.landmarks)
            }
            MeasurementJacobian::PaperPrintedElevation => sighting_model::paper_eq15_jacobian3(
                &computed.pos,
                &self.landmarks,
                sighting_model::PaperAlphaReading::Elevation,
            ),
        }
        .map_err(|source| RunError::Sighting { t_s, source })?;
        let nis = match &mut self.filter {
            Filter::None => return Ok(f64::NAN),
            Filter::Kf(f) => {
                f.predict(&phi, &q_model).map_err(fe)?;
                f.update(&z, &h, &self.r).map_err(fe)?.nis
            }
            Filter::Akf(f) => {
                let q = match f.q_estimate() {
                    Some(q_hat) => {
                        self.adaptive_q_used += 1;
                        *q_hat
                    }
                    None => q_model,
                };
                f.predict(&phi, &q).map_err(fe)?;
                f.update(&z, &h, &self.r).map_err(fe)?.nis
            }
        };
        if !nis.is_finite() || !self.filter.state().iter().all(|x| x.is_finite()) {
            return Err(RunError::NonFinite {
                t_s,
                what: "filter state",
            });
        }
        if t_s >= self.open_loop_until_s - 1e-9 {
            self.feedback();
        }
        Ok(nis)
    }

    /// Feedback: the estimated δp, δv, ψ are removed from the INS, ∇̂, ε̂ added to the sensor
    /// corrections, the error state reset to zero (P kept).
    pub(crate) fn feedback(&mut self) {
        let x = self.filter.state();
        let v = |i: usize| Vector3::new(x[i], x[i + 1], x[i + 2]);
        self.ins.apply_correction(&v(0), &v(3), &v(6));
        self.ins.add_sensor_corrections(&v(9), &v(12));
        self.filter.reset();
    }

    /// Writes the 1 Hz record for time `t_s`. The recorded errors are those of the system's
    /// navigation output: the INS corrected by the current estimate, e_INS − x̂ (x̂ = 0 in
    /// feedback after the reset, and in stand-alone mode).
    pub(crate) fn sample(
        &self,
        t_s: f64,
        truth: &NavState,
        distance_m: f64,
        nis: Option<f64>,
    ) -> Result<Sample, RunError> {
        let computed = self.ins.state();
        if !nav_finite(computed) {
            return Err(RunError::NonFinite {
                t_s,
                what: "INS navigation state",
            });
        }
        let e = self.true_error(truth) - self.filter.state();
        let nees = match (nis, self.filter.covariance()) {
            (Some(_), Some(p)) => {
                Some(akf::nees(&e, p).map_err(|source| RunError::Filter { t_s, source })?)
            }
            _ => None,
        };
        Ok(Sample {
            t_s,
            pos_err_ned_m: [e[0], e[1], e[2]],
            vel_err_ned_mps: [e[3], e[4], e[5]],
            misalignment_rad: [e[6], e[7], e[8]],
            distance_m,
            nees,
            nis,
        })
    }
}

/// The run loop behind [`super::run`].
pub(crate) fn run(
    scenario: &Scenario,
    mode: Mode,
    seed: u64,
    out: &mut [Sample],
) -> Result<RunOutcome, RunError> {
    let plan = scenario.plan()?;
    if out.len() != plan.samples {
        return Err(RunError::OutputLength {
            expected: plan.samples,
            got: out.len(),
        });
    }
    let tr = Trajectory::new(&scenario.trajectory).map_err(RunError::Ins)?;
    let mut truth_it = tr.samples();
    let Some(first) = truth_it.next() else {
        return Err(RunError::OutputLength {
            expected: plan.samples,
            got: 0,
        });
    };
    let mut lp = Loop::new(
        scenario,
        mode,
        seed,
        &first,
        plan.step_s,
        plan.steps_per_update,
    )?;
    let truth0 = nav_state(&first);
    out[0] = lp.sample(0.0, &truth0, 0.0, None)?;
    let mut ideal = first;
    let mut distance_m = 0.0;
    let mut speed_prev = first.vel_ned_mps.norm();
    let mut written = 1usize;
    let mut epochs = 0u64;
    let mut last_nis: Option<f64> = None;
    for k in 1..=plan.steps {
        let Some(s) = truth_it.next() else { break };
        lp.step(&ideal);
        epochs += 1;
        let speed = s.vel_ned_mps.norm();
        distance_m += 0.5 * (speed + speed_prev) * plan.step_s;
        speed_prev = speed;
        ideal = s;
        let t_s = k as f64 * plan.step_s;
        let update_due = mode != Mode::Standalone && k % plan.steps_per_update == 0;
        let sample_due = k % plan.steps_per_sample == 0;
        if !nav_finite(lp.ins.state()) {
            return Err(RunError::NonFinite {
                t_s,
                what: "INS navigation state",
            });
        }
        if !(update_due || sample_due) {
            continue;
        }
        let truth = nav_state(&s);
        if update_due {
            last_nis = Some(lp.sd_update(t_s, &truth)?);
        }
        if sample_due && written < out.len() {
            out[written] = lp.sample(t_s, &truth, distance_m, last_nis.take())?;
            written += 1;
        }
    }
    Ok(RunOutcome {
        samples_written: written,
        epochs,
    })
}
