//! Least-squares parabola: exactness, agreement with an independent solver, unbiasedness,
//! degenerate inputs.
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use hough_init::{
    HoughError, MIN_RELATIVE_PIVOT, Parabola, ParabolaFit, Point, PointSet, fit_parabola,
    fit_parabola_where,
};
use nalgebra::{DMatrix, DVector, Matrix3, Vector3};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngSeed};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

fn proptest_config() -> Config {
    Config {
        cases: 64,
        rng_seed: RngSeed::Fixed(0x7061_7261),
        failure_persistence: None,
        ..Config::default()
    }
}

fn signed(mag: f64, neg: bool) -> f64 {
    if neg { -mag } else { mag }
}

fn rel_err(got: f64, want: f64) -> f64 {
    (got - want).abs() / want.abs()
}

proptest! {
    #![proptest_config(proptest_config())]

    /// Noiseless points on a parabola are recovered to 1e-9 relative in each pixel
    /// coefficient, with rows anywhere in [0, 480] and repeated rows allowed.
    #[test]
    fn noiseless_points_are_fitted_exactly(
        a1 in 1e-4f64..3e-3, a1_neg in any::<bool>(),
        a2 in 0.05f64..2.0, a2_neg in any::<bool>(),
        a3 in 20.0f64..620.0,
        row_start in 0u32..=300,
        span in 60u32..=180,
        n in 3usize..300,
        seed in any::<u64>(),
    ) {
        let truth = Parabola { a1: signed(a1, a1_neg), a2: signed(a2, a2_neg), a3 };
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let row_end = (row_start + span).min(480);
        // Make sure at least three distinct rows exist, including both span ends.
        let mut rows = vec![row_start, row_end, (row_start + row_end) / 2];
        rows.extend((3..n).map(|_| rng.random_range(row_start..=row_end)));
        let pts: Vec<(f64, f64)> = rows
            .iter()
            .map(|&r| (truth.col_at_row(f64::from(r)), f64::from(r)))
            .collect();
        let fit = fit_parabola(&pts).unwrap();
        prop_assert!(rel_err(fit.parabola.a1, truth.a1) <= 1e-9, "a1 {} vs {}", fit.parabola.a1, truth.a1);
        prop_assert!(rel_err(fit.parabola.a2, truth.a2) <= 1e-9, "a2 {} vs {}", fit.parabola.a2, truth.a2);
        prop_assert!(rel_err(fit.parabola.a3, truth.a3) <= 1e-9, "a3 {} vs {}", fit.parabola.a3, truth.a3);
        prop_assert!(fit.rms_residual_px < 1e-9);
        prop_assert_eq!(fit.points_used, pts.len());
        prop_assert_eq!(fit.rows_px, (f64::from(row_start), f64::from(row_end)));
    }
}

/// Reference: least squares on the raw pixel design matrix [y², y, 1], by nalgebra's SVD
/// (an independent algorithm on the unnormalised problem).
fn reference_fit(pts: &[(f64, f64)]) -> Parabola {
    let n = pts.len();
    let a = DMatrix::from_fn(n, 3, |i, j| pts[i].1.powi(2 - j as i32));
    let b = DVector::from_iterator(n, pts.iter().map(|p| p.0));
    let sol = a.svd(true, true).solve(&b, 1e-14).unwrap();
    Parabola {
        a1: sol[0],
        a2: sol[1],
        a3: sol[2],
    }
}

fn noisy_points(
    truth: &Parabola,
    rows: (u32, u32),
    n: usize,
    sigma: f64,
    rng: &mut ChaCha8Rng,
) -> Vec<(f64, f64)> {
    let noise = Normal::new(0.0, sigma).unwrap();
    (0..n)
        .map(|_| {
            let y = f64::from(rng.random_range(rows.0..=rows.1));
            (truth.col_at_row(y) + noise.sample(rng), y)
        })
        .collect()
}

