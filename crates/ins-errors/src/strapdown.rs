//! Strapdown INS mechanization in the local-level NED frame, with feedback corrections.
//!
//! # Equations (continuous time)
//!
//! ```text
//! Ċ_b^n = C_b^n [ω_nb^b×],       ω_nb^b = ω_ib^b − C_n^b (Ω + ρ)
//! v̇^n   = C_b^n f_b + g^n(L, h) − (2Ω + ρ) × v^n
//! L̇ = v_N/(R_N + h),  λ̇ = v_E/((R_E + h) cosL),  ḣ = −v_D
//! ```
//!
//! (Ω, ρ, g, R_N, R_E from [`crate::earth`]). The measured f̃_b, ω̃_ib^b are first corrected by
//! the current sensor-error estimates: f_b = f̃_b − ∇̂, ω_ib^b = ω̃_ib^b − ε̂.
//!
//! # Discretisation (one step of T_s, second order)
//!
//! The IMU sample for [t_k, t_k+1] is taken as the interval's midpoint value. Midpoint
//! navigation quantities are predicted: v_mid = v_k + (v_k − v_{k−1})/2, (L, h)_mid from
//! v_mid; ω_in = Ω + ρ at the midpoint. With the half-step rotations
//! h_b = exp(ω_ib T_s/2), h_n = exp(−ω_in T_s/2) (quaternions):
//!
//! ```text
//! q_mid = h_n ⊗ q_k ⊗ h_b,   q_{k+1} = h_n ⊗ q_mid ⊗ h_b        (exact for constant rates)
//! v_{k+1} = v_k + T_s [ q_mid f_b + g(L_mid, h_mid) − (2Ω + ρ)_mid × v_mid ]
//! p_{k+1} = p_k + T_s · rates(L_mid, h_mid, (v_k + v_{k+1})/2)
//! ```
//!
//! Local truncation error O(T_s³) in v and p, so global O(T_s²): with the paper's flight the
//! perfect-sensor run stays within millimetres of the truth over 900 s (see the tests).
//!
//! # Corrections (feedback)
//!
//! [`Strapdown::apply_correction`] removes estimated errors in the contract's conventions
//! (δ = computed − true; ψ the psi-angle; see the crate doc): the position is moved by −δp,
//! the velocity becomes C_c^t (ṽ − δv) and the attitude C_b^t = C_c^t exp([ψ×]) C̃_b^n, with
//! C_c^t the exact rotation between the local-level frames at the old and new positions
//! (≈ I + [δθ×]; so the attitude is corrected by φ = ψ + δθ).

use nalgebra::{Matrix3, Quaternion, UnitQuaternion, Vector3};

use crate::earth::{self, Geodetic, LocalFrame};
use crate::error::InsError;

/// Navigation state: position, NED velocity and attitude C_b^n.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NavState {
    /// Geodetic position.
    pub pos: Geodetic,
    /// Ground velocity, NED, m/s.
    pub vel_ned_mps: Vector3<f64>,
    /// Attitude C_b^n (body FRD → NED).
    pub att_b_to_n: UnitQuaternion<f64>,
}

impl NavState {
    fn is_finite(&self) -> bool {
        self.pos.lat_rad.is_finite()
            && self.pos.lon_rad.is_finite()
            && self.pos.alt_m.is_finite()
            && self.vel_ned_mps.iter().all(|x| x.is_finite())
            && self.att_b_to_n.coords.iter().all(|x| x.is_finite())
    }
}

/// Quantities at which the error model is linearised (the INS's own outputs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LinearizationPoint {
    /// Computed position.
    pub pos: Geodetic,
    /// Computed velocity, NED, m/s.
    pub vel_ned_mps: Vector3<f64>,
    /// f_n = C̃_b^n f_b (corrected specific force in NED), m/s².
    pub specific_force_ned_mps2: Vector3<f64>,
    /// C̃_b^n as a DCM.
    pub c_b_to_n: Matrix3<f64>,
}

/// The strapdown INS.
#[derive(Clone, Debug)]
pub struct Strapdown {
    state: NavState,
    prev_vel_ned_mps: Option<Vector3<f64>>,
    step_s: f64,
    t_s: f64,
    accel_bias_est_body_mps2: Vector3<f64>,
    gyro_drift_est_body_radps: Vector3<f64>,
    last_specific_force_ned_mps2: Vector3<f64>,
    /// Local frame at the previous step's midpoint (radii for the half-step prediction).
    frame: LocalFrame,
}

