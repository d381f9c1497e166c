//! KIF per-frame cost: one time update (eq. 24) plus one power-sum measurement update, for
//! 50, 150 (the paper's maximum per lane) and 300 points.
#![allow(clippy::unwrap_used, clippy::expect_used)]
#![allow(missing_docs)]

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use info_filter::{ParabolaKif, RowNorm, ThetaCov, TimeUpdateForm};
use nalgebra::{Matrix3, Vector3};

fn points(n: usize) -> Vec<(f32, f32)> {
    (0..n)
        .map(|i| {
            let y = 100.0 + 140.0 * (i as f64) / (n as f64);
            let noise = ((i * 7919) % 13) as f64 / 13.0 - 0.5;
            ((1e-3 * y * y - 0.5 * y + 200.0 + noise) as f32, y as f32)
        })
        .collect()
}

fn bench_kif(c: &mut Criterion) {
    let mut group = c.benchmark_group("kif_predict_update");
    for form in [TimeUpdateForm::PositiveDefinite, TimeUpdateForm::Plain] {
        for n in [50usize, 150, 300] {
            let pts = points(n);
            let mut kif = ParabolaKif::new(
                &Vector3::new(0.0, 0.0, 160.0),
                &ThetaCov::Normalised(Matrix3::identity() * 100.0),
                RowNorm::default(),
            )
            .unwrap();
            kif.set_time_update_form(form);
            let q = kif
                .process_noise(&ThetaCov::Normalised(Matrix3::identity() * 0.25))
                .unwrap();
            let name = match form {
                TimeUpdateForm::PositiveDefinite => "eq24",
                TimeUpdateForm::Plain => "eq7",
            };
            group.bench_with_input(BenchmarkId::new(name, n), &pts, |b, pts| {
                b.iter(|| {
                    kif.predict(&q).unwrap();
                    kif.update(black_box(pts.as_slice()), black_box(1.0))
                        .unwrap();
                    black_box(kif.estimate())
                });
            });
        }
    }
    group.finish();
}

criterion_group!(benches, bench_kif);
criterion_main!(benches);
