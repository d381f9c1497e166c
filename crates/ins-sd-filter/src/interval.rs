//! Φ and Q_d over one SD update interval, from the error model averaged on sub-intervals.
//!
//! The INS runs at T_s = 0.01 s; the filter only needs (Φ_T, Q_T) between two SD updates
//! T = 1 s apart. The interval is cut into `m` sub-intervals of length τ = T/m (default m = 2,
//! τ = 0.5 s). On each, the INS's linearisation quantities are averaged over its 100 Hz steps
//! (latitude, height, velocity, f_n = C̃ f_b and C̃ itself — A is affine in f_n and C̃, so
//! averaging them is averaging A's force and bias columns exactly), A(τ-average) is built with
//! [`ins_errors::error_model::system_matrix`] and discretised by
//! [`ins_errors::error_model::discretize_fast`] (third-order series Φ, Simpson Q_d). The
//! sub-interval pieces are chained with the block structure of Φ (bias rows [0 I]):
//!
//! ```text
//! Φ_T ← Φ_τ Φ_T                       (Φ₁₁ ← Φ_τ,₁₁ Φ₁₁,  Φ₁₂ ← Φ_τ,₁₁ Φ₁₂ + Φ_τ,₁₂)
//! Q_T ← Φ_τ Q_T Φ_τᵀ + Q_τ            (ins_errors::error_model::propagate_covariance)
//! ```
//!
//! Per 100 Hz step this costs ≈ 20 additions (the averages); per sub-interval one A, one
//! discretisation and one block product. The accuracy against the paper's way (Φ of every
//! 0.01 s step multiplied over the interval, Q_d per step accumulated) is measured in the
//! tests (`tests/ins_sd_interval.rs`).
//!
//! The noise input W = G Q_c Gᵀ is constant: with equal PSDs on the three body axes,
//! C̃ (q I) C̃ᵀ = q I for any attitude, so W = diag(0, q_a I, q_g I, q_∇ I, q_ε I).

use ins_errors::earth::Geodetic;
use ins_errors::error_model::{self, Mat15, Transition};
use ins_errors::strapdown::LinearizationPoint;
use nalgebra::{Matrix3, SMatrix, Vector3};

/// Accumulates (Φ_T, Q_T) over one update interval from 100 Hz linearisation points.
#[derive(Clone, Debug)]
pub struct IntervalModel {
    steps_per_interval: usize,
    subintervals: usize,
    step_s: f64,
    w: Mat15,
    // Averages of the current sub-interval.
    n: usize,
    sum_lat: f64,
    sum_lon: f64,
    sum_alt: f64,
    sum_vel: Vector3<f64>,
    sum_f: Vector3<f64>,
    sum_c: Matrix3<f64>,
    // Length of the current sub-interval, s, and whether every step in it had the nominal
    // length (then τ = n·T_s exactly, as for a regular IMU).
    sum_dt: f64,
    all_nominal: bool,
    // Position in the interval.
    steps_done: usize,
    sub_done: usize,
    phi: Transition,
    q: Mat15,
    // Noise matrices of the four noise inputs at unit density (only when enabled).
    basis_on: bool,
    basis: [Mat15; 4],
    basis_taken: [Mat15; 4],
}

impl IntervalModel {
    /// A model for intervals of `steps_per_interval` INS steps of `step_s` seconds, cut into
    /// `subintervals` pieces (clamped to 1 ..= steps_per_interval), with continuous PSDs
    /// `psd` = (accelerometer (m/s²)²/Hz, gyro rad²/s, bias RW (m/s²)²/s, drift RW (rad/s)²/s).
    pub fn new(steps_per_interval: usize, subintervals: usize, step_s: f64, psd: [f64; 4]) -> Self {
        let steps_per_interval = steps_per_interval.max(1);
        let mut w = Mat15::zeros();
        for i in 0..3 {
            w[(3 + i, 3 + i)] = psd[0];
            w[(6 + i, 6 + i)] = psd[1];
            w[(9 + i, 9 + i)] = psd[2];
            w[(12 + i, 12 + i)] = psd[3];
        }
        Self {
            steps_per_interval,
            subintervals: subintervals.clamp(1, steps_per_interval),
            step_s,
            w,
            n: 0,
            sum_lat: 0.0,
            sum_lon: 0.0,
            sum_alt: 0.0,
            sum_vel: Vector3::zeros(),
            sum_f: Vector3::zeros(),
            sum_c: Matrix3::zeros(),
            sum_dt: 0.0,
            all_nominal: true,
            steps_done: 0,
            sub_done: 0,
            phi: Transition::from_dense(&Mat15::identity()),
            q: Mat15::zeros(),
            basis_on: false,
            basis: [Mat15::zeros(); 4],
            basis_taken: [Mat15::zeros(); 4],
        }
    }

