//! Stages I–II, (re-)initialisation: gradient over the whole ROI, then either the paper's Hough
//! line per angle band and least-squares parabola (`hough-init`), or the joint initialisation
//! (crate docs: the strongest lines of both bands, the ego pair chosen together), with the sanity
//! checks that accept a fit.

use hough_init::{Chord, HoughLine, LaneInit, OrientedPoint, Parabola, choose_ego_pair, init_lane};
use info_filter::ParabolaKif;
use nalgebra::Vector3;
use vision_gradient::{
    EdgeBuffer, EdgeClass, EdgePixel, GreyImage, Region, drop_periodic_stripes,
    gradient_normal_deg, keep_bright_stripes, split_stripes,
};

use super::points::{NEAR_VERTICAL_SLOPE, fit_profile};
use super::{
    Estimator, InitCandidate, Lane, LaneFilter, LaneState, LaneTracker, MAX_CANDIDATE_LINES,
};
use crate::TrackerError;
use crate::error::FilterFailure;
use crate::wrls_lane::WrlsLane;

/// The background of a candidate's row coverage is read on the parallel curves this many LS band
/// half-widths to each side (a gap of one band between them and the band of the candidate).
const BACKGROUND_SHIFT_BANDS: f64 = 3.0;
/// Unpaired edge pixels counted per row and band by the row coverage (where a paired pixel
/// weighs more): a single step (a kerb, a road's edge, a shadow's border) gives one or two a
/// row under the 3×3 Sobel; more unpaired pixels on one row within a band are texture or
/// noise.
const UNPAIRED_PER_ROW: usize = 2;

/// Fixed-point scale of [`counts_as`]'s lean bound (2^14).
const LEAN_SCALE: f64 = 16384.0;

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

/// Where `LaneTracker::fill_candidates` takes its pixels from, in their order: the edge pixels,
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

impl LaneTracker {
    /// Initialise the sides without an estimate in the ROI (or, both tracked, re-validate
    /// them: `track.revalidate_every_frames`, `track.revalidate_below_points`), then, with
    /// `roi.fallback_top_row_fraction`, a side still without one over the taller rows (the side
    /// found first locked into the pair). A weak lane the ROI's choice set aside
    /// (`initialise_jointly`) is back as it was if the second search did not find its side
    /// (or there is none), else it is what the new lane replaced (a switch, which the crossing
    /// gate may undo).
    pub(super) fn initialise(&mut self, image: &GreyImage<'_>) -> Result<(), TrackerError> {
        let searched = self.search_both(image);
        self.settle_set_asides();
        searched
    }

    /// After the frame's searches, each lane set aside on it (`Lane::set_aside`, kept with its
    /// side through a hand-over): what a lane now on its side replaced (a switch, counted, that
    /// the crossing gate may undo), else put back as it was.
    pub(super) fn settle_set_asides(&mut self) {
        for i in 0..2 {
            let lane = &mut self.lanes[i];
            let Some(set_aside) = lane.set_aside.take() else {
                continue;
            };
            if lane.has_estimate() {
                lane.replaced = Some(set_aside);
                self.counters.revalidation_switches[i] += 1;
            } else {
                lane.restore(set_aside);
            }
        }
    }

    /// [`Self::initialise`]'s two searches: the ROI's (which may set weak lanes aside), then
    /// the taller rows' for the sides still without a lane.
    fn search_both(&mut self, image: &GreyImage<'_>) -> Result<(), TrackerError> {
        self.initialise_in_roi(image, [true, true], true)?;
        let Some(tall) = self.fallback_roi else {
            return Ok(());
        };
        if self.lanes.iter().all(Lane::has_estimate) {
            return Ok(());
        }
        let without = [!self.lanes[0].has_estimate(), !self.lanes[1].has_estimate()];
        let searched = self.over_rows(tall, |t| t.initialise_in_roi(image, without, false));
        // A side found here is refined and tracked over these rows (`install` clears the flag).
        for (lane, was_without) in self.lanes.iter_mut().zip(without) {
            lane.tracked_tall |= was_without && lane.initialised_now;
        }
        searched
    }

