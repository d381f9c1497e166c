//! One lane's state between frames ([`Lane`]: its filter, the prediction, its state machine and
//! the buffers of its last measurement), the pair of them addressed by [`Side`] ([`Lanes`]), and
//! what the tracker keeps about its own health ([`Health`]: counters and the last filter
//! failure per lane).

use std::ops::{Index, IndexMut};

use hough_init::Chord;
use info_filter::ParabolaKif;
use lane_geometry::FitRows;
use nalgebra::Vector3;
use vision_gradient::ColSpan;

use super::report::{FarSegment, LaneReport, LaneState, Side, TrackerCounters};
use super::setup::Setup;
use crate::error::FilterFailure;
use crate::wrls_lane::WrlsLane;

/// The per-lane recursive estimator state.
#[derive(Debug, Clone)]
pub(super) enum LaneFilter {
    Kif(ParabolaKif),
    Wrls(WrlsLane),
}

impl LaneFilter {
    /// The estimate's column at `row_px`, px.
    pub(super) fn col_at_row(&self, row_px: f64) -> f64 {
        match self {
            LaneFilter::Kif(k) => k.col_at_row_px(row_px),
            LaneFilter::Wrls(w) => w.col_at_row_px(row_px),
        }
    }
    /// Its chord between rows `yt` and `yb` with `support` (the ego pair's view of a lane).
    pub(super) fn chord(&self, yt: f64, yb: f64, support: f64) -> Chord {
        Chord {
            col_top_px: self.col_at_row(yt),
            col_bottom_px: self.col_at_row(yb),
            support,
        }
    }
    /// `[a1, a2, a3]` of the estimate, px.
    pub(super) fn coeffs(&self) -> [f64; 3] {
        let v = match self {
            LaneFilter::Kif(k) => k.estimate(),
            LaneFilter::Wrls(w) => w.estimate(),
        };
        [v[0], v[1], v[2]]
    }
}

/// One lane between frames. Its slot in [`Lanes`] is its side: a hand-over moves the estimate
/// to the other slot ([`Lanes::hand_over`]), never the side.
#[derive(Debug)]
pub(super) struct Lane {
    pub(super) state: LaneState,
    pub(super) filter: Option<LaneFilter>,
    pub(super) predicted: Option<LaneFilter>,
    pub(super) misses: u32,
    pub(super) points: Vec<(f32, f32)>,
    /// Relative precision `1/v` of each point of `points` after a tracking update
    /// (`points::mark_centre`).
    pub(super) weights: Vec<f64>,
    pub(super) spans: Vec<ColSpan>,
    pub(super) rows: [f64; 2],
    /// The far segment followed up on this frame (module `reach`), working pixels.
    pub(super) far: Option<FarSegment>,
    /// Rows and weights of the points behind the last update or initialisation.
    pub(super) fit: FitRows,
    pub(super) points_now: usize,
    /// `points_now` of the frame before (a weak lane is set aside only when weak on two frames
    /// in a row, `track.revalidate_below_points`).
    pub(super) points_before: usize,
    pub(super) initialised_now: bool,
    /// Found by the second search (`roi.fallback_top_row_fraction`): refined, tracked and its
    /// kerb read over the taller rows, where its mark was, until it is initialised again from
    /// the ROI ([`Setup::rows_of`]).
    pub(super) tracked_tall: bool,
    /// `[α, β]`: the boundary reported lies `α + β·y` px from the edge the filter tracks — a
    /// kerb's foot from its top edge (`init.kerb_foot`); zero otherwise. Set after an
    /// initialisation, read again on each tracked frame and dropped after
    /// `track.lost_after_frames` frames without a kerb; cleared by the next initialisation. A
    /// kerb that appears later is not picked up until the lane is initialised again.
    pub(super) kerb_offset_px: [f64; 2],
    /// Tracked frames in a row on which the kerb behind `kerb_offset_px` was not read again.
    pub(super) kerb_misses: u32,
    /// Half the distance between the two lines of the double line the lane was centred on
    /// (`init.double_line_middle`: the half gap fitted over the rows read, the larger of its
    /// values at the top and bottom rows searched; px), 0 otherwise. Its
    /// tracking windows reach at least twice as far, so that they hold both lines; cleared by
    /// the next initialisation.
    pub(super) pair_half_gap_px: f64,
    pub(super) updated_now: bool,
    pub(super) fresh: bool,
    /// The tracked lane a switch replaced on this frame (the lane is `initialised_now`),
    /// restored if the crossing gate undoes the switch; `None` otherwise.
    pub(super) replaced: Option<SavedEstimate>,
    /// A weak lane the ROI's joint choice kept nothing of on this frame, set aside while its
    /// side is searched for again (`track.revalidate_below_points`); tied to its side (not
    /// moved by a hand-over); `None` otherwise and after the initialisation.
    pub(super) set_aside: Option<SavedEstimate>,
}

