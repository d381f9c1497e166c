//! What the unit tests of the outputs share: the robot camera and its bird's-eye view, and lane
//! reports built by hand on a 320×240 frame.
#![allow(clippy::unwrap_used)]

use lane_tracker::camera::CameraModel;
use lane_tracker::{LaneReport, LaneState, RoadReport, Side, TrackReport};

use crate::birdseye::BirdseyeView;

/// The `robot` camera preset (320×240 frames) and its bird's-eye view.
pub(crate) fn robot_view() -> (CameraModel, BirdseyeView) {
    let camera = crate::config::load_camera_config("robot")
        .unwrap()
        .model()
        .unwrap();
    let view = BirdseyeView::for_camera(&camera).unwrap();
    (camera, view)
}

/// A tracked lane of `side` with `coeffs` over `rows`.
pub(crate) fn tracked_lane(side: Side, coeffs: [f64; 3], rows: [f64; 2]) -> LaneReport {
    LaneReport {
        side,
        state: LaneState::Tracking,
        coeffs: Some(coeffs),
        rows,
        points: 10,
        initialised: false,
        far: None,
    }
}

/// A report of `lanes` on a 320×240 frame searched on rows 150–240, with `horizon_row_px`.
pub(crate) fn report(lanes: [LaneReport; 2], horizon_row_px: Option<f64>) -> TrackReport {
    TrackReport {
        lanes,
        full_gradient: false,
        road: RoadReport {
            bottom_row_px: 240.0,
            search_rows_px: [150.0, 240.0],
            horizon_row_px,
            refused: None,
        },
    }
}
