//! The per-pixel kernel and the frame pass, written once and compiled twice: as portable code
//! and inside an AVX2-enabled function (runtime-dispatched), so LLVM vectorises the same loop.

use crate::edges::{EdgeBuffer, EdgeClass, EdgePixel};
use crate::image::GreyImage;
use crate::{ColSpan, MAX_MAGNITUDE};

/// Fixed-point scale of the band constants (2^14).
pub(crate) const BAND_SCALE: f64 = 16384.0;

/// Columns processed per chunk (stack buffers, so any width works without allocation).
const CHUNK: usize = 512;

/// Number of histogram bins: one per magnitude value `0..=2040`, rounded up to a power of two.
pub(crate) const HIST_BINS: usize = (MAX_MAGNITUDE as usize + 1).next_power_of_two();

/// First of four spare histogram bins (above any magnitude) that absorb uncounted pixels.
pub(crate) const SPARE_BIN: usize = MAX_MAGNITUDE as usize + 1;

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
    /// Count the kept pixels (`in_band`) and histogram the magnitudes of those at or above
    /// `floor` (four interleaved histograms, summed by the caller).
    Histogram {
        hists: &'s mut [[u32; HIST_BINS]; 4],
        floor: u16,
        in_band: usize,
    },
    /// Store kept pixels, optionally paint the class image, count classes.
    Emit {
        edges: &'s mut EdgeBuffer,
        class_image: Option<&'s mut [u8]>,
        left: usize,
        right: usize,
    },
}

/// Pixels per vector block of the kernel (16 × i16 = one AVX2 register).
const BLOCK: usize = 16;

/// Sobel responses `(gx, gy)` of one pixel from its 3×3 neighbourhood `[a, b, c, d, f, g, h, k]`
/// (`a b c / d · f / g h k`, row by row). `|gx|, |gy| <= 1020`, so `|gx| + |gy| <= 2040` fits
/// `i16`.
#[inline(always)]
fn sobel(neighbours: [u8; 8]) -> (i16, i16) {
    let [a, b, c, d, f, g, h, k] = neighbours.map(i16::from);
    let gx = (c - a) + 2 * (f - d) + (k - g);
    let gy = (g + 2 * h + k) - (a + 2 * b + c);
    (gx, gy)
}

/// The per-pixel decision: orientation band and magnitude threshold.
#[derive(Clone, Copy)]
struct Decision {
    band: Band,
    thr: i16,
}

impl Decision {
    /// Class 0 (dropped), 1 (left) or 2 (right) of a pixel with Sobel responses `gx`, `gy`.
    #[inline(always)]
    fn classify(self, gx: i16, gy: i16) -> u8 {
        let ax = gx.abs();
        let ay = gy.abs();
        let ax32 = i32::from(ax);
        let ay32 = i32::from(ay);
        // Products <= 1020 · 16384 < 2^31.
        let lo_ok = ax32 * self.band.cos_min >= ay32 * self.band.sin_min;
        let hi_ok = ax32 * self.band.cos_max <= ay32 * self.band.sin_max;
        let keep = lo_ok & hi_ok & (gx != 0) & (gy != 0) & (ax + ay >= self.thr);
        let right = u8::from((gx ^ gy) < 0);
        u8::from(keep) * (1 + right)
    }

    /// Magnitude `|gx| + |gy|`, class and `gx` of the pixel with these neighbours.
    #[inline(always)]
    fn pixel(self, neighbours: [u8; 8]) -> (u16, u8, i16) {
        let (gx, gy) = sobel(neighbours);
        ((gx.abs() + gy.abs()) as u16, self.classify(gx, gy), gx)
    }
}

/// The three image rows around a row segment, each from the column left of the segment on.
#[derive(Clone, Copy)]
struct Rows3<'r> {
    up: &'r [u8],
    mid: &'r [u8],
    dn: &'r [u8],
}

impl<'r> Rows3<'r> {
    /// Columns `i ..= i + BLOCK + 1` of the three rows: the neighbourhoods of segment pixels
    /// `i .. i + BLOCK`. `None` past the rows' end.
    #[inline(always)]
    fn block(self, i: usize) -> Option<[&'r [u8; BLOCK + 2]; 3]> {
        let at = |row: &'r [u8]| row.get(i..i + BLOCK + 2)?.try_into().ok();
        Some([at(self.up)?, at(self.mid)?, at(self.dn)?])
    }

