//! # vision-gradient — directional gradient, stage I of the lane tracker
//!
//! Pimentel & Hemerly's lane tracker (ITA; reading in `shared/docs/lanes.md`, §II, Fig. 1 and
//! Fig. 4 of the paper) starts every frame with a *directional gradient*: the pixels whose
//! gradient magnitude passes a threshold and whose edge is neither near-horizontal nor
//! near-vertical, split by the sign of the edge slope into left- and right-lane candidates.
//! The paper does not give the operator, the bands or the threshold rule; this crate's choices
//! are below.
//!
//! ## Coordinates
//! `x` = column (to the right), `y` = row (downward), both in pixels, origin at the top-left
//! pixel. `I(x, y)` is the 8-bit grey level.
//!
//! ## Operator: 3×3 Sobel, L1 magnitude
//! ```text
//! gx(x,y) = [I(x+1,y-1) + 2 I(x+1,y) + I(x+1,y+1)] - [I(x-1,y-1) + 2 I(x-1,y) + I(x-1,y+1)]
//! gy(x,y) = [I(x-1,y+1) + 2 I(x,y+1) + I(x+1,y+1)] - [I(x-1,y-1) + 2 I(x,y-1) + I(x+1,y-1)]
//! magnitude = |gx| + |gy|            (grey levels, 0 ..= 2040)
//! ```
//! An ideal axis-aligned step of `h` grey levels gives magnitude `4h`; an ideal 45° step gives
//! `6h` (`|gx| = |gy| = 3h`) on the two pixels beside it. The L1 norm is used instead of the
//! Euclidean one because it is exact in integers and vectorises; on the diagonal edges that
//! matter here it is `√2` times the Euclidean norm. The gradient is computed at interior pixels
//! only: row 0, the last row, column 0 and the last column are never candidates (they still
//! serve as neighbours).
//!
//! ## Orientation bands and lane classes
//! The edge runs perpendicular to the gradient, along `(−gy, gx)`. Its angle from the image
//! horizontal, `α ∈ [0°, 90°]`, satisfies `tan α = |gx| / |gy|`: `α = 0°` is a horizontal edge
//! (`gx = 0`), `α = 90°` a vertical one (`gy = 0`). A pixel is in the band iff
//! ```text
//! α ≥ α_min  ⇔  |gx|·cos α_min ≥ |gy|·sin α_min
//! α ≤ α_max  ⇔  |gx|·cos α_max ≤ |gy|·sin α_max
//! gx ≠ 0 and gy ≠ 0   (an exactly horizontal/vertical edge has no slope sign)
//! ```
//! evaluated in integers with `cos`, `sin` rounded to multiples of 2⁻¹⁴ (so the band edges are
//! exact to about 0.004°; no `atan` per pixel). `α_min = 0` ([`GradientParams::min_edge_angle_deg`])
//! and `α_max = 90` ([`GradientParams::max_edge_angle_deg`]) disable the respective limit.
//!
//! The band is applied to the *per-pixel* Sobel angle. On a real (sampled) edge that angle
//! spreads around the true one: pixels on the rim of the 3×3 response lean toward 45°
//! (measured on anti-aliased stripes: a true 8° edge gives per-pixel angles up to ~27°, a
//! true 86° edge down to ~77°). So a band edge is a soft cut: an out-of-band mark loses most,
//! not all, of its pixels (the tests assert ≥ 90 % for 6° and 87° marks with the 15°..80°
//! default); exactly axis-aligned edges lose all of them.
//!
//! Slope sign → lane. Along the edge direction `(dx, dy) = (−gy, gx)`, `dx·dy = −gx·gy`.
//! For a camera looking down the road the **left** lane mark runs from the bottom-left up
//! toward the centre: `x` increases as `y` decreases, `dx·dy < 0`, i.e. **`gx·gy > 0` →
//! [`EdgeClass::LeftLane`]**, and **`gx·gy < 0` → [`EdgeClass::RightLane`]**. Both edges of a
//! bright mark (dark→bright and bright→dark) flip both `gx` and `gy`, so they get the same class.
//! The class says which way the edge leans, not on which side of the image it lies; a curve or
//! a lane change can put a "left-leaning" edge right of centre.
//!
//! ## Threshold
//! * [`Threshold::Fixed`]: keep `magnitude ≥ min_magnitude` (`0` disables).
//! * [`Threshold::Adaptive`]: a first pass counts, in a 2048-bin histogram on the stack (no
//!   allocation), the magnitudes of all `N` pixels of the region that pass the orientation band
//!   (any magnitude). With `K = ⌈keep_fraction·N⌉`, the threshold is the largest `t` with
//!   `#{magnitude ≥ t} ≥ K` — the `(1 − keep_fraction)` quantile, ties kept — and then
//!   `max(t, min_magnitude)`. Only pixels with magnitude `≥ min_magnitude` are binned: the
//!   others count in `N` but cannot lift `t` above the floor. Scaling the image contrast by `c`
//!   scales every magnitude by `c`, so the threshold follows and the kept set stays about the
//!   same (tested at `c = 1` and `c = 0.3`); `min_magnitude` stops a featureless frame from
//!   keeping pure noise. It costs a second gradient pass plus the histogram (≈ 4–5× the fixed
//!   mode, see below).
//!
//! ## Region of interest
//! [`Region::Full`], [`Region::Rows`] (a half-open row range, e.g. below the horizon),
//! [`Region::Mask`] (`width·height` bytes, non-zero = inside) or [`Region::Spans`] (one column
//! span per row — the tracking mode: only the windows around the predicted parabola are
//! computed, call once per lane). The region restricts which pixels are candidates and which
//! enter the adaptive histogram; the 3×3 neighbours are always read from the real image.
//!
//! ## Output
//! Each kept pixel carries its column, row, magnitude, class and `gx`; with the magnitude and
//! the class that gives the whole gradient ([`EdgePixel::gradient`]: `|gy| = magnitude − |gx|`,
//! `gy` of `gx`'s sign for the left class and of the opposite sign for the right one), so the
//! edge direction is known without reading the image again ([`gradient_normal_deg`] folds it to
//! the Hough normal angle; tested equal to a Sobel recomputed from the image). Kept pixels go
//! into a caller-owned [`EdgeBuffer`] (fixed capacity, refilled every call, bottom
//! row first so truncation loses the far rows; truncation is reported) and, optionally, into a
//! caller `&mut [u8]` class image of `width·height` bytes (`0` none, `1` left, `2` right).
//!
//! ## Stripe pairing (an addition beyond the paper; [`keep_bright_stripes`])
//! Lane marks are bright stripes on a darker ground. Both sides of a stripe get the same class,
//! but opposite horizontal polarity: the left side rises (`gx > 0`, dark → bright to the
//! right), the right side falls. [`keep_bright_stripes`] keeps, row by row, only the pixels
//! that have a partner of the same class and the opposite polarity within `max_width_px`
//! columns on the correct side, i.e. the two sides of a bright stripe at most that wide along
//! the row. The dark seam beside a mark, tar joints, and the single edges of dark objects
//! (cars, kerbs, walls, shadows) then no longer vote. [`split_stripes`] is the weighting form:
//! it copies the bright-stripe pixels aside (to be counted more) and drops only the sides of
//! *dark* stripes, so a single step such as a kerb still counts. Both run after
//! [`GradientDetector::detect`] on its output (any region), read the Sobel `gx` the detector stored
//! with each pixel, scan its row neighbours, and allocate nothing.
//!
//! ## Periodic stripes (an addition beyond the paper; [`drop_periodic_stripes`])
//! A crosswalk's stripes, painted letters and a railing's bars are bright stripes along the road
//! like a mark, but they cross a row many times at a steady pitch, where a mark crosses it once
//! and a double line twice. [`drop_periodic_stripes`] drops the edge pixels of each chain of at
//! least [`PeriodicStripeParams::min_stripes`] stripes of like width and close spacing along a
//! row that a chain on an adjacent row confirms, on its row and the two beside it (the
//! module's docs give the rule and its known gap). It also runs on the detector's output and
//! allocates nothing.
//!
//! ## Resampling by any factor ([`resample_rows`], [`downscale_box`])
//! The tracker works on a frame of a fixed working width whatever the camera's: the input is
//! resampled by `s` input pixels per working pixel, any real `s` (area average down, linear
//! interpolation up), the taps of each axis computed once ([`AxisTaps`]) and the pixels written
//! into caller-owned buffers whose sizes are checked. The maths is in module `resample`.
//!
//! ## Noise ([`noise_sigma_grey`], [`smooth_binomial`])
//! Immerkær's noise estimate σ̂ of a frame's rows, and the 3 × 3 binomial smoothing the tracker
//! applies to frames far noisier than its grey-level settings assume; the maths is in module
//! `noise`.
//!
//! ## Defaults
//! [`GradientParams::default`]: band 15°..80°, fixed threshold 120 (a 45° step of 20 grey
//! levels). On the Udacity 320×240 frames (`shared/data/udacity`) this keeps both marks of the
//! ego lane in the lower half plus some clutter near the horizon; adaptive mode with
//! `keep_fraction = 0.05` chose thresholds of about 260–290 there and kept mostly the marks.
//!
//! ## Speed
//! The kernel is integer-only and written row-wise; it is compiled twice, portable and inside an
//! `#[target_feature(enable = "avx2")]` function chosen at run time with
//! `is_x86_feature_detected!` ([`Backend`]). No `-C target-cpu` flag is needed; both paths give
//! identical output (tested on seeded random images). Blocks of 16 pixels in which no pixel
//! reaches the threshold skip the band test. See `benches/gradient.rs`. Best-of-1000 timings on
//! the shared development machine (AMD EPYC, AVX2 and AVX-512 present, other builds running),
//! Udacity frame 0001 at 320×240, defaults, full frame: ≈ 36 µs AVX2, ≈ 80 µs portable;
//! adaptive (`keep_fraction = 0.05`) ≈ 120–170 µs AVX2.
//!
//! ## Deviations and gaps with respect to the paper
//! The paper (§II) names a directional gradient with a threshold and an optional adaptive
//! threshold but gives no operator, band or rule; everything above is this crate's choice.
//! Nothing printed in the paper is contradicted.
//!
//! ## Example
//! ```
//! use vision_gradient::{EdgeBuffer, EdgeClass, GradientDetector, GradientParams, GreyImage, Region};
//!
//! // 64×48 dark image with a bright 3-px stripe along x + y = 60 (a left-lane-like mark).
//! let (w, h) = (64usize, 48usize);
//! let mut data = vec![30u8; w * h];
//! for y in 0..h {
//!     for x in 0..w {
//!         if (x + y).abs_diff(60) <= 1 {
//!             data[y * w + x] = 200;
//!         }
//!     }
//! }
//! let image = GreyImage::new(&data, w, h, w)?;
//! let detector = GradientDetector::new(GradientParams::default())?;
//! let mut edges = EdgeBuffer::with_capacity(4096);
//! let stats = detector.detect(&image, Region::Full, &mut edges, None)?;
//! assert!(stats.left_count > 50);
//! assert_eq!(stats.right_count, 0);
//! assert!(edges.pixels().iter().all(|p| p.class == EdgeClass::LeftLane));
//! # Ok::<(), vision_gradient::GradientError>(())
//! ```

