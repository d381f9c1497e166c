//! The vote: points into the accumulator (the plain and the orientation-restricted vote), and the
//! checks of their input.

use super::*;

impl HoughWorkspace {
    /// [`Self::vote_oriented`] then [`Self::take_peaks`]: the work of
    /// [`Self::find_lines_oriented`] once its input is checked. Both are inlined here and into
    /// [`Self::vote_and_take_peaks_avx2`], which compiles the same code for AVX2: the loops the compiler
    /// vectorises (the smoothing, the row maxima, the θ-major ρ bins) on 256-bit vectors. The same operations on the same values (integer sums, and `f32` products and sums
    /// in the same order, never fused): the same votes and peaks on either path.
    #[inline(always)]
    pub(super) fn vote_and_take_peaks(
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
    pub(super) fn vote_and_take_peaks_avx2(
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

    /// Validate the points and their number (2 ..= `MAX_VOTES`): the checks of every vote.
    pub(super) fn check_count<I>(&self, points: I) -> Result<(), HoughError>
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
    pub(super) fn oriented_points_valid(&self, points: &[OrientedPoint]) -> bool {
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
    pub(super) fn vote_checked<I>(
        &mut self,
        points: I,
        band: &AngleBand,
    ) -> Result<(usize, usize), HoughError>
    where
        I: IntoIterator + Clone,
        I::Item: PixelPoint,
    {
        let (k0, k1) = self.band_bins(band)?;
        self.check_count(points.clone())?;
        self.vote(points, k0, k1);
        Ok((k0, k1))
    }

    /// Validate every point; returns their number.
    pub(super) fn check_points<I>(&self, points: I) -> Result<usize, HoughError>
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

    pub(super) fn vote<I>(&mut self, points: I, k0: usize, k1: usize)
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
    pub(super) fn vote_oriented(
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
}
