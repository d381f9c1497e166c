//! What the tracker reports: per lane and per frame ([`LaneReport`], [`TrackReport`]), its
//! counters ([`TrackerCounters`]), the candidates of a joint initialisation ([`InitCandidate`])
//! and what an overlay draws ([`LaneView`]). Every figure is in the input's pixels.

use hough_init::Parabola;
use serde::Serialize;
use vision_gradient::{ColSpan, EdgeClass};

/// Which lane.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Side {
    /// The left lane mark (edge class [`EdgeClass::LeftLane`], a `/` in the image).
    Left,
    /// The right lane mark (edge class [`EdgeClass::RightLane`], a `\` in the image).
    Right,
}

impl Side {
    /// Both sides, left then right (the order of every per-lane array).
    pub const BOTH: [Side; 2] = [Side::Left, Side::Right];

    /// The side's index in per-lane arrays (`[left, right]`).
    pub fn index(self) -> usize {
        self as usize
    }

    /// The other side.
    pub fn other(self) -> Side {
        match self {
            Side::Left => Side::Right,
            Side::Right => Side::Left,
        }
    }

    /// The edge class of this side's mark seen as the paper sees it: [`EdgeClass::LeftLane`]
    /// (`/`) on the left, [`EdgeClass::RightLane`] (`\\`) on the right.
    pub(crate) fn edge_class(self) -> EdgeClass {
        match self {
            Side::Left => EdgeClass::LeftLane,
            Side::Right => EdgeClass::RightLane,
        }
    }
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
    /// `[y_min, y_max]`, rows (px) over which the lane is seen: the points behind the estimate
    /// (last update or initialisation), and above them the marks found along the lane on a frame
    /// it was updated on (module `tracker::reach`).
    pub rows: [f64; 2],
    /// Points used this frame (filter update, or LS fit of an initialisation; after an
    /// initialisation's refinement with `init.stripe_trace`, its points and the traced stripe's
    /// middles, so beyond `track.max_points_per_lane`); 0 when missed,
    /// also for an initialisation whose refinement missed (the LS parabola is kept, reported
    /// [`LaneState::Tracking`] and `initialised`).
    pub points: usize,
    /// `true` if the lane was (re-)initialised by Hough + LS on this frame.
    pub initialised: bool,
    /// Above `coeffs`' rows, where its marks bend away from the near field's parabola: the far
    /// segment that follows them (module `tracker::reach`); `None` when no marks were followed
    /// up past the near field on this frame.
    pub far: Option<FarSegment>,
}

/// The far part of a lane (module `tracker::reach`): `x = a1·y² + a2·y + a3` on its rows, joined
/// to the near field's parabola at its lower row with the same column and slope.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct FarSegment {
    /// `[a1, a2, a3]`, pixels of the input image.
    pub coeffs: [f64; 3],
    /// `[y_min, y_join]`, rows (px): from the highest mark followed to the row it joins the
    /// near field's parabola at.
    pub rows: [f64; 2],
}

impl FarSegment {
    /// Column at `row_px`.
    pub fn col_at_row(&self, row_px: f64) -> f64 {
        Parabola::from_coeffs(self.coeffs).col_at_row(row_px)
    }
}

impl LaneReport {
    /// Column of the reported parabola at `row_px`, if there is one.
    pub fn col_at_row(&self, row_px: f64) -> Option<f64> {
        self.coeffs
            .map(|c| Parabola::from_coeffs(c).col_at_row(row_px))
    }

    /// Column at `row_px` of the lane as seen: the far segment's above the row it joins the
    /// near parabola at, the near parabola's elsewhere; `None` without coefficients.
    pub fn col_seen_at_row(&self, row_px: f64) -> Option<f64> {
        match self.far {
            Some(far) if self.coeffs.is_some() && row_px < far.rows[1] => {
                Some(far.col_at_row(row_px))
            }
            _ => self.col_at_row(row_px),
        }
    }
}

