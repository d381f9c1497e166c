//! # The frame's noise (an addition beyond the paper; `denoise.above_noise_grey`)
//!
//! Every grey-level setting of the tracker — the gradient threshold
//! (`gradient.magnitude_threshold`), the stripe trace's and the reach's steps, the road's edge
//! step — is a number of grey levels tuned on frames with a few levels of sensor noise. A camera
//! with more gives other frames: noise of σ = 8 levels gives Sobel magnitudes `|gx| + |gy|` of
//! about 44 on a flat road (each Sobel component has σ·√12 ≈ 3.5σ), so a quarter of the road's
//! pixels pass a threshold of 60 and their votes drown the marks. This stage measures the noise
//! on the rows searched and, where it is far above what the settings assume, gives the stages a
//! working frame with less.
//!
//! **The estimate.** The mask `N = [1 −2 1; −2 4 −2; 1 −2 1]` cancels every linear ramp of grey,
//! so on a smooth scene `I ∗ N` is mostly the noise; for independent noise of σ it has
//! σ·‖N‖₂ = 6σ, and its absolute value's median is `0.6745 · 6σ` (Immerkær's estimator, with the
//! median instead of the mean so that the scene's edges, a minority of the pixels, do not count):
//!
//! ```text
//! σ̂ = median |I ∗ N| / (6 · 0.6745)   over every other pixel of every other ROI row.
//! ```
//!
//! On the labelled stills σ̂ is 0.5–2.5 grey levels for 80 % of the frames of every set (medians
//! 0.7–2.2); 19 of `seame`'s 90 textured floors read above 4 (up to 7.4); with σ = 8 added it
//! reads 8.2–8.9.
//!
//! **The remedy.** Above `denoise.above_noise_grey` the working frame is smoothed by the 3 × 3
//! binomial `B = [1 2 1]ᵀ[1 2 1]/16`, which keeps `Σw² = (6/16)² = 0.14` of independent noise's
//! variance (σ × 0.375) and 3/4 of a step edge's Sobel magnitude (the smoothed central difference
//! `[−1 −2 0 2 1]/4` sums to 3/4 either side). Giving the step its magnitude back by stretching
//! the grey levels by 4/3 was measured and not kept: it pulled a dashed lane onto a road edge
//! beside it in its gaps (the rendered `noise` scene) and gained nothing overall on the real
//! stills (`docs/lanes/history/denoising.md`).
//!
//! **When.** Measured on every frame that starts with no lane estimate (a new scene: the frame
//! the road's bottom is placed on) and every [`REMEASURE_EVERY_FRAMES`] frames while lanes are
//! tracked, carried in between. A frame below the limit is tracked as it is, at the cost of the
//! measurement; one above it is written once into this stage's buffer (the rows any stage reads),
//! which the stages then read instead.
//!
//! Decisions and figures: `docs/lanes/history/denoising.md`.

use serde::Serialize;
use vision_gradient::GreyImage;

use super::setup::Rows;

/// Frames between two measurements while a lane is tracked.
pub(crate) const REMEASURE_EVERY_FRAMES: u32 = 30;
/// `median |I ∗ N| = NOISE_MEDIAN_PER_SIGMA · σ` for independent Gaussian noise (`0.6745 · 6`).
const NOISE_MEDIAN_PER_SIGMA: f64 = 0.6745 * 6.0;

/// The last measurement of the frames' noise and what it does to them (`nav-app --json`'s
/// `noise`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct FrameNoise {
    /// Noise σ̂ of the rows searched, grey levels (0: not measured).
    pub sigma_grey: f64,
    /// Whether the frames are smoothed before the stages read them (σ̂ above
    /// `denoise.above_noise_grey`).
    pub denoised: bool,
}

impl FrameNoise {
    /// Nothing measured, nothing done.
    pub const NONE: FrameNoise = FrameNoise {
        sigma_grey: 0.0,
        denoised: false,
    };
}

/// The stage: its limit, the histogram of a measurement and the buffers the smoothed frame is
/// written to.
#[derive(Debug)]
pub(super) struct Denoiser {
    /// `denoise.above_noise_grey` (0: never measured nor smoothed).
    above_noise_grey: f64,
    last: FrameNoise,
    frames_since_measured: u32,
    noise_hist: Vec<u32>,
    /// The vertical binomial sums of the rows written, `width` a row.
    sums: Vec<u16>,
    /// The smoothed frame, `width` a row.
    pixels: Vec<u8>,
}

impl Denoiser {
    /// The stage for `width × height` working frames, smoothing above `above_noise_grey`
    /// (0: never).
    pub(super) fn new(above_noise_grey: f64, width: usize, height: usize) -> Self {
        let n = if above_noise_grey > 0.0 {
            width * height
        } else {
            0
        };
        Denoiser {
            above_noise_grey,
            last: FrameNoise::NONE,
            frames_since_measured: 0,
            noise_hist: vec![0; 256],
            sums: vec![0; n],
            pixels: vec![0; n],
        }
    }

    /// The last measurement and what it decided.
    pub(super) fn last(&self) -> FrameNoise {
        self.last
    }

    /// Forget the last measurement (a reset).
    pub(super) fn reset(&mut self) {
        self.last = FrameNoise::NONE;
        self.frames_since_measured = 0;
    }

