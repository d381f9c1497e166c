//! One full 900 s INS/SD run of the paper's scenario (truth + IMU + 100 Hz mechanization +
//! 1 Hz SD updates), per mode. The `kf` entry is the brief's "one 900 s kf run".
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use criterion::{Criterion, criterion_group, criterion_main};
use ins_sim::{Mode, Sample, Scenario, run, run_seed};
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    let sc = Scenario::paper_default();
    let mut out = vec![Sample::default(); sc.samples_per_run()];
    let seed = run_seed(sc.monte_carlo.seed, 0);
    let mut g = c.benchmark_group("closed_loop_900s");
    g.sample_size(10);
    for mode in [Mode::Kf, Mode::Standalone, Mode::Akf] {
        g.bench_function(mode.name(), |b| {
            b.iter(|| black_box(run(&sc, mode, seed, &mut out).unwrap()))
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
