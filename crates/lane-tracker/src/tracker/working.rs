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
//! centre (up, at most 2×) — `vision_gradient::resample_rows`; a whole `s` is the box average over `s × s`
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

use vision_gradient::{AxisTaps, ColSpan, GradientError, GreyImage, downscale_box, resample_rows};

use super::lane::Lanes;
use super::report::{InitCandidate, LaneReport, MAX_CANDIDATE_LINES};
use super::setup::Rows;
use super::view::{AxisMap, WorkingView};

/// The largest upsampling: a frame is tracked at most twice its own size.
const MAX_UPSAMPLING: f64 = 2.0;

/// The scale for `input_width_px × input_height_px` frames at working width `working_width_px`
/// (0: none, `s = 1`): `s = input width / working width`, so the working frame is the working
/// width wide whatever the input's width, held to a working frame of at least 3 × 3 px
/// (`s ≤ min(w, h)/3`: a 1280 × 8 strip is tracked at 480 × 3), at most twice the input's size
/// (`s ≥ 1/2`: a 100-px frame is tracked at 200 px) and at most `MAX_IMAGE_SIDE_PX` a side. A
/// ratio within rounding of a whole number is that number (the box average's path).
pub(crate) fn working_scale(
    input_width_px: usize,
    input_height_px: usize,
    working_width_px: usize,
) -> f64 {
    if working_width_px == 0 || input_width_px == working_width_px {
        return 1.0;
    }
    let (w, h) = (input_width_px as f64, input_height_px as f64);
    let max_side = hough_init::MAX_IMAGE_SIDE_PX as f64;
    let s = (w / working_width_px as f64)
        .min(w.min(h) / 3.0)
        .max(1.0 / MAX_UPSAMPLING)
        .max(w.max(h) / max_side);
    let whole = s.round();
    if (s - whole).abs() < 1e-9 && whole >= 1.0 {
        whole
    } else {
        s
    }
}

/// The working-frame size of a `width × height` input at `s`, px: `⌊w/s⌋ × ⌊h/s⌋`.
pub(crate) fn working_size(width: usize, height: usize, s: f64) -> (usize, usize) {
    let side = |v: usize| (v as f64 / s + 1e-9).floor() as usize;
    (side(width), side(height))
}

/// The working-frame stage: the input's size and the view of it (module `view`), the working
/// frame's pixels, and what the accessors hand out with a resampled input (the last frame's
/// reports, candidates, windows and points mapped to input pixels, refreshed at the end of
/// every frame, also one that returned an error, and by a reset). Without resampling it hands
/// out the stages' own.
#[derive(Debug)]
pub(super) struct WorkingFrame {
    /// The view in force.
    pub(super) view: WorkingView,
    /// Square pixels from the top-left: the view of a frame whose road reaches its bottom.
    square: WorkingView,
    /// The input frames' size, px.
    pub(super) input_size: (usize, usize),
    /// The working frame's size, px.
    size: (usize, usize),
    /// The working frame's pixels, its width a row.
    pixels: Vec<u8>,
    /// The box average's column sums (a whole factor), else empty.
    box_sums: Vec<u32>,
    /// The taps of both axes and a row of input-width sums (`vision_gradient::AxisTaps`).
    col_taps: AxisTaps,
    row_taps: AxisTaps,
    acc: Vec<f32>,
    /// The working rows any stage reads, `[first, end)`: the regions searched and the Sobel's
    /// row beside them; only these are resampled.
    rows: Rows,
    out_lanes: [LaneReport; 2],
    out_candidates: Vec<InitCandidate>,
    out_spans: [Vec<ColSpan>; 2],
    out_points: [Vec<(f32, f32)>; 2],
}

impl WorkingFrame {
    /// The stage for `input_size` frames worked on at `s` input pixels per working pixel
    /// (`size`, px), reading the working rows `rows`; `lanes` as they start (their reports
    /// published, their point buffers' capacity kept for the published points).
    pub(super) fn new(
        s: f64,
        input_size: (usize, usize),
        size: (usize, usize),
        rows: Rows,
        lanes: &Lanes,
    ) -> Self {
        let square = WorkingView::square(s);
        let point_capacity = lanes.iter().next().map_or(0, |lane| lane.points.capacity());
        WorkingFrame {
            view: square,
            square,
            input_size,
            size,
            pixels: vec![0; size.0 * size.1],
            box_sums: vec![
                0;
                if square.whole_factor().is_some() {
                    input_size.0
                } else {
                    0
                }
            ],
            col_taps: AxisTaps::new(input_size.0, size.0, square.cols.span(), s),
            row_taps: AxisTaps::new(input_size.1, size.1, square.rows.span(), s),
            acc: vec![0.0; input_size.0],
            rows,
            out_lanes: lanes.reports().map(|r| square.report_to_input(r)),
            out_candidates: Vec::with_capacity(4 * MAX_CANDIDATE_LINES),
            out_spans: std::array::from_fn(|_| vec![ColSpan::EMPTY; input_size.1]),
            out_points: std::array::from_fn(|_| Vec::with_capacity(point_capacity)),
        }
    }

