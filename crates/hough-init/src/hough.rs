//! Restricted-angle Hough transform with a caller-owned, reusable accumulator.

use serde::{Deserialize, Serialize};

use crate::{AngleBand, HoughError, HoughParams, OrientedPoint, Parabola, PixelPoint, PointSet};

/// Largest accepted image side, pixels.
pub const MAX_IMAGE_SIDE_PX: usize = 1 << 14;
/// Points converted to centred `f32` coordinates at a time while voting.
const VOTE_CHUNK: usize = 256;

/// 1.5·2²³: adding it to an `f32` in `[0, 2²²)` leaves the value rounded to the nearest
/// integer in the low 22 mantissa bits.
const ROUND_MAGIC: f32 = 12_582_912.0;
// Every shifted ρ index stays below 2²²: rho_bins ≤ 2·(hypot(W/2, H/2)/Δρ + 2) + 1 with
// hypot(W/2, H/2) ≤ MAX_IMAGE_SIDE_PX and Δρ ≥ 0.1 px.
const _: () = assert!(MAX_IMAGE_SIDE_PX * 20 + 5 < 1 << 22);

/// Largest accepted accumulator, cells (`u32` each).
pub const MAX_ACCUMULATOR_CELLS: usize = 1 << 25;

/// Most votes one call may cast in all (points, or the sum of the weights of oriented points):
/// a cell, and a ρ 3-sum of one θ row, hold at most that many, and the 3×3 smoothed peak search
/// adds three such sums in a `u32`.
const MAX_VOTES: u32 = u32::MAX / 3;

/// A straight line in normal form `ρ = x·cos θ + y·sin θ` (x = column, y = row, pixels; origin
/// at the centre of the top-left pixel).
///
/// `θ ∈ [−π/2, π/2)` is the angle of the line's normal from the column axis towards the
/// (downward) row axis, equivalently the line's tilt from the image vertical (positive when its
/// top leans right, `/`). `ρ` is the signed distance of the origin's foot point, pixels.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HoughLine {
    /// Signed distance from the origin (top-left pixel centre), pixels.
    pub rho_px: f64,
    /// Normal angle θ, radians.
    pub theta_rad: f64,
    /// Raw votes in the peak accumulator cell (before smoothing / refinement).
    pub votes: u32,
}

impl HoughLine {
    /// θ in degrees.
    #[must_use]
    pub fn theta_deg(&self) -> f64 {
        self.theta_rad.to_degrees()
    }

    /// Signed perpendicular distance of `(col_px, row_px)` from the line, pixels:
    /// `x cos θ + y sin θ − ρ`.
    #[inline]
    #[must_use]
    pub fn signed_distance_px(&self, col_px: f64, row_px: f64) -> f64 {
        let (s, c) = self.theta_rad.sin_cos();
        col_px * c + row_px * s - self.rho_px
    }

    /// Column where the line crosses row `row_px`, pixels; `None` for a (numerically)
    /// horizontal line (`|cos θ| < 1e-12`).
    #[must_use]
    pub fn col_at_row(&self, row_px: f64) -> Option<f64> {
        let (s, c) = self.theta_rad.sin_cos();
        (c.abs() >= 1e-12).then(|| (self.rho_px - row_px * s) / c)
    }

    /// The line as a curve of the column by row, `x = ρ/cos θ − y·tan θ` (a [`Parabola`] with
    /// `a1 = 0`), with `|cos θ|`; `None` for a line within `min_cos` of horizontal
    /// (`|cos θ| < min_cos`) or non-finite coefficients.
    #[must_use]
    pub fn columns(&self, min_cos: f64) -> Option<(Parabola, f64)> {
        let (s, c) = self.theta_rad.sin_cos();
        let curve = Parabola {
            a1: 0.0,
            a2: -s / c,
            a3: self.rho_px / c,
        };
        (c.abs() >= min_cos && curve.a2.is_finite() && curve.a3.is_finite())
            .then_some((curve, c.abs()))
    }
}

/// Reusable Hough state for one image size: accumulator, cos/sin tables and a smoothing
/// scratch buffer. Built once; [`HoughWorkspace::find_line`] does not allocate.
///
/// θ bins: `θ_k = −90° + k·Δθ`, `k = 0 … n_θ − 1`, `n_θ = ⌈180°/Δθ⌉`. Votes are cast relative to
/// the image centre `((W−1)/2, (H−1)/2)` so the ρ range is the half-diagonal `±hypot(W/2, H/2)`;
/// the reported [`HoughLine`] is converted to the top-left origin.
#[derive(Clone)]
pub struct HoughWorkspace {
    width_px: usize,
    height_px: usize,
    params: HoughParams,
    center_col_px: f64,
    center_row_px: f64,
    theta_bins: usize,
    rho_bins: usize,
    /// Index of the ρ bin centred on ρ_c = 0.
    rho_zero_bin: usize,
    /// cos θ_k / Δρ.
    cos_over_step: Vec<f32>,
    /// sin θ_k / Δρ.
    sin_over_step: Vec<f32>,
    /// Votes, θ-major: `acc[k * rho_bins + r]`.
    acc: Vec<u32>,
    /// Three rows of ρ-direction 3-sums (ring buffer) and one zero row, for the 3×3 smoothing.
    ring: Vec<u32>,
    /// The 3×3-smoothed votes of the band being searched for several peaks, θ-major like
    /// `acc` (`take_peaks`).
    smoothed: Vec<u32>,
    /// Per θ bin of `smoothed`: its largest value (its position is looked for only in the row
    /// that wins, `peak_of_rows`: most rows are never a peak's, and the scan for the position
    /// was the dearer half of finding it).
    row_best: Vec<u32>,
    /// The oriented vote's runs of θ bins, `x`, `y` and votes of their point in three
    /// arrays, sorted by the run's first bin (`vote_oriented`), a ρ bin per run for one θ row,
    /// with the runs as `(point index, first bin − base)` in point order, the index of each
    /// first bin's runs and a cursor per bin; `run_x`, `run_y`, `run_votes`, `run_bins` and
    /// `run_keys` reserved by [`HoughWorkspace::reserve_oriented_points`].
    run_x: Vec<f32>,
    run_y: Vec<f32>,
    run_votes: Vec<u32>,
    run_bins: Vec<u32>,
    run_keys: Vec<(u32, u32)>,
    run_starts: Vec<u32>,
    run_next: Vec<u32>,
    /// The CPU has AVX2 (`is_x86_feature_detected!`, once in [`Self::new`]): the oriented vote
    /// and its peak search then run compiled for it (`vote_and_take_peaks`).
    #[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]
    avx2: bool,
    /// Runs of [`Self::vote_and_take_peaks_avx2`], for the test that the AVX2 path is taken.
    #[cfg(test)]
    avx2_runs: usize,
}

impl core::fmt::Debug for HoughWorkspace {
    /// Shape and parameters only (the accumulator itself can hold millions of cells).
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("HoughWorkspace")
            .field("width_px", &self.width_px)
            .field("height_px", &self.height_px)
            .field("params", &self.params)
            .field("theta_bins", &self.theta_bins)
            .field("rho_bins", &self.rho_bins)
            .finish_non_exhaustive()
    }
}

/// The ρ bin of the centred point `(x, y)` for a θ bin with `c = cos θ/Δρ`, `s = sin θ/Δρ`:
/// `round(x·c + y·s + offset)`, `offset` the bin of ρ = 0. Rounded to nearest by the float-magic
/// trick (branch-free, vectorises): for 0 ≤ v < 2²², the low mantissa bits of v + 1.5·2²³ are
/// round(v). The same rounding for every vote, plain or oriented.
#[inline(always)]
fn rho_bin(x: f32, y: f32, c: f32, s: f32, offset: f32) -> u32 {
    (x * c + y * s + offset + ROUND_MAGIC).to_bits() & 0x003F_FFFF
}

