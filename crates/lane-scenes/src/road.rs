//! A road rendered from 3-D lane geometry through a pinhole camera: ground truth in metres.
//!
//! Where [`super::SceneRenderer`] draws lanes that are exact image parabolas, this renderer
//! draws the ground: a flat road whose centre line is a circular arc of curvature
//! `curvature_per_m`, with two marks of width `mark_width_m` parallel to it at `∓lane_width_m/2`,
//! seen by the [`PinholeCamera`] of a camera file posed `lateral_offset_m` right of the centre
//! line and `heading_rad` right of its tangent ([`ArcRoad`], `lane-geometry`). Every pixel
//! below the horizon is back-projected to the ground through the homography; its distance
//! across the road `n` is evaluated at the pixel's left and right edges, and the mark's
//! coverage of that interval (two sub-rows per pixel) blends the mark grey over the floor grey.
//! Above the horizon: a plain wall. Gaussian sensor noise (seeded ChaCha8).
//!
//! The truth of each frame is the [`EgoGeometry`] the renderer was given, so the tracker's
//! metric output ([`lane_tracker::camera::CameraModel::ego_lane`]) can be scored against it directly.

use lane_geometry::{ArcRoad, EgoGeometry, PinholeCamera};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

use lane_tracker::camera::CameraConfig;
use lane_tracker::{GreyFrame, TrackerError};

/// A rendered road sequence: geometry per frame and appearance.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RoadSpec {
    /// Sequence name.
    pub name: &'static str,
    /// Number of frames.
    pub frames: u64,
    /// Lane width between the mark centres, m.
    pub lane_width_m: f64,
    /// Mark (paint or tape) width, m.
    pub mark_width_m: f64,
    /// Lateral offset: mean and amplitude of a sine of period `period_frames`, m.
    pub offset_m: (f64, f64),
    /// Heading: mean and amplitude of a cosine of period `period_frames`, rad.
    pub heading_rad: (f64, f64),
    /// Curvature at the first and at the last frame (linear in between), 1/m.
    pub curvature_per_m: (f64, f64),
    /// Period of the sway, frames.
    pub period_frames: f64,
    /// Floor grey level.
    pub ground_grey: f64,
    /// Mark grey level.
    pub mark_grey: f64,
    /// Wall (above the horizon) grey level.
    pub wall_grey: f64,
    /// Sensor noise σ, grey levels.
    pub noise_sigma: f64,
    /// Noise seed.
    pub seed: u64,
}

/// The robot-scale sequences (the `robot` camera preset, 320×240): tape lanes 0.4 m apart on a
/// floor, the robot swaying by ±5 cm and ±0.06 rad (straight) or ±4 cm and ±0.05 rad (curve).
pub const ROBOT_ROADS: &[RoadSpec] = &[
    RoadSpec {
        name: "robot_straight",
        frames: 80,
        lane_width_m: 0.4,
        mark_width_m: 0.012,
        offset_m: (0.0, 0.05),
        heading_rad: (0.0, 0.06),
        curvature_per_m: (0.0, 0.0),
        period_frames: 40.0,
        ground_grey: 95.0,
        mark_grey: 200.0,
        wall_grey: 170.0,
        noise_sigma: 4.0,
        seed: 11,
    },
    RoadSpec {
        name: "robot_curve",
        frames: 80,
        lane_width_m: 0.4,
        mark_width_m: 0.012,
        offset_m: (0.01, 0.04),
        heading_rad: (0.0, 0.05),
        curvature_per_m: (-0.1, 0.1),
        period_frames: 40.0,
        ground_grey: 95.0,
        mark_grey: 200.0,
        wall_grey: 170.0,
        noise_sigma: 4.0,
        seed: 12,
    },
];

