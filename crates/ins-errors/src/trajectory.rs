//! Truth trajectory of the paper's flight and the ideal IMU outputs consistent with it.
//!
//! # Kinematics
//!
//! The flight is described by speed V, heading (course) χ and flight-path angle γ, each
//! changing linearly inside a segment ([`crate::config::SegmentConfig`]):
//! V(t) = V₀ + a·(t − t₀), χ(t) = χ₀ + χ̇·(t − t₀), γ(t) = γ₀ + γ̇·(t − t₀). Then
//!
//! ```text
//! v^n = V u,  u = (cosγ cosχ, cosγ sinχ, −sinγ)               (NED, ground-relative)
//! v̇^n = a u + V (γ̇ ∂u/∂γ + χ̇ ∂u/∂χ)
//! ```
//!
//! Attitude: the body x axis is along the velocity, no sideslip, no bank ("flat" skid turns,
//! roll ≡ 0 so the body rates stay bounded at segment boundaries):
//! C_b^n = R_z(χ) R_y(γ), ω_nb^b = (−χ̇ sinγ, γ̇, χ̇ cosγ).
//!
//! Position: per step, the NED displacement ∫v dt by Simpson's rule on the analytic velocity
//! (t_k, midpoint, t_k+1), converted to (δL, δλ, δh) with the radii at the midpoint position
//! (local error ~T_s⁵·|v⁗| plus ~1e-21 rad from the radii variation; far below the INS's own).
//!
//! # Ideal IMU outputs (same Earth model as the mechanization)
//!
//! ```text
//! f_b    = C_n^b ( v̇^n + (2Ω + ρ) × v^n − g^n )
//! ω_ib^b = ω_nb^b + C_n^b (Ω + ρ)
//! ```
//!
//! with Ω, ρ, g^n from [`crate::earth`]. Sample k ([`TruthSample`]) holds the true state at
//! t_k = k·T_s and the IMU output for the interval [t_k, t_k + T_s], evaluated at the
//! interval midpoint t_k + T_s/2 (position there from the quadratic velocity interpolant). Midpoint
//! values are the interval means to O(T_s²) — the representation that a second-order
//! mechanization ([`crate::strapdown`]) integrates with O(T_s²) global error.

use nalgebra::{Matrix3, Quaternion, UnitQuaternion, Vector3};

use crate::config::TrajectoryConfig;
use crate::earth::{Geodetic, LocalFrame};
use crate::error::InsError;
use crate::strapdown::NavState;

/// True state at one sample time plus the ideal IMU output for the following interval.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TruthSample {
    /// Time t_k, s.
    pub t_s: f64,
    /// True position at t_k.
    pub pos: Geodetic,
    /// True ground velocity at t_k, NED, m/s.
    pub vel_ned_mps: Vector3<f64>,
    /// True attitude C_b^n (body FRD → NED) at t_k.
    pub att_b_to_n: UnitQuaternion<f64>,
    /// Ideal specific force f_b for [t_k, t_k + T_s] (midpoint value), body, m/s².
    pub specific_force_body_mps2: Vector3<f64>,
    /// Ideal angular rate ω_ib^b for [t_k, t_k + T_s] (midpoint value), body, rad/s.
    pub ang_rate_ib_body_radps: Vector3<f64>,
}

impl TruthSample {
    /// The true navigation state (position, velocity, attitude) at t_k — e.g. to start a
    /// strapdown INS at the truth.
    pub fn nav_state(&self) -> NavState {
        NavState {
            pos: self.pos,
            vel_ned_mps: self.vel_ned_mps,
            att_b_to_n: self.att_b_to_n,
        }
    }
}

#[derive(Clone, Copy, Debug)]
struct Segment {
    t0_s: f64,
    t1_s: f64,
    speed0_mps: f64,
    heading0_rad: f64,
    path0_rad: f64,
    accel_mps2: f64,
    heading_rate_radps: f64,
    path_rate_radps: f64,
    /// sin/cos of χ̇·T_s/4 and γ̇·T_s/4 (half-angle increments per half step).
    quarter_step_heading_sin_cos: (f64, f64),
    quarter_step_path_sin_cos: (f64, f64),
}

