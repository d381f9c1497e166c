//! Least-squares parabola fit alone (normal equations in normalised rows), several sizes.
//! Run: `cargo bench -p hough-init --bench fit -- --warm-up-time 1 --measurement-time 3`
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use hough_init::{Parabola, Point, fit_parabola};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn bench_fit(c: &mut Criterion) {
    let truth = Parabola {
        a1: 1e-3,
        a2: -0.5,
        a3: 200.0,
    };
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let mut group = c.benchmark_group("fit_parabola");
    for n in [150usize, 1500, 6000] {
        let pts: Vec<Point> = (0..n)
            .map(|_| {
                let y = f64::from(rng.random_range(96u32..480));
                Point::new(truth.col_at_row(y) + rng.random_range(-1.0..1.0), y)
            })
            .collect();
        group.bench_with_input(BenchmarkId::from_parameter(n), &pts, |b, pts| {
            b.iter(|| black_box(fit_parabola(black_box(pts)).unwrap()));
        });
    }
    group.finish();
}

criterion_group!(benches, bench_fit);
criterion_main!(benches);
