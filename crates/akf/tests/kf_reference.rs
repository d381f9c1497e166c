//! The Kalman filter against independent reference forms: batch weighted least squares over the
//! stacked trajectory, the textbook (non-Joseph) update, explicit inverses; long random runs for
//! symmetry/PSD; input validation.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used)]

mod common;

use akf::{AkfError, KalmanFilter};
use common::*;
use nalgebra::{DMatrix, DVector, SMatrix, SVector};

type M4 = SMatrix<f64, 4, 4>;
type V4 = SVector<f64, 4>;

/// 2-D constant velocity: state (x m, y m, vx m/s, vy m/s), white acceleration densities
/// `qx`, `qy` (m²/s³), exact discretisation over `dt` s.
fn cv2d(dt: f64, qx: f64, qy: f64) -> (M4, M4) {
    let mut phi = M4::identity();
    phi[(0, 2)] = dt;
    phi[(1, 3)] = dt;
    let mut q = M4::zeros();
    for (axis, qa) in [(0usize, qx), (1usize, qy)] {
        q[(axis, axis)] = qa * dt.powi(3) / 3.0;
        q[(axis, axis + 2)] = qa * dt.powi(2) / 2.0;
        q[(axis + 2, axis)] = qa * dt.powi(2) / 2.0;
        q[(axis + 2, axis + 2)] = qa * dt;
    }
    (phi, q)
}

struct Problem {
    phi: M4,
    q: M4,
    h: SMatrix<f64, 2, 4>,
    r: SMatrix<f64, 2, 2>,
    x0_hat: V4,
    p0: M4,
    zs: Vec<SVector<f64, 2>>,
}

fn simulate(seed: u64, steps: usize) -> Problem {
    let mut rng = rng(seed);
    let (phi, q) = cv2d(0.5, 0.2, 0.05);
    let h = SMatrix::<f64, 2, 4>::new(1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0);
    let r = SMatrix::<f64, 2, 2>::new(0.3, 0.1, 0.1, 0.5);
    let p0 = random_spd::<4>(&mut rng, 1.0) * 2.0;
    let x0_hat = V4::new(10.0, -5.0, 1.0, 0.5);
    let mut x = x0_hat + sample_gaussian(&mut rng, &p0);
    let mut zs = Vec::with_capacity(steps);
    for _ in 0..steps {
        x = phi * x + sample_gaussian(&mut rng, &q);
        zs.push(h * x + sample_gaussian(&mut rng, &r));
    }
    Problem {
        phi,
        q,
        h,
        r,
        x0_hat,
        p0,
        zs,
    }
}

/// Batch WLS over x_0..x_K using the first K measurements: returns (x_K, marginal cov of x_K).
/// Uses nalgebra's dense Cholesky and explicit inverses, nothing from the crate.
fn batch_last(pr: &Problem, k_last: usize) -> (V4, M4) {
    let n = 4;
    let dim = n * (k_last + 1);
    let mut lambda = DMatrix::<f64>::zeros(dim, dim);
    let mut b = DVector::<f64>::zeros(dim);
    let p0_inv = pr.p0.try_inverse().unwrap();
    let q_inv = pr.q.try_inverse().unwrap();
    let r_inv = pr.r.try_inverse().unwrap();
    let add_block = |lambda: &mut DMatrix<f64>, i: usize, j: usize, m: &M4| {
        let mut view = lambda.view_mut((n * i, n * j), (n, n));
        view += m;
    };
    add_block(&mut lambda, 0, 0, &p0_inv);
    {
        let mut bv = b.rows_mut(0, n);
        bv += p0_inv * pr.x0_hat;
    }
    for k in 1..=k_last {
        // Dynamics pseudo-measurement 0 = x_k − Φ x_{k−1} + w, weight Q⁻¹.
        let a_prev = -pr.phi; // ∂/∂x_{k−1}
        add_block(
            &mut lambda,
            k - 1,
            k - 1,
            &(a_prev.transpose() * q_inv * a_prev),
        );
        add_block(&mut lambda, k - 1, k, &(a_prev.transpose() * q_inv));
        add_block(&mut lambda, k, k - 1, &(q_inv * a_prev));
        add_block(&mut lambda, k, k, &q_inv);
        // Measurement z_k = H x_k + v, weight R⁻¹.
        add_block(&mut lambda, k, k, &(pr.h.transpose() * r_inv * pr.h));
        let mut bv = b.rows_mut(n * k, n);
        bv += pr.h.transpose() * r_inv * pr.zs[k - 1];
    }
    let chol = lambda.clone().cholesky().expect("information matrix PD");
    let x = chol.solve(&b);
    let mut e = DMatrix::<f64>::zeros(dim, n);
    for i in 0..n {
        e[(n * k_last + i, i)] = 1.0;
    }
    let cols = chol.solve(&e);
    let x_last = V4::from_fn(|i, _| x[n * k_last + i]);
    let cov_last = M4::from_fn(|i, j| cols[(n * k_last + i, j)]);
    (x_last, cov_last)
}