    /// The 3×3 neighbourhood of segment pixel `i`. `None` past the rows' end.
    #[inline(always)]
    fn neighbours(self, i: usize) -> Option<[u8; 8]> {
        let (up, mid, dn) = (self.up, self.mid, self.dn);
        Some([
            *up.get(i)?,
            *up.get(i + 1)?,
            *up.get(i + 2)?,
            *mid.get(i)?,
            *mid.get(i + 2)?,
            *dn.get(i)?,
            *dn.get(i + 1)?,
            *dn.get(i + 2)?,
        ])
    }
}

/// The kernel's outputs over one row segment, one entry per pixel: magnitude, class (0, 1, 2)
/// and Sobel `gx`.
struct Outputs<'o> {
    mag: &'o mut [u16],
    cls: &'o mut [u8],
    gx: &'o mut [i16],
}

/// The outputs of one block of [`BLOCK`] pixels.
struct BlockOut<'o> {
    mag: &'o mut [u16; BLOCK],
    cls: &'o mut [u8; BLOCK],
    gx: &'o mut [i16; BLOCK],
}

impl Outputs<'_> {
    /// Pixels in the segment (the shortest output).
    fn len(&self) -> usize {
        self.mag.len().min(self.cls.len()).min(self.gx.len())
    }

    /// The outputs of pixels `i .. i + BLOCK`. `None` past the end.
    #[inline(always)]
    fn block(&mut self, i: usize) -> Option<BlockOut<'_>> {
        Some(BlockOut {
            mag: self.mag.get_mut(i..i + BLOCK)?.try_into().ok()?,
            cls: self.cls.get_mut(i..i + BLOCK)?.try_into().ok()?,
            gx: self.gx.get_mut(i..i + BLOCK)?.try_into().ok()?,
        })
    }
}

/// One fixed block of [`BLOCK`] pixels: fixed-size arrays, no remainder loop, so the block is
/// straight-line vector code. Blocks where no pixel reaches the threshold skip the band test.
#[inline(always)]
fn block([up, mid, dn]: [&[u8; BLOCK + 2]; 3], decision: Decision, out: BlockOut<'_>) {
    let mut gy = [0i16; BLOCK];
    let mut any = false;
    for i in 0..BLOCK {
        let (x, y) = sobel([
            up[i],
            up[i + 1],
            up[i + 2],
            mid[i],
            mid[i + 2],
            dn[i],
            dn[i + 1],
            dn[i + 2],
        ]);
        let m = x.abs() + y.abs();
        out.gx[i] = x;
        gy[i] = y;
        out.mag[i] = m as u16;
        any |= m >= decision.thr;
    }
    if any {
        for ((class, &x), &y) in out.cls.iter_mut().zip(out.gx.iter()).zip(&gy) {
            *class = decision.classify(x, y);
        }
    } else {
        *out.cls = [0; BLOCK];
    }
}

/// [`block`] at segment pixel `i` (no-op past the end, which the callers rule out). A plain
/// `fn`, not a closure, so it inherits the caller's target features when inlined.
#[inline(always)]
fn block_at(rows: Rows3<'_>, decision: Decision, out: &mut Outputs<'_>, i: usize) {
    if let (Some(rows), Some(out)) = (rows.block(i), out.block(i)) {
        block(rows, decision, out);
    }
}

