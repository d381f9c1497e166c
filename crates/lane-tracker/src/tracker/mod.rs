//! The tracking loop (paper Fig. 1): directional gradient → Hough + LS initialisation → KIF
//! (or WRLS) recursion, per lane, with a state machine and sanity gates.

use hough_init::{AngleBand, Chord, HoughWorkspace, LaneInitParams, OrientedPoint, Parabola};
use info_filter::{ParabolaKif, ProcessNoise, RowNorm, ThetaCov};
use lane_geometry::FitRows;
use nalgebra::{Matrix3, Vector3};
use serde::Serialize;
use vision_gradient::{ColSpan, EdgeBuffer, EdgeClass, GradientDetector, GreyImage};

use crate::error::FilterFailure;
use crate::wrls_lane::WrlsLane;
use crate::{GreyFrame, TrackerConfig, TrackerError};

mod chosen_fit;
mod double_line;
mod init;
mod kerb;
mod points;
mod stripe_trace;
#[cfg(test)]
mod tests;
mod turn_back;
mod update;
mod windows;
mod working;

use points::{BANDS, Candidate, MAX_WINDOW_HALF_WIDTH};
use working::WorkingScale;

/// Which lane.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Side {
    /// The left lane mark (edge class [`EdgeClass::LeftLane`], a `/` in the image).
    Left,
    /// The right lane mark (edge class [`EdgeClass::RightLane`], a `\` in the image).
    Right,
}

/// Per-lane state, reported every frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum LaneState {
    /// No estimate yet: the first initialisation has not succeeded.
    Initialising,
    /// Updated from this frame's points (or initialised on this frame).
    Tracking,
    /// Too few points (or a gated update) this frame, for fewer than
    /// `track.lost_after_frames` frames in a row: the reported coefficients are the prediction
    /// (shifted to a kerb's foot where the lane has one, `init.kerb_foot`).
    Coasting,
    /// Too many missed frames in a row: no coefficients are reported and the lane is
    /// re-initialised (Hough + LS over the whole region of interest) every frame until it is found.
    Lost,
}

impl LaneState {
    /// Lowercase name, as in the JSON output.
    pub fn name(self) -> &'static str {
        match self {
            LaneState::Initialising => "initialising",
            LaneState::Tracking => "tracking",
            LaneState::Coasting => "coasting",
            LaneState::Lost => "lost",
        }
    }
}

/// The recursive estimator of the lane coefficients.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Estimator {
    /// Kalman information filter, positive-definite form (paper eqs. 6–12, 24). The default.
    #[default]
    Kif,
    /// Exponentially weighted recursive least squares (paper eqs. 25–27), λ =
    /// `filter.wrls_lambda`, applied once per frame.
    Wrls,
}

/// One lane's result for one frame.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct LaneReport {
    /// Which lane.
    pub side: Side,
    /// Its state after this frame.
    pub state: LaneState,
    /// `[a1, a2, a3]` of `x = a1·y² + a2·y + a3` (x column, y row, pixels of the input image);
    /// `None` when the lane is [`LaneState::Initialising`] or [`LaneState::Lost`].
    pub coeffs: Option<[f64; 3]>,
    /// `[y_min, y_max]`, rows (px) of the points behind the estimate (last update or initialisation).
    pub rows: [f64; 2],
    /// Points used this frame (filter update, or LS fit of an initialisation; after an
    /// initialisation's refinement with `init.stripe_trace`, its points and the traced stripe's
    /// middles, so beyond `track.max_points_per_lane`); 0 when missed,
    /// also for an initialisation whose refinement missed (the LS parabola is kept, reported
    /// [`LaneState::Tracking`] and `initialised`).
    pub points: usize,
    /// `true` if the lane was (re-)initialised by Hough + LS on this frame.
    pub initialised: bool,
}

impl LaneReport {
    /// Column of the reported parabola at `row_px`, if there is one.
    pub fn col_at_row(&self, row_px: f64) -> Option<f64> {
        self.coeffs
            .map(|c| Parabola::from_coeffs(c).col_at_row(row_px))
    }
}

/// The tracker's result for one frame.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct TrackReport {
    /// Left then right.
    pub lanes: [LaneReport; 2],
    /// `true` if the full region of interest went through the gradient (an initialisation was
    /// attempted); `false` on a pure tracking frame (gradient inside the windows only).
    pub full_gradient: bool,
}