/// exp of a rotation vector as a unit quaternion; for |v| < 0.01 rad a series exact to rounding
/// (the next term is (|v|/2)⁸/8! < 1e-23), else the trigonometric form.
#[inline]
fn exp_quat(v: &Vector3<f64>) -> UnitQuaternion<f64> {
    let t2 = v.norm_squared();
    if t2 < 1e-4 {
        let h2 = 0.25 * t2;
        let c = 1.0 - h2 / 2.0 + h2 * h2 / 24.0 - h2 * h2 * h2 / 720.0;
        let sc = 0.5 * (1.0 - h2 / 6.0 + h2 * h2 / 120.0 - h2 * h2 * h2 / 5040.0);
        UnitQuaternion::new_unchecked(Quaternion::new(c, sc * v.x, sc * v.y, sc * v.z))
    } else {
        UnitQuaternion::from_scaled_axis(*v)
    }
}

impl Strapdown {
    /// Starts the INS at `initial` (time 0) with sample step `step_s` (s).
    pub fn new(initial: NavState, step_s: f64) -> Result<Self, InsError> {
        if !(step_s.is_finite() && step_s > 0.0) {
            return Err(InsError::InvalidArgument {
                func: "Strapdown::new",
                arg: "step_s",
                requirement: "must be finite and > 0",
                value: format!("{step_s:?}"),
            });
        }
        if !initial.is_finite() || initial.pos.lat_rad.abs() >= std::f64::consts::FRAC_PI_2 {
            return Err(InsError::InvalidArgument {
                func: "Strapdown::new",
                arg: "initial",
                requirement: "must be finite with |lat| < 90°",
                value: format!("{initial:?}"),
            });
        }
        let g = earth::gravity_ned_mps2(initial.pos.lat_rad, initial.pos.alt_m);
        Ok(Self {
            state: initial,
            prev_vel_ned_mps: None,
            step_s,
            t_s: 0.0,
            accel_bias_est_body_mps2: Vector3::zeros(),
            gyro_drift_est_body_radps: Vector3::zeros(),
            last_specific_force_ned_mps2: -g,
            frame: LocalFrame::new(initial.pos.lat_rad, initial.pos.alt_m),
        })
    }

    /// Current navigation state.
    #[inline]
    pub fn state(&self) -> &NavState {
        &self.state
    }

    /// Time since start, s.
    #[inline]
    pub fn time_s(&self) -> f64 {
        self.t_s
    }

    /// Step T_s, s.
    #[inline]
    pub fn step_s(&self) -> f64 {
        self.step_s
    }

    /// Current sensor-error estimates (∇̂ body m/s², ε̂ body rad/s) subtracted from the raw
    /// measurements.
    pub fn sensor_corrections(&self) -> (Vector3<f64>, Vector3<f64>) {
        (
            self.accel_bias_est_body_mps2,
            self.gyro_drift_est_body_radps,
        )
    }

    /// Replaces the sensor-error estimates.
    pub fn set_sensor_corrections(
        &mut self,
        accel_bias_body_mps2: &Vector3<f64>,
        gyro_drift_body_radps: &Vector3<f64>,
    ) {
        self.accel_bias_est_body_mps2 = *accel_bias_body_mps2;
        self.gyro_drift_est_body_radps = *gyro_drift_body_radps;
    }

    /// Adds estimated residual sensor errors to the corrections (feedback of the filter's
    /// ∇, ε states, which then reset to zero).
    pub fn add_sensor_corrections(
        &mut self,
        accel_bias_body_mps2: &Vector3<f64>,
        gyro_drift_body_radps: &Vector3<f64>,
    ) {
        self.accel_bias_est_body_mps2 += accel_bias_body_mps2;
        self.gyro_drift_est_body_radps += gyro_drift_body_radps;
    }

    /// Linearisation point for [`crate::error_model`]: computed position and velocity,
    /// f_n = C̃ f_b of the last step (midpoint) and C̃_b^n.
    pub fn linearization_point(&self) -> LinearizationPoint {
        LinearizationPoint {
            pos: self.state.pos,
            vel_ned_mps: self.state.vel_ned_mps,
            specific_force_ned_mps2: self.last_specific_force_ned_mps2,
            c_b_to_n: self.state.att_b_to_n.to_rotation_matrix().into_inner(),
        }
    }

    /// One mechanization step with raw measurements (f̃_b m/s², ω̃_ib^b rad/s) representing the
    /// interval [t, t + T_s]. Allocation-free.
    #[inline]
    pub fn step(
        &mut self,
        specific_force_body_mps2: &Vector3<f64>,
        ang_rate_ib_body_radps: &Vector3<f64>,
    ) {
        self.step_with_dt(
            specific_force_body_mps2,
            ang_rate_ib_body_radps,
            self.step_s,
        );
    }

