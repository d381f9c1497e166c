//! Stage III, point selection: which window pixels measure the lane on this frame (the paper's
//! inlier edge pixels, or one sub-pixel mark centre per row), and the measurement noise they
//! carry.
//!
//! Decisions and figures: `docs/lanes/history/orientation-gate.md`, `stripe-middles.md`.

use hough_init::Parabola;
use info_filter::{PowerSums, RowNorm};
use lane_geometry::{FIT_SAMPLES, FitRows};
use nalgebra::{Matrix3, Vector3};
use vision_gradient::{EdgeBuffer, EdgeClass, EdgePixel, GreyImage};

use super::lane::Lane;
use super::report::Side;
use super::setup::{Pass, Rows};
use crate::TrackerConfig;

/// A window pixel during point selection.
#[derive(Debug, Clone, Copy)]
pub(super) struct Candidate {
    /// The measured column rounded down: the pixel's, or its bright stripe's middle
    /// (`track.stripe_middles`, [`stripe_middle`]).
    col_px: u16,
    row_px: u16,
    /// Residual of the measured column (`col_px + ½` with `half_col`) about `x̂(y)`, rounded,
    /// plus the window half-width (0..=2w).
    bin: u16,
    /// Third of the rows searched (0, 1, 2).
    band: u8,
    /// The measured column is `col_px + ½` (a stripe middle between two columns).
    half_col: bool,
}

impl Candidate {
    /// The measured point `(x, y)`, px.
    fn point(&self) -> (f32, f32) {
        let half = if self.half_col { 0.5 } else { 0.0 };
        (f32::from(self.col_px) + half, f32::from(self.row_px))
    }
}

/// Sub-pixel column of a lane mark in one image row: the centroid of its grey level above the
/// local background, over the columns `lo..=hi` of the row's inlier edge pixels widened on each
/// side by `2 + ⌈|slope|⌉` px (`slope` = the predicted `dx/dy` of the lane: the 3×3 gradient of a
/// slanted edge reaches that far from it), at most 6 px. The background is the mean of the two
/// end pixels; the mark is the brighter or the darker side (whichever deviates more). When the
/// two ends differ by more than half the mark's contrast the window holds a single step edge
/// (a floor/wall boundary, a shadow border, a mark cut by the image border), and the point is
/// that edge's sub-pixel position ([`step_edge`]). `None` when there is no contrast.
///
/// Returns the column and `v = Σ_k (k − c)²/S²` over the window (`S` the summed excess grey,
/// `c` the centroid): the centroid's variance per unit of grey-level noise variance, so `1/v`
/// is the point's relative precision (a narrow or faint mark gives a noisier centre).
///
/// For a mark drawn with area anti-aliasing the centroid is exact up to a sawtooth of at most
/// `1/(8·w)` px for a mark `w` px wide (exact for whole-pixel widths), against up to half a pixel
/// for the integer columns of its edge pixels.
fn mark_centre(row: &[u8], lo: u16, hi: u16, slope: f64) -> Option<(f64, f64)> {
    let margin = if slope.is_finite() {
        (2.0 + slope.abs().ceil()).min(6.0) as usize
    } else {
        2
    };
    let a = usize::from(lo).saturating_sub(margin);
    let b = (usize::from(hi) + margin).min(row.len().checked_sub(1)?);
    let pixels = row.get(a..=b)?;
    let (&first, &last) = (pixels.first()?, pixels.last()?);
    let bg = 0.5 * (f64::from(first) + f64::from(last));
    let (mut hi_dev, mut lo_dev) = (0.0f64, 0.0f64);
    for &p in pixels {
        let d = f64::from(p) - bg;
        hi_dev = hi_dev.max(d);
        lo_dev = lo_dev.min(d);
    }
    let (polarity, contrast) = if hi_dev >= -lo_dev {
        (1.0, hi_dev)
    } else {
        (-1.0, -lo_dev)
    };
    let step = f64::from(last) - f64::from(first);
    if step.abs() > 0.5 * contrast {
        return step_edge(pixels, step).map(|(c, v)| (a as f64 + c, v));
    }
    if contrast <= 0.0 {
        return None;
    }
    let (mut sw, mut swx) = (0.0, 0.0);
    for (k, &p) in pixels.iter().enumerate() {
        let w = (polarity * (f64::from(p) - bg)).max(0.0);
        sw += w;
        swx += w * k as f64;
    }
    if sw <= 0.0 {
        return None;
    }
    let c = swx / sw;
    let spread: f64 = (0..pixels.len()).map(|k| (k as f64 - c).powi(2)).sum();
    Some((a as f64 + c, spread / (sw * sw)))
}