/// Kinematic state (V, χ, γ) and rates at an instant.
#[derive(Clone, Copy, Debug)]
struct Kin {
    vel_ned_mps: Vector3<f64>,
    acc_ned_mps2: Vector3<f64>,
    heading_rate_radps: f64,
    path_rate_radps: f64,
    sin_heading: f64,
    cos_heading: f64,
    sin_path: f64,
    cos_path: f64,
    /// sin(χ/2), cos(χ/2), sin(γ/2), cos(γ/2).
    half: [f64; 4],
}

impl Kin {
    /// C_b^n = R_z(χ) R_y(γ) from the cached sines and cosines.
    #[inline]
    fn c_b_to_n(&self) -> Matrix3<f64> {
        let (sc, cc, sg, cg) = (
            self.sin_heading,
            self.cos_heading,
            self.sin_path,
            self.cos_path,
        );
        Matrix3::new(cc * cg, -sc, cc * sg, sc * cg, cc, sc * sg, -sg, 0.0, cg)
    }

    /// q_b^n = q_z(χ) ⊗ q_y(γ) = (c_χ c_γ, −s_χ s_γ, c_χ s_γ, s_χ c_γ) in half angles.
    fn att_b_to_n(&self) -> UnitQuaternion<f64> {
        let [sc, cc, sg, cg] = self.half;
        UnitQuaternion::new_unchecked(Quaternion::new(cc * cg, -sc * sg, cc * sg, sc * cg))
    }
}

impl Segment {
    fn kin(&self, t_s: f64) -> Kin {
        let dt = t_s - self.t0_s;
        let chi = self.heading0_rad + self.heading_rate_radps * dt;
        let gam = self.path0_rad + self.path_rate_radps * dt;
        let (sc, cc) = (0.5 * chi).sin_cos();
        let (sg, cg) = (0.5 * gam).sin_cos();
        self.kin_from_trig(t_s, [sc, cc, sg, cg])
    }

    /// Kinematics at `t_s` (= t(prev) + T_s/2) by rotating `prev`'s half heading and path angles
    /// by the quarter-step increments (angle-addition recurrence, no trigonometric calls;
    /// rounding drift ~1e-16 per step, tested against the direct evaluation).
    #[inline]
    fn advance_half_step(&self, prev: &Kin, t_s: f64) -> Kin {
        let (sd, cd) = self.quarter_step_heading_sin_cos;
        let (sp, cp) = self.quarter_step_path_sin_cos;
        let [sc0, cc0, sg0, cg0] = prev.half;
        self.kin_from_trig(
            t_s,
            [
                sc0 * cd + cc0 * sd,
                cc0 * cd - sc0 * sd,
                sg0 * cp + cg0 * sp,
                cg0 * cp - sg0 * sp,
            ],
        )
    }

    #[inline]
    fn kin_from_trig(&self, t_s: f64, half: [f64; 4]) -> Kin {
        let [hsc, hcc, hsg, hcg] = half;
        let (sc, cc) = (2.0 * hsc * hcc, hcc * hcc - hsc * hsc);
        let (sg, cg) = (2.0 * hsg * hcg, hcg * hcg - hsg * hsg);
        let v = self.speed0_mps + self.accel_mps2 * (t_s - self.t0_s);
        let u = Vector3::new(cg * cc, cg * sc, -sg);
        let du_dg = Vector3::new(-sg * cc, -sg * sc, -cg);
        let du_dc = Vector3::new(-cg * sc, cg * cc, 0.0);
        Kin {
            vel_ned_mps: v * u,
            acc_ned_mps2: self.accel_mps2 * u
                + v * (self.path_rate_radps * du_dg + self.heading_rate_radps * du_dc),
            heading_rate_radps: self.heading_rate_radps,
            path_rate_radps: self.path_rate_radps,
            sin_heading: sc,
            cos_heading: cc,
            sin_path: sg,
            cos_path: cg,
            half,
        }
    }
}

/// A validated truth trajectory (segment table); generate samples with [`Trajectory::samples`]
/// or [`Trajectory::fill`].
#[derive(Clone, Debug)]
pub struct Trajectory {
    segments: Vec<Segment>,
    start: Geodetic,
    step_s: f64,
    n_steps: usize,
}

