//! The metric step added to a frame by `--camera`: both lanes' pixel covariances from the KIF
//! (information matrix inverted, mapped to pixel coefficients) and the ego lane in metres with
//! its covariance (`CameraModel::ego_lane`), on the robot road rendered through the robot camera.
//!
//! `cargo bench -p lane-eval --bench metric -- --warm-up-time 1 --measurement-time 3`
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use lane_scenes::road::{ROBOT_ROADS, RoadRenderer};
use lane_tracker::{Estimator, GreyFrame, LaneTracker, TrackerConfig};

fn metric_step(c: &mut Criterion) {
    let cam_cfg = lane_io::config::load_camera_config("robot").unwrap();
    let camera = cam_cfg.model().unwrap();
    let mut renderer = RoadRenderer::new(ROBOT_ROADS[1], &cam_cfg).unwrap();
    let mut cfg = TrackerConfig::indoor().unwrap();
    cfg.roi.top_row_fraction = 0.45;
    cfg.track.mark_centres = true; // sub-pixel mark centres (no preset turns them on)
    let mut tracker = LaneTracker::new(&cfg, Estimator::Kif, 320, 240).unwrap();
    let mut frame = GreyFrame::default();
    let mut report = None;
    for i in 0..12 {
        renderer.render(i, &mut frame);
        report = Some(tracker.track(&frame).unwrap());
    }
    let report = report.unwrap();
    assert!(camera.ego_lane(&tracker, &report).is_some());
    c.bench_function("ego_lane_from_tracker", |b| {
        b.iter(|| camera.ego_lane(black_box(&tracker), black_box(&report)))
    });
}

criterion_group!(benches, metric_step);
criterion_main!(benches);