/// [`super::LaneTracker::lane_fit_rows`] of `points` (with `weights`, or 1 each when `weights` is
/// shorter) over `rows` `[first, last]`.
pub(super) fn fit_profile(points: &[(f32, f32)], weights: &[f64], rows: [f64; 2]) -> FitRows {
    let mut sum_w = [0.0; FIT_SAMPLES];
    let mut sum_wy = [0.0; FIT_SAMPLES];
    let span = rows[1] - rows[0];
    for (i, &(_, y)) in points.iter().enumerate() {
        let w = weights.get(i).copied().unwrap_or(1.0);
        let y = f64::from(y);
        let t = if span > 0.0 {
            (y - rows[0]) / span
        } else {
            0.0
        };
        let b = ((t * FIT_SAMPLES as f64).max(0.0) as usize).min(FIT_SAMPLES - 1);
        sum_w[b] += w;
        sum_wy[b] += w * y;
    }
    let mut fit = FitRows {
        rows_px: [0.0; FIT_SAMPLES],
        weights: sum_w,
    };
    for (b, r) in fit.rows_px.iter_mut().enumerate() {
        *r = if sum_w[b] > 0.0 {
            sum_wy[b] / sum_w[b]
        } else {
            rows[0] + span * (b as f64 + 0.5) / FIT_SAMPLES as f64
        };
    }
    fit
}

/// Floor of the per-point σ the KIF is given, px: a scatter estimate below it (a noise-free
/// rendering) is not trusted further.
const MIN_R_SIGMA_PX: f64 = 0.02;

/// Fewest points for the scatter estimate of [`weighted_scatter`].
const MIN_SCATTER_POINTS: usize = 8;

/// The KIF's measurement for one frame of weighted points: the weighted power sums
/// (`info_filter::PowerSums::from_weighted_points`) and the scale `s²` of `R = s²·diag(1/w_i)`,
/// the unbiased weighted variance (`N − 3` degrees of freedom) of the points about their own
/// weighted least-squares parabola, floored so that the points' mean variance `s²·N/Σw` is at
/// least `MIN_R_SIGMA_PX²`. The residuals are taken about `pred` (the predicted coefficients)
/// first so the sums stay small. `None` for fewer than [`MIN_SCATTER_POINTS`] points, a
/// singular fit or bad weights.
pub(super) fn weighted_scatter(
    points: &[(f32, f32)],
    weights: &[f64],
    pred: [f64; 3],
    row_norm: &RowNorm,
) -> Option<(PowerSums, f64)> {
    if points.len() < MIN_SCATTER_POINTS || weights.len() != points.len() {
        return None;
    }
    let mut n = Matrix3::<f64>::zeros();
    let mut b = Vector3::<f64>::zeros();
    let (mut wrr, mut sw) = (0.0, 0.0);
    for (&(x, y), &w) in points.iter().zip(weights) {
        let y = f64::from(y);
        let r = f64::from(x) - Parabola::from_coeffs(pred).col_at_row(y);
        let u = row_norm.normalise_row(y);
        let phi = Vector3::new(u * u, u, 1.0);
        n += w * phi * phi.transpose();
        b += w * r * phi;
        wrr += w * r * r;
        sw += w;
    }
    let theta = n.cholesky()?.solve(&b);
    let count = points.len() as f64;
    let s2 = ((wrr - theta.dot(&b)).max(0.0) / (count - 3.0))
        .max(MIN_R_SIGMA_PX * MIN_R_SIGMA_PX * sw / count);
    let sums = PowerSums::from_weighted_points(points, weights, row_norm).ok()?;
    (s2.is_finite() && s2 > 0.0).then_some((sums, s2))
}

