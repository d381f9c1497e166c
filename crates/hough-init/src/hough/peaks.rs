//! The peaks: the 3×3-smoothed maxima of the accumulator, their sub-bin refinement, and the
//! suppression around each peak taken.

use super::*;

impl HoughWorkspace {
    /// The `out.len()` strongest peaks of θ bins `k0..=k1`, each followed by clearing the votes
    /// within the separation (non-maximum suppression); the number written.
    #[inline(always)]
    pub(super) fn take_peaks(
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
    pub(super) fn smooth_row(&mut self, k: usize, k0: usize, k1: usize) {
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
    pub(super) fn resmooth_cells(&mut self, k: usize, k0: usize, k1: usize, lo: usize, hi: usize) {
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
    pub(super) fn peak_of_rows(&self, k0: usize, k1: usize) -> (usize, usize) {
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

    /// The accumulator's peak cell in θ bins `k0..=k1` (raw or 3×3-smoothed votes).
    pub(super) fn peak(&mut self, k0: usize, k1: usize) -> (usize, usize) {
        if self.params.peak_smoothing {
            self.peak_smoothed(k0, k1)
        } else {
            self.peak_raw(k0, k1)
        }
    }

    /// The line of peak cell `(k, r)`, sub-bin refined when `subbin_refinement` is on.
    pub(super) fn refined_line(&self, k: usize, r: usize, k0: usize, k1: usize) -> HoughLine {
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
    pub(super) fn line_of(&self, k: f64, r: f64, votes: u32) -> HoughLine {
        let theta_rad = self.theta_deg_of_bin(k).to_radians();
        let rho_c_px = (r - self.rho_zero_bin as f64) * self.params.rho_step_px;
        let (s, c) = theta_rad.sin_cos();
        HoughLine {
            rho_px: rho_c_px + self.center_col_px * c + self.center_row_px * s,
            theta_rad,
            votes,
        }
    }

    pub(super) fn peak_raw(&self, k0: usize, k1: usize) -> (usize, usize) {
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

    pub(super) fn peak_smoothed(&mut self, k0: usize, k1: usize) -> (usize, usize) {
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
    pub(super) fn score(&self, k: usize, r: usize, k0: usize, k1: usize) -> f64 {
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
    pub(super) fn refine(&self, k: usize, r: usize, k0: usize, k1: usize) -> (f64, f64) {
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
pub(super) fn parabolic_offset(a: f64, b: f64, c: f64) -> f64 {
    let denom = a - 2.0 * b + c;
    if denom < 0.0 {
        (0.5 * (a - c) / denom).clamp(-0.5, 0.5)
    } else {
        0.0
    }
}
