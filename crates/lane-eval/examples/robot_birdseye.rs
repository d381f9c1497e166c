//! The robot road rendered through the robot camera, tracked, and drawn side by side: the camera
//! frame with the tracker's overlay, and the bird's-eye view with the ego lane in metres.
//!
//! `cargo run --release -p lane-eval --example robot_birdseye -- OUT.png [FRAME]`
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use lane_io::birdseye::BirdseyeView;
use lane_io::overlay::render_overlay;
use lane_scenes::road::{ROBOT_ROADS, RoadRenderer};
use lane_tracker::{Estimator, GreyFrame, LaneTracker, TrackerConfig};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let out = args
        .next()
        .unwrap_or_else(|| "robot_birdseye.png".to_owned());
    let last: u64 = args.next().map(|s| s.parse()).transpose()?.unwrap_or(40);
    let cam_cfg = lane_io::config::load_camera_config("robot")?;
    let camera = cam_cfg.model()?;
    let spec = ROBOT_ROADS[1];
    let mut renderer = RoadRenderer::new(spec, &cam_cfg)?;
    let mut cfg = TrackerConfig::indoor()?;
    cfg.roi.top_row_fraction = 0.45;
    cfg.track.mark_centres = true; // sub-pixel mark centres (no preset turns them on)
    let mut tracker = LaneTracker::new(&cfg, Estimator::Kif, 320, 240)?;
    let view = BirdseyeView::for_camera(&camera)?;
    let mut frame = GreyFrame::default();
    let mut report = None;
    for i in 0..=last {
        renderer.render(i, &mut frame);
        report = Some(tracker.track(&frame)?);
    }
    let report = report.expect("at least one frame");
    let ego = camera.ego_lane(&tracker, &report);
    let truth = renderer.truth(last);
    println!("frame {last}: truth {truth:?}\nestimate {ego:?}");
    let (mut cam_rgb, mut bird_rgb) = (Vec::new(), Vec::new());
    render_overlay(&frame, &tracker, &mut cam_rgb);
    view.render(&frame, &report, ego, &mut bird_rgb);
    let (bw, bh) = (view.width_px(), view.height_px());
    let (w, h) = (320 + bw, bh.max(240));
    let mut img = vec![0u8; w * h * 3];
    for y in 0..240 {
        let dst = 3 * (y + (h - 240) / 2) * w;
        img[dst..dst + 320 * 3].copy_from_slice(&cam_rgb[y * 320 * 3..(y + 1) * 320 * 3]);
    }
    for y in 0..bh {
        let dst = 3 * (y * w + 320);
        img[dst..dst + bw * 3].copy_from_slice(&bird_rgb[y * bw * 3..(y + 1) * bw * 3]);
    }
    image::save_buffer(
        &out,
        &img,
        w as u32,
        h as u32,
        image::ExtendedColorType::Rgb8,
    )?;
    println!("wrote {out}");
    Ok(())
}