/// Sub-pixel position (from the window's first pixel) of a single step edge rising by `step`
/// (grey levels, either sign) across `pixels`, and its relative variance: the centroid of the
/// forward differences of the step's sign, each at its half-pixel position — exact for an
/// area-anti-aliased step. `None` if the window holds no difference of that sign.
fn step_edge(pixels: &[u8], step: f64) -> Option<(f64, f64)> {
    let sign = step.signum();
    let (mut sw, mut swx) = (0.0, 0.0);
    for (k, pair) in pixels.windows(2).enumerate() {
        let d = (sign * (f64::from(pair[1]) - f64::from(pair[0]))).max(0.0);
        sw += d;
        swx += d * (k as f64 + 0.5);
    }
    if sw <= 0.0 {
        return None;
    }
    let c = swx / sw;
    // Each difference carries two pixels' noise.
    let spread: f64 = (0..pixels.len().saturating_sub(1))
        .map(|k| 2.0 * (k as f64 + 0.5 - c).powi(2))
        .sum();
    Some((c, spread / (sw * sw)))
}

/// `|dx/dy|` below which a tracked mark is near vertical and both edge classes are taken
/// (joint initialisation): tan 10°, within 10° of the vertical (the edge band of the default
/// reaches 90°, the presets' 80°).
pub(super) const NEAR_VERTICAL_SLOPE: f64 = 0.176;

/// Uniform decimation of `total` items in order down to `max` (all of them when
/// `total ≤ max`): item `j` is kept iff `⌊(j+1)·max/total⌋ > ⌊j·max/total⌋`, i.e. iff a
/// multiple of `total` lies in `(j·max, (j+1)·max]`, tracked as the running remainder of
/// `j·max` modulo `total` (a Bresenham step: no division per item).
struct Decimation {
    max: usize,
    total: usize,
    remainder: usize,
}

impl Decimation {
    fn new(max: usize, total: usize) -> Self {
        Self {
            max,
            total,
            remainder: 0,
        }
    }

    /// Whether the next item is kept.
    fn keep(&mut self) -> bool {
        if self.total <= self.max {
            return true;
        }
        self.remainder += self.max;
        if self.remainder >= self.total {
            self.remainder -= self.total;
            true
        } else {
            false
        }
    }
}

/// Largest |offset| of a row's residual bins, px: far beyond any column (an image is at most
/// `u16::MAX` px wide), so that the clamped offset still puts every pixel of a far-off
/// prediction in an end bin, and `i32` arithmetic cannot overflow.
const BIN_OFFSET_LIMIT: f64 = 1_000_000.0;

/// The residual bin of column `x` in a window `±w` px about the prediction `x̂` is the residual
/// rounded half up and shifted into `0..=2w`, `⌊x − x̂ + w + ½⌋` clamped. `x` is an integer,
/// so that is `x + ⌊w + ½ − x̂⌋`: this offset, once per row (a NaN prediction puts every pixel
/// in bin 0, an infinite one in an end bin). [`residual_bin`] applies it. (The per-pixel float
/// form, `((x − x̂) + w) + ½` rounded at each step, can differ from it by one bin when the sum
/// lies within a few ulp of an integer; this one rounds once.)
fn bin_offset(col_pred_px: f64, w: i64) -> i32 {
    let offset = (w as f64 + 0.5 - col_pred_px).floor();
    let offset = if offset.is_nan() {
        -BIN_OFFSET_LIMIT
    } else {
        offset.clamp(-BIN_OFFSET_LIMIT, BIN_OFFSET_LIMIT)
    };
    offset as i32
}

/// Column `col_px`'s residual bin with its row's [`bin_offset`], clamped to `0..=bin_max` (2w).
#[inline]
fn residual_bin(col_px: u16, offset: i32, bin_max: i32) -> usize {
    // (Not `clamp`, which panics for a negative `bin_max`.)
    (i32::from(col_px) + offset).max(0).min(bin_max) as usize
}