mod edges;
mod error;
mod exposure;
mod image;
mod kernel;
mod noise;
mod normal;
mod params;
mod periodic;
mod resample;
mod ridge;

pub use edges::{EdgeBuffer, EdgeClass, EdgePixel, EdgeStats};
pub use error::GradientError;
pub use exposure::{brighten, brighten_in_place, median_grey};
pub use image::{GreyImage, MAX_SIDE_PX};
pub use noise::{NOISE_MEDIAN_PER_SIGMA, noise_sigma_grey, smooth_binomial};
pub use normal::gradient_normal_deg;
pub use params::{GradientParams, Threshold};
pub use periodic::{PeriodicStripeParams, drop_periodic_stripes};
pub use resample::{AxisSpan, AxisTaps, downscale_box, resample_rows};
pub use ridge::{keep_bright_stripes, split_stripes};

use kernel::{Band, CheckedRegion, HIST_BINS, Sink};

/// Largest possible magnitude `|gx| + |gy|` (two Sobel responses of at most 4·255 each).
pub const MAX_MAGNITUDE: u16 = 2040;

/// Half-open column span `col_start_px .. col_end_px` of one row; `start == end` is empty.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ColSpan {
    /// First column, inclusive, pixels.
    pub col_start_px: u16,
    /// Last column, exclusive, pixels.
    pub col_end_px: u16,
}