/// On noisy data the fit agrees with the SVD reference (predicted columns within 1e-6 px on
/// the fitted rows), and its residual is orthogonal to the regressors (normal equations) and
/// its RMS matches the residual recomputed from the pixel coefficients.
#[test]
fn noisy_fit_matches_independent_svd_least_squares() {
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let truth = Parabola {
        a1: -1.2e-3,
        a2: 0.9,
        a3: 40.0,
    };
    for (rows, n) in [
        ((0, 480), 400),
        ((200, 479), 60),
        ((100, 130), 25),
        ((0, 239), 1500),
    ] {
        let pts = noisy_points(&truth, rows, n, 2.0, &mut rng);
        let fit = fit_parabola(&pts).unwrap();
        let reference = reference_fit(&pts);
        for r in rows.0..=rows.1 {
            let y = f64::from(r);
            let d = fit.parabola.col_at_row(y) - reference.col_at_row(y);
            assert!(
                d.abs() < 1e-6,
                "rows {rows:?}: column differs by {d} px at row {y}"
            );
        }
        // Normal equations: Σ r·(y')^k = 0 in the normalised basis, relative to Σ |r|·|y'|^k.
        let (y0, s) = (
            0.5 * f64::from(rows.0 + rows.1),
            0.5 * f64::from(rows.1 - rows.0),
        );
        let (lo, hi) = fit.rows_px;
        assert!(lo >= f64::from(rows.0) && hi <= f64::from(rows.1));
        for k in 0..3 {
            let (mut dot, mut scale) = (0.0, 0.0);
            for &(x, y) in &pts {
                let r = x - fit.parabola.col_at_row(y);
                let u = ((y - y0) / s).powi(k);
                dot += r * u;
                scale += (r * u).abs();
            }
            assert!(
                dot.abs() <= 1e-8 * scale,
                "rows {rows:?}: residual not orthogonal to y'^{k}"
            );
        }
        let rms = (pts
            .iter()
            .map(|&(x, y)| (x - fit.parabola.col_at_row(y)).powi(2))
            .sum::<f64>()
            / pts.len() as f64)
            .sqrt();
        assert!((rms - fit.rms_residual_px).abs() < 1e-9 * rms.max(1.0));
    }
}

/// Under seeded N(0, 0.5²) column noise the estimator is unbiased (mean over 400 trials within
/// 4 standard errors of the truth, per coefficient) and its spread matches least-squares
/// theory: the sample std of x̂ at the middle and bottom rows is within 15 % of
/// σ·sqrt(φᵀ(ΦᵀΦ)⁻¹φ) (≈ 4 standard errors of a sample std over 400 trials).
#[test]
fn noisy_fit_is_unbiased_with_the_theoretical_spread() {
    let truth = Parabola {
        a1: 1.5e-3,
        a2: -0.6,
        a3: 250.0,
    };
    let sigma = 0.5;
    let rows: Vec<f64> = (0..120).map(|i| 120.0 + f64::from(i)).collect(); // fixed design
    let trials = 400usize;
    let noise = Normal::new(0.0, sigma).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(99);
    let mut coeffs = Vec::with_capacity(trials);
    for _ in 0..trials {
        let pts: Vec<Point> = rows
            .iter()
            .map(|&y| Point::new(truth.col_at_row(y) + noise.sample(&mut rng), y))
            .collect();
        let fit = fit_parabola(&pts).unwrap();
        assert!(fit.rms_residual_px < 2.0 * sigma);
        coeffs.push(fit.parabola);
    }
    let mean_std = |f: &dyn Fn(&Parabola) -> f64| {
        let m = coeffs.iter().map(f).sum::<f64>() / trials as f64;
        let v = coeffs.iter().map(|c| (f(c) - m).powi(2)).sum::<f64>() / (trials - 1) as f64;
        (m, v.sqrt())
    };
    for (name, get, want) in [
        (
            "a1",
            (|c: &Parabola| c.a1) as fn(&Parabola) -> f64,
            truth.a1,
        ),
        ("a2", |c: &Parabola| c.a2, truth.a2),
        ("a3", |c: &Parabola| c.a3, truth.a3),
    ] {
        let (m, sd) = mean_std(&get);
        let se = sd / (trials as f64).sqrt();
        assert!(
            (m - want).abs() <= 4.0 * se,
            "{name}: mean {m} vs truth {want} (se {se})"
        );
    }
    // Theory in the normalised basis (exact for the fixed design).
    let (y0, s) = (179.5, 59.5);
    let mut gram = Matrix3::zeros();
    for &y in &rows {
        let u = (y - y0) / s;
        let phi = Vector3::new(1.0, u, u * u);
        gram += phi * phi.transpose();
    }
    let cov = gram.try_inverse().unwrap() * sigma * sigma;
    for y in [179.5, 239.0] {
        let u = (y - y0) / s;
        let phi = Vector3::new(1.0, u, u * u);
        let predicted = (phi.transpose() * cov * phi)[(0, 0)].sqrt();
        let (m, sd) = mean_std(&|c: &Parabola| c.col_at_row(y));
        assert!((m - truth.col_at_row(y)).abs() <= 4.0 * sd / (trials as f64).sqrt());
        assert!(
            (sd / predicted - 1.0).abs() < 0.15,
            "row {y}: std {sd} vs theory {predicted}"
        );
    }
}