/// Counters over the tracker's life.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
pub struct TrackerCounters {
    /// Frames processed.
    pub frames: u64,
    /// Successful initialisations per lane (left, right), the first one included.
    pub initialisations: [u64; 2],
    /// Updates rejected by the jump gate, per lane.
    pub gated_jumps: [u64; 2],
    /// Estimates rejected because the lanes crossed, per lane.
    pub gated_crossings: [u64; 2],
    /// Frames on which the tracked pair had lost an ego lane's shape and both lanes were
    /// initialised again (the pair gate; joint initialisation only).
    pub gated_pairs: u64,
    /// Re-validations (`track.revalidate_every_frames`, `track.revalidate_below_points`):
    /// frames on which the tracked pair was weighed against a fresh initialisation's
    /// candidates.
    pub revalidations: u64,
    /// Tracked lanes the joint choice replaced by a candidate off their mark (with
    /// re-validation on: in a re-validation, or when the other side was initialised again),
    /// or a weak lane it set aside replaced by the frame's searches
    /// (`track.revalidate_below_points`), per lane.
    pub revalidation_switches: [u64; 2],
    /// Weak lanes set aside while the frame's second search looked for their side
    /// (`track.revalidate_below_points`: weak on two frames in a row, kept nothing of by the
    /// ROI's choice), per lane; those the search replaced count in `revalidation_switches`
    /// too, the others were put back as they were.
    pub set_asides: [u64; 2],
    /// Lane changes: a tracked boundary the joint initialisation or a re-validation put on the
    /// other side of the pair (the camera crossed it), handed over to that side.
    pub lane_changes: u64,
    /// Filter failures, per lane: any set-up, prediction or update the filter refused (a
    /// non-positive-definite matrix, or an input it rejects, such as a variance or forgetting
    /// factor out of range).
    pub filter_failures: [u64; 2],
}

/// The per-lane recursive estimator state.
#[derive(Debug, Clone)]
enum LaneFilter {
    Kif(ParabolaKif),
    Wrls(WrlsLane),
}

impl LaneFilter {
    fn col_at_row(&self, row_px: f64) -> f64 {
        match self {
            LaneFilter::Kif(k) => k.col_at_row_px(row_px),
            LaneFilter::Wrls(w) => w.col_at_row_px(row_px),
        }
    }
    /// Its chord between rows `yt` and `yb` with `support` (the ego pair's view of a lane).
    fn chord(&self, yt: f64, yb: f64, support: f64) -> Chord {
        Chord {
            col_top_px: self.col_at_row(yt),
            col_bottom_px: self.col_at_row(yb),
            support,
        }
    }
    fn coeffs(&self) -> [f64; 3] {
        let v = match self {
            LaneFilter::Kif(k) => k.estimate(),
            LaneFilter::Wrls(w) => w.estimate(),
        };
        [v[0], v[1], v[2]]
    }
}

#[derive(Debug)]
struct Lane {
    side: Side,
    class: EdgeClass,
    band: AngleBand,
    state: LaneState,
    filter: Option<LaneFilter>,
    predicted: Option<LaneFilter>,
    misses: u32,
    points: Vec<(f32, f32)>,
    /// Relative precision `1/v` of each point of `points` after a tracking update
    /// (`points::mark_centre`).
    weights: Vec<f64>,
    spans: Vec<ColSpan>,
    rows: [f64; 2],
    /// Rows and weights of the points behind the last update or initialisation.
    fit: FitRows,
    points_now: usize,
    /// `points_now` of the frame before (a weak lane is set aside only when weak on two frames
    /// in a row, `track.revalidate_below_points`).
    points_before: usize,
    initialised_now: bool,
    /// Found by the second search (`roi.fallback_top_row_fraction`): refined, tracked and its
    /// kerb read over the taller rows, where its mark was, until it is initialised again from
    /// the ROI ([`LaneTracker::rows_of`]).
    tracked_tall: bool,
    /// `[α, β]`: the boundary reported lies `α + β·y` px from the edge the filter tracks — a
    /// kerb's foot from its top edge (`init.kerb_foot`); zero otherwise. Set after an
    /// initialisation, read again on each tracked frame and dropped after
    /// `track.lost_after_frames` frames without a kerb; cleared by the next initialisation. A
    /// kerb that appears later is not picked up until the lane is initialised again.
    kerb_offset_px: [f64; 2],
    /// Tracked frames in a row on which the kerb behind `kerb_offset_px` was not read again.
    kerb_misses: u32,
    /// Half the distance between the two lines of the double line the lane was centred on
    /// (`init.double_line_middle`: the half gap fitted over the rows read, the larger of its
    /// values at the top and bottom rows searched; px), 0 otherwise. Its
    /// tracking windows reach at least twice as far, so that they hold both lines; cleared by
    /// the next initialisation.
    pair_half_gap_px: f64,
    updated_now: bool,
    fresh: bool,
    /// The tracked lane a switch replaced on this frame (the lane is `initialised_now`),
    /// restored if the crossing gate undoes the switch; `None` otherwise.
    replaced: Option<SavedEstimate>,
    /// A weak lane the ROI's joint choice kept nothing of on this frame, set aside while its
    /// side is searched for again (`track.revalidate_below_points`); tied to its side (not
    /// moved by a hand-over); `None` otherwise and after the initialisation.
    set_aside: Option<SavedEstimate>,
}