/// The column `row[j]` measures with `track.stripe_middles`: the middle of the bright stripe it
/// bounds, as `(column rounded down, whether it lies half a column further)`; `None` where it
/// bounds none (it measures its own column then). `row` is one image row's edge pixels
/// (columns increasing, [`vision_gradient::EdgeBuffer`]), `grey` that row's grey levels.
///
/// The stripe is the one [`vision_gradient::split_stripes`] pairs: the nearest pixel of the same
/// class and the opposite polarity on the pixel's bright side (right of a rising pixel, left of
/// a falling one) within `max_width_px` columns (the scan stops there). It counts only if the
/// two are more than `min_width_px` columns apart (narrower stripes need no middle, see
/// `select_points`) and the stripe stands on a floor alike on both sides: the grey levels two
/// columns outside its edges differ by at most half its contrast (its middle pixel above their
/// mean), the test [`mark_centre`] uses to tell a mark from a step. A kerb's face, bright
/// between the road and a pavement of another grey, is a step whose foot the lane keeps
/// (`init.kerb_foot`); a mark is a stripe whose middle the labels and the lane model mean.
fn stripe_middle(
    row: &[EdgePixel],
    j: usize,
    grey: &[u8],
    (min_width_px, max_width_px): (u16, u16),
) -> Option<(u16, bool)> {
    let p = row.get(j)?;
    let partner = |q: &&EdgePixel| q.class == p.class && (q.gx > 0) != (p.gx > 0);
    let (a, b) = if p.gx > 0 {
        let reach = p.col_px.saturating_add(max_width_px);
        let q = row
            .get(j + 1..)?
            .iter()
            .take_while(|q| q.col_px <= reach)
            .find(partner)?;
        (p.col_px, q.col_px)
    } else {
        let reach = p.col_px.saturating_sub(max_width_px);
        let q = row
            .get(..j)?
            .iter()
            .rev()
            .take_while(|q| q.col_px >= reach)
            .find(partner)?;
        (q.col_px, p.col_px)
    };
    // (Columns increase along the row: a ≤ b.)
    if b.saturating_sub(a) <= min_width_px {
        return None;
    }
    let (a, b) = (usize::from(a), usize::from(b));
    let left = f32::from(*grey.get(a.checked_sub(2)?)?);
    let right = f32::from(*grey.get(b + 2)?);
    let inside = f32::from(*grey.get((a + b) / 2)?);
    let contrast = inside - 0.5 * (left + right);
    // (a + b)/2 ≤ b: a column of the row.
    (contrast > 0.0 && (left - right).abs() <= 0.5 * contrast)
        .then(|| (((a + b) / 2) as u16, (a + b) % 2 == 1))
}

/// What the pass over one lane's window pixels needs besides them ([`WindowPass::gather`]).
struct WindowPass<'a> {
    /// The predicted lane.
    predicted: Parabola,
    /// Joint initialisation: each row's class from the predicted slope.
    joint: bool,
    /// The lane's class otherwise.
    lane_class: EdgeClass,
    /// Orientation gate on (`track.orientation_tolerance_deg > 0`).
    gate: bool,
    /// `tan τ` of the gate's tolerance τ.
    tan_tolerance: f32,
    /// First rows of the second and third row bands.
    band_rows: [usize; 2],
    /// Window half-width, px.
    w: i64,
    /// The frame (grey levels for the stripe middles).
    image: &'a GreyImage<'a>,
    /// Stripes whose edge pixels measure their middle (`MIDDLES`): more than `.0` and at most
    /// `.1` px between their edge pixels.
    stripe_widths_px: (u16, u16),
}

