//! The per-pixel kernel and the frame pass, written once and compiled twice: as portable code
//! and inside an AVX2-enabled function (runtime-dispatched), so LLVM vectorises the same loop.

use crate::edges::{EdgeBuffer, EdgeClass, EdgePixel};
use crate::image::GreyImage;
use crate::{ColSpan, MAX_MAGNITUDE};

/// Fixed-point scale of the band constants (2^14).
pub(crate) const BAND_SCALE: f64 = 16384.0;

/// Columns processed per chunk (stack buffers, so any width works without allocation).
const CHUNK: usize = 512;

/// Number of histogram bins: one per magnitude value `0..=2040`.
pub(crate) const HIST_BINS: usize = MAX_MAGNITUDE as usize + 1;

/// Fixed-point orientation band: keep iff
/// `|gx|·cos_min ≥ |gy|·sin_min` (α ≥ α_min) and `|gx|·cos_max ≤ |gy|·sin_max` (α ≤ α_max),
/// constants rounded from `cos`/`sin` × 2^14.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Band {
    pub cos_min: i32,
    pub sin_min: i32,
    pub cos_max: i32,
    pub sin_max: i32,
}

impl Band {
    pub(crate) fn from_degrees(min_deg: f64, max_deg: f64) -> Self {
        let q = |v: f64| (v * BAND_SCALE).round() as i32;
        let (s0, c0) = min_deg.to_radians().sin_cos();
        let (s1, c1) = max_deg.to_radians().sin_cos();
        Self {
            cos_min: q(c0),
            sin_min: q(s0),
            cos_max: q(c1),
            sin_max: q(s1),
        }
    }
}