    /// One mechanization step over an interval of `dt_s` seconds instead of the nominal T_s
    /// (irregular or dropped IMU samples): the same equations with T_s replaced by `dt_s`;
    /// [`Strapdown::step`] is this with `dt_s = T_s`. The midpoint-velocity extrapolation
    /// assumes the previous step had the same length, so the step is second order only at a
    /// regular rate (first order across a change of step). The caller checks `dt_s` is finite
    /// and > 0 (the online filter of `ins-sd-filter` does). Allocation-free.
    pub fn step_with_dt(
        &mut self,
        specific_force_body_mps2: &Vector3<f64>,
        ang_rate_ib_body_radps: &Vector3<f64>,
        dt_s: f64,
    ) {
        let ts = dt_s;
        let f_b = specific_force_body_mps2 - self.accel_bias_est_body_mps2;
        let w_b = ang_rate_ib_body_radps - self.gyro_drift_est_body_radps;
        let s = &self.state;
        let v_k = s.vel_ned_mps;
        let v_mid = match self.prev_vel_ned_mps {
            Some(p) => 1.5 * v_k - 0.5 * p,
            None => v_k,
        };
        let r0 = self.frame.geodetic_rates(&v_mid);
        let lat_mid = s.pos.lat_rad + 0.5 * ts * r0.x;
        let alt_mid = s.pos.alt_m + 0.5 * ts * r0.z;
        let lf = self.frame.near(lat_mid, alt_mid);
        let omega = lf.earth_rate_ned_radps;
        let rho = lf.transport_rate_ned_radps(&v_mid);
        let hb = exp_quat(&(w_b * (0.5 * ts)));
        let hn = exp_quat(&((omega + rho) * (-0.5 * ts)));
        let q_mid = hn * s.att_b_to_n * hb;
        let mut q_next = hn * q_mid * hb;
        q_next.renormalize_fast();
        let f_n = q_mid * f_b;
        let g = Vector3::new(0.0, 0.0, lf.gravity_mps2);
        let v_next = v_k + ts * (f_n + g - (2.0 * omega + rho).cross(&v_mid));
        let r = lf.geodetic_rates(&(0.5 * (v_k + v_next)));
        let pos = Geodetic {
            lat_rad: s.pos.lat_rad + ts * r.x,
            lon_rad: s.pos.lon_rad + ts * r.y,
            alt_m: s.pos.alt_m + ts * r.z,
        };
        self.frame = lf;
        self.prev_vel_ned_mps = Some(v_k);
        self.last_specific_force_ned_mps2 = f_n;
        self.state = NavState {
            pos,
            vel_ned_mps: v_next,
            att_b_to_n: q_next,
        };
        self.t_s += ts;
    }

    /// Feedback correction of the navigation state by estimated errors (contract conventions,
    /// δ = computed − true): `pos_err_ned_m` δp (m, NED), `vel_err_ned_mps` δv (m/s, NED),
    /// `psi_rad` ψ (rad). See the module doc for the exact update.
    pub fn apply_correction(
        &mut self,
        pos_err_ned_m: &Vector3<f64>,
        vel_err_ned_mps: &Vector3<f64>,
        psi_rad: &Vector3<f64>,
    ) {
        let old = self.state;
        let new_pos = earth::displace_by_ned_m(&old.pos, &(-pos_err_ned_m));
        let c_c_to_t = earth::ned_from_ecef(new_pos.lat_rad, new_pos.lon_rad)
            * earth::ned_from_ecef(old.pos.lat_rad, old.pos.lon_rad).transpose();
        if !(c_c_to_t.iter().all(|x| x.is_finite()) && psi_rad.iter().all(|x| x.is_finite())) {
            // A non-finite correction (a diverged filter): the state becomes non-finite, which
            // every caller checks, instead of `from_matrix` iterating on NaN forever.
            self.state.pos.lat_rad = f64::NAN;
            self.state.vel_ned_mps = Vector3::from_element(f64::NAN);
            return;
        }
        let q_ct = UnitQuaternion::from_matrix(&c_c_to_t);
        let v_new = c_c_to_t * (old.vel_ned_mps - vel_err_ned_mps);
        let q_fix = q_ct * UnitQuaternion::from_scaled_axis(*psi_rad);
        let q_new = q_fix * old.att_b_to_n;
        if let Some(p) = self.prev_vel_ned_mps.as_mut() {
            *p += v_new - old.vel_ned_mps;
        }
        self.last_specific_force_ned_mps2 = q_fix * self.last_specific_force_ned_mps2;
        self.state = NavState {
            pos: new_pos,
            vel_ned_mps: v_new,
            att_b_to_n: q_new,
        };
    }
}