/// The number of points of a vote: 2 ..= `MAX_VOTES`.
fn check_number(count: usize) -> Result<(), HoughError> {
    if count > MAX_VOTES as usize {
        return Err(HoughError::TooManyPoints {
            found: count,
            limit: MAX_VOTES as usize,
        });
    }
    if count < 2 {
        return Err(HoughError::TooFewPoints {
            set: PointSet::Candidates,
            found: count,
            required: 2,
        });
    }
    Ok(())
}

/// The separations of [`HoughWorkspace::find_lines`]: finite and ≥ 0.
fn check_separation(sep_theta_deg: f64, sep_rho_px: f64) -> Result<(), HoughError> {
    for (field, value) in [("sep_theta_deg", sep_theta_deg), ("sep_rho_px", sep_rho_px)] {
        if !(value.is_finite() && value >= 0.0) {
            return Err(HoughError::InvalidParam {
                field,
                value,
                reason: "must be finite and >= 0",
            });
        }
    }
    Ok(())
}

impl HoughWorkspace {
    /// Build the workspace for `width_px × height_px` images.
    ///
    /// # Errors
    /// [`HoughError::InvalidParam`] from [`HoughParams::validate`];
    /// [`HoughError::InvalidImageSize`] for a zero side or one above [`MAX_IMAGE_SIDE_PX`];
    /// [`HoughError::AccumulatorTooLarge`] above [`MAX_ACCUMULATOR_CELLS`].
    pub fn new(width_px: usize, height_px: usize, params: HoughParams) -> Result<Self, HoughError> {
        params.validate()?;
        if width_px == 0 || height_px == 0 {
            return Err(HoughError::InvalidImageSize {
                width_px,
                height_px,
                reason: "both sides must be at least 1 px",
            });
        }
        if width_px > MAX_IMAGE_SIDE_PX || height_px > MAX_IMAGE_SIDE_PX {
            return Err(HoughError::InvalidImageSize {
                width_px,
                height_px,
                reason: "a side exceeds MAX_IMAGE_SIDE_PX (16384 px)",
            });
        }
        let theta_bins = (180.0 / params.theta_step_deg - 1e-9).ceil() as usize;
        let half_diag_px = (0.5 * width_px as f64).hypot(0.5 * height_px as f64);
        // One spare bin each side absorbs rounding at the image corners.
        let rho_zero_bin = (half_diag_px / params.rho_step_px).ceil() as usize + 1;
        let rho_bins = 2 * rho_zero_bin + 1;
        let cells = theta_bins.saturating_mul(rho_bins);
        if cells > MAX_ACCUMULATOR_CELLS {
            return Err(HoughError::AccumulatorTooLarge {
                theta_bins,
                rho_bins,
                limit: MAX_ACCUMULATOR_CELLS,
            });
        }
        #[cfg(target_arch = "x86_64")]
        let avx2 = std::arch::is_x86_feature_detected!("avx2");
        #[cfg(not(target_arch = "x86_64"))]
        let avx2 = false;
        let inv_step = 1.0 / params.rho_step_px;
        let (cos_over_step, sin_over_step) = (0..theta_bins)
            .map(|k| {
                let theta = (-90.0 + k as f64 * params.theta_step_deg).to_radians();
                let (s, c) = theta.sin_cos();
                ((c * inv_step) as f32, (s * inv_step) as f32)
            })
            .unzip();
        Ok(Self {
            width_px,
            height_px,
            params,
            center_col_px: 0.5 * (width_px as f64 - 1.0),
            center_row_px: 0.5 * (height_px as f64 - 1.0),
            theta_bins,
            rho_bins,
            rho_zero_bin,
            cos_over_step,
            sin_over_step,
            acc: vec![0; cells],
            ring: vec![0; 4 * rho_bins],
            smoothed: vec![0; cells],
            row_best: vec![0; theta_bins],
            run_x: Vec::new(),
            run_y: Vec::new(),
            run_votes: Vec::new(),
            run_bins: Vec::new(),
            run_keys: Vec::new(),
            run_starts: Vec::with_capacity(2 * theta_bins + 2),
            run_next: Vec::with_capacity(2 * theta_bins + 1),
            avx2,
            #[cfg(test)]
            avx2_runs: 0,
        })
    }

    /// Image width, pixels.
    #[must_use]
    pub fn width_px(&self) -> usize {
        self.width_px
    }

    /// Image height, pixels.
    #[must_use]
    pub fn height_px(&self) -> usize {
        self.height_px
    }

    /// Reserve room for [`Self::find_lines_oriented`] with up to `points` points, so that it
    /// does not allocate (without it, the first calls grow a buffer and keep it). The buffer
    /// holds at most two entries a point: of a point's window and its two copies 180° away,
    /// all three can meet a band only if the window covers the half circle, and that case
    /// votes without the buffer.
    pub fn reserve_oriented_points(&mut self, points: usize) {
        let runs = 2 * points;
        self.run_x.reserve(runs);
        self.run_y.reserve(runs);
        self.run_votes.reserve(runs);
        self.run_bins.reserve(runs);
        self.run_keys.reserve(runs);
    }

    /// The parameters the workspace was built with.
    #[must_use]
    pub fn params(&self) -> &HoughParams {
        &self.params
    }

    /// Accumulator shape `(θ bins over [−90°, 90°), ρ bins)`.
    #[must_use]
    pub fn accumulator_shape(&self) -> (usize, usize) {
        (self.theta_bins, self.rho_bins)
    }

    /// θ of bin `k`, degrees.
    fn theta_deg_of_bin(&self, k: f64) -> f64 {
        -90.0 + k * self.params.theta_step_deg
    }

    /// Inclusive θ-bin range `[k0, k1]` covered by `band`.
    ///
    /// # Errors
    /// [`HoughError::InvalidBand`] if the band is invalid or contains no bin centre.
    pub fn band_bins(&self, band: &AngleBand) -> Result<(usize, usize), HoughError> {
        band.validate()?;
        let step = self.params.theta_step_deg;
        let k0 = ((band.min_deg + 90.0) / step - 1e-9).ceil().max(0.0) as usize;
        let k1 = (((band.max_deg + 90.0) / step + 1e-9).floor() as usize).min(self.theta_bins - 1);
        if k0 > k1 {
            return Err(HoughError::InvalidBand {
                min_deg: band.min_deg,
                max_deg: band.max_deg,
                reason: "the band contains no θ bin centre (narrower than theta_step_deg)",
            });
        }
        Ok((k0, k1))
    }

    /// Vote every point into the θ bins of `band` and return the peak line.
    ///
    /// Each point votes once per θ bin, for the ρ bin nearest to `x_c cos θ + y_c sin θ`
    /// (centred coordinates). The peak is the maximum of the raw votes, or of their 3×3 box sum
    /// when `peak_smoothing` is on (cells outside the band do not contribute); ties go to the
    /// smallest θ, then the smallest ρ. With `subbin_refinement` the peak is refined along θ
    /// and ρ separately by a three-point parabola.
    ///
    /// # Errors
    /// [`HoughError::InvalidBand`]; [`HoughError::NonFinitePoint`];
    /// [`HoughError::PointOutsideImage`] for a point outside
    /// `[−0.5, W − 0.5] × [−0.5, H − 0.5]`; [`HoughError::TooFewPoints`] for fewer than 2 points.
    pub fn find_line<I>(&mut self, points: I, band: &AngleBand) -> Result<HoughLine, HoughError>
    where
        I: IntoIterator + Clone,
        I::Item: PixelPoint,
    {
        let (k0, k1) = self.vote_checked(points, band)?;
        let (k, r) = self.peak(k0, k1);
        Ok(self.refined_line(k, r, k0, k1))
    }

