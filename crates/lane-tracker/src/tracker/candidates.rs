//! The candidate pixels of one edge class for the initialisation, and the index of them by row
//! that the joint initialisation reads: each Hough line's least-squares parabola and its row
//! coverage (crate docs), read row by row so that each costs the pixels near the curve, not
//! every candidate pixel.
//!
//! Decisions and figures: `docs/lanes/history/unpaired-pixels.md`, `orientation-hough-vote.md`.

use hough_init::{HoughLine, OrientedPoint, Parabola};
use vision_gradient::{EdgeBuffer, EdgeClass, EdgePixel, gradient_normal_deg};

use super::edges::EdgeStage;
use super::setup::{Rows, Setup};

/// The background of a candidate's row coverage is read on the parallel curves this many LS band
/// half-widths to each side (a gap of one band between them and the band of the candidate).
const BACKGROUND_SHIFT_BANDS: f64 = 3.0;
/// Unpaired edge pixels counted per row and band by the row coverage (where a paired pixel
/// weighs more): a single step (a kerb, a road's edge, a shadow's border) gives one or two a
/// row under the 3×3 Sobel; more unpaired pixels on one row within a band are texture or
/// noise.
const UNPAIRED_PER_ROW: usize = 2;

/// Fixed-point scale of [`counts_as`]'s lean bound (2^14).
pub(super) const LEAN_SCALE: f64 = 16384.0;

/// Whether edge pixel `p` counts as an edge of `class`: its own class, or either class when its
/// edge runs within `atan(t)` of the vertical, `t = near_vertical_q14 / 2^14`
/// (`|gy| ≤ t·|gx|`, in integers: `|gy| = magnitude − |gx|`, [`EdgePixel::gradient`]). The
/// class is the sign of `gx·gy` (the edge's lean, `/` or `\\`); along a mark straight ahead the
/// edge has almost no lean, `gy` is a few grey levels of noise, and its pixels fall into both
/// classes at random — each band would see about half of the mark. `near_vertical_q14 = 0` is
/// the class alone (the detector emits no pixel with `gy = 0`).
#[inline(always)]
pub(super) fn counts_as(p: &EdgePixel, class: EdgeClass, near_vertical_q14: i32) -> bool {
    let gx_abs = i32::from(p.gx).abs();
    let gy_abs = i32::from(p.magnitude) - gx_abs;
    // Products ≤ 2040 · 2^14 < 2^31 (magnitudes ≤ 2040, bounds < 2^14 for angles < 45°).
    (p.class == class) | (gy_abs * LEAN_SCALE as i32 <= near_vertical_q14 * gx_abs)
}

/// Appends `item(index, pixel)` for the pixels among `pixels` that count as `class`
/// ([`counts_as`] with `near_vertical_q14`), in their order, without a branch on the class (the
/// classes alternate along a row: such a branch is mispredicted often). Needs room for
/// `pixels.len() + 1` more in `out`'s capacity not to allocate.
fn extend_with_class_by<T: Copy + Default>(
    out: &mut Vec<T>,
    pixels: &[EdgePixel],
    class: EdgeClass,
    near_vertical_q14: i32,
    item: impl Fn(usize, &EdgePixel) -> T,
) {
    let mut n = out.len();
    out.resize(n + pixels.len() + 1, T::default());
    for (i, p) in pixels.iter().enumerate() {
        if let Some(slot) = out.get_mut(n) {
            *slot = item(i, p);
        }
        n += usize::from(counts_as(p, class, near_vertical_q14));
    }
    out.truncate(n);
}

/// The `(column, row)` of the pixels among `pixels` that count as `class` appended to `points`
/// ([`extend_with_class_by`]).
pub(super) fn extend_with_class(
    points: &mut Vec<(f32, f32)>,
    pixels: &[EdgePixel],
    class: EdgeClass,
    near_vertical_q14: i32,
) {
    extend_with_class_by(points, pixels, class, near_vertical_q14, |_, p| {
        (f32::from(p.col_px), f32::from(p.row_px))
    });
}