/// A tracked estimate taken out of its lane on this frame — replaced by a switch to another
/// candidate, or set aside — with what it carried: filter, prediction, state, misses, the
/// offsets read for it (a kerb's foot, a double line's gap), whether its next update is its
/// first (`fresh`, not jump-gated), and this frame's update (its rows, row profile and points).
/// [`Lane::restore`] puts it back; the buffers (points and weights, for overlays, and the
/// windows) are not kept: after a switch undone they are the candidate's until the next frame.
#[derive(Debug, Clone)]
struct SavedEstimate {
    filter: LaneFilter,
    predicted: Option<LaneFilter>,
    state: LaneState,
    misses: u32,
    kerb_offset_px: [f64; 2],
    kerb_misses: u32,
    pair_half_gap_px: f64,
    fresh: bool,
    tracked_tall: bool,
    rows: [f64; 2],
    fit: FitRows,
    points_now: usize,
}

impl Lane {
    /// The lane's estimate with `filter` and `predicted` (the lane's own, taken or cloned by
    /// the caller).
    fn saved_with(&self, filter: LaneFilter, predicted: Option<LaneFilter>) -> SavedEstimate {
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
    fn take_estimate(&mut self) -> Option<SavedEstimate> {
        let filter = self.filter.take()?;
        let predicted = self.predicted.take();
        let saved = self.saved_with(filter, predicted);
        self.state = LaneState::Lost;
        Some(saved)
    }

    /// Puts back an estimate taken out on this frame ([`SavedEstimate`]), as it was after this
    /// frame's update or miss: not initialised on this frame.
    fn restore(&mut self, before: SavedEstimate) {
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
    fn drop_estimate(&mut self) {
        self.filter = None;
        self.predicted = None;
        self.state = LaneState::Lost;
        self.points_now = 0;
        self.initialised_now = false;
        self.replaced = None;
        self.spans.fill(ColSpan::EMPTY);
        self.points.clear();
    }

    fn report(&self) -> LaneReport {
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
            side: self.side,
            state: self.state,
            coeffs,
            rows: self.rows,
            points: self.points_now,
            initialised: self.initialised_now,
        }
    }

    fn has_estimate(&self) -> bool {
        matches!(self.state, LaneState::Tracking | LaneState::Coasting) && self.filter.is_some()
    }
}

/// Most Hough candidate lines per angle band in the joint initialisation
/// (`init.candidate_lines` is validated to at most this).
pub(crate) const MAX_CANDIDATE_LINES: usize = 8;

/// One Hough candidate line of the last joint initialisation (`init.candidate_lines > 0`) as the
/// choice of the ego pair weighed it: for overlays, and for finding at which stage a lane is lost
/// (`lane_eval::labelled::census_lanes`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct InitCandidate {
    /// The angle band whose pixels voted for it: [`Side::Left`] the `/` band, [`Side::Right`]
    /// the `\` band (on a curve a boundary may lean either way; the choice puts it on a side by
    /// position).
    pub band: Side,
    /// `[a1, a2, a3]` of `x = a1·y² + a2·y + a3`, px: the least-squares parabola the choice
    /// weighed (`init.candidate_coverage`), else the Hough line itself (`a1 = 0`).
    pub coeffs: [f64; 3],
    /// Its support in the choice: the row coverage net of the clutter beside it
    /// (`init.candidate_coverage`), else its Hough votes; counted in the working frame
    /// ([`LaneTracker::working_size`]) like every count the tracker reports.
    pub support: f64,
    /// The side the choice gave it, if any. A side without an estimate, or whose competing
    /// tracked lane (re-validation on) lies off this candidate's mark, is then initialised from
    /// this candidate's line refitted by least squares and refined in the windows
    /// (`track.refine_passes`), unless the fit or the sanity checks refuse it; a candidate on
    /// the tracked lane's own mark is marked but leaves the lane as it is. A side the choice
    /// gave a tracked lane's own chord has no chosen candidate.
    pub chosen: Option<Side>,
}

/// What an overlay needs of one lane: its windows, its points and its estimate. The windows
/// and the points are those of the edge the filter tracks; on a kerb (`init.kerb_foot`) the
/// reported boundary lies on the kerb's foot, a few pixels from them.
#[derive(Debug, Clone, Copy)]
pub struct LaneView<'a> {
    /// The lane's report for the last frame.
    pub report: LaneReport,
    /// Window of interest per image row (empty spans outside it) used on the last frame; all
    /// empty if the lane was not tracked on it.
    pub spans: &'a [ColSpan],
    /// The points fed to the filter or the LS fit on the last frame, `(col_px, row_px)`.
    pub points: &'a [(f32, f32)],
}