/// A tracked estimate taken out of its lane on this frame — replaced by a switch to another
/// candidate, or set aside — with what it carried: filter, prediction, state, misses, the
/// offsets read for it (a kerb's foot, a double line's gap), whether its next update is its
/// first (`fresh`, not jump-gated), and this frame's update (its rows, row profile and points).
/// [`Lane::restore`] puts it back; the buffers (points and weights, for overlays, and the
/// windows) are not kept: after a switch undone they are the candidate's until the next frame.
#[derive(Debug, Clone)]
pub(super) struct SavedEstimate {
    pub(super) filter: LaneFilter,
    pub(super) predicted: Option<LaneFilter>,
    pub(super) state: LaneState,
    pub(super) misses: u32,
    pub(super) kerb_offset_px: [f64; 2],
    pub(super) kerb_misses: u32,
    pub(super) pair_half_gap_px: f64,
    pub(super) fresh: bool,
    pub(super) tracked_tall: bool,
    pub(super) rows: [f64; 2],
    pub(super) fit: FitRows,
    pub(super) points_now: usize,
}

impl Lane {
    /// A lane without an estimate, its buffers sized once: `point_capacity` points and weights,
    /// a window span for each of `height_px` rows.
    pub(super) fn new(point_capacity: usize, height_px: usize) -> Self {
        Lane {
            state: LaneState::Initialising,
            filter: None,
            predicted: None,
            misses: 0,
            points: Vec::with_capacity(point_capacity),
            weights: Vec::with_capacity(point_capacity),
            spans: vec![ColSpan::EMPTY; height_px],
            rows: [0.0, 0.0],
            far: None,
            fit: FitRows::uniform(0.0, 0.0),
            points_now: 0,
            points_before: 0,
            initialised_now: false,
            tracked_tall: false,
            kerb_offset_px: [0.0; 2],
            kerb_misses: 0,
            pair_half_gap_px: 0.0,
            updated_now: false,
            fresh: false,
            replaced: None,
            set_aside: None,
        }
    }

    /// Back to no estimate (the next frame initialises it), its buffers kept.
    pub(super) fn reset(&mut self) {
        self.state = LaneState::Initialising;
        self.filter = None;
        self.predicted = None;
        self.kerb_offset_px = [0.0; 2];
        self.kerb_misses = 0;
        self.pair_half_gap_px = 0.0;
        self.misses = 0;
        self.points.clear();
        self.weights.clear();
        self.spans.fill(ColSpan::EMPTY);
        self.points_now = 0;
        self.tracked_tall = false;
        self.far = None;
    }

    /// The start of a frame: nothing initialised, updated, replaced or set aside on it yet;
    /// the last frame's point count kept as the one before.
    pub(super) fn begin_frame(&mut self) {
        self.initialised_now = false;
        self.updated_now = false;
        self.points_before = self.points_now;
        self.points_now = 0;
        self.replaced = None;
        self.set_aside = None;
        self.far = None;
    }

