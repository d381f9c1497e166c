//! Lanes in metres, end to end: a road rendered from known 3-D geometry through the robot camera
//! → tracker (KIF) → ego lane in metres, scored against the truth; and the reported σ checked
//! against the actual errors.
#![cfg(feature = "lane")]
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use nav_app::camera::CameraConfig;
use nav_app::synth::road::{HIGHWAY_ROADS, ROBOT_ROADS, RoadRenderer, RoadSpec};
use nav_app::{Estimator, GreyFrame, LaneTracker, TrackerConfig};

/// The tracker configuration for the robot camera: the indoor preset with the ROI from 45 % of
/// the height (the floor from 0.27 m to 1.2 m ahead).
fn robot_tracker_config() -> TrackerConfig {
    let mut cfg = TrackerConfig::indoor().unwrap();
    cfg.roi.top_row_fraction = 0.45;
    cfg.filter.q_sigma_px = [0.2, 1.0, 1.5];
    cfg
}

struct Run {
    /// (truth, estimate, σ) per frame with an ego lane: offset, heading, curvature, width.
    frames: Vec<[(f64, f64, f64); 4]>,
    total: u64,
}

fn run(spec: &RoadSpec, cfg: &TrackerConfig) -> Run {
    run_with(spec, cfg, "robot")
}

fn run_with(spec: &RoadSpec, cfg: &TrackerConfig, camera: &str) -> Run {
    let cam_cfg = CameraConfig::load(camera).unwrap();
    let camera = cam_cfg.model().unwrap();
    let mut renderer = RoadRenderer::new(*spec, &cam_cfg).unwrap();
    let mut tracker = LaneTracker::new(cfg, Estimator::Kif, 320, 240).unwrap();
    let mut frame = GreyFrame::default();
    let mut frames = Vec::new();
    for i in 0..spec.frames {
        renderer.render(i, &mut frame);
        let report = tracker.track(&frame).unwrap();
        let truth = renderer.truth(i);
        if let Some(e) = camera.ego_lane(&tracker, &report) {
            frames.push([
                (
                    truth.lateral_offset_m,
                    e.lateral_offset_m,
                    e.lateral_offset_m_sigma,
                ),
                (truth.heading_rad, e.heading_rad, e.heading_rad_sigma),
                (
                    truth.curvature_per_m,
                    e.curvature_per_m,
                    e.curvature_per_m_sigma,
                ),
                (truth.lane_width_m, e.lane_width_m, e.lane_width_m_sigma),
            ]);
        }
    }
    Run {
        frames,
        total: spec.frames,
    }
}

/// Frames skipped at the start while the filters converge from their initialisation.
const SETTLE_FRAMES: usize = 10;

fn errors(r: &Run, k: usize) -> Vec<f64> {
    r.frames
        .iter()
        .skip(SETTLE_FRAMES)
        .map(|f| f[k].1 - f[k].0)
        .collect()
}

fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0f64, |a, e| a.max(e.abs()))
}

#[test]
fn straight_robot_road_offset_within_5_cm_and_heading_within_half_a_degree_rms() {
    let spec = ROBOT_ROADS
        .iter()
        .find(|s| s.name == "robot_straight")
        .unwrap();
    let r = run(spec, &robot_tracker_config());
    assert_eq!(
        r.frames.len() as u64,
        r.total,
        "both lanes held on every frame"
    );
    let (off, hdg, width) = (errors(&r, 0), errors(&r, 1), errors(&r, 3));
    eprintln!(
        "robot_straight: max |error| offset {:.4} m, heading {:.3}°, width {:.4} m",
        max_abs(&off),
        max_abs(&hdg).to_degrees(),
        max_abs(&width)
    );
    // Measured: offset ≤ 4.4 mm; heading RMS 0.33°, max 0.70° (a 0.30° bias from the tracker's
    // 0.2–0.35 px edge-pixel bias, see the σ test below, plus noise): within 0.5° in RMS, not on
    // every frame.
    let rms_hdg = (hdg.iter().map(|e| e * e).sum::<f64>() / hdg.len() as f64).sqrt();
    eprintln!("robot_straight: heading RMS {:.3}°", rms_hdg.to_degrees());
    assert!(max_abs(&off) < 0.05, "offset {}", max_abs(&off));
    assert!(
        rms_hdg < 0.5f64.to_radians(),
        "heading RMS {}°",
        rms_hdg.to_degrees()
    );
    assert!(
        max_abs(&hdg) < 1.0f64.to_radians(),
        "heading {}°",
        max_abs(&hdg).to_degrees()
    );
    assert!(max_abs(&width) < 0.02, "width {}", max_abs(&width));
}