impl ColSpan {
    /// The empty span.
    pub const EMPTY: Self = Self {
        col_start_px: 0,
        col_end_px: 0,
    };

    /// Span `col_start_px .. col_end_px` clipped to `0 .. width_px` (empty if nothing is left),
    /// for windows that may stick out of the image, e.g. around a predicted parabola.
    pub fn clamped(col_start_px: i64, col_end_px: i64, width_px: usize) -> Self {
        let w = i64::try_from(width_px.min(crate::MAX_SIDE_PX)).unwrap_or(0);
        let s = col_start_px.clamp(0, w);
        let e = col_end_px.clamp(0, w);
        if s >= e {
            return Self::EMPTY;
        }
        Self {
            col_start_px: s as u16,
            col_end_px: e as u16,
        }
    }
}

/// Which pixels are computed.
#[derive(Debug, Clone, Copy)]
pub enum Region<'a> {
    /// The whole image.
    Full,
    /// Rows `row_start_px .. row_end_px` (half-open), all columns.
    Rows {
        /// First row, inclusive.
        row_start_px: usize,
        /// Last row, exclusive (`<= height`).
        row_end_px: usize,
    },
    /// A `width·height` mask, row-major without padding; non-zero = inside.
    Mask(&'a [u8]),
    /// One column span per image row (`len == height`); only those pixels are computed.
    Spans(&'a [ColSpan]),
}

/// Code path of the kernel.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Backend {
    /// AVX2 if the running CPU has it, otherwise portable.
    Auto,
    /// Baseline instruction set (any target).
    Portable,
    /// x86-64 AVX2 (runtime-detected).
    Avx2,
}

