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

mod peaks;
#[cfg(test)]
mod tests;
mod vote;

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
}