impl Trajectory {
    /// Builds the segment table from a config (validated first).
    pub fn new(cfg: &TrajectoryConfig) -> Result<Self, InsError> {
        cfg.validate()?;
        let mut segments = Vec::with_capacity(cfg.segments.len() + 1);
        let mut t = 0.0;
        let mut v = cfg.start_speed_mps;
        let mut chi = cfg.start_heading_deg.to_radians();
        let mut gam = cfg.start_path_angle_deg.to_radians();
        for s in &cfg.segments {
            let seg = Segment {
                t0_s: t,
                t1_s: t + s.duration_s,
                speed0_mps: v,
                heading0_rad: chi,
                path0_rad: gam,
                accel_mps2: s.along_accel_mps2,
                heading_rate_radps: s.turn_rate_degps.to_radians(),
                path_rate_radps: s.path_angle_rate_degps.to_radians(),
                quarter_step_heading_sin_cos: (0.25 * cfg.step_s * s.turn_rate_degps.to_radians())
                    .sin_cos(),
                quarter_step_path_sin_cos: (0.25
                    * cfg.step_s
                    * s.path_angle_rate_degps.to_radians())
                .sin_cos(),
            };
            t = seg.t1_s;
            v += seg.accel_mps2 * s.duration_s;
            chi += seg.heading_rate_radps * s.duration_s;
            gam += seg.path_rate_radps * s.duration_s;
            segments.push(seg);
        }
        segments.push(Segment {
            t0_s: t,
            t1_s: f64::INFINITY,
            speed0_mps: v,
            heading0_rad: chi,
            path0_rad: gam,
            accel_mps2: 0.0,
            heading_rate_radps: 0.0,
            path_rate_radps: 0.0,
            quarter_step_heading_sin_cos: (0.0, 1.0),
            quarter_step_path_sin_cos: (0.0, 1.0),
        });
        let n_steps = (cfg.end_time_s / cfg.step_s).round() as usize;
        Ok(Self {
            segments,
            start: Geodetic::from_deg(cfg.start_lat_deg, cfg.start_lon_deg, cfg.start_alt_m),
            step_s: cfg.step_s,
            n_steps,
        })
    }

    /// Sample step T_s, s.
    pub fn step_s(&self) -> f64 {
        self.step_s
    }

    /// Number of INS steps N (end_time/T_s); there are N + 1 samples, t = 0 … N·T_s.
    pub fn n_steps(&self) -> usize {
        self.n_steps
    }

    /// Number of samples produced, N + 1.
    pub fn n_samples(&self) -> usize {
        self.n_steps + 1
    }

    /// Start position.
    pub fn start(&self) -> Geodetic {
        self.start
    }

    /// Iterator over the N + 1 samples (no allocation per step).
    pub fn samples(&self) -> TruthGenerator<'_> {
        TruthGenerator::new(self)
    }

    /// Fills a caller-owned buffer of exactly [`Trajectory::n_samples`] samples.
    pub fn fill(&self, out: &mut [TruthSample]) -> Result<(), InsError> {
        if out.len() != self.n_samples() {
            return Err(InsError::BufferLength {
                what: "Trajectory::fill out",
                expected: self.n_samples(),
                got: out.len(),
            });
        }
        for (o, s) in out.iter_mut().zip(self.samples()) {
            *o = s;
        }
        Ok(())
    }

    /// Sum of the manoeuvre durations plus the final straight leg: ground distance flown over
    /// [0, N·T_s] computed from the speed profile, m.
    pub fn distance_m(&self) -> f64 {
        let t_end = self.n_steps as f64 * self.step_s;
        let mut d = 0.0;
        for s in &self.segments {
            let t1 = s.t1_s.min(t_end);
            if t1 <= s.t0_s {
                break;
            }
            let dt = t1 - s.t0_s;
            d += s.speed0_mps * dt + 0.5 * s.accel_mps2 * dt * dt;
        }
        d
    }
}

/// Iterator producing [`TruthSample`]s in time order.
#[derive(Clone, Debug)]
pub struct TruthGenerator<'a> {
    traj: &'a Trajectory,
    k: usize,
    seg: usize,
    /// (L rad, λ rad, h m) at t_k.
    pos: Vector3<f64>,
    /// Kinematics at t_k (from the previous step's end point).
    kin0: Option<(Kin, UnitQuaternion<f64>)>,
    /// Local frame near t_k (previous midpoint) for the half-step prediction.
    frame: LocalFrame,
}