#[test]
fn kf_estimate_and_covariance_equal_batch_least_squares_on_every_prefix() {
    for seed in [11u64, 12, 13] {
        let pr = simulate(seed, 40);
        let mut kf = KalmanFilter::new(pr.x0_hat, pr.p0).unwrap();
        for (k, z) in pr.zs.iter().enumerate() {
            kf.predict(&pr.phi, &pr.q).unwrap();
            kf.update(z, &pr.h, &pr.r).unwrap();
            let k_last = k + 1;
            if [1, 2, 5, 17, 40].contains(&k_last) {
                let (xb, pb) = batch_last(&pr, k_last);
                let dx = (kf.state() - xb).norm() / xb.norm();
                let dp = (kf.covariance() - pb).norm() / pb.norm();
                assert!(dx < 1e-9, "seed {seed} k {k_last}: state rel diff {dx:e}");
                assert!(
                    dp < 1e-9,
                    "seed {seed} k {k_last}: covariance rel diff {dp:e}"
                );
            }
        }
    }
}

#[test]
fn joseph_update_equals_textbook_update_for_the_optimal_gain() {
    let mut rng = rng(21);
    for _ in 0..200 {
        let p = random_spd::<6>(&mut rng, 0.1);
        let x: SVector<f64, 6> = normal_vec(&mut rng);
        let h: SMatrix<f64, 3, 6> = uniform_mat(&mut rng);
        let r = random_spd::<3>(&mut rng, 0.05);
        let z: SVector<f64, 3> = normal_vec(&mut rng);

        let mut kf = KalmanFilter::new(x, p).unwrap();
        let inn = kf.update(&z, &h, &r).unwrap();

        // Textbook form with explicit inverses.
        let s = h * p * h.transpose() + r;
        let s_inv = s.try_inverse().unwrap();
        let k = p * h.transpose() * s_inv;
        let nu = z - h * x;
        let x_ref = x + k * nu;
        let p_ref = (SMatrix::<f64, 6, 6>::identity() - k * h) * p;
        let nis_ref = nu.dot(&(s_inv * nu));

        assert!((kf.state() - x_ref).norm() <= 1e-10 * (1.0 + x_ref.norm()));
        assert!((kf.covariance() - p_ref).norm() <= 1e-10 * p.norm());
        assert!((inn.innovation - nu).norm() <= 1e-12 * (1.0 + nu.norm()));
        assert!((inn.innovation_covariance - s).norm() <= 1e-12 * s.norm());
        assert!((inn.nis - nis_ref).abs() <= 1e-10 * nis_ref.max(1.0));
    }
}

