//! One Monte Carlo run of the INS/SD loop (see the module doc of [`super`]): the simulator
//! (truth, IMU errors, sighting generation) around the online filter of `ins-sd-filter`, which
//! is the one filter code path (the same object `nav-app ins` runs on logs).

use akf::{AdaptiveQConfig, QProjection, SageHusaConfig};
use ins_errors::error_model;
use ins_errors::imu::{ImuErrorParams, ImuErrors};
use ins_errors::strapdown::NavState;
use ins_errors::trajectory::{Trajectory, TruthSample};
use ins_sd_filter::{
    ErrorSigmas, ErrorStateEstimator, FilterError, InsSdFilter, InsSdFilterConfig, LandmarkEntry,
    LandmarkTable, ProcessNoisePsd, Sighting, Vec15, nav_pose,
};
use nalgebra::{SVector, Vector2, Vector3};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use sighting_model::Landmark;

use super::mismatch::World;
use super::{AkfScheme, Mode, Sample, Scenario, SimError, SimRunOutcome};

/// Sees what a run feeds its filter (for exporting a run as logs, [`super::logs`]). Every
/// method defaults to nothing; the Monte Carlo uses [`NoObserver`] (compiled away).
pub trait RunObserver {
    /// The INS start: time 0 and the initial navigation state (the truth at t = 0).
    fn start(&mut self, _initial: &NavState) {}
    /// One IMU sample at `t_s` (mean specific force, body m/s², and angular rate, body rad/s,
    /// over the interval ending at `t_s`).
    fn imu(
        &mut self,
        _t_s: f64,
        _specific_force_body_mps2: &Vector3<f64>,
        _ang_rate_body_radps: &Vector3<f64>,
    ) {
    }
    /// Just before a sighting epoch's update: the filter as it points the device.
    fn before_epoch(&mut self, _filter: &InsSdFilter) {}
    /// A sighting epoch: the sightings handed to the filter and the filter after its update.
    fn epoch(&mut self, _t_s: f64, _sightings: &[Sighting], _filter: &InsSdFilter) {}
    /// The truth at a 1 Hz record time (t = 0, 1, …).
    fn truth(&mut self, _t_s: f64, _truth: &NavState) {}
}

/// The observer that observes nothing.
pub struct NoObserver;

impl RunObserver for NoObserver {}

/// Everything a run carries from step to step (built once, no allocation in the loop).
pub(crate) struct Loop {
    pub(crate) filter: InsSdFilter,
    pub(crate) imu: ImuErrors,
    /// The simulated landmarks (ids = indices in `[sighting] landmarks`), in sighting order.
    landmarks: Vec<Landmark>,
    /// Reused sighting buffer (capacity = number of landmarks).
    sightings: Vec<Sighting>,
    pub(crate) sd_noise_var_m2: f64,
    pub(crate) rng_imu: ChaCha8Rng,
    pub(crate) rng_sd: ChaCha8Rng,
    step_s: f64,
    k: u64,
    /// The simulated world's mismatch (`None`: the world is the filter's model).
    world: Option<Box<World>>,
}

pub(crate) fn nav_state(s: &TruthSample) -> NavState {
    s.nav_state()
}

/// The online filter's configuration for `mode` from the scenario's `[filter]`, the SD period
/// of `[sighting]` and the IMU step of `[trajectory]`.
pub(crate) fn online_config(scenario: &Scenario, mode: Mode) -> InsSdFilterConfig {
    let f = &scenario.filter;
    let step_s = scenario.trajectory.step_s;
    let [pos, vel, psi, acc, gyro] = f.p0_sigmas();
    let psd = f.psd(step_s);
    InsSdFilterConfig {
        imu_step_s: step_s,
        timestamp_tolerance_s: 1e-6 * step_s,
        update_period_s: scenario.sighting.update_period_s,
        phi_subintervals: f.phi_subintervals,
        p0_sigma: ErrorSigmas {
            pos_m: pos,
            vel_mps: vel,
            psi_rad: psi,
            accel_bias_mps2: acc,
            gyro_drift_radps: gyro,
        },
        process_noise: ProcessNoisePsd {
            accel_white_m2ps3: psd[0],
            gyro_white_rad2ps: psd[1],
            accel_bias_rw_m2ps5: psd[2],
            gyro_drift_rw_rad2ps3: psd[3],
        },
        r_var_m2: f.r_var_m2,
        open_loop_until_s: f.open_loop_until_s,
        gate_probability: f.gate_probability,
        estimator: {
            let ms = |projection| {
                ErrorStateEstimator::MohamedSchwarz(AdaptiveQConfig {
                    window: f.akf_window,
                    projection,
                    min_variance: f.akf_min_variance,
                })
            };
            let sh = |projection| {
                ErrorStateEstimator::SageHusa(SageHusaConfig {
                    forgetting: f.sage_husa_forgetting,
                    warmup: f.akf_window,
                    projection,
                    min_variance: f.akf_min_variance,
                })
            };
            match mode {
                Mode::Standalone => ErrorStateEstimator::StandAlone,
                Mode::Kf => ErrorStateEstimator::Kalman,
                Mode::Akf => match f.akf_scheme {
                    AkfScheme::MohamedSchwarz => ms(f.akf_projection),
                    AkfScheme::SageHusa => sh(f.akf_projection),
                },
                Mode::AkfSageHusa => sh(f.akf_projection),
                Mode::AkfStructured => ms(QProjection::Structured),
            }
        },
        jacobian: f.measurement_jacobian,
    }
}