/// Where `CandidateIndex::fill` takes its pixels from, in their order: the edge pixels,
/// then the paired ones `stripe_paired_votes − 1` more times (weighted stripe pairing: the sides
/// of bright stripes count `gradient.stripe_paired_votes` times in all, the other edge pixels
/// once).
pub(super) fn candidate_sources<'a>(
    edges: &'a EdgeBuffer,
    paired: &'a EdgeBuffer,
    stripe_paired_votes: u8,
) -> impl Iterator<Item = &'a [EdgePixel]> {
    let repeats = usize::from(stripe_paired_votes.max(1)) - 1;
    std::iter::once(edges.pixels()).chain(std::iter::repeat_n(paired.pixels(), repeats))
}

/// The candidate pixels of one class and their index by row, in buffers sized once.
#[derive(Debug)]
pub(super) struct CandidateIndex {
    /// The pixels of one class (`fill`, or `fill_near` for a chosen line's fit), paired ones
    /// repeated, as `(col_px, row_px)`: the Hough vote's and the LS fit's input.
    pub(super) candidates: Vec<(f32, f32)>,
    /// The candidate pixels once each, with the normal angle of their edge and their weight as
    /// votes, for the orientation-restricted Hough vote (`init.orientation_tolerance_deg > 0`;
    /// empty and unallocated otherwise).
    pub(super) oriented: Vec<OrientedPoint>,
    /// The candidate pixels as `(column, weight)` sorted by row then column,
    /// `row_start[r]..row_start[r + 1]` the pixels of row `r` (`init.candidate_coverage`), and
    /// a counting-sort cursor per row.
    pub(super) by_row: Vec<(u16, u16)>,
    pub(super) row_start: Vec<u32>,
    row_next: Vec<u32>,
    /// One bit per image pixel: the paired pixels of one class while `by_row` is built.
    paired_mask: Vec<u64>,
    /// The indices in `edges` of one class's pixels while `by_row` is built (capacity: the
    /// buffer's, plus one).
    of_class: Vec<u32>,
    /// Per image row, the columns of the nearest candidate pixels on each side that
    /// `fill_near` left out (`chosen_fit`).
    pub(super) left_out_cols: Box<[(f32, f32)]>,
}

impl CandidateIndex {
    /// Buffers for `capacity` edge pixels (the tallest region searched) of frames of
    /// `setup`'s working size.
    pub(super) fn new(setup: &Setup, capacity: usize) -> Self {
        let (width, height) = (setup.width, setup.height);
        let cfg = &setup.cfg;
        CandidateIndex {
            // The pixels of one class, paired ones repeated, and a spare slot for the last
            // branch-free append.
            candidates: Vec::with_capacity(
                usize::from(cfg.gradient.stripe_paired_votes.max(1)) * capacity + 1,
            ),
            oriented: Vec::with_capacity(if cfg.init.orientation_tolerance_deg > 0.0 {
                capacity
            } else {
                0
            }),
            by_row: Vec::with_capacity(capacity),
            row_start: vec![0; height + 1],
            row_next: Vec::with_capacity(height),
            paired_mask: vec![0; (width * height).div_ceil(64)],
            of_class: Vec::with_capacity(capacity + 1),
            left_out_cols: vec![(f32::NEG_INFINITY, f32::INFINITY); height].into_boxed_slice(),
        }
    }

    /// `self.candidates` = the edge pixels that count as `class` ([`counts_as`]: those of the
    /// class and the near-vertical ones of either), from the last full-ROI gradient, the
    /// paired ones `gradient.stripe_paired_votes` times.
    pub(super) fn fill(&mut self, edges: &EdgeStage, class: EdgeClass, setup: &Setup) {
        self.candidates.clear();
        let near_vertical = setup.near_vertical_either_class();
        let votes = setup.cfg.gradient.stripe_paired_votes;
        for pixels in candidate_sources(&edges.edges, &edges.paired, votes) {
            extend_with_class(&mut self.candidates, pixels, class, near_vertical);
        }
    }

