//! # akf — discrete Kalman filter with adaptive process-noise estimation
//!
//! A small, allocation-free Kalman filter on fixed-size nalgebra types (`SVector<f64, N>`,
//! `SMatrix<f64, M, N>`, const generics), with the adaptive estimate of the process noise used by
//! Lustosa, Chagas & Waldmann, *Sighting device-aided inertial navigation: fusion with adaptative
//! Kalman filtering techniques* (§5, eq. 19), after Mohamed & Schwarz (1999), *Adaptive Kalman
//! filtering for INS/GPS*, J. Geodesy 73:193–203. Nothing here is INS-specific.
//!
//! ## Filter ([`KalmanFilter`])
//!
//! State x (N), covariance P (N×N), both in the caller's units.
//!
//! * Predict: x̂⁻ = Φ x̂⁺,  P⁻ = Φ P⁺ Φᵀ + Q_d, then P ← (P + Pᵀ)/2.
//! * Update with z (M), H (M×N), R (M×M, PD, measurement units²):
//!   ν = z − H x̂⁻,  S = H P⁻ Hᵀ + R,  K = P⁻ Hᵀ S⁻¹ (solved with a Cholesky factor of S, never an
//!   explicit inverse),  x̂⁺ = x̂⁻ + K ν,
//!   P⁺ = (I − K H) P⁻ (I − K H)ᵀ + K R Kᵀ (Joseph form, PSD for any K), then symmetrised.
//!   Returns ν, S and NIS = νᵀ S⁻¹ ν = ‖L⁻¹ν‖² (S = L Lᵀ).
//! * Error-state feedback: [`KalmanFilter::reset_error_state`] sets x̂ ← 0 and keeps P.
//!
//! ## Adaptive process noise ([`AdaptiveQ`], [`AdaptiveKalmanFilter`])
//!
//! With k counting measurement updates and Φ the transition over the interval between updates
//! k−1 and k (the product of every step Φ in between), paper eq. (19):
//!
//! Q̂_k = (1/N_w) Σ_{j=k−N_w+1..k} Δx_j Δx_jᵀ + P_k⁺ − Φ P_{k−1}⁺ Φᵀ,   Δx_j = x̂_j⁺ − x̂_j⁻.
//!
//! Why: Δx_j = K_j ν_j and E[K ν νᵀ Kᵀ] = K S Kᵀ = P⁻ − P⁺ for a consistent filter, while
//! P_k⁻ = Φ P_{k−1}⁺ Φᵀ + Q; eliminating P⁻ gives the formula with the expectation replaced by a
//! window average. For a filter run with some Q_f the expectation of Q̂ is
//! Q_f + K (C_ν − S) Kᵀ, C_ν the actual innovation covariance: Q̂ only sees Q through the
//! innovations, so with few measurements per state (rank K < N) only the part of Q in the range of
//! K is corrected. The tests use a fully measured toy system where Q is identifiable.
//!
//! * The window N_w (default 10, as in the paper) lives in a fixed ring buffer (capacity
//!   `CAP`, default [`DEFAULT_WINDOW_CAPACITY`]); before N_w updates have been seen there is no
//!   estimate (`None`) and the caller keeps its a-priori Q.
//! * Q̂ is indefinite in general (a difference of covariances plus a rank-≤N_w sample term). It is
//!   symmetrised, then projected ([`QProjection`]): eigenvalue clipping at a floor ≥ 0 (default,
//!   [`project_psd`]: the Frobenius-nearest matrix with eigenvalues ≥ floor) or a diagonal with
//!   per-state floors ([`project_diagonal`]). Clipping raises the estimate, so time averages of the
//!   projected Q̂ are biased upwards; the raw symmetrised estimate stays available.
//! * Q̂ is noise over one *update interval*. The INS filter predicts in 100 steps of 0.01 s between
//!   1 s updates; it predicts once per interval with (Φ_T, Q_T) (crate `ins-sd-filter`, module
//!   `interval`), so Q̂ is used as Q_T unchanged and no conversion to a per-step Q_d is needed.
//!
//! ### What the tests measured (toy 1-D constant velocity, both states measured, q = 0.5 m²/s³)
//!
//! * Filter run with the true Q, 20 000 updates, N_w = 10: the time average of the raw Q̂ matches
//!   the true Q (and, with 10 prediction sub-steps per update, the accumulated interval Q_T) to a
//!   few per cent; the average of the *projected* Q̂ is ≈ +17 % high on the poorly observed
//!   entry (clipping bias).
//! * Adaptive loop (each projected Q̂ fed back as the next Q), started at 100 × or 1/100 × the
//!   true Q: it forgets the start within a window and settles at a biased fixed point, q11
//!   (position) +40…+80 % and q22 (velocity) −10…−20 % with N_w = 10 (8 seeds);
//!   q11 −5…+47 %, q22 −7…+1 % with N_w = 50. The noisy, window-10 estimate feeding itself is consistent with the paper's
//!   observation that the AKF did worse than the hand-tuned filter.
//!
//! ### Reading of the printed paper
//!
//! * Eq. (19) prints the sum from j₀ to k; with window N this is j₀ = k − N + 1.
//! * §5 says Φ is the discretisation of A at T_s = 0.01 s, while k in eq. (19) counts SD updates
//!   (T_SD = 1 s) and P_k⁺, P_{k−1}⁺ are one update apart. Taken literally (Φ of one 0.01 s step
//!   between covariances 1 s apart) the formula is inconsistent; this crate uses the Φ spanning
//!   the update interval (the product of the 100 step Φs), which is what the derivation needs.
//!   [`AdaptiveKalmanFilter`] accumulates it.
//! * For the 15-state INS error vector (m, m/s, rad, m/s², rad/s) eigenvalue clipping mixes units;
//!   the diagonal projection with per-state floors is the unit-safe choice.
//!
//! ## Other adaptive schemes
//!
//! * [`SageHusaQ`]: Sage–Husa with a forgetting factor b — the exponentially weighted mean of
//!   the single-update estimates Δx Δxᵀ + P⁺ − Φ P⁺₋ Φᵀ (b = 1: the running average).
//! * [`project_structured`]: the raw estimate projected onto Σ q_k B_k, q ≥ 0 (the model's
//!   noise inputs) by non-negative least squares ([`nnls_gram`], Lawson–Hanson), selected as
//!   [`QProjection::Structured`] by callers that own the basis B_k.
//!
//! ## Consistency ([`nees`], [`average_band`])
//!
//! NEES = eᵀP⁻¹e ~ χ²(N), NIS ~ χ²(M); the average over `runs` Monte Carlo runs times `runs` is
//! χ²(runs·dof), giving the acceptance band of [`average_band`].
//!
//! ## Decisions where the paper is silent
//!
//! * The symmetric eigen-decomposition is a cyclic Jacobi solver of this crate (nalgebra's
//!   `SymmetricEigen` needs extra trait bounds for generic `N`); tests check it against nalgebra.
//! * Inputs are validated (finite, symmetric R and Q_d, R PD with the failing pivot named) and a
//!   failing call leaves the filter unchanged. Q_d is checked for non-negative diagonal only.
//!
//! ## Example
//!
//! ```
//! use akf::{AdaptiveKalmanFilter, AdaptiveQConfig};
//! use nalgebra::{Matrix1x2, Matrix2, Vector1, Vector2};
//!
//! // Constant-velocity model: state (position m, velocity m/s), dt = 1 s.
//! let phi = Matrix2::new(1.0, 1.0, 0.0, 1.0);
//! let q_d = Matrix2::new(1.0 / 3.0, 0.5, 0.5, 1.0) * 0.01; // white acceleration, q = 0.01 m²/s³
//! let h = Matrix1x2::new(1.0, 0.0); // position measured
//! let r = nalgebra::Matrix1::new(4.0); // m²
//!
//! let mut akf = AdaptiveKalmanFilter::<2>::new(
//!     Vector2::zeros(),
//!     Matrix2::identity() * 100.0,
//!     AdaptiveQConfig { window: 3, ..Default::default() },
//! )?;
//! for k in 0..5 {
//!     akf.predict(&phi, &q_d)?;
//!     let z = Vector1::new(2.0 * k as f64); // position readings, m
//!     let inn = akf.update(&z, &h, &r)?;
//!     assert!(inn.nis >= 0.0);
//! }
//! // Three updates fill the window: a PSD estimate of Q over one interval exists.
//! let q_hat = akf.q_estimate().expect("window is full");
//! assert!(q_hat.symmetric_eigenvalues().min() >= -1e-12);
//! // Feedback: the caller applied x̂ to its nominal solution; zero the error state.
//! akf.reset_error_state();
//! assert_eq!(akf.filter().state(), &Vector2::zeros());
//! # Ok::<(), akf::AkfError>(())
//! ```

mod adaptive;
mod consistency;
mod error;
mod kf;
mod linalg;
mod sage_husa;
mod structured;

pub use adaptive::{
    AdaptiveKalmanFilter, AdaptiveQ, AdaptiveQConfig, DEFAULT_WINDOW_CAPACITY, Projected,
    QProjection, project_diagonal, project_psd,
};
pub use consistency::{average_band, chi_square_quantile, nees, normal_quantile};
pub use error::AkfError;
pub use kf::{Innovation, KalmanFilter, PSD_REL_TOL};
pub use linalg::{SYMMETRY_REL_TOL, symmetric_eigen};
pub use sage_husa::{SageHusaConfig, SageHusaQ};
pub use structured::{StructuredFit, nnls_gram, project_structured};
