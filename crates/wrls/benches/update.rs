//! WRLS per-frame cost for 50, 150 (the paper's maximum per lane) and 300 points:
//! the paper's form with the N×N Cholesky (`paper_nxn`, what the paper's 22.2 ms measures) and
//! the information form with power sums (`fast_info`).
#![allow(clippy::unwrap_used, clippy::expect_used)]
#![allow(missing_docs)]

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use nalgebra::{Matrix3, Vector3};
use wrls::{PAPER_LAMBDA, RowNorm, ThetaCov, WrlsFast, WrlsPaper};

fn points(n: usize) -> Vec<(f32, f32)> {
    (0..n)
        .map(|i| {
            let y = 100.0 + 140.0 * (i as f64) / (n as f64);
            let noise = ((i * 7919) % 13) as f64 / 13.0 - 0.5;
            ((1e-3 * y * y - 0.5 * y + 200.0 + noise) as f32, y as f32)
        })
        .collect()
}

fn bench_wrls(c: &mut Criterion) {
    let mut group = c.benchmark_group("wrls_update");
    let theta0 = Vector3::new(0.0, 0.0, 160.0);
    let p0 = ThetaCov::Normalised(Matrix3::identity() * 100.0);
    for n in [50usize, 150, 300] {
        let pts = points(n);
        let mut fast = WrlsFast::new(&theta0, &p0, PAPER_LAMBDA, RowNorm::default()).unwrap();
        group.bench_with_input(BenchmarkId::new("fast_info", n), &pts, |b, pts| {
            b.iter(|| {
                fast.update(black_box(pts.as_slice())).unwrap();
                black_box(fast.estimate())
            });
        });
        let mut paper =
            WrlsPaper::new(&theta0, &p0, PAPER_LAMBDA, RowNorm::default(), 300).unwrap();
        group.bench_with_input(BenchmarkId::new("paper_nxn", n), &pts, |b, pts| {
            b.iter(|| {
                paper.update(black_box(pts.as_slice())).unwrap();
                black_box(paper.estimate())
            });
        });
    }
    group.finish();
}

criterion_group!(benches, bench_wrls);
criterion_main!(benches);
