//! The joint choice of the ego pair in steps (`init.candidate_lines > 0`, crate docs): a band's
//! pixels indexed by row with the competing lanes' coverage read on them ([`prepare_band`]), its
//! Hough vote ([`vote_band`]), its lines' least-squares parabolas and row coverages
//! ([`fit_lines`]), gathered in a [`Gathered`], then the choice among them and the lanes with an
//! estimate ([`Gathered::choose`]). `Initialiser::initialise_jointly` (module `init`) runs the
//! steps on one frame and applies the choice; the re-validation spread over its period (module
//! `revalidation`) runs the same steps over several frames on one frame's edges and asks only
//! whether the choice would change a lane ([`JointChoice::changes_lanes`]). The steps read the
//! lanes as a [`WeighedPair`] taken when the choice begins, so that both see them as they were
//! on the frame whose edges they weigh.

use hough_init::{Chord, EgoChoice, HoughLine, HoughWorkspace, Parabola, choose_ego_pair};
use vision_gradient::EdgeClass;

use super::candidates::CandidateIndex;
use super::edges::EdgeStage;
use super::lane::{LaneFilter, Lanes};
use super::report::{InitCandidate, MAX_CANDIDATE_LINES, Side};
use super::setup::{Pass, Rows, Setup};

/// Candidates a joint choice gathers at most: `init.candidate_lines` (≤ `MAX_CANDIDATE_LINES`)
/// in each band.
const MAX_GATHERED: usize = 2 * MAX_CANDIDATE_LINES;

/// A lane with an estimate as the joint choice weighs it.
#[derive(Debug, Clone)]
pub(super) struct Weighed {
    /// Its estimate.
    filter: LaneFilter,
    /// Whether it competes with the candidates, weighed by its own row coverage (re-validation
    /// on, a lane tracked from earlier frames), or is locked into the pair.
    competes: bool,
    /// Its tracking window's half-width, px: a candidate within it at every row lies on its
    /// mark.
    window_half_width_px: f64,
}

/// The lanes with an estimate, left then right, as the joint choice weighs them.
pub(super) type WeighedPair = [Option<Weighed>; 2];

/// The lanes with an estimate as the joint choice weighs them now. With re-validation on
/// (`TrackConfig::revalidates`), a lane tracked from earlier frames competes with the
/// candidates, weighed by its own row coverage: in a re-validation (both tracked) and when the
/// other side is (re-)initialised. A lane initialised on this frame (the first search's, during
/// the second search) is locked into the pair instead, as every tracked lane is with
/// re-validation off. A lane tracked over the taller rows (`Lane::tracked_tall`) competes too,
/// weighed on the ROI's rows, where its mark may not be: a candidate of the ROI for its side
/// replaces it. (Locked instead, lanes of an earlier scene were kept: the stress test fell.)
/// Copies the two filters (fixed-size, no allocation).
pub(super) fn weighed(lanes: &Lanes, setup: &Setup) -> WeighedPair {
    Side::BOTH.map(|side| {
        let lane = &lanes[side];
        let filter = lane.filter.as_ref().filter(|_| lane.has_estimate())?;
        Some(Weighed {
            filter: filter.clone(),
            competes: setup.cfg.track.revalidates()
                && setup.cfg.init.candidate_coverage
                && !lane.initialised_now,
            window_half_width_px: setup.window_half_width(lane, Pass::Tracking) as f64,
        })
    })
}

/// Whether each lane of `pair` competes with the candidates.
pub(super) fn competes(pair: &WeighedPair) -> [bool; 2] {
    pair.each_ref()
        .map(|w| w.as_ref().is_some_and(|w| w.competes))
}

/// The candidates of one joint choice, gathered band by band: each with its Hough line, its
/// edge class, its chord and what the tracker reports of it; and the competing lanes' row
/// coverage, the better band's. Fixed-size: no allocation.
#[derive(Debug, Clone)]
pub(super) struct Gathered {
    pub(super) lines: [HoughLine; MAX_GATHERED],
    pub(super) classes: [EdgeClass; MAX_GATHERED],
    chords: [Chord; MAX_GATHERED],
    pub(super) candidates: [InitCandidate; MAX_GATHERED],
    /// How many are gathered.
    pub(super) len: usize,
    /// Each competing lane's row coverage by the pixels of the bands prepared so far (the
    /// better band's: on a bend a boundary leans into the other band).
    tracked_support: [f64; 2],
}