    /// Whether [`Self::fill`] would put at least `min` pixels in `self.candidates`
    /// for `class`, counted without filling it and only until `min` is reached.
    pub(super) fn has(
        &self,
        edges: &EdgeStage,
        class: EdgeClass,
        min: usize,
        setup: &Setup,
    ) -> bool {
        let near_vertical = setup.near_vertical_either_class();
        let votes = setup.cfg.gradient.stripe_paired_votes;
        // `fill_candidates`' sources in its order, each read only for what `min` still lacks.
        let mut found = 0;
        for pixels in candidate_sources(&edges.edges, &edges.paired, votes) {
            if found >= min {
                break;
            }
            found += pixels
                .iter()
                .filter(|p| counts_as(p, class, near_vertical))
                .take(min - found)
                .count();
        }
        found >= min
    }

    /// `self.by_row` = the edge pixels of `class` as `(column, weight)` sorted by row then
    /// column, the weight being how many times `self.candidates` holds the pixel
    /// (`gradient.stripe_paired_votes` for a paired one, else 1), with `self.row_start[r]` the
    /// index of row `r`'s first pixel (`row_start[height]` = their number): the paired pixels
    /// marked in a bit mask, a counting sort by row, and a row sorted by column only if the
    /// detector did not emit it so. With `init.orientation_tolerance_deg > 0`, also
    /// `self.oriented` = the same pixels, once each, with the normal angle of their stored
    /// gradient and the weight as their votes (the Hough input). No allocation.
    pub(super) fn sort_by_row(&mut self, edges: &EdgeStage, class: EdgeClass, setup: &Setup) {
        let (w, h) = (setup.width, setup.height);
        let paired_votes = setup.cfg.gradient.stripe_paired_votes;
        let bit =
            |p: &vision_gradient::EdgePixel| usize::from(p.row_px) * w + usize::from(p.col_px);
        let near_vertical = setup.near_vertical_either_class();
        let mask = &mut self.paired_mask;
        if paired_votes > 0 {
            for p in (edges.paired.pixels().iter()).filter(|p| counts_as(p, class, near_vertical)) {
                if let Some(word) = mask.get_mut(bit(p) / 64) {
                    *word |= 1 << (bit(p) % 64);
                }
            }
        }
        let starts = &mut self.row_start;
        starts.fill(0);
        // The indices of the pixels of `class`, selected without a branch on the class (the
        // classes alternate along a row: such a branch is mispredicted often).
        let pixels = edges.edges.pixels();
        let of_class = &mut self.of_class;
        of_class.clear();
        // i < the buffer's capacity ≤ width·height < 2³².
        extend_with_class_by(of_class, pixels, class, near_vertical, |i, _| i as u32);
        let of_class = &*of_class;
        let in_class = || of_class.iter().filter_map(|&i| pixels.get(i as usize));
        for e in in_class() {
            if let Some(c) = starts.get_mut(usize::from(e.row_px) + 1) {
                *c += 1;
            }
        }
        for r in 0..h {
            starts[r + 1] += starts[r];
        }
        let next = &mut self.row_next;
        next.clear();
        next.extend_from_slice(&starts[..h]);
        let by_row = &mut self.by_row;
        by_row.clear();
        by_row.resize(starts[h] as usize, (0, 0));
        let oriented = &mut self.oriented;
        oriented.clear();
        let with_normals = setup.cfg.init.orientation_tolerance_deg > 0.0;
        for e in in_class() {
            let paired = mask
                .get(bit(e) / 64)
                .is_some_and(|word| word & (1 << (bit(e) % 64)) != 0);
            let weight = if paired { u16::from(paired_votes) } else { 1 };
            if with_normals
                && let Some(normal_deg) = {
                    let (gx, gy) = e.gradient();
                    gradient_normal_deg(gx, gy)
                }
            {
                oriented.push(OrientedPoint {
                    col_px: f32::from(e.col_px),
                    row_px: f32::from(e.row_px),
                    normal_deg,
                    votes: weight,
                });
            }
            if let Some(k) = next.get_mut(usize::from(e.row_px)) {
                by_row[*k as usize] = (e.col_px, weight);
                *k += 1;
            }
        }
        // Leave the mask clear for the next call: every word a paired pixel may have set.
        if paired_votes > 0 {
            for p in edges.paired.pixels() {
                if let Some(word) = mask.get_mut(bit(p) / 64) {
                    *word = 0;
                }
            }
        }
        for r in 0..h {
            let row = &mut by_row[starts[r] as usize..starts[r + 1] as usize];
            if !row.windows(2).all(|p| p[0].0 <= p[1].0) {
                row.sort_unstable();
            }
        }
    }