    /// The `out.len()` strongest, mutually separated lines of `points` in `band` (an addition
    /// beyond the paper, which takes the single best line): the peak of [`Self::find_line`],
    /// then repeatedly the next peak after the votes within `±sep_theta_deg` and `±sep_rho_px`
    /// of every line taken are cleared (non-maximum suppression), strongest first. Stops early
    /// when no vote is left. Returns the number of lines written. No allocation.
    ///
    /// # Errors
    /// As [`Self::find_line`]; [`HoughError::InvalidParam`] for a negative or non-finite
    /// separation.
    pub fn find_lines<I>(
        &mut self,
        points: I,
        band: &AngleBand,
        sep_theta_deg: f64,
        sep_rho_px: f64,
        out: &mut [HoughLine],
    ) -> Result<usize, HoughError>
    where
        I: IntoIterator + Clone,
        I::Item: PixelPoint,
    {
        check_separation(sep_theta_deg, sep_rho_px)?;
        let (k0, k1) = self.vote_checked(points, band)?;
        Ok(self.take_peaks(k0, k1, sep_theta_deg, sep_rho_px, out))
    }

    /// [`Self::find_lines`] with an **orientation-restricted vote** (an addition beyond the
    /// paper): each point votes only in the θ bins within `⌊tolerance_deg/Δθ⌋` bins of the bin
    /// nearest its own edge normal [`OrientedPoint::normal_deg`] (about `±tolerance_deg`, to half
    /// a bin; θ taken modulo 180°), instead of in every bin of the band. A straight mark's edge
    /// pixels share its normal and keep all their votes; the pixels of texture, of the jagged
    /// border of a mat or of a blob point every way and spread their votes over other lines, so
    /// a long mark stands out of clutter that would outvote it in the plain transform. With
    /// `tolerance_deg ≥ 90` every point votes in every bin of the band and the accumulator, hence
    /// the lines, equal [`Self::find_lines`]'s (tested, also with a θ step that does not divide
    /// 180°). The per-pixel Sobel angle spreads by several degrees about the true one, so the
    /// tolerance should not be much below ~10°.
    ///
    /// Each point casts [`OrientedPoint::votes`] votes per bin (in the accumulator, the same as
    /// repeating it; the minimum of two points counts points). The vote runs θ-major (each θ
    /// row takes the votes of the points whose window covers it, from one slice of the points
    /// sorted by their window's first bin; their ρ bins in a loop of their own, which
    /// vectorises, then the votes); it allocates nothing once
    /// [`Self::reserve_oriented_points`] has reserved room for as many points.
    ///
    /// # Errors
    /// As [`Self::find_lines`]; [`HoughError::InvalidParam`] for a `tolerance_deg` that is not
    /// finite and ≥ 0; [`HoughError::InvalidNormal`] naming the first point whose angle is not
    /// finite in `[−90°, 90°)`; [`HoughError::TooManyVotes`] when the votes of all points exceed
    /// a third of `u32::MAX` (the counters and the smoothed peak search).
    pub fn find_lines_oriented(
        &mut self,
        points: &[OrientedPoint],
        band: &AngleBand,
        tolerance_deg: f64,
        sep_theta_deg: f64,
        sep_rho_px: f64,
        out: &mut [HoughLine],
    ) -> Result<usize, HoughError> {
        check_separation(sep_theta_deg, sep_rho_px)?;
        if !(tolerance_deg.is_finite() && tolerance_deg >= 0.0) {
            return Err(HoughError::InvalidParam {
                field: "tolerance_deg",
                value: tolerance_deg,
                reason: "must be finite and >= 0",
            });
        }
        // One branch-free pass (it vectorises) tells whether any point fails a check; only
        // then are the points walked again for the first one that fails and its error.
        let valid = self.oriented_points_valid(points);
        if !valid
            && let Some((index, p)) = points
                .iter()
                .enumerate()
                .find(|(_, p)| !(p.normal_deg.is_finite() && (-90.0..90.0).contains(&p.normal_deg)))
        {
            return Err(HoughError::InvalidNormal {
                index,
                normal_deg: f64::from(p.normal_deg),
            });
        }
        let (k0, k1) = self.band_bins(band)?;
        if valid {
            check_number(points.len())?;
        } else {
            self.check_count(points.iter())?;
        }
        let votes: u64 = points.iter().map(|p| u64::from(p.votes)).sum();
        if votes > u64::from(MAX_VOTES) {
            return Err(HoughError::TooManyVotes {
                found: votes,
                limit: u64::from(MAX_VOTES),
            });
        }
        let separation = (sep_theta_deg, sep_rho_px);
        #[cfg(target_arch = "x86_64")]
        if self.avx2 {
            // SAFETY: `avx2` is true only where `is_x86_feature_detected!("avx2")` returned true
            // (`Self::new`), so this CPU executes the AVX2 instructions the function uses.
            return Ok(unsafe {
                self.vote_and_take_peaks_avx2(points, (k0, k1), tolerance_deg, separation, out)
            });
        }
        Ok(self.vote_and_take_peaks(points, (k0, k1), tolerance_deg, separation, out))
    }

    /// [`Self::vote_oriented`] then [`Self::take_peaks`]: the work of
    /// [`Self::find_lines_oriented`] once its input is checked. Both are inlined here and into
    /// [`Self::vote_and_take_peaks_avx2`], which compiles the same code for AVX2: the loops the compiler
    /// vectorises (the smoothing, the row maxima, the θ-major ρ bins) on 256-bit vectors. The same operations on the same values (integer sums, and `f32` products and sums
    /// in the same order, never fused): the same votes and peaks on either path.
    #[inline(always)]
    fn vote_and_take_peaks(
        &mut self,
        points: &[OrientedPoint],
        (k0, k1): (usize, usize),
        tolerance_deg: f64,
        (sep_theta_deg, sep_rho_px): (f64, f64),
        out: &mut [HoughLine],
    ) -> usize {
        self.vote_oriented(points, k0, k1, tolerance_deg);
        self.take_peaks(k0, k1, sep_theta_deg, sep_rho_px, out)
    }

