//! KIF checked against independent forms: the covariance-form Kalman filter (Joseph update),
//! eq. (24) vs eq. (7), dense φR⁻¹φᵀ vs power sums, positive definiteness over 10⁶ updates.
#![allow(clippy::unwrap_used, clippy::expect_used)]
#![allow(missing_docs)]

use info_filter::{
    InformationFilter, KifError, ParabolaKif, PowerSums, ProcessNoise, RowNorm, ThetaCov,
    TimeUpdateForm,
};
use nalgebra::{DMatrix, DVector, Matrix3, SMatrix, SVector, SymmetricEigen, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;

fn normal(rng: &mut ChaCha8Rng) -> f64 {
    rng.sample::<f64, _>(StandardNormal)
}

/// Random SPD 3×3 matrix `scale · (A Aᵀ + 0.05 I)`.
fn random_spd(rng: &mut ChaCha8Rng, scale: f64) -> Matrix3<f64> {
    let a = Matrix3::from_fn(|_, _| normal(rng));
    (a * a.transpose() + Matrix3::identity() * 0.05) * scale
}

/// Random frame: `n` points spread over rows [0, 480) around a parabola, with column noise.
fn random_points(rng: &mut ChaCha8Rng, n: usize, theta_px: &Vector3<f64>) -> Vec<(f64, f64)> {
    (0..n)
        .map(|_| {
            let y: f64 = rng.random_range(0.0..480.0);
            let x = theta_px[0] * y * y + theta_px[1] * y + theta_px[2] + 3.0 * normal(rng);
            (x, y)
        })
        .collect()
}

fn rel(a: &DMatrix<f64>, b: &DMatrix<f64>) -> f64 {
    (a - b).norm() / b.norm()
}

/// Plain covariance-form Kalman filter in the normalised parameterisation, written out:
/// predict `P ← P + Q`; update `K = Pφ(φᵀPφ + R)⁻¹`, `θ ← θ + K(x − φᵀθ)`,
/// `P ← (I − Kφᵀ) P (I − Kφᵀ)ᵀ + K R Kᵀ` (Joseph).
struct ReferenceKf {
    theta: DVector<f64>,
    p: DMatrix<f64>,
}

impl ReferenceKf {
    fn predict(&mut self, q: &Matrix3<f64>) {
        self.p += DMatrix::from_column_slice(3, 3, q.as_slice());
    }

    fn update(&mut self, points: &[(f64, f64)], sigma2: f64, norm: &RowNorm) {
        let n = points.len();
        if n == 0 {
            return;
        }
        // φ is 3×N with column i = (u², u, 1).
        let mut phi = DMatrix::zeros(3, n);
        let mut x = DVector::zeros(n);
        for (i, &(col, row)) in points.iter().enumerate() {
            let u = (row - norm.center_row_px) / norm.scale_px;
            phi[(0, i)] = u * u;
            phi[(1, i)] = u;
            phi[(2, i)] = 1.0;
            x[i] = col;
        }
        let r = DMatrix::identity(n, n) * sigma2;
        let s = phi.transpose() * &self.p * &phi + &r;
        let k = &self.p * &phi * s.try_inverse().unwrap();
        let innov = &x - phi.transpose() * &self.theta;
        self.theta += &k * innov;
        let i_kh = DMatrix::identity(3, 3) - &k * phi.transpose();
        self.p = &i_kh * &self.p * i_kh.transpose() + &k * r * k.transpose();
    }
}

fn to_d(m: &Matrix3<f64>) -> DMatrix<f64> {
    DMatrix::from_column_slice(3, 3, m.as_slice())
}

fn dv(v: &DVector<f64>) -> DMatrix<f64> {
    DMatrix::from_column_slice(v.len(), 1, v.as_slice())
}

fn to_dv(v: &Vector3<f64>) -> DMatrix<f64> {
    DMatrix::from_column_slice(3, 1, v.as_slice())
}

#[test]
fn kif_equals_covariance_form_kalman_filter_on_random_sequences() {
    let mut rng = ChaCha8Rng::seed_from_u64(0x4b49_4601);
    let norm = RowNorm::new(240.0, 240.0).unwrap();
    let mut worst_theta: f64 = 0.0;
    let mut worst_p: f64 = 0.0;
    for _sequence in 0..40 {
        let truth = Vector3::new(
            rng.random_range(-2e-3..2e-3),
            rng.random_range(-1.0..1.0),
            rng.random_range(50.0..270.0),
        );
        let theta0_u = Vector3::new(normal(&mut rng), normal(&mut rng), 160.0 + normal(&mut rng));
        let p0_u = {
            let sc = 10f64.powf(rng.random_range(0.0..3.0));
            random_spd(&mut rng, sc)
        };
        let mut kif = ParabolaKif::new(
            &norm.theta_to_px(&theta0_u),
            &ThetaCov::Normalised(p0_u),
            norm,
        )
        .unwrap();
        let mut kf = ReferenceKf {
            theta: DVector::from_column_slice(theta0_u.as_slice()),
            p: to_d(&p0_u),
        };
        for _frame in 0..30 {
            let q_u = {
                let sc = 10f64.powf(rng.random_range(-4.0..1.0));
                random_spd(&mut rng, sc)
            };
            let q = ProcessNoise::new(&q_u).unwrap();
            kif.predict(&q).unwrap();
            kf.predict(&q_u);
            // 0, 1 and 2 points make rank-deficient increments: still a valid update.
            let n = rng.random_range(0..=60);
            let sigma2 = 10f64.powf(rng.random_range(-1.0..1.0));
            let points = random_points(&mut rng, n, &truth);
            kif.update(&points, sigma2).unwrap();
            kf.update(&points, sigma2, &norm);

            let e_theta = rel(&to_dv(&kif.estimate_normalised()), &dv(&kf.theta));
            let e_p = rel(&to_d(&kif.covariance_normalised().unwrap()), &kf.p);
            worst_theta = worst_theta.max(e_theta);
            worst_p = worst_p.max(e_p);
        }
    }
    assert!(worst_theta < 1e-9, "worst relative θ error {worst_theta:e}");
    assert!(worst_p < 1e-9, "worst relative P error {worst_p:e}");
}

#[test]
fn generic_filter_with_dense_correlated_r_equals_kalman_filter() {
    // N = 3 parameters, M = 4 measurements per step with a full (correlated) R.
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let theta0 = Vector3::new(1.0, -2.0, 0.5);
    let p0 = random_spd(&mut rng, 2.0);
    let mut f = InformationFilter::<3>::new(&theta0, &p0).unwrap();
    let mut theta = DVector::from_column_slice(theta0.as_slice());
    let mut p = to_d(&p0);
    for _ in 0..50 {
        let q = random_spd(&mut rng, 0.01);
        f.predict(&ProcessNoise::new(&q).unwrap()).unwrap();
        p += to_d(&q);
        let phi = SMatrix::<f64, 3, 4>::from_fn(|_, _| normal(&mut rng));
        let a = SMatrix::<f64, 4, 4>::from_fn(|_, _| normal(&mut rng));
        let r = a * a.transpose() + SMatrix::<f64, 4, 4>::identity() * 0.1;
        let x = SVector::<f64, 4>::from_fn(|_, _| normal(&mut rng));
        f.update(&phi, &r, &x).unwrap();

        let phi_d = DMatrix::from_column_slice(3, 4, phi.as_slice());
        let r_d = DMatrix::from_column_slice(4, 4, r.as_slice());
        let s = phi_d.transpose() * &p * &phi_d + &r_d;
        let k = &p * &phi_d * s.try_inverse().unwrap();
        theta += &k * (DVector::from_column_slice(x.as_slice()) - phi_d.transpose() * &theta);
        let i_kh = DMatrix::identity(3, 3) - &k * phi_d.transpose();
        p = &i_kh * &p * i_kh.transpose() + &k * r_d * k.transpose();

        assert!(rel(&to_dv(&f.estimate()), &dv(&theta)) < 1e-9);
        assert!(rel(&to_d(&f.covariance().unwrap()), &p) < 1e-9);
    }
}

#[test]
fn eq24_time_update_equals_eq7_to_round_off() {
    let mut rng = ChaCha8Rng::seed_from_u64(24);
    let norm = RowNorm::default();
    let truth = Vector3::new(1e-3, -0.4, 180.0);
    let p0 = ThetaCov::Normalised(random_spd(&mut rng, 50.0));
    let mut pd = ParabolaKif::new(&Vector3::new(0.0, 0.0, 160.0), &p0, norm).unwrap();
    let mut plain = pd.clone();
    plain.set_time_update_form(TimeUpdateForm::Plain);
    assert_eq!(
        pd.filter().time_update_form(),
        TimeUpdateForm::PositiveDefinite
    );
    let mut worst: f64 = 0.0;
    for _ in 0..200 {
        let q = ProcessNoise::new(&{
            let sc = 10f64.powf(rng.random_range(-4.0..1.0));
            random_spd(&mut rng, sc)
        })
        .unwrap();
        pd.predict(&q).unwrap();
        plain.predict(&q).unwrap();
        // Compare right after the time update, where the two forms differ algebraically.
        worst = worst.max(rel(
            &to_d(&plain.information_normalised()),
            &to_d(&pd.information_normalised()),
        ));
        worst = worst.max(rel(
            &to_dv(&plain.information_vector_normalised()),
            &to_dv(&pd.information_vector_normalised()),
        ));
        let n = rng.random_range(1..=150);
        let points = random_points(&mut rng, n, &truth);
        pd.update(&points, 2.0).unwrap();
        plain.update(&points, 2.0).unwrap();
        worst = worst.max(rel(&to_dv(&plain.estimate()), &to_dv(&pd.estimate())));
    }
    assert!(
        worst < 1e-9,
        "eq. 24 vs eq. 7 worst relative difference {worst:e}"
    );
}

#[test]
fn information_matrix_stays_positive_definite_over_a_million_updates() {
    let mut rng = ChaCha8Rng::seed_from_u64(1_000_000);
    let norm = RowNorm::new(240.0, 240.0).unwrap();
    let truth = Vector3::new(5e-4, -0.3, 150.0);
    let mut kif = ParabolaKif::new(
        &Vector3::new(0.0, 0.0, 160.0),
        &ThetaCov::Normalised(Matrix3::identity() * 1e4),
        norm,
    )
    .unwrap();
    // A small pool of process noises spanning ten decades, validated once (as a tracker would).
    let qs: Vec<ProcessNoise<3>> = (0..16)
        .map(|i| {
            let scale = 10f64.powf(-8.0 + 10.0 * f64::from(i) / 15.0);
            ProcessNoise::new(&random_spd(&mut rng, scale)).unwrap()
        })
        .collect();
    let mut points = [(0.0f64, 0.0f64); 8];
    let mut min_eig = f64::INFINITY;
    for step in 0..1_000_000u32 {
        let q = &qs[rng.random_range(0..qs.len())];
        kif.predict(q).unwrap();
        // 1..=8 points (often rank-deficient increments), σ² over four decades.
        let n = rng.random_range(1..=8);
        for p in points.iter_mut().take(n) {
            let y: f64 = rng.random_range(0.0..480.0);
            *p = (
                truth[0] * y * y + truth[1] * y + truth[2] + normal(&mut rng),
                y,
            );
        }
        let sigma2 = 10f64.powf(rng.random_range(-2.0..2.0));
        // `update` factorises the new Y by Cholesky and fails on a non-positive pivot.
        if let Err(e) = kif.update(&points[..n], sigma2) {
            panic!("step {step}: {e}");
        }
        let y = kif.information_normalised();
        assert_eq!(y, y.transpose(), "step {step}: Y not exactly symmetric");
        let eig = SymmetricEigen::new(y).eigenvalues.min();
        assert!(eig > 0.0, "step {step}: min eigenvalue {eig:e}");
        min_eig = min_eig.min(eig);
    }
    assert!(min_eig > 0.0);
    assert!(kif.estimate().iter().all(|v| v.is_finite()));
}

#[test]
fn power_sum_update_equals_dense_phi_r_inv_phi_t() {
    let mut rng = ChaCha8Rng::seed_from_u64(42);
    let norm = RowNorm::new(240.0, 240.0).unwrap();
    for _ in 0..50 {
        let n = rng.random_range(1..=150);
        let sigma2 = 10f64.powf(rng.random_range(-1.0..1.0));
        let truth = Vector3::new(1e-3, -0.5, 200.0);
        let points = random_points(&mut rng, n, &truth);
        let mut kif = ParabolaKif::new(
            &Vector3::new(0.0, 0.0, 100.0),
            &ThetaCov::Normalised(random_spd(&mut rng, 10.0)),
            norm,
        )
        .unwrap();
        let y_before = kif.information_normalised();
        let yv_before = kif.information_vector_normalised();
        let ypx_before = kif.information();
        kif.update(&points, sigma2).unwrap();

        // Dense 3×N φ (normalised and pixel) and N×N R⁻¹.
        let mut phi_u = DMatrix::zeros(3, n);
        let mut phi_px = DMatrix::zeros(3, n);
        let mut x = DVector::zeros(n);
        for (i, &(col, row)) in points.iter().enumerate() {
            let u = (row - 240.0) / 240.0;
            phi_u.set_column(i, &DVector::from_vec(vec![u * u, u, 1.0]));
            phi_px.set_column(i, &DVector::from_vec(vec![row * row, row, 1.0]));
            x[i] = col;
        }
        let r_inv = DMatrix::identity(n, n) / sigma2;
        let d_y = &phi_u * &r_inv * phi_u.transpose();
        let d_yv = &phi_u * &r_inv * &x;
        let d_y_px = &phi_px * &r_inv * phi_px.transpose();

        let got = to_d(&(kif.information_normalised() - y_before));
        assert!(rel(&got, &d_y) < 1e-12, "ΔY {:e}", rel(&got, &d_y));
        let got_v = to_dv(&(kif.information_vector_normalised() - yv_before));
        assert!(rel(&got_v, &dv(&d_yv)) < 1e-12);
        // Pixel information (Mᵀ Y_u M) increments by φ_px R⁻¹ φ_pxᵀ: entry-wise relative, since
        // entries span ~10 orders of magnitude.
        let got_px = kif.information() - ypx_before;
        for i in 0..3 {
            for j in 0..3 {
                let e = (got_px[(i, j)] - d_y_px[(i, j)]).abs() / d_y_px[(i, j)].abs();
                assert!(e < 1e-6, "ΔY_px({i},{j}) relative error {e:e}");
            }
        }
    }
}

#[test]
fn row_normalisation_maps_are_inverse_and_preserve_the_curve_and_its_variance() {
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    for _ in 0..100 {
        let norm =
            RowNorm::new(rng.random_range(0.0..480.0), rng.random_range(10.0..500.0)).unwrap();
        let theta_px = Vector3::new(
            normal(&mut rng) * 1e-3,
            normal(&mut rng),
            100.0 * normal(&mut rng),
        );
        let theta_u = norm.theta_to_normalised(&theta_px);
        assert!((norm.theta_to_px(&theta_u) - theta_px).norm() <= 1e-9 * theta_px.norm());
        let t = norm.normalised_to_px_matrix();
        let m = norm.px_to_normalised_matrix();
        assert!((t * m - Matrix3::identity()).norm() < 1e-9);
        let p_u = random_spd(&mut rng, 1.0);
        let p_px = norm.cov_to_px(&p_u);
        assert!((norm.cov_to_normalised(&p_px) - p_u).norm() < 1e-8 * p_u.norm());
        for _ in 0..5 {
            let y: f64 = rng.random_range(0.0..480.0);
            let u = norm.normalise_row(y);
            let phi_px = Vector3::new(y * y, y, 1.0);
            let phi_u = Vector3::new(u * u, u, 1.0);
            // Same curve …
            let x_px = phi_px.dot(&theta_px);
            assert!((x_px - phi_u.dot(&theta_u)).abs() < 1e-9 * (1.0 + x_px.abs()));
            // … and the same variance of the predicted column in both parameterisations.
            let v_u = (phi_u.transpose() * p_u * phi_u)[0];
            let v_px = (phi_px.transpose() * p_px * phi_px)[0];
            assert!((v_u - v_px).abs() < 1e-7 * v_u, "{v_u} vs {v_px}");
        }
    }
}

#[test]
fn noiseless_points_converge_to_the_true_parabola_in_pixels() {
    let truth = Vector3::new(-8e-4, 0.6, 40.0);
    let norm = RowNorm::for_image_height(480).unwrap();
    let points: Vec<[f32; 2]> = (0..150)
        .map(|i| {
            let y = 200.0 + 1.8 * f64::from(i);
            [
                (truth[0] * y * y + truth[1] * y + truth[2]) as f32,
                y as f32,
            ]
        })
        .collect();
    let mut kif = ParabolaKif::new(
        &Vector3::new(0.0, 0.0, 100.0),
        &ThetaCov::Normalised(Matrix3::identity() * 1e4),
        norm,
    )
    .unwrap();
    let q = kif
        .process_noise(&ThetaCov::Normalised(Matrix3::identity() * 1e-6))
        .unwrap();
    for _ in 0..20 {
        kif.predict(&q).unwrap();
        kif.update(&points, 1.0).unwrap();
    }
    for y in [200.0, 300.0, 468.0] {
        let x_true = truth[0] * y * y + truth[1] * y + truth[2];
        assert!((kif.col_at_row_px(y) - x_true).abs() < 0.01, "row {y}");
    }
    // The pixel covariance agrees with the normalised one mapped by T.
    let p_px = kif.covariance().unwrap();
    let p_u = kif.covariance_normalised().unwrap();
    assert!((p_px - norm.cov_to_px(&p_u)).norm() <= 1e-12 * p_px.norm());
}

#[test]
fn empty_frame_is_a_no_op_but_still_validates_the_variance() {
    let mut kif = ParabolaKif::new(
        &Vector3::new(1e-3, 0.0, 100.0),
        &ThetaCov::Normalised(Matrix3::identity()),
        RowNorm::default(),
    )
    .unwrap();
    let before = kif.clone();
    kif.update::<(f32, f32)>(&[], 1.0).unwrap();
    assert_eq!(kif, before);
    assert!(matches!(
        kif.update::<(f32, f32)>(&[], f64::NAN),
        Err(KifError::InvalidVariance {
            name: "sigma2_px2",
            ..
        })
    ));
}

#[test]
fn bad_inputs_are_typed_errors_and_leave_the_state_unchanged() {
    let norm = RowNorm::default();
    let mut kif = ParabolaKif::new(
        &Vector3::new(1e-3, 0.0, 100.0),
        &ThetaCov::Normalised(Matrix3::identity()),
        norm,
    )
    .unwrap();
    let before = kif.clone();
    let pts = [(100.0f32, 10.0f32), (101.0, 20.0), (102.0, 30.0)];
    for bad in [f64::NAN, 0.0, -1.0, f64::INFINITY] {
        let e = kif.update(&pts, bad).unwrap_err();
        assert!(
            matches!(e, KifError::InvalidVariance { name: "sigma2_px2", value } if value.to_bits() == bad.to_bits()),
            "{e:?}"
        );
    }
    let with_nan = [
        (100.0f32, 10.0f32),
        (101.0, 20.0),
        (f32::NAN, 30.0),
        (1.0, f32::INFINITY),
    ];
    assert!(matches!(
        kif.update(&with_nan, 1.0),
        Err(KifError::NonFinitePoint { index: 2, .. })
    ));
    let with_inf = [(100.0f64, 10.0f64), (1.0, f64::NEG_INFINITY)];
    assert!(matches!(
        kif.update(&with_inf, 1.0),
        Err(KifError::NonFinitePoint { index: 1, .. })
    ));
    assert_eq!(kif, before, "failed updates must not touch the state");

    // Q: indefinite (pivot 2), asymmetric, non-finite.
    let q_indef = Matrix3::new(1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, -1e-3);
    assert!(matches!(
        ProcessNoise::new(&q_indef),
        Err(KifError::NotPositiveDefinite {
            matrix: "Q",
            pivot: 2,
            ..
        })
    ));
    let q_rank1 = Matrix3::new(1.0, 1.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0, 1.0);
    assert!(matches!(
        kif.process_noise(&ThetaCov::Normalised(q_rank1)),
        Err(KifError::NotPositiveDefinite {
            matrix: "Q",
            pivot: 1,
            ..
        })
    ));
    let mut q_asym = Matrix3::identity();
    q_asym[(0, 2)] = 0.5;
    assert!(matches!(
        ProcessNoise::new(&q_asym),
        Err(KifError::NotSymmetric {
            matrix: "Q",
            row: 0,
            col: 2,
            ..
        })
    ));
    let mut q_nan = Matrix3::identity();
    q_nan[(1, 1)] = f64::NAN;
    assert!(matches!(
        ProcessNoise::new(&q_nan),
        Err(KifError::NonFiniteMatrix {
            matrix: "Q",
            row: 1,
            col: 1,
            ..
        })
    ));

    // P0 and θ0.
    assert!(matches!(
        ParabolaKif::new(
            &Vector3::zeros(),
            &ThetaCov::Normalised(-Matrix3::identity()),
            norm
        ),
        Err(KifError::NotPositiveDefinite {
            matrix: "P0",
            pivot: 0,
            ..
        })
    ));
    assert!(matches!(
        ParabolaKif::new(
            &Vector3::new(0.0, f64::NAN, 0.0),
            &ThetaCov::Normalised(Matrix3::identity()),
            norm
        ),
        Err(KifError::NonFiniteVector {
            vector: "theta0_px",
            index: 1,
            ..
        })
    ));
    assert!(matches!(
        kif.reset(&Vector3::zeros(), &ThetaCov::Normalised(Matrix3::zeros())),
        Err(KifError::NotPositiveDefinite {
            matrix: "P0",
            pivot: 0,
            ..
        })
    ));
    assert_eq!(kif, before, "failed reset must not touch the state");

    // Row normalisation.
    assert!(matches!(
        RowNorm::new(120.0, 0.0),
        Err(KifError::InvalidRowNorm {
            field: "scale_px",
            ..
        })
    ));
    assert!(matches!(
        RowNorm::new(f64::NAN, 1.0),
        Err(KifError::InvalidRowNorm {
            field: "center_row_px",
            ..
        })
    ));
    assert!(matches!(
        ParabolaKif::new(
            &Vector3::zeros(),
            &ThetaCov::Normalised(Matrix3::identity()),
            RowNorm {
                center_row_px: 0.0,
                scale_px: -2.0
            }
        ),
        Err(KifError::InvalidRowNorm {
            field: "scale_px",
            ..
        })
    ));

    // Generic update: R not PD, φ not finite.
    let mut f = InformationFilter::<3>::new(&Vector3::zeros(), &Matrix3::identity()).unwrap();
    let phi = SMatrix::<f64, 3, 2>::from_element(1.0);
    let r_bad = SMatrix::<f64, 2, 2>::new(1.0, 2.0, 2.0, 1.0);
    assert!(matches!(
        f.update(&phi, &r_bad, &SVector::<f64, 2>::zeros()),
        Err(KifError::NotPositiveDefinite {
            matrix: "R",
            pivot: 1,
            ..
        })
    ));
    let mut phi_nan = phi;
    phi_nan[(2, 1)] = f64::NAN;
    assert!(matches!(
        f.update(
            &phi_nan,
            &SMatrix::<f64, 2, 2>::identity(),
            &SVector::<f64, 2>::zeros()
        ),
        Err(KifError::NonFiniteMatrix {
            matrix: "phi",
            row: 2,
            col: 1,
            ..
        })
    ));
}

#[test]
fn reset_restarts_from_the_new_prior_and_keeps_the_form() {
    let norm = RowNorm::default();
    let mut kif = ParabolaKif::new(
        &Vector3::new(1e-3, 0.0, 100.0),
        &ThetaCov::Normalised(Matrix3::identity()),
        norm,
    )
    .unwrap();
    kif.set_time_update_form(TimeUpdateForm::Plain);
    kif.update(&[(150.0f32, 100.0f32), (160.0, 200.0)], 1.0)
        .unwrap();
    let theta = Vector3::new(-1e-3, 0.2, 250.0);
    let p0 = ThetaCov::Normalised(Matrix3::identity() * 4.0);
    kif.reset(&theta, &p0).unwrap();
    let fresh = {
        let mut k = ParabolaKif::new(&theta, &p0, norm).unwrap();
        k.set_time_update_form(TimeUpdateForm::Plain);
        k
    };
    assert_eq!(kif.filter().time_update_form(), TimeUpdateForm::Plain);
    assert!((kif.estimate() - theta).norm() < 1e-12 * theta.norm());
    assert!((kif.information_normalised() - fresh.information_normalised()).norm() < 1e-12);
}

#[test]
fn row_norm_config_rejects_unknown_fields_and_validates() {
    let ok: RowNorm =
        serde_json::from_str(r#"{"center_row_px": 239.5, "scale_px": 240.0}"#).unwrap();
    assert_eq!(ok, RowNorm::for_image_height(480).unwrap());
    assert!(
        serde_json::from_str::<RowNorm>(r#"{"center_row_px": 1.0, "scale_px": 2.0, "scale": 3.0}"#)
            .is_err()
    );
    let bad: RowNorm = serde_json::from_str(r#"{"center_row_px": 1.0, "scale_px": -2.0}"#).unwrap();
    assert!(matches!(
        bad.validate(),
        Err(KifError::InvalidRowNorm {
            field: "scale_px",
            ..
        })
    ));
    let form: TimeUpdateForm = serde_json::from_str(r#""plain""#).unwrap();
    assert_eq!(form, TimeUpdateForm::Plain);
}

#[test]
fn weighted_power_sum_update_equals_dense_phi_r_inv_phi_t_with_diagonal_r() {
    // R = s²·diag(1/w_i): the weighted sums give φR⁻¹φᵀ and φR⁻¹x of the dense form.
    let mut rng = ChaCha8Rng::seed_from_u64(43);
    let norm = RowNorm::new(120.0, 100.0).unwrap();
    for _ in 0..30 {
        let n = rng.random_range(3..=150);
        let s2 = 10f64.powf(rng.random_range(-3.0..1.0));
        let points = random_points(&mut rng, n, &Vector3::new(1e-3, -0.5, 200.0));
        let weights: Vec<f64> = (0..n)
            .map(|_| 10f64.powf(rng.random_range(-1.0..1.0)))
            .collect();
        let mut kif = ParabolaKif::new(
            &Vector3::new(0.0, 0.0, 100.0),
            &ThetaCov::Normalised(random_spd(&mut rng, 10.0)),
            norm,
        )
        .unwrap();
        let (y0, v0) = (
            kif.information_normalised(),
            kif.information_vector_normalised(),
        );
        let sums = PowerSums::from_weighted_points(&points, &weights, &norm).unwrap();
        kif.update_sums(&sums, s2).unwrap();
        let mut phi = DMatrix::zeros(3, n);
        let mut x = DVector::zeros(n);
        let mut r_inv = DMatrix::zeros(n, n);
        for (i, &(col, row)) in points.iter().enumerate() {
            let u = norm.normalise_row(row);
            phi.set_column(i, &DVector::from_vec(vec![u * u, u, 1.0]));
            x[i] = col;
            r_inv[(i, i)] = weights[i] / s2;
        }
        let d_y = &phi * &r_inv * phi.transpose();
        let d_yv = &phi * &r_inv * &x;
        let got = to_d(&(kif.information_normalised() - y0));
        assert!(rel(&got, &d_y) < 1e-12, "ΔY {:e}", rel(&got, &d_y));
        let got_v = to_dv(&(kif.information_vector_normalised() - v0));
        assert!(rel(&got_v, &dv(&d_yv)) < 1e-12);
    }
    // Unit weights are the unweighted sums; a bad weight is a typed error.
    let pts = [(10.0f64, 50.0f64), (12.0, 80.0), (15.0, 110.0)];
    let a = PowerSums::from_weighted_points(&pts, &[1.0; 3], &norm).unwrap();
    let b = PowerSums::from_points(&pts, &norm).unwrap();
    assert!((a.normal_matrix() - b.normal_matrix()).norm() < 1e-12);
    for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        assert!(matches!(
            PowerSums::from_weighted_points(&pts, &[1.0, bad, 1.0], &norm),
            Err(KifError::InvalidVariance { name: "weight", .. })
        ));
    }
}