/// The scenario's landmarks as table entries (id = index in `[sighting] landmarks`): what the
/// simulated filter uses and what a log export writes.
pub(crate) fn landmark_entries(scenario: &Scenario) -> Vec<LandmarkEntry> {
    scenario
        .sighting
        .landmarks
        .iter()
        .enumerate()
        .map(|(i, l)| LandmarkEntry {
            id: i as u32,
            lat_deg: l.lat_deg,
            lon_deg: l.lon_deg,
            alt_m: l.alt_m,
        })
        .collect()
}

/// The scenario's landmarks as a table ([`landmark_entries`]).
pub(crate) fn landmark_table(scenario: &Scenario) -> Result<LandmarkTable, SimError> {
    LandmarkTable::new(&landmark_entries(scenario))
        .map_err(|source| SimError::Online { t_s: 0.0, source })
}

/// Maps the online filter's errors onto the run's error kinds.
pub(crate) fn run_error(e: FilterError) -> SimError {
    match e {
        FilterError::NonFiniteState { what, t_s } => SimError::NonFinite { t_s, what },
        FilterError::Sighting { t_s, source, .. } => SimError::Sighting { t_s, source },
        FilterError::Akf { t_s, source } => SimError::Filter { t_s, source },
        FilterError::Ins(e) => SimError::Ins(e),
        other => SimError::Online {
            t_s: f64::NAN,
            source: other,
        },
    }
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
    ) -> Result<Self, SimError> {
        let params = ImuErrorParams::from_config(&scenario.imu).map_err(SimError::Ins)?;
        let mut rng_imu = ChaCha8Rng::seed_from_u64(seed);
        let imu = ImuErrors::draw(&params, &mut rng_imu);
        let mut rng_sd = ChaCha8Rng::seed_from_u64(seed);
        rng_sd.set_stream(1);
        let landmarks = scenario
            .sighting
            .landmarks()
            .map_err(|source| SimError::Sighting { t_s: 0.0, source })?;
        let filter = InsSdFilter::new(
            online_config(scenario, mode),
            landmark_table(scenario)?,
            nav_state(first),
            0.0,
        )
        .map_err(run_error)?;
        let world = (!scenario.mismatch.is_matched()).then(|| {
            Box::new(World::new(
                &scenario.mismatch,
                seed,
                &landmarks,
                scenario.trajectory.step_s,
            ))
        });
        Ok(Self {
            world,
            filter,
            imu,
            sightings: Vec::with_capacity(landmarks.len()),
            landmarks,
            sd_noise_var_m2: scenario.sighting.noise_var_m2,
            rng_imu,
            rng_sd,
            step_s: scenario.trajectory.step_s,
            k: 0,
        })
    }

    /// Current error-state estimate x̂.
    #[cfg(test)]
    pub(crate) fn filter_state(&self) -> Vec15 {
        self.filter.error_state()
    }

    /// Current covariance P (None in stand-alone mode).
    #[cfg(test)]
    pub(crate) fn filter_covariance(&self) -> Option<&ins_errors::error_model::Mat15> {
        self.filter.covariance()
    }

    /// One 100 Hz step: corrupt the ideal IMU sample of the interval just flown and hand it to
    /// the filter (time stamp k·T_s).
    #[inline]
    pub(crate) fn step(
        &mut self,
        ideal: &TruthSample,
    ) -> Result<(Vector3<f64>, Vector3<f64>), SimError> {
        let (f, w) = match self.world.as_deref_mut() {
            None => self.imu.measure(
                &ideal.specific_force_body_mps2,
                &ideal.ang_rate_ib_body_radps,
                &mut self.rng_imu,
            ),
            Some(world) => {
                let (f, w) = world.corrupt(
                    &ideal.specific_force_body_mps2,
                    &ideal.ang_rate_ib_body_radps,
                );
                self.imu.measure(&f, &w, &mut self.rng_imu)
            }
        };
        self.k += 1;
        self.filter
            .propagate_rates(self.k as f64 * self.step_s, &f, &w)
            .map_err(run_error)?;
        Ok((f, w))
    }

    /// The full true error of the INS (15 states): δp, δv, ψ of the INS against `truth`,
    /// then the residual sensor errors (true ∇, ε minus the corrections applied so far).
    pub(crate) fn true_error(&self, truth: &NavState) -> Vec15 {
        let ins = self.filter.ins();
        let e9 = error_model::error_state(truth, ins.state());
        let (acc_corr, gyro_corr) = ins.sensor_corrections();
        let mut e = Vec15::zeros();
        e.fixed_rows_mut::<9>(0).copy_from(&e9);
        e.fixed_rows_mut::<3>(9)
            .copy_from(&(self.imu.accel_bias_body_mps2 - acc_corr));
        e.fixed_rows_mut::<3>(12)
            .copy_from(&(self.imu.gyro_drift_body_radps - gyro_corr));
        e
    }

    /// The sightings at time `t_s` against the truth `truth`: each landmark measured with the
    /// nonlinear model (camera pointed with the filter's INS) plus N(0, σ²_SD) noise on w and h
    /// (drawn in the order w₀, h₀, w₁, h₁, …). Written into the reused buffer.
    pub(crate) fn simulate_sightings(
        &mut self,
        t_s: f64,
        truth: &NavState,
    ) -> Result<&[Sighting], SimError> {
        let computed = self.filter.pointing_pose();
        let truth_pose = nav_pose(truth);
        self.sightings.clear();
        let se = |source| SimError::Sighting { t_s, source };
        if let Some(world) = self.world.as_deref_mut() {
            let sigma_m = self.sd_noise_var_m2.sqrt();
            for (i, lm) in self.landmarks.iter().enumerate() {
                // Draws happen for every landmark, visible or not (stable streams).
                let (nw, nh): (f64, f64) = (
                    rand::Rng::sample(&mut self.rng_sd, rand_distr::StandardNormal),
                    rand::Rng::sample(&mut self.rng_sd, rand_distr::StandardNormal),
                );
                let (visible, range_m) = world.visible(i, truth);
                let (ew, eh) = world.sighting_error(range_m);
                if !visible {
                    continue;
                }
                let z = sighting_model::sighting_offset_surveyed_m(
                    &truth_pose,
                    &computed,
                    lm,
                    &world.actual_ecef_m[i],
                )
                .map_err(se)?;
                self.sightings.push(Sighting {
                    landmark_id: lm.id() as u32,
                    w_m: z.x + sigma_m * nw + ew,
                    h_m: z.y + sigma_m * nh + eh,
                });
            }
            return Ok(&self.sightings);
        }
        for lm in &self.landmarks {
            let z = sighting_model::sighting_offset_m(&truth_pose, &computed, lm).map_err(se)?;
            self.sightings.push(Sighting {
                landmark_id: lm.id() as u32,
                w_m: z.x,
                h_m: z.y,
            });
        }
        for s in &mut self.sightings {
            let mut z: SVector<f64, 2> = Vector2::new(s.w_m, s.h_m);
            sighting_model::add_sighting_noise(&mut z, self.sd_noise_var_m2, &mut self.rng_sd)
                .map_err(se)?;
            s.w_m = z.x;
            s.h_m = z.y;
        }
        Ok(&self.sightings)
    }

    /// SD epoch at time `t_s`: simulate the sightings, then the filter's update (predict,
    /// update, feedback after `open_loop_until_s`). Returns the NIS (NaN without a filter).
    pub(crate) fn sd_update(&mut self, t_s: f64, truth: &NavState) -> Result<f64, SimError> {
        if self.latency_steps() == 0 {
            self.simulate_sightings(t_s, truth)?;
        }
        let report = self
            .filter
            .update(t_s, &self.sightings)
            .map_err(run_error)?;
        Ok(report.nis.unwrap_or(f64::NAN))
    }

    /// Sighting latency in IMU steps (0 without a mismatch).
    pub(crate) fn latency_steps(&self) -> usize {
        self.world.as_deref().map_or(0, |w| w.latency_steps)
    }

    /// Feedback now (see [`InsSdFilter::feedback`]).
    #[cfg(test)]
    pub(crate) fn feedback(&mut self) {
        self.filter.feedback();
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
    ) -> Result<Sample, SimError> {
        let e = self.true_error(truth) - self.filter.error_state();
        let nees = match (nis, self.filter.covariance()) {
            (Some(_), Some(p)) => {
                Some(akf::nees(&e, p).map_err(|source| SimError::Filter { t_s, source })?)
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
            nis_dof: if nis.is_some() {
                2 * self.filter.last_report().used as u32
            } else {
                0
            },
        })
    }
}