/// The tracker's result for one frame.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct TrackReport {
    /// Left then right.
    pub lanes: [LaneReport; 2],
    /// `true` if the full region of interest went through the gradient for an initialisation or
    /// a whole re-validation on this frame's edges; `false` on a tracking frame (gradient inside
    /// the windows), also on the frames of a re-validation spread over its period
    /// (`track.revalidate_spread`), the first of which puts the ROI through the gradient for it.
    pub full_gradient: bool,
    /// The road region the frame was searched in.
    pub road: RoadReport,
}

/// The road region of a frame, rows of the input (module `tracker::road`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct RoadReport {
    /// One past the lowest row of road, px: the frame's height when the road reaches its
    /// bottom; the edge of a bonnet or a dashboard when one was found (`roi.road_bottom =
    /// "found"`).
    pub bottom_row_px: f64,
    /// The rows searched for lanes, `[top, bottom)`, px (the ROI, placed in the road's rows).
    pub search_rows_px: [f64; 2],
    /// The horizon as the ego lanes show it: the row where the two reported lanes' tangents at
    /// the top of the search band meet, px; `None` unless both lanes are reported and close in
    /// upwards ([`Self::refused`] says why not, when the pair cannot be a road's).
    pub horizon_row_px: Option<f64>,
    /// Why the road the two reported lanes show was refused, when it was: on a flat road seen
    /// by a camera looking ahead the ego lanes close in upwards, so a pair that moves apart
    /// upwards, or whose left lane lies right of its right one, shows no road; `None` otherwise
    /// (also with fewer than two lanes). The lanes are reported as tracked; the horizon is not.
    pub refused: Option<RoadRefusal>,
}

/// Why a frame's road region was refused ([`RoadReport::refused`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum RoadRefusal {
    /// The two lanes move apart upwards at the top of the search band.
    LanesDivergeUpwards,
    /// The left lane lies right of the right one at the top of the search band.
    LanesCrossed,
}

impl RoadReport {
    /// The region of `lanes` reported on a frame searched in `search_rows_px`, the road ending
    /// at `bottom_row_px` (module docs of [`RoadReport::horizon_row_px`]).
    pub(crate) fn of(
        lanes: &[LaneReport; 2],
        search_rows_px: [f64; 2],
        bottom_row_px: f64,
    ) -> Self {
        let (horizon_row_px, refused) = match horizon_of(lanes, search_rows_px[0]) {
            Ok(horizon) => (horizon, None),
            Err(why) => (None, Some(why)),
        };
        RoadReport {
            bottom_row_px,
            search_rows_px,
            horizon_row_px,
            refused,
        }
    }
}

/// [`horizon_of`]'s horizon, `None` also where the pair is refused.
pub(super) fn horizon_row_px(lanes: &[LaneReport; 2], y_t: f64) -> Option<f64> {
    horizon_of(lanes, y_t).ok().flatten()
}

