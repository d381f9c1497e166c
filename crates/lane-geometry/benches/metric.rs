//! The metric step per frame: both lanes' parabolas and covariances → lateral offset, heading,
//! curvature and lane width with their covariance (`EgoLaneEstimator::estimate`).
//!
//! `cargo bench -p lane-geometry --bench metric -- --warm-up-time 1 --measurement-time 3`
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use lane_geometry::{EgoLaneEstimator, Intrinsics, Mounting, PinholeCamera};
use nalgebra::{Matrix3, Vector3};

fn metric(c: &mut Criterion) {
    let camera = PinholeCamera::new(
        Intrinsics {
            focal_length_px: 300.0,
            principal_point_px: [159.5, 119.5],
        },
        Mounting {
            height_m: 0.3,
            pitch_down_rad: 0.2,
            roll_rad: 0.01,
            yaw_rad: -0.02,
        },
    )
    .unwrap();
    let ego = EgoLaneEstimator::new(camera.homography().unwrap(), 0.6, 2.0).unwrap();
    // A curved pair of marks (image parabolas), covariance of a converged KIF.
    let left = [6e-4, -1.1, 260.0];
    let right = [6e-4, 0.9, -60.0];
    let cov = Matrix3::from_diagonal(&Vector3::new(1e-10, 2e-5, 0.4));
    ego.estimate(&left, &cov, &right, &cov).unwrap();
    c.bench_function("ego_lane_estimate", |b| {
        b.iter(|| {
            ego.estimate(
                black_box(&left),
                black_box(&cov),
                black_box(&right),
                black_box(&cov),
            )
            .unwrap()
        })
    });
}

criterion_group!(benches, metric);
criterion_main!(benches);
