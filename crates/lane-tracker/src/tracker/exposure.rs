//! # The frame's exposure (an addition beyond the paper; `exposure.below_median_grey`)
//!
//! Every grey-level setting of the tracker — the gradient threshold
//! (`gradient.magnitude_threshold`), the stripe trace's and the reach's steps — is a number of
//! grey levels tuned on frames exposed as the labelled stills are. A camera that exposes its road
//! `g` times darker gives every mark's step, and so its Sobel magnitude, `g` times less: at half
//! the exposure a mark whose edge reads 90 falls under the threshold of 60 and is never seen.
//!
//! **The measure** is the median grey of the rows searched (`vision_gradient::median_grey`): on a
//! road or a floor, the surface's own grey. On the development parts of the labelled stills the
//! 10th percentile of each set's medians is 50 (`seame`), 51 (`culane`), 74, 110 and 118; the
//! medians of the whole stills run from 39 to 145.
//!
//! **The remedy.** A frame whose median lies under `exposure.below_median_grey` (default 50: the
//! darkest set's 10th percentile) is brightened by `gain = min(below_median_grey / median,
//! MAX_GAIN)` (`vision_gradient::brighten`) before the stages read it, which puts its median at
//! the limit — the edge of the exposures the settings were tuned on, not their middle: frames
//! inside that range are read as they are. Noise is brightened with the frame, so the noise
//! stage compares `gain · σ̂` with its own limit (module `denoise`). A frame brighter than the
//! stills is left as it is: its lost highlights cannot be given back, and scaling the stills'
//! own bright frames down lost as much as it gained (`docs/lanes/history/exposure.md`).
//!
//! **When.** On every frame (every other pixel of every other row: about 2 µs at 320 × 180).
//! A gain carried over frames, as the noise's verdict is, would brighten a bright frame that
//! follows dark ones (a tunnel's exit) for up to 30 frames. On a frame whose road's bottom
//! is looked for (module `road`), also before that, on the square view's rows: the road's edges
//! are then read as if brightened (their step divided by the gain), or an under-exposed road's
//! marks would read as a smooth bonnet.
//!
//! Decisions and figures: `docs/lanes/history/exposure.md`.

use serde::Serialize;
use vision_gradient::{GreyImage, median_grey};

use super::setup::Rows;

/// The largest gain: a frame at a quarter of the limit is brought to half of it (its grey levels
/// lost to rounding and its noise are multiplied too).
pub const MAX_EXPOSURE_GAIN: f64 = 2.0;

/// The last measurement of the frames' exposure and what it does to them (`nav-app --json`'s
/// `exposure`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct FrameExposure {
    /// Median grey of the rows searched, grey levels (0: not measured, or a black frame).
    pub median_grey: f64,
    /// The factor the frames' grey levels are multiplied by before the stages read them (1: read
    /// as they are).
    pub gain: f64,
}

impl FrameExposure {
    /// Nothing measured, nothing done.
    pub const NONE: FrameExposure = FrameExposure {
        median_grey: 0.0,
        gain: 1.0,
    };
}

/// The stage: its limit, the last measurement and the histogram of a measurement.
#[derive(Debug)]
pub(super) struct Exposure {
    /// `exposure.below_median_grey` (0: never measured nor brightened).
    below_median_grey: f64,
    last: FrameExposure,
    hist: [u32; 256],
}

impl Exposure {
    /// The stage brightening frames whose median grey is below `below_median_grey` (0: never).
    pub(super) fn new(below_median_grey: f64) -> Self {
        Exposure {
            below_median_grey,
            last: FrameExposure::NONE,
            hist: [0; 256],
        }
    }

    /// Whether the stage may brighten a frame (its limit is not 0).
    pub(super) fn is_on(&self) -> bool {
        self.below_median_grey > 0.0
    }

    /// The last measurement and what it decided.
    pub(super) fn last(&self) -> FrameExposure {
        self.last
    }

    /// Forget the last measurement (a reset).
    pub(super) fn reset(&mut self) {
        self.last = FrameExposure::NONE;
    }

    /// Measure `image` over `roi` (module docs): the gain this frame is read with.
    pub(super) fn measure_frame(&mut self, image: &GreyImage<'_>, roi: Rows) {
        if self.is_on() {
            self.last = self.measure(image, roi);
        }
    }

    /// The gain `image` would be brightened by, measured over `roi` and not kept (the road's
    /// bottom is looked for before the working rows, and so the rows measured, are placed;
    /// 1 with the stage off).
    pub(super) fn gain_of(&mut self, image: &GreyImage<'_>, roi: Rows) -> f64 {
        if self.is_on() {
            self.measure(image, roi).gain
        } else {
            1.0
        }
    }

    /// The median grey of `image` over `roi` and its gain.
    fn measure(&mut self, image: &GreyImage<'_>, roi: Rows) -> FrameExposure {
        match median_grey(image, roi, &mut self.hist) {
            Some(median) => FrameExposure {
                median_grey: f64::from(median),
                gain: self.gain_for(f64::from(median)),
            },
            None => FrameExposure::NONE,
        }
    }

    /// The gain for a frame of median grey `median` (module docs).
    fn gain_for(&self, median: f64) -> f64 {
        if median >= self.below_median_grey {
            1.0
        } else if median <= 0.0 {
            MAX_EXPOSURE_GAIN
        } else {
            (self.below_median_grey / median).min(MAX_EXPOSURE_GAIN)
        }
    }
}

#[cfg(test)]
mod tests;
