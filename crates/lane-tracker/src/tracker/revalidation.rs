//! The period's re-validation spread over the period's frames (`track.revalidate_spread`, an
//! addition beyond the paper; issue 53 item 6, "the mean cost").
//!
//! **What it does.** The re-validation every `track.revalidate_every_frames` (P) frames runs the
//! joint initialisation over the ROI and weighs the tracked lanes against its candidates
//! (module `init`): on the real udacity clip a tracked frame costs ≈ 25–30 µs, a re-validation
//! frame 0.4–0.6 ms, so that the mean per frame was 2.2–3 times the median (the clip bench's
//! printout, `nav-app --json`). Spread, the same work is cut into [`STEPS`] steps done on the
//! frames of the period (module `joint`'s steps, on the edges of one frame); the last column is
//! what each step added to a frame of the clip (`track_us`, the median of its frames at that
//! place in the period, three quiet runs, 2026-12-07; the whole re-validation added ≈ 400–540):
//!
//! | step | work | added, µs |
//! |---|---|---|
//! | 0 | the ROI's gradient and stripe filters, into this stage's own buffers; the lanes as they are then ([`WeighedPair`]) | ≈ 70 |
//! | 1, 5 | a band's pixels indexed by row, the lanes' row coverage by them | ≈ 17, 26 |
//! | 2, 6 | the band's Hough vote | ≈ 45, 69 |
//! | 3, 4, 7, 8 | half the band's candidate lines fitted and covered | ≈ 35, 29, 61, 49 |
//! | 9 | the choice among the candidates and the tracked lanes | ≈ 0 |
//!
//! With P = 10 (the default) one step a frame; with another P ≥ 2, step `k` runs on the period's
//! frame `⌈(k + 1)·P/10⌉ − 1` (several a frame when P < 10, none on some frames when P > 10);
//! the choice is always on the period's last frame, the frame the whole re-validation ran on.
//! The work is the same as the whole re-validation's (827 k against 823 k instructions a frame
//! over the clip): the mean stays, the median rises by about what the mean loses.
//!
//! **The choice on the last frame** is the one the whole re-validation would have made on the
//! frame of step 0 (the period's first with P ≤ 10): the same steps in the same order, the same
//! edges, the lanes as they were then (all ten steps on one frame reproduce the whole
//! re-validation's stress-test figures exactly). If it keeps both lanes (the usual case: on the
//! udacity clip every time), the period ends and nothing is changed. If it would change a lane — a switch to a candidate off its mark, a lane
//! handed over to the other side ([`JointChoice::changes_lanes`]) — its evidence is `P − 1`
//! frames old, and the whole re-validation runs at once on the current frame, which changes the
//! lanes or not on this frame's evidence, exactly as without the spread. So every change of a
//! lane comes from a whole re-validation on the frame it happens on; what the spread can miss is
//! a better pair that appeared during the period (found by the next period, or at once by the
//! weak-evidence trigger, `track.revalidate_below_points`, which stays whole and immediate and
//! restarts the period, as does every (re-)initialisation). A weak lane's set-aside never
//! arises here: no lane is weak on a frame that reaches the period's steps.
//!
//! **Why this and not the alternatives** (issue 53 item 6 proposed the first two):
//! - the ROI's gradient in slices of rows over the period and the Hough vote and choice on its
//!   last frame: the gradient is ≈ 11 % of a re-validation; the vote (≈ 36 %) and the candidates'
//!   fits and coverages (≈ 39 %; `perf record` on `frame_cost revalidate`) would still fall on one
//!   frame, and the rows would come from ten different frames (on the stress test, ten
//!   different scenes);
//! - re-validating in a band around each tracked lane only: cheaper, but the candidates it
//!   exists to find (the stress test's next scene, a mark beside a lane that slid onto a seam)
//!   are where the band does not look;
//! - a mean at most 1.5 times the median needs the work of a re-validation cut to ≈ 50 µs (a
//!   sixth of it, the first frame's initialisation taking ≈ 8 µs of the mean) or spread over more
//!   than half of the period's frames; all of them keep each frame's share smallest;
//! - the steps on the period's last five frames (the evidence 4 frames old, twice the cost a
//!   frame): stress test (`cargo xtask eval-lanes --no-peer --one-sequence`, default overall,
//!   all / development / held out) 70.7 / 71.2 / 69.3 % against 71.1 / 71.2 / 70.6 % with ten
//!   frames and 71.4 / 73.2 / 67.3 % whole: no closer.
//!
//! Figures (before/after, the clip bench and `nav-app --json`, the labelled benchmark):
//! `docs/results/speed.md` ("The whole real clip"), `docs/lanes/history/revalidation-spread.md`.

use hough_init::{HoughLine, HoughWorkspace};
use vision_gradient::GreyImage;

use super::candidates::CandidateIndex;
use super::edges::EdgeStage;
use super::joint::{self, Gathered, JointChoice, WeighedPair};
use super::lane::{Health, Lanes};
use super::report::{MAX_CANDIDATE_LINES, Side};
use super::setup::Setup;
use crate::TrackerError;

/// The steps a spread re-validation is cut into.
pub(super) const STEPS: usize = 10;

/// Half of a band's candidate lines.
#[derive(Debug, Clone, Copy)]
enum Half {
    First,
    Second,
}