impl<'a> TruthGenerator<'a> {
    fn new(traj: &'a Trajectory) -> Self {
        let s = traj.start;
        Self {
            traj,
            k: 0,
            seg: 0,
            pos: Vector3::new(s.lat_rad, s.lon_rad, s.alt_m),
            kin0: None,
            frame: LocalFrame::new(s.lat_rad, s.alt_m),
        }
    }
}

impl Iterator for TruthGenerator<'_> {
    type Item = TruthSample;

    fn next(&mut self) -> Option<TruthSample> {
        if self.k > self.traj.n_steps {
            return None;
        }
        let ts = self.traj.step_s;
        let t0 = self.k as f64 * ts;
        let tm = t0 + 0.5 * ts;
        let t1 = t0 + ts;
        while self.traj.segments[self.seg].t1_s <= tm {
            self.seg += 1;
        }
        let seg = &self.traj.segments[self.seg];
        let (k0, q0) = match self.kin0 {
            Some(k) => k,
            None => {
                let k = seg.kin(t0);
                (k, k.att_b_to_n())
            }
        };
        let km = seg.advance_half_step(&k0, tm);
        let k1 = seg.advance_half_step(&km, t1);
        let (v0, vm, v1) = (k0.vel_ned_mps, km.vel_ned_mps, k1.vel_ned_mps);
        // Displacements (NED, m) over the first half step and the full step: quadratic
        // interpolation of v through t0, tm, t1 (Simpson for the full step).
        let d_half = (5.0 * v0 + 8.0 * vm - v1) * (ts / 24.0);
        let d_full = (v0 + 4.0 * vm + v1) * (ts / 6.0);
        let p0 = self.pos;
        let pm = p0 + self.frame.geodetic_rates(&d_half);
        let lf = self.frame.near(pm.x, pm.z);
        // Radii at the midpoint: the product error is ~T_s³·(d/dt 1/(R+h))·a ≈ 1e-21 rad/step.
        let p1 = p0 + lf.geodetic_rates(&d_full);
        // Ideal IMU at the midpoint.
        let omega = lf.earth_rate_ned_radps;
        let rho = lf.transport_rate_ned_radps(&vm);
        let g = Vector3::new(0.0, 0.0, lf.gravity_mps2);
        let c_mid = km.c_b_to_n();
        let f_n = km.acc_ned_mps2 + (2.0 * omega + rho).cross(&vm) - g;
        let w_nb = Vector3::new(
            -km.heading_rate_radps * km.sin_path,
            km.path_rate_radps,
            km.heading_rate_radps * km.cos_path,
        );
        let sample = TruthSample {
            t_s: t0,
            pos: Geodetic {
                lat_rad: p0.x,
                lon_rad: p0.y,
                alt_m: p0.z,
            },
            vel_ned_mps: v0,
            att_b_to_n: q0,
            specific_force_body_mps2: c_mid.tr_mul(&f_n),
            ang_rate_ib_body_radps: w_nb + c_mid.tr_mul(&(omega + rho)),
        };
        self.pos = p1;
        self.frame = lf;
        self.kin0 = Some((k1, k1.att_b_to_n()));
        self.k += 1;
        Some(sample)
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        let n = self.traj.n_steps + 1 - self.k.min(self.traj.n_steps + 1);
        (n, Some(n))
    }
}

