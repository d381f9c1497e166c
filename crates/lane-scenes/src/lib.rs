//! # lane-scenes — rendered lane scenes with exact ground truth
//!
//! Deterministic synthetic road and corridor sequences with exact ground truth: the `nav-app`
//! binary's sample input (a [`SceneSource`] when it is given no input), the synthetic regression's
//! sequences (`lane_eval::regress`) and the tests' inputs; [`road`] renders roads from known 3-D
//! geometry for the metric round trips.
//!
//! ## Scene model (image plane, pixels; x column, y row)
//! Rows below the horizon `y_h` are ground. With `d = y − y_h` and the bottom row `y_b`:
//!
//! ```text
//! centre  c(y) = c_x + o·d + κ·(y_b − y)²/100     o: lateral sway (px/row), κ: curvature (px/100 row²)
//! half-width h(y) = h_b · d / (y_b − y_h)          h_b: lane half-width at the bottom row, px
//! left  x_L(y) = c(y) − h(y),   right  x_R(y) = c(y) + h(y)
//! ```
//!
//! Both marks are exact parabolas `x = a1·y² + a2·y + a3` (eq. 1 of the paper), which are the
//! ground truth. A mark is drawn centred on its curve, `m_b·d/(y_b − y_h)` px wide, with
//! horizontal anti-aliasing (pixel coverage). Dashes follow the ground distance
//! `Z = 10·(y_b − y_h)/d` m: a dash where `frac((Z + s)/12) < 1/3`, `s` advancing with the
//! vehicle. Extras: shadow bands across the road, a car occluding the right mark, frames facing a
//! wall (no lanes), Gaussian sensor noise (seeded ChaCha8), low contrast, and an indoor corridor
//! whose "lanes" are the floor/wall boundaries.

pub mod road;

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use serde::{Deserialize, Serialize};

use lane_tracker::GreyFrame;

/// Ground truth of one lane in one frame.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TruthLane {
    /// `true` when the mark is in view on this frame.
    pub visible: bool,
    /// `[a1, a2, a3]` of `x = a1·y² + a2·y + a3` (pixels).
    pub coeffs: [f64; 3],
}

impl TruthLane {
    /// Column of the true mark centre at `row_px`.
    pub fn col_at_row(&self, row_px: f64) -> f64 {
        hough_init::Parabola::from_coeffs(self.coeffs).col_at_row(row_px)
    }
}

/// Ground truth of one frame: left then right lane.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TruthFrame {
    /// Frame index.
    pub frame: u64,
    /// Left and right lanes.
    pub lanes: [TruthLane; 2],
}

/// Ground truth of a whole sequence (the JSON file beside each `.y4m` fixture).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SequenceTruth {
    /// Sequence name (file stem).
    pub name: String,
    /// What it exercises.
    pub description: String,
    /// Configuration preset to track it with (`outdoor` or `indoor`).
    pub config: String,
    /// Frame width, px.
    pub width: usize,
    /// Frame height, px.
    pub height: usize,
    /// Rows at which the lateral error and the accuracy are scored, px.
    pub eval_rows: Vec<f64>,
    /// Per-frame truth.
    pub frames: Vec<TruthFrame>,
}

/// Which kind of scene, and its knobs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SceneSpec {
    /// Sequence name.
    pub name: &'static str,
    /// What it exercises.
    pub description: &'static str,
    /// Preset to track with.
    pub config: &'static str,
    /// Number of frames.
    pub frames: u64,
    /// Corridor instead of road.
    pub corridor: bool,
    /// Curvature at the start and at the end of the sequence, px per 100 rows².
    pub curvature: (f64, f64),
    /// Left / right marks dashed.
    pub dashed: (bool, bool),
    /// Grey levels of the ground and of the marks.
    pub ground_grey: f64,
    /// Mark grey level.
    pub mark_grey: f64,
    /// Sensor noise σ, grey levels (0 = none).
    pub noise_sigma: f64,
    /// Shadow bands across the road.
    pub shadows: bool,
    /// A car occluding part of the right mark.
    pub car: bool,
    /// Frames `[start, end)` facing a wall (no lanes).
    pub wall: Option<(u64, u64)>,
    /// Noise seed.
    pub seed: u64,
}

