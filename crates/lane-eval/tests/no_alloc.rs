//! The per-frame tracking path does not allocate (issue 4 §1): counted with the `alloc-counter`
//! global allocator, which counts allocations made by the measuring thread only.
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use alloc_counter::allocations_in;
use lane_scenes::{SCENES, SceneRenderer};
use lane_tracker::{Estimator, GreyFrame, LaneTracker, TrackerConfig};

#[global_allocator]
static ALLOC: alloc_counter::CountingAllocator = alloc_counter::CountingAllocator::new();

fn allocations_while_tracking(estimator: Estimator, scene: &str) -> (u64, u64) {
    let spec = SCENES.iter().find(|s| s.name == scene).copied().unwrap();
    allocations_with(
        estimator,
        scene,
        &lane_io::config::load_tracker_config(spec.config).unwrap(),
    )
}

fn allocations_with(estimator: Estimator, scene: &str, cfg: &TrackerConfig) -> (u64, u64) {
    allocations_at(estimator, scene, cfg, 320, 240)
}

/// [`allocations_with`] on frames `w × h` (wider ones are tracked on their box average).
fn allocations_at(
    estimator: Estimator,
    scene: &str,
    cfg: &TrackerConfig,
    w: usize,
    h: usize,
) -> (u64, u64) {
    let spec = SCENES.iter().find(|s| s.name == scene).copied().unwrap();
    let cfg = *cfg;
    let mut renderer = SceneRenderer::new(spec, w, h);
    let mut tracker = LaneTracker::new(&cfg, estimator, w, h).unwrap();
    let mut frame = GreyFrame::default();
    let mut frames = 0;
    let mut allocs = 0;
    for i in 0..spec.frames {
        renderer.render(i, &mut frame); // rendering may allocate (RNG, truth); not counted
        let (report, n) = allocations_in(|| tracker.track(&frame));
        report.unwrap();
        allocs += n;
        frames += 1;
    }
    (allocs, frames)
}

#[test]
fn kif_tracking_and_reinitialisation_frames_do_not_allocate() {
    // wall_recovery covers tracking, coasting, loss and Hough + LS re-initialisation.
    for scene in ["straight_solid", "wall_recovery", "noise"] {
        let (allocs, frames) = allocations_while_tracking(Estimator::Kif, scene);
        assert!(frames > 20);
        assert_eq!(
            allocs, 0,
            "{scene}: {allocs} allocations in {frames} frames"
        );
    }
}

#[test]
fn the_default_configuration_does_not_allocate() {
    // Joint initialisation (several Hough candidates, ego-pair choice) and stripe splitting,
    // on every frame of sequences with re-initialisation, and a re-validation every
    // `track.revalidate_every_frames` frames (> 20 frames: at least two).
    let cfg = TrackerConfig::default_preset().unwrap();
    assert!(cfg.init.candidate_lines > 0 && cfg.gradient.stripe_paired_votes > 0);
    assert!((1..=10).contains(&cfg.track.revalidate_every_frames));
    for scene in ["wall_recovery", "noise"] {
        let (allocs, frames) = allocations_with(Estimator::Kif, scene, &cfg);
        assert!(frames > 20);
        assert_eq!(
            allocs, 0,
            "{scene}: {allocs} allocations in {frames} frames"
        );
    }
}

#[test]
fn wrls_tracking_frames_do_not_allocate() {
    let (allocs, frames) = allocations_while_tracking(Estimator::Wrls, "wall_recovery");
    assert!(frames > 20);
    assert_eq!(allocs, 0, "{allocs} allocations in {frames} frames");
}

#[test]
fn the_metric_step_does_not_allocate() {
    // Tracking plus the ego lane in metres (covariances from the tracker, lane-geometry's
    // estimate) on every frame of a sequence with loss and re-initialisation.
    let camera = lane_tracker::camera::CameraConfig::preset("robot")
        .expect("a preset")
        .unwrap()
        .model()
        .unwrap();
    let spec = SCENES
        .iter()
        .find(|s| s.name == "wall_recovery")
        .copied()
        .unwrap();
    let cfg = lane_io::config::load_tracker_config(spec.config).unwrap();
    let mut renderer = SceneRenderer::new(spec, 320, 240);
    let mut tracker = LaneTracker::new(&cfg, Estimator::Kif, 320, 240).unwrap();
    let mut frame = GreyFrame::default();
    let (mut allocs, mut with_ego) = (0, 0);
    for i in 0..spec.frames {
        renderer.render(i, &mut frame);
        let (ego, n) = allocations_in(|| {
            let report = tracker.track(&frame).unwrap();
            camera.ego_lane(&tracker, &report)
        });
        allocs += n;
        with_ego += u32::from(ego.is_some());
    }
    assert!(with_ego > 15, "{with_ego}");
    assert_eq!(allocs, 0, "{allocs} allocations");
}