#[test]
fn covariance_stays_exactly_symmetric_and_psd_over_long_random_runs() {
    let mut rng = rng(31);
    let p0 = random_spd::<15>(&mut rng, 1.0);
    let mut kf = KalmanFilter::new(SVector::<f64, 15>::zeros(), p0).unwrap();
    for step in 0..5000 {
        let phi = SMatrix::<f64, 15, 15>::identity() + uniform_mat::<15, 15>(&mut rng) * 0.05;
        let b: SMatrix<f64, 15, 15> = uniform_mat(&mut rng);
        let q = b * b.transpose() * 1e-3;
        kf.predict(&phi, &q).unwrap();
        if step % 3 == 0 {
            let h: SMatrix<f64, 6, 15> = uniform_mat(&mut rng);
            // Alternate very precise and ordinary measurements: the textbook form loses
            // symmetry/PSD with precise ones, Joseph must not.
            let scale = if step % 2 == 0 { 1e-8 } else { 1.0 };
            let r = random_spd::<6>(&mut rng, 0.1) * scale;
            let z: SVector<f64, 6> = normal_vec(&mut rng);
            kf.update(&z, &h, &r).unwrap();
        }
        let p = kf.covariance();
        assert_eq!(*p, p.transpose(), "P not exactly symmetric at step {step}");
        let min_eig = p.symmetric_eigenvalues().min();
        let max_abs = p.amax();
        assert!(
            min_eig >= -1e-10 * max_abs,
            "step {step}: smallest eigenvalue {min_eig:e} (max |P| {max_abs:e})"
        );
    }
}

#[test]
fn reset_error_state_zeroes_the_state_and_keeps_the_covariance() {
    let mut rng = rng(41);
    let p = random_spd::<4>(&mut rng, 0.5);
    let mut kf = KalmanFilter::new(V4::new(1.0, 2.0, 3.0, 4.0), p).unwrap();
    let before = *kf.covariance();
    kf.reset_error_state();
    assert_eq!(*kf.state(), V4::zeros());
    assert_eq!(*kf.covariance(), before);
}

#[test]
fn non_finite_inputs_are_rejected_naming_the_input_and_entry() {
    let (phi, q) = cv2d(1.0, 0.1, 0.1);
    let mut kf = KalmanFilter::new(V4::zeros(), M4::identity()).unwrap();
    let h = SMatrix::<f64, 2, 4>::new(1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0);
    let r = SMatrix::<f64, 2, 2>::identity();
    let z = SVector::<f64, 2>::new(1.0, f64::NAN);
    assert_eq!(
        kf.update(&z, &h, &r),
        Err(AkfError::NonFinite {
            what: "z",
            row: 1,
            col: 0
        })
    );
    let mut h_bad = h;
    h_bad[(0, 3)] = f64::INFINITY;
    assert!(matches!(
        kf.update(&SVector::<f64, 2>::zeros(), &h_bad, &r),
        Err(AkfError::NonFinite {
            what: "h",
            row: 0,
            col: 3
        })
    ));
    let mut phi_bad = phi;
    phi_bad[(2, 1)] = f64::NAN;
    assert!(matches!(
        kf.predict(&phi_bad, &q),
        Err(AkfError::NonFinite {
            what: "phi",
            row: 2,
            col: 1
        })
    ));
    assert!(matches!(
        KalmanFilter::new(V4::new(0.0, f64::NAN, 0.0, 0.0), M4::identity()),
        Err(AkfError::NonFinite { what: "x0", .. })
    ));
    // Nothing changed.
    assert_eq!(*kf.state(), V4::zeros());
    assert_eq!(*kf.covariance(), M4::identity());
}

#[test]
fn non_pd_measurement_noise_is_rejected_naming_the_pivot_and_filter_is_unchanged() {
    let mut rng = rng(51);
    let p = random_spd::<15>(&mut rng, 1.0);
    let x: SVector<f64, 15> = normal_vec(&mut rng);
    let mut kf = KalmanFilter::new(x, p).unwrap();
    let h: SMatrix<f64, 6, 15> = uniform_mat(&mut rng);
    let z: SVector<f64, 6> = normal_vec(&mut rng);
    // Leading 3×3 block PD; the 4th pivot is negative.
    let r =
        SMatrix::<f64, 6, 6>::from_diagonal(&SVector::<f64, 6>::new(1.0, 1.0, 1.0, -0.5, 1.0, 1.0));
    match kf.update(&z, &h, &r) {
        Err(AkfError::NotPositiveDefinite {
            what,
            pivot,
            pivot_value,
        }) => {
            assert_eq!(what, "r");
            assert_eq!(pivot, 3);
            assert!(pivot_value <= 0.0);
        }
        other => panic!("expected NotPositiveDefinite, got {other:?}"),
    }
    // Rank-deficient PSD R: pivot 1 is exactly zero (row 1 = row 0).
    let mut r2 = SMatrix::<f64, 6, 6>::identity();
    r2[(0, 1)] = 1.0;
    r2[(1, 0)] = 1.0;
    assert!(matches!(
        kf.update(&z, &h, &r2),
        Err(AkfError::NotPositiveDefinite {
            what: "r",
            pivot: 1,
            ..
        })
    ));
    // Asymmetric R.
    let mut r3 = SMatrix::<f64, 6, 6>::identity();
    r3[(4, 2)] = 0.3;
    assert!(matches!(
        kf.update(&z, &h, &r3),
        Err(AkfError::NotSymmetric {
            what: "r",
            row: 4,
            col: 2,
            ..
        })
    ));
    assert_eq!(*kf.state(), x);
    assert_eq!(*kf.covariance(), p);
}

