//! # Working resolution (an addition beyond the paper; `frame.working_width_px`)
//!
//! The paper's frames are the BT848's 320×240, and every pixel-valued setting of the default and
//! the presets (mark widths, windows, gates, noise) is tuned there. A camera or a recording of
//! another size would meet those settings at another scale: on the labelled stills enlarged to
//! 640×360 and 1280×720 (`cargo xtask resample-lanes`), the default's pixel settings used at the
//! input's size reach 66.0 % and 43.9 % held out (TuSimple) against 78.8 % at 320×180; scaled
//! with the width (`TrackerConfig::scale_pixels`) they still lose ground at 4× — a 3×3 Sobel on
//! a frame four times as sharp sees edges four times as soft — and the work grows with the
//! area. The tracker therefore works on a frame exactly the working width `W` (320 px by
//! default) wide, which reaches 79.0 % and 79.5 % there:
//!
//! ```text
//! s = input width / W   (input pixels per working pixel, any real > 0),
//! working frame: ⌊w/s⌋ × ⌊h/s⌋,   working pixel c' ↔ input interval [s·c', s·(c' + 1)),
//! ```
//!
//! the area average of that interval in both axes (down), or linear interpolation at its
//! centre (up, at most 2×) — module `resample`; a whole `s` is the box average over `s × s`
//! blocks, computed as such. Rounding `s` to a whole number instead (as before) tracked a
//! 512-px frame at 256 px, where the pixel settings are 25 % too wide: 11 points lost on
//! TuSimple stills given at 512 × 288 against the same stills resized to 320 first.
//! Working pixel `c'` is centred on input `x = s·x' + o` with `o = (s − 1)/2`, and rows alike.
//! A working-frame parabola `x' = b1·y'² + b2·y' + b3` is then, substituting `y' = (y − o)/s`,
//!
//! ```text
//! x = (b1/s)·(y − o)² + b2·(y − o) + s·b3 + o
//!   ⇒ a1 = b1/s,   a2 = b2 − 2·o·b1/s,   a3 = b1·o²/s − b2·o + s·b3 + o,
//! ```
//!
//! the affine map `a = T·b + t` with
//!
//! ```text
//!     ⎡  1/s     0   0 ⎤        ⎡ 0 ⎤
//! T = ⎢ −2o/s    1   0 ⎥,   t = ⎢ 0 ⎥,   Cov(a) = T·Cov(b)·Tᵀ.
//!     ⎣  o²/s   −o   s ⎦        ⎣ o ⎦
//! ```
//!
//! Every report, covariance, row profile, window, point and candidate's coefficients leave the
//! tracker in input pixels by these maps (counts — a report's points, a candidate's support —
//! stay counts of the working frame); with `s = 1` (a frame the working width wide, or
//! `working_width_px = 0`) nothing is resampled or mapped, and the tracker is the one it was.
//! `s` is at most a third of either side (a working frame keeps 3 × 3 px) and at least 1/2.
//!
//! Decisions and figures: `docs/lanes/history/working-resolution.md`.

use nalgebra::Matrix3;
use vision_gradient::{ColSpan, GreyImage};

use super::lane::Lanes;
use super::report::{InitCandidate, LaneReport, MAX_CANDIDATE_LINES};
use super::resample::{AxisTaps, resample_rows};
use super::setup::Rows;

/// The scale between the input frame and the working frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct WorkingScale {
    /// Input pixels per working pixel along each axis, `s > 0` (module docs).
    s: f64,
}

/// The largest upsampling: a frame is tracked at most twice its own size.
const MAX_UPSAMPLING: f64 = 2.0;

impl WorkingScale {
    /// The scale for `input_width_px × input_height_px` frames at working width
    /// `working_width_px` (0: none, `s = 1`): `s = input width / working width`, so the working
    /// frame is the working width wide whatever the input's width, held to a working frame of
    /// at least 3 × 3 px (`s ≤ min(w, h)/3`: a 1280 × 8 strip is tracked at 480 × 3), at most
    /// twice the input's size (`s ≥ 1/2`: a 100-px frame is tracked at 200 px) and at most
    /// `MAX_IMAGE_SIDE_PX` a side.
    pub(crate) fn for_input(
        input_width_px: usize,
        input_height_px: usize,
        working_width_px: usize,
    ) -> Self {
        if working_width_px == 0 || input_width_px == working_width_px {
            return WorkingScale { s: 1.0 };
        }
        let (w, h) = (input_width_px as f64, input_height_px as f64);
        let max_side = hough_init::MAX_IMAGE_SIDE_PX as f64;
        let s = (w / working_width_px as f64)
            .min(w.min(h) / 3.0)
            .max(1.0 / MAX_UPSAMPLING)
            .max(w.max(h) / max_side);
        // A ratio within rounding of a whole number is that number (the box average's path).
        let whole = s.round();
        WorkingScale {
            s: if (s - whole).abs() < 1e-9 && whole >= 1.0 {
                whole
            } else {
                s
            },
        }
    }

