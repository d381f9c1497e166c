//! Noisy cameras on rendered frames (module `lane_tracker::tracker::denoise`): a frame below the
//! noise limit is tracked exactly as with denoising off, and a noisy camera is measured, smoothed
//! and tracked closer to the truth than without.
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use lane_scenes::{SCENES, SceneRenderer, add_sensor_noise};
use lane_tracker::{Estimator, GreyFrame, LaneTracker, TrackerConfig};

fn off(cfg: &TrackerConfig) -> TrackerConfig {
    let mut off = *cfg;
    off.denoise.above_noise_grey = 0.0;
    off
}

#[test]
fn frames_below_the_noise_limit_are_tracked_exactly_as_with_denoising_off() {
    let cfg = TrackerConfig::default_preset().unwrap();
    assert!(cfg.denoise.above_noise_grey > 0.0);
    let (w, h) = (320usize, 240usize);
    for spec in SCENES.iter().filter(|s| s.name != "noise") {
        let mut renderer = SceneRenderer::new(*spec, w, h);
        let mut on = LaneTracker::new(&cfg, Estimator::Kif, w, h).unwrap();
        let mut without = LaneTracker::new(&off(&cfg), Estimator::Kif, w, h).unwrap();
        let mut frame = GreyFrame::default();
        for i in 0..spec.frames.min(60) {
            renderer.render(i, &mut frame);
            let (a, b) = (on.track(&frame).unwrap(), without.track(&frame).unwrap());
            let noise = on.frame_noise();
            assert!(
                !noise.denoised,
                "{} frame {i}: σ̂ {}",
                spec.name, noise.sigma_grey
            );
            assert_eq!(a, b, "{} frame {i}", spec.name);
        }
    }
}

#[test]
fn a_noisy_camera_is_measured_smoothed_and_tracked_closer_to_the_truth() {
    // Every rendered scene with sensor noise of σ = 10 grey levels added: the default reads σ̂
    // near 10 on every frame it measures, smooths the frames, and its lanes on the ROI's rows are
    // closer to the truth than with denoising off (a lost lane counted as the frame's width;
    // measured 0.36 against 8.68 px).
    let cfg = TrackerConfig::default_preset().unwrap();
    let (w, h) = (320usize, 240usize);
    let rows: Vec<f64> = (0..8).map(|k| 0.66 * h as f64 + k as f64 * 10.0).collect();
    let (mut errors, mut count) = ([0.0f64; 2], 0usize);
    for spec in SCENES {
        let mut renderer = SceneRenderer::new(*spec, w, h);
        let mut trackers =
            [cfg, off(&cfg)].map(|c| LaneTracker::new(&c, Estimator::Kif, w, h).unwrap());
        let mut frame = GreyFrame::default();
        for i in 0..spec.frames.min(40) {
            renderer.render(i, &mut frame);
            add_sensor_noise(&mut frame, 10.0, 53 + i);
            let truth = renderer.truth(i);
            for (k, tracker) in trackers.iter_mut().enumerate() {
                let report = tracker.track(&frame).unwrap();
                if k == 0 {
                    let n = tracker.frame_noise();
                    assert!(n.denoised, "{} frame {i}", spec.name);
                    // (The `noise` scene has its own on top.)
                    let most = if spec.name == "noise" { 16.0 } else { 11.5 };
                    assert!(
                        (8.5..=most).contains(&n.sigma_grey),
                        "{} frame {i}: σ̂ {}",
                        spec.name,
                        n.sigma_grey
                    );
                }
                for (lane, t) in report.lanes.iter().zip(truth.lanes) {
                    if !t.visible {
                        continue;
                    }
                    for &y in &rows {
                        count += usize::from(k == 0);
                        errors[k] += lane
                            .col_at_row(y)
                            .map_or(w as f64, |x| (x - t.col_at_row(y)).abs().min(w as f64));
                    }
                }
            }
        }
    }
    let mean = errors.map(|e| e / count as f64);
    assert!(
        mean[0] < 0.8 * mean[1],
        "smoothed {:.2} px, as they are {:.2} px",
        mean[0],
        mean[1]
    );
}