/// The lane tracker for frames of one size. Build once; [`LaneTracker::track`] per frame does
/// not allocate.
#[derive(Debug)]
pub struct LaneTracker {
    cfg: TrackerConfig,
    estimator: Estimator,
    /// The working frame's size, px (module `working`): the input's own when it is not
    /// resampled. Every stage works in these pixels.
    width: usize,
    height: usize,
    /// The input frames' size, px.
    input_size: (usize, usize),
    /// Input pixels per working pixel (`frame.working_width_px`).
    scale: WorkingScale,
    /// The working frame's pixels, `width` a row (empty when the input is not resampled), and
    /// the column sums of its box average (the input's width).
    work: Vec<u8>,
    work_sums: Vec<u32>,
    /// The working rows any stage reads, `[first, end)`: the regions searched and the Sobel's
    /// row beside them; only these are resampled.
    work_rows: (usize, usize),
    /// With a resampled input: the last frame's reports, candidates, windows and points in
    /// input pixels (what the accessors hand out), refreshed at the end of every frame (also
    /// one that returned an error) and by `reset`.
    out_lanes: [LaneReport; 2],
    out_candidates: Vec<InitCandidate>,
    out_spans: [Vec<ColSpan>; 2],
    out_points: [Vec<(f32, f32)>; 2],
    /// The ROI's rows `[top, bottom)` (`roi.*_row_fraction`), px; fixed.
    roi: (usize, usize),
    /// The rows the current stage reads, `[top, bottom)`, px: [`Self::roi`], or the second
    /// search's taller rows while it runs, while a lane it found is refined, and while such a
    /// lane (`Lane::tracked_tall`) is tracked and its kerb read again.
    search_rows: (usize, usize),
    /// The rows of the second search (`roi.fallback_top_row_fraction`), if any.
    fallback_roi: Option<(usize, usize)>,
    detector: GradientDetector,
    edges: EdgeBuffer,
    /// The edge pixels that pair into bright stripes (`gradient.stripe_paired_votes`).
    paired: EdgeBuffer,
    hough: HoughWorkspace,
    init_params: LaneInitParams,
    candidates: Vec<(f32, f32)>,
    /// The candidate pixels once each, with the normal angle of their edge and their weight as
    /// votes, for the orientation-restricted Hough vote (`init.orientation_tolerance_deg > 0`;
    /// empty and unallocated otherwise).
    oriented: Vec<OrientedPoint>,
    /// The candidate pixels as `(column, weight)` sorted by row then column,
    /// `row_start[r]..row_start[r + 1]` the pixels of row `r` (`init.candidate_coverage`), and
    /// a counting-sort cursor per row.
    by_row: Vec<(u16, u16)>,
    /// One bit per image pixel: the paired pixels of one class while `by_row` is built.
    paired_mask: Vec<u64>,
    row_start: Vec<u32>,
    row_next: Vec<u32>,
    /// The indices in `edges` of one class's pixels while `by_row` is built (capacity: the
    /// buffer's, plus one).
    of_class: Vec<u32>,
    scratch: Vec<Candidate>,
    /// Point selection's residual histograms, one per third of the rows searched
    /// (`points::BANDS`), bins `0..=2w` of a window `±w` px.
    residual_hist: Box<[[u32; 2 * MAX_WINDOW_HALF_WIDTH + 1]; BANDS]>,
    /// The rows' kerb feet `(row, offset)` read by `onto_kerb_foot` and `recheck_kerb_foot`
    /// (capacity: the height).
    kerb_rows: Vec<(f64, f64)>,
    /// The middles of the stripe `stripe_trace::trace_stripe` follows, one a row (capacity:
    /// the height).
    traced: Vec<(f32, f32)>,
    row_norm: RowNorm,
    q: ProcessNoise<3>,
    p0: ThetaCov,
    lanes: [Lane; 2],
    /// The candidates of the last frame's joint initialisation, then those of its second search
    /// (capacity `4 · MAX_CANDIDATE_LINES`, never exceeded); empty on a frame without one.
    init_candidates: Vec<InitCandidate>,
    counters: TrackerCounters,
    /// The last filter failure per lane (left, right), kept typed without allocating.
    last_failure: [Option<FilterFailure>; 2],
    /// Frames since the last one whose whole ROI went through the gradient (an initialisation
    /// or a re-validation).
    frames_since_full_gradient: u64,
    /// Per image row, the columns of the nearest candidate pixels on each side that
    /// `fill_candidates_near` left out (`chosen_fit::fit_chosen_line`).
    left_out_cols: Box<[(f32, f32)]>,
}

