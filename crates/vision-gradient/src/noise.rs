//! # A frame's noise: the estimate and the smoothing
//!
//! **The estimate.** The mask `N = [1 −2 1; −2 4 −2; 1 −2 1]` cancels every linear ramp of grey,
//! so on a smooth scene `I ∗ N` is mostly the noise; for independent noise of σ it has
//! σ·‖N‖₂ = 6σ, and its absolute value's median is `0.6745 · 6σ` (Immerkær's estimator, with the
//! median instead of the mean so that the scene's edges, a minority of the pixels, do not count):
//!
//! ```text
//! σ̂ = median |I ∗ N| / (6 · 0.6745)   over every other pixel of every other row asked for.
//! ```
//!
//! **The smoothing.** The 3 × 3 binomial `B = [1 2 1]ᵀ[1 2 1]/16` keeps `Σw² = (6/16)² = 0.14` of
//! independent noise's variance (σ × 0.375) and 3/4 of a step edge's Sobel magnitude (the
//! smoothed central difference `[−1 −2 0 2 1]/4` sums to 3/4 either side). In integers: with `S`
//! the mask's sum (clamped to the frame: its border rows and columns repeat their neighbour),
//! `(S + 8)/16`, rounded half up.

use crate::resample::check;
use crate::{GradientError, GreyImage};

/// `median |I ∗ N| = NOISE_MEDIAN_PER_SIGMA · σ` for independent Gaussian noise (`0.6745 · 6`).
pub const NOISE_MEDIAN_PER_SIGMA: f64 = 0.6745 * 6.0;

/// σ̂ of `image`'s rows `[first, end)` (those with a row above and below; every other pixel of
/// every other row), grey levels, counting `|I ∗ N|` in `hist` (cleared first); `None` when no
/// pixel has all its neighbours (a frame or a band under 3 × 3 px).
pub fn noise_sigma_grey(
    image: &GreyImage<'_>,
    (first, end): (usize, usize),
    hist: &mut [u32; 256],
) -> Option<f64> {
    hist.fill(0);
    let (w, h) = (image.width(), image.height());
    let mut n = 0usize;
    for y in (first.max(1)..end.min(h.saturating_sub(1))).step_by(2) {
        let (Some(up), Some(mid), Some(down)) = (image.row(y - 1), image.row(y), image.row(y + 1))
        else {
            continue;
        };
        for x in (1..w.saturating_sub(1)).step_by(2) {
            let p = |r: &[u8], c: usize| i32::from(r[c]);
            let corners = p(up, x - 1) + p(up, x + 1) + p(down, x - 1) + p(down, x + 1);
            let sides = p(up, x) + p(mid, x - 1) + p(mid, x + 1) + p(down, x);
            let laplacian = corners - 2 * sides + 4 * p(mid, x);
            hist[laplacian.unsigned_abs().min(255) as usize] += 1;
            n += 1;
        }
    }
    (n > 0).then(|| f64::from(median(hist, n)) / NOISE_MEDIAN_PER_SIGMA)
}

/// `out` = `image` smoothed by `B` (module docs) over the rows `[top, end)` (clamped to the
/// frame), the vertical sums in `sums`; `out` and `sums` are `width` a row and must hold `end`
/// rows, else [`GradientError::BufferTooSmall`] and nothing is written. Other rows are left as
/// they are.
pub fn smooth_binomial(
    image: &GreyImage<'_>,
    (top, end): (usize, usize),
    sums: &mut [u16],
    out: &mut [u8],
) -> Result<(), GradientError> {
    let (w, h) = (image.width(), image.height());
    let end = end.min(h);
    check("out", out.len(), end.saturating_mul(w))?;
    check("sums", sums.len(), end.saturating_mul(w))?;
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
    Ok(())
}

/// The smallest value with at least half of the `n` counted values at or below it.
pub(crate) fn median(hist: &[u32], n: usize) -> u32 {
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
