//! One stand-alone INS run: truth generation + IMU error model + mechanization at 100 Hz.
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use ins_errors::config::{ImuConfig, TrajectoryConfig};
use ins_errors::imu::{ImuErrorParams, ImuErrors};
use ins_errors::strapdown::{NavState, Strapdown};
use ins_errors::trajectory::Trajectory;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use std::hint::black_box;

fn run(tr: &Trajectory, params: &ImuErrorParams, seed: u64) -> NavState {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let imu = ImuErrors::draw(params, &mut rng);
    let mut it = tr.samples();
    let s0 = it.next().unwrap();
    let mut ins = Strapdown::new(s0.nav_state(), tr.step_s()).unwrap();
    let mut ideal = (s0.specific_force_body_mps2, s0.ang_rate_ib_body_radps);
    for s in it {
        let (f, w) = imu.measure(&ideal.0, &ideal.1, &mut rng);
        ins.step(&f, &w);
        ideal = (s.specific_force_body_mps2, s.ang_rate_ib_body_radps);
    }
    *ins.state()
}

fn bench(c: &mut Criterion) {
    let params = ImuErrorParams::from_config(&ImuConfig::paper()).unwrap();
    let mut g = c.benchmark_group("standalone_run");
    g.sample_size(20);
    for end in [90.0, 900.0] {
        let mut cfg = TrajectoryConfig::paper();
        cfg.end_time_s = end;
        if end < 600.0 {
            cfg.segments.truncate((end / 40.0) as usize);
        }
        let tr = Trajectory::new(&cfg).unwrap();
        g.bench_with_input(
            BenchmarkId::new("truth+imu+ins", format!("{end}s")),
            &tr,
            |b, tr| b.iter(|| black_box(run(tr, &params, 1))),
        );
    }
    let tr = Trajectory::new(&TrajectoryConfig::paper()).unwrap();
    g.bench_function("truth_only/900s", |b| {
        b.iter(|| {
            let mut acc = 0.0;
            for s in tr.samples() {
                acc += s.specific_force_body_mps2.z;
            }
            black_box(acc)
        })
    });
    let mut buf = vec![tr.samples().next().unwrap(); tr.n_samples()];
    tr.fill(&mut buf).unwrap();
    g.bench_function("ins_only/900s", |b| {
        b.iter(|| {
            let s0 = &buf[0];
            let mut ins = Strapdown::new(s0.nav_state(), tr.step_s()).unwrap();
            for s in &buf[..buf.len() - 1] {
                ins.step(&s.specific_force_body_mps2, &s.ang_rate_ib_body_radps);
            }
            black_box(*ins.state())
        })
    });
    let imu = ImuErrors::draw(&params, &mut ChaCha8Rng::seed_from_u64(2));
    g.bench_function("imu_only/900s", |b| {
        b.iter(|| {
            let mut rng = ChaCha8Rng::seed_from_u64(3);
            let mut acc = nalgebra::Vector3::zeros();
            for s in &buf[..buf.len() - 1] {
                let (f, _) = imu.measure(
                    &s.specific_force_body_mps2,
                    &s.ang_rate_ib_body_radps,
                    &mut rng,
                );
                acc += f;
            }
            black_box(acc)
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
