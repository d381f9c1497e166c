//! # ins-errors — strapdown INS, truth, IMU errors and the 15-state psi-angle error model
//!
//! Reference implementation of the inertial part of Lustosa, Chagas & Waldmann (ITA),
//! *sighting-device-aided INS with adaptive Kalman filtering* (§§2–3, eqs. 4–14, §6/Table 1).
//!
//! | module | content |
//! |---|---|
//! | [`earth`] | WGS-84: radii, normal gravity, Earth/transport rate, geodetic ↔ ECEF ↔ NED, position-error helpers |
//! | [`trajectory`] | truth of the §6 flight (segments of constant acceleration) and ideal f_b, ω_ib^b at 100 Hz |
//! | [`imu`] | random-constant bias/drift + per-sample white noise |
//! | [`strapdown`] | NED mechanization (quaternion), feedback corrections |
//! | [`error_model`] | A(t), G, Van Loan Φ/Q_d, fast series Φ, block covariance step, error extraction |
//! | [`config`] | serde `[trajectory]` / `[imu]` sections of `configs/paper.toml` |
//!
//! ## Conventions (binding contract with `sighting-model`)
//!
//! * Navigation frame n = NED at the vehicle; body b = FRD; ECEF e = WGS-84. Attitude C_b^n
//!   (body → NED), stored as a unit quaternion.
//! * Error state (15): δp (0..3, m, NED), δv (3..6, m/s, NED), ψ (6..9, rad), ∇ (9..12,
//!   accelerometer bias, body, m/s²), ε (12..15, gyro drift, body, rad/s).
//! * δ(·) = computed − true. δp_N = (R_N + h)δL, δp_E = (R_E + h) cosL δλ, δp_D = −δh
//!   ([`earth::pos_err_ned_m`] computes it exactly through ECEF).
//! * ψ (Benson psi-angle): c = NED at the computed position, t = NED at the true position,
//!   C_t^c = I − [δθ×], δθ = (δp_E/(R_E+h), −δp_N/(R_N+h), −δp_E tanL/(R_E+h))
//!   ([`earth::frame_tilt_rad`]); C̃_b^n = (I − [ψ×]) C_b^c with C_b^c = C_t^c C_b^t. The
//!   misalignment w.r.t. the true frame is φ = ψ + δθ. δv = ṽ^n − C_t^c v^t.
//!   [`error_model::error_state`] / [`error_model::inject_errors`] implement these exactly.
//! * Sensor errors: f̃_b = f_b + ∇ + w_a, ω̃_ib = ω_ib + ε + w_g.
//!
//! **Mapping to the paper's axes.** The paper's local frame is (north, west, up): paper axis 1 =
//! our N, axis 2 = −E, axis 3 = −D. This is our NED rotated by 180° about north,
//! T = diag(1, −1, −1) (a proper rotation, so the pseudo-vectors ψ, ε transform like δp):
//! x_paper = T x_ours for δp, δv, ψ, and B_paper = T A₉ₓ₉ T. Figures of the paper's "position
//! error 2" are −δp_E here, "3" is +δh = −δp_D.
//!
//! ## The model (paper eqs. 7–14) as implemented
//!
//! Paper eq. (7) is the navigation-error equation in vector form (second order in δp), eq. (8)
//! the ψ equation, eq. (9) the gravity error, eqs. (10)–(14) the state-space form
//! `ẋ = A x + w` with `A = [[B₉ₓ₉, [0; D; 0], [0; 0; −D]], [0], [0]]` (D = D_p^b = C̃_b^n). Written
//! as first-order equations in the computed frame c (see [`error_model`] for the derivation):
//!
//! ```text
//! δṗ = −ρ × δp + δv                                        (eq. 7, first-order form; B rows 1–3)
//! δv̇ = −(2Ω + ρ) × δv − ψ × f + C̃ ∇ + δg                   (eq. 7; B rows 4–6)
//! δg = G_p δp ≈ (g/R)(−δp_N, −δp_E, +2δp_D)                 (eq. 9 linearised; B columns 1–3)
//! ψ̇  = −(Ω + ρ) × ψ − C̃ ε                                  (eq. 8; B rows 7–9, eq. 14)
//! Ω = ω_ie (cosL, 0, −sinL),  ρ = (v_E/(R_E+h), −v_N/(R_N+h), −v_E tanL/(R_E+h))
//! ```
//!
//! all evaluated on the INS's own outputs (L̃, h̃, ṽ, f_n = C̃ f̃_b, C̃). Checks: the linear
//! propagation agrees with the nonlinear INS within 0.5 % of each group's (δp, δv, ψ) magnitude
//! over 100–120 s of manoeuvres (the residual is shown to be second order);
//! G_p matches central differences of the gravity model to 1e-4; the eigenvalues at rest give
//! the Schuler period 84.45 min (Foucault split 2Ω sinL) and τ = 571.1 s; a nonlinear stationary
//! INS gives 84.37 min and τ = 570.2 s (δh grows ×2.53 in 900 s).
//!
//! **Where the printed paper differs, and how (the numerical checks win):**
//! 1. Eq. (13) prints B as 9×10: the unit entries of rows 2–3 sit in columns 6–7 instead of 5–6,
//!    and the ψ columns of rows 4–9 are shifted one to the right (columns 8–10 instead of 7–9).
//!    Read with the columns realigned, every surviving entry agrees with T A₉ₓ₉ T above,
//!    given that the paper's axis 2 (west) carries no Earth rate (Ω₂ = 0): rows 1–3 are
//!    −[ω×]δp plus δv, rows 4–6 are −[(ω + 2Ω)×]δv − ψ × A with the gravity diagonal
//!    (−g/R, −g/R, +2g/R), rows 7–9 are −[(ω + Ω)×]ψ with p₁, p₂, p₃ of eq. (14). We use the
//!    9×9 form.
//! 2. Eq. (8) reads ψ̇ + ω × ψ = +ε while eq. (12) puts −D_p^b on ε. With the contract's ψ
//!    (C̃ = (I − [ψ×])C) and ε = measured − true, the derivation and the nonlinear check give
//!    −C̃ε, as in eq. (12); eq. (8)'s sign belongs to the opposite sign convention for ε or ψ.
//! 3. Eq. (9) prints −δp/‖δp‖³ where a spherical gravity gradient needs −δp/‖p‖³ (the
//!    expression as printed diverges for small δp). We linearise the WGS-84 normal gravity
//!    instead: horizontal −γ/(R_N + h), −γ/(R_E + h) (not one R), vertical −∂γ/∂h (≈ 2γ/R) plus
//!    the small (∂γ/∂L)/(R_N + h) δp_N coupling; all within 1 % of the printed (g/R)(−1, −1, 2).
//! 4. The bias/drift block uses C̃_b^n of the INS (D_p^b in the paper) — the same.
//!
//! ## Discretisation and the filter's hot path
//!
//! [`error_model::van_loan`] is exact (30×30 exponential, nalgebra's Padé scaling and squaring;
//! equals an independent Taylor exponential to 1.1e-16 at 0.01 s, 8.6e-15 at 1 s; Q_d equals a
//! 1000-step Simpson integral
//! to 1e-13 normalised). At the 0.01 s INS step the hot path uses
//! [`error_model::Transition::series`] (third-order series using the zero bias rows; 5.4e-13
//! relative to Van Loan on the paper's flight) and [`error_model::discretize_fast`] (Simpson on
//! [0, T]; Q_d within 7.9e-11 of √(Q_ii Q_jj) of Van Loan), and
//! [`error_model::propagate_covariance`] (block form, ≈ 3200 multiply-adds).
//!
//! ## Choices where the paper is silent (all in `configs/paper.toml`)
//!
//! * Flight: start 30 m/s, heading 120°, level; fifteen 40 s segments to 600 s (speed 30–36 m/s,
//!   turns ≤ 1.2 °/s, ±1° climb/descent, |a| ≤ 0.75 m/s²), straight at 40° to 900 s, 28.1 km,
//!   looping around the three landmarks. Attitude: body x along the velocity, zero roll (flat
//!   turns, so body rates stay bounded at segment boundaries).
//! * "3 mg", "2 °/h" are the σ of per-run random constants (Gaussian per axis; a
//!   ±σ-random-sign mode exists). "1 mg²", "1 (°/h)²" are per-sample variances at 100 Hz;
//!   the continuous PSD for the filter is σ²·T_s (9.6e-7 (m/s²)²/Hz, 2.35e-13 rad²/s).
//! * Gravity: WGS-84 normal gravity (Somigliana + second-order free-air), along the ellipsoid
//!   normal; truth and INS use the same model, so no gravity-model error is simulated.
//! * IMU samples are interval-midpoint values of f_b, ω_ib (not increments).
//!
//! ## Example
//!
//! ```
//! use ins_errors::config::{ImuConfig, TrajectoryConfig};
//! use ins_errors::error_model::{self, Mat15, Transition};
//! use ins_errors::imu::{ImuErrorParams, ImuErrors};
//! use ins_errors::strapdown::{NavState, Strapdown};
//! use ins_errors::trajectory::Trajectory;
//! use rand::SeedableRng;
//!
//! let mut cfg = TrajectoryConfig::paper();
//! cfg.end_time_s = 80.0; // the first two segments: straight, then a 40° right turn
//! cfg.segments.truncate(2);
//! let tr = Trajectory::new(&cfg)?;
//! let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
//! let imu = ImuErrors::draw(&ImuErrorParams::from_config(&ImuConfig::paper())?, &mut rng);
//! let mut it = tr.samples();
//! let s0 = it.next().unwrap();
//! let mut ins = Strapdown::new(
//!     s0.nav_state(),
//!     tr.step_s(),
//! )?;
//! let mut p = Mat15::identity() * 1e-2;
//! let mut ideal = (s0.specific_force_body_mps2, s0.ang_rate_ib_body_radps);
//! for s in it {
//!     let (f, w) = imu.measure(&ideal.0, &ideal.1, &mut rng);
//!     ins.step(&f, &w);
//!     let a = error_model::system_matrix(&ins.linearization_point());
//!     let phi = Transition::series(&a, tr.step_s());
//!     error_model::propagate_covariance(&mut p, &phi, &Mat15::zeros());
//!     ideal = (s.specific_force_body_mps2, s.ang_rate_ib_body_radps);
//! }
//! // Position uncertainty grows from the initial velocity/attitude uncertainty.
//! assert!(p[(0, 0)] > 1e-2);
//! # Ok::<(), ins_errors::InsError>(())
//! ```

pub mod config;
pub mod earth;
pub mod error;
pub mod error_model;
pub mod imu;
pub mod strapdown;
pub mod trajectory;

pub use error::InsError;