/// A highway-scale sequence (the `highway` camera preset, 320×240): marks 0.15 m wide, 3.7 m
/// apart, the car weaving by ±0.3 m and ±0.01 rad on a gentle curve.
pub const HIGHWAY_ROADS: &[RoadSpec] = &[RoadSpec {
    name: "highway_curve",
    frames: 80,
    lane_width_m: 3.7,
    mark_width_m: 0.15,
    offset_m: (0.0, 0.3),
    heading_rad: (0.0, 0.01),
    curvature_per_m: (0.0, 0.001),
    period_frames: 80.0,
    ground_grey: 90.0,
    mark_grey: 210.0,
    wall_grey: 180.0,
    noise_sigma: 4.0,
    seed: 21,
}];

/// Renders a [`RoadSpec`] through a camera.
#[derive(Debug)]
pub struct RoadRenderer {
    spec: RoadSpec,
    camera: PinholeCamera,
    width: usize,
    height: usize,
    rng: ChaCha8Rng,
    /// `(s, n)` at the pixel edges of one sub-row (reused).
    edges: Vec<[f64; 2]>,
    /// Grey values of one row (reused).
    row: Vec<f64>,
}

impl RoadRenderer {
    /// A renderer for `spec` seen by the modelled camera of `camera` (frames of its
    /// `image_size_px`).
    ///
    /// # Errors
    /// [`TrackerError::ConfigField`] if the camera file is invalid, gives a homography instead of
    /// intrinsics and mounting, or a side over [`super::MAX_SIDE_PX`].
    pub fn new(spec: RoadSpec, camera: &CameraConfig) -> Result<Self, TrackerError> {
        let model = camera.model()?;
        let Some(cam) = model.camera().copied() else {
            return Err(TrackerError::ConfigField {
                field: "intrinsics",
                value: "missing".to_owned(),
                reason: "rendering needs a modelled camera ([intrinsics] + [mounting])".to_owned(),
            });
        };
        let [width, height] = camera.image_size_px;
        if width > super::MAX_SIDE_PX || height > super::MAX_SIDE_PX {
            return Err(TrackerError::ConfigField {
                field: "image_size_px",
                value: format!("[{width}, {height}]"),
                reason: format!("rendering takes sides up to {} px", super::MAX_SIDE_PX),
            });
        }
        Ok(Self {
            spec,
            camera: cam,
            width,
            height,
            rng: ChaCha8Rng::seed_from_u64(spec.seed),
            edges: vec![[0.0; 2]; width + 1],
            row: vec![0.0; width],
        })
    }

    /// The sequence's spec.
    pub fn spec(&self) -> &RoadSpec {
        &self.spec
    }

    /// The true geometry of `frame`.
    pub fn truth(&self, frame: u64) -> EgoGeometry {
        let s = &self.spec;
        let phase = 2.0 * std::f64::consts::PI * frame as f64 / s.period_frames;
        let t = frame as f64 / (s.frames.max(2) - 1) as f64;
        EgoGeometry {
            lateral_offset_m: s.offset_m.0 + s.offset_m.1 * phase.sin(),
            heading_rad: s.heading_rad.0 + s.heading_rad.1 * phase.cos(),
            curvature_per_m: s.curvature_per_m.0 + t * (s.curvature_per_m.1 - s.curvature_per_m.0),
            lane_width_m: s.lane_width_m,
        }
    }

