//! One 15×15 covariance step P ← Φ P Φᵀ + Q_d (block form vs dense), and the per-step cost of
//! building A and Φ (series) and of the exact Van Loan discretisation.
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use criterion::{Criterion, criterion_group, criterion_main};
use ins_errors::config::TrajectoryConfig;
use ins_errors::error_model::{
    Mat15, Transition, continuous_noise_psd, discretize_fast, noise_input_matrix,
    propagate_covariance, system_matrix, van_loan,
};
use ins_errors::strapdown::LinearizationPoint;
use ins_errors::trajectory::Trajectory;
use std::hint::black_box;

fn setup() -> (LinearizationPoint, Mat15, Mat15) {
    let tr = Trajectory::new(&TrajectoryConfig::paper()).unwrap();
    let s = tr.samples().nth(13_000).unwrap();
    let c = s.att_b_to_n.to_rotation_matrix().into_inner();
    let lp = LinearizationPoint {
        pos: s.pos,
        vel_ned_mps: s.vel_ned_mps,
        specific_force_ned_mps2: c * s.specific_force_body_mps2,
        c_b_to_n: c,
    };
    let a = system_matrix(&lp);
    let g = noise_input_matrix(&c);
    let (_, qd) = van_loan(
        &a,
        &g,
        &continuous_noise_psd(9.6e-7, 2.35e-13, 0.0, 0.0),
        0.01,
    )
    .unwrap();
    let mut p = Mat15::identity();
    for i in 0..15 {
        for j in 0..15 {
            p[(i, j)] += 0.01 / (1.0 + (i as f64 - j as f64).abs());
        }
    }
    (lp, qd, p)
}

fn bench(c: &mut Criterion) {
    let (lp, qd, p0) = setup();
    let a = system_matrix(&lp);
    let phi = Transition::series(&a, 0.01);
    let phi_dense = phi.to_dense();
    let mut g = c.benchmark_group("covariance_step_15");
    g.bench_function("block", |b| {
        let mut p = p0;
        b.iter(|| {
            propagate_covariance(black_box(&mut p), black_box(&phi), black_box(&qd));
        })
    });
    g.bench_function("dense_reference", |b| {
        let mut p = p0;
        b.iter(|| {
            p = black_box(&phi_dense) * p * phi_dense.transpose() + black_box(&qd);
        })
    });
    g.bench_function("system_matrix+series_phi", |b| {
        b.iter(|| Transition::series(&system_matrix(black_box(&lp)), 0.01))
    });
    let gq = {
        let gm = noise_input_matrix(&lp.c_b_to_n);
        gm * continuous_noise_psd(9.6e-7, 2.35e-13, 0.0, 0.0) * gm.transpose()
    };
    g.bench_function("discretize_fast", |b| {
        b.iter(|| discretize_fast(black_box(&a), &gq, 0.01))
    });
    let gm = noise_input_matrix(&lp.c_b_to_n);
    let qc = continuous_noise_psd(9.6e-7, 2.35e-13, 0.0, 0.0);
    g.bench_function("van_loan_30x30", |b| {
        b.iter(|| van_loan(black_box(&a), &gm, &qc, 0.01).unwrap())
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
