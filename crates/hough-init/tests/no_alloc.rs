//! Initialisation with an existing workspace does not allocate, the oriented vote once its
//! points are reserved (counting global allocator from `alloc-counter`, which counts only the
//! measuring thread's allocations, so the test harness's own threads cannot disturb the count).
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use alloc_counter::allocations_in;
use hough_init::{
    AngleBand, HoughLine, HoughParams, HoughWorkspace, LaneInitParams, OrientedPoint, Point,
    fit_parabola, init_lane,
};

#[global_allocator]
static ALLOC: alloc_counter::CountingAllocator = alloc_counter::CountingAllocator::new();

#[test]
fn repeated_initialisations_do_not_allocate() {
    let left: Vec<Point> = (100..240)
        .map(|r| Point::new(200.0 - 0.8 * f64::from(r - 100), f64::from(r)))
        .collect();
    let right: Vec<Point> = (100..240)
        .map(|r| Point::new(170.0 + 0.9 * f64::from(r - 100), f64::from(r)))
        .collect();
    let mut ws = HoughWorkspace::new(320, 240, HoughParams::default()).unwrap();
    let params = LaneInitParams {
        refit_iterations: 1,
        ..LaneInitParams::default()
    };
    // Sanity: the counter does see this thread's allocations.
    let (probe, allocations) = allocations_in(|| std::hint::black_box(vec![1u8; 16]));
    assert_eq!(allocations, 1, "counter is not counting");
    drop(probe);
    let oriented: Vec<OrientedPoint> = left
        .iter()
        .map(|p| OrientedPoint {
            col_px: p.col_px as f32,
            row_px: p.row_px as f32,
            normal_deg: 51.3,
            votes: 1,
        })
        .collect();
    ws.reserve_oriented_points(oriented.len());
    let mut lines = [HoughLine {
        rho_px: 0.0,
        theta_rad: 0.0,
        votes: 0,
    }; 4];
    let (used, allocations) = allocations_in(|| {
        let mut used = 0;
        for _ in 0..10 {
            used += ws
                .find_lines_oriented(&oriented, &AngleBand::LEFT_LANE, 15.0, 3.0, 8.0, &mut lines)
                .unwrap();
            used += init_lane(&left, &AngleBand::LEFT_LANE, &mut ws, &params)
                .unwrap()
                .points_used;
            used += init_lane(&right, &AngleBand::RIGHT_LANE, &mut ws, &params)
                .unwrap()
                .points_used;
            used += fit_parabola(&left).unwrap().points_used;
        }
        used
    });
    assert!(used > 0);
    assert_eq!(
        allocations, 0,
        "{allocations} allocations during initialisation"
    );
}