impl LaneTracker {
    /// A tracker for `width × height` frames. Validates `cfg`.
    pub fn new(
        cfg: &TrackerConfig,
        estimator: Estimator,
        width: usize,
        height: usize,
    ) -> Result<Self, TrackerError> {
        cfg.validate()?;
        if width < 3 || height < 3 {
            return Err(TrackerError::ZeroSize { width, height });
        }
        if width > hough_init::MAX_IMAGE_SIDE_PX || height > hough_init::MAX_IMAGE_SIDE_PX {
            return Err(hough_init::HoughError::InvalidImageSize {
                width_px: width,
                height_px: height,
                reason: "a side exceeds MAX_IMAGE_SIDE_PX (16384 px)",
            }
            .into());
        }
        let input_size = (width, height);
        let working = WorkingScale::for_input(width, height, cfg.frame.working_width_px);
        let (width, height) = working.working_size(width, height);
        if width < 3 || height < 3 {
            return Err(TrackerError::ZeroSize {
                width: input_size.0,
                height: input_size.1,
            });
        }
        let detector = GradientDetector::new(cfg.gradient.params())?;
        let roi = cfg.roi_rows(height);
        let fallback_roi = cfg.fallback_roi_rows(height);
        // (Refuses a side above `hough_init::MAX_IMAGE_SIDE_PX` before anything is sized.)
        let mut hough = HoughWorkspace::new(width, height, cfg.init.hough_params())?;
        // The buffers hold the pixels of the tallest region searched.
        let capacity = width * (roi.1 - fallback_roi.map_or(roi.0, |r| r.0));
        if cfg.init.orientation_tolerance_deg > 0.0 {
            // The oriented vote's points: one class of the tallest region's pixels at most.
            hough.reserve_oriented_points(capacity);
        }
        let init_params = cfg.init.lane_params();
        init_params.validate()?;
        let center = (roi.0 + roi.1 - 1) as f64 / 2.0;
        let scale = ((roi.1 - 1 - roi.0) as f64 / 2.0).max(1.0);
        let row_norm = RowNorm::new(center, scale)?;
        let f = &cfg.filter;
        let q_u = Matrix3::from_diagonal(&Vector3::from(f.q_sigma_px.map(|s| s * s)));
        let q = ProcessNoise::new(&q_u)?;
        let p0 = ThetaCov::Normalised(Matrix3::from_diagonal(&Vector3::from(
            f.p0_sigma_px.map(|s| s * s),
        )));
        let [left_band, right_band] = cfg.gradient.hough_bands();
        let make_lane = |side, class, band| Lane {
            side,
            class,
            band,
            state: LaneState::Initialising,
            filter: None,
            predicted: None,
            misses: 0,
            points: Vec::with_capacity(cfg.track.max_points_per_lane.max(capacity.min(1 << 16))),
            weights: Vec::with_capacity(cfg.track.max_points_per_lane.max(capacity.min(1 << 16))),
            spans: vec![ColSpan::EMPTY; height],
            rows: [0.0, 0.0],
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
        };
        let lanes = [
            make_lane(Side::Left, EdgeClass::LeftLane, left_band),
            make_lane(Side::Right, EdgeClass::RightLane, right_band),
        ];
        for lane in &lanes {
            lane.band.validate()?;
        }
        let resampled = working.resamples();
        let work_rows = (
            fallback_roi
                .map_or(roi.0, |r| r.0.min(roi.0))
                .saturating_sub(1),
            (roi.1 + 1).min(height),
        );
        let point_capacity = if resampled {
            lanes[0].points.capacity()
        } else {
            0
        };
        Ok(LaneTracker {
            cfg: *cfg,
            estimator,
            width,
            height,
            input_size,
            scale: working,
            work: vec![0; if resampled { width * height } else { 0 }],
            work_sums: vec![0; if resampled { input_size.0 } else { 0 }],
            work_rows,
            out_lanes: [0, 1].map(|i| working.report_to_input(lanes[i].report())),
            out_candidates: Vec::with_capacity(if resampled {
                4 * MAX_CANDIDATE_LINES
            } else {
                0
            }),
            out_spans: std::array::from_fn(|_| {
                vec![ColSpan::EMPTY; if resampled { input_size.1 } else { 0 }]
            }),
            out_points: std::array::from_fn(|_| Vec::with_capacity(point_capacity)),
            roi,
            search_rows: roi,
            fallback_roi,
            detector,
            edges: EdgeBuffer::with_capacity(capacity),
            paired: EdgeBuffer::with_capacity(capacity),
            hough,
            init_params,
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
            paired_mask: vec![0; (width * height).div_ceil(64)],
            row_next: Vec::with_capacity(height),
            of_class: Vec::with_capacity(capacity + 1),
            scratch: Vec::with_capacity(capacity),
            residual_hist: Box::new([[0; 2 * MAX_WINDOW_HALF_WIDTH + 1]; BANDS]),
            left_out_cols: vec![(f32::NEG_INFINITY, f32::INFINITY); height].into_boxed_slice(),
            kerb_rows: Vec::with_capacity(height),
            traced: Vec::with_capacity(height),
            row_norm,
            q,
            p0,
            lanes,
            init_candidates: Vec::with_capacity(4 * MAX_CANDIDATE_LINES),
            counters: TrackerCounters::default(),
            last_failure: [None; 2],
            frames_since_full_gradient: 0,
        })
    }

    /// Frame size this tracker takes, px (the input's; it may work on a resampled frame:
    /// [`LaneTracker::working_size`]).
    pub fn frame_size(&self) -> (usize, usize) {
        self.input_size
    }

