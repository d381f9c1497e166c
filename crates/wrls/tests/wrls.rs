//! WRLS checked against the exponentially weighted batch least-squares solution, ordinary RLS,
//! the other form, and the algebra of eq. (27).
#![allow(clippy::unwrap_used, clippy::expect_used)]
#![allow(missing_docs)]

use info_filter::KifError;
use nalgebra::{DMatrix, DVector, Matrix3, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use wrls::{PAPER_LAMBDA, RowNorm, ThetaCov, WrlsConfig, WrlsError, WrlsFast, WrlsPaper};

fn normal(rng: &mut ChaCha8Rng) -> f64 {
    // Box–Muller, to keep the dev-dependencies to rand + rand_chacha.
    let u1: f64 = rng.random_range(f64::EPSILON..1.0);
    let u2: f64 = rng.random();
    (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
}

fn random_spd(rng: &mut ChaCha8Rng, scale: f64) -> Matrix3<f64> {
    let a = Matrix3::from_fn(|_, _| normal(rng));
    (a * a.transpose() + Matrix3::identity() * 0.05) * scale
}

fn random_frame(rng: &mut ChaCha8Rng, n: usize, truth: &Vector3<f64>) -> Vec<(f64, f64)> {
    (0..n)
        .map(|_| {
            let y: f64 = rng.random_range(0.0..480.0);
            (
                truth[0] * y * y + truth[1] * y + truth[2] + 2.0 * normal(rng),
                y,
            )
        })
        .collect()
}

/// Dense `Φ` (3×N, column i = (u², u, 1)) and `x` in the normalised row coordinate.
fn dense(points: &[(f64, f64)], norm: &RowNorm) -> (DMatrix<f64>, DVector<f64>) {
    let n = points.len();
    let mut phi = DMatrix::zeros(3, n);
    let mut x = DVector::zeros(n);
    for (i, &(col, row)) in points.iter().enumerate() {
        let u = (row - norm.center_row_px) / norm.scale_px;
        phi[(0, i)] = u * u;
        phi[(1, i)] = u;
        phi[(2, i)] = 1.0;
        x[i] = col;
    }
    (phi, x)
}

fn d3(m: &Matrix3<f64>) -> DMatrix<f64> {
    DMatrix::from_column_slice(3, 3, m.as_slice())
}

fn dv3(v: &Vector3<f64>) -> DVector<f64> {
    DVector::from_column_slice(v.as_slice())
}

fn rel_m(a: &DMatrix<f64>, b: &DMatrix<f64>) -> f64 {
    (a - b).norm() / b.norm()
}

fn rel_v(a: &DVector<f64>, b: &DVector<f64>) -> f64 {
    (a - b).norm() / b.norm()
}

#[test]
fn both_forms_equal_exponentially_weighted_batch_least_squares() {
    let mut rng = ChaCha8Rng::seed_from_u64(25);
    let norm = RowNorm::new(240.0, 240.0).unwrap();
    let mut worst: f64 = 0.0;
    for seq in 0..12 {
        let lambda = if seq == 0 {
            PAPER_LAMBDA
        } else {
            rng.random_range(0.5..=1.0)
        };
        let truth = Vector3::new(
            rng.random_range(-2e-3..2e-3),
            rng.random_range(-1.0..1.0),
            rng.random_range(50.0..270.0),
        );
        let theta0_u = Vector3::new(normal(&mut rng), normal(&mut rng), 160.0);
        let p0_u = random_spd(&mut rng, 100.0);
        let theta0_px = norm.theta_to_px(&theta0_u);
        let p0 = ThetaCov::Normalised(p0_u);
        let mut paper = WrlsPaper::new(&theta0_px, &p0, lambda, norm, 80).unwrap();
        let mut fast = WrlsFast::new(&theta0_px, &p0, lambda, norm).unwrap();
        let mut frames = Vec::new();
        for big_t in 1..=20i32 {
            // Frames of 0…80 points; 0-point frames age the past by λ too.
            let n = rng.random_range(0..=80);
            let frame = random_frame(&mut rng, n, &truth);
            paper.update(&frame).unwrap();
            fast.update(&frame).unwrap();
            frames.push(frame);

            // Batch: (λ^T P0⁻¹ + Σ_t λ^{T−t} Φ_tΦ_tᵀ) θ = λ^T P0⁻¹ θ0 + Σ_t λ^{T−t} Φ_t x_t.
            let p0_inv = d3(&p0_u).try_inverse().unwrap();
            let mut g = &p0_inv * lambda.powi(big_t);
            let mut h = &p0_inv * dv3(&theta0_u) * lambda.powi(big_t);
            for (t, f) in frames.iter().enumerate() {
                let w = lambda.powi(big_t - 1 - t as i32);
                let (phi, x) = dense(f, &norm);
                g += &phi * phi.transpose() * w;
                h += &phi * x * w;
            }
            let g_inv = g.clone().try_inverse().unwrap();
            let theta_batch = &g_inv * h;

            for (theta, p) in [
                (paper.estimate_normalised(), paper.covariance_normalised()),
                (
                    fast.estimate_normalised(),
                    fast.covariance_normalised().unwrap(),
                ),
            ] {
                worst = worst.max(rel_v(&dv3(&theta), &theta_batch));
                worst = worst.max(rel_m(&d3(&p), &g_inv));
            }
        }
    }
    assert!(
        worst < 1e-9,
        "worst relative difference to batch LS {worst:e}"
    );
}

#[test]
fn lambda_one_is_ordinary_recursive_least_squares() {
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let norm = RowNorm::default();
    let truth = Vector3::new(1e-3, -0.2, 120.0);
    let theta0_u = Vector3::new(0.0, 0.0, 150.0);
    let p0_u = random_spd(&mut rng, 50.0);
    let p0 = ThetaCov::Normalised(p0_u);
    let mut paper = WrlsPaper::new(&norm.theta_to_px(&theta0_u), &p0, 1.0, norm, 150).unwrap();
    let mut fast = WrlsFast::new(&norm.theta_to_px(&theta0_u), &p0, 1.0, norm).unwrap();
    // Ordinary RLS, one scalar measurement at a time:
    // k = Pφ/(1 + φᵀPφ), θ ← θ + k(x − φᵀθ), P ← P − kφᵀP.
    let mut theta = theta0_u;
    let mut p = p0_u;
    for _ in 0..30 {
        let n = rng.random_range(1..=150);
        let frame = random_frame(&mut rng, n, &truth);
        paper.update(&frame).unwrap();
        fast.update(&frame).unwrap();
        for &(col, row) in &frame {
            let u = norm.normalise_row(row);
            let phi = Vector3::new(u * u, u, 1.0);
            let p_phi = p * phi;
            let k = p_phi / (1.0 + phi.dot(&p_phi));
            theta += k * (col - phi.dot(&theta));
            p -= k * p_phi.transpose();
        }
        for (t, pp) in [
            (paper.estimate_normalised(), paper.covariance_normalised()),
            (
                fast.estimate_normalised(),
                fast.covariance_normalised().unwrap(),
            ),
        ] {
            assert!(rel_v(&dv3(&t), &dv3(&theta)) < 1e-9);
            assert!(
                rel_m(&d3(&pp), &d3(&p)) < 1e-8,
                "{:e}",
                rel_m(&d3(&pp), &d3(&p))
            );
        }
    }
}

#[test]
fn paper_and_fast_forms_give_the_same_estimates_over_long_sequences() {
    let mut rng = ChaCha8Rng::seed_from_u64(2227);
    let norm = RowNorm::new(240.0, 240.0).unwrap();
    let mut worst: f64 = 0.0;
    for _ in 0..5 {
        let truth = Vector3::new(-5e-4, 0.3, 200.0);
        let theta0 = Vector3::new(0.0, 0.0, 150.0);
        let p0 = ThetaCov::Normalised(Matrix3::identity() * 1e3);
        let mut paper = WrlsPaper::new(&theta0, &p0, PAPER_LAMBDA, norm, 150).unwrap();
        let mut fast = WrlsFast::new(&theta0, &p0, PAPER_LAMBDA, norm).unwrap();
        for _ in 0..200 {
            let n = rng.random_range(3..=150);
            let frame = random_frame(&mut rng, n, &truth);
            paper.update(&frame).unwrap();
            fast.update(&frame).unwrap();
            worst = worst.max(rel_v(&dv3(&paper.estimate()), &dv3(&fast.estimate())));
            worst = worst.max(rel_m(
                &d3(&paper.covariance_normalised()),
                &d3(&fast.covariance_normalised().unwrap()),
            ));
        }
    }
    assert!(
        worst < 1e-9,
        "paper vs fast worst relative difference {worst:e}"
    );
}

#[test]
fn corrected_eq27_equals_lambda_inverse_i_minus_k_phi_t_p_and_the_printed_one_does_not() {
    let mut rng = ChaCha8Rng::seed_from_u64(27);
    let norm = RowNorm::default();
    let lambda = PAPER_LAMBDA;
    for _ in 0..20 {
        let theta0_u = Vector3::new(normal(&mut rng), normal(&mut rng), 150.0);
        let p_u = random_spd(&mut rng, 10.0);
        let mut paper = WrlsPaper::new(
            &norm.theta_to_px(&theta0_u),
            &ThetaCov::Normalised(p_u),
            lambda,
            norm,
            150,
        )
        .unwrap();
        // At least 3 points so that K Kᵀ is not negligible next to P in every direction
        // (λ = 0.7 then moves P by roughly 1 − λ = 30 %).
        let n = rng.random_range(3..=40);
        let frame = random_frame(&mut rng, n, &Vector3::new(1e-3, -0.4, 150.0));
        paper.update(&frame).unwrap();

        // Eq. (26) with an explicit N×N inverse, eq. (25), and the closed form λ⁻¹(I − Kφᵀ)P.
        let (phi, x) = dense(&frame, &norm);
        let p = d3(&p_u);
        let s = DMatrix::identity(n, n) * lambda + phi.transpose() * &p * &phi;
        let k = &p * &phi * s.try_inverse().unwrap();
        let i_kf = DMatrix::identity(3, 3) - &k * phi.transpose();
        let closed = &i_kf * &p / lambda;
        let corrected = &i_kf * &p * i_kf.transpose() / lambda + &k * k.transpose();
        let printed = &i_kf * &p * i_kf.transpose() / lambda + &k * k.transpose() * lambda;
        let theta_expected = dv3(&theta0_u) + &k * (x - phi.transpose() * dv3(&theta0_u));

        // The implementation equals the closed form, and so does the corrected eq. 27. The
        // closed form subtracts KφᵀP from P, so its round-off scales with ‖P_t‖/λ, not with the
        // (much smaller) result: measure the differences against that.
        let scale = p.norm() / lambda;
        let got = d3(&paper.covariance_normalised());
        let e_impl = (&got - &closed).norm() / scale;
        assert!(e_impl < 1e-10, "implementation vs closed form {e_impl:e}");
        let e_corr = (&corrected - &closed).norm() / scale;
        assert!(e_corr < 1e-10, "corrected eq. 27 vs closed form {e_corr:e}");
        assert!(rel_v(&dv3(&paper.estimate_normalised()), &theta_expected) < 1e-9);
        // The printed placement is off by exactly (λ − 1) K Kᵀ — far from round-off.
        let kkt = &k * k.transpose();
        assert!(rel_m(&(&printed - &closed), &(&kkt * (lambda - 1.0))) < 1e-6);
        let e_printed = rel_m(&printed, &closed);
        assert!(e_printed > 1e-2, "printed eq. 27 too close: {e_printed:e}");
    }
}

#[test]
fn empty_frame_only_forgets() {
    let norm = RowNorm::default();
    let theta0 = Vector3::new(1e-3, -0.5, 200.0);
    let p0_u = Matrix3::new(4.0, 1.0, 0.5, 1.0, 3.0, 0.2, 0.5, 0.2, 2.0);
    let p0 = ThetaCov::Normalised(p0_u);
    let mut paper = WrlsPaper::new(&theta0, &p0, 0.8, norm, 10).unwrap();
    let mut fast = WrlsFast::new(&theta0, &p0, 0.8, norm).unwrap();
    paper.update::<(f32, f32)>(&[]).unwrap();
    fast.update::<(f32, f32)>(&[]).unwrap();
    let expected = p0_u / 0.8;
    assert!((paper.covariance_normalised() - expected).norm() < 1e-12 * expected.norm());
    assert!((fast.covariance_normalised().unwrap() - expected).norm() < 1e-12 * expected.norm());
    assert!((paper.estimate() - theta0).norm() < 1e-12 * theta0.norm());
    assert!((fast.estimate() - theta0).norm() < 1e-12 * theta0.norm());
}

#[test]
fn paper_form_grows_its_buffers_when_a_frame_exceeds_max_points() {
    let mut rng = ChaCha8Rng::seed_from_u64(9);
    let norm = RowNorm::default();
    let theta0 = Vector3::new(0.0, 0.0, 150.0);
    let p0 = ThetaCov::Normalised(Matrix3::identity() * 100.0);
    let mut paper = WrlsPaper::new(&theta0, &p0, 0.9, norm, 10).unwrap();
    let mut fast = WrlsFast::new(&theta0, &p0, 0.9, norm).unwrap();
    assert_eq!(paper.capacity(), 10);
    for n in [5, 50, 20] {
        let frame = random_frame(&mut rng, n, &Vector3::new(1e-3, 0.1, 100.0));
        paper.update(&frame).unwrap();
        fast.update(&frame).unwrap();
        assert!(rel_v(&dv3(&paper.estimate()), &dv3(&fast.estimate())) < 1e-9);
    }
    assert_eq!(paper.capacity(), 50);
}

#[test]
fn bad_inputs_are_typed_errors() {
    let norm = RowNorm::default();
    let theta0 = Vector3::new(0.0, 0.0, 150.0);
    let p0 = ThetaCov::Normalised(Matrix3::identity());
    for bad in [0.0, -0.5, 1.0 + 1e-12, f64::NAN, f64::INFINITY] {
        let is_lambda_err = |e: WrlsError| {
            matches!(e, WrlsError::InvalidForgettingFactor { field: "lambda", value }
                if value.to_bits() == bad.to_bits())
        };
        assert!(is_lambda_err(
            WrlsPaper::new(&theta0, &p0, bad, norm, 10).unwrap_err()
        ));
        assert!(is_lambda_err(
            WrlsFast::new(&theta0, &p0, bad, norm).unwrap_err()
        ));
        assert!(is_lambda_err(
            WrlsConfig { lambda: bad }.validate().unwrap_err()
        ));
    }
    assert!(WrlsConfig::default().validate().is_ok());
    assert!(WrlsFast::new(&theta0, &p0, 1.0, norm).is_ok());

    let mut paper = WrlsPaper::new(&theta0, &p0, 0.7, norm, 10).unwrap();
    let mut fast = WrlsFast::new(&theta0, &p0, 0.7, norm).unwrap();
    let (p_before, t_before) = (paper.covariance_normalised(), paper.estimate());
    let fast_before = fast.clone();
    let bad_points = [(10.0f32, 1.0f32), (11.0, 2.0), (12.0, f32::NAN)];
    assert!(matches!(
        paper.update(&bad_points),
        Err(WrlsError::Filter(KifError::NonFinitePoint { index: 2, .. }))
    ));
    assert!(matches!(
        fast.update(&bad_points),
        Err(WrlsError::Filter(KifError::NonFinitePoint { index: 2, .. }))
    ));
    assert_eq!(paper.covariance_normalised(), p_before);
    assert_eq!(paper.estimate(), t_before);
    assert_eq!(fast, fast_before);

    let not_pd = ThetaCov::Normalised(Matrix3::new(1.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0, 0.0, 1.0));
    assert!(matches!(
        WrlsPaper::new(&theta0, &not_pd, 0.7, norm, 10),
        Err(WrlsError::Filter(KifError::NotPositiveDefinite {
            matrix: "P0",
            pivot: 1,
            ..
        }))
    ));
    assert!(matches!(
        WrlsFast::new(&Vector3::new(f64::NAN, 0.0, 0.0), &p0, 0.7, norm),
        Err(WrlsError::Filter(KifError::NonFiniteVector {
            vector: "theta0_px",
            index: 0,
            ..
        }))
    ));
    assert!(matches!(
        WrlsFast::new(
            &theta0,
            &p0,
            0.7,
            RowNorm {
                center_row_px: 0.0,
                scale_px: 0.0
            }
        ),
        Err(WrlsError::Filter(KifError::InvalidRowNorm {
            field: "scale_px",
            ..
        }))
    ));
}

#[test]
fn config_rejects_unknown_fields_and_defaults_to_the_paper_lambda() {
    let c: WrlsConfig = serde_json::from_str(r#"{"lambda": 0.9}"#).unwrap();
    assert!(c.validate().is_ok());
    assert!(serde_json::from_str::<WrlsConfig>(r#"{"lambda": 0.9, "lamda": 0.8}"#).is_err());
    assert_eq!(WrlsConfig::default().lambda, 0.70);
}