    /// Render `frame` into `out` (reshaped to the camera's frame size).
    pub fn render(&mut self, frame: u64, out: &mut GreyFrame) {
        let (w, h) = (self.width, self.height);
        // Both sides are at most MAX_SIDE_PX (checked in `new`): the reshape cannot fail.
        let fits = out.reshape(w, h);
        debug_assert!(fits.is_ok(), "{w}×{h} within MAX_SIDE_PX");
        let road = ArcRoad {
            geometry: self.truth(frame),
        };
        let s = self.spec;
        let half_mark = 0.5 * s.mark_width_m;
        let marks = [-0.5 * s.lane_width_m, 0.5 * s.lane_width_m];
        let Ok(hom) = self.camera.homography() else {
            out.data_mut().fill(s.wall_grey as u8);
            return;
        };
        for y in 0..h {
            // Two sub-rows; a pixel's value is the mean of theirs.
            for (sub, dy) in [-0.25, 0.25].into_iter().enumerate() {
                let v = y as f64 + dy;
                let mut on_ground = true;
                for (i, e) in self.edges.iter_mut().enumerate() {
                    match hom.image_to_ground([i as f64 - 0.5, v]) {
                        Ok(g) => *e = road.along_across(g),
                        Err(_) => {
                            on_ground = false;
                            break;
                        }
                    }
                }
                for (x, a) in self.row.iter_mut().enumerate() {
                    let value = if on_ground {
                        let (n0, n1) = (self.edges[x][1], self.edges[x + 1][1]);
                        let (lo, hi) = (n0.min(n1), n0.max(n1));
                        let span = (hi - lo).max(1e-12);
                        let mut c = 0.0;
                        for m in marks {
                            let overlap = hi.min(m + half_mark) - lo.max(m - half_mark);
                            c += (overlap.max(0.0) / span).min(1.0);
                        }
                        let c = c.min(1.0);
                        s.ground_grey * (1.0 - c) + s.mark_grey * c
                    } else {
                        s.wall_grey
                    };
                    *a = if sub == 0 { value } else { 0.5 * (*a + value) };
                }
            }
            for (px, a) in out.data_mut()[y * w..(y + 1) * w].iter_mut().zip(&self.row) {
                *px = a.round().clamp(0.0, 255.0) as u8;
            }
        }
        if s.noise_sigma > 0.0
            && let Ok(normal) = Normal::new(0.0, s.noise_sigma)
        {
            for px in out.data_mut().iter_mut() {
                let n: f64 = normal.sample(&mut self.rng);
                *px = (f64::from(*px) + n).round().clamp(0.0, 255.0) as u8;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_marks_are_drawn_where_the_camera_sees_the_true_road() {
        // Noise-free: in each row the grey-weighted centre of each mark must sit on the
        // projection of the true mark centre line (found by bisection along the road).
        let spec = RoadSpec {
            noise_sigma: 0.0,
            curvature_per_m: (0.08, 0.08),
            ..ROBOT_ROADS[0]
        };
        let cam = lane_io::config::load_camera_config("robot").unwrap();
        let mut r = RoadRenderer::new(spec, &cam).unwrap();
        let hom = cam.model().unwrap().homography().to_owned();
        let mut frame = GreyFrame::default();
        let (mut sum, mut count) = (0.0, 0.0);
        for f in [0, 13] {
            r.render(f, &mut frame);
            let road = ArcRoad {
                geometry: r.truth(f),
            };
            for n_m in [-0.2, 0.2] {
                for s_m in [0.35, 0.45, 0.6, 0.75, 0.9, 1.05] {
                    let [u, v] = hom.ground_to_image(road.point(s_m, n_m)).unwrap();
                    // The row through the point, and the mark's centre on it.
                    let y = v.round() as usize;
                    let (mut lo, mut hi) = (s_m - 0.2, s_m + 0.2);
                    let row_of = |s: f64| hom.ground_to_image(road.point(s, n_m)).unwrap();
                    for _ in 0..60 {
                        let mid = 0.5 * (lo + hi);
                        if row_of(mid)[1] > y as f64 {
                            lo = mid
                        } else {
                            hi = mid
                        }
                    }
                    let xt = row_of(0.5 * (lo + hi))[0];
                    let (mut sw, mut sx) = (0.0, 0.0);
                    for x in (u as usize).saturating_sub(10)..((u as usize) + 11).min(320) {
                        let excess =
                            (f64::from(frame.data()[y * 320 + x]) - spec.ground_grey).max(0.0);
                        sw += excess;
                        sx += excess * x as f64;
                    }
                    let centre = sx / sw;
                    sum += centre - xt;
                    count += 1.0;
                    assert!(
                        (centre - xt).abs() < 0.15,
                        "frame {f}, mark {n_m}, row {y}: drawn at {centre:.3}, truth {xt:.3}"
                    );
                }
            }
        }
        // No rendering bias: the tracker's sub-pixel mark centres are scored against this truth
        // at the 0.01 px level (tests/metric_roundtrip.rs), so the drawing must not carry one.
        let mean = sum / count;
        assert!(mean.abs() < 0.03, "mean drawn − truth {mean:.4} px");
    }
}