/// The run loop behind [`super::run`].
pub(crate) fn run(
    scenario: &Scenario,
    mode: Mode,
    seed: u64,
    out: &mut [Sample],
) -> Result<SimRunOutcome, SimError> {
    run_observed(scenario, mode, seed, out, &mut NoObserver)
}

/// [`run`], showing `obs` every IMU sample, sighting epoch and 1 Hz truth.
pub(crate) fn run_observed<O: RunObserver>(
    scenario: &Scenario,
    mode: Mode,
    seed: u64,
    out: &mut [Sample],
    obs: &mut O,
) -> Result<SimRunOutcome, SimError> {
    let plan = scenario.plan()?;
    if out.len() != plan.samples {
        return Err(SimError::OutputLength {
            expected: plan.samples,
            got: out.len(),
        });
    }
    let tr = Trajectory::new(&scenario.trajectory).map_err(SimError::Ins)?;
    let mut truth_it = tr.samples();
    let Some(first) = truth_it.next() else {
        return Err(SimError::OutputLength {
            expected: plan.samples,
            got: 0,
        });
    };
    let mut lp = Loop::new(scenario, mode, seed, &first)?;
    let truth0 = nav_state(&first);
    obs.start(&truth0);
    obs.truth(0.0, &truth0);
    out[0] = lp.sample(0.0, &truth0, 0.0, None)?;
    let mut ideal = first;
    let mut distance_m = 0.0;
    let mut speed_prev = first.vel_ned_mps.norm();
    let mut written = 1usize;
    let mut steps = 0u64;
    let mut last_nis: Option<f64> = None;
    for k in 1..=plan.steps {
        let Some(s) = truth_it.next() else { break };
        let (f, w) = lp.step(&ideal)?;
        obs.imu(k as f64 * plan.step_s, &f, &w);
        steps += 1;
        let speed = s.vel_ned_mps.norm();
        distance_m += 0.5 * (speed + speed_prev) * plan.step_s;
        speed_prev = speed;
        ideal = s;
        let t_s = k as f64 * plan.step_s;
        let update_due = mode != Mode::Standalone && k % plan.steps_per_update == 0;
        let sample_due = k % plan.steps_per_sample == 0;
        let lat = lp.latency_steps();
        if lat > 0 && mode != Mode::Standalone && (k + lat) % plan.steps_per_update == 0 {
            // The image of the next epoch is taken now (latency): truth and INS of this step.
            lp.simulate_sightings(t_s, &nav_state(&s))?;
        }
        if !(update_due || sample_due) {
            continue;
        }
        let truth = nav_state(&s);
        if update_due {
            obs.before_epoch(&lp.filter);
            last_nis = Some(lp.sd_update(t_s, &truth)?);
            obs.epoch(t_s, &lp.sightings, &lp.filter);
        }
        if sample_due {
            obs.truth(t_s, &truth);
        }
        if sample_due && written < out.len() {
            out[written] = lp.sample(t_s, &truth, distance_m, last_nis.take())?;
            written += 1;
        }
    }
    let st = lp.filter.statistics();
    Ok(SimRunOutcome {
        samples_written: written,
        steps,
        sightings_used: st.sightings_used,
        sightings_rejected: st.sightings_rejected,
    })
}