/// Where the tangents of both lanes at row `y_t` (the top of the search band: the parabolas
/// are fitted to the band's points) meet, px: `y_t − g/(m_r − m_l)` with `g = x_r(y_t) −
/// x_l(y_t) > 0` the gap and `m = dx/dy = 2·a1·y_t + a2` the slopes, the gap closing upwards
/// (`m_r > m_l`); `Ok(None)` with fewer than two lanes or tangents parallel within 10⁻⁶ px/row;
/// the refusal for a gap that is not positive or opens upwards.
fn horizon_of(lanes: &[LaneReport; 2], y_t: f64) -> Result<Option<f64>, RoadRefusal> {
    const PARALLEL: f64 = 1e-6;
    let (Some(l), Some(r)) = (lanes[0].coeffs, lanes[1].coeffs) else {
        return Ok(None);
    };
    let x = |c: [f64; 3]| c[0] * y_t * y_t + c[1] * y_t + c[2];
    let m = |c: [f64; 3]| 2.0 * c[0] * y_t + c[1];
    let (gap, closing) = (x(r) - x(l), m(r) - m(l));
    if gap <= 0.0 {
        return Err(RoadRefusal::LanesCrossed);
    }
    if closing < -PARALLEL {
        return Err(RoadRefusal::LanesDivergeUpwards);
    }
    Ok((closing > PARALLEL)
        .then(|| y_t - gap / closing)
        .filter(|y| y.is_finite()))
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
    /// candidates; a re-validation spread over its period (`track.revalidate_spread`) counts
    /// once, on the period's last frame (also when it re-validates whole there).
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

/// Most Hough candidate lines per angle band in the joint initialisation
/// (`init.candidate_lines` is validated to at most this).
pub(crate) const MAX_CANDIDATE_LINES: usize = 8;

/// One Hough candidate line of the last joint initialisation (`init.candidate_lines > 0`) as the
/// choice of the ego pair weighed it: for overlays, and for finding at which stage a lane is lost
/// (`lane_bench::labelled::census_lanes`).
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
    /// ([`super::LaneTracker::working_size`]) like every count the tracker reports.
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

#[cfg(test)]
mod tests {
    use super::*;

    fn lane(side: Side, coeffs: Option<[f64; 3]>) -> LaneReport {
        LaneReport {
            side,
            state: if coeffs.is_some() {
                LaneState::Tracking
            } else {
                LaneState::Lost
            },
            coeffs,
            rows: [150.0, 239.0],
            points: 40,
            initialised: false,
            far: None,
        }
    }

    fn road(left: Option<[f64; 3]>, right: Option<[f64; 3]>) -> RoadReport {
        let lanes = [lane(Side::Left, left), lane(Side::Right, right)];
        RoadReport::of(&lanes, [150.0, 240.0], 240.0)
    }

    #[test]
    fn lanes_closing_in_upwards_meet_at_the_horizon() {
        // x_l = 100 − 0.5·(y − 150), x_r = 220 + 0.5·(y − 150): gap 120 at row 150, closing
        // by 1 px a row upwards: they meet at row 30.
        let r = road(Some([0.0, -0.5, 175.0]), Some([0.0, 0.5, 145.0]));
        let y = r.horizon_row_px.expect("a horizon");
        assert!((y - 30.0).abs() < 1e-9, "{y}");
        assert_eq!(r.refused, None);
    }

    #[test]
    fn a_pair_no_road_shows_is_refused_with_its_reason_and_no_horizon() {
        let diverging = road(Some([0.0, 0.5, 25.0]), Some([0.0, -0.5, 295.0]));
        assert_eq!(diverging.refused, Some(RoadRefusal::LanesDivergeUpwards));
        assert_eq!(diverging.horizon_row_px, None);
        let crossed = road(Some([0.0, -0.5, 375.0]), Some([0.0, 0.5, 45.0]));
        assert_eq!(crossed.refused, Some(RoadRefusal::LanesCrossed));
        assert_eq!(crossed.horizon_row_px, None);
        // One lane, or parallel lanes: no horizon and nothing refused.
        let one = road(Some([0.0, -0.5, 175.0]), None);
        assert_eq!((one.horizon_row_px, one.refused), (None, None));
        let parallel = road(Some([0.0, 0.2, 50.0]), Some([0.0, 0.2, 170.0]));
        assert_eq!((parallel.horizon_row_px, parallel.refused), (None, None));
    }

    #[test]
    fn the_column_seen_is_the_far_segments_above_its_join_and_the_near_parabolas_below() {
        let mut l = lane(Side::Left, Some([0.0, -0.5, 175.0]));
        l.rows = [60.0, 239.0];
        l.far = Some(FarSegment {
            coeffs: [0.0, 0.0, 120.0],
            rows: [60.0, 110.0],
        });
        assert_eq!(l.col_seen_at_row(80.0), Some(120.0));
        assert_eq!(l.col_seen_at_row(110.0), l.col_at_row(110.0));
        assert_eq!(l.col_seen_at_row(200.0), Some(75.0));
        let lost = LaneReport { coeffs: None, ..l };
        assert_eq!(lost.col_seen_at_row(80.0), None);
    }
}
