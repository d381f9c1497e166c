//! Stages I–II, (re-)initialisation: gradient over the whole ROI, then either the paper's Hough
//! line per angle band and least-squares parabola (`hough-init`), or the joint initialisation
//! (crate docs: the strongest lines of both bands, the ego pair chosen together), with the sanity
//! checks that accept a fit.
//!
//! The stage is [`Initialiser`]: the Hough accumulator, the candidate pixels and their index by
//! row (module `candidates`), and the candidates it weighed on this frame. It reads the edges of
//! the region searched ([`EdgeStage`]) and writes the lanes it initialises.
//!
//! Decisions and figures (`docs/lanes/history/`): `stripe-pairing-and-ego-pair.md` (the joint
//! choice), `second-search.md`, `ego-meet-top-quarter.md`, `near-vertical-both-bands.md`,
//! `vertical-marks.md`, `revalidation-period.md`, `revalidation-weak-evidence.md`; whether each
//! earns its place: `docs/results/ablation.md`.

use hough_init::{HoughLine, HoughWorkspace, LaneInit, Parabola, init_lane};
use nalgebra::Vector3;
use vision_gradient::GreyImage;

use super::candidates::CandidateIndex;
use super::edges::EdgeStage;
use super::joint::{self, Gathered, JointChoice};
use super::lane::{HandOver, Health, Lane, Lanes};
use super::points::fit_profile;
use super::report::{InitCandidate, LaneState, MAX_CANDIDATE_LINES, Side};
use super::revalidation::SpreadRevalidation;
use super::setup::{Rows, Setup};
use crate::TrackerError;

pub(super) use super::candidates::LEAN_SCALE;

/// Whether the joint choice may set aside a weak lane it keeps nothing of (the ROI's search) or
/// not (the second search, which looks for the sides still without a lane).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum WeakLanes {
    /// Set a weak lane aside for the second search to replace.
    SetAside,
    /// Leave every lane as the choice leaves it.
    Keep,
}

/// Stages I–II: the Hough accumulator, the candidate pixels and the candidates of this frame.
#[derive(Debug)]
pub(super) struct Initialiser {
    hough: HoughWorkspace,
    pub(super) index: CandidateIndex,
    /// The candidates of the last frame's joint initialisation, then those of its second search
    /// (capacity `4 · MAX_CANDIDATE_LINES`, never exceeded); empty on a frame without one.
    pub(super) found: Vec<InitCandidate>,
    /// The period's re-validation spread over its frames (`track.revalidate_spread`, module
    /// `revalidation`); `None` when it is off or cannot be spread.
    spread: Option<SpreadRevalidation>,
}

impl Initialiser {
    /// The stage for `setup`'s frames, its buffers holding `capacity` edge pixels (the tallest
    /// region searched).
    pub(super) fn new(setup: &Setup, capacity: usize) -> Result<Self, TrackerError> {
        // (Refuses a side above `hough_init::MAX_IMAGE_SIDE_PX` before anything is sized.)
        let mut hough =
            HoughWorkspace::new(setup.width, setup.height, setup.cfg.init.hough_params())?;
        if setup.cfg.init.orientation_tolerance_deg > 0.0 {
            // The oriented vote's points: one class of the tallest region's pixels at most.
            hough.reserve_oriented_points(capacity);
        }
        let t = &setup.cfg.track;
        let spreads = t.revalidate_spread
            && t.revalidate_every_frames >= 2
            && setup.cfg.init.candidate_lines > 0
            && setup.cfg.init.candidate_coverage;
        Ok(Initialiser {
            hough,
            index: CandidateIndex::new(setup, capacity),
            found: Vec::with_capacity(4 * MAX_CANDIDATE_LINES),
            spread: spreads
                .then(|| SpreadRevalidation::new(setup))
                .transpose()?,
        })
    }

    /// Whether the period's re-validation is spread over its frames (module `revalidation`).
    pub(super) fn spreads(&self) -> bool {
        self.spread.is_some()
    }