#[test]
fn the_counter_sees_an_allocation() {
    // Guards the guard: an allocation on the counting thread is counted.
    let (v, allocations) = allocations_in(|| Vec::<u8>::with_capacity(17));
    drop(v);
    assert_eq!(allocations, 1);
}

#[test]
fn frames_of_other_widths_tracked_at_the_working_width_do_not_allocate() {
    // The working resolution: the box average (1280×720, s = 4), the area average (1283×722,
    // 512×288: s = 4.009, 1.6) and the interpolation up (256×144, s = 0.8), the mapping of every
    // output back to input pixels and a reset.
    let cfg = TrackerConfig::default_preset().unwrap();
    for (w, h) in [(1280, 720), (1283, 722), (512, 288), (256, 144)] {
        for scene in ["wall_recovery", "noise"] {
            let (allocs, frames) = allocations_at(Estimator::Kif, scene, &cfg, w, h);
            assert!(frames > 20);
            assert_eq!(allocs, 0, "{scene} at {w}×{h}: {allocs} allocations");
        }
        let mut tracker = LaneTracker::new(&cfg, Estimator::Kif, w, h).unwrap();
        let frame = GreyFrame::from_vec(w, h, vec![90; w * h]).unwrap();
        tracker.track(&frame).unwrap();
        let ((), n) = allocations_in(|| tracker.reset());
        assert_eq!(n, 0, "reset at {w}×{h}");
    }
}

#[test]
fn noisy_frames_smoothed_before_tracking_do_not_allocate() {
    // A noisy camera (module `lane_tracker::tracker::denoise`): the frames measured and smoothed
    // into the stage's own buffer, at 320×240 and resampled from 640×480. The noise (a fixed
    // pseudo-random pattern: σ ≈ 9 grey levels at 320×240, twice that at 640×480, where the
    // 2 × 2 average halves it) is added outside the count.
    let cfg = TrackerConfig::default_preset().unwrap();
    let spec = SCENES.iter().find(|s| s.name == "wall_recovery").unwrap();
    for (w, h, divisor) in [(320, 240, 16), (640, 480, 8)] {
        let mut renderer = SceneRenderer::new(*spec, w, h);
        let mut tracker = LaneTracker::new(&cfg, Estimator::Kif, w, h).unwrap();
        let mut frame = GreyFrame::default();
        let mut state = 0x2545_F491_4F6C_DD1Du64;
        let mut allocs = 0;
        for i in 0..spec.frames {
            renderer.render(i, &mut frame);
            for v in frame.data_mut() {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                // Four uniform bytes' deviations (σ 74 each), summed (σ 148), over the divisor.
                let n: i32 = (0..4)
                    .map(|k| i32::from((state >> (8 * k)) as u8) - 128)
                    .sum();
                *v = (i32::from(*v) + n / divisor).clamp(0, 255) as u8;
            }
            let (report, n) = allocations_in(|| tracker.track(&frame));
            report.unwrap();
            assert!(tracker.frame_noise().denoised, "{w}×{h} frame {i}");
            allocs += n;
        }
        assert_eq!(allocs, 0, "{w}×{h}: {allocs} allocations");
    }
}

#[test]
fn brightened_dark_frames_do_not_allocate() {
    // The default on a camera at a fifth of the scene's exposure: every frame brightened before
    // the stages read it (module `lane_tracker::tracker::exposure`), the road's bottom looked
    // for with the gain, re-initialisations included.
    let cfg = TrackerConfig::default_preset().unwrap();
    let spec = SCENES
        .iter()
        .find(|s| s.name == "wall_recovery")
        .copied()
        .unwrap();
    let mut renderer = SceneRenderer::new(spec, 320, 240);
    let mut tracker = LaneTracker::new(&cfg, Estimator::Kif, 320, 240).unwrap();
    let mut frame = GreyFrame::default();
    let mut allocs = 0;
    for i in 0..spec.frames {
        renderer.render(i, &mut frame);
        for v in frame.data_mut() {
            *v /= 5;
        }
        let (report, n) = allocations_in(|| tracker.track(&frame));
        report.unwrap();
        assert!(tracker.frame_exposure().gain > 1.0, "frame {i}");
        allocs += n;
    }
    assert!(spec.frames > 20);
    assert_eq!(allocs, 0, "{allocs} allocations in {} frames", spec.frames);
}