    /// A frame without an update: coasting on the prediction, lost after
    /// `track.lost_after_frames` in a row.
    pub(super) fn miss(&mut self, lost_after_frames: u32) {
        self.misses += 1;
        self.points_now = 0;
        self.state = if self.misses >= lost_after_frames {
            LaneState::Lost
        } else {
            LaneState::Coasting
        };
    }

    /// The filter restarted at `theta` (pixel coefficients) with `filter.p0_sigma_px`, after a
    /// reading of the image moved its estimate (a double line's middle, no turn back);
    /// `false`, the lane left as it was and the failure counted and kept in `health`, if the
    /// filter refuses it.
    pub(super) fn restart_filter(
        &mut self,
        side: Side,
        theta: &Vector3<f64>,
        setup: &Setup,
        health: &mut Health,
    ) -> bool {
        match setup.new_filter(theta) {
            Ok(filter) => {
                self.filter = Some(filter);
                true
            }
            Err(e) => {
                health.filter_failed(side, e);
                false
            }
        }
    }

    /// The lane's estimate with `filter` and `predicted` (the lane's own, taken or cloned by
    /// the caller).
    pub(super) fn saved_with(
        &self,
        filter: LaneFilter,
        predicted: Option<LaneFilter>,
    ) -> SavedEstimate {
        SavedEstimate {
            filter,
            predicted,
            state: self.state,
            misses: self.misses,
            kerb_offset_px: self.kerb_offset_px,
            kerb_misses: self.kerb_misses,
            pair_half_gap_px: self.pair_half_gap_px,
            fresh: self.fresh,
            tracked_tall: self.tracked_tall,
            rows: self.rows,
            fit: self.fit,
            points_now: self.points_now,
        }
    }

    /// Takes the estimate out of the lane (filter and prediction moved, not copied), leaving
    /// it lost; `None` without a filter.
    pub(super) fn take_estimate(&mut self) -> Option<SavedEstimate> {
        let filter = self.filter.take()?;
        let predicted = self.predicted.take();
        let saved = self.saved_with(filter, predicted);
        self.state = LaneState::Lost;
        Some(saved)
    }

    /// Puts back an estimate taken out on this frame ([`SavedEstimate`]), as it was after this
    /// frame's update or miss: not initialised on this frame.
    pub(super) fn restore(&mut self, before: SavedEstimate) {
        self.filter = Some(before.filter);
        self.predicted = before.predicted;
        self.state = before.state;
        self.misses = before.misses;
        self.kerb_offset_px = before.kerb_offset_px;
        self.kerb_misses = before.kerb_misses;
        self.pair_half_gap_px = before.pair_half_gap_px;
        self.fresh = before.fresh;
        self.tracked_tall = before.tracked_tall;
        self.rows = before.rows;
        self.fit = before.fit;
        self.points_now = before.points_now;
        self.initialised_now = false;
    }

    /// No estimate any more (lost: initialised again), and no windows or points to draw.
    pub(super) fn drop_estimate(&mut self) {
        self.filter = None;
        self.predicted = None;
        self.state = LaneState::Lost;
        self.points_now = 0;
        self.initialised_now = false;
        self.replaced = None;
        self.spans.fill(ColSpan::EMPTY);
        self.points.clear();
    }

    /// Its report for this frame, as the lane on `side`.
    pub(super) fn report(&self, side: Side) -> LaneReport {
        let coeffs = match self.state {
            LaneState::Tracking | LaneState::Coasting => {
                let [alpha, beta] = self.kerb_offset_px;
                self.filter
                    .as_ref()
                    .map(LaneFilter::coeffs)
                    .map(|[a1, a2, a3]| [a1, a2 + beta, a3 + alpha])
            }
            LaneState::Initialising | LaneState::Lost => None,
        };
        LaneReport {
            side,
            state: self.state,
            coeffs,
            rows: self.rows,
            points: self.points_now,
            initialised: self.initialised_now,
            far: self.far.filter(|_| coeffs.is_some()),
        }
    }

