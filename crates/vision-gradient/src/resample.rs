//! # Resampling by any factor
//!
//! The lane tracker's working frame is its input resampled by `s` input pixels per working pixel
//! along each axis, `s` any positive real ([`AxisSpan`]; the tracker's `view` module derives its
//! coefficient maps in the same convention). Working pixel `j` of an axis stands for the
//! input interval `[start + s·j, start + s·(j + 1))` (input pixel `i` covering `[i, i + 1)`),
//! centred on input coordinate `x_j = start + s·j + (s − 1)/2`. Its value is a weighted sum of input pixels, separable:
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
//! The taps of both axes are computed once for a frame size ([`AxisTaps::new`]), the rows' again
//! when the road's rows change ([`AxisTaps::rebuild`], in place); a frame then costs one
//! multiply-add per tap and pixel of the rows resampled, into caller-owned buffers whose sizes
//! are checked ([`GradientError::BufferTooSmall`] names the buffer). A whole
//! factor on square pixels from the top-left is the box average, summed in integers
//! ([`downscale_box`]).

use crate::{GradientError, GreyImage};

/// One axis of a resampling: output pixel `j` stands for input `[start + s·j, start + s·(j + 1))`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AxisSpan {
    /// Input pixels per output pixel, > 0.
    pub scale: f64,
    /// Input coordinate of output pixel 0's leading edge, px.
    pub start_px: f64,
}

impl AxisSpan {
    /// The input coordinate of output pixel `j`'s centre, px: `start + s·j + (s − 1)/2`.
    pub fn centre_px(self, j: f64) -> f64 {
        self.start_px + self.scale * j + (self.scale - 1.0) / 2.0
    }
}

/// [`GradientError::BufferTooSmall`] unless `len ≥ required`.
pub(crate) fn check(
    buffer: &'static str,
    len: usize,
    required: usize,
) -> Result<(), GradientError> {
    if len < required {
        return Err(GradientError::BufferTooSmall {
            buffer,
            len,
            required,
        });
    }
    Ok(())
}

/// The input pixels and weights behind each working pixel of one axis.
#[derive(Debug, Clone, PartialEq)]
pub struct AxisTaps {
    /// `first[j]`: the first input pixel of working pixel `j`; its taps are
    /// `weights[offset[j]..offset[j + 1]]`, for input pixels `first[j]`, `first[j] + 1`, ….
    first: Vec<usize>,
    offset: Vec<usize>,
    weights: Vec<f32>,
}

impl AxisTaps {
    /// The taps of `out_len` working pixels over `in_len` input pixels under `map` (module
    /// docs), with room to be rebuilt ([`Self::rebuild`]) for maps of up to `max_scale` input
    /// pixels per working pixel without allocating.
    pub fn new(in_len: usize, out_len: usize, map: AxisSpan, max_scale: f64) -> Self {
        let per_pixel = max_scale.max(map.scale).ceil() as usize + 2;
        let mut taps = AxisTaps {
            first: Vec::with_capacity(out_len),
            offset: Vec::with_capacity(out_len + 1),
            weights: Vec::with_capacity(out_len * per_pixel),
        };
        taps.rebuild(in_len, out_len, map);
        taps
    }

    /// The taps for `map`, in the buffers there are. Input pixels outside `[0, in_len)` are
    /// never read: their weight goes to the nearest pixel inside.
    pub fn rebuild(&mut self, in_len: usize, out_len: usize, map: AxisSpan) {
        self.first.clear();
        self.offset.clear();
        self.weights.clear();
        self.offset.push(0);
        let last = in_len.saturating_sub(1) as f64;
        let clamp = |v: f64| v.clamp(0.0, last) as usize;
        let s = map.scale;
        for j in 0..out_len {
            let base = self.weights.len();
            if s >= 1.0 {
                let (lo, hi) = (
                    map.start_px + s * j as f64,
                    map.start_px + s * (j + 1) as f64,
                );
                // Every `i` of the loop has `⌊lo⌋ ≤ i < hi`, so `clamp(i)` lies in `[first, end)`.
                let (first, end) = (clamp(lo.floor()), clamp(hi.ceil() - 1.0) + 1);
                self.weights.resize(base + end.max(first + 1) - first, 0.0);
                let mut i = lo.floor();
                while i < hi {
                    let overlap = (hi.min(i + 1.0) - lo.max(i)).max(0.0);
                    if let Some(w) = self.weights.get_mut(base + clamp(i).saturating_sub(first)) {
                        *w += (overlap / s) as f32;
                    }
                    i += 1.0;
                }
                self.first.push(first);
            } else {
                let x = map.centre_px(j as f64);
                let t = x - x.floor();
                let (i0, i1) = (clamp(x.floor()), clamp(x.floor() + 1.0));
                self.weights.resize(base + i1 - i0 + 1, 0.0);
                self.weights[base] += (1.0 - t) as f32;
                self.weights[base + i1 - i0] += t as f32;
                self.first.push(i0);
            }
            // Renormalised: a sum of exactly 1 keeps a flat frame flat.
            let w = &mut self.weights[base..];
            let total: f32 = w.iter().sum();
            if total > 0.0 {
                w.iter_mut().for_each(|v| *v /= total);
            }
            self.offset.push(self.weights.len());
        }
    }

