//! # A frame's exposure: its median grey and a gain
//!
//! **The measure.** The median grey of the rows asked for (a histogram of every other pixel of
//! every other row, as the noise estimate reads them; the smallest level with at least half the
//! pixels counted at or below it). On a road or a floor most of
//! the rows searched are the surface itself, so the median is the surface's grey — the camera's
//! exposure of it — and a mark, a shadow or a car move it little.
//!
//! **The gain.** A frame exposed `g` times darker has every grey difference, and so every
//! gradient, `g` times smaller; multiplying its grey levels by `g` gives them back, up to the
//! levels lost to rounding when it was recorded:
//!
//! ```text
//! out = min(255, ⌊gain · I + 1/2⌋)     (a table of the 256 levels, gain ≥ 1)
//! ```
//!
//! Noise is multiplied by the same `gain`; its estimate ([`crate::noise_sigma_grey`]) is taken
//! before the gain, so a caller compares `gain · σ̂` with its own noise limit.

use crate::noise::median;
use crate::resample::check;
use crate::{GradientError, GreyImage};

/// The median grey of `image`'s rows `[first, end)` (clamped to the frame), counting every other
/// pixel of every other row (from `first`) in `hist` (cleared first); `None` when the rows hold
/// no pixel.
pub fn median_grey(
    image: &GreyImage<'_>,
    (first, end): (usize, usize),
    hist: &mut [u32; 256],
) -> Option<u8> {
    hist.fill(0);
    let mut n = 0usize;
    for y in (first..end.min(image.height())).step_by(2) {
        let Some(row) = image.row(y) else { continue };
        for &v in row.iter().step_by(2) {
            hist[usize::from(v)] += 1;
            n += 1;
        }
    }
    // The median of 8-bit levels is one.
    (n > 0).then(|| median(hist, n) as u8)
}

/// `out` = `image` multiplied by `gain` (module docs) over the rows `[top, end)` (clamped to the
/// frame); `out` is `width` a row and must hold `end` rows, else
/// [`GradientError::BufferTooSmall`] and nothing is written. Other rows are left as they are.
pub fn brighten(
    image: &GreyImage<'_>,
    (top, end): (usize, usize),
    gain: f64,
    out: &mut [u8],
) -> Result<(), GradientError> {
    let (w, h) = (image.width(), image.height());
    let end = end.min(h);
    check("out", out.len(), end.saturating_mul(w))?;
    let table = gain_table(gain);
    for y in top..end {
        let Some(row) = image.row(y) else { continue };
        for (o, &v) in out[y * w..(y + 1) * w].iter_mut().zip(row) {
            *o = table[usize::from(v)];
        }
    }
    Ok(())
}

/// `pixels` multiplied by `gain` where they are (module docs).
pub fn brighten_in_place(pixels: &mut [u8], gain: f64) {
    let table = gain_table(gain);
    for v in pixels {
        *v = table[usize::from(*v)];
    }
}

/// The 256 levels multiplied by `gain`, rounded half up and clamped to 0..=255 (a gain that is
/// not a finite number leaves them as they are).
fn gain_table(gain: f64) -> [u8; 256] {
    let gain = if gain.is_finite() { gain.max(0.0) } else { 1.0 };
    // Clamped to 0..=255 before the conversion.
    std::array::from_fn(|v| (gain * v as f64 + 0.5).floor().min(255.0) as u8)
}

#[cfg(test)]
mod tests;