impl SceneSpec {
    const BASE: SceneSpec = SceneSpec {
        name: "",
        description: "",
        config: "outdoor",
        frames: 24,
        corridor: false,
        curvature: (0.0, 0.0),
        dashed: (false, false),
        ground_grey: 90.0,
        mark_grey: 210.0,
        noise_sigma: 2.0,
        shadows: false,
        car: false,
        wall: None,
        seed: 1,
    };
}

/// The fixture set `cargo xtask fixtures` renders (320×240, mono).
pub const SCENES: &[SceneSpec] = &[
    SceneSpec {
        name: "straight_solid",
        description: "straight road, solid marks, lateral sway",
        ..SceneSpec::BASE
    },
    SceneSpec {
        name: "curve_left_dashed",
        description: "road curving left, dashed left mark, solid right",
        curvature: (0.0, -0.6),
        dashed: (true, false),
        seed: 2,
        ..SceneSpec::BASE
    },
    SceneSpec {
        name: "curve_right_dashed",
        description: "road curving right, both marks dashed",
        curvature: (0.2, 0.7),
        dashed: (true, true),
        seed: 3,
        ..SceneSpec::BASE
    },
    SceneSpec {
        name: "shadows",
        description: "tree shadows across the road, moving with the vehicle",
        shadows: true,
        dashed: (true, false),
        curvature: (0.4, 0.4),
        seed: 4,
        ..SceneSpec::BASE
    },
    SceneSpec {
        name: "low_contrast",
        description: "worn marks: 35 grey levels above the asphalt",
        ground_grey: 100.0,
        mark_grey: 135.0,
        curvature: (-0.5, 0.5),
        seed: 5,
        ..SceneSpec::BASE
    },
    SceneSpec {
        name: "noise",
        description: "sensor noise σ = 8 grey levels",
        noise_sigma: 8.0,
        curvature: (0.6, -0.6),
        dashed: (true, false),
        seed: 6,
        ..SceneSpec::BASE
    },
    SceneSpec {
        name: "occlusion",
        description: "a car ahead occluding part of the right mark",
        car: true,
        seed: 7,
        ..SceneSpec::BASE
    },
    SceneSpec {
        name: "wall_recovery",
        description: "facing a wall (no lanes) for frames 8..14, then the road again",
        frames: 28,
        wall: Some((8, 14)),
        seed: 8,
        ..SceneSpec::BASE
    },
    SceneSpec {
        name: "corridor",
        description: "indoor corridor: floor/wall boundary lines, low contrast, even light",
        config: "indoor",
        corridor: true,
        ground_grey: 120.0,
        mark_grey: 165.0,
        noise_sigma: 2.0,
        seed: 9,
        ..SceneSpec::BASE
    },
];

/// Fixed geometry of the synthetic camera.
const HORIZON_FRAC: f64 = 0.45;
const HALF_WIDTH_BOTTOM_FRAC: f64 = 0.36;
const MARK_WIDTH_BOTTOM_FRAC: f64 = 0.022;

/// A renderer for one scene at one size.
#[derive(Debug)]
pub struct SceneRenderer {
    spec: SceneSpec,
    width: usize,
    height: usize,
    rng: ChaCha8Rng,
}

/// Largest side of a rendered frame, px: renderers clamp to it, so a frame of their size always
/// fits (its area cannot overflow).
pub const MAX_SIDE_PX: usize = 1 << 14;