    /// Also accumulates, per interval, the noise matrices B_k of the four noise inputs at unit
    /// density (accelerometer white noise on δv, gyro white noise on ψ, random walks on ∇ and
    /// ε): Q_T = Σ_k psd_k B_k exactly (Q_T is linear in W). Read them with
    /// [`IntervalModel::noise_basis`] after [`IntervalModel::take`]. Costs four more
    /// discretisations per sub-interval.
    pub fn enable_noise_basis(&mut self) {
        self.basis_on = true;
    }

    /// The B_k of the interval returned by the last [`IntervalModel::take`] (zeros unless
    /// [`IntervalModel::enable_noise_basis`]).
    pub fn noise_basis(&self) -> &[Mat15; 4] {
        &self.basis_taken
    }

    /// The constant W = G Q_c Gᵀ (state units² / s).
    pub fn noise_density(&self) -> &Mat15 {
        &self.w
    }

    /// Adds the linearisation point after one INS step of the nominal length. Closes a
    /// sub-interval when due.
    #[inline]
    pub fn push(&mut self, lp: &LinearizationPoint) {
        self.push_dt(lp, self.step_s);
    }

    /// Adds the linearisation point after one INS step of `dt_s` seconds (irregular samples).
    /// Sub-intervals still close after `steps_per_interval / subintervals` steps; the
    /// sub-interval's length is the sum of its steps (n·T_s exactly when every step was
    /// nominal), and the averages are plain means over the steps (for steps of unequal length
    /// a first-order approximation of the time average).
    #[inline]
    pub fn push_dt(&mut self, lp: &LinearizationPoint, dt_s: f64) {
        self.n += 1;
        self.sum_dt += dt_s;
        self.all_nominal &= dt_s == self.step_s;
        self.sum_lat += lp.pos.lat_rad;
        self.sum_lon += lp.pos.lon_rad;
        self.sum_alt += lp.pos.alt_m;
        self.sum_vel += lp.vel_ned_mps;
        self.sum_f += lp.specific_force_ned_mps2;
        self.sum_c += lp.c_b_to_n;
        self.steps_done += 1;
        let end = ((self.sub_done + 1) * self.steps_per_interval) / self.subintervals;
        if self.steps_done >= end {
            self.close_subinterval();
        }
    }

    fn close_subinterval(&mut self) {
        if self.n == 0 {
            return;
        }
        let inv = 1.0 / self.n as f64;
        let lp = LinearizationPoint {
            pos: Geodetic {
                lat_rad: self.sum_lat * inv,
                lon_rad: self.sum_lon * inv,
                alt_m: self.sum_alt * inv,
            },
            vel_ned_mps: self.sum_vel * inv,
            specific_force_ned_mps2: self.sum_f * inv,
            c_b_to_n: self.sum_c * inv,
        };
        let a = error_model::system_matrix(&lp);
        let tau_s = if self.all_nominal {
            self.n as f64 * self.step_s
        } else {
            self.sum_dt
        };
        let (phi_s, q_s) = error_model::discretize_fast(&a, &self.w, tau_s);
        let phi11: SMatrix<f64, 9, 9> = phi_s.phi11 * self.phi.phi11;
        let phi12: SMatrix<f64, 9, 6> = phi_s.phi11 * self.phi.phi12 + phi_s.phi12;
        self.phi = Transition { phi11, phi12 };
        error_model::propagate_covariance(&mut self.q, &phi_s, &q_s);
        if self.basis_on {
            for (k, b) in self.basis.iter_mut().enumerate() {
                let mut w = Mat15::zeros();
                for i in 0..3 {
                    w[(3 + 3 * k + i, 3 + 3 * k + i)] = 1.0;
                }
                let (phi_k, q_k) = error_model::discretize_fast(&a, &w, tau_s);
                error_model::propagate_covariance(b, &phi_k, &q_k);
            }
        }
        self.sub_done += 1;
        self.n = 0;
        self.sum_lat = 0.0;
        self.sum_lon = 0.0;
        self.sum_alt = 0.0;
        self.sum_vel = Vector3::zeros();
        self.sum_f = Vector3::zeros();
        self.sum_c = Matrix3::zeros();
        self.sum_dt = 0.0;
        self.all_nominal = true;
    }

    /// Number of INS steps pushed since the last [`IntervalModel::take`].
    pub fn steps_done(&self) -> usize {
        self.steps_done
    }

    /// (Φ, Q) from the last [`IntervalModel::take`] to now, without starting a new interval
    /// (works on a copy; for predictions between updates).
    pub fn peek(&self) -> (Mat15, Mat15) {
        let mut copy = self.clone();
        copy.take()
    }

    /// Returns (Φ_T dense, Q_T) for the steps pushed since the last call (closing a partial
    /// sub-interval) and starts a new interval.
    pub fn take(&mut self) -> (Mat15, Mat15) {
        self.close_subinterval();
        let out = (self.phi.to_dense(), self.q);
        self.phi = Transition::from_dense(&Mat15::identity());
        self.q = Mat15::zeros();
        if self.basis_on {
            self.basis_taken = self.basis;
            self.basis = [Mat15::zeros(); 4];
        }
        self.steps_done = 0;
        self.sub_done = 0;
        out
    }
}