    pub(super) fn has_estimate(&self) -> bool {
        matches!(self.state, LaneState::Tracking | LaneState::Coasting) && self.filter.is_some()
    }
}

/// The two lanes, addressed by [`Side`].
#[derive(Debug)]
pub(super) struct Lanes([Lane; 2]);

impl Lanes {
    /// Both lanes without an estimate ([`Lane::new`]).
    pub(super) fn new(point_capacity: usize, height_px: usize) -> Self {
        Lanes([
            Lane::new(point_capacity, height_px),
            Lane::new(point_capacity, height_px),
        ])
    }

    /// Left then right.
    pub(super) fn iter(&self) -> impl Iterator<Item = &Lane> {
        self.0.iter()
    }

    /// Left then right.
    pub(super) fn iter_mut(&mut self) -> impl Iterator<Item = &mut Lane> {
        self.0.iter_mut()
    }

    /// `(side, lane)`, left then right.
    pub(super) fn sides_mut(&mut self) -> impl Iterator<Item = (Side, &mut Lane)> {
        Side::BOTH.into_iter().zip(self.0.iter_mut())
    }

    /// Both lanes at once, left then right.
    pub(super) fn pair(&self) -> &[Lane; 2] {
        &self.0
    }

    /// This frame's reports, left then right.
    pub(super) fn reports(&self) -> [LaneReport; 2] {
        [self.0[0].report(Side::Left), self.0[1].report(Side::Right)]
    }

    /// The lane on `from` becomes the lane on `to`: its filter, state and buffers move; each
    /// side keeps a lane set aside on this frame (`Lane::set_aside`: the searches replace it on
    /// its side), and a kerb's offset is dropped (it was read towards the old side). With
    /// `HandOver::DropOther`, the lane that was on `to` is dropped onto `from` (no estimate, no
    /// windows or points: the choice's candidate for that side, if any, is installed next);
    /// with `HandOver::Swap`, the two change sides. No allocation (the buffers are swapped).
    pub(super) fn hand_over(&mut self, from: Side, to: Side, other: HandOver) {
        if from == to {
            return;
        }
        self.0.swap(0, 1);
        let [a, b] = &mut self.0;
        // A lane set aside on this frame stays with its side: the searches replace it there.
        std::mem::swap(&mut a.set_aside, &mut b.set_aside);
        for lane in &mut self.0 {
            lane.kerb_offset_px = [0.0; 2];
            lane.kerb_misses = 0;
        }
        if other == HandOver::DropOther {
            self[from].drop_estimate();
        }
    }
}

/// What [`Lanes::hand_over`] does with the lane that was on the receiving side.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum HandOver {
    /// It changes sides too (both lanes were put on the other side).
    Swap,
    /// It is dropped (a lane change: the crossed boundary replaces it).
    DropOther,
}

impl Index<Side> for Lanes {
    type Output = Lane;
    fn index(&self, side: Side) -> &Lane {
        &self.0[side.index()]
    }
}

impl IndexMut<Side> for Lanes {
    fn index_mut(&mut self, side: Side) -> &mut Lane {
        &mut self.0[side.index()]
    }
}

/// What the tracker keeps about its own run: the counters it reports, the last filter failure
/// per lane, and how many frames ago the whole region last went through the gradient.
#[derive(Debug, Default)]
pub(super) struct Health {
    pub(super) counters: TrackerCounters,
    /// The last filter failure per lane (left, right), kept typed without allocating.
    pub(super) last_failure: [Option<FilterFailure>; 2],
    /// Frames since the last one whose whole region went through the gradient (an
    /// initialisation or a re-validation).
    pub(super) frames_since_full_gradient: u64,
}

impl Health {
    /// A filter on `side` refused a set-up, prediction or update: counted and kept.
    pub(super) fn filter_failed(&mut self, side: Side, e: FilterFailure) {
        self.counters.filter_failures[side.index()] += 1;
        self.last_failure[side.index()] = Some(e);
    }
}
