//! Predict / update / adaptive-estimate timings for the INS size (N = 15, M = 6) and a smaller
//! size (N = 9, M = 3).
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used)]

use akf::{AdaptiveQ, AdaptiveQConfig, KalmanFilter};
use criterion::{Criterion, black_box, criterion_group, criterion_main};
use nalgebra::{SMatrix, SVector};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn random_matrix<const R: usize, const C: usize>(rng: &mut ChaCha8Rng) -> SMatrix<f64, R, C> {
    SMatrix::from_fn(|_, _| rng.random_range(-1.0..1.0))
}

struct Setup<const N: usize, const M: usize> {
    kf: KalmanFilter<N>,
    phi: SMatrix<f64, N, N>,
    q: SMatrix<f64, N, N>,
    h: SMatrix<f64, M, N>,
    r: SMatrix<f64, M, M>,
    z: SVector<f64, M>,
}

fn setup<const N: usize, const M: usize>(seed: u64) -> Setup<N, M> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let a: SMatrix<f64, N, N> = random_matrix(&mut rng);
    let p0 = a * a.transpose() + SMatrix::identity();
    let phi = SMatrix::<f64, N, N>::identity() + random_matrix::<N, N>(&mut rng) * 0.01;
    let b: SMatrix<f64, N, N> = random_matrix(&mut rng);
    let q = b * b.transpose() * 1e-4;
    let h: SMatrix<f64, M, N> = random_matrix(&mut rng);
    let r = SMatrix::<f64, M, M>::identity() * 0.5;
    let z: SVector<f64, M> = random_matrix(&mut rng);
    Setup {
        kf: KalmanFilter::new(SVector::zeros(), p0).unwrap(),
        phi,
        q,
        h,
        r,
        z,
    }
}

fn bench_size<const N: usize, const M: usize>(c: &mut Criterion) {
    let Setup {
        kf,
        phi,
        q,
        h,
        r,
        z,
    } = setup::<N, M>(7);
    let mut group = c.benchmark_group(format!("kf_n{N}_m{M}"));
    group.bench_function("predict", |bencher| {
        bencher.iter_batched_ref(
            || kf.clone(),
            |f| f.predict(black_box(&phi), black_box(&q)).unwrap(),
            criterion::BatchSize::SmallInput,
        )
    });
    group.bench_function("update_joseph", |bencher| {
        bencher.iter_batched_ref(
            || kf.clone(),
            |f| {
                f.update(black_box(&z), black_box(&h), black_box(&r))
                    .unwrap()
            },
            criterion::BatchSize::SmallInput,
        )
    });
    group.bench_function("adaptive_q_push_w10_eigenclip", |bencher| {
        let mut est = AdaptiveQ::<N>::new(AdaptiveQConfig::default()).unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let dx: SVector<f64, N> = random_matrix(&mut rng);
        let p_post = *kf.covariance();
        for _ in 0..10 {
            est.push(&dx, &p_post, &p_post, &phi).unwrap();
        }
        bencher.iter(|| {
            est.push(black_box(&dx), &p_post, &p_post, black_box(&phi))
                .unwrap()
                .is_some()
        })
    });
    group.finish();
}

fn benches(c: &mut Criterion) {
    bench_size::<15, 6>(c);
    bench_size::<9, 3>(c);
}

criterion_group!(kf_benches, benches);
criterion_main!(kf_benches);