fn avx2_available() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx2")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// Validated parameters plus the chosen code path. Cheap to build; build once, reuse per frame.
#[derive(Debug, Clone)]
pub struct GradientDetector {
    params: GradientParams,
    band: Band,
    backend: Backend,
}

impl GradientDetector {
    /// Validates `params` and picks the fastest backend the CPU supports.
    ///
    /// # Errors
    /// [`GradientError::InvalidParam`] from [`GradientParams::validate`].
    pub fn new(params: GradientParams) -> Result<Self, GradientError> {
        Self::with_backend(params, Backend::Auto)
    }

    /// Like [`GradientDetector::new`] with an explicit backend.
    ///
    /// # Errors
    /// [`GradientError::InvalidParam`], or [`GradientError::BackendUnavailable`] if
    /// [`Backend::Avx2`] is requested on a CPU/target without AVX2.
    pub fn with_backend(params: GradientParams, backend: Backend) -> Result<Self, GradientError> {
        params.validate()?;
        let backend = match backend {
            Backend::Auto if avx2_available() => Backend::Avx2,
            Backend::Auto | Backend::Portable => Backend::Portable,
            Backend::Avx2 if avx2_available() => Backend::Avx2,
            Backend::Avx2 => return Err(GradientError::BackendUnavailable { backend: "avx2" }),
        };
        let band = Band::from_degrees(params.min_edge_angle_deg, params.max_edge_angle_deg);
        Ok(Self {
            params,
            band,
            backend,
        })
    }

    /// The backend in use ([`Backend::Portable`] or [`Backend::Avx2`], never `Auto`).
    pub fn backend(&self) -> Backend {
        self.backend
    }

    /// The validated parameters.
    pub fn params(&self) -> &GradientParams {
        &self.params
    }