impl SceneRenderer {
    /// Renderer for `spec` at `width × height`, each clamped to 32…[`MAX_SIDE_PX`].
    pub fn new(spec: SceneSpec, width: usize, height: usize) -> Self {
        SceneRenderer {
            spec,
            width: width.clamp(32, MAX_SIDE_PX),
            height: height.clamp(32, MAX_SIDE_PX),
            rng: ChaCha8Rng::seed_from_u64(spec.seed),
        }
    }

    fn t_frac(&self, frame: u64) -> f64 {
        frame as f64 / (self.spec.frames.max(2) - 1) as f64
    }

    fn geometry(&self, frame: u64) -> (f64, f64, f64, f64) {
        let (w, h) = (self.width as f64, self.height as f64);
        let t = self.t_frac(frame);
        let kappa = (self.spec.curvature.0 + t * (self.spec.curvature.1 - self.spec.curvature.0))
            * (240.0 / h).powi(2)
            * (w / 320.0);
        let sway = 0.12 * (2.0 * std::f64::consts::PI * frame as f64 / 30.0).sin() * (w / 320.0)
            / (h / 240.0);
        let cx = 0.5 * w + if self.spec.corridor { 0.0 } else { 0.02 * w };
        (cx, sway, kappa, HORIZON_FRAC * h)
    }

    /// The true lanes of `frame`.
    pub fn truth(&self, frame: u64) -> TruthFrame {
        let (cx, o, kappa, yh) = self.geometry(frame);
        let yb = (self.height - 1) as f64;
        let g = HALF_WIDTH_BOTTOM_FRAC * self.width as f64 / (yb - yh);
        let k = kappa / 100.0;
        // c(y) = k·y² + (o − 2k·y_b)·y + (c_x − o·y_h + k·y_b²); h(y) = g·y − g·y_h.
        let c = [k, o - 2.0 * k * yb, cx - o * yh + k * yb * yb];
        let hw = [0.0, g, -g * yh];
        let visible = self.spec.wall.is_none_or(|(a, b)| frame < a || frame >= b);
        let lane = |s: f64| TruthLane {
            visible,
            coeffs: [c[0] + s * hw[0], c[1] + s * hw[1], c[2] + s * hw[2]],
        };
        TruthFrame {
            frame,
            lanes: [lane(-1.0), lane(1.0)],
        }
    }

    /// Rows the tracker is scored at: ten rows evenly over the lower 40 % of the image.
    pub fn eval_rows(&self) -> Vec<f64> {
        let h = self.height as f64;
        (0..10)
            .map(|i| (0.60 * h + i as f64 * 0.38 * h / 9.0).round())
            .collect()
    }

