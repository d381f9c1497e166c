//! Relating the AKF's Q̂ (noise over one update interval) to the per-step Q_d the filter predicts
//! with.
//!
//! When the filter predicts in `n` steps Φ_1 … Φ_n with per-step noise Q_d between two updates,
//! the covariance propagates as P_k⁻ = Φ_T P_{k−1}⁺ Φ_Tᵀ + Q_T with
//!
//! Φ_T = Φ_n ⋯ Φ_1,   Q_T = Σ_{i=1..n} (Φ_n ⋯ Φ_{i+1}) Q_d (Φ_n ⋯ Φ_{i+1})ᵀ  =: L(Q_d).
//!
//! Q̂ from the Mohamed–Schwarz formula (with Φ = Φ_T) estimates Q_T, not Q_d. Two ways back:
//!
//! * [`per_step_q_uniform`]: Q_d ≈ Q_T / n. Exact when Φ_i = I; otherwise the relative error is
//!   O(‖A‖·T) for Φ = exp(A·Δt), T = nΔt (for a white-noise-driven integrator chain it
//!   mis-shapes the cross terms, e.g. Q_T ∝ [T³/3, T²/2; T²/2, T] vs Q_d ∝ [Δt³/3, Δt²/2; …]).
//! * [`per_step_q_exact`] / [`per_step_q_exact_const`]: solve L(Q_d) = Q_T by Richardson
//!   iteration X ← X + (Q_T − L(X))/n, starting from Q_T/n. L is linear; for Φ_i close to I its
//!   eigenvalues are ≈ n (all equal to n when the Φ_i are unipotent, e.g. integrator chains, and
//!   then the iteration terminates in a few steps). Converges when the interval is short compared
//!   with the dynamics' time constants (roughly ‖A‖·T < 2). The exact inverse of a PSD Q_T need
//!   not be PSD: project the result (e.g. [`crate::project_psd`]) if the caller needs it.
//!
//! [`accumulate_interval`] / [`accumulate_interval_const`] compute the forward map (Φ_T, Q_T).
//! Which conversion to use is the caller's decision; all functions are allocation-free.

use nalgebra::SMatrix;

use crate::AkfError;
use crate::linalg::{check_finite, symmetrise_in_place};

/// Sequence of step transitions over one update interval.
#[derive(Clone, Copy)]
enum Steps<'a, const N: usize> {
    Constant(&'a SMatrix<f64, N, N>, usize),
    Varying(&'a [SMatrix<f64, N, N>]),
}

impl<const N: usize> Steps<'_, N> {
    fn len(&self) -> usize {
        match self {
            Steps::Constant(_, n) => *n,
            Steps::Varying(s) => s.len(),
        }
    }

    fn check(&self) -> Result<(), AkfError> {
        match self {
            Steps::Constant(phi, _) => check_finite("phi_step", *phi),
            Steps::Varying(s) => {
                for phi in s.iter() {
                    check_finite("phi_steps", phi)?;
                }
                Ok(())
            }
        }
    }

    /// L(X) = Σ_i Φ_{n←i} X Φ_{n←i}ᵀ by the recursion acc ← Φ_i acc Φ_iᵀ + X, plus Φ_T.
    fn forward(&self, x: &SMatrix<f64, N, N>) -> (SMatrix<f64, N, N>, SMatrix<f64, N, N>) {
        let mut acc = SMatrix::<f64, N, N>::zeros();
        let mut phi_t = SMatrix::<f64, N, N>::identity();
        let mut step = |phi: &SMatrix<f64, N, N>| {
            acc = phi * acc * phi.transpose() + x;
            phi_t = phi * phi_t;
        };
        match self {
            Steps::Constant(phi, n) => {
                for _ in 0..*n {
                    step(phi);
                }
            }
            Steps::Varying(s) => {
                for phi in s.iter() {
                    step(phi);
                }
            }
        }
        symmetrise_in_place(&mut acc);
        (phi_t, acc)
    }
}

fn check_n(n_steps: usize) -> Result<(), AkfError> {
    if n_steps == 0 {
        return Err(AkfError::InvalidParameter {
            field: "n_steps",
            reason: "an update interval needs at least one prediction step".into(),
        });
    }
    Ok(())
}