    /// Stages I–II over the rows `self.search_rows`; with the joint initialisation, the Hough
    /// candidates of the bands `vote[k]` only, and with `set_aside_weak` a weak lane the choice
    /// gives nothing to set aside ([`Self::initialise_jointly`]).
    pub(super) fn initialise_in_roi(
        &mut self,
        image: &GreyImage<'_>,
        vote: [bool; 2],
        set_aside_weak: bool,
    ) -> Result<(), TrackerError> {
        let outward = self.outward_col();
        let (top, bottom) = self.search_rows;
        self.detector.detect(
            image,
            Region::Rows {
                row_start_px: top,
                row_end_px: bottom,
            },
            &mut self.edges,
            None,
        )?;
        drop_periodic_stripes(&mut self.edges, &self.cfg.gradient.periodic_params());
        if self.cfg.gradient.stripe_paired_votes > 0 {
            split_stripes(
                &mut self.edges,
                &mut self.paired,
                self.cfg.gradient.stripe_max_width_px,
                self.cfg.gradient.stripe_drop_dark,
            );
        } else {
            keep_bright_stripes(
                &mut self.edges,
                self.cfg.gradient.stripe_max_width_px,
                outward,
            );
        }
        if self.cfg.init.candidate_lines > 0 {
            self.initialise_jointly(vote, set_aside_weak);
            return Ok(());
        }
        for i in 0..2 {
            if self.lanes[i].has_estimate() {
                continue;
            }
            self.fill_candidates(self.lanes[i].class);
            let Ok(init) = init_lane(
                &self.candidates,
                &self.lanes[i].band,
                &mut self.hough,
                &self.init_params,
            ) else {
                continue;
            };
            self.install(i, &init);
        }
        Ok(())
    }

    /// Centre column for `gradient.stripe_keep_outward_steps`.
    pub(super) fn outward_col(&self) -> Option<u16> {
        self.cfg
            .gradient
            .stripe_keep_outward_steps
            .then(|| u16::try_from(self.width / 2).unwrap_or(u16::MAX))
    }

    /// The lean bound below which an edge pixel counts in both classes in the initialisation
    /// ([`counts_as`], 2^14 fixed point): the joint initialisation's, `tan 10°` (as the
    /// tracking windows take either class where the lane is within 10° of the vertical,
    /// `points::NEAR_VERTICAL_SLOPE`); none for the paper's line per band
    /// (`init.candidate_lines = 0`).
    pub(super) fn near_vertical_either_class(&self) -> i32 {
        if self.cfg.init.candidate_lines > 0 {
            (NEAR_VERTICAL_SLOPE * LEAN_SCALE).round() as i32
        } else {
            0
        }
    }

    /// `self.candidates` = the edge pixels that count as `class` ([`counts_as`]: those of the
    /// class and the near-vertical ones of either), from the last full-ROI gradient, the
    /// paired ones `gradient.stripe_paired_votes` times.
    pub(super) fn fill_candidates(&mut self, class: EdgeClass) {
        self.candidates.clear();
        let near_vertical = self.near_vertical_either_class();
        let votes = self.cfg.gradient.stripe_paired_votes;
        for pixels in candidate_sources(&self.edges, &self.paired, votes) {
            extend_with_class(&mut self.candidates, pixels, class, near_vertical);
        }
    }