    /// Render `frame` into `out` (reshaped to the renderer's size).
    pub fn render(&mut self, frame: u64, out: &mut GreyFrame) {
        let (w, h) = (self.width, self.height);
        // Both sides are at most MAX_SIDE_PX (clamped in `new`): the reshape cannot fail.
        let fits = out.reshape(w, h);
        debug_assert!(fits.is_ok(), "{w}×{h} within MAX_SIDE_PX");
        let spec = self.spec;
        let truth = self.truth(frame);
        let (_, _, _, yh) = self.geometry(frame);
        let yb = (h - 1) as f64;
        let on_wall = !truth.lanes[0].visible;
        let speed_m = 0.8 * frame as f64;
        for y in 0..h {
            let yf = y as f64;
            let row = &mut out.data_mut()[y * w..(y + 1) * w];
            if on_wall {
                // A painted wall: smooth vertical shading, a door frame of vertical edges.
                for (x, px) in row.iter_mut().enumerate() {
                    let door = (x as f64 - 0.3 * w as f64).abs() < 2.0
                        || (x as f64 - 0.55 * w as f64).abs() < 2.0;
                    *px = if door {
                        95
                    } else {
                        (150.0 + 10.0 * yf / h as f64) as u8
                    };
                }
                continue;
            }
            if yf <= yh + 0.5 {
                let sky = if spec.corridor {
                    200.0
                } else {
                    185.0 - 30.0 * yf / yh.max(1.0)
                };
                row.fill(sky as u8);
                continue;
            }
            let d = yf - yh;
            let xl = truth.lanes[0].col_at_row(yf);
            let xr = truth.lanes[1].col_at_row(yf);
            let mark_w = (MARK_WIDTH_BOTTOM_FRAC * w as f64 * d / (yb - yh)).max(0.8);
            let z_m = 10.0 * (yb - yh) / d;
            let dash_on = ((z_m + speed_m) / 12.0).fract() < 1.0 / 3.0;
            for (x, px) in row.iter_mut().enumerate() {
                let xf = x as f64;
                let mut v = if spec.corridor {
                    if xf < xl || xf > xr {
                        205.0 - 0.1 * d
                    } else {
                        spec.ground_grey
                    }
                } else if xf < xl - 0.25 * (xr - xl) || xf > xr + 0.25 * (xr - xl) {
                    70.0
                } else {
                    spec.ground_grey
                };
                if !spec.corridor {
                    for (i, &xm) in [xl, xr].iter().enumerate() {
                        let dashed = if i == 0 { spec.dashed.0 } else { spec.dashed.1 };
                        if dashed && !dash_on {
                            continue;
                        }
                        let cov =
                            (xf + 0.5).min(xm + 0.5 * mark_w) - (xf - 0.5).max(xm - 0.5 * mark_w);
                        let cov = cov.clamp(0.0, 1.0);
                        v = v * (1.0 - cov) + spec.mark_grey * cov;
                    }
                } else {
                    // Anti-alias the floor/wall boundary over one pixel.
                    for &xm in &[xl, xr] {
                        let dist = xf - xm;
                        if dist.abs() < 0.5 {
                            let wall = 205.0 - 0.1 * d;
                            let floor_frac = if xm == xl { dist + 0.5 } else { 0.5 - dist };
                            v = wall * (1.0 - floor_frac) + spec.ground_grey * floor_frac;
                        }
                    }
                }
                if spec.shadows {
                    // Two soft-edged shadow bands, nearly horizontal, moving down the image.
                    for k in 0..2 {
                        let y0 = yh + ((frame as f64 * 3.0 + 40.0 * k as f64) % (yb - yh));
                        let yy = yf
                            - (y0 + 0.08 * (xf - 0.5 * w as f64) * if k == 0 { 1.0 } else { -1.0 });
                        if (0.0..14.0).contains(&yy) {
                            v *= 0.5;
                        }
                    }
                }
                if spec.car {
                    // A dark car box over the right mark's lower-middle rows.
                    let car_y = (0.70 * h as f64, 0.82 * h as f64);
                    let x_c = truth.lanes[1].col_at_row(car_y.1) - 0.02 * w as f64;
                    let half = 0.12 * w as f64;
                    if yf >= car_y.0 && yf < car_y.1 && (xf - x_c).abs() < half {
                        v = if yf < car_y.0 + 0.35 * (car_y.1 - car_y.0) {
                            60.0
                        } else {
                            35.0
                        };
                    }
                }
                *px = v.round().clamp(0.0, 255.0) as u8;
            }
        }
        add_noise(out, spec.noise_sigma, &mut self.rng);
    }