    /// Input pixels per working pixel, `s > 0`.
    pub(crate) fn factor(self) -> f64 {
        self.s
    }

    /// `s` when it is a whole number ≥ 2: the working frame is then the box average over
    /// `s × s` blocks.
    pub(crate) fn whole_factor(self) -> Option<usize> {
        (self.s >= 2.0 && self.s.fract() == 0.0).then_some(self.s as usize)
    }

    /// `true` when the input is resampled (`s ≠ 1`).
    pub(crate) fn resamples(self) -> bool {
        self.s != 1.0
    }

    /// `o = (s − 1)/2`, px: the input coordinate of working pixel 0's centre.
    fn offset_px(self) -> f64 {
        (self.s - 1.0) / 2.0
    }

    /// A working-frame row or column `v'` in input pixels: `s·v' + o`.
    pub(crate) fn to_input_px(self, working_px: f64) -> f64 {
        self.s * working_px + self.offset_px()
    }

    /// The working-frame size of a `width × height` input, px: `⌊w/s⌋ × ⌊h/s⌋`.
    pub(crate) fn working_size(self, width: usize, height: usize) -> (usize, usize) {
        let side = |v: usize| (v as f64 / self.s + 1e-9).floor() as usize;
        (side(width), side(height))
    }

    /// Working rows `[first, end)` as the input rows they stand for, `[⌊s·first⌉, ⌊s·end⌉)`,
    /// the end at most `input_height_px`.
    pub(crate) fn rows_to_input(self, rows: Rows, input_height_px: usize) -> Rows {
        let edge = |r: usize| (self.s * r as f64).round() as usize;
        (
            edge(rows.0).min(input_height_px),
            edge(rows.1).min(input_height_px),
        )
    }

    /// The working row that input row `row_px` falls in, `⌊y/s⌋`.
    fn working_row(self, row_px: usize) -> usize {
        (row_px as f64 / self.s + 1e-9).floor() as usize
    }

    /// `T` of the module docs.
    fn coeff_map(self) -> Matrix3<f64> {
        let f = self.s;
        let o = self.offset_px();
        Matrix3::new(1.0 / f, 0.0, 0.0, -2.0 * o / f, 1.0, 0.0, o * o / f, -o, f)
    }

    /// Working-frame coefficients `[b1, b2, b3]` as input-pixel `[a1, a2, a3]`: `T·b + t`.
    pub(crate) fn coeffs_to_input(self, b: [f64; 3]) -> [f64; 3] {
        let a = self.coeff_map() * nalgebra::Vector3::from(b);
        [a[0], a[1], a[2] + self.offset_px()]
    }

    /// A lane's report with its coefficients and rows in input pixels.
    pub(crate) fn report_to_input(self, mut report: LaneReport) -> LaneReport {
        report.coeffs = report.coeffs.map(|b| self.coeffs_to_input(b));
        report.rows = report.rows.map(|r| self.to_input_px(r));
        report
    }

    /// A covariance of working-frame coefficients as one of input-pixel coefficients:
    /// `T·P·Tᵀ`.
    pub(crate) fn cov_to_input(self, p: &Matrix3<f64>) -> Matrix3<f64> {
        let t = self.coeff_map();
        t * p * t.transpose()
    }

    /// A working-frame window span as the input columns it covers, `[⌊s·start⌋, ⌈s·end⌉)`.
    pub(crate) fn span_to_input(self, s: ColSpan) -> ColSpan {
        let wide = |c: f64| {
            // `end ≤ working width`, so `s·end ≤ input width ≤ u16::MAX` (`MAX_SIDE_PX`).
            u16::try_from(c.max(0.0) as u64).unwrap_or(u16::MAX)
        };
        ColSpan {
            col_start_px: wide((self.s * f64::from(s.col_start_px)).floor()),
            col_end_px: wide((self.s * f64::from(s.col_end_px) - 1e-9).ceil()),
        }
    }
}