    /// The spread re-validation's steps on the period's frame `since` of `every` (module
    /// `revalidation`, `SpreadRevalidation::step`): `true` when the tracked pair is to be
    /// re-validated whole on this frame; `false` without a spread re-validation.
    #[allow(clippy::too_many_arguments)] // the stages it reads and writes, each named
    pub(super) fn spread_step(
        &mut self,
        since: u64,
        every: u64,
        image: &GreyImage<'_>,
        lanes: &Lanes,
        setup: &Setup,
        health: &mut Health,
    ) -> Result<bool, TrackerError> {
        let Initialiser {
            hough,
            index,
            spread,
            ..
        } = self;
        match spread {
            Some(spread) => spread.step(since, every, image, lanes, hough, index, setup, health),
            None => Ok(false),
        }
    }

    /// Initialise the sides without an estimate in the ROI (or, both tracked, re-validate
    /// them: `track.revalidate_every_frames`, `track.revalidate_below_points`), then, with
    /// `roi.fallback_top_row_fraction`, a side still without one over the taller rows (the side
    /// found first locked into the pair). A weak lane the ROI's choice set aside
    /// (`initialise_jointly`) is back as it was if the second search did not find its side
    /// (or there is none), else it is what the new lane replaced (a switch, which the crossing
    /// gate may undo).
    pub(super) fn initialise(
        &mut self,
        image: &GreyImage<'_>,
        edges: &mut EdgeStage,
        lanes: &mut Lanes,
        health: &mut Health,
        setup: &Setup,
    ) -> Result<(), TrackerError> {
        let searched = self.search_both(image, edges, lanes, health, setup);
        settle_set_asides(lanes, health);
        searched
    }

    /// [`Self::initialise`]'s two searches: the ROI's (which may set weak lanes aside), then
    /// the taller rows' for the sides still without a lane.
    fn search_both(
        &mut self,
        image: &GreyImage<'_>,
        edges: &mut EdgeStage,
        lanes: &mut Lanes,
        health: &mut Health,
        setup: &Setup,
    ) -> Result<(), TrackerError> {
        let roi = setup.roi;
        self.search(
            image,
            edges,
            lanes,
            health,
            setup,
            roi,
            [true, true],
            WeakLanes::SetAside,
        )?;
        let Some(tall) = setup.fallback_roi else {
            return Ok(());
        };
        if lanes.iter().all(Lane::has_estimate) {
            return Ok(());
        }
        let without = Side::BOTH.map(|side| !lanes[side].has_estimate());
        let searched = self.search(
            image,
            edges,
            lanes,
            health,
            setup,
            tall,
            without,
            WeakLanes::Keep,
        );
        // A side found here is refined and tracked over these rows (`install` clears the flag).
        for (lane, was_without) in lanes.iter_mut().zip(without) {
            lane.tracked_tall |= was_without && lane.initialised_now;
        }
        searched
    }

    /// Stages I–II over `rows`; with the joint initialisation, the Hough candidates of the
    /// bands `vote[k]` only, and with `WeakLanes::SetAside` a weak lane the choice gives
    /// nothing to set aside ([`Self::initialise_jointly`]).
    #[allow(clippy::too_many_arguments)] // the stages it reads and writes, each named
    pub(super) fn search(
        &mut self,
        image: &GreyImage<'_>,
        edges: &mut EdgeStage,
        lanes: &mut Lanes,
        health: &mut Health,
        setup: &Setup,
        rows: Rows,
        vote: [bool; 2],
        weak: WeakLanes,
    ) -> Result<(), TrackerError> {
        edges.detect_rows(image, rows, setup)?;
        if setup.cfg.init.candidate_lines > 0 {
            self.initialise_jointly(edges, lanes, health, setup, rows, vote, weak);
            return Ok(());
        }
        for side in Side::BOTH {
            if lanes[side].has_estimate() {
                continue;
            }
            self.index.fill(edges, side.edge_class(), setup);
            let Ok(init) = init_lane(
                &self.index.candidates,
                &setup.band(side),
                &mut self.hough,
                &setup.init_params,
            ) else {
                continue;
            };
            self.install(&init, &mut lanes[side], side, health, setup, rows);
        }
        Ok(())
    }