/// Kernel over one row segment of `out.len()` pixels, `rows` holding its columns `c−1 ..= c+n`.
/// Full blocks first; the remainder is one more block ending at `n` (overlapping the previous
/// one, which recomputes identical values) or, for `n < BLOCK`, a per-pixel loop.
#[inline(always)]
fn kernel(rows: Rows3<'_>, decision: Decision, mut out: Outputs<'_>) {
    let n = out.len();
    if n >= BLOCK {
        let mut i = 0;
        while i + BLOCK <= n {
            block_at(rows, decision, &mut out, i);
            i += BLOCK;
        }
        if i < n {
            block_at(rows, decision, &mut out, n - BLOCK);
        }
        return;
    }
    for i in 0..n {
        let Some(neighbours) = rows.neighbours(i) else {
            return;
        };
        (out.mag[i], out.cls[i], out.gx[i]) = decision.pixel(neighbours);
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
    let decision = Decision { band, thr };
    let mut mag = [0u16; CHUNK];
    let mut cls = [0u8; CHUNK];
    let mut gxs = [0i16; CHUNK];
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
            let rows = Rows3 {
                up: &up[c - 1..],
                mid: &mid[c - 1..],
                dn: &dn[c - 1..],
            };
            kernel(
                rows,
                decision,
                Outputs {
                    mag: &mut mag[..n],
                    cls: &mut cls[..n],
                    gx: &mut gxs[..n],
                },
            );
            let (m, k, x) = (&mag[..n], &mut cls[..n], &gxs[..n]);
            if let CheckedRegion::Mask(mask) = region
                && let Some(mrow) = mask.get(r * w + c..r * w + c + n)
            {
                for (kk, &mm) in k.iter_mut().zip(mrow) {
                    *kk &= 0u8.wrapping_sub(u8::from(mm != 0));
                }
            }
            consume(sink, r, c, m, k, x, w);
            c += n;
        }
    }
}

#[inline(always)]
fn consume(sink: &mut Sink<'_>, r: usize, c: usize, mag: &[u16], cls: &[u8], gx: &[i16], w: usize) {
    match sink {
        Sink::Histogram {
            hists,
            floor,
            in_band,
        } => {
            // Count every in-band pixel; histogram only those at or above `floor` (the others
            // cannot move the threshold above the floor, they only count in N). Branch-free:
            // compact the magnitudes first, then scatter into four interleaved histograms
            // (breaks the store-to-load dependency on popular bins).
            *in_band += cls.iter().map(|&k| u32::from(k != 0)).sum::<u32>() as usize;
            // Pixels not to be counted go to spare bins 2041..=2044 (above MAX_MAGNITUDE,
            // cleared by the caller), rotated so no single bin forms a long dependency chain.
            let floor = *floor;
            let [h0, h1, h2, h3] = &mut **hists;
            let bin = |k: u8, m: u16, spare: usize| {
                let sel = (k != 0) & (m >= floor);
                // `& (HIST_BINS - 1)`: m <= 2040 < HIST_BINS; the mask only spares a bounds check.
                (if sel {
                    usize::from(m)
                } else {
                    SPARE_BIN + spare
                }) & (HIST_BINS - 1)
            };
            let mut kq = cls.chunks_exact(4);
            let mut mq = mag.chunks_exact(4);
            for (q, (k, m)) in kq.by_ref().zip(mq.by_ref()).enumerate() {
                let spare = q & 3;
                h0[bin(k[0], m[0], spare)] += 1;
                h1[bin(k[1], m[1], spare)] += 1;
                h2[bin(k[2], m[2], spare)] += 1;
                h3[bin(k[3], m[3], spare)] += 1;
            }
            for (&k, &m) in kq.remainder().iter().zip(mq.remainder()) {
                h0[bin(k, m, 0)] += 1;
            }
        }
        Sink::Emit {
            edges,
            class_image,
            left,
            right,
        } => {
            if let Some(ci) = class_image
                && let Some(dst) = ci.get_mut(r * w + c..r * w + c + cls.len())
            {
                dst.copy_from_slice(cls);
            }
            // No branch on the class (the classes alternate along a row: mispredicted often).
            let mut emit = |i: usize, k: u8| {
                let is_left = k == 1;
                *left += usize::from(is_left);
                *right += usize::from(!is_left);
                let class = if is_left {
                    EdgeClass::LeftLane
                } else {
                    EdgeClass::RightLane
                };
                edges.push(EdgePixel {
                    col_px: (c + i) as u16,
                    row_px: r as u16,
                    magnitude: mag.get(i).copied().unwrap_or(0),
                    class,
                    gx: gx.get(i).copied().unwrap_or(0),
                });
            };
            let mut chunks = cls.chunks_exact(16);
            let mut base = 0;
            for chunk in chunks.by_ref() {
                let word: [u8; 16] = chunk.try_into().unwrap_or([1; 16]);
                if u128::from_ne_bytes(word) != 0 {
                    for (j, &k) in chunk.iter().enumerate() {
                        if k != 0 {
                            emit(base + j, k);
                        }
                    }
                }
                base += 16;
            }
            for (j, &k) in chunks.remainder().iter().enumerate() {
                if k != 0 {
                    emit(base + j, k);
                }
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
