//! TuSimple-style accuracy of the initialisation stage on the six labelled lanenet frames.
//!
//! `cargo run --release -p lane-eval --example lanenet_eval [DIR]` (default `../shared/data/lanenet`).
//! Each 1280×720 colour frame goes to a fresh tracker (grey conversion, full-ROI gradient,
//! Hough + LS per lane, one windowed refinement on the same frame) and the two reported lanes
//! are scored against the two ego lanes of `gt_instance_image/` at rows 160, 170, … (TuSimple's
//! h-samples) from the ROI top down: correct within 20 px at 1280 px width.
//! The default configuration is used as it is (its pixel parameters are for 320-px-wide frames,
//! and the tracker works on the 1280-px frames' 4 × 4 box average: `frame.working_width_px`) with
//! the ROI top at 40 % of the height (the horizon of these frames is at about 36 %).
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use std::path::PathBuf;

use lane_eval::eval::score_against_instance_label;
use lane_io::sources::decode_image_file;
use lane_tracker::{Estimator, GreyFrame, LaneTracker, TrackerConfig};

fn main() {
    let dir = std::env::args()
        .nth(1)
        .map(PathBuf::from)
        .unwrap_or_else(|| {
            PathBuf::from(concat!(
                env!("CARGO_MANIFEST_DIR"),
                "/../../../shared/data/lanenet"
            ))
        });
    let mut cfg = TrackerConfig::default_preset().unwrap();
    cfg.roi.top_row_fraction = 0.40;
    let (mut frame, mut label) = (GreyFrame::default(), GreyFrame::default());
    let (mut points, mut correct) = (0u64, 0u64);
    println!("frame  points correct accuracy mean_err_px  left right");
    for i in 0..6 {
        let name = format!("{i:04}.png");
        decode_image_file(&dir.join("image").join(&name), &mut frame).unwrap();
        decode_image_file(&dir.join("gt_instance_image").join(&name), &mut label).unwrap();
        let mut tracker =
            LaneTracker::new(&cfg, Estimator::Kif, frame.width(), frame.height()).unwrap();
        let report = tracker.track(&frame).unwrap();
        let top = tracker.roi_rows().0.div_ceil(10) * 10;
        let s = score_against_instance_label(&report, &label, top.max(160), 10);
        points += s.points;
        correct += s.correct;
        println!(
            "{name}  {:6} {:7} {:8.3} {:11.2}  {} {}",
            s.points,
            s.correct,
            s.accuracy,
            s.mean_error_px,
            report.lanes[0].state.name(),
            report.lanes[1].state.name()
        );
    }
    println!(
        "all    {points:6} {correct:7} {:8.3}",
        correct as f64 / points.max(1) as f64
    );
}
