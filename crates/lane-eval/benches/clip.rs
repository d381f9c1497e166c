//! The whole real udacity clip (221 frames, 320×240, `lane_bench::data::UDACITY_CLIP`) tracked
//! frame after frame, one thread: the **mean time per frame over the clip**, the first frame's
//! initialisation and every re-validation included, as a video fed to `nav-app --input` sees it
//! (the `track` bench measures one frame of each kind).
//!
//! Each iteration tracks every frame of the clip (decoded into memory once, before any timing)
//! with a **fresh tracker**, built outside the timed part (`LaneTracker::new` sizes its buffers;
//! a user builds one per stream): frame 0 initialises both lanes as in `nav-app`. Criterion's
//! time is the iteration's total divided by the clip's frames (`iter_custom`), so the figure it
//! reports is the per-frame mean. Before the benchmark each case also tracks the clip five times
//! more with every frame timed, and prints the median, the mean, the 90th percentile and the
//! largest per-frame time of those 5 × 221 frames (the mean over the median is what issue 53
//! item 6 bounds), and how many frames re-validated.
//!
//! Cases: `default` (the default configuration: the period's re-validation spread over its
//! frames, `track.revalidate_spread`), `whole_revalidation` (the same with
//! `track.revalidate_spread = false`: the whole re-validation on every 10th frame, the default
//! before issue 53 item 6), `revalidation_off` (`track.revalidate_every_frames = 0` and
//! `track.revalidate_below_points = 0`: what the tracked frames alone cost).
//!
//! `cargo bench -p lane-eval --bench clip -- --warm-up-time 2 --measurement-time 10`
//!
//! Without the clip under the data root (`lane_bench::data`), it says so and measures nothing.
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use std::hint::black_box;
use std::time::{Duration, Instant};

mod common;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use lane_tracker::{Estimator, GreyFrame, LaneTracker, TrackerConfig};

/// Tracks `frames` with a fresh tracker, each frame timed: the per-frame times and the
/// re-validations counted.
fn timed_pass(cfg: &TrackerConfig, frames: &[GreyFrame], times: &mut Vec<Duration>) -> u64 {
    let (w, h) = (frames[0].width(), frames[0].height());
    let mut tracker = LaneTracker::new(cfg, Estimator::Kif, w, h).unwrap();
    for frame in frames {
        let start = Instant::now();
        black_box(tracker.track(black_box(frame)).unwrap());
        times.push(start.elapsed());
    }
    tracker.counters().revalidations
}

/// Prints the median, mean, 90th percentile and largest per-frame time of five timed passes.
fn print_per_frame(case: &str, cfg: &TrackerConfig, frames: &[GreyFrame]) {
    let mut times = Vec::with_capacity(5 * frames.len());
    let mut revalidations = 0;
    for _ in 0..5 {
        revalidations = timed_pass(cfg, frames, &mut times);
    }
    times.sort_unstable();
    let us = |d: Duration| d.as_secs_f64() * 1e6;
    let median = us(times[times.len() / 2]);
    let mean = times.iter().map(|&d| us(d)).sum::<f64>() / times.len() as f64;
    let p90 = us(times[times.len() * 9 / 10]);
    let max = us(times[times.len() - 1]);
    println!(
        "clip/{case}: {} frames × 5 passes, per frame: median {median:.1} µs, mean {mean:.1} µs \
         (mean/median {:.2}), 90th percentile {p90:.1} µs, largest {max:.1} µs; \
         {revalidations} re-validations a pass",
        frames.len(),
        mean / median
    );
}

fn clip(c: &mut Criterion) {
    let Some(frames) = common::udacity_clip("clip") else {
        return;
    };
    let default = TrackerConfig::default_preset().unwrap();
    let mut whole = default;
    whole.track.revalidate_spread = false;
    let mut off = default;
    off.track.revalidate_every_frames = 0;
    off.track.revalidate_below_points = 0;
    let (w, h) = (frames[0].width(), frames[0].height());
    let n = u32::try_from(frames.len()).unwrap();
    let mut group = c.benchmark_group("clip");
    group.sample_size(20);
    for (case, cfg) in [
        ("default", default),
        ("whole_revalidation", whole),
        ("revalidation_off", off),
    ] {
        print_per_frame(case, &cfg, &frames);
        group.bench_function(BenchmarkId::new(case, "udacity_320x240_per_frame"), |b| {
            b.iter_custom(|iters| {
                let mut total = Duration::ZERO;
                for _ in 0..iters {
                    let mut tracker = LaneTracker::new(&cfg, Estimator::Kif, w, h).unwrap();
                    let start = Instant::now();
                    for frame in &frames {
                        black_box(tracker.track(black_box(frame)).unwrap());
                    }
                    total += start.elapsed();
                }
                // Criterion divides by `iters`: the time it reports is per frame.
                total / n
            });
        });
    }
    group.finish();
}

criterion_group!(benches, clip);
criterion_main!(benches);