    /// Finds the lane-candidate pixels of `image` inside `region`.
    ///
    /// `edges` is cleared and refilled (never grown). If `class_image` is given it must hold
    /// `width·height` bytes; it is overwritten with `0` / `1` (left) / `2` (right).
    /// No allocation.
    ///
    /// # Errors
    /// [`GradientError::MaskSizeMismatch`], [`GradientError::RowRangeInvalid`],
    /// [`GradientError::SpansLengthMismatch`], [`GradientError::SpanOutOfRange`],
    /// [`GradientError::ClassImageSizeMismatch`]; nothing is written on error.
    pub fn detect(
        &self,
        image: &GreyImage<'_>,
        region: Region<'_>,
        edges: &mut EdgeBuffer,
        mut class_image: Option<&mut [u8]>,
    ) -> Result<EdgeStats, GradientError> {
        let checked = check_region(image, region)?;
        let expected = image.width() * image.height();
        if let Some(ci) = class_image.as_deref()
            && ci.len() != expected
        {
            return Err(GradientError::ClassImageSizeMismatch {
                len: ci.len(),
                expected,
            });
        }
        edges.clear();
        let (threshold, in_band_count) = match self.params.threshold {
            Threshold::Fixed { min_magnitude } => (min_magnitude, None),
            Threshold::Adaptive {
                keep_fraction,
                min_magnitude,
            } => {
                let mut hists = [[0u32; HIST_BINS]; 4];
                let mut sink = Sink::Histogram {
                    hists: &mut hists,
                    floor: min_magnitude,
                    in_band: 0,
                };
                self.run(image, checked, 0, &mut sink);
                let Sink::Histogram { in_band: total, .. } = sink else {
                    return Ok(EdgeStats::default());
                };
                let [mut hist, h1, h2, h3] = hists;
                for (((a, b), c), d) in hist.iter_mut().zip(h1).zip(h2).zip(h3) {
                    *a += b + c + d;
                }
                // Spare bins above MAX_MAGNITUDE parked the uncounted pixels (kernel::consume).
                hist[usize::from(MAX_MAGNITUDE) + 1..].fill(0);
                let t = upper_quantile(&hist, total, keep_fraction);
                (t.max(min_magnitude), Some(total))
            }
        };
        if let Some(ci) = class_image.as_deref_mut() {
            ci.fill(0);
        }
        let mut sink = Sink::Emit {
            edges,
            class_image,
            left: 0,
            right: 0,
        };
        let thr = i16::try_from(threshold).unwrap_or(i16::MAX);
        self.run(image, checked, thr, &mut sink);
        let Sink::Emit {
            edges, left, right, ..
        } = sink
        else {
            return Ok(EdgeStats::default());
        };
        Ok(EdgeStats {
            threshold_magnitude: threshold,
            in_band_count,
            left_count: left,
            right_count: right,
            stored: edges.len(),
            dropped: edges.dropped(),
        })
    }

    fn run(&self, image: &GreyImage<'_>, region: CheckedRegion<'_>, thr: i16, sink: &mut Sink<'_>) {
        match self.backend {
            #[cfg(target_arch = "x86_64")]
            Backend::Avx2 => {
                // SAFETY: `backend` is `Avx2` only if `is_x86_feature_detected!("avx2")` returned
                // true in `with_backend`, so the AVX2 instructions exist on this CPU.
                unsafe { kernel::pass_avx2(image, region, self.band, thr, sink) }
            }
            _ => kernel::pass_scalar(image, region, self.band, thr, sink),
        }
    }
}

/// Largest `t` with `#{m ≥ t} ≥ ⌈f·N⌉` among `N = total` pixels, of which `hist` holds those
/// at or above some floor; `0` if the histogram does not reach `⌈f·N⌉` (then `t` is below the
/// floor, which the caller applies) or `N = 0`.
fn upper_quantile(hist: &[u32; HIST_BINS], total: usize, keep_fraction: f64) -> u16 {
    if total == 0 {
        return 0;
    }
    let k = ((keep_fraction * total as f64).ceil() as usize).clamp(1, total);
    let mut acc = 0usize;
    for (m, &count) in hist.iter().enumerate().rev() {
        acc += count as usize;
        if acc >= k {
            return m as u16;
        }
    }
    0
}

fn check_region<'a>(
    image: &GreyImage<'_>,
    region: Region<'a>,
) -> Result<CheckedRegion<'a>, GradientError> {
    let (w, h) = (image.width(), image.height());
    match region {
        Region::Full => Ok(CheckedRegion::Full),
        Region::Rows {
            row_start_px,
            row_end_px,
        } => {
            if row_start_px >= row_end_px || row_end_px > h {
                return Err(GradientError::RowRangeInvalid {
                    row_start_px,
                    row_end_px,
                    height_px: h,
                });
            }
            Ok(CheckedRegion::Rows {
                start: row_start_px,
                end: row_end_px,
            })
        }
        Region::Mask(mask) => {
            if mask.len() != w * h {
                return Err(GradientError::MaskSizeMismatch {
                    len: mask.len(),
                    expected: w * h,
                });
            }
            Ok(CheckedRegion::Mask(mask))
        }
        Region::Spans(spans) => {
            if spans.len() != h {
                return Err(GradientError::SpansLengthMismatch {
                    len: spans.len(),
                    expected: h,
                });
            }
            for (row_px, s) in spans.iter().enumerate() {
                if s.col_start_px > s.col_end_px || usize::from(s.col_end_px) > w {
                    return Err(GradientError::SpanOutOfRange {
                        row_px,
                        col_start_px: s.col_start_px.into(),
                        col_end_px: s.col_end_px.into(),
                        width_px: w,
                    });
                }
            }
            Ok(CheckedRegion::Spans(spans))
        }
    }
}