    /// The size of the frame the stages work on, px: the input box-averaged over `f × f`
    /// blocks, `f` the whole number nearest the input width over `frame.working_width_px`
    /// (module `tracker::working`); the input's own size when `f = 1`. The configuration's
    /// pixel fields are in these pixels; everything the tracker reports is in input pixels.
    pub fn working_size(&self) -> (usize, usize) {
        (self.width, self.height)
    }

    /// Input pixels per working pixel along each axis (`f ≥ 1`; module `tracker::working`):
    /// working pixel `c'` is the mean of input pixels `f·c' … f·c' + f − 1`, centred on input
    /// `x = f·c' + (f − 1)/2`. 1 when the stages work on the input itself.
    pub fn working_factor(&self) -> usize {
        self.scale.factor()
    }

    /// What the stages read of the last frame, when the input is resampled (`f > 1`): the
    /// working frame ([`LaneTracker::working_size`]) and the rows `[first, end)` of it that are
    /// written — the rows any stage reads (the ROI, the second search's rows, a row beside
    /// them for the Sobel); the other rows are not (zero). All zero before the first frame.
    /// `None` with `f = 1`: the stages read the input frame as it is. For diagnostics on the
    /// working frame (`lane_eval::labelled::census_lanes`); no copy.
    pub fn working_frame(&self) -> Option<(GreyImage<'_>, (usize, usize))> {
        if !self.scale.resamples() {
            return None;
        }
        let image = GreyImage::new(&self.work, self.width, self.height, self.width).ok()?;
        Some((image, self.work_rows))
    }

    /// The rows lane `i` is refined, tracked and its kerb read over: the second search's taller
    /// rows for a lane it found (`Lane::tracked_tall`), else the ROI's.
    fn rows_of(&self, i: usize) -> (usize, usize) {
        match (self.fallback_roi, self.lanes.get(i)) {
            (Some(tall), Some(lane)) if lane.tracked_tall => tall,
            _ => self.roi,
        }
    }

    /// `stage` run with `search_rows` set to `rows` (`[top, bottom)`, px), which are the ROI's
    /// again afterwards, whatever `stage` returns: every stage reads its rows from
    /// `search_rows`, and outside such a call they are the ROI's.
    fn over_rows<T>(&mut self, rows: (usize, usize), stage: impl FnOnce(&mut Self) -> T) -> T {
        self.search_rows = rows;
        let out = stage(self);
        self.search_rows = self.roi;
        out
    }

    /// Rows searched, `[top, bottom)`, px of the input (with a resampled input, the input rows
    /// the working ROI's rows average).
    pub fn roi_rows(&self) -> (usize, usize) {
        let f = self.scale.factor();
        (f * self.roi.0, (f * self.roi.1).min(self.input_size.1))
    }

    /// The configuration in use.
    pub fn config(&self) -> &TrackerConfig {
        &self.cfg
    }

    /// The estimator in use.
    pub fn estimator(&self) -> Estimator {
        self.estimator
    }

    /// Counters since construction (or the last [`LaneTracker::reset`]).
    pub fn counters(&self) -> &TrackerCounters {
        &self.counters
    }

    /// Forget both lanes (next frame initialises again) and zero the counters.
    pub fn reset(&mut self) {
        for lane in &mut self.lanes {
            lane.state = LaneState::Initialising;
            lane.filter = None;
            lane.predicted = None;
            lane.kerb_offset_px = [0.0; 2];
            lane.kerb_misses = 0;
            lane.pair_half_gap_px = 0.0;
            lane.misses = 0;
            lane.points.clear();
            lane.weights.clear();
            lane.spans.fill(ColSpan::EMPTY);
            lane.points_now = 0;
            lane.tracked_tall = false;
        }
        self.init_candidates.clear();
        self.counters = TrackerCounters::default();
        self.last_failure = [None; 2];
        self.frames_since_full_gradient = 0;
        // What the accessors hand out with a resampled input: the cleared lanes, mapped.
        if self.scale.resamples() {
            self.publish_in_input_pixels();
        }
    }

    /// Why lane `side`'s filter last refused a prediction, an update or an initialisation (the
    /// component's typed error; counted in [`TrackerCounters::filter_failures`]), `None` if it
    /// never has since construction or the last [`LaneTracker::reset`].
    pub fn last_filter_error(&self, side: Side) -> Option<FilterFailure> {
        self.last_failure[side as usize]
    }