    /// Measure `image` over `roi` when due: on a frame that starts with no lane estimate
    /// (`new_scene`), or [`REMEASURE_EVERY_FRAMES`] frames after the last measurement.
    pub(super) fn measure_if_due(&mut self, image: &GreyImage<'_>, roi: Rows, new_scene: bool) {
        if self.above_noise_grey <= 0.0 {
            return;
        }
        self.frames_since_measured += 1;
        if new_scene || self.frames_since_measured >= REMEASURE_EVERY_FRAMES {
            self.frames_since_measured = 0;
            self.measure(image, roi);
        }
    }

    /// σ̂ and the median grey of every other pixel of every other row of `roi` (those with a
    /// pixel on each side), and whether to smooth.
    fn measure(&mut self, image: &GreyImage<'_>, roi: Rows) {
        self.noise_hist.fill(0);
        let (w, h) = (image.width(), image.height());
        let mut n = 0usize;
        for y in (roi.0.max(1)..roi.1.min(h.saturating_sub(1))).step_by(2) {
            let (Some(up), Some(mid), Some(down)) =
                (image.row(y - 1), image.row(y), image.row(y + 1))
            else {
                continue;
            };
            for x in (1..w.saturating_sub(1)).step_by(2) {
                let p = |r: &[u8], c: usize| i32::from(r[c]);
                let corners = p(up, x - 1) + p(up, x + 1) + p(down, x - 1) + p(down, x + 1);
                let sides = p(up, x) + p(mid, x - 1) + p(mid, x + 1) + p(down, x);
                let laplacian = corners - 2 * sides + 4 * p(mid, x);
                self.noise_hist[laplacian.unsigned_abs().min(255) as usize] += 1;
                n += 1;
            }
        }
        if n == 0 {
            self.last = FrameNoise::NONE;
            return;
        }
        let sigma_grey = f64::from(median(&self.noise_hist, n)) / NOISE_MEDIAN_PER_SIGMA;
        self.last = FrameNoise {
            sigma_grey,
            denoised: sigma_grey > self.above_noise_grey,
        };
    }

    /// The frame the stages read when the last measurement smooths: `image`'s rows `rows`
    /// smoothed into a buffer lent out of the stage (the other rows are stale;
    /// give it back with [`Self::put_back`]); `None`: `image` as it is.
    pub(super) fn smoothed(&mut self, image: &GreyImage<'_>, rows: Rows) -> Option<Vec<u8>> {
        let (w, h) = (image.width(), image.height());
        if !self.last.denoised || self.pixels.len() != w * h {
            return None;
        }
        let mut out = std::mem::take(&mut self.pixels);
        let rows = (rows.0.min(h), rows.1.min(h));
        smooth(image, rows, &mut self.sums, &mut out);
        Some(out)
    }

    /// The buffer [`Self::smoothed`] lent out, back.
    pub(super) fn put_back(&mut self, pixels: Vec<u8>) {
        self.pixels = pixels;
    }
}

/// `out` = `image` smoothed by `B = [1 2 1]ᵀ[1 2 1]/16` over the rows `[top, end)`: with `S` the
/// integer sum of the mask (clamped to the frame: its border rows and columns repeat their
/// neighbour), `(S + 8)/16`, rounded half up, in integers (the inner columns vectorise). `sums`
/// and `out` hold `width × height`.
fn smooth(image: &GreyImage<'_>, (top, end): Rows, sums: &mut [u16], out: &mut [u8]) {
    let (w, h) = (image.width(), image.height());
    if w == 0 || h == 0 {
        return;
    }
    let round = |s: i32| ((s + 8) / 16).min(255) as u8;
    for y in top..end {
        let (Some(up), Some(mid), Some(down)) = (
            image.row(y.saturating_sub(1)),
            image.row(y),
            image.row((y + 1).min(h - 1)),
        ) else {
            continue;
        };
        let col = &mut sums[y * w..(y + 1) * w];
        for (((s, &a), &b), &c) in col.iter_mut().zip(up).zip(mid).zip(down) {
            *s = u16::from(a) + 2 * u16::from(b) + u16::from(c);
        }
        let o = &mut out[y * w..(y + 1) * w];
        let sum3 = |l: u16, c: u16, r: u16| i32::from(l) + 2 * i32::from(c) + i32::from(r);
        if w == 1 {
            o[0] = round(4 * i32::from(col[0]));
            continue;
        }
        o[0] = round(sum3(col[0], col[0], col[1]));
        o[w - 1] = round(sum3(col[w - 2], col[w - 1], col[w - 1]));
        for (((v, &l), &c), &r) in o[1..w - 1]
            .iter_mut()
            .zip(&col[..w - 2])
            .zip(&col[1..w - 1])
            .zip(&col[2..])
        {
            *v = round(sum3(l, c, r));
        }
    }
}

/// The smallest value with at least half of the `n` counted values at or below it.
fn median(hist: &[u32], n: usize) -> u32 {
    let k = n.div_ceil(2).max(1);
    let mut acc = 0usize;
    for (v, &count) in hist.iter().enumerate() {
        acc += count as usize;
        if acc >= k {
            return v as u32;
        }
    }
    hist.len().saturating_sub(1) as u32
}

#[cfg(test)]
mod tests;
