//! The photometric perturbations' images: brightness, JPEG, noise and motion blur (the maths in
//! the module docs of [`super`]).

use lane_io::GreyFrame;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::geometry::from_vec;
use crate::BenchError;

/// Every grey level multiplied by `gain`, rounded and clamped.
pub(super) fn brightness(frame: &GreyFrame, gain: f64) -> GreyFrame {
    map(frame, |v| {
        (gain * f64::from(v)).round().clamp(0.0, 255.0) as u8
    })
}

/// `frame` encoded as a JPEG of `quality` and decoded, in memory; `name` names it in errors.
pub(super) fn jpeg(frame: &GreyFrame, quality: u8, name: &str) -> Result<GreyFrame, BenchError> {
    let (w, h) = (frame.width(), frame.height());
    let failed = |action, source| BenchError::Image {
        action,
        path: name.to_owned(),
        source,
    };
    let side = |v: usize| u32::try_from(v).unwrap_or(u32::MAX);
    let mut bytes = Vec::new();
    image::codecs::jpeg::JpegEncoder::new_with_quality(&mut bytes, quality)
        .encode(frame.data(), side(w), side(h), image::ExtendedColorType::L8)
        .map_err(|e| failed("encode as JPEG", e))?;
    let back = image::load_from_memory_with_format(&bytes, image::ImageFormat::Jpeg)
        .map_err(|e| failed("decode the JPEG of", e))?
        .to_luma8();
    Ok(from_vec(w, h, back.into_raw()))
}

/// `frame` plus Gaussian noise of standard deviation `sigma_grey` (≥ 0, finite), drawn from a
/// ChaCha8 generator seeded with `seed` (Box–Muller: two uniforms `u1 ∈ (0, 1]`, `u2 ∈ [0, 1)`
/// give `√(−2 ln u1)·cos(2π u2)`), rounded and clamped.
pub(super) fn noise(frame: &GreyFrame, sigma_grey: f64, seed: u64) -> GreyFrame {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    map(frame, |v| {
        let u1 = 1.0 - rng.random::<f64>();
        let u2 = rng.random::<f64>();
        let n = (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos();
        (f64::from(v) + sigma_grey * n).round().clamp(0.0, 255.0) as u8
    })
}

/// A horizontal box filter of `taps` (odd) along every row, the columns beyond the border
/// clamped to it; the mean rounded to the nearest level.
pub(super) fn box_blur_rows(frame: &GreyFrame, taps: usize) -> GreyFrame {
    let (w, h) = (frame.width(), frame.height());
    if w == 0 || taps <= 1 {
        return frame.clone();
    }
    let half = (taps / 2) as isize;
    let mut out = vec![0u8; w * h];
    for (src, dst) in frame.data().chunks_exact(w).zip(out.chunks_exact_mut(w)) {
        for (x, o) in dst.iter_mut().enumerate() {
            let sum: u32 = (-half..=half)
                .map(|k| {
                    let c = (x as isize + k).clamp(0, w as isize - 1) as usize;
                    u32::from(src[c])
                })
                .sum();
            *o = ((sum + taps as u32 / 2) / taps as u32) as u8;
        }
    }
    from_vec(w, h, out)
}

/// `f` applied to every pixel of `frame`, in row-major order.
fn map(frame: &GreyFrame, mut f: impl FnMut(u8) -> u8) -> GreyFrame {
    let data = frame.data().iter().map(|&v| f(v)).collect();
    from_vec(frame.width(), frame.height(), data)
}