impl WindowPass<'_> {
    /// One pass over the window pixels `edges` (the detector's, row by row): each pixel of the
    /// row's class within the orientation gate is binned by its residual in its row band's
    /// histogram (`hist`, cleared by the caller) and kept in `scratch` (up to its capacity).
    /// `MIDDLES`: a pixel measures its bright stripe's middle ([`stripe_middle`]) where it
    /// bounds one.
    fn gather<const MIDDLES: bool>(
        &self,
        edges: &[EdgePixel],
        hist: &mut [[u32; 2 * MAX_WINDOW_HALF_WIDTH + 1]; BANDS],
        scratch: &mut Vec<Candidate>,
    ) {
        let bin_max = (2 * self.w) as i32; // ≤ 2·MAX_WINDOW_HALF_WIDTH (the configuration's range)
        // The detector stores its pixels row by row: the prediction, its slope and the class
        // test are evaluated once per row, not once per pixel.
        for row_pixels in edges.chunk_by(|a, b| a.row_px == b.row_px) {
            let Some(first) = row_pixels.first() else {
                continue;
            };
            let row = usize::from(first.row_px);
            let y = f64::from(first.row_px);
            let slope = self.predicted.slope_at_row(y);
            let col_pred = self.predicted.col_at_row(y);
            // The class this row's pixels must have; `None`: either (a near-vertical mark).
            let class = if !self.joint {
                Some(self.lane_class)
            } else if slope.abs() < NEAR_VERTICAL_SLOPE {
                None
            } else if slope < 0.0 {
                Some(EdgeClass::LeftLane)
            } else {
                Some(EdgeClass::RightLane)
            };
            let slope_f32 = slope as f32;
            let grey = if MIDDLES { self.image.row(row) } else { None };
            let offset = bin_offset(col_pred, self.w);
            let offset_half = if MIDDLES {
                bin_offset(col_pred - 0.5, self.w)
            } else {
                offset
            };
            let band =
                usize::from(row >= self.band_rows[0]) + usize::from(row >= self.band_rows[1]);
            let Some(hist) = hist.get_mut(band) else {
                continue;
            };
            for (j, p) in row_pixels.iter().enumerate() {
                if class.is_some_and(|c| p.class != c) {
                    continue;
                }
                if self.gate {
                    let (gx, gy) = p.gradient();
                    let (gx, gy) = (f32::from(gx), f32::from(gy));
                    if (gx * slope_f32 + gy).abs()
                        > self.tan_tolerance * (gx - gy * slope_f32).abs()
                    {
                        continue;
                    }
                }
                let (mut col_px, mut half_col) = (p.col_px, false);
                if let Some(grey) = grey
                    && let Some(middle) = stripe_middle(row_pixels, j, grey, self.stripe_widths_px)
                {
                    (col_px, half_col) = middle;
                }
                // A middle `col_px + ½` is binned as `⌊col_px + ½ − x̂ + w + ½⌋`.
                let bin =
                    residual_bin(col_px, if half_col { offset_half } else { offset }, bin_max);
                if let Some(count) = hist.get_mut(bin) {
                    *count += 1;
                }
                if scratch.len() < scratch.capacity() {
                    scratch.push(Candidate {
                        col_px,
                        row_px: p.row_px,
                        bin: bin as u16,
                        band: band as u8,
                        half_col,
                    });
                }
            }
        }
    }
}

/// Row bands of point selection's outlier rejection (thirds of the rows searched).
pub(super) const BANDS: usize = 3;

/// Largest window half-width accepted by the configuration, px.
pub(crate) const MAX_WINDOW_HALF_WIDTH: usize = 200;

/// Point selection: the residual histograms and the window pixels of one lane, in buffers sized
/// once.
#[derive(Debug)]
pub(super) struct PointSelector {
    /// The window pixels of the lane's class with their residual bin and row band.
    scratch: Vec<Candidate>,
    /// The residual histograms, one per third of the rows searched ([`BANDS`]), bins `0..=2w`
    /// of a window `±w` px.
    residual_hist: Box<[[u32; 2 * MAX_WINDOW_HALF_WIDTH + 1]; BANDS]>,
}

impl PointSelector {
    /// Buffers for `capacity` window pixels (the edge buffer's).
    pub(super) fn new(capacity: usize) -> Self {
        PointSelector {
            scratch: Vec::with_capacity(capacity),
            residual_hist: Box::new([[0; 2 * MAX_WINDOW_HALF_WIDTH + 1]; BANDS]),
        }
    }