/// One step of the spread re-validation (module docs).
#[derive(Debug, Clone, Copy)]
enum Step {
    Gradient,
    Prepare(Side),
    Vote(Side),
    Fit(Side, Half),
    Choose,
}

/// The steps in their order.
const SCHEDULE: [Step; STEPS] = [
    Step::Gradient,
    Step::Prepare(Side::Left),
    Step::Vote(Side::Left),
    Step::Fit(Side::Left, Half::First),
    Step::Fit(Side::Left, Half::Second),
    Step::Prepare(Side::Right),
    Step::Vote(Side::Right),
    Step::Fit(Side::Right, Half::First),
    Step::Fit(Side::Right, Half::Second),
    Step::Choose,
];

/// The steps done by the end of the period's frame `position` (0-based) of `every` frames:
/// `⌊(position + 1)·STEPS/every⌋`, all of them on its last frame.
pub(super) fn steps_by(position: u64, every: u64) -> usize {
    let done = (position + 1).saturating_mul(STEPS as u64) / every.max(1);
    usize::try_from(done).map_or(STEPS, |d| d.min(STEPS))
}

/// The spread re-validation's state between the frames of a period: the edges of the period's
/// first frame, the lanes as they were then, the candidates gathered so far and the next step.
/// Its buffers are sized once; a step does not allocate.
#[derive(Debug)]
pub(super) struct SpreadRevalidation {
    /// The ROI's edges of the period's first frame (the windows of the frames after it use the
    /// tracker's own `EdgeStage`).
    edges: EdgeStage,
    /// The lanes on the period's first frame.
    pair: WeighedPair,
    gathered: Gathered,
    /// The Hough lines of the band being fitted, and how many.
    lines: [HoughLine; MAX_CANDIDATE_LINES],
    lines_len: usize,
    /// Whether the band being worked on has enough pixels (else its vote and fits are skipped).
    band_ready: bool,
    /// The next step to do.
    next_step: usize,
    /// `frames_since_full_gradient` on the last frame that did a step: a period whose first
    /// frame did not go through step 0 here (never, by how the tracker calls it) does nothing.
    last_frame: Option<u64>,
}

impl SpreadRevalidation {
    /// The stage for `setup`'s frames, its edge buffers holding the ROI's pixels.
    pub(super) fn new(setup: &Setup) -> Result<Self, TrackerError> {
        let (top, bottom) = setup.roi;
        let none = HoughLine {
            rho_px: 0.0,
            theta_rad: 0.0,
            votes: 0,
        };
        Ok(SpreadRevalidation {
            edges: EdgeStage::new(setup, setup.width * (bottom - top))?,
            pair: [None, None],
            gathered: Gathered::default(),
            lines: [none; MAX_CANDIDATE_LINES],
            lines_len: 0,
            band_ready: false,
            next_step: STEPS,
            last_frame: None,
        })
    }

    /// The steps of the period's frame `since` (`Health::frames_since_full_gradient` before this
    /// frame: the period's frame `since mod every`), `every` = P ≥ 2, both lanes tracked on
    /// `image`. `true` when the choice on the period's last frame would change a lane: the
    /// caller re-validates whole on this frame. A period the choice ends without a change is
    /// counted in `TrackerCounters::revalidations`.
    #[allow(clippy::too_many_arguments)] // the stages it reads and writes, each named
    pub(super) fn step(
        &mut self,
        since: u64,
        every: u64,
        image: &GreyImage<'_>,
        lanes: &Lanes,
        hough: &mut HoughWorkspace,
        index: &mut CandidateIndex,
        setup: &Setup,
        health: &mut Health,
    ) -> Result<bool, TrackerError> {
        let position = since % every.max(1);
        if position == 0 {
            self.next_step = 0;
        } else if self.last_frame != since.checked_sub(1) {
            self.next_step = STEPS; // not from the period's first frame: nothing until the next
        }
        self.last_frame = Some(since);
        let rows = setup.roi;
        let end = steps_by(position, every);
        while self.next_step < end {
            let step = SCHEDULE[self.next_step];
            self.next_step += 1;
            match step {
                Step::Gradient => {
                    self.edges.detect_rows(image, rows, setup)?;
                    self.pair = joint::weighed(lanes, setup);
                    self.gathered.clear();
                }
                Step::Prepare(side) => {
                    self.lines_len = 0;
                    self.band_ready = joint::prepare_band(
                        index,
                        &self.edges,
                        side,
                        &self.pair,
                        &mut self.gathered,
                        setup,
                        rows,
                    );
                }
                Step::Vote(side) => {
                    if self.band_ready {
                        self.lines_len =
                            joint::vote_band(hough, index, side, setup, &mut self.lines);
                    }
                }
                Step::Fit(side, half) => {
                    let split = self.lines_len.div_ceil(2);
                    let lines = match half {
                        Half::First => &self.lines[..split],
                        Half::Second => &self.lines[split..self.lines_len],
                    };
                    joint::fit_lines(index, side, lines, &mut self.gathered, setup, rows);
                }
                Step::Choose => {
                    let choice: JointChoice = self.gathered.choose(&self.pair, setup, rows);
                    if choice.changes_lanes(&self.pair) {
                        return Ok(true);
                    }
                    health.counters.revalidations += 1;
                }
            }
        }
        Ok(false)
    }
}