/// How the working frame is made of the input (module docs, and module `resample`).
#[derive(Debug)]
enum Resampling {
    /// `s = 1`: the input is the working frame.
    None,
    /// A whole factor `f ≥ 2`: the box average over `f × f` blocks, with its column sums
    /// (`f · working width` entries).
    Box { factor: usize, sums: Vec<u32> },
    /// Any other `s`: the area average down, linear interpolation up (module `resample`), with
    /// the taps of both axes and a row of input-width sums.
    Taps {
        cols: AxisTaps,
        rows: AxisTaps,
        acc: Vec<f32>,
    },
}

impl Resampling {
    fn new(scale: WorkingScale, input_size: (usize, usize), size: (usize, usize)) -> Self {
        if !scale.resamples() {
            return Resampling::None;
        }
        if let Some(factor) = scale.whole_factor() {
            return Resampling::Box {
                factor,
                sums: vec![0; input_size.0],
            };
        }
        Resampling::Taps {
            cols: AxisTaps::new(input_size.0, size.0, scale.factor()),
            rows: AxisTaps::new(input_size.1, size.1, scale.factor()),
            acc: vec![0.0; input_size.0],
        }
    }

    /// Resample working rows `rows = [first, end)` of `src` into `dst` (`working_width` bytes
    /// a row); rows outside are left as they are.
    fn rows(&mut self, src: &GreyImage<'_>, dst: &mut [u8], working_width: usize, rows: Rows) {
        match self {
            Resampling::None => {}
            Resampling::Box { factor, sums } => {
                downscale_box(*factor, src, dst, working_width, rows, sums)
            }
            Resampling::Taps { cols, rows: r, acc } => resample_rows(src, dst, cols, r, rows, acc),
        }
    }
}

/// Box-average rows `rows = [first, end)` of the working frame from `src` into `dst`
/// (`working_width` bytes a row, row `r` at `r · working_width`), summing the `f` input rows
/// of each working row column by column in `sums` (at least `f · working_width` entries;
/// `u32`), then each run of `f` sums. Rows outside `rows` are left as they are.
///
/// Needs `src` at least `f·working_width` wide and `f·end` high, `dst` and `sums` large
/// enough; the tracker sizes all of them in `LaneTracker::new` and checks the frame's size
/// before calling. The common factors are compiled for their constant `f` (the sums of a
/// run then vectorise).
fn downscale_box(
    factor: usize,
    src: &GreyImage<'_>,
    dst: &mut [u8],
    working_width: usize,
    rows: (usize, usize),
    sums: &mut [u32],
) {
    match factor {
        2 => box_rows::<2>(src, dst, working_width, rows, sums),
        3 => box_rows::<3>(src, dst, working_width, rows, sums),
        4 => box_rows::<4>(src, dst, working_width, rows, sums),
        5 => box_rows::<5>(src, dst, working_width, rows, sums),
        6 => box_rows::<6>(src, dst, working_width, rows, sums),
        f => box_rows_any(f, src, dst, working_width, rows, sums),
    }
}

/// The working-frame stage: the input's size and scale, the working frame's pixels, and what
/// the accessors hand out with a resampled input (the last frame's reports, candidates, windows
/// and points mapped to input pixels, refreshed at the end of every frame, also one that
/// returned an error, and by a reset). Without resampling it holds nothing.
#[derive(Debug)]
pub(super) struct WorkingFrame {
    pub(super) scale: WorkingScale,
    /// The input frames' size, px.
    pub(super) input_size: (usize, usize),
    /// The working frame's size, px.
    size: (usize, usize),
    /// The working frame's pixels, its width a row (empty when the input is not resampled),
    /// and how they are made.
    pixels: Vec<u8>,
    resampling: Resampling,
    /// The working rows any stage reads, `[first, end)`: the regions searched and the Sobel's
    /// row beside them; only these are resampled.
    rows: Rows,
    out_lanes: [LaneReport; 2],
    out_candidates: Vec<InitCandidate>,
    out_spans: [Vec<ColSpan>; 2],
    out_points: [Vec<(f32, f32)>; 2],
}