    /// The measurement for this frame of the lane on `side` from the window pixels `edges`
    /// (windows `±w` px over `rows`) about the predicted `coeffs`: fills `lane.points` (and
    /// `lane.weights` with mark centres). In a refinement ([`Pass::Refinement`]) wide stripes
    /// measure their middles (`track.stripe_middles`).
    #[allow(clippy::too_many_arguments)] // the stage's inputs, each named
    pub(super) fn select(
        &mut self,
        edges: &EdgeBuffer,
        lane: &mut Lane,
        side: Side,
        image: &GreyImage<'_>,
        coeffs: [f64; 3],
        w: i64,
        pass: Pass,
        rows: Rows,
        cfg: &TrackerConfig,
    ) {
        let (top, bottom) = rows;
        let max_points = cfg.track.max_points_per_lane;
        // Outlier rejection: the residuals r = x − x̂(y) of the window pixels are histogrammed
        // in three row bands; pixels farther than `inlier_half_width_px` from their band's
        // midhinge residual (mean of the quartiles) are dropped (clutter, noise, the edges of a shadow).
        let band_rows = [top + (bottom - top) / 3, top + 2 * (bottom - top) / 3];
        let w_us = w as usize;
        // One pass over the window pixels of the lane's class: residual bin (r + w, rounded;
        // window pixels are within ±w of the prediction) and row band, histogrammed per band.
        // (The tracker's buffer, cleared over the bins this window uses.)
        let hist = &mut *self.residual_hist;
        for h in hist.iter_mut() {
            if let Some(bins) = h.get_mut(..=2 * w_us) {
                bins.fill(0);
            }
        }
        self.scratch.clear();
        // Joint initialisation (lanes sided by position, not lean): per row, the edge class of
        // the predicted slope (`/`: dx/dy < 0), either class where the mark is near vertical.
        let joint = cfg.init.candidate_lines > 0;
        // Orientation gate (`track.orientation_tolerance_deg`): along x = x̂(y) the tangent is
        // (x̂′, 1) and the normal n = (1, −x̂′); the pixel's stored Sobel gradient
        // g = (gx, gy) (`EdgePixel::gradient`) is within the tolerance τ of ±n iff
        // |g × n| ≤ tan τ · |g · n|, with g × n = −(gx·x̂′ + gy) and g · n = gx − gy·x̂′ (no
        // angle computed).
        let tolerance_deg = cfg.track.orientation_tolerance_deg;
        let gate = tolerance_deg > 0.0;
        let tan_tolerance = tolerance_deg.to_radians().tan() as f32;
        let predicted = Parabola::from_coeffs(coeffs);
        // Stripe middles (`track.stripe_middles`; crate docs, "Stripe middles"): in the
        // refinement, the edge pixels of a bright stripe more than the inlier half-width and at
        // most `gradient.stripe_max_width_px` wide measure its middle. A narrower one needs
        // none: from either of its edges the other lies within the inlier band, so the band
        // settles on its middle and its edge pixels measure it (and the lines of a double line,
        // each narrow, keep measuring the middle between them); from one edge of a wider one
        // the other edge lies beyond the band, and the edge pixels hold the lane on that edge.
        let stripe_w =
            if pass == Pass::Refinement && cfg.track.stripe_middles && !cfg.track.mark_centres {
                cfg.gradient.stripe_max_width_px
            } else {
                0
            };
        // (The configuration keeps the half-width finite and > 0.)
        let stripe_min_w = cfg
            .track
            .inlier_half_width_px
            .floor()
            .min(f64::from(u16::MAX)) as u16;
        let window = WindowPass {
            predicted,
            joint,
            lane_class: side.edge_class(),
            gate,
            tan_tolerance,
            band_rows,
            w,
            image,
            stripe_widths_px: (stripe_min_w, stripe_w),
        };
        // (Two copies of the pass: tracked frames run the paper's alone.)
        if stripe_w > 0 {
            window.gather::<true>(edges.pixels(), hist, &mut self.scratch);
        } else {
            window.gather::<false>(edges.pixels(), hist, &mut self.scratch);
        }
        // Band centre = midhinge (mean of the quartiles): with the two edges of a mark it
        // lands between them, where a median would pick one edge.
        let mut centre = [w; BANDS];
        for (b, h) in hist.iter().enumerate() {
            let n: u32 = h[..=2 * w_us].iter().sum();
            if n == 0 {
                continue;
            }
            let (q1, q3) = (n.div_ceil(4), (3 * n).div_ceil(4));
            let (mut acc, mut r1, mut r3) = (0u32, None, None);
            for (r, &c) in h[..=2 * w_us].iter().enumerate() {
                acc += c;
                if r1.is_none() && acc >= q1 {
                    r1 = Some(r as i64);
                }
                if acc >= q3 {
                    r3 = Some(r as i64);
                    break;
                }
            }
            if let (Some(a), Some(c)) = (r1, r3) {
                centre[b] = (a + c).div_euclid(2);
            }
        }
        // |bin − centre| ≤ inlier_half_width_px for an integer difference: ≤ its floor (the
        // configuration keeps it finite and > 0); per band, the bins `lo..=hi`.
        // (Capped at the histogram's width: a wider half-width keeps every bin, as it did.)
        let inlier =
            (cfg.track.inlier_half_width_px.floor() as i64).min(2 * MAX_WINDOW_HALF_WIDTH as i64);
        let bounds = centre.map(|c| {
            let lo = (c - inlier).clamp(0, i64::from(u16::MAX)) as u16;
            let hi = (c + inlier).clamp(-1, i64::from(u16::MAX)) as i32;
            (lo, hi)
        });
        let is_inlier = |c: &Candidate| {
            let (lo, hi) = bounds[usize::from(c.band) % BANDS];
            c.bin >= lo && i32::from(c.bin) <= hi
        };
        // With `track.mark_centres`, one sub-pixel point per row (crate docs, "Mark centres"):
        // the inlier edge pixels of a row (both edges of the mark; the detector emits them row
        // by row) bracket the mark, and the centroid of its grey level above the local
        // background is the measurement.
        lane.points.clear();
        lane.weights.clear();
        let mark_centres = cfg.track.mark_centres;
        if !mark_centres {
            // The paper's measurement: the inlier edge pixels, uniformly decimated (in row
            // order) down to max_points, spread over the rows and over both edges of a mark.
            // Every counted pixel was stored (the buffer holds the detector's whole capacity),
            // so the inliers are the histograms' bins within the bounds.
            let total = if self.scratch.len() < self.scratch.capacity() {
                hist.iter()
                    .zip(bounds)
                    .map(|(h, (lo, hi))| match usize::try_from(hi) {
                        Ok(hi) => h
                            .get(usize::from(lo)..=hi.min(2 * w_us))
                            .map_or(0, |b| b.iter().sum::<u32>()),
                        Err(_) => 0, // no bin
                    })
                    .sum::<u32>() as usize
            } else {
                self.scratch.iter().filter(|c| is_inlier(c)).count()
            };
            let inliers = self.scratch.iter().filter(|c| is_inlier(c));
            let point = Candidate::point;
            if total <= max_points {
                lane.points.extend(inliers.map(point));
            } else {
                // (The decimation's test hoisted out of the loop.)
                let mut decimation = Decimation::new(max_points, total);
                lane.points
                    .extend(inliers.filter(|_| decimation.keep()).map(point));
            }
        }
        let mut run: Option<(u16, u16, u16)> = None;
        let rows_out = self
            .scratch
            .iter()
            .filter(|c| mark_centres && is_inlier(c))
            .map(Some)
            .chain([None]);
        for c in rows_out {
            match (run, c) {
                (Some((row, lo, hi)), Some(c)) if c.row_px == row => {
                    run = Some((row, lo.min(c.col_px), hi.max(c.col_px)));
                }
                (prev, next) => {
                    if let Some((row, lo, hi)) = prev {
                        let y = f64::from(row);
                        let slope = 2.0 * coeffs[0] * y + coeffs[1];
                        if let Some((x, v)) = image
                            .row(usize::from(row))
                            .and_then(|pixels| mark_centre(pixels, lo, hi, slope))
                            && lane.points.len() < lane.points.capacity()
                        {
                            lane.points.push((x as f32, f32::from(row)));
                            lane.weights.push(1.0 / v);
                        }
                    }
                    run = next.map(|c| (c.row_px, c.col_px, c.col_px));
                }
            }
        }
        // Mark centres: uniform decimation over the rows down to max_points (frames taller
        // than the limit).
        let total = lane.points.len();
        if mark_centres && total > max_points {
            let mut k = 0;
            let mut decimation = Decimation::new(max_points, total);
            for j in 0..total {
                if decimation.keep() {
                    lane.points[k] = lane.points[j];
                    lane.weights[k] = lane.weights[j];
                    k += 1;
                }
            }
            lane.points.truncate(k);
            lane.weights.truncate(k);
        }
    }
}

#[cfg(test)]
mod tests;