/// Forward map for time-varying steps: returns (Φ_T, Q_T) for per-step noise `q_d_step`.
pub fn accumulate_interval<const N: usize>(
    phi_steps: &[SMatrix<f64, N, N>],
    q_d_step: &SMatrix<f64, N, N>,
) -> Result<(SMatrix<f64, N, N>, SMatrix<f64, N, N>), AkfError> {
    check_n(phi_steps.len())?;
    check_finite("q_d_step", q_d_step)?;
    let steps = Steps::Varying(phi_steps);
    steps.check()?;
    Ok(steps.forward(q_d_step))
}

/// Forward map for `n_steps` identical steps `phi_step`: returns (Φ_T, Q_T).
pub fn accumulate_interval_const<const N: usize>(
    phi_step: &SMatrix<f64, N, N>,
    q_d_step: &SMatrix<f64, N, N>,
    n_steps: usize,
) -> Result<(SMatrix<f64, N, N>, SMatrix<f64, N, N>), AkfError> {
    check_n(n_steps)?;
    check_finite("q_d_step", q_d_step)?;
    let steps = Steps::Constant(phi_step, n_steps);
    steps.check()?;
    Ok(steps.forward(q_d_step))
}

/// First-order conversion Q_d ≈ Q_T / n (exact only for Φ = I; see the module doc).
pub fn per_step_q_uniform<const N: usize>(
    q_interval: &SMatrix<f64, N, N>,
    n_steps: usize,
) -> Result<SMatrix<f64, N, N>, AkfError> {
    check_n(n_steps)?;
    check_finite("q_interval", q_interval)?;
    Ok(q_interval / n_steps as f64)
}

/// Stopping rule of the exact per-step inversion.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InverseOptions {
    /// Maximum Richardson iterations (each costs one pass over the interval's steps).
    pub max_iterations: usize,
    /// Stop when ‖Q_T − L(Q_d)‖_F ≤ rel_tolerance · ‖Q_T‖_F.
    pub rel_tolerance: f64,
}

impl Default for InverseOptions {
    fn default() -> Self {
        Self {
            max_iterations: 100,
            rel_tolerance: 1e-12,
        }
    }
}

fn per_step_exact_impl<const N: usize>(
    q_interval: &SMatrix<f64, N, N>,
    steps: Steps<'_, N>,
    options: InverseOptions,
) -> Result<SMatrix<f64, N, N>, AkfError> {
    check_n(steps.len())?;
    check_finite("q_interval", q_interval)?;
    steps.check()?;
    if !(options.rel_tolerance.is_finite() && options.rel_tolerance > 0.0) {
        return Err(AkfError::InvalidParameter {
            field: "rel_tolerance",
            reason: format!("{} must be finite and > 0", options.rel_tolerance),
        });
    }
    let target = q_interval.norm();
    if target == 0.0 {
        return Ok(SMatrix::zeros());
    }
    let n = steps.len() as f64;
    let mut x = q_interval / n;
    let mut residual = f64::INFINITY;
    for _ in 0..options.max_iterations {
        let (_, lx) = steps.forward(&x);
        let r = q_interval - lx;
        residual = r.norm() / target;
        if !residual.is_finite() || residual > 1e6 {
            break;
        }
        if residual <= options.rel_tolerance {
            symmetrise_in_place(&mut x);
            return Ok(x);
        }
        x += r / n;
    }
    Err(AkfError::NotConverged {
        algorithm: "per-step Q Richardson iteration",
        iterations: options.max_iterations,
        residual,
    })
}

/// Exact per-step Q_d with L(Q_d) = Q_T for time-varying steps (see the module doc).
pub fn per_step_q_exact<const N: usize>(
    q_interval: &SMatrix<f64, N, N>,
    phi_steps: &[SMatrix<f64, N, N>],
    options: InverseOptions,
) -> Result<SMatrix<f64, N, N>, AkfError> {
    per_step_exact_impl(q_interval, Steps::Varying(phi_steps), options)
}

/// Exact per-step Q_d with L(Q_d) = Q_T for `n_steps` identical steps `phi_step`.
pub fn per_step_q_exact_const<const N: usize>(
    q_interval: &SMatrix<f64, N, N>,
    phi_step: &SMatrix<f64, N, N>,
    n_steps: usize,
    options: InverseOptions,
) -> Result<SMatrix<f64, N, N>, AkfError> {
    per_step_exact_impl(q_interval, Steps::Constant(phi_step, n_steps), options)
}
