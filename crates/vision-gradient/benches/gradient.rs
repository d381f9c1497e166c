//! Criterion benches of the directional gradient: full frame (fixed and adaptive threshold,
//! AVX2 and portable backends) at 320×240 and 640×480, and the tracking mode (two windows);
//! of the periodic-stripe filter on a frame's edges; and of the exposure's kernels (the median
//! grey of the rows searched, a frame brightened).
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used)]

use criterion::{BatchSize, BenchmarkId, Criterion, criterion_group, criterion_main};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::hint::black_box;
use vision_gradient::{
    Backend, ColSpan, EdgeBuffer, GradientDetector, GradientParams, GreyImage,
    PeriodicStripeParams, Region, Threshold, brighten, drop_periodic_stripes, median_grey,
};

/// Road-like test frame: textured grey with two bright diagonal marks.
fn frame(w: usize, h: usize) -> Vec<u8> {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let mut data = vec![0u8; w * h];
    for y in 0..h {
        for x in 0..w {
            let mut v = 90 + rng.random_range(0..24);
            let xl = w as f64 * 0.45 - (y as f64 - h as f64 * 0.5) * 0.9;
            let xr = w as f64 * 0.55 + (y as f64 - h as f64 * 0.5) * 0.9;
            if y > h / 2 && ((x as f64 - xl).abs() < 2.5 || (x as f64 - xr).abs() < 2.5) {
                v = 220;
            }
            data[y * w + x] = v as u8;
        }
    }
    data
}

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("gradient");
    for &(w, h) in &[(320usize, 240usize), (640, 480)] {
        let data = frame(w, h);
        let img = GreyImage::new(&data, w, h, w).unwrap();
        let mut edges = EdgeBuffer::with_capacity(w * h);
        let mut class_img = vec![0u8; w * h];
        let mut backends = vec![("portable", Backend::Portable)];
        if GradientDetector::with_backend(GradientParams::default(), Backend::Avx2).is_ok() {
            backends.push(("avx2", Backend::Avx2));
        }
        for (name, backend) in backends {
            let fixed = GradientDetector::with_backend(GradientParams::default(), backend).unwrap();
            group.bench_function(
                BenchmarkId::new(format!("full_fixed_{name}"), format!("{w}x{h}")),
                |b| {
                    b.iter(|| {
                        fixed
                            .detect(black_box(&img), Region::Full, &mut edges, None)
                            .unwrap()
                    })
                },
            );
            group.bench_function(
                BenchmarkId::new(format!("full_fixed_classimg_{name}"), format!("{w}x{h}")),
                |b| {
                    b.iter(|| {
                        fixed
                            .detect(
                                black_box(&img),
                                Region::Full,
                                &mut edges,
                                Some(&mut class_img),
                            )
                            .unwrap()
                    })
                },
            );
            let params = GradientParams {
                threshold: Threshold::Adaptive {
                    keep_fraction: 0.05,
                    min_magnitude: 40,
                },
                ..GradientParams::default()
            };
            let adaptive = GradientDetector::with_backend(params, backend).unwrap();
            group.bench_function(
                BenchmarkId::new(format!("full_adaptive_{name}"), format!("{w}x{h}")),
                |b| {
                    b.iter(|| {
                        adaptive
                            .detect(black_box(&img), Region::Full, &mut edges, None)
                            .unwrap()
                    })
                },
            );
            // Tracking: one 40-px window per row in the lower half, per lane (two calls).
            let mut rng = ChaCha8Rng::seed_from_u64(1);
            let spans: Vec<Vec<ColSpan>> = (0..2)
                .map(|lane| {
                    (0..h)
                        .map(|y| {
                            if y < h / 2 {
                                return ColSpan::EMPTY;
                            }
                            let x0 = if lane == 0 {
                                w as i64 / 4
                            } else {
                                w as i64 * 3 / 4
                            };
                            let x = x0 + rng.random_range(-3..=3);
                            ColSpan::clamped(x - 20, x + 20, w)
                        })
                        .collect()
                })
                .collect();
            group.bench_function(
                BenchmarkId::new(format!("spans_two_lanes_40px_{name}"), format!("{w}x{h}")),
                |b| {
                    b.iter(|| {
                        for s in &spans {
                            fixed
                                .detect(black_box(&img), Region::Spans(s), &mut edges, None)
                                .unwrap();
                        }
                    })
                },
            );
        }
    }
    group.finish();
}

/// `frame` with a crosswalk across the lower quarter: eight bright stripes, 5 % of the width
/// wide and as far apart, leaning as the marks do.
fn crosswalk_frame(w: usize, h: usize) -> Vec<u8> {
    let mut data = frame(w, h);
    for y in h * 3 / 4..h {
        for x in 0..w {
            let along = x as f64 + (y as f64 - h as f64) * 0.3;
            if along.rem_euclid(0.1 * w as f64) < 0.05 * w as f64 {
                data[y * w + x] = 210;
            }
        }
    }
    data
}

/// `drop_periodic_stripes` on the whole-frame edges of `crosswalk_frame` (default gradient,
/// four-stripe chains), the edge list copied afresh for each call outside the timing.
fn bench_periodic(c: &mut Criterion) {
    let mut group = c.benchmark_group("periodic_stripes");
    let (w, h) = (320usize, 240usize);
    let data = crosswalk_frame(w, h);
    let img = GreyImage::new(&data, w, h, w).unwrap();
    let mut edges = EdgeBuffer::with_capacity(w * h);
    GradientDetector::new(GradientParams::default())
        .unwrap()
        .detect(&img, Region::Full, &mut edges, None)
        .unwrap();
    let params = PeriodicStripeParams {
        min_stripes: 4,
        ..PeriodicStripeParams::default()
    };
    let mut probe = edges.clone();
    assert!(
        drop_periodic_stripes(&mut probe, &params) > 0,
        "no chain in the bench frame"
    );
    group.bench_function(BenchmarkId::new("drop", format!("{w}x{h}")), |b| {
        b.iter_batched_ref(
            || edges.clone(),
            |e| drop_periodic_stripes(black_box(e), &params),
            BatchSize::SmallInput,
        )
    });
    group.finish();
}

fn bench_exposure(c: &mut Criterion) {
    let mut group = c.benchmark_group("exposure");
    let (w, h) = (320usize, 240usize);
    let data: Vec<u8> = frame(w, h).iter().map(|&v| v / 3).collect();
    let img = GreyImage::new(&data, w, h, w).unwrap();
    // The default ROI of a 320×240 frame: rows 148..240.
    let roi = (148, h);
    let mut hist = [0u32; 256];
    group.bench_function(BenchmarkId::new("median_grey", "320x240_roi"), |b| {
        b.iter(|| median_grey(black_box(&img), roi, &mut hist))
    });
    let mut out = vec![0u8; w * h];
    group.bench_function(BenchmarkId::new("brighten", "320x240_rows_0_240"), |b| {
        b.iter(|| brighten(black_box(&img), (0, h), 1.7, &mut out).unwrap())
    });
    group.finish();
}

criterion_group!(benches, bench, bench_periodic, bench_exposure);
criterion_main!(benches);