    /// The sequence's ground truth for all its frames.
    pub fn sequence_truth(&self) -> SequenceTruth {
        SequenceTruth {
            name: self.spec.name.to_owned(),
            description: self.spec.description.to_owned(),
            config: self.spec.config.to_owned(),
            width: self.width,
            height: self.height,
            eval_rows: self.eval_rows(),
            frames: (0..self.spec.frames).map(|f| self.truth(f)).collect(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_ground_truth_is_where_the_marks_are_drawn() {
        // Noise-free solid scene: in each row the intensity-weighted centre of the mark's bright
        // pixels must sit on the true curve (the truth is what is rendered, not a guess).
        let spec = SceneSpec {
            noise_sigma: 0.0,
            ..SCENES[0]
        };
        let mut r = SceneRenderer::new(spec, 320, 240);
        let mut frame = GreyFrame::default();
        for f in [0, 7, 15] {
            r.render(f, &mut frame);
            let truth = r.truth(f);
            for y in [150usize, 190, 235] {
                for lane in truth.lanes {
                    let xt = lane.col_at_row(y as f64);
                    let (mut sw, mut sx) = (0.0, 0.0);
                    for x in (xt as usize).saturating_sub(8)..((xt as usize) + 9).min(320) {
                        let excess =
                            (f64::from(frame.data()[y * 320 + x]) - spec.ground_grey).max(0.0);
                        sw += excess;
                        sx += excess * x as f64;
                    }
                    let centre = sx / sw;
                    assert!(
                        (centre - xt).abs() < 0.15,
                        "frame {f} row {y}: drawn {centre}, truth {xt}"
                    );
                }
            }
        }
    }

    #[test]
    fn rendering_is_deterministic_and_the_wall_hides_the_lanes() {
        let spec = SCENES.iter().find(|s| s.wall.is_some()).copied().unwrap();
        let (a, b) = spec.wall.unwrap();
        let (mut r1, mut r2) = (
            SceneRenderer::new(spec, 320, 240),
            SceneRenderer::new(spec, 320, 240),
        );
        let (mut f1, mut f2) = (GreyFrame::default(), GreyFrame::default());
        for f in 0..spec.frames {
            r1.render(f, &mut f1);
            r2.render(f, &mut f2);
            assert_eq!(f1, f2);
            let visible = r1.truth(f).lanes.iter().all(|l| l.visible);
            assert_eq!(visible, !(a..b).contains(&f));
        }
    }
}

/// A rendered scene as a frame source (`lane_io::FrameSource`): frames `0..spec.frames` of
/// [`SceneRenderer`] at [`SceneSource::FRAME_RATE_HZ`], deterministic. The `nav-app` binary
/// tracks one when it is given no input, so its default run needs no third-party data.
#[derive(Debug)]
pub struct SceneSource {
    renderer: SceneRenderer,
    next: u64,
}

impl SceneSource {
    /// Frame rate the time stamps assume, frames/s.
    pub const FRAME_RATE_HZ: f64 = 25.0;

    /// The ground truth of the whole sequence (what `cargo xtask fixtures` writes beside it).
    pub fn truth(&self) -> SequenceTruth {
        self.renderer.sequence_truth()
    }

    /// The scene `spec` rendered at `width × height`.
    pub fn new(spec: SceneSpec, width: usize, height: usize) -> Self {
        SceneSource {
            renderer: SceneRenderer::new(spec, width, height),
            next: 0,
        }
    }
}

impl lane_io::FrameSource for SceneSource {
    fn next_frame(
        &mut self,
        frame: &mut GreyFrame,
    ) -> Result<Option<lane_io::FrameMeta>, lane_io::LaneIoError> {
        if self.next >= self.renderer.spec.frames {
            return Ok(None);
        }
        let index = self.next;
        self.renderer.render(index, frame);
        self.next += 1;
        Ok(Some(lane_io::FrameMeta {
            index,
            t_s: index as f64 / Self::FRAME_RATE_HZ,
        }))
    }

    fn describe(&self) -> String {
        format!(
            "rendered scene `{}` ({} frames, {:.0} frames/s)",
            self.renderer.spec.name,
            self.renderer.spec.frames,
            Self::FRAME_RATE_HZ
        )
    }

    fn frame_rate_hz(&self) -> Option<f64> {
        Some(Self::FRAME_RATE_HZ)
    }
}

/// The scene `spec` rendered at `width × height` as a grey (`C mono`) YUV4MPEG2 stream at
/// [`SceneSource::FRAME_RATE_HZ`], into `out` (a file, a `Vec<u8>`): the bytes `cargo xtask
/// fixtures` writes, so tests render their inputs instead of reading committed copies.
///
/// # Errors
/// [`WriteError`] when `out` refuses a write (`name` in the message).
pub fn write_scene_y4m<W: std::io::Write>(
    spec: SceneSpec,
    width: usize,
    height: usize,
    out: W,
    name: &str,
) -> Result<(), WriteError> {
    let io = |source| WriteError {
        name: name.to_owned(),
        source,
    };
    let mut renderer = SceneRenderer::new(spec, width, height);
    let mut frame = GreyFrame::default();
    let mut writer = lane_io::y4m::Y4mWriter::new(
        out,
        renderer.width,
        renderer.height,
        SceneSource::FRAME_RATE_HZ,
        lane_io::y4m::Y4mChroma::Mono,
    )
    .map_err(io)?;
    for i in 0..spec.frames {
        renderer.render(i, &mut frame);
        writer.write_grey(frame.data()).map_err(io)?;
    }
    writer.finish().map_err(io)?;
    Ok(())
}

/// Every scene of [`SCENES`] rendered at `width × height` into `out` (created if needed) as
/// `<name>.y4m` ([`write_scene_y4m`]) and `<name>.json`, its [`SequenceTruth`] (pretty JSON and a
/// newline: the golden copies under `fixtures/synthetic/` that `cargo xtask regress` checks the
/// renderer against). Returns each scene with the size of its stream, bytes.
///
/// # Errors
/// [`WriteError`] naming the file that could not be written.
pub fn write_fixtures(
    out: &std::path::Path,
    width: usize,
    height: usize,
) -> Result<Vec<(SceneSpec, u64)>, WriteError> {
    let fail = |path: &std::path::Path| {
        let name = path.display().to_string();
        move |source| WriteError { name, source }
    };
    std::fs::create_dir_all(out).map_err(fail(out))?;
    let mut written = Vec::with_capacity(SCENES.len());
    for spec in SCENES {
        let y4m = out.join(format!("{}.y4m", spec.name));
        let file = std::fs::File::create(&y4m).map_err(fail(&y4m))?;
        let name = y4m.display().to_string();
        write_scene_y4m(*spec, width, height, std::io::BufWriter::new(file), &name)?;
        let json = out.join(format!("{}.json", spec.name));
        let truth = SceneSource::new(*spec, width, height).truth();
        let text = serde_json::to_string_pretty(&truth).map_err(std::io::Error::from);
        std::fs::write(&json, text.map_err(fail(&json))? + "\n").map_err(fail(&json))?;
        let size = std::fs::metadata(&y4m).map_err(fail(&y4m))?.len();
        written.push((*spec, size));
    }
    Ok(written)
}

/// A rendered scene's YUV4MPEG2 stream could not be written ([`write_scene_y4m`]).
#[derive(Debug, thiserror::Error)]
#[error("cannot write the rendered scene to {name}")]
pub struct WriteError {
    /// Where it was written.
    pub name: String,
    /// What the writer said.
    #[source]
    pub source: std::io::Error,
}

/// `frame` plus independent Gaussian sensor noise of `sigma_grey` grey levels, rounded and
/// clamped to 0..=255, drawn from ChaCha8 seeded with `seed` (what the `noise` scene adds to its
/// frames; nothing for `sigma_grey ≤ 0`).
pub fn add_sensor_noise(frame: &mut GreyFrame, sigma_grey: f64, seed: u64) {
    add_noise(frame, sigma_grey, &mut ChaCha8Rng::seed_from_u64(seed));
}

fn add_noise(frame: &mut GreyFrame, sigma_grey: f64, rng: &mut ChaCha8Rng) {
    if sigma_grey > 0.0
        && let Ok(normal) = Normal::new(0.0, sigma_grey)
    {
        for px in frame.data_mut().iter_mut() {
            let n: f64 = normal.sample(rng);
            *px = (f64::from(*px) + n).round().clamp(0.0, 255.0) as u8;
        }
    }
}