impl Default for Gathered {
    fn default() -> Self {
        let none = HoughLine {
            rho_px: 0.0,
            theta_rad: 0.0,
            votes: 0,
        };
        Gathered {
            lines: [none; MAX_GATHERED],
            classes: [EdgeClass::LeftLane; MAX_GATHERED],
            chords: [Chord::default(); MAX_GATHERED],
            candidates: [InitCandidate {
                band: Side::Left,
                coeffs: [0.0; 3],
                support: 0.0,
                chosen: None,
            }; MAX_GATHERED],
            len: 0,
            tracked_support: [0.0; 2],
        }
    }
}

/// The joint choice: the candidate (index into the gathered ones, then the lanes' chords) each
/// side was given, and the lane each pick lies on.
#[derive(Debug, Clone, Copy)]
pub(super) struct JointChoice {
    /// The pick of each side, left then right: `j < Gathered::len` a candidate, else the chord
    /// of a lane with an estimate.
    pub(super) picks: [Option<usize>; 2],
    /// The lane (0 left, 1 right) each pick lies on, if any: its own chord, or (a competing lane)
    /// a candidate within the lane's tracking window at every row — its own mark.
    pub(super) owners: [Option<usize>; 2],
    /// A locked lane the choice put on the other side: both are left as they are.
    pub(super) locked_moved: bool,
}

impl JointChoice {
    /// Whether applying the choice to the lanes of `pair` would change either: a lane handed
    /// over to the other side (a lane change), or a side given a candidate off its lane's mark
    /// (a switch, or a fresh lane where there was none), which the initialisation then tries to
    /// install. (It may refuse the fit: then nothing changes, which this does not foresee.)
    pub(super) fn changes_lanes(&self, pair: &WeighedPair) -> bool {
        if self.locked_moved {
            return false;
        }
        let handed_over = self.owners == [Some(1), Some(0)]
            || Side::BOTH
                .into_iter()
                .any(|side| self.owners[side.index()] == Some(side.other().index()));
        let installs = (0..2).any(|i| {
            let locked = pair[i].as_ref().is_some_and(|w| !w.competes);
            self.picks[i].is_some() && self.owners[i].is_none() && !locked
        });
        handed_over || installs
    }
}

impl Gathered {
    /// Empty, for a new choice.
    pub(super) fn clear(&mut self) {
        self.len = 0;
        self.tracked_support = [0.0; 2];
    }

    /// The gathered candidates.
    pub(super) fn candidates(&self) -> &[InitCandidate] {
        &self.candidates[..self.len]
    }

    /// The ego pair chosen among the gathered candidates and the lanes of `pair` by
    /// `hough_init::choose_ego_pair` (over the chords between the first and the last of `rows`):
    /// the lanes' chords after the candidates, a competing one with its row coverage counted
    /// `track.revalidate_keep_factor` times, unlocked; otherwise the first one, locked into the
    /// pair with the strongest support. With lanes competing, the pair gate's rules
    /// (`Setup::tracked_pair_rules`): the choice's 0.9 margin would refuse the tracked pair of a
    /// camera looking down and pair one of its lanes with clutter instead.
    pub(super) fn choose(&self, pair: &WeighedPair, setup: &Setup, rows: Rows) -> JointChoice {
        let (top, bottom) = rows;
        let (yt, yb) = (top as f64, (bottom - 1) as f64);
        let m0 = self.len;
        let competes = competes(pair);
        let mut chords = [Chord::default(); MAX_GATHERED + 2];
        chords[..m0].copy_from_slice(&self.chords[..m0]);
        let s_max = chords[..m0].iter().map(|c| c.support).fold(0.0, f64::max);
        let mut m = m0;
        let mut locked = None;
        let mut tracked_at = [None; 2];
        for (i, weighed) in pair.iter().enumerate() {
            let Some(w) = weighed else { continue };
            if !w.competes && locked.is_some() {
                continue;
            }
            let support = if w.competes {
                self.tracked_support[i] * setup.cfg.track.revalidate_keep_factor
            } else {
                s_max
            };
            chords[m] = w.filter.chord(yt, yb, support);
            tracked_at[i] = Some(m);
            if !w.competes {
                locked = Some((m, i));
            }
            m += 1;
        }
        let ego_pair = if competes.contains(&true) {
            setup.tracked_pair_rules()
        } else {
            setup.cfg.init.ego_pair
        };
        let choice: EgoChoice = choose_ego_pair(
            &chords[..m],
            setup.width as f64,
            yb - yt,
            &ego_pair,
            locked.map(|(j, _)| j),
        );
        let picks = [choice.left, choice.right];
        let locked_moved = locked.is_some_and(|(j, i)| picks[i] != Some(j));
        let owner = |j: usize| -> Option<usize> {
            if let Some(k) = tracked_at.iter().position(|&t| t == Some(j)) {
                return Some(k);
            }
            let c = self.candidates().get(j)?;
            let p = Parabola::from_coeffs(c.coeffs);
            (0..2).find(|&k| {
                // The lane's tracking window (wider on a double line: both its lines).
                pair[k].as_ref().is_some_and(|w| {
                    w.competes
                        && (top..bottom).all(|y| {
                            let y = y as f64;
                            (p.col_at_row(y) - w.filter.col_at_row(y)).abs()
                                <= w.window_half_width_px
                        })
                })
            })
        };
        JointChoice {
            picks,
            owners: picks.map(|p| p.and_then(owner)),
            locked_moved,
        }
    }
}

