//! The tracker's tests, one file per stage (the synthetic scenes they draw in `scenes`). They
//! reach into the stages' state: a test sets a lane or a buffer by hand and runs one stage on it
//! with the inputs the pipeline would give it (the helpers below, over the ROI's rows).

use alloc_counter::{CountingAllocator, allocations_in};
use hough_init::Parabola;
use info_filter::KifError;
use nalgebra::Vector3;
use vision_gradient::{EdgeClass, EdgePixel, GreyImage};
use wrls::WrlsError;

use super::lane::{HandOver, LaneFilter, SavedEstimate};
use super::{Estimator, InitCandidate, LaneState, LaneTracker, Side};
use crate::tracker::candidates::counts_as;
use crate::tracker::init::WeakLanes;
use crate::{FilterFailure, GreyFrame, TrackerConfig};

mod candidates;
mod failures;
mod gates;
mod init;
mod readings;
mod revalidation;
mod scenes;
mod second_search;
mod stripe_trace;

#[global_allocator]
static ALLOC: CountingAllocator = CountingAllocator::new();

/// The stripe trace of the lane on `side` over the ROI's rows (module `stripe_trace`).
fn trace_stripe(t: &mut LaneTracker, side: Side, image: &GreyImage<'_>) -> usize {
    let (setup, health) = (&t.setup, &mut t.health);
    let rows = setup.roi;
    t.tracer
        .trace(&mut t.lanes[side], side, image, rows, &setup.cfg, health)
}

/// The lane on `side` moved to a double line's middle over the ROI's rows (module
/// `double_line`).
fn centre_on_double_line(t: &mut LaneTracker, side: Side, image: &GreyImage<'_>) -> bool {
    let rows = t.setup.roi;
    crate::tracker::double_line::centre_on_double_line(
        &mut t.lanes[side],
        side,
        image,
        rows,
        &t.setup,
        &mut t.health,
    )
}

/// The lane on `side` moved onto a kerb's foot over the ROI's rows (module `kerb`).
fn onto_kerb_foot(t: &mut LaneTracker, side: Side, image: &GreyImage<'_>) -> bool {
    let rows = t.setup.roi;
    t.kerb
        .onto_kerb_foot(&mut t.lanes[side], side, image, rows, &t.setup.cfg)
}

/// The lane on `side` straightened where it turns back, over the ROI's rows (module
/// `turn_back`).
fn straighten_turn_back(t: &mut LaneTracker, side: Side) -> bool {
    let rows = t.setup.roi;
    crate::tracker::turn_back::straighten_turn_back(
        &mut t.lanes[side],
        side,
        rows,
        &t.setup,
        &mut t.health,
    )
}

/// Stages I–II over the ROI's rows, every band voting, no weak lane set aside: the edges and
/// candidates of `image` left in the stages' buffers.
fn search_roi(t: &mut LaneTracker, image: &GreyImage<'_>) {
    let rows = t.setup.roi;
    t.init
        .search(
            image,
            &mut t.edges,
            &mut t.lanes,
            &mut t.health,
            &t.setup,
            rows,
            [true, true],
            WeakLanes::Keep,
        )
        .expect("a search");
}
