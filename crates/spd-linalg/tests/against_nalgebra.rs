//! The workspace's Cholesky against nalgebra's on random SPD matrices, and its pivot reports.
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use nalgebra::{SMatrix, SVector};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use spd_linalg::{Cholesky, symmetrise};

/// A random SPD matrix B Bᵀ + δI with a condition number spread over several decades.
fn random_spd<const N: usize>(rng: &mut ChaCha8Rng) -> SMatrix<f64, N, N> {
    let b = SMatrix::<f64, N, N>::from_fn(|_, _| rng.random_range(-1.0..1.0));
    let scale = SMatrix::<f64, N, N>::from_diagonal(&SVector::<f64, N>::from_fn(|_, _| {
        10f64.powf(rng.random_range(-3.0..3.0))
    }));
    let m = scale * b * b.transpose() * scale + SMatrix::<f64, N, N>::identity() * 1e-9;
    let mut m = m;
    symmetrise(&mut m);
    m
}

fn check<const N: usize>(rng: &mut ChaCha8Rng) {
    for _ in 0..200 {
        let a = random_spd::<N>(rng);
        let ours = Cholesky::new(&a, "A").unwrap();
        let theirs = nalgebra::Cholesky::new(a).unwrap();
        let l_ref = theirs.l();
        let rel = (ours.l() - l_ref).norm() / l_ref.norm();
        assert!(rel < 1e-10, "N={N}: factor differs by {rel:e}");
        let b = SVector::<f64, N>::from_fn(|_, _| rng.random_range(-1.0..1.0));
        let x = ours.solve(&b);
        let x_ref = theirs.solve(&b);
        assert!(
            (x - x_ref).norm() <= 1e-8 * x_ref.norm().max(1e-300) + 1e-12,
            "N={N} solve"
        );
        let m = ours.mahalanobis_squared(&b);
        assert!(
            (m - b.dot(&x_ref)).abs() <= 1e-8 * m.abs().max(1.0),
            "N={N} mahalanobis"
        );
        let ld = 2.0 * l_ref.diagonal().map(f64::ln).sum();
        assert!((ours.log_det() - ld).abs() < 1e-9 * ld.abs().max(1.0));
        let inv = ours.inverse();
        assert_eq!(inv, inv.transpose(), "inverse exactly symmetric");
        assert!(
            (inv * a - SMatrix::<f64, N, N>::identity()).norm() < 1e-6 * (a.norm() * inv.norm())
        );
    }
}

#[test]
fn factor_solve_inverse_and_log_det_equal_nalgebras_on_random_spd_matrices() {
    let mut rng = ChaCha8Rng::seed_from_u64(2009);
    check::<1>(&mut rng);
    check::<3>(&mut rng);
    check::<6>(&mut rng);
    check::<15>(&mut rng);
}

#[test]
fn the_error_names_the_matrix_and_the_first_failing_pivot() {
    // Leading 2×2 block PD, the 3×3 not: pivot 2 fails.
    let a = SMatrix::<f64, 3, 3>::new(4.0, 2.0, 0.0, 2.0, 3.0, 1.0, 0.0, 1.0, 0.25);
    let e = Cholesky::new(&a, "S").unwrap_err();
    assert_eq!((e.matrix, e.pivot), ("S", 2));
    assert!(e.value <= 0.0);
    assert!(
        e.to_string()
            .contains("S is not positive definite: Cholesky pivot 2"),
        "{e}"
    );
    // NaN input fails at its pivot, not later.
    let mut n = SMatrix::<f64, 3, 3>::identity();
    n[(1, 1)] = f64::NAN;
    assert_eq!(Cholesky::new(&n, "N").unwrap_err().pivot, 1);
    // Only the lower triangle is read.
    let mut upper_garbage = SMatrix::<f64, 3, 3>::identity() * 2.0;
    upper_garbage[(0, 2)] = 1e300;
    assert!(Cholesky::new(&upper_garbage, "U").is_ok());
}

#[test]
fn the_relative_floor_rejects_a_nearly_dependent_regressor() {
    // Normal equations of regressors (1, t, t + 1e-7·noise): the third pivot keeps ~1e-14 of its
    // diagonal after elimination.
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let mut m = SMatrix::<f64, 3, 3>::zeros();
    for i in 0..50 {
        let t = i as f64 / 49.0;
        let phi = SVector::<f64, 3>::new(1.0, t, t + 1e-7 * rng.random_range(-1.0..1.0));
        m += phi * phi.transpose();
    }
    assert!(
        Cholesky::new(&m, "M").is_ok(),
        "positive definite in exact terms"
    );
    let e = Cholesky::with_relative_floor(&m, "M", 1e-10).unwrap_err();
    assert_eq!(e.pivot, 2);
    assert!(e.floor > 0.0 && e.value <= e.floor);
}
