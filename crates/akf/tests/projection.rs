//! PSD projection of Q̂ and the crate's Jacobi eigensolver, against nalgebra and against the
//! defining properties (PSD, identity on PSD input, Frobenius-nearest).
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used)]

mod common;

use akf::{AkfError, project_diagonal, project_psd, symmetric_eigen};
use common::*;
use nalgebra::{SMatrix, SVector};

fn random_symmetric<const N: usize>(rng: &mut rand_chacha::ChaCha8Rng) -> SMatrix<f64, N, N> {
    let a: SMatrix<f64, N, N> = uniform_mat(rng);
    (a + a.transpose()) * 0.5
}

fn orthogonal15(rng: &mut rand_chacha::ChaCha8Rng) -> SMatrix<f64, 15, 15> {
    uniform_mat::<15, 15>(rng).qr().q()
}

fn orthogonal6(rng: &mut rand_chacha::ChaCha8Rng) -> SMatrix<f64, 6, 6> {
    uniform_mat::<6, 6>(rng).qr().q()
}

#[test]
fn jacobi_eigen_matches_nalgebra_symmetric_eigen() {
    let mut rng = rng(401);
    for _ in 0..50 {
        let a = random_symmetric::<15>(&mut rng) * 10.0;
        let (lambda, v) = symmetric_eigen(&a).unwrap();
        let mut ours: Vec<f64> = lambda.iter().copied().collect();
        let mut theirs: Vec<f64> = a.symmetric_eigenvalues().iter().copied().collect();
        ours.sort_by(f64::total_cmp);
        theirs.sort_by(f64::total_cmp);
        for (x, y) in ours.iter().zip(&theirs) {
            assert!((x - y).abs() < 1e-12 * a.norm(), "{x} vs {y}");
        }
        let recon = v * SMatrix::<f64, 15, 15>::from_diagonal(&lambda) * v.transpose();
        assert!((recon - a).norm() < 1e-13 * a.norm());
        assert!((v.transpose() * v - SMatrix::<f64, 15, 15>::identity()).norm() < 1e-13);
    }
    // Repeated eigenvalues and a zero matrix.
    let q = orthogonal6(&mut rng);
    let d = SVector::<f64, 6>::new(2.0, 2.0, 2.0, -1.0, -1.0, 0.0);
    let a = q * SMatrix::<f64, 6, 6>::from_diagonal(&d) * q.transpose();
    let (lambda, _) = symmetric_eigen(&a).unwrap();
    let mut l: Vec<f64> = lambda.iter().copied().collect();
    l.sort_by(f64::total_cmp);
    for (x, y) in l.iter().zip([-1.0, -1.0, 0.0, 2.0, 2.0, 2.0]) {
        assert!((x - y).abs() < 1e-13);
    }
    assert_eq!(
        symmetric_eigen(&SMatrix::<f64, 3, 3>::zeros()).unwrap().0,
        SVector::<f64, 3>::zeros()
    );
}

#[test]
fn projection_of_an_indefinite_matrix_clips_exactly_the_low_eigenvalues() {
    // A = V diag(λ) Vᵀ with known V, λ: the projection must be V diag(max(λ, floor)) Vᵀ.
    let mut rng = rng(402);
    for floor in [0.0, 0.05] {
        let v = orthogonal15(&mut rng);
        let lambda = SVector::<f64, 15>::from_fn(|i, _| i as f64 * 0.1 - 0.6);
        let a = v * SMatrix::<f64, 15, 15>::from_diagonal(&lambda) * v.transpose();
        let expected_l = lambda.map(|l| l.max(floor));
        let expected = v * SMatrix::<f64, 15, 15>::from_diagonal(&expected_l) * v.transpose();
        let p = project_psd(&a, floor).unwrap();
        assert!((p.matrix - expected).norm() < 1e-12 * a.norm());
        let clipped_expected = lambda.iter().filter(|&&l| l < floor).count();
        assert_eq!(p.clipped, clipped_expected);
        assert!((p.smallest_before + 0.6).abs() < 1e-12);
        assert!(p.matrix.symmetric_eigenvalues().min() >= floor - 1e-12);
        assert_eq!(p.matrix, p.matrix.transpose());
    }
}

#[test]
fn projection_result_is_psd_and_nearer_than_any_other_psd_candidate() {
    let mut rng = rng(403);
    for _ in 0..20 {
        let a = random_symmetric::<6>(&mut rng);
        let p = project_psd(&a, 0.0).unwrap().matrix;
        assert!(p.symmetric_eigenvalues().min() >= -1e-13);
        let dist = (a - p).norm();
        for _ in 0..200 {
            // Random PSD candidates, including small perturbations of the projection itself.
            let b: SMatrix<f64, 6, 6> = uniform_mat(&mut rng);
            let far = b * b.transpose() * 0.3;
            let e: SMatrix<f64, 6, 6> = uniform_mat(&mut rng);
            let near = project_psd(&(p + (e + e.transpose()) * 1e-3), 0.0)
                .unwrap()
                .matrix;
            assert!(dist <= (a - far).norm() + 1e-12);
            assert!(dist <= (a - near).norm() + 1e-12);
        }
    }
}

#[test]
fn projection_returns_psd_input_unchanged() {
    let mut rng = rng(404);
    for _ in 0..20 {
        let b: SMatrix<f64, 15, 6> = uniform_mat(&mut rng);
        let singular_psd = b * b.transpose(); // rank 6
        let pd = random_spd::<15>(&mut rng, 0.2);
        // Rank-deficient PSD input: round-off eigenvalues can be ±1e-16; with floor 0 those may
        // be clipped, so compare to round-off, then exactly for a PD input.
        let p = project_psd(&singular_psd, 0.0).unwrap();
        assert!((p.matrix - singular_psd).norm() < 1e-13 * singular_psd.norm());
        let q = project_psd(&pd, 0.1).unwrap();
        assert_eq!(q.clipped, 0);
        assert_eq!(q.matrix, pd);
    }
}

#[test]
fn diagonal_projection_keeps_the_diagonal_raised_to_per_state_floors() {
    let a = SMatrix::<f64, 3, 3>::new(2.0, 0.5, -0.3, 0.5, -1.0, 0.2, -0.3, 0.2, 1e-6);
    let floors = SVector::<f64, 3>::new(0.1, 0.2, 1e-3);
    let p = project_diagonal(&a, &floors).unwrap();
    assert_eq!(
        p.matrix,
        SMatrix::<f64, 3, 3>::from_diagonal(&SVector::<f64, 3>::new(2.0, 0.2, 1e-3))
    );
    assert_eq!(p.clipped, 2);
    assert_eq!(p.smallest_before, -1.0);
    assert!(matches!(
        project_diagonal(&a, &SVector::<f64, 3>::new(0.0, -1.0, 0.0)),
        Err(AkfError::InvalidParameter {
            field: "floors",
            ..
        })
    ));
    assert!(matches!(
        project_psd(&a, -0.1),
        Err(AkfError::InvalidParameter {
            field: "min_eigenvalue",
            ..
        })
    ));
    let mut nan = a;
    nan[(1, 2)] = f64::NAN;
    assert!(matches!(
        project_psd(&nan, 0.0),
        Err(AkfError::NonFinite { what: "q", .. })
    ));
}
