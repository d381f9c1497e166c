//! Monte Carlo consistency of a toy filter whose model matches the simulation: NIS and NEES
//! averages fall in the 95 % χ² bands; mis-tuned filters (R ×4, R /4, Q /10) fall out of them.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used)]

mod common;

use akf::{KalmanFilter, average_band, nees};
use common::*;
use nalgebra::{SMatrix, SVector};

const RUNS: usize = 50;
const EPOCHS: usize = 200;

type M4 = SMatrix<f64, 4, 4>;

/// 2-D constant velocity, dt = 1 s, position measured (M = 2).
fn model() -> (M4, M4, SMatrix<f64, 2, 4>, SMatrix<f64, 2, 2>) {
    let (phi1, q1) = cv_model(1.0, 0.2);
    let mut phi = M4::zeros();
    let mut q = M4::zeros();
    for a in 0..2 {
        for (i, j) in [(0, 0), (0, 1), (1, 0), (1, 1)] {
            phi[(a + 2 * i, a + 2 * j)] = phi1[(i, j)];
            q[(a + 2 * i, a + 2 * j)] = q1[(i, j)] * (1.0 + a as f64);
        }
    }
    let h = SMatrix::<f64, 2, 4>::new(1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0);
    let r = SMatrix::<f64, 2, 2>::new(2.0, 0.4, 0.4, 1.0);
    (phi, q, h, r)
}

/// Per-epoch averages over the runs of NIS and NEES, for a filter using `q_scale·Q`, `r_scale·R`.
fn monte_carlo(seed: u64, q_scale: f64, r_scale: f64) -> (Vec<f64>, Vec<f64>) {
    let (phi, q, h, r) = model();
    let p0 = M4::from_diagonal(&SVector::<f64, 4>::new(25.0, 25.0, 4.0, 4.0));
    let mut nis_avg = vec![0.0; EPOCHS];
    let mut nees_avg = vec![0.0; EPOCHS];
    let mut rng = rng(seed);
    for _ in 0..RUNS {
        let mut x = sample_gaussian(&mut rng, &p0);
        let mut kf = KalmanFilter::new(SVector::zeros(), p0).unwrap();
        for k in 0..EPOCHS {
            x = phi * x + sample_gaussian(&mut rng, &q);
            let z = h * x + sample_gaussian(&mut rng, &r);
            kf.predict(&phi, &(q * q_scale)).unwrap();
            let inn = kf.update(&z, &h, &(r * r_scale)).unwrap();
            nis_avg[k] += inn.nis / RUNS as f64;
            nees_avg[k] += nees(&(x - kf.state()), kf.covariance()).unwrap() / RUNS as f64;
        }
    }
    (nis_avg, nees_avg)
}

fn fraction_inside(v: &[f64], band: (f64, f64)) -> f64 {
    v.iter().filter(|&&a| a >= band.0 && a <= band.1).count() as f64 / v.len() as f64
}

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len() as f64
}

#[test]
fn consistent_filter_nis_and_nees_sit_in_the_95_percent_bands() {
    let (nis, nees_v) = monte_carlo(601, 1.0, 1.0);
    let nis_band = average_band(2, RUNS, 0.95).unwrap();
    let nees_band = average_band(4, RUNS, 0.95).unwrap();
    // Expected 95 % of epochs inside; 200 epochs → binomial σ ≈ 1.5 %.
    let f_nis = fraction_inside(&nis, nis_band);
    assert!(f_nis >= 0.90, "NIS: {f_nis} of epochs inside {nis_band:?}");
    // NEES is correlated across epochs (fewer effective samples): looser bound.
    let f_nees = fraction_inside(&nees_v, nees_band);
    assert!(
        f_nees >= 0.85,
        "NEES: {f_nees} of epochs inside {nees_band:?}"
    );
    // Innovations of the optimal filter are white, so the pooled NIS over all runs × epochs is
    // χ²(2·RUNS·EPOCHS)/(RUNS·EPOCHS).
    let pooled_band = average_band(2, RUNS * EPOCHS, 0.95).unwrap();
    let pooled = mean(&nis);
    assert!(
        pooled >= pooled_band.0 && pooled <= pooled_band.1,
        "pooled NIS {pooled} outside {pooled_band:?}"
    );
}

#[test]
fn mistuned_filters_fall_out_of_the_bands() {
    let pooled_band = average_band(2, RUNS * EPOCHS, 0.95).unwrap();
    // Measurement noise overstated ×4: under-confident, NIS too small.
    let (nis_hi_r, _) = monte_carlo(602, 1.0, 4.0);
    assert!(mean(&nis_hi_r) < pooled_band.0, "R×4: {}", mean(&nis_hi_r));
    // Understated /4: over-confident, NIS too large.
    let (nis_lo_r, _) = monte_carlo(603, 1.0, 0.25);
    assert!(mean(&nis_lo_r) > pooled_band.1, "R/4: {}", mean(&nis_lo_r));
    // Process noise understated /10: NEES far above its band most of the time.
    let (_, nees_lo_q) = monte_carlo(604, 0.1, 1.0);
    let nees_band = average_band(4, RUNS, 0.95).unwrap();
    let above = nees_lo_q.iter().filter(|&&a| a > nees_band.1).count() as f64 / EPOCHS as f64;
    assert!(
        above > 0.8,
        "Q/10: only {above} of epochs above the NEES band"
    );
}
