//! Discretisation and linearisation checks: Van Loan Φ ≡ matrix exponential, Q_d ≡ numerical
//! integral, fast series forms vs Van Loan, block covariance propagation vs dense, gravity
//! block vs finite differences, error-state extraction vs injection.
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use ins_errors::config::TrajectoryConfig;
use ins_errors::earth::{self, skew};
use ins_errors::error_model::{
    Mat12, Mat15, Transition, continuous_noise_psd, discretize_fast, error_state, expm,
    gravity_gradient_block, inject_errors, noise_input_matrix, propagate_covariance, system_matrix,
    van_loan,
};
use ins_errors::strapdown::{LinearizationPoint, NavState};
use ins_errors::trajectory::Trajectory;
use nalgebra::{Matrix3, SMatrix, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Linearisation point in the middle of the 60° right turn (t = 130 s) of the paper's flight.
fn turn_point() -> LinearizationPoint {
    let tr = Trajectory::new(&TrajectoryConfig::paper()).unwrap();
    let s = tr.samples().nth(13_000).unwrap();
    let c = s.att_b_to_n.to_rotation_matrix().into_inner();
    LinearizationPoint {
        pos: s.pos,
        vel_ned_mps: s.vel_ned_mps,
        specific_force_ned_mps2: c * s.specific_force_body_mps2,
        c_b_to_n: c,
    }
}

fn paper_qc() -> Mat12 {
    // Paper PSDs (per-sample variance × T_s) plus small bias random walks to excite every block.
    continuous_noise_psd(9.6e-7, 2.35e-13, 1e-10, 1e-16)
}

/// Independent exponential: Taylor series (30 terms) with scaling to ‖M‖ ≤ 1/16 and squaring.
fn expm_taylor<const N: usize>(m: &SMatrix<f64, N, N>) -> SMatrix<f64, N, N> {
    let norm = m.abs().row_sum().max();
    let s = if norm > 1.0 / 16.0 {
        (norm * 16.0).log2().ceil() as i32
    } else {
        0
    };
    let x = m * 2f64.powi(-s);
    let mut term = SMatrix::<f64, N, N>::identity();
    let mut sum = term;
    for k in 1..30 {
        term = term * x / k as f64;
        sum += term;
    }
    for _ in 0..s {
        sum = sum * sum;
    }
    sum
}

fn max_rel(a: &Mat15, b: &Mat15) -> f64 {
    (a - b).abs().max() / b.abs().max()
}

/// Normalised difference max |a_ij − b_ij| / √(b_ii b_jj) (covariance-like matrices).
fn cov_diff(a: &Mat15, b: &Mat15) -> f64 {
    let mut m: f64 = 0.0;
    for i in 0..15 {
        for j in 0..15 {
            m = m.max((a[(i, j)] - b[(i, j)]).abs() / (b[(i, i)] * b[(j, j)]).sqrt());
        }
    }
    m
}

#[test]
fn expm_of_skew_is_rodrigues_rotation() {
    let w = Vector3::new(0.3, -1.2, 2.0);
    for t in [1e-3, 0.5, 3.0, 40.0] {
        let e = expm(&(skew(&w) * t)).unwrap();
        let th = w.norm() * t;
        let k = skew(&(w / w.norm()));
        let r = Matrix3::identity() + th.sin() * k + (1.0 - th.cos()) * k * k;
        assert!(
            (e - r).abs().max() < 1e-12 * (1.0 + t),
            "t {t}: {}",
            (e - r).abs().max()
        );
    }
}

#[test]
fn expm_rejects_non_finite_input() {
    let mut m = Mat15::zeros();
    m[(2, 3)] = f64::NAN;
    assert!(expm(&m).is_err());
}

/// Van Loan Φ equals e^{AT} computed independently (Taylor + scaling-squaring), for the 0.01 s
/// INS step, the 1 s filter interval and 100 s.
#[test]
fn van_loan_phi_is_matrix_exponential() {
    let lp = turn_point();
    let a = system_matrix(&lp);
    let g = noise_input_matrix(&lp.c_b_to_n);
    for dt in [0.01, 1.0, 100.0] {
        let (phi, _) = van_loan(&a, &g, &paper_qc(), dt).unwrap();
        let reference = expm_taylor(&(a * dt));
        let e = max_rel(&phi, &reference);
        println!("dt {dt}: Van Loan Φ vs Taylor expm max rel {e:.2e}");
        // Rounding grows with the number of squarings (≈ log2(‖A‖T)).
        assert!(e < 5e-14 * (1.0 + dt), "dt {dt}: {e}");
    }
}

/// Q_d equals Simpson's rule over 1000 sub-steps of ∫ Φ(s) G Q Gᵀ Φ(s)ᵀ ds.
#[test]
fn van_loan_qd_is_integral_of_propagated_noise() {
    let lp = turn_point();
    let a = system_matrix(&lp);
    let g = noise_input_matrix(&lp.c_b_to_n);
    let w = g * paper_qc() * g.transpose();
    for dt in [0.01, 1.0] {
        let (_, qd) = van_loan(&a, &g, &paper_qc(), dt).unwrap();
        let n = 1000;
        let h = dt / n as f64;
        let step = expm_taylor(&(a * h));
        let mut phi = Mat15::identity();
        let mut sum = Mat15::zeros();
        for i in 0..=n {
            let wgt = if i == 0 || i == n {
                1.0
            } else if i % 2 == 1 {
                4.0
            } else {
                2.0
            };
            sum += wgt * phi * w * phi.transpose();
            phi = step * phi;
        }
        let simpson = sum * (h / 3.0);
        let e = cov_diff(&qd, &simpson);
        println!("dt {dt}: Van Loan Q_d vs Simpson normalised max diff {e:.2e}");
        assert!(e < 1e-9, "dt {dt}: {e}");
    }
}

/// The fast forms used at the 0.01 s step agree with Van Loan: Φ (third-order series) to
/// 1e-11 relative (measured 5.4e-13); Q_d (Simpson on [0, T]) to 1e-9 of √(Q_ii Q_jj)
/// (measured 7.9e-11).
#[test]
fn fast_discretisation_matches_van_loan_at_ins_step() {
    let lp = turn_point();
    let a = system_matrix(&lp);
    let g = noise_input_matrix(&lp.c_b_to_n);
    let qc = paper_qc();
    let dt = 0.01;
    let (phi_vl, qd_vl) = van_loan(&a, &g, &qc, dt).unwrap();
    let (phi, qd) = discretize_fast(&a, &(g * qc * g.transpose()), dt);
    let e_phi = max_rel(&phi.to_dense(), &phi_vl);
    let e_q = cov_diff(&qd, &qd_vl);
    let e_q_abs = (qd - qd_vl).abs().max() / qd_vl.abs().max();
    println!(
        "Φ series vs Van Loan {e_phi:.2e}; Q_d Simpson vs Van Loan normalised {e_q:.2e}, rel-to-max {e_q_abs:.2e}"
    );
    assert!(e_phi < 1e-11, "{e_phi}");
    assert!(e_q < 1e-9, "{e_q}");
    assert!(e_q_abs < 1e-8, "{e_q_abs}");
    // Φ's last six rows are [0 I] exactly in the Van Loan result too (structure assumed).
    let tail = phi_vl.fixed_view::<6, 15>(9, 0) - Mat15::identity().fixed_view::<6, 15>(9, 0);
    assert!(tail.abs().max() < 1e-13);
}

/// Block propagation equals the dense Φ P Φᵀ + Q_d on a random SPD P.
#[test]
fn block_covariance_propagation_equals_dense() {
    let lp = turn_point();
    let a = system_matrix(&lp);
    let g = noise_input_matrix(&lp.c_b_to_n);
    let (phi, qd) = van_loan(&a, &g, &paper_qc(), 0.01).unwrap();
    let tr = Transition::from_dense(&phi);
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let l = Mat15::from_fn(|_, _| rng.random_range(-1.0..1.0));
    let p0 = l * l.transpose() + Mat15::identity();
    let dense = phi * p0 * phi.transpose() + qd;
    let mut p = p0;
    propagate_covariance(&mut p, &tr, &qd);
    assert!(max_rel(&p, &dense) < 1e-14, "{}", max_rel(&p, &dense));
    assert_eq!(p, p.transpose());
}

/// A's gravity block against central finite differences of the gravity model: δg(δp) = g^c at the
/// computed position minus C_t^c g^t at the true one (true = computed displaced by −δp).
#[test]
fn gravity_block_matches_finite_differences() {
    let lp = turn_point();
    let gp = gravity_gradient_block(lp.pos.lat_rad, lp.pos.alt_m);
    let base = NavState {
        pos: lp.pos,
        vel_ned_mps: Vector3::zeros(),
        att_b_to_n: nalgebra::UnitQuaternion::identity(),
    };
    let dg = |dp: &Vector3<f64>| {
        let truth_pos = earth::displace_by_ned_m(&base.pos, &(-dp));
        let c_tc = earth::ned_from_ecef(base.pos.lat_rad, base.pos.lon_rad)
            * earth::ned_from_ecef(truth_pos.lat_rad, truth_pos.lon_rad).transpose();
        earth::gravity_ned_mps2(base.pos.lat_rad, base.pos.alt_m)
            - c_tc * earth::gravity_ned_mps2(truth_pos.lat_rad, truth_pos.alt_m)
    };
    for i in 0..3 {
        let mut e = Vector3::zeros();
        e[i] = 10.0;
        let fd = (dg(&e) - dg(&(-e))) / 20.0;
        let col = gp.column(i).into_owned();
        println!("column {i}: analytic {col:?} fd {fd:?}");
        assert!((fd - col).norm() < 1e-4 * gp.abs().max(), "column {i}");
    }
    // The sanity figures: −g/R horizontally, +2g/R ≈ 3.07e-6 s⁻² vertically.
    assert!((gp[(2, 2)] - 3.07e-6).abs() < 0.01e-6);
}

#[test]
fn error_state_inverts_injection() {
    let lp = turn_point();
    let truth = NavState {
        pos: lp.pos,
        vel_ned_mps: lp.vel_ned_mps,
        att_b_to_n: nalgebra::UnitQuaternion::from_matrix(&lp.c_b_to_n),
    };
    let dp = Vector3::new(120.0, -80.0, 15.0);
    let dv = Vector3::new(0.5, -0.3, 0.1);
    let psi = Vector3::new(2e-3, -1e-3, 5e-3);
    let x = error_state(&truth, &inject_errors(&truth, &dp, &dv, &psi));
    assert!((x.fixed_rows::<3>(0) - dp).norm() < 1e-6);
    assert!((x.fixed_rows::<3>(3) - dv).norm() < 1e-9);
    assert!((x.fixed_rows::<3>(6) - psi).norm() < 1e-12);
}