impl ExactSizeIterator for TruthGenerator<'_> {}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::earth;

    #[test]
    fn paper_flight_figures() {
        let tr = Trajectory::new(&TrajectoryConfig::paper()).unwrap();
        assert_eq!(tr.n_samples(), 90_001);
        let d = tr.distance_m();
        assert!((27_000.0..=30_000.0).contains(&d), "distance {d}");
        let mut max_acc: f64 = 0.0;
        let mut last = None;
        let mut path = 0.0;
        for s in tr.samples() {
            // Kinematic acceleration from the specific force: a = C f + g − (2Ω+ρ)×v (≈ C f + g).
            let f_n = s.att_b_to_n * s.specific_force_body_mps2;
            let a = f_n + earth::gravity_ned_mps2(s.pos.lat_rad, s.pos.alt_m);
            max_acc = max_acc.max(a.norm());
            assert!((25.0..=37.0).contains(&s.vel_ned_mps.norm()));
            if let Some(p) = last {
                path += earth::pos_err_ned_m(&s.pos, &p).norm();
            }
            last = Some(s.pos);
        }
        assert!(max_acc <= 0.8, "max acceleration {max_acc}");
        assert!(
            (path - d).abs() < 1.0,
            "integrated path {path} vs profile {d}"
        );
        let end = last.unwrap();
        assert!((end.alt_m - 6000.0).abs() < 50.0);
    }

    #[test]
    fn angle_recurrence_matches_direct_evaluation() {
        let tr = Trajectory::new(&TrajectoryConfig::paper()).unwrap();
        let last = tr.samples().last().unwrap();
        let seg = tr.segments.last().unwrap();
        let direct = seg.kin(last.t_s);
        let q = direct.att_b_to_n();
        assert!(
            q.angle_to(&last.att_b_to_n) < 1e-12,
            "{}",
            q.angle_to(&last.att_b_to_n)
        );
        assert!((direct.vel_ned_mps - last.vel_ned_mps).norm() < 1e-10);
        // Half-angle quaternion and C_b^n = R_z(χ) R_y(γ) agree with nalgebra's yaw-pitch-roll.
        let (chi, gam) = (2.3_f64, -0.2_f64);
        let k = Segment {
            heading0_rad: chi,
            path0_rad: gam,
            ..*seg
        }
        .kin(seg.t0_s);
        let reference = UnitQuaternion::from_euler_angles(0.0, gam, chi);
        assert!(k.att_b_to_n().angle_to(&reference) < 1e-15);
        assert!((k.c_b_to_n() - reference.to_rotation_matrix().into_inner()).norm() < 1e-15);
    }

    #[test]
    fn fill_checks_length() {
        let mut cfg = TrajectoryConfig::paper();
        cfg.end_time_s = 1.0;
        cfg.segments.clear();
        let tr = Trajectory::new(&cfg).unwrap();
        let mut buf = vec![tr.samples().next().unwrap(); 5];
        assert!(matches!(
            tr.fill(&mut buf),
            Err(InsError::BufferLength { expected: 101, .. })
        ));
        let mut buf = vec![buf[0]; 101];
        tr.fill(&mut buf).unwrap();
        assert_eq!(buf[100].t_s, 1.0);
    }

    #[test]
    fn imu_outputs_are_derivatives_of_the_truth() {
        // Check f_b and ω_ib against central differences of the sampled truth (independent
        // of the formulas above except the Earth model): Ċ = C[ω_nb×], ω_nb = ω_ib − C^T(Ω+ρ).
        let tr = Trajectory::new(&TrajectoryConfig::paper()).unwrap();
        let s: Vec<TruthSample> = tr.samples().skip(13_000).take(3).collect();
        let ts = tr.step_s();
        // Midpoint of [t1, t2] compared with differences over that interval.
        let (a, b) = (&s[1], &s[2]);
        let dq = a.att_b_to_n.inverse() * b.att_b_to_n;
        let w_nb_fd = dq.scaled_axis() / ts;
        let lat = 0.5 * (a.pos.lat_rad + b.pos.lat_rad);
        let alt = 0.5 * (a.pos.alt_m + b.pos.alt_m);
        let v = 0.5 * (a.vel_ned_mps + b.vel_ned_mps);
        let cm = a.att_b_to_n.slerp(&b.att_b_to_n, 0.5);
        let w_in = earth::earth_rate_ned_radps(lat) + earth::transport_rate_ned_radps(lat, alt, &v);
        let w_ib_fd = w_nb_fd + cm.inverse_transform_vector(&w_in);
        assert!(
            (w_ib_fd - a.ang_rate_ib_body_radps).norm() < 1e-9,
            "{w_ib_fd} {}",
            a.ang_rate_ib_body_radps
        );
        let acc = (b.vel_ned_mps - a.vel_ned_mps) / ts;
        let f_fd = cm.inverse_transform_vector(
            &(acc
                + (2.0 * earth::earth_rate_ned_radps(lat)
                    + earth::transport_rate_ned_radps(lat, alt, &v))
                .cross(&v)
                - earth::gravity_ned_mps2(lat, alt)),
        );
        assert!((f_fd - a.specific_force_body_mps2).norm() < 1e-6);
    }
}