    /// [`Self::vote_and_take_peaks`] compiled with AVX2 enabled.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn vote_and_take_peaks_avx2(
        &mut self,
        points: &[OrientedPoint],
        bins: (usize, usize),
        tolerance_deg: f64,
        separation: (f64, f64),
        out: &mut [HoughLine],
    ) -> usize {
        #[cfg(test)]
        {
            self.avx2_runs += 1;
        }
        self.vote_and_take_peaks(points, bins, tolerance_deg, separation, out)
    }

    /// The `out.len()` strongest peaks of θ bins `k0..=k1`, each followed by clearing the votes
    /// within the separation (non-maximum suppression); the number written.
    #[inline(always)]
    fn take_peaks(
        &mut self,
        k0: usize,
        k1: usize,
        sep_theta_deg: f64,
        sep_rho_px: f64,
        out: &mut [HoughLine],
    ) -> usize {
        let nr = self.rho_bins;
        // A separation wider than the accumulator clears all of it: clamped, so that the index
        // arithmetic below cannot overflow (a finite separation may saturate the cast).
        let dk =
            ((sep_theta_deg / self.params.theta_step_deg).round() as usize).min(self.theta_bins);
        let dr = ((sep_rho_px / self.params.rho_step_px).round() as usize).min(nr);
        let smoothing = self.params.peak_smoothing;
        if smoothing {
            for k in k0..=k1 {
                self.smooth_row(k, k0, k1);
            }
        }
        let mut n = 0;
        for slot in out.iter_mut() {
            let (k, r) = if smoothing {
                self.peak_of_rows(k0, k1)
            } else {
                self.peak_raw(k0, k1)
            };
            if self.score(k, r, k0, k1) <= 0.0 {
                break;
            }
            *slot = self.refined_line(k, r, k0, k1);
            n += 1;
            let (ka, kb) = (k.saturating_sub(dk).max(k0), (k + dk).min(k1));
            for kk in ka..=kb {
                let lo = kk * nr + r.saturating_sub(dr);
                let hi = kk * nr + (r + dr).min(nr - 1);
                self.acc[lo..=hi].fill(0);
            }
            // Clearing rows ka..=kb changes the 3×3 sums of one more row on each side only, and
            // of one more ρ cell on each side of the cleared ones.
            if smoothing {
                let (lo, hi) = (r.saturating_sub(dr + 1), (r + dr + 1).min(nr - 1));
                for kk in ka.saturating_sub(1).max(k0)..=(kb + 1).min(k1) {
                    self.resmooth_cells(kk, k0, k1, lo, hi);
                }
            }
        }
        n
    }

    /// Row `k` of `smoothed` (the 3×3 sums of `acc` over the θ bins `k0..=k1`, the bins
    /// outside the band and beyond the ρ ends counting as zero) and its entry of `row_best`.
    #[inline(always)]
    fn smooth_row(&mut self, k: usize, k0: usize, k1: usize) {
        let nr = self.rho_bins;
        // The θ-direction sum of the (up to) three rows first, into the ring's first row (a
        // scratch row here; `peak_smoothed` rewrites it), then its ρ-direction 3-sums: the
        // same integer sums as the 3×3 window, in two passes that vectorise.
        let column = &mut self.ring[..nr];
        column.copy_from_slice(&self.acc[k * nr..(k + 1) * nr]);
        for kk in [
            k.checked_sub(1).filter(|&kk| kk >= k0),
            (k < k1).then_some(k + 1),
        ]
        .into_iter()
        .flatten()
        {
            for (d, &s) in column.iter_mut().zip(&self.acc[kk * nr..(kk + 1) * nr]) {
                *d += s;
            }
        }
        let out = &mut self.smoothed[k * nr..(k + 1) * nr];
        hsum3(column, out);
        if nr == 1 {
            out[0] = column[0];
        }
        self.row_best[k] = row_max(out);
    }

    /// Cells `lo..=hi` of row `k` of `smoothed` recomputed after a suppression cleared votes
    /// under them, and the row's largest value kept up to date: the cleared votes only lower
    /// these sums, so while the largest of their old values stayed below the row's largest, a
    /// cell outside them holds it still; otherwise it is looked for again over the whole row.
    #[inline(always)]
    fn resmooth_cells(&mut self, k: usize, k0: usize, k1: usize, lo: usize, hi: usize) {
        let nr = self.rho_bins;
        let (ka, kb) = (k.saturating_sub(1).max(k0), (k + 1).min(k1));
        let mut lowered_max = 0u32;
        for i in lo..=hi {
            let (a, b) = (i.saturating_sub(1), (i + 1).min(nr - 1));
            let mut sum = 0u32;
            for kk in ka..=kb {
                sum += self.acc[kk * nr + a..=kk * nr + b].iter().sum::<u32>();
            }
            let cell = &mut self.smoothed[k * nr + i];
            lowered_max = lowered_max.max(*cell);
            *cell = sum;
        }
        if lowered_max >= self.row_best[k] {
            self.row_best[k] = row_max(&self.smoothed[k * nr..(k + 1) * nr]);
        }
    }

    /// The first largest cell of `smoothed` over the θ bins `k0..=k1` in scan order (θ, then
    /// ρ), from `row_best`: the cell `peak_smoothed` finds (`(k0, 0)` when every cell is 0).
    /// Only the winning row is scanned for the position.
    #[inline(always)]
    fn peak_of_rows(&self, k0: usize, k1: usize) -> (usize, usize) {
        let mut best = (0u32, k0);
        for k in k0..=k1 {
            let v = self.row_best[k];
            if v > best.0 {
                best = (v, k);
            }
        }
        let (v, k) = best;
        if v == 0 {
            return (k0, 0);
        }
        let nr = self.rho_bins;
        // `v` is the row's largest value (`row_best`), so it is found.
        let r = self.smoothed[k * nr..(k + 1) * nr]
            .iter()
            .position(|&c| c == v)
            .unwrap_or(0);
        (k, r)
    }

    /// Validate the points and their number (2 ..= `MAX_VOTES`): the checks of every vote.
    fn check_count<I>(&self, points: I) -> Result<(), HoughError>
    where
        I: IntoIterator,
        I::Item: PixelPoint,
    {
        check_number(self.check_points(points)?)
    }

    /// Whether every oriented point has a normal in `[−90°, 90°)` and passes
    /// [`Self::check_points`] (finite, inside the image with half a pixel to spare): the same
    /// tests in `f32`, without a branch (`W − ½` and `H − ½` are exact in `f32` for sides up
    /// to [`MAX_IMAGE_SIDE_PX`]; a NaN or an infinity fails a comparison).
    fn oriented_points_valid(&self, points: &[OrientedPoint]) -> bool {
        let col_max = self.width_px as f32 - 0.5;
        let row_max = self.height_px as f32 - 0.5;
        points.iter().fold(true, |ok, p| {
            ok & (p.normal_deg >= -90.0)
                & (p.normal_deg < 90.0)
                & (p.col_px >= -0.5)
                & (p.col_px <= col_max)
                & (p.row_px >= -0.5)
                & (p.row_px <= row_max)
        })
    }

    /// Check the band and the points, then vote; returns the band's θ bins `(k0, k1)`.
    fn vote_checked<I>(&mut self, points: I, band: &AngleBand) -> Result<(usize, usize), HoughError>
    where
        I: IntoIterator + Clone,
        I::Item: PixelPoint,
    {
        let (k0, k1) = self.band_bins(band)?;
        self.check_count(points.clone())?;
        self.vote(points, k0, k1);
        Ok((k0, k1))
    }

    /// The accumulator's peak cell in θ bins `k0..=k1` (raw or 3×3-smoothed votes).
    fn peak(&mut self, k0: usize, k1: usize) -> (usize, usize) {
        if self.params.peak_smoothing {
            self.peak_smoothed(k0, k1)
        } else {
            self.peak_raw(k0, k1)
        }
    }

    /// The line of peak cell `(k, r)`, sub-bin refined when `subbin_refinement` is on.
    fn refined_line(&self, k: usize, r: usize, k0: usize, k1: usize) -> HoughLine {
        let (dk, dr) = if self.params.subbin_refinement {
            self.refine(k, r, k0, k1)
        } else {
            (0.0, 0.0)
        };
        self.line_of(
            k as f64 + dk,
            r as f64 + dr,
            self.acc[k * self.rho_bins + r],
        )
    }

    /// The line of (fractional) bin `(k, r)`, top-left origin.
    fn line_of(&self, k: f64, r: f64, votes: u32) -> HoughLine {
        let theta_rad = self.theta_deg_of_bin(k).to_radians();
        let rho_c_px = (r - self.rho_zero_bin as f64) * self.params.rho_step_px;
        let (s, c) = theta_rad.sin_cos();
        HoughLine {
            rho_px: rho_c_px + self.center_col_px * c + self.center_row_px * s,
            theta_rad,
            votes,
        }
    }

    /// Validate every point; returns their number.
    fn check_points<I>(&self, points: I) -> Result<usize, HoughError>
    where
        I: IntoIterator,
        I::Item: PixelPoint,
    {
        let mut count = 0;
        let col_max = self.width_px as f64 - 0.5;
        let row_max = self.height_px as f64 - 0.5;
        for (index, p) in points.into_iter().enumerate() {
            count += 1;
            let (x, y) = (p.col_px(), p.row_px());
            if !(x.is_finite() && y.is_finite()) {
                return Err(HoughError::NonFinitePoint {
                    index,
                    col_px: x,
                    row_px: y,
                });
            }
            if !((-0.5..=col_max).contains(&x) && (-0.5..=row_max).contains(&y)) {
                return Err(HoughError::PointOutsideImage {
                    index,
                    col_px: x,
                    row_px: y,
                    width_px: self.width_px,
                    height_px: self.height_px,
                });
            }
        }
        Ok(count)
    }

    fn vote<I>(&mut self, points: I, k0: usize, k1: usize)
    where
        I: IntoIterator,
        I::Item: PixelPoint,
    {
        let nr = self.rho_bins;
        let cx = self.center_col_px;
        let cy = self.center_row_px;
        // All shifted values are positive: |ρ_c/Δρ| ≤ rho_zero_bin − 1 for in-image points.
        let offset = self.rho_zero_bin as f32;
        self.acc[k0 * nr..(k1 + 1) * nr].fill(0);
        // Points are processed in stack-sized chunks of centred f32 coordinates, so the
        // per-vote work is a multiply-add, a conversion and an increment (no heap buffer).
        let mut xs = [0f32; VOTE_CHUNK];
        let mut ys = [0f32; VOTE_CHUNK];
        let mut idx = [0u32; VOTE_CHUNK];
        let mut iter = points.into_iter();
        loop {
            // The buffer side of the zip comes first so that a full chunk does not pull (and
            // lose) one more point from `iter`.
            let mut m = 0;
            for ((x, y), p) in xs.iter_mut().zip(ys.iter_mut()).zip(iter.by_ref()) {
                *x = (p.col_px() - cx) as f32;
                *y = (p.row_px() - cy) as f32;
                m += 1;
            }
            if m == 0 {
                break;
            }
            for k in k0..=k1 {
                let c = self.cos_over_step[k];
                let s = self.sin_over_step[k];
                for ((j, &x), &y) in idx[..m].iter_mut().zip(&xs[..m]).zip(&ys[..m]) {
                    *j = rho_bin(x, y, c, s, offset);
                }
                let row = &mut self.acc[k * nr..(k + 1) * nr];
                for &j in &idx[..m] {
                    // In range by construction; `get_mut` keeps a bad index from panicking.
                    // No overflow: a cell gets at most one vote per point per call and
                    // `check_count` rejects more than `MAX_VOTES` points.
                    if let Some(cell) = row.get_mut(j as usize) {
                        *cell += 1;
                    }
                }
            }
            if m < VOTE_CHUNK {
                break;
            }
        }
    }

    /// The orientation-restricted vote of [`Self::find_lines_oriented`]: each point's votes in
    /// the θ bins within `half = ⌊tolerance/Δθ⌋` bins of the bin nearest its normal, and of the
    /// bins nearest the same normal ± 180° (the window wraps at ±90°), those inside `k0..=k1`,
    /// once each; every bin of the band when the window covers the half circle. The ρ bin is
    /// rounded exactly as [`Self::vote`] does (so that case gives the same accumulator).
    #[inline(always)]
    fn vote_oriented(
        &mut self,
        points: &[OrientedPoint],
        k0: usize,
        k1: usize,
        tolerance_deg: f64,
    ) {
        let nr = self.rho_bins;
        let nt = self.theta_bins as i64;
        let (cx, cy) = (self.center_col_px, self.center_row_px);
        let offset = self.rho_zero_bin as f32;
        let step = self.params.theta_step_deg;
        self.acc[k0 * nr..(k1 + 1) * nr].fill(0);
        let half = (tolerance_deg / step + 1e-9).floor() as i64;
        let all = tolerance_deg >= 90.0 || 2 * half + 1 >= nt;
        let (k0i, k1i) = (k0 as i64, k1 as i64);
        // Nearest θ bin of an angle (θ_k = −90° + k·Δθ).
        // Rounded half away from zero as `f64::round` does, by a truncating cast (`round` is a
        // libm call on the baseline x86-64 target, three a point here): the fraction
        // |v| − ⌊|v|⌋ is exact, so the comparison with ½ decides as `round` does.
        let bin = |deg: f64| {
            let v = (deg + 90.0) / step;
            let a = v.abs();
            let t = a as i64;
            let t = if a - t as f64 >= 0.5 { t + 1 } else { t };
            if v < 0.0 { -t } else { t }
        };
        let centred = |p: &OrientedPoint| {
            (
                (f64::from(p.col_px) - cx) as f32,
                (f64::from(p.row_px) - cy) as f32,
            )
        };
        if all {
            for p in points {
                let (x, y) = centred(p);
                let votes = u32::from(p.votes);
                let rows = self.acc[k0 * nr..(k1 + 1) * nr].chunks_exact_mut(nr);
                for ((row, &c), &s) in rows
                    .zip(&self.cos_over_step[k0..=k1])
                    .zip(&self.sin_over_step[k0..=k1])
                {
                    // In range by construction (as in `vote`); a bad index is skipped, never
                    // spilled into the next θ row.
                    if let Some(cell) = row.get_mut(rho_bin(x, y, c, s, offset) as usize) {
                        *cell += votes;
                    }
                }
            }
            return;
        }
        // The point's window and its copies one half-turn either way, as runs of L = 2·half + 1
        // bins starting at a; they do not overlap (L < nt bins, each copy 180° away). A run
        // meets the band iff its start lies in base..=k1, base = k0 − L + 1.
        let len = 2 * half + 1;
        let base = k0i - len + 1;
        let starts_of = |p: &OrientedPoint| {
            let theta = f64::from(p.normal_deg);
            [theta, theta + 180.0, theta - 180.0].map(|t| bin(t) - half)
        };
        // θ-major: the runs counting-sorted by their start, so that the runs through bin k are
        // those starting in k − L + 1..=k, one slice; each θ row then takes its votes while it
        // sits in the cache, instead of every point touching L rows. The same votes as a
        // point-major loop (integer sums do not depend on their order).
        let buckets = (k1i - base + 1) as usize;
        let counts = &mut self.run_starts;
        counts.clear();
        counts.resize(buckets + 1, 0);
        // The runs that meet the band as (point, bucket), in point order: their starts are
        // computed once.
        let keys = &mut self.run_keys;
        keys.clear();
        for (i, p) in points.iter().enumerate() {
            for a in starts_of(p) {
                if (base..=k1i).contains(&a) {
                    let bucket = (a - base) as usize;
                    counts[bucket + 1] += 1;
                    keys.push((i as u32, bucket as u32)); // i < 2³²: reserve_oriented_points
                }
            }
        }
        for i in 0..buckets {
            counts[i + 1] += counts[i];
        }
        let total = counts[buckets] as usize;
        let (run_x, run_y, run_votes) = (&mut self.run_x, &mut self.run_y, &mut self.run_votes);
        run_x.clear();
        run_x.resize(total, 0.0);
        run_y.clear();
        run_y.resize(total, 0.0);
        run_votes.clear();
        run_votes.resize(total, 0);
        self.run_bins.clear();
        self.run_bins.resize(total, 0);
        let next = &mut self.run_next;
        next.clear();
        next.extend_from_slice(&counts[..buckets]);
        for &(i, bucket) in keys.iter() {
            if let (Some(p), Some(slot)) = (points.get(i as usize), next.get_mut(bucket as usize)) {
                let (x, y) = centred(p);
                let j = *slot as usize;
                (run_x[j], run_y[j], run_votes[j]) = (x, y, u32::from(p.votes));
                *slot += 1;
            }
        }
        for k in k0..=k1 {
            // Runs starting in k − L + 1 ..= k: buckets (k − L + 1 − base) ..= (k − base).
            let lo = (k as i64 - len + 1 - base) as usize;
            let hi = (k as i64 - base) as usize;
            let (c, s) = (self.cos_over_step[k], self.sin_over_step[k]);
            let row = &mut self.acc[k * nr..(k + 1) * nr];
            let runs = counts[lo] as usize..counts[hi + 1] as usize;
            // The bins first, in a loop of their own (it vectorises), then the votes.
            let bins = &mut self.run_bins[runs.clone()];
            for ((b, &x), &y) in bins
                .iter_mut()
                .zip(&run_x[runs.clone()])
                .zip(&run_y[runs.clone()])
            {
                *b = rho_bin(x, y, c, s, offset);
            }
            for (&b, &votes) in bins.iter().zip(&run_votes[runs]) {
                // In range by construction (as in `vote`); a bad index is skipped.
                if let Some(cell) = row.get_mut(b as usize) {
                    *cell += votes;
                }
            }
        }
    }

    fn peak_raw(&self, k0: usize, k1: usize) -> (usize, usize) {
        let nr = self.rho_bins;
        let mut best = (0u32, k0, 0usize);
        for k in k0..=k1 {
            for (r, &v) in self.acc[k * nr..(k + 1) * nr].iter().enumerate() {
                if v > best.0 {
                    best = (v, k, r);
                }
            }
        }
        (best.1, best.2)
    }

    fn peak_smoothed(&mut self, k0: usize, k1: usize) -> (usize, usize) {
        let nr = self.rho_bins;
        let acc = &self.acc;
        // Slots 0..3: ρ-direction 3-sums of rows k0 + j (j mod 3); slot 3 stays zero and
        // stands in for the rows outside the band.
        let slot = |k: usize| (k - k0) % 3;
        let row = |k: usize| &acc[k * nr..(k + 1) * nr];
        let ring = &mut self.ring;
        ring[3 * nr..].fill(0);
        hsum3(row(k0), &mut ring[0..nr]);
        if k0 < k1 {
            hsum3(row(k0 + 1), &mut ring[nr..2 * nr]);
        }
        let mut best = (0u32, k0, 0usize);
        for k in k0..=k1 {
            if k > k0 && k < k1 {
                let j = slot(k + 1);
                hsum3(row(k + 1), &mut ring[j * nr..(j + 1) * nr]);
            }
            let prev = if k > k0 { slot(k - 1) } else { 3 };
            let next = if k < k1 { slot(k + 1) } else { 3 };
            let cur = slot(k);
            let (a, b, c) = (
                &ring[prev * nr..(prev + 1) * nr],
                &ring[cur * nr..(cur + 1) * nr],
                &ring[next * nr..(next + 1) * nr],
            );
            let mut row_best = (0u32, 0usize);
            for (r, ((&x, &y), &z)) in a.iter().zip(b).zip(c).enumerate() {
                let v = x + y + z;
                if v > row_best.0 {
                    row_best = (v, r);
                }
            }
            if row_best.0 > best.0 {
                best = (row_best.0, k, row_best.1);
            }
        }
        (best.1, best.2)
    }

    /// Peak score of cell `(k, r)`: raw votes or 3×3 box sum inside `[k0, k1]`.
    fn score(&self, k: usize, r: usize, k0: usize, k1: usize) -> f64 {
        let nr = self.rho_bins;
        if !self.params.peak_smoothing {
            return f64::from(self.acc[k * nr + r]);
        }
        let mut v = 0u64;
        for kk in k.saturating_sub(1).max(k0)..=(k + 1).min(k1) {
            for rr in r.saturating_sub(1)..=(r + 1).min(nr - 1) {
                v += u64::from(self.acc[kk * nr + rr]);
            }
        }
        v as f64
    }

    /// Sub-bin offsets `(dθ, dρ)` in bins, each in `[−½, ½]`.
    fn refine(&self, k: usize, r: usize, k0: usize, k1: usize) -> (f64, f64) {
        let s0 = self.score(k, r, k0, k1);
        let dk = if k > k0 && k < k1 {
            parabolic_offset(
                self.score(k - 1, r, k0, k1),
                s0,
                self.score(k + 1, r, k0, k1),
            )
        } else {
            0.0
        };
        let dr = if r > 0 && r + 1 < self.rho_bins {
            parabolic_offset(
                self.score(k, r - 1, k0, k1),
                s0,
                self.score(k, r + 1, k0, k1),
            )
        } else {
            0.0
        };
        (dk, dr)
    }
}

