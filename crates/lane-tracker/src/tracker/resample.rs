//! # Resampling by any factor (module `working`'s fractional scale)
//!
//! The working frame is the input resampled by `s` input pixels per working pixel along both
//! axes, `s` any positive real (module `working`). Working pixel `j` of an axis stands for the
//! input interval `[s·j, s·(j + 1))` (input pixel `i` covering `[i, i + 1)`), centred on input
//! coordinate `x_j = s·j + (s − 1)/2`, the pixel-centre convention the coefficient map of
//! module `working` is derived in. Its value is a weighted sum of input pixels, separable:
//!
//! ```text
//! I'(c, r) = Σ_i Σ_k  w_x(c, i) · w_y(r, k) · I(i, k),        Σ_i w_x(c, i) = Σ_k w_y(r, k) = 1,
//! ```
//!
//! - **down** (`s ≥ 1`): the area average, `w(j, i) = |[i, i + 1) ∩ [s·j, s·(j + 1))| / s`: the
//!   box average of the integer factors generalised to a box `s` wide (a 512-px frame at the
//!   320-px working width averages 1.6 input pixels per working pixel, so no input pixel is
//!   skipped and none counts twice);
//! - **up** (`s < 1`, at most 2×): linear interpolation at `x_j`, `w = 1 − t` at `⌊x_j⌋` and `t`
//!   at `⌊x_j⌋ + 1` (`t = x_j − ⌊x_j⌋`), clamped to the edge pixels — the area weights would copy
//!   each input pixel into blocks.
//!
//! The taps of both axes are computed once for a frame size ([`AxisTaps::new`]); a frame then
//! costs one multiply-add per tap and pixel of the rows resampled, into caller-owned buffers.

/// The input pixels and weights behind each working pixel of one axis.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct AxisTaps {
    /// `first[j]`: the first input pixel of working pixel `j`; its taps are
    /// `weights[offset[j]..offset[j + 1]]`, for input pixels `first[j]`, `first[j] + 1`, ….
    first: Vec<usize>,
    offset: Vec<usize>,
    weights: Vec<f32>,
}

impl AxisTaps {
    /// The taps of `out_len` working pixels over `in_len` input pixels at `s` input pixels per
    /// working pixel (`s > 0`; module docs). Input pixels outside `[0, in_len)` are never read:
    /// their weight goes to the nearest pixel inside.
    pub(crate) fn new(in_len: usize, out_len: usize, s: f64) -> Self {
        let mut taps = AxisTaps {
            first: Vec::with_capacity(out_len),
            offset: Vec::with_capacity(out_len + 1),
            weights: Vec::new(),
        };
        taps.offset.push(0);
        let last = in_len.saturating_sub(1);
        for j in 0..out_len {
            let mut pixel_weights: Vec<(usize, f64)> = Vec::with_capacity(4);
            if s >= 1.0 {
                let (lo, hi) = (s * j as f64, s * (j + 1) as f64);
                let mut i = lo.floor().max(0.0) as usize;
                while (i as f64) < hi {
                    let overlap = (hi.min(i as f64 + 1.0) - lo.max(i as f64)).max(0.0);
                    if overlap > 0.0 {
                        pixel_weights.push((i.min(last), overlap / s));
                    }
                    i += 1;
                }
            } else {
                let x = s * j as f64 + (s - 1.0) / 2.0;
                let i0 = x.floor();
                let t = x - i0;
                let clamp = |v: f64| (v.max(0.0) as usize).min(last);
                pixel_weights.push((clamp(i0), 1.0 - t));
                pixel_weights.push((clamp(i0 + 1.0), t));
            }
            // Merge the clamped duplicates into a run of consecutive pixels.
            let first = pixel_weights.iter().map(|p| p.0).min().unwrap_or(0);
            let end = pixel_weights
                .iter()
                .map(|p| p.0 + 1)
                .max()
                .unwrap_or(first + 1);
            let total: f64 = pixel_weights.iter().map(|p| p.1).sum();
            let base = taps.weights.len();
            taps.weights.resize(base + (end - first), 0.0);
            for (i, w) in pixel_weights {
                // Renormalised: a sum of exactly 1 keeps a flat frame flat.
                taps.weights[base + i - first] += (w / total.max(f64::MIN_POSITIVE)) as f32;
            }
            taps.first.push(first);
            taps.offset.push(taps.weights.len());
        }
        taps
    }

    /// The first input pixel of working pixel `j` and its weights (empty past the end).
    fn of(&self, j: usize) -> (usize, &[f32]) {
        match (
            self.first.get(j),
            self.offset.get(j),
            self.offset.get(j + 1),
        ) {
            (Some(&first), Some(&a), Some(&b)) => (first, &self.weights[a..b]),
            _ => (0, &[]),
        }
    }
}