    /// Whether the input is resampled (the view is not the identity).
    pub(super) fn resamples(&self) -> bool {
        !self.view.is_identity()
    }

    /// The square view: the one a frame whose road reaches its bottom is tracked in.
    pub(super) fn square_view(&self) -> WorkingView {
        self.square
    }

    /// Track the next frames in `rows` for the rows (the columns stay as they are); the rows'
    /// taps are rebuilt in place when they change.
    pub(super) fn set_rows(&mut self, rows: AxisMap) {
        if rows == self.view.rows {
            return;
        }
        self.view.rows = rows;
        self.row_taps
            .rebuild(self.input_size.1, self.size.1, rows.span());
    }

    /// The working frame of `input` (its working rows resampled, the others as they were), in
    /// a buffer taken out of the stage (no allocation: `take` leaves an empty vector); give it
    /// back with [`Self::put_back`]. A buffer the frame does not fit (the caller checks the
    /// frame's size first, so never in practice) is an error, the buffer kept.
    pub(super) fn resample(&mut self, input: &GreyImage<'_>) -> Result<Vec<u8>, GradientError> {
        let mut pixels = std::mem::take(&mut self.pixels);
        let width = self.size.0;
        let done = match self.view.whole_factor() {
            Some(f) => downscale_box(f, input, &mut pixels, width, self.rows, &mut self.box_sums),
            None => resample_rows(
                input,
                &mut pixels,
                &self.col_taps,
                &self.row_taps,
                self.rows,
                &mut self.acc,
            ),
        };
        match done {
            Ok(()) => Ok(pixels),
            Err(e) => {
                self.pixels = pixels;
                Err(e)
            }
        }
    }

    /// The working rows that are resampled, `[first, end)`.
    pub(super) fn resampled_rows(&self) -> Rows {
        self.rows
    }

    /// The buffer [`Self::resample`] lent out, back.
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
    /// now, mapped to input pixels (module `view`), into the buffers the accessors hand out.
    pub(super) fn publish(&mut self, lanes: &Lanes, candidates: &[InitCandidate]) {
        let v = self.view;
        for (out, report) in self.out_lanes.iter_mut().zip(lanes.reports()) {
            *out = v.report_to_input(report);
        }
        self.out_candidates.clear();
        // Within capacity: as many as the initialiser holds.
        self.out_candidates
            .extend(candidates.iter().map(|c| InitCandidate {
                coeffs: v.coeffs_to_input(c.coeffs),
                ..*c
            }));
        for ((spans, points), lane) in self
            .out_spans
            .iter_mut()
            .zip(&mut self.out_points)
            .zip(lanes.iter())
        {
            for (y, span) in spans.iter_mut().enumerate() {
                *span = v
                    .rows
                    .working_px(y)
                    .and_then(|r| lane.spans.get(r))
                    .map_or(ColSpan::EMPTY, |&w| v.span_to_input(w));
            }
            points.clear();
            // Within capacity: the lane's own points buffer's.
            points.extend(lane.points.iter().map(|&(x, y)| {
                (
                    v.cols.to_input_px(f64::from(x)) as f32,
                    v.rows.to_input_px(f64::from(y)) as f32,
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_scale_is_the_width_over_the_working_width_within_its_bounds() {
        let s = |w, ww| working_scale(w, 720, ww);
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
        assert_eq!(WorkingView::square(4.0).whole_factor(), Some(4));
        assert_eq!(WorkingView::square(1.6).whole_factor(), None);
        assert_eq!(working_size(512, 288, 1.6), (320, 180));
        assert_eq!(working_size(256, 144, 0.8), (320, 180));
        // A short frame keeps a working frame of 3 rows at least.
        let short = working_scale(1280, 8, 320);
        assert_eq!(working_size(1280, 8, short), (480, 3));
        assert_eq!(working_scale(1280, 12, 320), 4.0);
    }
}