    /// Covariance of one lane's reported coefficients `(a1, a2, a3)` in the pixel
    /// parameterisation (entry `(i, j)` in units of `a_i·a_j`), `None` when the lane has no
    /// estimate (initialising or lost) or its information matrix cannot be inverted. A kerb's
    /// offset (`init.kerb_foot`) is added to the reported coefficients as a shift whose own
    /// uncertainty (it is re-measured on each frame from a few rows) is not included: the
    /// covariance is the tracked edge's.
    ///
    /// KIF: `P_px = T·Y_u⁻¹·Tᵀ`, the inverse of the information matrix the filter propagates in
    /// the normalised rows `u = (y − y_c)/s`, mapped by the exact linear map `T` between the
    /// normalised and the pixel coefficients (`info_filter::RowNorm`). WRLS: its `P` (a scaled
    /// inverse normal matrix) times `filter.r_sigma_px²`, the least-squares covariance for that
    /// pixel noise. With a resampled input, mapped once more from working to input pixels
    /// (`T_w·P·T_wᵀ`, module `working`). No allocation.
    pub fn lane_covariance_px(&self, side: Side) -> Option<Matrix3<f64>> {
        let lane = &self.lanes[side as usize];
        if !lane.has_estimate() {
            return None;
        }
        let p = match lane.filter.as_ref()? {
            LaneFilter::Kif(k) => k.covariance().ok(),
            LaneFilter::Wrls(w) => {
                let r = self.cfg.filter.r_sigma_px;
                w.covariance_px().map(|p| p * (r * r))
            }
        }?;
        // In input pixels: `T·P·Tᵀ` (module `working`).
        Some(if self.scale.resamples() {
            self.scale.cov_to_input(&p)
        } else {
            p
        })
    }

    /// How one lane's estimate was fitted on the last update or initialisation: the weighted
    /// mean row and the summed weight of its points in each eighth of their rows (edge pixels
    /// weigh 1, mark centres their relative precision). `lane-geometry` uses it to remove the
    /// image-parabola model error ([`crate::camera::CameraModel::ego_lane`]). `None` when the
    /// lane has no estimate.
    pub fn lane_fit_rows(&self, side: Side) -> Option<FitRows> {
        let lane = &self.lanes[side as usize];
        let mut fit = lane.fit;
        for r in &mut fit.rows_px {
            *r = self.scale.to_input_px(*r);
        }
        lane.has_estimate().then_some(fit)
    }

    /// The Hough candidate lines of the last frame's joint initialisation or re-validation, both
    /// angle bands (at most `init.candidate_lines` each), with their support and the side the
    /// choice gave them ([`InitCandidate`]). Empty when the last frame ran neither (both lanes
    /// tracked between re-validations, or `init.candidate_lines = 0`, the paper's one line per
    /// band).
    pub fn init_candidates(&self) -> &[InitCandidate] {
        if self.scale.resamples() {
            &self.out_candidates
        } else {
            &self.init_candidates
        }
    }

