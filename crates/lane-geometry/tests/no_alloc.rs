//! The per-frame metric step does not allocate.
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use alloc_counter::allocations_in;
use lane_geometry::{EgoLaneEstimator, FitRows, Intrinsics, Mounting, PinholeCamera};
use nalgebra::{Matrix3, Vector3};

#[global_allocator]
static ALLOC: alloc_counter::CountingAllocator = alloc_counter::CountingAllocator::new();

#[test]
fn ego_lane_estimate_does_not_allocate() {
    let camera = PinholeCamera::new(
        Intrinsics {
            focal_length_px: 300.0,
            principal_point_px: [159.5, 119.5],
        },
        Mounting {
            height_m: 0.3,
            pitch_down_rad: 0.2,
            roll_rad: 0.0,
            yaw_rad: 0.0,
        },
    )
    .unwrap();
    let ego = EgoLaneEstimator::new(camera.homography().unwrap(), 0.55, 1.0).unwrap();
    let cov = Matrix3::from_diagonal(&Vector3::new(1e-10, 2e-5, 0.4));
    let (lane, n) = allocations_in(|| {
        let mut last = None;
        for k in 0..100 {
            let dk = f64::from(k) * 0.1;
            last = Some(ego.estimate(&[0.0, -1.1, 300.0 + dk], &cov, &[0.0, 0.9, 20.0], &cov));
        }
        last
    });
    assert!(lane.unwrap().unwrap().geometry.lane_width_m > 0.0);
    assert_eq!(n, 0, "{n} allocations in 100 estimates");
    // With the image-parabola model error removed (step 5).
    let fit = [
        FitRows::uniform(150.0, 230.0),
        FitRows::uniform(150.0, 230.0),
    ];
    let (lane, n) = allocations_in(|| {
        let mut last = None;
        for k in 0..100 {
            let dk = f64::from(k) * 0.1;
            let left = [1e-4, -1.1, 300.0 + dk];
            last = Some(ego.estimate_fitted(&left, &cov, &[-1e-4, 0.9, 20.0], &cov, &fit));
        }
        last
    });
    assert!(lane.unwrap().unwrap().geometry.lane_width_m > 0.0);
    assert_eq!(n, 0, "{n} allocations in 100 fitted estimates");
}
