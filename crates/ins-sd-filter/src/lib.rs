//! # ins-sd-filter — the online INS / sighting-device filter
//!
//! One object, [`InsSdFilter`], that runs the error-state filter of Lustosa, Chagas & Waldmann
//! (sighting-device-aided INS, §§4–6) on data as it arrives: timestamped IMU samples and
//! sightings of landmarks from a [`LandmarkTable`]. It composes the three numeric crates —
//! `ins-errors` (NED strapdown INS, 15-state ψ-angle error model), `sighting-model` (the
//! sighting Jacobian H) and `akf` (Joseph-form KF, Mohamed–Schwarz Q̂) — and is the single
//! filter code path: the Monte Carlo of `nav-app` drives this same object with simulated data,
//! and `nav-app ins` drives it with logs.
//!
//! ## Model
//!
//! * Error state x = (δp m NED, δv m/s NED, ψ rad, ∇ m/s² body, ε rad/s body), δ = computed −
//!   true (the `ins-errors` contract).
//! * **Propagation** ([`InsSdFilter::propagate`]): an IMU sample at t_k carries the increments
//!   Δv = ∫f̃_b dt, Δθ = ∫ω̃_ib dt over (t_{k−1}, t_k] (or the mean rates,
//!   [`InsSdFilter::propagate_rates`]); the INS mechanises f̃ = Δv/Δt, ω̃ = Δθ/Δt over Δt
//!   (Δt within `timestamp_tolerance_s` of the nominal step is taken as the nominal step). The
//!   linearisation points are accumulated by [`interval::IntervalModel`] (A averaged on
//!   sub-intervals of `update_period_s / phi_subintervals`, series Φ, Simpson Q_d).
//! * **Update** ([`InsSdFilter::update`]) at a sighting epoch t (= the INS time): predict
//!   x̂⁻ = Φ_T x̂, P⁻ = Φ_T P Φ_Tᵀ + Q_T over the interval since the last epoch (Q_T the a-priori
//!   model, or the adaptive Q̂); for each sighting i of landmark ℓ_i with measured offsets
//!   z_i = (w_i, h_i) (camera pointed with [`InsSdFilter::pointing_pose`], i.e. the INS's own
//!   position and attitude, so the predicted offset of the INS is zero):
//!
//!   ```text
//!   ν_i = z_i − H_i x̂⁻,   S_i = H_i P⁻ H_iᵀ + r I₂,   NIS_i = ν_iᵀ S_i⁻¹ ν_i
//!   gate: reject if NIS_i > χ²₂(p) = −2 ln(1 − p)        (gate_probability = p)
//!   ```
//!
//!   H_i = ∂(w, h)/∂x at the computed position (`sighting-model`, verified against finite
//!   differences). The accepted sightings are stacked (batches of ≤ [`MAX_BATCH`] landmarks)
//!   into z = H x + v, R = r I, and applied with the Joseph-form update; the reported NIS is
//!   νᵀ S⁻¹ ν of the stack (χ² with 2·used dof). The Mohamed–Schwarz estimator is then pushed
//!   Δx = x̂⁺ − x̂⁻, P⁺, the previous P⁺ and Φ since that push.
//! * **Pointed sightings** ([`InsSdFilter::update_pointed`]): a sighting that carries its
//!   pointing (the measured line of sight in body or local-level axes, [`PointedSighting`]) is
//!   turned into the offsets a camera pointed with this filter's INS would have seen
//!   (`sighting_model::offsets_from_los`) and used as above; local-level directions do not see
//!   the attitude (H's ψ columns zero). Such a record means the same to any filter, whoever
//!   recorded it; a direction that points away from its landmark as seen from the INS is
//!   rejected. The paper's offsets ([`InsSdFilter::update`]) are the special case the Monte
//!   Carlo uses (the device pointed by the filter's own INS).
//! * **Feedback** at epochs t ≥ `open_loop_until_s`: δp̂, δv̂, ψ̂ are removed from the INS,
//!   ∇̂, ε̂ added to its sensor corrections, x̂ ← 0, P kept.
//! * 0 sightings at an epoch: nothing happens (the interval continues to the next epoch).
//! * Between epochs, [`InsSdFilter::predicted`] gives (x̂, P) at the INS time (the a-priori Q
//!   of the part of the interval elapsed, or the adaptive Q̂ scaled to it): the σ a solution
//!   is reported with at any IMU sample. Sensor biases known beforehand (a static alignment)
//!   are set with [`InsSdFilter::set_sensor_corrections`].
//!
//! ## Estimators ([`ErrorStateEstimator`])
//!
//! Stand-alone INS (no filter), the KF with the a-priori Q, and two adaptive Q̂ schemes used
//! as the next interval's Q once they have an estimate: Mohamed–Schwarz (paper eq. 19, a
//! window of N updates) and Sage–Husa (a forgetting factor b), each made PSD by eigenvalue
//! clipping, the diagonal, or the **structured** projection: non-negative least squares of
//! the raw Q̂ onto the interval noise matrices B_k of the four noise inputs (accelerometer and
//! gyro white noise, bias and drift random walks; [`interval::IntervalModel::noise_basis`],
//! Q_T = Σ q_k B_k exactly), residual scaled by the previous P⁺'s diagonal; the prediction then
//! uses Σ q̂_k B_k on the new interval's basis ([`InsSdFilter::fitted_noise_densities`]).
//!
//! ## Errors
//!
//! Out-of-order time stamps, an epoch not at the INS time, unknown landmark ids, NaN/∞ inputs,
//! an IMU gap longer than one update interval and an implausible IMU sample (mean specific force
//! above [`MAX_SPECIFIC_FORCE_MPS2`] or rate above [`MAX_ANGULAR_RATE_RADPS`] — a corrupt record)
//! are rejected with a typed [`FilterError`] before anything changes.
//!
//! ## Example
//!
//! A vehicle at rest, 5 km from two landmarks, a perfect IMU at 100 Hz, one sighting epoch per
//! second; the second epoch carries an outlier that the gate rejects.
//!
//! ```
//! use ins_errors::earth::{Geodetic, gravity_ned_mps2};
//! use ins_errors::strapdown::NavState;
//! use ins_sd_filter::{
//!     ErrorSigmas, ErrorStateEstimator, InsSdFilter, InsSdFilterConfig, LandmarkEntry, LandmarkTable,
//!     MeasurementJacobian, ProcessNoisePsd, Sighting,
//! };
//! use nalgebra::{UnitQuaternion, Vector3};
//!
//! let config = InsSdFilterConfig {
//!     imu_step_s: 0.01,
//!     timestamp_tolerance_s: 1e-6,
//!     update_period_s: 1.0,
//!     phi_subintervals: 2,
//!     p0_sigma: ErrorSigmas {
//!         pos_m: 10.0, vel_mps: 0.1, psi_rad: 1e-3, accel_bias_mps2: 0.03, gyro_drift_radps: 1e-5,
//!     },
//!     process_noise: ProcessNoisePsd {
//!         accel_white_m2ps3: 1e-6, gyro_white_rad2ps: 1e-12,
//!         accel_bias_rw_m2ps5: 0.0, gyro_drift_rw_rad2ps3: 0.0,
//!     },
//!     r_var_m2: 40.0,
//!     open_loop_until_s: f64::INFINITY,
//!     gate_probability: Some(0.999),
//!     estimator: ErrorStateEstimator::Kalman,
//!     jacobian: MeasurementJacobian::Verified,
//! };
//! let table = LandmarkTable::new(&[
//!     LandmarkEntry { id: 1, lat_deg: -23.25, lon_deg: -45.85, alt_m: 0.0 },
//!     LandmarkEntry { id: 2, lat_deg: -23.20, lon_deg: -45.90, alt_m: 0.0 },
//! ])?;
//! let start = Geodetic::from_deg(-23.2, -45.85, 3000.0);
//! let at_rest = NavState {
//!     pos: start, vel_ned_mps: Vector3::zeros(), att_b_to_n: UnitQuaternion::identity(),
//! };
//! let mut filter = InsSdFilter::new(config, table, at_rest, 0.0)?;
//! // At rest the accelerometers read −g (NED "down" = body z) and the gyros the Earth rate.
//! let g = gravity_ned_mps2(start.lat_rad, start.alt_m);
//! let w_ie = 7.292115e-5 * Vector3::new(start.lat_rad.cos(), 0.0, -start.lat_rad.sin());
//! for k in 1..=200 {
//!     let t = k as f64 * 0.01;
//!     filter.propagate(t, &(-g * 0.01), &(w_ie * 0.01))?;
//!     if k % 100 == 0 {
//!         let outlier = if k == 200 { 500.0 } else { 0.0 }; // a gross error on landmark 2
//!         let report = filter.update(t, &[
//!             Sighting { landmark_id: 1, w_m: 0.0, h_m: 0.0 },
//!             Sighting { landmark_id: 2, w_m: outlier, h_m: 0.0 },
//!         ])?;
//!         assert_eq!(report.rejected, if k == 200 { 1 } else { 0 });
//!     }
//! }
//! assert_eq!(filter.statistics().sightings_rejected, 1);
//! // The sightings shrank the position uncertainty from 10 m.
//! let p = filter.covariance().expect("a Kalman filter");
//! assert!(p[(0, 0)].sqrt() < 10.0);
//! // Out-of-order data and unknown landmarks are typed errors.
//! assert!(filter.propagate(1.0, &Vector3::zeros(), &Vector3::zeros()).is_err());
//! assert!(filter.update(2.0, &[Sighting { landmark_id: 9, w_m: 0.0, h_m: 0.0 }]).is_err());
//! # Ok::<(), ins_sd_filter::FilterError>(())
//! ```

mod config;
mod error;
mod filter;
pub mod interval;
mod landmarks;

pub use config::{
    ErrorSigmas, ErrorStateEstimator, InsSdFilterConfig, MeasurementJacobian, ProcessNoisePsd,
};
pub use error::FilterError;
pub use filter::{
    FilterStatistics, InsSdFilter, MAX_ANGULAR_RATE_RADPS, MAX_BATCH, MAX_SPECIFIC_FORCE_MPS2,
    PointedSighting, Sighting, UpdateReport, Vec15, nav_pose,
};
pub use landmarks::{LandmarkEntry, LandmarkTable};
pub use sighting_model::LosFrame;