    /// Windows, points and report of one lane after the last frame (for overlays).
    pub fn lane_view(&self, side: Side) -> LaneView<'_> {
        let i = side as usize;
        if self.scale.resamples() {
            return LaneView {
                report: self.out_lanes[i],
                spans: &self.out_spans[i],
                points: &self.out_points[i],
            };
        }
        let lane = &self.lanes[i];
        LaneView {
            report: lane.report(),
            spans: &lane.spans,
            points: &lane.points,
        }
    }

    /// Process one frame. Errors only for a frame of the wrong size or a component refusing
    /// its (validated) input; a lane that cannot be tracked is reported as such, not as an error.
    pub fn track(&mut self, frame: &GreyFrame) -> Result<TrackReport, TrackerError> {
        self.track_pixels(frame.data(), frame.width(), frame.height(), frame.width())
    }

    /// [`LaneTracker::track`] on borrowed pixels: `width × height` grey pixels, row `y` starting at
    /// `data[y * stride_px]` (`stride_px ≥ width`), so a caller's buffer (a numpy array, a capture
    /// buffer with padded rows) is read in place without a copy. Errors for a size other than the
    /// tracker's or a `data` too short for the stride.
    pub fn track_pixels(
        &mut self,
        data: &[u8],
        width: usize,
        height: usize,
        stride_px: usize,
    ) -> Result<TrackReport, TrackerError> {
        if (width, height) != self.input_size {
            return Err(TrackerError::FrameSize {
                expected_w: self.input_size.0,
                expected_h: self.input_size.1,
                got_w: width,
                got_h: height,
            });
        }
        let input = GreyImage::new(data, width, height, stride_px)?;
        if !self.scale.resamples() {
            return self.track_working(input);
        }
        // The working frame (module `working`), in a buffer taken out of `self` for the
        // frame (no allocation: `take` leaves an empty vector) and put back whatever happens.
        let mut work = std::mem::take(&mut self.work);
        self.scale.downscale_rows(
            &input,
            &mut work,
            self.width,
            self.work_rows,
            &mut self.work_sums,
        );
        let tracked = GreyImage::new(&work, self.width, self.height, self.width)
            .map_err(TrackerError::from)
            .and_then(|image| self.track_working(image));
        self.work = work;
        // Published whatever happened, so the accessors read this frame's state as they do
        // without resampling (also after an error part-way through).
        self.publish_in_input_pixels();
        let mut report = tracked?;
        report.lanes = self.out_lanes;
        Ok(report)
    }

    /// With a resampled input: the lanes' reports, candidates, windows and points as they are
    /// now, mapped to input pixels (module `working`), into the buffers the accessors hand out.
    fn publish_in_input_pixels(&mut self) {
        let s = self.scale;
        for (out, lane) in self.out_lanes.iter_mut().zip(&self.lanes) {
            *out = s.report_to_input(lane.report());
        }
        self.out_candidates.clear();
        // Within capacity: as many as `init_candidates` holds.
        self.out_candidates
            .extend(self.init_candidates.iter().map(|c| InitCandidate {
                coeffs: s.coeffs_to_input(c.coeffs),
                ..*c
            }));
        let f = s.factor();
        for (i, lane) in self.lanes.iter().enumerate() {
            for (y, span) in self.out_spans[i].iter_mut().enumerate() {
                *span = lane
                    .spans
                    .get(y / f)
                    .map_or(ColSpan::EMPTY, |&w| s.span_to_input(w));
            }
            let points = &mut self.out_points[i];
            points.clear();
            // Within capacity: the lane's own points buffer's.
            points.extend(lane.points.iter().map(|&(x, y)| {
                (
                    s.to_input_px(f64::from(x)) as f32,
                    s.to_input_px(f64::from(y)) as f32,
                )
            }));
        }
    }

    /// [`LaneTracker::track_pixels`] on the working frame.
    fn track_working(&mut self, image: GreyImage<'_>) -> Result<TrackReport, TrackerError> {
        self.counters.frames += 1;
        self.init_candidates.clear();
        for i in 0..2 {
            let lane = &mut self.lanes[i];
            lane.initialised_now = false;
            lane.updated_now = false;
            lane.points_before = lane.points_now;
            lane.points_now = 0;
            lane.replaced = None;
            lane.set_aside = None;
            if lane.has_estimate() {
                self.over_rows(self.rows_of(i), |t| t.track_lane(i, &image, true))?;
            } else {
                lane.spans.fill(ColSpan::EMPTY);
                lane.points.clear();
            }
        }
        self.pair_gate();
        let need_init = self.lanes.iter().any(|l| !l.has_estimate());
        // Re-validation (`track.revalidate_every_frames`, `track.revalidate_below_points`;
        // joint initialisation weighing its candidates by row coverage only): both lanes
        // tracked, the joint initialisation runs over the ROI and the tracked lanes compete with
        // its candidates — every `revalidate_every_frames` frames, and at once on a frame a
        // lane's window gave fewer than `revalidate_below_points` points.
        let track_cfg = &self.cfg.track;
        let every = u64::from(track_cfg.revalidate_every_frames);
        let weak = self
            .lanes
            .iter()
            .any(|l| l.points_now < track_cfg.revalidate_below_points);
        let revalidate = !need_init
            && self.cfg.init.candidate_lines > 0
            && self.cfg.init.candidate_coverage
            && ((every > 0 && self.frames_since_full_gradient + 1 >= every) || weak);
        self.counters.revalidations += u64::from(revalidate);
        self.frames_since_full_gradient = if need_init || revalidate {
            0
        } else {
            self.frames_since_full_gradient + 1
        };
        if need_init || revalidate {
            self.initialise(&image)?;
            // Refine a fresh initialisation on the same frame: `track.refine_passes` windowed
            // updates (at least one) from the LS parabola, with the window's outlier rejection
            // (the Hough band keeps clutter).
            for i in 0..2 {
                if self.lanes[i].initialised_now {
                    // A lane the second search found is refined over the rows it was found in.
                    self.over_rows(self.rows_of(i), |t| {
                        for _ in 0..t.cfg.track.refine_passes.max(1) {
                            t.track_lane(i, &image, false)?;
                        }
                        if t.cfg.init.stripe_trace {
                            t.trace_stripe(i, &image);
                        }
                        if t.cfg.init.no_turn_back {
                            t.straighten_turn_back(i);
                        }
                        let doubled =
                            t.cfg.init.double_line_middle && t.centre_on_double_line(i, &image);
                        if !doubled && t.cfg.init.kerb_foot {
                            t.onto_kerb_foot(i, &image);
                        }
                        Ok::<(), TrackerError>(())
                    })?;
                    let lane = &mut self.lanes[i];
                    if lane.state != LaneState::Tracking {
                        // The refinement missed: keep the LS initialisation as it was.
                        lane.state = LaneState::Tracking;
                        lane.misses = 0;
                    }
                    lane.initialised_now = true;
                }
            }
        }
        self.crossing_gate();
        // A kerb is read again against the tracked lanes' final estimates (after the crossing
        // gate, which may undo an update).
        // A lane tracked over the taller rows reads its kerb there, as its refinement did.
        for i in 0..2 {
            if self.lanes[i].has_estimate() && !self.lanes[i].initialised_now {
                self.over_rows(self.rows_of(i), |t| t.recheck_kerb_foot(i, &image));
            }
        }
        Ok(TrackReport {
            lanes: [self.lanes[0].report(), self.lanes[1].report()],
            full_gradient: need_init || revalidate,
        })
    }
}