/// Resample working rows `rows = [first, end)` of `src` (`in_w × in_h`, row `k` at
/// `src[k·stride..]`) into `dst` (`cols.len()` bytes a row, row `r` at `r · cols.len()`) by the
/// taps of both axes, summing the input rows of each working row in `acc` (at least `in_w`
/// entries). Rows outside `rows`, and rows the buffers are too short for, are left as they are.
pub(crate) fn resample_rows(
    src: &vision_gradient::GreyImage<'_>,
    dst: &mut [u8],
    cols: &AxisTaps,
    row_taps: &AxisTaps,
    rows: (usize, usize),
    acc: &mut [f32],
) {
    let out_w = cols.first.len();
    for r in rows.0..rows.1 {
        let (first_row, weights) = row_taps.of(r);
        acc.fill(0.0);
        for (k, &wy) in weights.iter().enumerate() {
            let Some(line) = src.row(first_row + k) else {
                continue;
            };
            for (a, &v) in acc.iter_mut().zip(line) {
                *a += wy * f32::from(v);
            }
        }
        let Some(out) = dst.get_mut(r * out_w..(r + 1) * out_w) else {
            return;
        };
        for (c, o) in out.iter_mut().enumerate() {
            let (first_col, weights) = cols.of(c);
            let v: f32 = acc
                .get(first_col..first_col + weights.len())
                .map_or(0.0, |a| a.iter().zip(weights).map(|(a, w)| a * w).sum());
            // Rounded to the nearest grey level, within 0..=255 (a convex sum of bytes, up to
            // the rounding of `f32`).
            *o = (v + 0.5).clamp(0.0, 255.0) as u8;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use vision_gradient::GreyImage;

    #[test]
    fn every_working_pixels_weights_sum_to_one_and_stay_inside_the_input() {
        for (n, m) in [
            (512usize, 320usize),
            (1920, 320),
            (256, 320),
            (1640, 320),
            (3, 6),
        ] {
            let s = n as f64 / m as f64;
            let t = AxisTaps::new(n, m, s);
            for j in 0..m {
                let (first, w) = t.of(j);
                let sum: f32 = w.iter().sum();
                assert!((sum - 1.0).abs() < 1e-5, "{n}→{m}, pixel {j}: {sum}");
                assert!(first + w.len() <= n, "{n}→{m}, pixel {j}");
            }
        }
    }

    #[test]
    fn area_weights_spread_each_input_pixel_over_the_working_pixels_once() {
        // Down by 1.6: each input pixel's weights over all working pixels sum to 1/s (an input
        // pixel counted once, neither skipped nor twice).
        let (n, m) = (512usize, 320usize);
        let s = n as f64 / m as f64;
        let t = AxisTaps::new(n, m, s);
        let mut per_input = vec![0.0f64; n];
        for j in 0..m {
            let (first, w) = t.of(j);
            for (k, &wk) in w.iter().enumerate() {
                per_input[first + k] += f64::from(wk);
            }
        }
        for (i, v) in per_input.iter().enumerate() {
            assert!((v - 1.0 / s).abs() < 1e-5, "input {i}: {v}");
        }
    }

    #[test]
    fn a_ramp_keeps_its_centres_under_any_factor() {
        // A linear ramp I(x) = x resampled reads x_j = s·j + (s − 1)/2 at working pixel j (the
        // centre the coefficient map uses), away from the clamped edges: exactly for a whole
        // `s` and up; down by a fraction within a quarter pixel (the area average of
        // piecewise-constant pixels: [4.8, 6.4) reads 5.125 for 5.1) and exactly on average.
        for (n, m) in [(512usize, 320usize), (1280, 320), (256, 320), (1920, 320)] {
            let s = n as f64 / m as f64;
            let t = AxisTaps::new(n, m, s);
            let tol = if s.fract() == 0.0 || s < 1.0 {
                1e-3
            } else {
                0.25
            };
            let mut sum_err = 0.0;
            for j in 2..m - 2 {
                let (first, w) = t.of(j);
                let x: f64 = w
                    .iter()
                    .enumerate()
                    .map(|(k, &wk)| f64::from(wk) * (first + k) as f64)
                    .sum();
                let want = s * j as f64 + (s - 1.0) / 2.0;
                assert!((x - want).abs() < tol, "{n}→{m}, pixel {j}: {x} vs {want}");
                sum_err += x - want;
            }
            let mean_err = sum_err / (m - 4) as f64;
            assert!(mean_err.abs() < 1e-2, "{n}→{m}: mean error {mean_err}");
        }
    }

    #[test]
    fn a_flat_frame_stays_flat_and_only_the_rows_asked_for_are_written() {
        let (w, h) = (512usize, 288usize);
        let input = vec![137u8; w * h];
        let src = GreyImage::new(&input, w, h, w).expect("image");
        let s = w as f64 / 320.0;
        let (cols, rows) = (AxisTaps::new(w, 320, s), AxisTaps::new(h, 180, s));
        let mut dst = vec![9u8; 320 * 180];
        let mut acc = vec![0.0f32; w];
        resample_rows(&src, &mut dst, &cols, &rows, (100, 180), &mut acc);
        assert!(dst[..100 * 320].iter().all(|&v| v == 9));
        assert!(dst[100 * 320..].iter().all(|&v| v == 137));
    }

    #[test]
    fn an_integer_factor_is_the_box_average() {
        let (w, h) = (12usize, 8usize);
        let input: Vec<u8> = (0..w * h).map(|i| ((i * 37) % 256) as u8).collect();
        let src = GreyImage::new(&input, w, h, w).expect("image");
        let (cols, rows) = (AxisTaps::new(w, 6, 2.0), AxisTaps::new(h, 4, 2.0));
        let mut dst = vec![0u8; 24];
        let mut acc = vec![0.0f32; w];
        resample_rows(&src, &mut dst, &cols, &rows, (0, 4), &mut acc);
        for r in 0..4 {
            for c in 0..6 {
                let sum: u32 = [(0, 0), (0, 1), (1, 0), (1, 1)]
                    .iter()
                    .map(|&(i, j)| u32::from(input[(2 * r + j) * w + 2 * c + i]))
                    .sum();
                let mean = f64::from(sum) / 4.0;
                assert!(
                    (f64::from(dst[r * 6 + c]) - mean).abs() <= 0.5,
                    "({c}, {r})"
                );
            }
        }
    }
}
