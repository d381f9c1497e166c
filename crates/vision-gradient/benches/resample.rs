//! Criterion bench of the resampling kernels: a 1280×720 frame to the 320-px working width by
//! the whole factor 4 (`downscale_box`), and a 512×288 frame by 1.6 (`resample_rows`), all rows.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used)]

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::hint::black_box;
use vision_gradient::{AxisSpan, AxisTaps, GreyImage, downscale_box, resample_rows};

/// A seeded textured frame.
fn frame(w: usize, h: usize) -> Vec<u8> {
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    (0..w * h).map(|_| rng.random_range(60..200u8)).collect()
}

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("resample");
    let (w, h) = (1280usize, 720usize);
    let data = frame(w, h);
    let src = GreyImage::new(&data, w, h, w).unwrap();
    let (ww, wh) = (320usize, 180usize);
    let mut dst = vec![0u8; ww * wh];
    let mut sums = vec![0u32; w];
    group.bench_function(BenchmarkId::new("downscale_box", "1280x720/4"), |b| {
        b.iter(|| downscale_box(4, black_box(&src), &mut dst, ww, (0, wh), &mut sums).unwrap());
    });
    let (w, h) = (512usize, 288usize);
    let data = frame(w, h);
    let src = GreyImage::new(&data, w, h, w).unwrap();
    let s = w as f64 / ww as f64;
    let span = AxisSpan {
        scale: s,
        start_px: 0.0,
    };
    let (cols, rows) = (AxisTaps::new(w, ww, span, s), AxisTaps::new(h, wh, span, s));
    let mut acc = vec![0.0f32; w];
    group.bench_function(BenchmarkId::new("resample_rows", "512x288/1.6"), |b| {
        b.iter(|| {
            resample_rows(black_box(&src), &mut dst, &cols, &rows, (0, wh), &mut acc).unwrap();
        });
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