    /// The number of output pixels.
    pub fn len(&self) -> usize {
        self.first.len()
    }

    /// Whether there are no output pixels.
    pub fn is_empty(&self) -> bool {
        self.first.is_empty()
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
/// entries). Rows outside `rows` are left as they are; `dst` must hold `end` rows and `acc`
/// the input's width, else [`GradientError::BufferTooSmall`] and nothing is written.
pub fn resample_rows(
    src: &GreyImage<'_>,
    dst: &mut [u8],
    cols: &AxisTaps,
    row_taps: &AxisTaps,
    rows: (usize, usize),
    acc: &mut [f32],
) -> Result<(), GradientError> {
    let out_w = cols.first.len();
    check("dst", dst.len(), rows.1.saturating_mul(out_w))?;
    check("acc", acc.len(), src.width())?;
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
            break;
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
    Ok(())
}

/// Box-average rows `rows = [first, end)` of the working frame from `src` into `dst`
/// (`working_width` bytes a row, row `r` at `r · working_width`), summing the `f` input rows
/// of each working row column by column in `sums` (at least `f · working_width` entries;
/// `u32`), then each run of `f` sums. Rows outside `rows` are left as they are.
///
/// `dst` must hold `end` rows and `sums` `f · working_width` entries, else
/// [`GradientError::BufferTooSmall`] and nothing is written; input rows or columns
/// past `src`'s edge count as 0 (the caller checks the frame's size). The common factors are compiled for their constant `f` (the sums of a
/// run then vectorise).
pub fn downscale_box(
    factor: usize,
    src: &GreyImage<'_>,
    dst: &mut [u8],
    working_width: usize,
    rows: (usize, usize),
    sums: &mut [u32],
) -> Result<(), GradientError> {
    check("dst", dst.len(), rows.1.saturating_mul(working_width))?;
    check("sums", sums.len(), factor.saturating_mul(working_width))?;
    match factor {
        2 => box_rows::<2>(src, dst, working_width, rows, sums),
        3 => box_rows::<3>(src, dst, working_width, rows, sums),
        4 => box_rows::<4>(src, dst, working_width, rows, sums),
        5 => box_rows::<5>(src, dst, working_width, rows, sums),
        6 => box_rows::<6>(src, dst, working_width, rows, sums),
        f => box_rows_any(f, src, dst, working_width, rows, sums),
    }
    Ok(())
}

/// [`downscale_box`] for a constant factor `F` (the body inlined with `f = F`).
fn box_rows<const F: usize>(
    src: &GreyImage<'_>,
    dst: &mut [u8],
    working_width: usize,
    rows: (usize, usize),
    sums: &mut [u32],
) {
    box_rows_any(F, src, dst, working_width, rows, sums);
}

/// [`downscale_box`] for any factor `f`.
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
    let Some(sums) = sums.get_mut(..f * working_width) else {
        return;
    };
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

    fn square(s: f64) -> AxisSpan {
        AxisSpan {
            scale: s,
            start_px: 0.0,
        }
    }

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
            let t = AxisTaps::new(n, m, square(s), s);
            for j in 0..m {
                let (first, w) = t.of(j);
                let sum: f32 = w.iter().sum();
                assert!((sum - 1.0).abs() < 1e-5, "{n}→{m}, pixel {j}: {sum}");
                assert!(first + w.len() <= n, "{n}→{m}, pixel {j}");
            }
        }
    }

    #[test]
    fn taps_for_any_scale_and_start_stay_inside_and_sum_to_one() {
        // A lattice of scales and starts, the rows' views of a found road's bottom among them
        // (a scale of 1.0000000001 once put a tap one past its run).
        let (n, m) = (180usize, 172usize);
        let mut scales: Vec<f64> = (0..120).map(|k| 0.5 + 0.037 * k as f64).collect();
        scales.extend([1.0 + 1e-10, 1.0 - 1e-10, 180.0 / 172.0, 4.0 / 3.0]);
        for &s in &scales {
            for start in [0.0, -3.25, 7.5, 1e-9] {
                let t = AxisTaps::new(
                    n,
                    m,
                    AxisSpan {
                        scale: s,
                        start_px: start,
                    },
                    s,
                );
                for j in 0..m {
                    let (first, w) = t.of(j);
                    let sum: f32 = w.iter().sum();
                    assert!(
                        (sum - 1.0).abs() < 1e-4,
                        "s {s}, start {start}, pixel {j}: {sum}"
                    );
                    assert!(first + w.len() <= n, "s {s}, start {start}, pixel {j}");
                }
            }
        }
    }

    #[test]
    fn area_weights_spread_each_input_pixel_over_the_working_pixels_once() {
        // Down by 1.6: each input pixel's weights over all working pixels sum to 1/s (an input
        // pixel counted once, neither skipped nor twice).
        let (n, m) = (512usize, 320usize);
        let s = n as f64 / m as f64;
        let t = AxisTaps::new(n, m, square(s), s);
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
            let t = AxisTaps::new(n, m, square(s), s);
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
        let (cols, rows) = (
            AxisTaps::new(w, 320, square(s), s),
            AxisTaps::new(h, 180, square(s), s),
        );
        let mut dst = vec![9u8; 320 * 180];
        let mut acc = vec![0.0f32; w];
        resample_rows(&src, &mut dst, &cols, &rows, (100, 180), &mut acc).expect("buffers sized");
        assert!(dst[..100 * 320].iter().all(|&v| v == 9));
        assert!(dst[100 * 320..].iter().all(|&v| v == 137));
    }

    #[test]
    fn an_integer_factor_is_the_box_average() {
        let (w, h) = (12usize, 8usize);
        let input: Vec<u8> = (0..w * h).map(|i| ((i * 37) % 256) as u8).collect();
        let src = GreyImage::new(&input, w, h, w).expect("image");
        let (cols, rows) = (
            AxisTaps::new(w, 6, square(2.0), 2.0),
            AxisTaps::new(h, 4, square(2.0), 2.0),
        );
        let mut dst = vec![0u8; 24];
        let mut acc = vec![0.0f32; w];
        resample_rows(&src, &mut dst, &cols, &rows, (0, 4), &mut acc).expect("buffers sized");
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
        let (mut dst, mut acc) = (vec![9u8; 6], vec![0u32; 6]);
        downscale_box(2, &src, &mut dst, 3, (0, 2), &mut acc).expect("buffers sized");
        // (0+1+1+1)/4 = 0.75 → 1; 41/4 = 10.25 → 10; 1019/4 = 254.75 → 255;
        // 29/4 = 7.25 → 7; 1/4 → 0; 100/4 = 25.
        assert_eq!(dst, vec![1, 10, 255, 7, 0, 25]);
        // Only the rows asked for are written.
        let mut dst = vec![9u8; 6];
        downscale_box(2, &src, &mut dst, 3, (1, 2), &mut acc).expect("buffers sized");
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
            let (ww, wh) = (w / f, h / f);
            let (mut dst, mut sums) = (vec![0u8; ww * wh], vec![0u32; w]);
            downscale_box(f, &src, &mut dst, ww, (0, wh), &mut sums).expect("buffers sized");
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
    fn a_buffer_too_small_is_a_named_error_and_nothing_is_written() {
        let (w, h) = (64usize, 36usize);
        let input = vec![200u8; w * h];
        let src = GreyImage::new(&input, w, h, w).expect("image");
        let (cols, rows) = (
            AxisTaps::new(w, 32, square(2.0), 2.0),
            AxisTaps::new(h, 18, square(2.0), 2.0),
        );
        let mut short = vec![7u8; 32 * 17];
        let mut acc = vec![0.0f32; w];
        assert_eq!(
            resample_rows(&src, &mut short, &cols, &rows, (0, 18), &mut acc),
            Err(GradientError::BufferTooSmall {
                buffer: "dst",
                len: 32 * 17,
                required: 32 * 18
            })
        );
        assert!(short.iter().all(|&v| v == 7));
        let mut dst = vec![7u8; 32 * 18];
        let mut sums = vec![0u32; 63];
        assert_eq!(
            downscale_box(2, &src, &mut dst, 32, (0, 18), &mut sums),
            Err(GradientError::BufferTooSmall {
                buffer: "sums",
                len: 63,
                required: 64
            })
        );
        assert!(dst.iter().all(|&v| v == 7));
        let mut acc_short = vec![0.0f32; w - 1];
        assert!(matches!(
            resample_rows(&src, &mut dst, &cols, &rows, (0, 18), &mut acc_short),
            Err(GradientError::BufferTooSmall { buffer: "acc", .. })
        ));
    }
}
