//! Cost of one sighting update's model evaluation: the analytic H plus the nonlinear offsets
//! (w, h), for 1 and 3 landmarks at the paper's start geometry.
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::{Rotation3, Vector3};
use sighting_model::{
    Geodetic, NavPose, paper_landmarks, sighting_jacobian, sighting_jacobian3, sighting_offset_m,
    sighting_offsets3_m, true_pose_from_errors,
};

fn bench(c: &mut Criterion) {
    let start = Geodetic::from_deg(-(23.0 + 12.0 / 60.0), -(45.0 + 52.0 / 60.0), 6000.0);
    let computed = NavPose {
        position: start,
        c_b_n: Rotation3::from_euler_angles(0.02, -0.01, 0.52),
    };
    let truth = true_pose_from_errors(
        &computed,
        &Vector3::new(40.0, -25.0, 10.0),
        &Vector3::new(1e-3, -2e-3, 3e-3),
    );
    let landmarks = paper_landmarks();
    let mut g = c.benchmark_group("sighting_h_plus_offsets");
    g.bench_function("1_landmark", |b| {
        b.iter(|| {
            let h = sighting_jacobian(black_box(&computed.position), black_box(&landmarks[0]));
            let z = sighting_offset_m(black_box(&truth), black_box(&computed), &landmarks[0]);
            (h.unwrap(), z.unwrap())
        })
    });
    g.bench_function("3_landmarks", |b| {
        b.iter(|| {
            let h = sighting_jacobian3(black_box(&computed.position), black_box(&landmarks));
            let z = sighting_offsets3_m(black_box(&truth), black_box(&computed), &landmarks);
            (h.unwrap(), z.unwrap())
        })
    });
    g.bench_function("3_landmarks_h_only", |b| {
        b.iter(|| sighting_jacobian3(black_box(&computed.position), black_box(&landmarks)).unwrap())
    });
    g.bench_function("3_landmarks_offsets_only", |b| {
        b.iter(|| {
            sighting_offsets3_m(
                black_box(&truth),
                black_box(&computed),
                black_box(&landmarks),
            )
            .unwrap()
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