impl WorkingFrame {
    /// The stage for `input_size` frames worked on at `scale` (`size`, px), reading the working
    /// rows `rows`; `lanes` as they start (their reports published, their point buffers'
    /// capacity kept for the published points).
    pub(super) fn new(
        scale: WorkingScale,
        input_size: (usize, usize),
        size: (usize, usize),
        rows: Rows,
        lanes: &Lanes,
    ) -> Self {
        let resampled = scale.resamples();
        let point_capacity = match lanes.iter().next() {
            Some(lane) if resampled => lane.points.capacity(),
            _ => 0,
        };
        WorkingFrame {
            scale,
            input_size,
            size,
            pixels: vec![0; if resampled { size.0 * size.1 } else { 0 }],
            resampling: Resampling::new(scale, input_size, size),
            rows,
            out_lanes: lanes.reports().map(|r| scale.report_to_input(r)),
            out_candidates: Vec::with_capacity(if resampled {
                4 * MAX_CANDIDATE_LINES
            } else {
                0
            }),
            out_spans: std::array::from_fn(|_| {
                vec![ColSpan::EMPTY; if resampled { input_size.1 } else { 0 }]
            }),
            out_points: std::array::from_fn(|_| Vec::with_capacity(point_capacity)),
        }
    }

    /// Whether the input is resampled (`s ≠ 1`).
    pub(super) fn resamples(&self) -> bool {
        self.scale.resamples()
    }

    /// The working frame of `input` (its working rows resampled, the others as they
    /// were), in a buffer taken out of the stage (no allocation: `take` leaves an empty vector);
    /// give it back with [`Self::put_back`].
    pub(super) fn downscale(&mut self, input: &GreyImage<'_>) -> Vec<u8> {
        let mut pixels = std::mem::take(&mut self.pixels);
        self.resampling
            .rows(input, &mut pixels, self.size.0, self.rows);
        pixels
    }

    /// The buffer [`Self::downscale`] lent out, back.
    pub(super) fn put_back(&mut self, pixels: Vec<u8>) {
        self.pixels = pixels;
    }

    /// The working frame of the last tracked frame and its rows that were resampled, `None`
    /// when the input is not resampled.
    pub(super) fn image(&self) -> Option<(GreyImage<'_>, Rows)> {
        if !self.resamples() {
            return None;
        }
        let (w, h) = self.size;
        let image = GreyImage::new(&self.pixels, w, h, w).ok()?;
        Some((image, self.rows))
    }

    /// With a resampled input: the lanes' reports, candidates, windows and points as they are
    /// now, mapped to input pixels (module docs), into the buffers the accessors hand out.
    pub(super) fn publish(&mut self, lanes: &Lanes, candidates: &[InitCandidate]) {
        let s = self.scale;
        for (out, report) in self.out_lanes.iter_mut().zip(lanes.reports()) {
            *out = s.report_to_input(report);
        }
        self.out_candidates.clear();
        // Within capacity: as many as the initialiser holds.
        self.out_candidates
            .extend(candidates.iter().map(|c| InitCandidate {
                coeffs: s.coeffs_to_input(c.coeffs),
                ..*c
            }));
        for ((spans, points), lane) in self
            .out_spans
            .iter_mut()
            .zip(&mut self.out_points)
            .zip(lanes.iter())
        {
            for (y, span) in spans.iter_mut().enumerate() {
                *span = lane
                    .spans
                    .get(s.working_row(y))
                    .map_or(ColSpan::EMPTY, |&w| s.span_to_input(w));
            }
            points.clear();
            // Within capacity: the lane's own points buffer's.
            points.extend(lane.points.iter().map(|&(x, y)| {
                (
                    s.to_input_px(f64::from(x)) as f32,
                    s.to_input_px(f64::from(y)) as f32,
                )
            }));
        }
    }

    /// The published reports (input pixels), left then right.
    pub(super) fn lanes(&self) -> [LaneReport; 2] {
        self.out_lanes
    }

    /// The published candidates (input pixels).
    pub(super) fn candidates(&self) -> &[InitCandidate] {
        &self.out_candidates
    }

    /// The published report, windows and points of lane `i` (0 left, 1 right), input pixels.
    pub(super) fn lane(&self, i: usize) -> (LaneReport, &[ColSpan], &[(f32, f32)]) {
        (self.out_lanes[i], &self.out_spans[i], &self.out_points[i])
    }
}

