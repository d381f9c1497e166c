//! Shared seeded simulation helpers for the integration tests.
#![allow(dead_code, clippy::unwrap_used, clippy::expect_used)]

use nalgebra::{SMatrix, SVector};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};

/// Seeded generator used by every test.
pub fn rng(seed: u64) -> ChaCha8Rng {
    ChaCha8Rng::seed_from_u64(seed)
}

/// Standard normal vector.
pub fn normal_vec<const N: usize>(rng: &mut ChaCha8Rng) -> SVector<f64, N> {
    SVector::from_fn(|_, _| StandardNormal.sample(rng))
}

/// Uniform(−1, 1) matrix.
pub fn uniform_mat<const R: usize, const C: usize>(rng: &mut ChaCha8Rng) -> SMatrix<f64, R, C> {
    use rand::Rng;
    SMatrix::from_fn(|_, _| rng.random_range(-1.0..1.0))
}

/// Random SPD matrix A Aᵀ + eps I.
pub fn random_spd<const N: usize>(rng: &mut ChaCha8Rng, eps: f64) -> SMatrix<f64, N, N> {
    let a: SMatrix<f64, N, N> = uniform_mat(rng);
    a * a.transpose() + SMatrix::identity() * eps
}

/// Sample of N(0, C) using nalgebra's own Cholesky (independent of the crate's).
pub fn sample_gaussian<const N: usize>(
    rng: &mut ChaCha8Rng,
    cov: &SMatrix<f64, N, N>,
) -> SVector<f64, N> {
    let l = cov.cholesky().expect("covariance PD").l();
    l * normal_vec::<N>(rng)
}

/// Sample of N(0, C) for PSD C (may be singular) through nalgebra's SymmetricEigen.
pub fn sample_gaussian_psd<const N: usize>(
    rng: &mut ChaCha8Rng,
    cov: &SMatrix<f64, N, N>,
) -> SVector<f64, N>
where
    nalgebra::Const<N>: nalgebra::DimSub<nalgebra::U1>,
    nalgebra::DefaultAllocator:
        nalgebra::allocator::Allocator<nalgebra::DimDiff<nalgebra::Const<N>, nalgebra::U1>>,
{
    let e = cov.symmetric_eigen();
    let mut s = normal_vec::<N>(rng);
    for i in 0..N {
        s[i] *= e.eigenvalues[i].max(0.0).sqrt();
    }
    e.eigenvectors * s
}

/// Constant-velocity model for one axis: state (position m, velocity m/s), white acceleration
/// with spectral density `q` (m²/s³). Exact discretisation over `dt` s (Van Loan closed form).
pub fn cv_model(dt: f64, q: f64) -> (SMatrix<f64, 2, 2>, SMatrix<f64, 2, 2>) {
    let phi = SMatrix::<f64, 2, 2>::new(1.0, dt, 0.0, 1.0);
    let qd = SMatrix::<f64, 2, 2>::new(dt * dt * dt / 3.0, dt * dt / 2.0, dt * dt / 2.0, dt) * q;
    (phi, qd)
}