/// Region, already checked against the image size.
#[derive(Clone, Copy)]
pub(crate) enum CheckedRegion<'a> {
    Full,
    Rows { start: usize, end: usize },
    Mask(&'a [u8]),
    Spans(&'a [ColSpan]),
}

/// What a pass does with its kept pixels.
pub(crate) enum Sink<'s> {
    /// Count the magnitudes of kept pixels.
    Histogram(&'s mut [u32; HIST_BINS]),
    /// Store kept pixels, optionally paint the class image, count classes.
    Emit {
        edges: &'s mut EdgeBuffer,
        class_image: Option<&'s mut [u8]>,
        left: usize,
        right: usize,
    },
}

/// Sobel + band + threshold over one row segment. `up`, `mid`, `dn` hold columns
/// `c-1 ..= c+n` of three consecutive rows, `mag` and `cls` receive columns `c .. c+n`.
/// `cls` is 0 (dropped), 1 (left) or 2 (right); `mag` is `|gx| + |gy|`.
#[inline(always)]
fn kernel(up: &[u8], mid: &[u8], dn: &[u8], band: Band, thr: i16, mag: &mut [u16], cls: &mut [u8]) {
    let n = mag.len().min(cls.len());
    let w = n + 2;
    if up.len() < w || mid.len() < w || dn.len() < w {
        return;
    }
    let (up, mid, dn) = (&up[..w], &mid[..w], &dn[..w]);
    let (mag, cls) = (&mut mag[..n], &mut cls[..n]);
    for i in 0..n {
        let a = i16::from(up[i]);
        let b = i16::from(up[i + 1]);
        let c = i16::from(up[i + 2]);
        let d = i16::from(mid[i]);
        let f = i16::from(mid[i + 2]);
        let g = i16::from(dn[i]);
        let h = i16::from(dn[i + 1]);
        let k = i16::from(dn[i + 2]);
        // |gx|, |gy| <= 1020, |gx| + |gy| <= 2040: no i16 overflow.
        let gx = (c - a) + 2 * (f - d) + (k - g);
        let gy = (g + 2 * h + k) - (a + 2 * b + c);
        let ax = gx.abs();
        let ay = gy.abs();
        let m = ax + ay;
        let ax32 = i32::from(ax);
        let ay32 = i32::from(ay);
        // Products <= 1020 · 16384 < 2^31.
        let lo_ok = ax32 * band.cos_min >= ay32 * band.sin_min;
        let hi_ok = ax32 * band.cos_max <= ay32 * band.sin_max;
        let keep = lo_ok & hi_ok & (gx != 0) & (gy != 0) & (m >= thr);
        let right = u8::from((gx ^ gy) < 0);
        cls[i] = u8::from(keep) * (1 + right);
        mag[i] = m as u16;
    }
}

/// One pass over the image (rows bottom to top) with threshold `thr`.
#[inline(always)]
fn pass_impl(
    img: &GreyImage<'_>,
    region: CheckedRegion<'_>,
    band: Band,
    thr: i16,
    sink: &mut Sink<'_>,
) {
    let w = img.width();
    let h = img.height();
    if w < 3 || h < 3 {
        return;
    }
    let mut mag = [0u16; CHUNK];
    let mut cls = [0u8; CHUNK];
    for r in (1..h - 1).rev() {
        let (c0, c1) = match region {
            CheckedRegion::Full | CheckedRegion::Mask(_) => (1, w - 1),
            CheckedRegion::Rows { start, end } => {
                if r < start || r >= end {
                    continue;
                }
                (1, w - 1)
            }
            CheckedRegion::Spans(spans) => match spans.get(r) {
                Some(s) => (
                    usize::from(s.col_start_px).max(1),
                    usize::from(s.col_end_px).min(w - 1),
                ),
                None => continue,
            },
        };
        if c0 >= c1 {
            continue;
        }
        let (Some(up), Some(mid), Some(dn)) = (img.row(r - 1), img.row(r), img.row(r + 1)) else {
            continue;
        };
        let mut c = c0;
        while c < c1 {
            let n = CHUNK.min(c1 - c);
            let (m, k) = (&mut mag[..n], &mut cls[..n]);
            kernel(&up[c - 1..], &mid[c - 1..], &dn[c - 1..], band, thr, m, k);
            if let CheckedRegion::Mask(mask) = region {
                if let Some(mrow) = mask.get(r * w + c..r * w + c + n) {
                    for (kk, &mm) in k.iter_mut().zip(mrow) {
                        *kk &= 0u8.wrapping_sub(u8::from(mm != 0));
                    }
                }
            }
            consume(sink, r, c, m, k, w);
            c += n;
        }
    }
}

#[inline(always)]
fn consume(sink: &mut Sink<'_>, r: usize, c: usize, mag: &[u16], cls: &[u8], w: usize) {
    match sink {
        Sink::Histogram(hist) => {
            for (&k, &m) in cls.iter().zip(mag) {
                if k != 0 {
                    if let Some(bin) = hist.get_mut(usize::from(m)) {
                        *bin += 1;
                    }
                }
            }
        }
        Sink::Emit {
            edges,
            class_image,
            left,
            right,
        } => {
            if let Some(ci) = class_image {
                if let Some(dst) = ci.get_mut(r * w + c..r * w + c + cls.len()) {
                    dst.copy_from_slice(cls);
                }
            }
            let mut base = 0;
            for chunk in cls.chunks(8) {
                let any = chunk.iter().fold(0u8, |acc, &v| acc | v);
                if any != 0 {
                    for (j, &k) in chunk.iter().enumerate() {
                        if k != 0 {
                            let i = base + j;
                            let class = if k == 1 {
                                *left += 1;
                                EdgeClass::LeftLane
                            } else {
                                *right += 1;
                                EdgeClass::RightLane
                            };
                            edges.push(EdgePixel {
                                col_px: (c + i) as u16,
                                row_px: r as u16,
                                magnitude: mag.get(i).copied().unwrap_or(0),
                                class,
                            });
                        }
                    }
                }
                base += chunk.len();
            }
        }
    }
}

/// Portable pass (baseline instruction set).
pub(crate) fn pass_scalar(
    img: &GreyImage<'_>,
    region: CheckedRegion<'_>,
    band: Band,
    thr: i16,
    sink: &mut Sink<'_>,
) {
    pass_impl(img, region, band, thr, sink);
}

/// The same pass compiled with AVX2 enabled.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
pub(crate) fn pass_avx2(
    img: &GreyImage<'_>,
    region: CheckedRegion<'_>,
    band: Band,
    thr: i16,
    sink: &mut Sink<'_>,
) {
    pass_impl(img, region, band, thr, sink);
}