#[test]
fn curved_robot_road_offset_within_5_cm_heading_within_the_model_error() {
    // Curvature −0.1 → 0.1 /m: a circular arc is not an image parabola, so the heading carries
    // the model error of lane-geometry's docs (≈ 0.1·|κ|·1 m here) on top of the tracking error.
    let spec = ROBOT_ROADS
        .iter()
        .find(|s| s.name == "robot_curve")
        .unwrap();
    let r = run(spec, &robot_tracker_config());
    assert_eq!(
        r.frames.len() as u64,
        r.total,
        "both lanes held on every frame"
    );
    let (off, hdg, curv) = (errors(&r, 0), errors(&r, 1), errors(&r, 2));
    eprintln!(
        "robot_curve: max |error| offset {:.4} m, heading {:.3}°, curvature {:.4} /m",
        max_abs(&off),
        max_abs(&hdg).to_degrees(),
        max_abs(&curv)
    );
    assert!(max_abs(&off) < 0.05, "offset {}", max_abs(&off));
    assert!(
        max_abs(&hdg) < 1.5f64.to_radians(),
        "heading {}°",
        max_abs(&hdg).to_degrees()
    );
    assert!(max_abs(&curv) < 0.06, "curvature {}", max_abs(&curv));
}

/// 95 % interval of a χ²(n)/n variable (Wilson–Hilferty).
fn chi2_mean_interval(n: usize) -> (f64, f64) {
    let n = n as f64;
    let z = 1.959_964;
    let c = 2.0 / (9.0 * n);
    (
        (1.0 - c - z * c.sqrt()).powi(3),
        (1.0 - c + z * c.sqrt()).powi(3),
    )
}

#[test]
fn reported_sigma_matches_the_scatter_of_the_errors_and_bounds_their_bias() {
    // 150 frames of the straight road swaying slowly. The errors of successive frames are
    // correlated (the filter's memory), so every 5th frame is taken as an independent sample
    // (lag-5 correlation ≈ 0). Measured (see the README): the normalised errors z = e/σ scatter
    // a little LESS than σ says (centred mean square 0.5–0.6: σ is 1.3× the random scatter), but
    // carry a bias of 1.2–1.6 σ, the image of a 0.2–0.35 px bias of the tracker's edge-pixel
    // measurement of the marks, which the KIF's R = σ²·I model does not contain (pixel-level
    // NEES of the lane coefficients 4.7–5.1 for 3 dof on a static straight road; bottom-row
    // scatter 0.24 px against σ 0.31 px). The uncentred mean square is therefore 2–3, not 1:
    // σ describes the random part of the error, not this bias. The test holds the two facts:
    // σ is not over-confident about the scatter (centred mean square below the χ² interval's
    // upper end), and the bias stays under 2 σ. (lane_width_m is not held to it: its centred
    // mean square is 3.3, σ too small by 1.8× — reported, not explained yet.)
    let spec = RoadSpec {
        name: "robot_slow",
        frames: 150,
        period_frames: 150.0,
        ..ROBOT_ROADS[0]
    };
    let r = run(&spec, &robot_tracker_config());
    for (k, name) in [(0, "lateral_offset_m"), (1, "heading_rad")] {
        let z: Vec<f64> = r
            .frames
            .iter()
            .skip(SETTLE_FRAMES)
            .step_by(5)
            .map(|f| (f[k].1 - f[k].0) / f[k].2)
            .collect();
        let n = z.len();
        let mean = z.iter().sum::<f64>() / n as f64;
        let centred = z.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1) as f64;
        let ms = z.iter().map(|v| v * v).sum::<f64>() / n as f64;
        let (lo, hi) = chi2_mean_interval(n - 1);
        eprintln!(
            "{name}: {n} samples, mean z {mean:.2}, centred mean square {centred:.2} in [{lo:.2}, {hi:.2}], mean z² {ms:.2}"
        );
        assert!(
            centred <= hi && centred > 0.25,
            "{name}: centred mean square {centred:.2} vs the 95 % χ² interval [{lo:.2}, {hi:.2}]"
        );
        assert!(mean.abs() < 2.0, "{name}: bias {mean:.2} σ");
    }
}

#[test]
fn highway_road_through_the_highway_camera() {
    let spec = &HIGHWAY_ROADS[0];
    let r = run_with(spec, &TrackerConfig::outdoor().unwrap(), "highway");
    let (off, hdg, curv, width) = (errors(&r, 0), errors(&r, 1), errors(&r, 2), errors(&r, 3));
    eprintln!(
        "highway_curve: {} of {} frames; max |error| offset {:.4} m, heading {:.3}°, curvature {:.5} /m, width {:.4} m",
        r.frames.len(),
        r.total,
        max_abs(&off),
        max_abs(&hdg).to_degrees(),
        max_abs(&curv),
        max_abs(&width)
    );
    assert_eq!(
        r.frames.len() as u64,
        r.total,
        "both lanes held on every frame"
    );
    let rms = |v: &[f64]| (v.iter().map(|e| e * e).sum::<f64>() / v.len() as f64).sqrt();
    eprintln!(
        "highway_curve: RMS offset {:.4} m, heading {:.3}°",
        rms(&off),
        rms(&hdg).to_degrees()
    );
    // Measured: offset max 0.12 m, heading max 1.3°, width max 0.035 m. At 6–13 m a pixel is
    // 2–3.4 cm across the road, and the offset and heading at the car are extrapolated from there.
    assert!(max_abs(&off) < 0.2, "offset {}", max_abs(&off));
    assert!(
        max_abs(&hdg) < 2.0f64.to_radians(),
        "heading {}°",
        max_abs(&hdg).to_degrees()
    );
    assert!(max_abs(&width) < 0.06, "width {}", max_abs(&width));
    assert!(max_abs(&curv) < 0.004, "curvature {}", max_abs(&curv));
}
