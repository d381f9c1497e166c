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
//! **The estimate** is Immerkær's: σ̂ = median |I ∗ N| / (6 · 0.6745), `N` the 3 × 3 mask that
//! cancels every linear ramp of grey, over every other pixel of every other ROI row
//! (`vision_gradient::noise_sigma_grey`, where the maths is).
//!
//! On the labelled stills σ̂ is 0.5–2.5 grey levels for 80 % of the frames of every set (medians
//! 0.7–2.2); 19 of `seame`'s 90 textured floors read above 4 (up to 7.4); with σ = 8 added it
//! reads 8.2–8.9.
//!
//! **The remedy.** Above `denoise.above_noise_grey` the working frame is smoothed by the 3 × 3
//! binomial (`vision_gradient::smooth_binomial`), which keeps σ × 0.375 of independent noise and
//! 3/4 of a step edge's Sobel magnitude. Giving the step its magnitude back by stretching
//! the grey levels by 4/3 was measured and not kept: it pulled a dashed lane onto a road edge
//! beside it in its gaps (the rendered `noise` scene) and gained nothing overall on the real
//! stills (`docs/lanes/history/denoising.md`).
//!
//! **A brightened frame** (module `exposure`) has its noise multiplied by the gain: σ̂ is measured
//! on the frame as it came and `gain · σ̂` compared with the limit, on every frame with that
//! frame's gain (σ̂ is carried, the gain is not).
//!
//! **When.** Measured on every frame that starts with no lane estimate (a new scene: the frame
//! the road's bottom is placed on) and every [`REMEASURE_EVERY_FRAMES`] frames while lanes are
//! tracked, carried in between. A frame below the
//! limit and not brightened is tracked as it is, at the cost of the measurements; otherwise it is
//! written once into this stage's buffer (the rows any stage reads), smoothed then brightened,
//! which the stages then read instead.
//!
//! Decisions and figures: `docs/lanes/history/denoising.md`.

use serde::Serialize;
use vision_gradient::{GreyImage, brighten, brighten_in_place, noise_sigma_grey, smooth_binomial};

use super::setup::Rows;

/// Frames between two measurements while a lane is tracked.
pub(crate) const REMEASURE_EVERY_FRAMES: u32 = 30;

/// The last measurement of the frames' noise and what it does to them (`nav-app --json`'s
/// `noise`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct FrameNoise {
    /// Noise σ̂ of the rows searched, grey levels (0: not measured).
    pub sigma_grey: f64,
    /// Whether the frames are smoothed before the stages read them (σ̂, times the exposure's
    /// gain, above `denoise.above_noise_grey`).
    pub denoised: bool,
}

impl FrameNoise {
    /// Nothing measured, nothing done.
    pub const NONE: FrameNoise = FrameNoise {
        sigma_grey: 0.0,
        denoised: false,
    };
}

/// The stage: its limit, the histogram of a measurement and the buffers the frame as the stages
/// read it (smoothed, brightened) is written to.
#[derive(Debug)]
pub(super) struct Denoiser {
    /// `denoise.above_noise_grey` (0: never measured nor smoothed).
    above_noise_grey: f64,
    last: FrameNoise,
    frames_since_measured: u32,
    /// The exposure's gain on this frame.
    gain: f64,
    noise_hist: [u32; 256],
    /// The vertical binomial sums of the rows written, `width` a row.
    sums: Vec<u16>,
    /// The frame as the stages read it (smoothed, brightened), `width` a row.
    pixels: Vec<u8>,
}

impl Denoiser {
    /// The stage for `width × height` working frames, smoothing above `above_noise_grey`
    /// (0: never); `brightens`: whether the exposure stage may brighten them (the frame's buffer
    /// is then kept even when the noise is never measured).
    pub(super) fn new(above_noise_grey: f64, brightens: bool, width: usize, height: usize) -> Self {
        let smooths = above_noise_grey > 0.0;
        let size = |kept: bool| if kept { width * height } else { 0 };
        Denoiser {
            above_noise_grey,
            last: FrameNoise::NONE,
            frames_since_measured: 0,
            gain: 1.0,
            noise_hist: [0; 256],
            sums: vec![0; size(smooths)],
            pixels: vec![0; size(smooths || brightens)],
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
        self.gain = 1.0;
    }

    /// Measure `image` over `roi` when due: on a frame that starts with no lane estimate
    /// (`new_scene`), or [`REMEASURE_EVERY_FRAMES`] frames after the last measurement; and
    /// whether this frame, brightened by `gain` (the exposure stage's on this frame; 1: not
    /// brightened), is smoothed.
    pub(super) fn measure_if_due(
        &mut self,
        image: &GreyImage<'_>,
        roi: Rows,
        new_scene: bool,
        gain: f64,
    ) {
        self.gain = gain;
        if self.above_noise_grey <= 0.0 {
            return;
        }
        self.frames_since_measured += 1;
        if new_scene || self.frames_since_measured >= REMEASURE_EVERY_FRAMES {
            self.frames_since_measured = 0;
            self.last.sigma_grey =
                noise_sigma_grey(image, roi, &mut self.noise_hist).unwrap_or(0.0);
        }
        self.last.denoised = self.last.sigma_grey * gain > self.above_noise_grey;
    }

    /// The frame the stages read when the last measurements smooth or brighten it: `image`'s
    /// rows `rows` smoothed, then multiplied by the exposure's gain, into a buffer lent out of
    /// the stage (the other rows are stale; give it back with [`Self::put_back`]); `None`:
    /// `image` as it is.
    pub(super) fn frame_as_read(&mut self, image: &GreyImage<'_>, rows: Rows) -> Option<Vec<u8>> {
        let (w, h) = (image.width(), image.height());
        let brightened = self.gain > 1.0;
        if !(self.last.denoised || brightened) || self.pixels.len() != w * h {
            return None;
        }
        let mut out = std::mem::take(&mut self.pixels);
        let rows = (rows.0.min(h), rows.1.min(h));
        // The buffers hold `w × h` (checked above), all any rows need.
        let written = if self.last.denoised {
            smooth_binomial(image, rows, &mut self.sums, &mut out).map(|()| {
                if brightened {
                    brighten_in_place(&mut out[rows.0 * w..rows.1.max(rows.0) * w], self.gain);
                }
            })
        } else {
            brighten(image, rows, self.gain, &mut out)
        };
        if written.is_err() {
            self.pixels = out;
            return None;
        }
        Some(out)
    }

    /// The buffer [`Self::frame_as_read`] lent out, back.
    pub(super) fn put_back(&mut self, pixels: Vec<u8>) {
        self.pixels = pixels;
    }
}

#[cfg(test)]
mod tests;