/// [`WorkingScale::downscale_rows`] for a constant factor `F` (the body inlined with `f = F`).
fn box_rows<const F: usize>(
    src: &GreyImage<'_>,
    dst: &mut [u8],
    working_width: usize,
    rows: (usize, usize),
    sums: &mut [u32],
) {
    box_rows_any(F, src, dst, working_width, rows, sums);
}

/// [`WorkingScale::downscale_rows`] for any factor `f`.
#[inline(always)]
fn box_rows_any(
    f: usize,
    src: &GreyImage<'_>,
    dst: &mut [u8],
    working_width: usize,
    rows: (usize, usize),
    sums: &mut [u32],
) {
    let area = (f * f) as u32;
    let sums = &mut sums[..f * working_width];
    for r in rows.0..rows.1 {
        sums.fill(0);
        for j in 0..f {
            let Some(line) = src.row(f * r + j) else {
                continue;
            };
            for (s, &v) in sums.iter_mut().zip(line) {
                *s += u32::from(v);
            }
        }
        let Some(out) = dst.get_mut(r * working_width..(r + 1) * working_width) else {
            return;
        };
        for (o, run) in out.iter_mut().zip(sums.chunks_exact(f)) {
            let sum: u32 = run.iter().sum();
            // Rounded to the nearest grey level; ≤ 255 as a mean of bytes.
            *o = ((sum + area / 2) / area).min(255) as u8;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parabola(c: [f64; 3], y: f64) -> f64 {
        c[0] * y * y + c[1] * y + c[2]
    }

    #[test]
    fn the_scale_is_the_width_over_the_working_width_within_its_bounds() {
        let s = |w, ww| WorkingScale::for_input(w, 720, ww).factor();
        assert_eq!(s(320, 320), 1.0);
        assert_eq!(s(480, 320), 1.5);
        assert_eq!(s(512, 320), 1.6);
        assert_eq!(s(640, 320), 2.0);
        assert_eq!(s(1280, 320), 4.0);
        assert_eq!(s(1640, 320), 5.125);
        assert_eq!(s(256, 320), 0.8);
        // At most twice the input's size; none with working width 0.
        assert_eq!(s(100, 320), 0.5);
        assert_eq!(s(1280, 0), 1.0);
        assert_eq!(
            WorkingScale::for_input(1280, 720, 320).whole_factor(),
            Some(4)
        );
        assert_eq!(WorkingScale::for_input(512, 288, 320).whole_factor(), None);
        assert_eq!(
            WorkingScale::for_input(512, 288, 320).working_size(512, 288),
            (320, 180)
        );
        assert_eq!(
            WorkingScale::for_input(256, 144, 320).working_size(256, 144),
            (320, 180)
        );
        // A short frame keeps a working frame of 3 rows at least.
        let short = |h| WorkingScale::for_input(1280, h, 320);
        assert_eq!(short(8).working_size(1280, 8), (480, 3));
        assert_eq!(short(12).factor(), 4.0);
    }

    #[test]
    fn mapped_coefficients_pass_through_the_mapped_points() {
        // A working-frame parabola's point (x', y') is the input point (f·x' + o, f·y' + o).
        for factor_px in [2.0, 3.0, 4.0, 5.0, 1.6, 0.8, 5.125] {
            let s = WorkingScale { s: factor_px };
            let b = [0.0031, -0.42, 97.5];
            let a = s.coeffs_to_input(b);
            for y_w in [0.0, 17.0, 60.5, 179.0] {
                let x_in = s.to_input_px(parabola(b, y_w));
                let y_in = s.to_input_px(y_w);
                assert!(
                    (parabola(a, y_in) - x_in).abs() < 1e-9,
                    "f = {factor_px}, y' = {y_w}"
                );
            }
        }
    }

    #[test]
    fn the_mapped_covariance_is_the_covariance_of_mapped_samples() {
        // Cov(T·b + t) = T·Cov(b)·Tᵀ, checked against the sample covariance of coefficients
        // drawn around a mean and mapped one by one (a fixed lattice: no randomness needed).
        let s = WorkingScale { s: 1.6 };
        let mean = [0.002, 0.3, 150.0];
        let steps = [1e-4, 0.05, 2.0];
        let mut samples = Vec::new();
        for i in -2i32..=2 {
            for j in -2i32..=2 {
                for k in -2i32..=2 {
                    // Correlated through the sum in the last coordinate.
                    let d = [
                        f64::from(i) * steps[0],
                        f64::from(j) * steps[1],
                        f64::from(k + i) * steps[2],
                    ];
                    samples.push([mean[0] + d[0], mean[1] + d[1], mean[2] + d[2]]);
                }
            }
        }
        let cov = |pts: &[[f64; 3]]| {
            let n = pts.len() as f64;
            let m: [f64; 3] = std::array::from_fn(|r| pts.iter().map(|p| p[r]).sum::<f64>() / n);
            Matrix3::from_fn(|r, c| {
                pts.iter()
                    .map(|p| (p[r] - m[r]) * (p[c] - m[c]))
                    .sum::<f64>()
                    / n
            })
        };
        let mapped: Vec<[f64; 3]> = samples.iter().map(|&b| s.coeffs_to_input(b)).collect();
        let want = cov(&mapped);
        let got = s.cov_to_input(&cov(&samples));
        for r in 0..3 {
            for c in 0..3 {
                let tol = 1e-9 * want[(r, c)].abs().max(1e-12);
                assert!((got[(r, c)] - want[(r, c)]).abs() <= tol, "({r}, {c})");
            }
        }
    }

    #[test]
    fn downscaling_averages_each_block_and_rounds() {
        // 6×4 input, f = 2: working 3×2; each block's mean rounded to the nearest level.
        let input: Vec<u8> = vec![
            0, 1, 10, 10, 255, 255, //
            1, 1, 10, 11, 255, 254, //
            7, 7, 0, 0, 100, 0, //
            7, 8, 0, 1, 0, 0, //
        ];
        let src = GreyImage::new(&input, 6, 4, 6).expect("image");
        let s = WorkingScale::for_input(6, 6, 3);
        assert_eq!(s.whole_factor(), Some(2));
        let (mut dst, mut acc) = (vec![9u8; 6], vec![0u32; 6]);
        downscale_box(2, &src, &mut dst, 3, (0, 2), &mut acc);
        // (0+1+1+1)/4 = 0.75 → 1; 41/4 = 10.25 → 10; 1019/4 = 254.75 → 255;
        // 29/4 = 7.25 → 7; 1/4 → 0; 100/4 = 25.
        assert_eq!(dst, vec![1, 10, 255, 7, 0, 25]);
        // Only the rows asked for are written.
        let mut dst = vec![9u8; 6];
        downscale_box(2, &src, &mut dst, 3, (1, 2), &mut acc);
        assert_eq!(dst, vec![9, 9, 9, 7, 0, 25]);
    }

    #[test]
    fn every_factor_gives_each_blocks_rounded_mean() {
        // The compiled-in factors and the general path against the mean block by block, on a
        // frame whose sides are not multiples of the factor (the remainder is not read).
        let (w, h) = (53usize, 37usize);
        let input: Vec<u8> = (0..w * h)
            .map(|i| ((i * 7919 + i / w * 31) % 256) as u8)
            .collect();
        let src = GreyImage::new(&input, w, h, w).expect("image");
        for f in 2..=9 {
            let s = WorkingScale { s: f as f64 };
            let (ww, wh) = s.working_size(w, h);
            let (mut dst, mut sums) = (vec![0u8; ww * wh], vec![0u32; w]);
            downscale_box(f, &src, &mut dst, ww, (0, wh), &mut sums);
            for r in 0..wh {
                for c in 0..ww {
                    let mut sum = 0u32;
                    for j in 0..f {
                        for i in 0..f {
                            sum += u32::from(input[(f * r + j) * w + f * c + i]);
                        }
                    }
                    let mean = (f64::from(sum) / (f * f) as f64).round();
                    assert!(
                        (f64::from(dst[r * ww + c]) - mean).abs() <= 0.5,
                        "f = {f} at ({c}, {r})"
                    );
                }
            }
        }
    }

    #[test]
    fn spans_cover_the_input_columns_of_their_working_columns() {
        let span = |s: f64| {
            let c = WorkingScale { s }.span_to_input(ColSpan {
                col_start_px: 10,
                col_end_px: 21,
            });
            (c.col_start_px, c.col_end_px)
        };
        assert_eq!(span(4.0), (40, 84));
        // Input columns [16, 33.6): every column any of the working columns reads.
        assert_eq!(span(1.6), (16, 34));
    }
}