/// Prepares band `band_side`'s pixels of `edges` for the vote and the fits: `false` (the band
/// is skipped) with fewer than `init.min_points` of them; else the band's pixels indexed by row
/// (`CandidateIndex::sort_by_row`, with `init.candidate_coverage` or the oriented vote), each
/// competing lane's row coverage by them kept if better than another band's, and (the plain
/// vote) the vote's input filled.
pub(super) fn prepare_band(
    index: &mut CandidateIndex,
    edges: &EdgeStage,
    band_side: Side,
    pair: &WeighedPair,
    gathered: &mut Gathered,
    setup: &Setup,
    rows: Rows,
) -> bool {
    let class = band_side.edge_class();
    if !index.has(edges, class, setup.init_params.min_points, setup) {
        return false;
    }
    if setup.cfg.init.candidate_coverage || setup.cfg.init.orientation_tolerance_deg > 0.0 {
        index.sort_by_row(edges, class, setup);
    }
    for (support, weighed) in gathered.tracked_support.iter_mut().zip(pair) {
        if let Some(w) = weighed.as_ref().filter(|w| w.competes) {
            let p = Parabola::from_coeffs(w.filter.coeffs());
            *support = support.max(index.row_coverage(&p, rows, setup));
        }
    }
    if setup.cfg.init.orientation_tolerance_deg <= 0.0 {
        index.fill(edges, class, setup); // the plain vote's input
    }
    true
}

/// Band `band_side`'s Hough vote on the pixels [`prepare_band`] prepared: its strongest
/// `init.candidate_lines` separated lines into `out` (each pixel voting near its own edge normal
/// with `init.orientation_tolerance_deg > 0`), their number; 0 if the vote refuses its input.
pub(super) fn vote_band(
    hough: &mut HoughWorkspace,
    index: &CandidateIndex,
    band_side: Side,
    setup: &Setup,
    out: &mut [HoughLine; MAX_CANDIDATE_LINES],
) -> usize {
    let n = setup.cfg.init.candidate_lines.min(MAX_CANDIDATE_LINES);
    let band = setup.band(band_side);
    let init = &setup.cfg.init;
    let (sep_deg, sep_px) = (init.candidate_separation_deg, init.candidate_separation_px);
    let tolerance_deg = init.orientation_tolerance_deg;
    let found = if tolerance_deg > 0.0 {
        hough.find_lines_oriented(
            &index.oriented,
            &band,
            tolerance_deg,
            sep_deg,
            sep_px,
            &mut out[..n],
        )
    } else {
        hough.find_lines(&index.candidates, &band, sep_deg, sep_px, &mut out[..n])
    };
    found.unwrap_or(0)
}

/// Band `band_side`'s Hough `lines` (from [`vote_band`], in its order) gathered as candidates:
/// each as a curve x(y) — its LS parabola over `rows` with `init.candidate_coverage` (a line
/// without one is dropped), else the Hough line itself — with its support, the row coverage
/// net of the clutter beside it, else its votes.
pub(super) fn fit_lines(
    index: &CandidateIndex,
    band_side: Side,
    lines: &[HoughLine],
    gathered: &mut Gathered,
    setup: &Setup,
    rows: Rows,
) {
    let (top, bottom) = rows;
    let (yt, yb) = (top as f64, (bottom - 1) as f64);
    for line in lines {
        let (p, support) = if setup.cfg.init.candidate_coverage {
            let Some(p) = index.row_fit(line, rows, setup) else {
                continue;
            };
            (p, index.row_coverage(&p, rows, setup))
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
        let m = gathered.len;
        if m >= MAX_GATHERED {
            return; // not reached: at most `MAX_CANDIDATE_LINES` a band, two bands
        }
        gathered.chords[m] = Chord {
            col_top_px: p.col_at_row(yt),
            col_bottom_px: p.col_at_row(yb),
            support,
        };
        gathered.candidates[m] = InitCandidate {
            band: band_side,
            coeffs: [p.a1, p.a2, p.a3],
            support,
            chosen: None,
        };
        gathered.lines[m] = *line;
        gathered.classes[m] = band_side.edge_class();
        gathered.len += 1;
    }
}