    /// Joint initialisation (`init.candidate_lines > 0`, crate docs): the strongest
    /// `candidate_lines` Hough lines of each band (each pixel voting near its own edge normal
    /// with `init.orientation_tolerance_deg > 0`), the ego pair chosen among all of them by
    /// `hough_init::choose_ego_pair`, each chosen line refined by least squares on the pixels of
    /// its own class. A lane tracked from earlier frames competes with the candidates (with
    /// re-validation on), weighed by its own row coverage × `track.revalidate_keep_factor`, and
    /// is replaced only by a candidate off its mark, or handed over to the other side when the
    /// choice puts it there (a lane change); otherwise, and for a lane initialised on this
    /// frame, it is locked into the pair. With `WeakLanes::SetAside` (the ROI's search), a competing
    /// lane with fewer than `track.revalidate_below_points` points on this frame and the one
    /// before that the choice keeps nothing of is set aside (`Lane::set_aside`) for the second
    /// search to replace;
    /// [`Initialiser::initialise`] puts it back if it does not.
    ///
    /// `vote[k]`: whether band `k`'s pixels vote (the second search votes only in the bands of
    /// the sides still without a lane; a side's boundary leans into the other band only on a
    /// tight bend, where the ROI holds its near part).
    #[allow(clippy::too_many_arguments)] // the stages it reads and writes, each named
    fn initialise_jointly(
        &mut self,
        edges: &EdgeStage,
        lanes: &mut Lanes,
        health: &mut Health,
        setup: &Setup,
        rows: Rows,
        vote: [bool; 2],
        weak: WeakLanes,
    ) {
        // The steps of module `joint`, all on this frame.
        let pair = joint::weighed(lanes, setup);
        let competes = joint::competes(&pair);
        let mut gathered = Gathered::default();
        let mut lines = [HoughLine {
            rho_px: 0.0,
            theta_rad: 0.0,
            votes: 0,
        }; MAX_CANDIDATE_LINES];
        for (band_side, _) in Side::BOTH.into_iter().zip(vote).filter(|&(_, votes)| votes) {
            if !joint::prepare_band(
                &mut self.index,
                edges,
                band_side,
                &pair,
                &mut gathered,
                setup,
                rows,
            ) {
                continue;
            }
            let count =
                joint::vote_band(&mut self.hough, &self.index, band_side, setup, &mut lines);
            joint::fit_lines(
                &self.index,
                band_side,
                &lines[..count],
                &mut gathered,
                setup,
                rows,
            );
        }
        let choice = gathered.choose(&pair, setup, rows);
        // This search's candidates follow those of an earlier search on the same frame
        // (within capacity: at most `MAX_CANDIDATE_LINES` per band, two searches a frame).
        let first = self.found.len();
        self.found.extend_from_slice(gathered.candidates());
        if choice.locked_moved {
            return; // a locked lane the choice put on the other side: both left as they are
        }
        let JointChoice { picks, owners, .. } = choice;
        // A competing lane the choice put on the other side: the camera crossed it (a lane
        // change), and it is that side's boundary now. It moves over with its filter; the lane
        // it replaces there is dropped unless the choice gives that side a candidate below.
        if owners == [Some(1), Some(0)] {
            // Both put on the other side (not a pair the gates let through; kept, swapped).
            lanes.hand_over(Side::Right, Side::Left, HandOver::Swap);
        } else if let Some(side) = Side::BOTH
            .into_iter()
            .find(|side| owners[side.index()] == Some(side.other().index()))
        {
            lanes.hand_over(side.other(), side, HandOver::DropOther);
            health.counters.lane_changes += 1;
        }
        for (side, pick) in Side::BOTH.into_iter().zip(picks) {
            let i = side.index();
            let Some(j) = pick else { continue };
            // `found[first..]` holds the candidates in the order of the chords.
            if let Some(c) = self.found.get_mut(first + j).filter(|_| j < gathered.len) {
                c.chosen = Some(side);
            }
            // A lane kept on its side (or just handed over to it), or a locked one.
            let replaced = lanes[side].has_estimate();
            if owners[i].is_some() || (replaced && !competes[i]) {
                continue;
            }
            if let Ok(init) = self.index.fit_chosen_line(
                edges,
                gathered.classes[j],
                gathered.lines[j],
                rows,
                setup,
            ) {
                // The estimate a switch replaces is kept for the crossing gate, which restores
                // it if it undoes the switch.
                let lane = &lanes[side];
                let before = lane
                    .filter
                    .clone()
                    .filter(|_| replaced)
                    .map(|filter| lane.saved_with(filter, lane.predicted.clone()));
                if self.install(&init, &mut lanes[side], side, health, setup, rows) && replaced {
                    lanes[side].replaced = before;
                    health.counters.revalidation_switches[i] += 1;
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
        if weak == WeakLanes::SetAside && competes.contains(&true) {
            let weak_below = setup.cfg.track.revalidate_below_points;
            for ((lane, owner), count) in lanes
                .iter_mut()
                .zip(owners)
                .zip(&mut health.counters.set_asides)
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

    /// Accept an initialisation of the lane on `side` (`self.index.candidates` holds the pixels
    /// it was fitted to), found over `rows`: sanity checks, a fresh filter, the lane's state.
    /// `false` if refused.
    fn install(
        &self,
        init: &LaneInit,
        lane: &mut Lane,
        side: Side,
        health: &mut Health,
        setup: &Setup,
        rows: Rows,
    ) -> bool {
        let bottom = rows.1;
        // Sanity: the fit must cover a fair part of the ROI (a quarter of its rows, in the second
        // search too: a dash seen only over the taller rows, far ahead, is no longer than one
        // seen in the ROI) and stay near the image.
        let span_rows = init.rows_px.1 - init.rows_px.0;
        let min_span = 0.25 * (setup.roi.1 - setup.roi.0) as f64;
        let x_bottom = init.parabola.col_at_row((bottom - 1) as f64);
        let w = setup.width as f64;
        if span_rows < min_span || !x_bottom.is_finite() || x_bottom < -w || x_bottom > 2.0 * w {
            return false;
        }
        // A fit whose pixels all lie above the ROI (only the second search finds one) is
        // extrapolated down over the ROI's rows: a short far segment sets its slope, not its
        // curvature. It starts as its chord over its rows (the refinement may bend it again).
        let (y0, y1) = init.rows_px;
        let p = if y1 < setup.roi.0 as f64 && y1 > y0 {
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
        let filter = match setup.new_filter(&theta) {
            Ok(filter) => filter,
            Err(e) => {
                health.filter_failed(side, e);
                return false;
            }
        };
        // Keep the points the LS fit used, for overlays.
        lane.points.clear();
        let (s, c) = init.line.theta_rad.sin_cos();
        let band = setup.init_params.band_px;
        for &(x, y) in &self.index.candidates {
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
        health.counters.initialisations[side.index()] += 1;
        true
    }
}

/// After the frame's searches, each lane set aside on it (`Lane::set_aside`, kept with its
/// side through a hand-over): what a lane now on its side replaced (a switch, counted, that
/// the crossing gate may undo), else put back as it was.
pub(super) fn settle_set_asides(lanes: &mut Lanes, health: &mut Health) {
    for (side, lane) in lanes.sides_mut() {
        let Some(set_aside) = lane.set_aside.take() else {
            continue;
        };
        if lane.has_estimate() {
            lane.replaced = Some(set_aside);
            health.counters.revalidation_switches[side.index()] += 1;
        } else {
            lane.restore(set_aside);
        }
    }
}