#[test]
fn invalid_process_noise_and_initial_covariance_are_rejected() {
    let (phi, q) = cv2d(1.0, 0.1, 0.1);
    let mut kf = KalmanFilter::new(V4::zeros(), M4::identity()).unwrap();
    let mut q_asym = q;
    q_asym[(0, 2)] += 1e-3;
    assert!(matches!(
        kf.predict(&phi, &q_asym),
        Err(AkfError::NotSymmetric { what: "q_d", .. })
    ));
    let mut q_neg = q;
    q_neg[(3, 3)] = -1e-6;
    assert!(matches!(
        kf.predict(&phi, &q_neg),
        Err(AkfError::NotPositiveSemiDefinite { what: "q_d", .. })
    ));
    // Indefinite P0 (eigenvalues 3 and −1) is rejected …
    let mut p_indef = M4::identity();
    p_indef[(0, 1)] = 2.0;
    p_indef[(1, 0)] = 2.0;
    assert!(matches!(
        KalmanFilter::new(V4::zeros(), p_indef),
        Err(AkfError::NotPositiveSemiDefinite { what: "p0", .. })
    ));
    // … a singular PSD P0 (position perfectly known) is accepted and usable.
    let p_sing = M4::from_diagonal(&V4::new(0.0, 0.0, 1.0, 1.0));
    let mut kf2 = KalmanFilter::new(V4::zeros(), p_sing).unwrap();
    kf2.predict(&phi, &q).unwrap();
    let h = SMatrix::<f64, 2, 4>::new(1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0);
    let inn = kf2
        .update(
            &SVector::<f64, 2>::new(0.5, -0.5),
            &h,
            &SMatrix::<f64, 2, 2>::identity(),
        )
        .unwrap();
    assert!(inn.nis > 0.0);
}

#[test]
fn joseph_form_keeps_psd_to_round_off_where_the_textbook_form_does_not() {
    // Very precise measurements of poorly known states (P ~ 1e8, R ~ 1e-8). The textbook
    // (I − K H) P loses positive semi-definiteness at the 1e-13 relative level; the Joseph form
    // stays at the eigen-solver's own round-off (≈ 1e-16). The bound 2e-15 separates the two.
    let mut rng = rng(61);
    let mut textbook_violations = 0;
    for case in 0..300 {
        let p = random_spd::<6>(&mut rng, 1e-3) * 1e8;
        let h: SMatrix<f64, 3, 6> = uniform_mat(&mut rng);
        let r = random_spd::<3>(&mut rng, 0.1) * 1e-8;
        let mut kf = KalmanFilter::new(SVector::zeros(), p).unwrap();
        kf.update(&SVector::<f64, 3>::zeros(), &h, &r).unwrap();
        let joseph_min = kf.covariance().symmetric_eigenvalues().min() / kf.covariance().amax();
        assert!(
            joseph_min >= -2e-15,
            "case {case}: Joseph min eigenvalue {joseph_min:e}"
        );

        let s = h * p * h.transpose() + r;
        let k = p * h.transpose() * s.try_inverse().unwrap();
        let textbook = (SMatrix::<f64, 6, 6>::identity() - k * h) * p;
        let textbook = (textbook + textbook.transpose()) * 0.5;
        if textbook.symmetric_eigenvalues().min() / textbook.amax() < -2e-15 {
            textbook_violations += 1;
        }
    }
    assert!(
        textbook_violations > 30,
        "only {textbook_violations} textbook violations"
    );
}