    /// The pixels of row `r` in `self.by_row` (sorted by column) from the first with `x ≥ lo`
    /// on (a binary search; callers scan on while `x ≤` their upper bound).
    fn row_from(&self, r: usize, lo: f64) -> &[(u16, u16)] {
        let (Some(&a), Some(&b)) = (self.row_start.get(r), self.row_start.get(r + 1)) else {
            return &[];
        };
        let row = self.by_row.get(a as usize..b as usize).unwrap_or(&[]);
        // For an integer column c: c < lo ⟺ c < ⌈lo⌉; the search compares integers (⌈lo⌉ by a
        // truncating cast: `ceil` is a libm call on the baseline x86-64 target).
        let from = if lo.is_nan() || lo > f64::from(u16::MAX) {
            row.len()
        } else if lo <= 0.0 {
            0
        } else {
            let t = lo as u16; // ⌊lo⌋ for 0 < lo ≤ u16::MAX
            let ceil = if f64::from(t) < lo { t + 1 } else { t }; // ≤ u16::MAX: lo ≤ u16::MAX
            row.partition_point(|p| p.0 < ceil)
        };
        row.get(from..).unwrap_or(&[])
    }

    /// The least-squares parabola a candidate `line` would be initialised with
    /// (`hough_init::fit_around_line`'s pixel sets: those within `band_half_width_px` of the
    /// line, then `refit_iterations` times those within it, horizontally, of the last fit), read
    /// row by row from `self.by_row` so that each pass costs the pixels in the band, not every
    /// candidate pixel; rows normalised over the ROI. `None` with fewer than `min_points` pixels
    /// in a band, or a degenerate fit. For the choice of the ego pair only: the chosen line is
    /// fitted by `fit_around_line` itself.
    pub(super) fn row_fit(&self, line: &HoughLine, rows: Rows, setup: &Setup) -> Option<Parabola> {
        let (top, bottom) = rows;
        let band = setup.init_params.band_px;
        let (sin_t, cos_t) = line.theta_rad.sin_cos();
        if cos_t.abs() < 1e-9 {
            return None;
        }
        let yc = 0.5 * (top + bottom - 1) as f64;
        let sc = (0.5 * (bottom - 1 - top) as f64).max(1.0);
        // Pass 0 around the line: |x·cos θ + y·sin θ − ρ| ≤ band ⟺ |x − x_line(y)| ≤ band/|cos θ|.
        let mut half = band / cos_t.abs();
        let mut fit: Option<Parabola> = None;
        for _ in 0..=setup.init_params.refit_iterations {
            // Σ u^k (k = 0..4) and Σ x·u^k (k = 0..2) over the pixels in the band.
            let (mut su, mut sxu) = ([0.0f64; 5], [0.0f64; 3]);
            let mut count = 0usize;
            for r in top..bottom {
                if self.row_start.get(r) == self.row_start.get(r + 1) {
                    continue; // no pixel on this row
                }
                let x0 = match fit {
                    Some(p) => p.col_at_row(r as f64),
                    None => (line.rho_px - r as f64 * sin_t) / cos_t,
                };
                if !x0.is_finite() {
                    continue;
                }
                let (mut k, mut sx) = (0usize, 0.0f64);
                for &(col, weight) in self.row_from(r, x0 - half) {
                    let x = f64::from(col);
                    if x > x0 + half {
                        break;
                    }
                    k += usize::from(weight);
                    sx += f64::from(weight) * x;
                }
                if k == 0 {
                    continue;
                }
                let u = (r as f64 - yc) / sc;
                let u2 = u * u;
                count += k;
                let k = k as f64;
                su[0] += k;
                su[1] += k * u;
                su[2] += k * u2;
                su[3] += k * u2 * u;
                su[4] += k * u2 * u2;
                sxu[0] += sx;
                sxu[1] += sx * u;
                sxu[2] += sx * u2;
            }
            if count < setup.init_params.min_points {
                return None;
            }
            let n = nalgebra::Matrix3::new(
                su[0], su[1], su[2], su[1], su[2], su[3], su[2], su[3], su[4],
            );
            let c = n.cholesky()?.solve(&nalgebra::Vector3::from(sxu));
            // x = c0 + c1·u + c2·u², u = (y − yc)/sc, in pixel coefficients.
            let p = Parabola {
                a1: c[2] / (sc * sc),
                a2: c[1] / sc - 2.0 * c[2] * yc / (sc * sc),
                a3: c[0] - c[1] * yc / sc + c[2] * yc * yc / (sc * sc),
            };
            if !(p.a1.is_finite() && p.a2.is_finite() && p.a3.is_finite()) {
                return None;
            }
            fit = Some(p);
            half = band;
        }
        fit
    }