/// The largest value of `row` (0 for an empty row): one pass that vectorises.
#[inline(always)]
fn row_max(row: &[u32]) -> u32 {
    row.iter().copied().max().unwrap_or(0)
}

/// `dst[r] = src[r − 1] + src[r] + src[r + 1]` (missing neighbours count as zero); both
/// slices have the same length ≥ 2.
#[inline(always)]
fn hsum3(src: &[u32], dst: &mut [u32]) {
    let n = src.len();
    if n < 2 || dst.len() != n {
        return;
    }
    dst[0] = src[0] + src[1];
    // Three shifted slices rather than `windows(3)`: the loop vectorises.
    for (((d, &a), &b), &c) in dst[1..n - 1]
        .iter_mut()
        .zip(&src[..n - 2])
        .zip(&src[1..n - 1])
        .zip(&src[2..])
    {
        *d = a + b + c;
    }
    dst[n - 1] = src[n - 2] + src[n - 1];
}

/// Vertex offset of the parabola through `(−1, a)`, `(0, b)`, `(1, c)`, clamped to `[−½, ½]`;
/// `0` when the three values are not a strict local maximum shape.
fn parabolic_offset(a: f64, b: f64, c: f64) -> f64 {
    let denom = a - 2.0 * b + c;
    if denom < 0.0 {
        (0.5 * (a - c) / denom).clamp(-0.5, 0.5)
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Point;

    /// The θ-major oriented vote (runs counting-sorted by their first bin) fills the same
    /// accumulator as a point-major reference: every point, every bin of the band, a vote
    /// where the bin is within `⌊tolerance/Δθ⌋` bins of the bin nearest the point's normal
    /// taken modulo 180° (every bin for a window covering the half circle) — with θ steps that
    /// do and do not divide 180°, narrow and wide windows, bands at both ends of the range, and
    /// weighted points.
    #[test]
    fn the_theta_major_oriented_vote_equals_a_point_major_reference() {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = move || xorshift(&mut state);
        for step in [1.0, 0.7, 2.5] {
            let params = HoughParams {
                theta_step_deg: step,
                ..HoughParams::default()
            };
            let mut ws = HoughWorkspace::new(160, 120, params).unwrap();
            let (nr, nt) = (ws.rho_bins, ws.theta_bins);
            let points: Vec<OrientedPoint> = (0..400)
                .map(|_| OrientedPoint {
                    col_px: (next() % 160) as f32,
                    row_px: (next() % 120) as f32,
                    normal_deg: -90.0 + (next() % 18_000) as f32 / 100.0,
                    votes: (next() % 4) as u16,
                })
                .collect();
            ws.reserve_oriented_points(points.len());
            for (k0, k1) in [(0, nt - 1), (0, nt / 6), (nt / 3, nt / 2), (nt - 5, nt - 1)] {
                for tolerance_deg in [0.0, 1.0, 15.0, 40.0, 89.0, 90.0] {
                    ws.vote_oriented(&points, k0, k1, tolerance_deg);
                    let half = (tolerance_deg / step + 1e-9).floor() as i64;
                    // A window covering the half circle votes in every bin.
                    let every = tolerance_deg >= 90.0 || 2 * half + 1 >= nt as i64;
                    let mut expected = vec![0u32; (k1 - k0 + 1) * nr];
                    let (cx, cy) = (ws.center_col_px, ws.center_row_px);
                    for p in &points {
                        let x = (f64::from(p.col_px) - cx) as f32;
                        let y = (f64::from(p.row_px) - cy) as f32;
                        let centres = [0.0, 180.0, -180.0]
                            .map(|d| ((f64::from(p.normal_deg) + d + 90.0) / step).round() as i64);
                        for k in k0..=k1 {
                            if every || centres.iter().any(|&c| (k as i64 - c).abs() <= half) {
                                let (c, s) = (ws.cos_over_step[k], ws.sin_over_step[k]);
                                let r = rho_bin(x, y, c, s, ws.rho_zero_bin as f32) as usize;
                                expected[(k - k0) * nr + r] += u32::from(p.votes);
                            }
                        }
                    }
                    assert!(
                        ws.acc[k0 * nr..(k1 + 1) * nr] == expected[..],
                        "step {step}, band {k0}..={k1}, tolerance {tolerance_deg}"
                    );
                }
            }
        }
    }

    /// Random oriented points with lines in them: `lines` lines of 60 points (normals along
    /// the line's, jittered) among `clutter` random points, votes 0–3.
    fn oriented_scene(
        next: &mut impl FnMut() -> u64,
        lines: usize,
        clutter: usize,
    ) -> Vec<OrientedPoint> {
        let mut points = Vec::new();
        for _ in 0..lines {
            let theta_deg = -80.0 + (next() % 16_000) as f32 / 100.0;
            let (s, c) = theta_deg.to_radians().sin_cos();
            let (x0, y0) = ((next() % 320) as f32, (next() % 240) as f32);
            for t in 0..60 {
                // Along the line (direction (−sin θ, cos θ)), inside the image.
                let d = t as f32 * 2.0 - 60.0;
                let (x, y) = (x0 - d * s, y0 + d * c);
                if (0.0..=319.0).contains(&x) && (0.0..=239.0).contains(&y) {
                    let jitter = (next() % 600) as f32 / 100.0 - 3.0;
                    points.push(OrientedPoint {
                        col_px: x.round(),
                        row_px: y.round(),
                        normal_deg: (theta_deg + jitter).clamp(-90.0, 89.99),
                        votes: (next() % 4) as u16,
                    });
                }
            }
        }
        points.extend((0..clutter).map(|_| OrientedPoint {
            col_px: (next() % 320) as f32,
            row_px: (next() % 240) as f32,
            normal_deg: -90.0 + (next() % 18_000) as f32 / 100.0,
            votes: (next() % 4) as u16,
        }));
        points
    }

    /// The AVX2 build of the oriented vote and its peak search finds the same peaks, from the
    /// same accumulator and smoothed votes, as the portable one (the same integer sums and
    /// unfused `f32` products): 60 seeded scenes, both bands, several tolerances and
    /// separations, under the default Hough parameters and with peak smoothing, sub-bin
    /// refinement and other bin sizes changed. Both paths are reached through
    /// [`HoughWorkspace::find_lines_oriented`], which takes the AVX2 one wherever
    /// [`HoughWorkspace::new`] detected AVX2 (checked here too). Skipped (and said so) on a CPU
    /// without AVX2.
    #[test]
    #[cfg(target_arch = "x86_64")]
    fn the_avx2_vote_and_peak_search_equal_the_portable_ones() {
        let detected = std::arch::is_x86_feature_detected!("avx2");
        let param_sets = [
            HoughParams::default(),
            HoughParams {
                peak_smoothing: false,
                ..HoughParams::default()
            },
            HoughParams {
                subbin_refinement: false,
                ..HoughParams::default()
            },
            HoughParams {
                theta_step_deg: 1.0,
                rho_step_px: 2.0,
                peak_smoothing: false,
                subbin_refinement: false,
            },
        ];
        let none = HoughLine {
            rho_px: 0.0,
            theta_rad: 0.0,
            votes: 0,
        };
        let mut compared = 0;
        for params in param_sets {
            let mut ws = HoughWorkspace::new(320, 240, params).unwrap();
            assert_eq!(ws.avx2, detected, "the path follows the CPU's AVX2");
            if !detected {
                eprintln!("no AVX2 on this CPU: only the portable path exists to test");
                return;
            }
            let mut state = 0x2545_f491_4f6c_dd1du64;
            let mut next = move || xorshift(&mut state);
            for scene in 0..60 {
                let points = oriented_scene(&mut next, 1 + scene % 4, 50 * (scene % 7));
                ws.reserve_oriented_points(points.len());
                for band in [AngleBand::LEFT_LANE, AngleBand::RIGHT_LANE] {
                    for (tolerance_deg, (sep_theta_deg, sep_rho_px)) in
                        [(15.0, (3.0, 8.0)), (5.0, (1.0, 2.0)), (90.0, (6.0, 20.0))]
                    {
                        let mut run = |avx2: bool, out: &mut [HoughLine; 8]| {
                            ws.avx2 = avx2;
                            let runs = ws.avx2_runs;
                            let n = ws
                                .find_lines_oriented(
                                    &points,
                                    &band,
                                    tolerance_deg,
                                    sep_theta_deg,
                                    sep_rho_px,
                                    out,
                                )
                                .unwrap();
                            assert_eq!(ws.avx2_runs, runs + usize::from(avx2), "path taken");
                            (n, ws.acc.clone(), ws.smoothed.clone())
                        };
                        let (mut portable, mut avx2) = ([none; 8], [none; 8]);
                        let (n, acc, smoothed) = run(false, &mut portable);
                        let (m, acc_avx2, smoothed_avx2) = run(true, &mut avx2);
                        assert_eq!(
                            (n, &portable[..n]),
                            (m, &avx2[..m]),
                            "{params:?}, scene {scene}, {band:?}"
                        );
                        assert!(
                            acc == acc_avx2 && smoothed == smoothed_avx2,
                            "{params:?}, scene {scene}, {band:?}"
                        );
                        compared += n;
                    }
                }
            }
        }
        // The scenes hold lines: most searches return several peaks.
        assert!(compared > 4 * 60 * 2 * 3 * 4, "{compared} peaks compared");
    }

    /// The one-pass validity test of the oriented points agrees with the checks that name the
    /// first bad point: normals at and around ±90°, coordinates at and around the image's
    /// bounds (half a pixel outside), NaN and infinities.
    #[test]
    fn the_fast_validity_pass_agrees_with_the_point_checks() {
        let ws = HoughWorkspace::new(320, 240, HoughParams::default()).unwrap();
        let around = |v: f32| [v, v.next_down(), v.next_up()];
        let mut cols = vec![f32::NAN, f32::INFINITY, f32::NEG_INFINITY, 100.0];
        cols.extend(around(-0.5).into_iter().chain(around(319.5)));
        let mut rows = vec![f32::NAN, f32::INFINITY, 50.0];
        rows.extend(around(-0.5).into_iter().chain(around(239.5)));
        let mut normals = vec![f32::NAN, f32::NEG_INFINITY, 0.0];
        normals.extend(around(-90.0).into_iter().chain(around(90.0)));
        let good = OrientedPoint {
            col_px: 10.0,
            row_px: 10.0,
            normal_deg: 10.0,
            votes: 1,
        };
        let mut seen = [0; 2];
        for &col_px in &cols {
            for &row_px in &rows {
                for &normal_deg in &normals {
                    let odd = OrientedPoint {
                        col_px,
                        row_px,
                        normal_deg,
                        votes: 1,
                    };
                    let points = [good, odd, good];
                    let checked = points
                        .iter()
                        .all(|p| p.normal_deg.is_finite() && (-90.0..90.0).contains(&p.normal_deg))
                        && ws.check_points(points.iter()).is_ok();
                    assert_eq!(ws.oriented_points_valid(&points), checked, "{odd:?}");
                    seen[usize::from(checked)] += 1;
                }
            }
        }
        assert!(seen[0] > 0 && seen[1] > 0, "{seen:?}");
    }

    /// The next value of a xorshift sequence (`state` never 0): deterministic, no external RNG.
    fn xorshift(state: &mut u64) -> u64 {
        *state ^= *state << 13;
        *state ^= *state >> 7;
        *state ^= *state << 17;
        *state
    }

    /// Deterministic pseudo-random votes (xorshift).
    fn fill_votes(ws: &mut HoughWorkspace, k0: usize, k1: usize, seed: u64) {
        let mut state = seed | 1;
        let nr = ws.rho_bins;
        for v in &mut ws.acc[k0 * nr..(k1 + 1) * nr] {
            *v = (xorshift(&mut state) % 50) as u32;
        }
    }

    /// Brute-force argmax of `score` in scan order (first maximum wins).
    fn naive_peak(ws: &HoughWorkspace, k0: usize, k1: usize) -> (usize, usize) {
        let mut best = (-1.0, k0, 0);
        for k in k0..=k1 {
            for r in 0..ws.rho_bins {
                let v = ws.score(k, r, k0, k1);
                if v > best.0 {
                    best = (v, k, r);
                }
            }
        }
        (best.1, best.2)
    }

    /// The ring-buffer 3×3 peak and the raw peak equal a brute-force argmax of the
    /// independently written `score` (direct 3×3 sums clipped to the band), for bands of
    /// 1, 2, 3 and many θ bins.
    #[test]
    fn fast_peak_search_matches_brute_force() {
        for smoothing in [true, false] {
            let params = HoughParams {
                peak_smoothing: smoothing,
                ..HoughParams::default()
            };
            let mut ws = HoughWorkspace::new(64, 48, params).unwrap();
            for (i, (k0, k1)) in [(10, 10), (10, 11), (10, 12), (0, 359), (200, 317)]
                .into_iter()
                .enumerate()
            {
                fill_votes(&mut ws, k0, k1, 17 + i as u64);
                let fast = if smoothing {
                    ws.peak_smoothed(k0, k1)
                } else {
                    ws.peak_raw(k0, k1)
                };
                assert_eq!(
                    fast,
                    naive_peak(&ws, k0, k1),
                    "band {k0}..={k1}, smoothing {smoothing}"
                );
            }
        }
    }

    /// The peaks `take_peaks` takes from its smoothed rows, updated only where a suppression
    /// changed them, are those of a brute-force argmax of `score` over the whole band after
    /// every suppression, in the same order, for bands of 1, 2, 3 and many θ bins.
    #[test]
    fn incremental_peaks_match_a_brute_force_search_after_every_suppression() {
        for smoothing in [true, false] {
            let params = HoughParams {
                peak_smoothing: smoothing,
                subbin_refinement: false,
                ..HoughParams::default()
            };
            let mut ws = HoughWorkspace::new(64, 48, params).unwrap();
            let mut reference = HoughWorkspace::new(64, 48, params).unwrap();
            let nr = ws.rho_bins;
            let none = HoughLine {
                rho_px: 0.0,
                theta_rad: 0.0,
                votes: 0,
            };
            for (i, (k0, k1)) in [(10, 10), (10, 11), (10, 12), (0, 359), (200, 317)]
                .into_iter()
                .enumerate()
            {
                fill_votes(&mut ws, k0, k1, 29 + i as u64);
                // A broad hill: after the suppression of its top the strongest cells lie just
                // outside the cleared cells, where stale smoothed sums would be wrong.
                let (kc, rc) = ((k0 + k1) / 2, nr / 2);
                for k in k0..=k1 {
                    for r in 0..nr {
                        let d = k.abs_diff(kc) + r.abs_diff(rc);
                        ws.acc[k * nr + r] += 400u32.saturating_sub(20 * d as u32);
                    }
                }
                reference.acc.copy_from_slice(&ws.acc);
                let mut out = [none; 12];
                let n = ws.take_peaks(k0, k1, 3.0, 4.0, &mut out);
                let dk = (3.0 / params.theta_step_deg).round() as usize;
                let dr = (4.0 / params.rho_step_px).round() as usize;
                let mut expected = Vec::new();
                while expected.len() < out.len() {
                    let (k, r) = naive_peak(&reference, k0, k1);
                    if reference.score(k, r, k0, k1) <= 0.0 {
                        break;
                    }
                    expected.push(reference.refined_line(k, r, k0, k1));
                    for kk in k.saturating_sub(dk).max(k0)..=(k + dk).min(k1) {
                        reference.acc
                            [kk * nr + r.saturating_sub(dr)..=kk * nr + (r + dr).min(nr - 1)]
                            .fill(0);
                    }
                }
                assert!(n > 1, "band {k0}..={k1}: {n} peaks");
                assert_eq!(
                    &out[..n],
                    &expected[..],
                    "band {k0}..={k1}, smoothing {smoothing}"
                );
                let differing = ws
                    .acc
                    .iter()
                    .zip(&reference.acc)
                    .filter(|(a, b)| a != b)
                    .count();
                assert_eq!(
                    differing, 0,
                    "band {k0}..={k1}, smoothing {smoothing}: cells cleared differently"
                );
            }
        }
    }

    /// `find_lines` returns the drawn lines strongest first, separated, and stops when no vote
    /// is left; its first line is `find_line`'s.
    #[test]
    fn find_lines_returns_separate_lines_strongest_first() {
        let mut ws = HoughWorkspace::new(320, 240, HoughParams::default()).unwrap();
        // Two `/` lines: x = 200 − 0.6·(y − 100) over 140 rows and x = 100 − 0.5·(y − 100) over
        // 80 rows (weaker), both θ > 0.
        let mut pts: Vec<Point> = (100..240)
            .map(|y| Point::new(200.0 - 0.6 * f64::from(y - 100), f64::from(y)))
            .collect();
        pts.extend((100..180).map(|y| Point::new(100.0 - 0.5 * f64::from(y - 100), f64::from(y))));
        let band = AngleBand::LEFT_LANE;
        let best = ws.find_line(&pts, &band).unwrap();
        let none = HoughLine {
            rho_px: 0.0,
            theta_rad: 0.0,
            votes: 0,
        };
        let mut out = [none; 6];
        let n = ws.find_lines(&pts, &band, 3.0, 8.0, &mut out).unwrap();
        assert!(n >= 2, "{n} lines");
        assert_eq!(out[0], best);
        assert!(out[0].votes >= out[1].votes);
        let at = |l: &HoughLine, y: f64| l.col_at_row(y).unwrap();
        assert!((at(&out[0], 200.0) - 140.0).abs() < 1.0, "{:?}", out[0]);
        // The second line is the weaker drawn one, not a near copy of the first.
        assert!((at(&out[1], 150.0) - 75.0).abs() < 1.0, "{:?}", out[1]);
        for l in &out[..n] {
            assert!(band.contains_deg(l.theta_deg()));
        }
        // Two points only: at most as many lines as there are votes, never an error.
        let two = [Point::new(10.0, 10.0), Point::new(20.0, 30.0)];
        let k = ws.find_lines(&two, &band, 3.0, 8.0, &mut out).unwrap();
        assert!((1..=6).contains(&k));
        assert!(ws.find_lines(&pts, &band, -1.0, 8.0, &mut out).is_err());
    }

    /// The three-point vertex formula is exact on a sampled parabola and clamps outside ±½.
    #[test]
    fn parabolic_offset_recovers_the_vertex() {
        for d in [-0.45, -0.2, 0.0, 0.13, 0.5] {
            let f = |x: f64| 10.0 - 3.0 * (x - d) * (x - d);
            assert!((parabolic_offset(f(-1.0), f(0.0), f(1.0)) - d).abs() < 1e-12);
        }
        assert_eq!(parabolic_offset(0.0, 1.0, 5.0), 0.0); // not a maximum: convex → no shift
        assert_eq!(parabolic_offset(1.0, 1.0, 1.0), 0.0);
        assert_eq!(parabolic_offset(0.0, 1.0, 1.9), 0.5); // vertex beyond the bin → clamped
    }

    /// Every in-image point (corners included) votes exactly once per θ bin of the band,
    /// also across vote-chunk boundaries and for iterator inputs.
    #[test]
    fn each_point_votes_once_per_theta_bin() {
        let mut ws = HoughWorkspace::new(320, 240, HoughParams::default()).unwrap();
        let band = AngleBand::new(-90.0, 90.0);
        let (k0, k1) = ws.band_bins(&band).unwrap();
        assert_eq!((k0, k1), (0, 359));
        let corners = [
            Point::new(-0.5, -0.5),
            Point::new(319.5, -0.5),
            Point::new(-0.5, 239.5),
            Point::new(319.5, 239.5),
        ];
        for n in [4, VOTE_CHUNK, VOTE_CHUNK + 1, 2 * VOTE_CHUNK + 3] {
            // Cycle the corners and the centre through n points, fed as an iterator.
            let pts = (0..n).map(|i| {
                corners
                    .get(i % 5)
                    .copied()
                    .unwrap_or(Point::new(160.0, 120.0))
            });
            ws.vote(pts, k0, k1);
            let nr = ws.rho_bins;
            for k in k0..=k1 {
                let total: u32 = ws.acc[k * nr..(k + 1) * nr].iter().sum();
                assert_eq!(total as usize, n, "θ bin {k}, {n} points");
            }
        }
    }
}