    /// Whether [`Self::fill_candidates`] would put at least `min` pixels in `self.candidates`
    /// for `class`, counted without filling it and only until `min` is reached.
    pub(super) fn has_candidates(&self, class: EdgeClass, min: usize) -> bool {
        let near_vertical = self.near_vertical_either_class();
        let votes = self.cfg.gradient.stripe_paired_votes;
        // `fill_candidates`' sources in its order, each read only for what `min` still lacks.
        let mut found = 0;
        for pixels in candidate_sources(&self.edges, &self.paired, votes) {
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

    /// Joint initialisation (`init.candidate_lines > 0`, crate docs): the strongest
    /// `candidate_lines` Hough lines of each band (each pixel voting near its own edge normal
    /// with `init.orientation_tolerance_deg > 0`), the ego pair chosen among all of them by
    /// `hough_init::choose_ego_pair`, each chosen line refined by least squares on the pixels of
    /// its own class. A lane tracked from earlier frames competes with the candidates (with
    /// re-validation on), weighed by its own row coverage × `track.revalidate_keep_factor`, and
    /// is replaced only by a candidate off its mark, or handed over to the other side when the
    /// choice puts it there (a lane change); otherwise, and for a lane initialised on this
    /// frame, it is locked into the pair. With `set_aside_weak` (the ROI's search), a competing
    /// lane with fewer than `track.revalidate_below_points` points on this frame and the one
    /// before that the choice keeps nothing of is set aside (`Lane::set_aside`) for the second
    /// search to replace;
    /// [`Self::initialise`] puts it back if it does not.
    ///
    /// `vote[k]`: whether band `k`'s pixels vote (the second search votes only in the bands of
    /// the sides still without a lane; a side's boundary leans into the other band only on a
    /// tight bend, where the ROI holds its near part).
    fn initialise_jointly(&mut self, vote: [bool; 2], set_aside_weak: bool) {
        const MAX_LINES: usize = MAX_CANDIDATE_LINES;
        let none = HoughLine {
            rho_px: 0.0,
            theta_rad: 0.0,
            votes: 0,
        };
        let n = self.cfg.init.candidate_lines.min(MAX_LINES);
        let (top, bottom) = self.search_rows;
        let (yt, yb) = (top as f64, (bottom - 1) as f64);
        let mut lines = [none; 2 * MAX_LINES];
        let mut classes = [EdgeClass::LeftLane; 2 * MAX_LINES];
        let mut chords = [Chord::default(); 2 * MAX_LINES + 2];
        let mut found = [none; MAX_LINES];
        let mut m = 0;
        // This search's candidates follow those of an earlier search on the same frame.
        let first = self.init_candidates.len();
        // With re-validation on (`TrackConfig::revalidates`), a lane tracked from
        // earlier frames competes with the candidates, weighed by its own row coverage: in a
        // re-validation (both tracked) and when the other side is (re-)initialised. A lane
        // initialised on this frame (the first search's, during the second search) is locked
        // into the pair instead, as every tracked lane is with re-validation off.
        // A lane tracked over the taller rows (`Lane::tracked_tall`) competes too, weighed on the
        // ROI's rows, where its mark may not be: a candidate of the ROI for its side replaces
        // it. (Locked instead, lanes of an earlier scene were kept: the stress test fell.)
        let competes: [bool; 2] = std::array::from_fn(|i| {
            let lane = &self.lanes[i];
            self.cfg.track.revalidates()
                && self.cfg.init.candidate_coverage
                && lane.has_estimate()
                && !lane.initialised_now
        });
        let mut tracked_support = [0.0f64; 2];
        for (k, _) in vote.into_iter().enumerate().filter(|&(_, votes)| votes) {
            let (class, band) = (self.lanes[k].class, self.lanes[k].band);
            if !self.has_candidates(class, self.init_params.min_points) {
                continue;
            }
            if self.cfg.init.candidate_coverage || self.cfg.init.orientation_tolerance_deg > 0.0 {
                self.sort_candidates_by_row(class);
            }
            if competes.contains(&true) {
                // Each competing lane's coverage by this band's pixels; the better band counts
                // (on a bend a boundary leans into the other band).
                for (i, support) in tracked_support.iter_mut().enumerate() {
                    if let (true, Some(f)) = (competes[i], self.lanes[i].filter.as_ref()) {
                        let p = Parabola::from_coeffs(f.coeffs());
                        *support = support.max(self.row_coverage(&p));
                    }
                }
            }
            if self.cfg.init.orientation_tolerance_deg <= 0.0 {
                self.fill_candidates(class); // the plain vote's input
            }
            let (sep_deg, sep_px) = (
                self.cfg.init.candidate_separation_deg,
                self.cfg.init.candidate_separation_px,
            );
            let tolerance_deg = self.cfg.init.orientation_tolerance_deg;
            let lines_found = if tolerance_deg > 0.0 {
                self.hough.find_lines_oriented(
                    &self.oriented,
                    &band,
                    tolerance_deg,
                    sep_deg,
                    sep_px,
                    &mut found[..n],
                )
            } else {
                self.hough
                    .find_lines(&self.candidates, &band, sep_deg, sep_px, &mut found[..n])
            };
            let Ok(count) = lines_found else {
                continue;
            };
            for line in &found[..count] {
                // The candidate as a curve x(y): its LS parabola, or the Hough line itself.
                let (p, support) = if self.cfg.init.candidate_coverage {
                    let Some(p) = self.row_fit(line) else {
                        continue;
                    };
                    (p, self.row_coverage(&p))
                } else {
                    let (Some(x0), Some(x1)) = (line.col_at_row(0.0), line.col_at_row(1.0)) else {
                        continue;
                    };
                    let p = Parabola {
                        a1: 0.0,
                        a2: x1 - x0,
                        a3: x0,
                    };
                    (p, f64::from(line.votes))
                };
                let chord = Chord {
                    col_top_px: p.col_at_row(yt),
                    col_bottom_px: p.col_at_row(yb),
                    support,
                };
                // Within capacity: at most MAX_LINES per band, two searches a frame.
                self.init_candidates.push(InitCandidate {
                    band: self.lanes[k].side,
                    coeffs: [p.a1, p.a2, p.a3],
                    support,
                    chosen: None,
                });
                lines[m] = *line;
                classes[m] = class;
                chords[m] = chord;
                m += 1;
            }
        }
        let s_max = chords[..m].iter().map(|c| c.support).fold(0.0, f64::max);
        // Lanes with an estimate as chords after the candidates: a competing one with its row
        // coverage counted `track.revalidate_keep_factor` times, unlocked; otherwise the first
        // one, locked into the pair with the strongest support.
        let mut locked = None;
        let mut tracked_at = [None; 2];
        for (i, lane) in self.lanes.iter().enumerate() {
            let (true, Some(f)) = (lane.has_estimate(), lane.filter.as_ref()) else {
                continue;
            };
            if !competes[i] && locked.is_some() {
                continue;
            }
            let support = if competes[i] {
                tracked_support[i] * self.cfg.track.revalidate_keep_factor
            } else {
                s_max
            };
            chords[m] = f.chord(yt, yb, support);
            tracked_at[i] = Some(m);
            if !competes[i] {
                locked = Some((m, i));
            }
            m += 1;
        }
        // With tracked lanes competing, the pair gate's rules: the choice's 0.9 margin would
        // refuse the tracked pair of a camera looking down and pair one of its lanes with
        // clutter instead.
        let ego_pair = if competes.contains(&true) {
            self.tracked_pair_rules()
        } else {
            self.cfg.init.ego_pair
        };
        let choice = choose_ego_pair(
            &chords[..m],
            self.width as f64,
            yb - yt,
            &ego_pair,
            locked.map(|(j, _)| j),
        );
        // A locked lane the choice put on the other side: leave both as they are.
        if let Some((j, i)) = locked
            && [choice.left, choice.right][i] != Some(j)
        {
            return;
        }
        let picks = [choice.left, choice.right];
        // The lane each pick lies on, if any: its own chord, or (a competing lane) a candidate
        // within the tracking window of it at every ROI row — its own mark.
        let owner = |j: usize| -> Option<usize> {
            if let Some(k) = tracked_at.iter().position(|&t| t == Some(j)) {
                return Some(k);
            }
            let c = self.init_candidates.get(first + j)?;
            let p = Parabola::from_coeffs(c.coeffs);
            (0..2).filter(|&k| competes[k]).find(|&k| {
                // The lane's tracking window (wider on a double line: both its lines).
                let w = self.window_half_width(k, true) as f64;
                self.lanes[k].filter.as_ref().is_some_and(|f| {
                    (top..bottom)
                        .all(|y| (p.col_at_row(y as f64) - f.col_at_row(y as f64)).abs() <= w)
                })
            })
        };
        let owners = picks.map(|p| p.and_then(owner));
        // A competing lane the choice put on the other side: the camera crossed it (a lane
        // change), and it is that side's boundary now. It moves over with its filter; the lane
        // it replaces there is dropped unless the choice gives that side a candidate below.
        if owners == [Some(1), Some(0)] {
            // Both put on the other side (not a pair the gates let through; kept, swapped).
            self.hand_over(1, 0, false);
        } else if let Some(i) = (0..2).find(|&i| owners[i] == Some(1 - i)) {
            self.hand_over(1 - i, i, true);
            self.counters.lane_changes += 1;
        }
        for (i, pick) in picks.into_iter().enumerate() {
            let Some(j) = pick else { continue };
            // `init_candidates[first..]` holds the first candidates' chords in order.
            if let Some(c) = self.init_candidates.get_mut(first + j) {
                c.chosen = Some(self.lanes[i].side);
            }
            // A lane kept on its side (or just handed over to it), or a locked one.
            let replaced = self.lanes[i].has_estimate();
            if owners[i].is_some() || (replaced && !competes[i]) {
                continue;
            }
            if let Ok(init) = self.fit_chosen_line(classes[j], lines[j]) {
                // The estimate a switch replaces is kept for the crossing gate, which restores
                // it if it undoes the switch.
                let lane = &self.lanes[i];
                let before = lane
                    .filter
                    .clone()
                    .filter(|_| replaced)
                    .map(|filter| lane.saved_with(filter, lane.predicted.clone()));
                if self.install(i, &init) && replaced {
                    self.lanes[i].replaced = before;
                    self.counters.revalidation_switches[i] += 1;
                }
            }
        }
        // A lane weak on this frame and the one before (fewer than
        // `track.revalidate_below_points` points on each) that the choice kept nothing of — no
        // pick on its mark or chord, and no candidate installed in its place — is set aside:
        // the second search looks for its side on this frame, as for a lost lane, and
        // `initialise` puts it back as it was if nothing is found. A lane weak on one frame
        // only (a dropout) coasts as before: the second search would initialise it from the
        // far field above an occlusion of the ROI. A longer occlusion is searched for from its
        // second frame (a lost lane's initialisation would from its third). `owners` is by side,
        // so it holds after a hand-over too.
        if set_aside_weak && competes.contains(&true) {
            let weak_below = self.cfg.track.revalidate_below_points;
            for ((lane, owner), count) in self
                .lanes
                .iter_mut()
                .zip(owners)
                .zip(&mut self.counters.set_asides)
            {
                if owner.is_some()
                    || lane.initialised_now
                    || !lane.has_estimate()
                    || lane.points_now >= weak_below
                    || lane.points_before >= weak_below
                {
                    continue;
                }
                lane.set_aside = lane.take_estimate();
                *count += u64::from(lane.set_aside.is_some());
            }
        }
    }

    /// Lane `from` becomes lane `to`: its filter, state and buffers move, each slot keeps its
    /// side, edge class and angle band and a lane set aside on this frame (`Lane::set_aside`:
    /// the searches replace it on its side), and a kerb's offset is dropped (it was read
    /// towards the old side). With `drop_other`, the lane that was at `to` is dropped into slot
    /// `from` (no estimate, no windows or points: the choice's candidate for that side, if any,
    /// is installed next); without, the two are swapped. No allocation (the buffers are
    /// swapped).
    pub(super) fn hand_over(&mut self, from: usize, to: usize, drop_other: bool) {
        if from == to || from > 1 || to > 1 {
            return;
        }
        self.lanes.swap(from, to);
        let [a, b] = &mut self.lanes;
        std::mem::swap(&mut a.side, &mut b.side);
        std::mem::swap(&mut a.class, &mut b.class);
        std::mem::swap(&mut a.band, &mut b.band);
        // A lane set aside on this frame stays with its side: the searches replace it there.
        std::mem::swap(&mut a.set_aside, &mut b.set_aside);
        for lane in &mut self.lanes {
            lane.kerb_offset_px = [0.0; 2];
            lane.kerb_misses = 0;
        }
        if drop_other {
            self.lanes[from].drop_estimate();
        }
    }

    /// `self.by_row` = the edge pixels of `class` as `(column, weight)` sorted by row then
    /// column, the weight being how many times `self.candidates` holds the pixel
    /// (`gradient.stripe_paired_votes` for a paired one, else 1), with `self.row_start[r]` the
    /// index of row `r`'s first pixel (`row_start[height]` = their number): the paired pixels
    /// marked in a bit mask, a counting sort by row, and a row sorted by column only if the
    /// detector did not emit it so. With `init.orientation_tolerance_deg > 0`, also
    /// `self.oriented` = the same pixels, once each, with the normal angle of their stored
    /// gradient and the weight as their votes (the Hough input). No allocation.
    fn sort_candidates_by_row(&mut self, class: EdgeClass) {
        let (w, h) = (self.width, self.height);
        let paired_votes = self.cfg.gradient.stripe_paired_votes;
        let bit =
            |p: &vision_gradient::EdgePixel| usize::from(p.row_px) * w + usize::from(p.col_px);
        let near_vertical = self.near_vertical_either_class();
        let mask = &mut self.paired_mask;
        if paired_votes > 0 {
            for p in (self.paired.pixels().iter()).filter(|p| counts_as(p, class, near_vertical)) {
                if let Some(word) = mask.get_mut(bit(p) / 64) {
                    *word |= 1 << (bit(p) % 64);
                }
            }
        }
        let starts = &mut self.row_start;
        starts.fill(0);
        // The indices of the pixels of `class`, selected without a branch on the class (the
        // classes alternate along a row: such a branch is mispredicted often).
        let pixels = self.edges.pixels();
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
        let with_normals = self.cfg.init.orientation_tolerance_deg > 0.0;
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
            for p in self.paired.pixels() {
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
    fn row_fit(&self, line: &HoughLine) -> Option<Parabola> {
        let (top, bottom) = self.search_rows;
        let band = self.init_params.band_px;
        let (sin_t, cos_t) = line.theta_rad.sin_cos();
        if cos_t.abs() < 1e-9 {
            return None;
        }
        let yc = 0.5 * (top + bottom - 1) as f64;
        let sc = (0.5 * (bottom - 1 - top) as f64).max(1.0);
        // Pass 0 around the line: |x·cos θ + y·sin θ − ρ| ≤ band ⟺ |x − x_line(y)| ≤ band/|cos θ|.
        let mut half = band / cos_t.abs();
        let mut fit: Option<Parabola> = None;
        for _ in 0..=self.init_params.refit_iterations {
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
            if count < self.init_params.min_points {
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
    pub(super) fn row_coverage(&self, p: &Parabola) -> f64 {
        let (top, bottom) = self.search_rows;
        let band = self.init_params.band_px;
        let shift = BACKGROUND_SHIFT_BANDS * band;
        let votes = self.cfg.gradient.stripe_paired_votes;
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

    /// A fresh estimator at `theta = (a1, a2, a3)` (pixel coefficients) with the initial
    /// covariance `filter.p0_sigma_px`.
    pub(super) fn new_filter(&self, theta: &Vector3<f64>) -> Result<LaneFilter, FilterFailure> {
        match self.estimator {
            Estimator::Kif => ParabolaKif::new(theta, &self.p0, self.row_norm)
                .map(LaneFilter::Kif)
                .map_err(FilterFailure::Kif),
            Estimator::Wrls => {
                WrlsLane::new(theta, &self.p0, self.row_norm, self.cfg.filter.wrls_lambda)
                    .map(LaneFilter::Wrls)
                    .map_err(FilterFailure::Wrls)
            }
        }
    }

    /// Lane `i`'s filter restarted at `theta` (pixel coefficients) with `filter.p0_sigma_px`,
    /// after a reading of the image moved its estimate (a double line's middle, no turn back);
    /// `false`, the lane left as it was and the failure counted and kept, if the filter refuses
    /// it.
    pub(super) fn restart_filter(&mut self, i: usize, theta: &Vector3<f64>) -> bool {
        match self.new_filter(theta) {
            Ok(filter) => {
                self.lanes[i].filter = Some(filter);
                true
            }
            Err(e) => {
                self.counters.filter_failures[i] += 1;
                self.last_failure[i] = Some(e);
                false
            }
        }
    }

    /// Accept an initialisation of lane `i` (`self.candidates` holds the pixels it was fitted
    /// to): sanity checks, a fresh filter, the lane's state. `false` if refused.
    fn install(&mut self, i: usize, init: &LaneInit) -> bool {
        let bottom = self.search_rows.1;
        // Sanity: the fit must cover a fair part of the ROI (a quarter of its rows, in the second
        // search too: a dash seen only over the taller rows, far ahead, is no longer than one
        // seen in the ROI) and stay near the image.
        let span_rows = init.rows_px.1 - init.rows_px.0;
        let min_span = 0.25 * (self.roi.1 - self.roi.0) as f64;
        let x_bottom = init.parabola.col_at_row((bottom - 1) as f64);
        let w = self.width as f64;
        if span_rows < min_span || !x_bottom.is_finite() || x_bottom < -w || x_bottom > 2.0 * w {
            return false;
        }
        // A fit whose pixels all lie above the ROI (only the second search finds one) is
        // extrapolated down over the ROI's rows: a short far segment sets its slope, not its
        // curvature. It starts as its chord over its rows (the refinement may bend it again).
        let (y0, y1) = init.rows_px;
        let p = if y1 < self.roi.0 as f64 && y1 > y0 {
            let (x0, x1) = (init.parabola.col_at_row(y0), init.parabola.col_at_row(y1));
            let slope = (x1 - x0) / (y1 - y0);
            Parabola {
                a1: 0.0,
                a2: slope,
                a3: x0 - slope * y0,
            }
        } else {
            init.parabola
        };
        let theta = Vector3::new(p.a1, p.a2, p.a3);
        let filter = match self.new_filter(&theta) {
            Ok(filter) => filter,
            Err(e) => {
                self.counters.filter_failures[i] += 1;
                self.last_failure[i] = Some(e);
                return false;
            }
        };
        let lane = &mut self.lanes[i];
        // Keep the points the LS fit used, for overlays.
        lane.points.clear();
        let (s, c) = init.line.theta_rad.sin_cos();
        let band = self.init_params.band_px;
        for &(x, y) in &self.candidates {
            let (xf, yf) = (f64::from(x), f64::from(y));
            if (xf * c + yf * s - init.line.rho_px).abs() <= band
                && lane.points.len() < lane.points.capacity()
            {
                lane.points.push((x, y));
            }
        }
        lane.filter = Some(filter);
        lane.predicted = None;
        lane.fresh = true;
        lane.tracked_tall = false;
        lane.kerb_offset_px = [0.0; 2];
        lane.kerb_misses = 0;
        lane.pair_half_gap_px = 0.0;
        lane.state = LaneState::Tracking;
        lane.misses = 0;
        lane.rows = [init.rows_px.0, init.rows_px.1];
        lane.weights.clear();
        lane.fit = fit_profile(&lane.points, &lane.weights, lane.rows);
        lane.points_now = init.points_used;
        lane.initialised_now = true;
        self.counters.initialisations[i] += 1;
        true
    }
}