    /// Row coverage of parabola `p` (`init.candidate_coverage`), net of the clutter around it:
    /// over the ROI rows, the candidate pixels (paired ones repeated) within the LS band
    /// (`±band_half_width_px`) of `p`, at most `2·max(gradient.stripe_paired_votes, 1)` per
    /// row, summed; minus the mean of the same sum for the two parallel curves
    /// `p ± 3·band_half_width_px` (a mark on a clean floor keeps its coverage, a line through
    /// texture or clutter, as dense beside it as on it, loses it); at least 0. Where a paired
    /// pixel weighs more than an unpaired one (`stripe_paired_votes ≥ 2`), a band's unpaired
    /// pixels count at most [`UNPAIRED_PER_ROW`] a row: one step's worth, so that a step edge
    /// through noise or texture (which adds unpaired pixels on it as beside it) no longer
    /// reaches a bright stripe's coverage row for row. Read row by row from `self.by_row`; no
    /// allocation.
    pub(super) fn row_coverage(&self, p: &Parabola, rows: Rows, setup: &Setup) -> f64 {
        let (top, bottom) = rows;
        let band = setup.init_params.band_px;
        let shift = BACKGROUND_SHIFT_BANDS * band;
        let votes = setup.cfg.gradient.stripe_paired_votes;
        let cap = 2 * usize::from(votes.max(1));
        // Where a paired pixel weighs more than an unpaired one, the unpaired ones of a band
        // count at most `UNPAIRED_PER_ROW` a row.
        let unpaired_cap = if votes > 1 {
            UNPAIRED_PER_ROW
        } else {
            usize::MAX
        };
        let (mut on, mut beside) = (0usize, 0usize);
        for r in top..bottom {
            let x = p.col_at_row(r as f64);
            if !x.is_finite() || self.row_start.get(r) == self.row_start.get(r + 1) {
                continue;
            }
            // The three bands do not overlap (shift = 3·band > 2·band): one scan.
            // Per band (left, centre, right): [paired weight, unpaired pixels].
            let mut sums = [[0usize; 2]; 3];
            for &(col, weight) in self.row_from(r, x - shift - band) {
                let d = f64::from(col) - x;
                if d > shift + band {
                    break;
                }
                let b = if d.abs() <= band {
                    1
                } else if (d - shift).abs() <= band {
                    2
                } else if (d + shift).abs() <= band {
                    0
                } else {
                    continue;
                };
                sums[b][usize::from(weight == 1)] += usize::from(weight);
            }
            let [left, centre, right] =
                sums.map(|[paired, unpaired]| (paired + unpaired.min(unpaired_cap)).min(cap));
            on += centre;
            beside += left + right;
        }
        (on as f64 - 0.5 * beside as f64).max(0.0)
    }
}