#[test]
fn too_few_points_are_rejected_with_the_count() {
    let pts = [(10.0, 1.0), (11.0, 2.0)];
    for n in 0..=2 {
        assert_eq!(
            fit_parabola(&pts[..n.min(2)]),
            Err(HoughError::TooFewPoints {
                set: PointSet::Fit,
                found: n.min(2),
                required: 3
            })
        );
    }
}

#[test]
fn a_single_row_is_rejected() {
    let pts: Vec<(f32, f32)> = (0..10).map(|i| (i as f32 * 3.0, 77.0)).collect();
    assert_eq!(
        fit_parabola(&pts),
        Err(HoughError::SingleRow {
            row_px: 77.0,
            count: 10
        })
    );
}

/// Two distinct rows determine a line, not a parabola: the quadratic pivot fails.
#[test]
fn two_distinct_rows_fail_the_quadratic_pivot() {
    let pts: Vec<(f64, f64)> = (0..20)
        .map(|i| (f64::from(i), if i % 2 == 0 { 10.0 } else { 200.0 }))
        .collect();
    match fit_parabola(&pts) {
        Err(HoughError::RankDeficient {
            pivot,
            value,
            threshold,
            ..
        }) => {
            assert_eq!(pivot, 2);
            assert!(value <= threshold && threshold > 0.0);
            // The quadratic column's diagonal is mean(y'^4) = 1 for rows at y' = ±1.
            assert!((threshold - MIN_RELATIVE_PIVOT).abs() < 1e-20);
        }
        other => panic!("expected RankDeficient at pivot 2, got {other:?}"),
    }
}

#[test]
fn non_finite_coordinates_are_rejected_with_their_index() {
    let mut pts: Vec<(f64, f64)> = (0..10).map(|i| (f64::from(i), f64::from(i * i))).collect();
    pts[4].0 = f64::NAN;
    assert!(matches!(
        fit_parabola(&pts),
        Err(HoughError::NonFinitePoint { index: 4, .. })
    ));
    pts[4].0 = 4.0;
    pts[7].1 = f64::INFINITY;
    assert!(matches!(
        fit_parabola(&pts),
        Err(HoughError::NonFinitePoint { index: 7, .. })
    ));
    // Also when the predicate would have dropped the point.
    assert!(matches!(
        fit_parabola_where(&pts, |_, y| y < 10.0),
        Err(HoughError::NonFinitePoint { index: 7, .. })
    ));
}

/// Coordinates so large that the sums overflow give an error, never NaN coefficients.
#[test]
fn overflowing_coordinates_give_an_error_not_nan() {
    // Σx overflows to +∞.
    let pts: Vec<(f64, f64)> = (0..10)
        .map(|i| (1.7e308 * f64::from(i % 2), f64::from(i)))
        .collect();
    let r = fit_parabola(&pts);
    assert!(r.is_err(), "got {r:?}");
}

/// `fit_parabola_where` equals `fit_parabola` on the pre-filtered copy, bit for bit.
#[test]
fn filtered_fit_equals_fit_of_filtered_copy() {
    let mut rng = ChaCha8Rng::seed_from_u64(8);
    let truth = Parabola {
        a1: 2e-3,
        a2: -0.3,
        a3: 100.0,
    };
    let pts = noisy_points(&truth, (50, 239), 300, 5.0, &mut rng);
    let keep = |x: f64, y: f64| (x - truth.col_at_row(y)).abs() < 4.0;
    let copy: Vec<(f64, f64)> = pts.iter().copied().filter(|&(x, y)| keep(x, y)).collect();
    assert!(copy.len() < pts.len());
    let a: ParabolaFit = fit_parabola_where(&pts, keep).unwrap();
    let b = fit_parabola(&copy).unwrap();
    assert_eq!(a, b);
}

/// Every supported point representation gives the identical fit.
#[test]
fn point_representations_are_interchangeable() {
    let rows = [3u16, 40, 41, 100, 180, 239];
    let cols = [10u16, 30, 31, 70, 150, 300];
    let as_u16: Vec<(u16, u16)> = cols.iter().zip(rows).map(|(&c, r)| (c, r)).collect();
    let as_f32: Vec<[f32; 2]> = as_u16
        .iter()
        .map(|&(c, r)| [f32::from(c), f32::from(r)])
        .collect();
    let as_point: Vec<Point> = as_u16
        .iter()
        .map(|&(c, r)| Point::new(c.into(), r.into()))
        .collect();
    let f = fit_parabola(&as_point).unwrap();
    assert_eq!(fit_parabola(&as_u16).unwrap(), f);
    assert_eq!(fit_parabola(&as_f32).unwrap(), f);
}
