//! A deterministic work count for the tracker's frames, beside the criterion bench
//! (`cargo bench -p lane-eval --bench track`), whose wall times swing with a shared VM's load:
//! runs `N` frames of one kind on the udacity clip's 10th frame (the bench's frame) with the
//! default configuration and prints the wall time per frame. Run under
//! `valgrind --tool=callgrind --callgrind-out-file=/dev/null` with `N` and with `0` frames; the
//! difference of the two "Collected" counts over `N` is the instructions per frame.
//!
//! `frame_cost KIND N`, `KIND` one of `init` (an initialisation frame), `right` (the ROI's right
//! half blanked: the second search runs for the right side), `both` (the whole ROI blanked: both
//! sides searched for over the taller rows), `track` (a tracked frame; re-validation off),
//! `revalidate` (a re-validation frame: both lanes tracked, the joint initialisation run over
//! the ROI on every frame), `clip` (the whole clip, 221 frames, with a fresh tracker, `N` times:
//! the difference over `N · 221` is the mean per frame over the clip, re-validations and the
//! first frame's initialisation included), `clip_whole` (the same with
//! `track.revalidate_spread = false`: the whole re-validation on every 10th frame).
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]
use lane_io::FrameSource;
use lane_io::y4m::Y4mSource;
use lane_tracker::{Estimator, GreyFrame, LaneTracker, TrackerConfig};

fn main() {
    let mut args = std::env::args().skip(1);
    let kind = args.next().unwrap_or_else(|| "init".into());
    let n: usize = args
        .next()
        .map_or(100, |s| s.parse().expect("a frame count"));
    let path =
        lane_bench::data::data_file(lane_bench::data::UDACITY_CLIP).expect("the udacity clip");
    let file = std::fs::File::open(&path).expect("the udacity clip opens");
    let mut src = Y4mSource::new(std::io::BufReader::new(file), path.display().to_string())
        .expect("a y4m stream");
    let mut frame = GreyFrame::default();
    if kind.starts_with("clip") {
        let mut cfg = TrackerConfig::default_preset().unwrap();
        cfg.track.revalidate_spread = kind != "clip_whole";
        let mut clip = Vec::new();
        while src.next_frame(&mut frame).unwrap().is_some() {
            clip.push(frame.clone());
        }
        let (w, h) = (clip[0].width(), clip[0].height());
        let start = std::time::Instant::now();
        for _ in 0..n {
            let mut tracker = LaneTracker::new(&cfg, Estimator::Kif, w, h).unwrap();
            for f in &clip {
                std::hint::black_box(tracker.track(std::hint::black_box(f)).unwrap());
            }
        }
        let frames = (n * clip.len()).max(1);
        let per_frame_us = start.elapsed().as_secs_f64() * 1e6 / frames as f64;
        println!(
            "{kind}: {n} × {} frames, {per_frame_us:.1} µs a frame (wall, trackers' construction included)",
            clip.len()
        );
        return;
    }
    for _ in 0..10 {
        src.next_frame(&mut frame).unwrap().expect("10 frames");
    }
    let mut cfg = TrackerConfig::default_preset().unwrap();
    cfg.track.revalidate_every_frames = match kind.as_str() {
        "track" => 0,
        "revalidate" => 1,
        _ => cfg.track.revalidate_every_frames,
    };
    if kind == "track" {
        cfg.track.revalidate_below_points = 0;
    }
    let mut tracker =
        LaneTracker::new(&cfg, Estimator::Kif, frame.width(), frame.height()).unwrap();
    for _ in 0..5 {
        tracker.track(&frame).unwrap();
    }
    let (top, bottom) = tracker.roi_rows();
    let w = frame.width();
    let blank_from = match kind.as_str() {
        "init" | "track" | "revalidate" => None,
        "right" => Some(w / 2),
        "both" => Some(0),
        other => {
            panic!("unknown kind {other}: init, right, both, track, revalidate, clip or clip_whole")
        }
    };
    let mut input = frame.clone();
    if let Some(from_col) = blank_from {
        let fill = frame.data()[top * w];
        for row in input.data_mut()[top * w..bottom * w].chunks_mut(w) {
            row[from_col..].fill(fill);
        }
    }
    let start = std::time::Instant::now();
    for _ in 0..n {
        if kind != "track" && kind != "revalidate" {
            tracker.reset();
        }
        std::hint::black_box(tracker.track(std::hint::black_box(&input)).unwrap());
    }
    let per_frame_us = start.elapsed().as_secs_f64() * 1e6 / n.max(1) as f64;
    println!("{kind}: {n} frames, {per_frame_us:.1} µs a frame (wall)");
}
