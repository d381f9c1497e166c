//! # How far up each lane is seen (an addition beyond the paper)
//!
//! The paper tracks each lane in a band of rows near the camera, and a lane's report said only
//! the rows of the points behind its estimate: the band's. Lane keeping needs the near field,
//! but the labels (and curvature, lane changes, anything ahead) run on towards the horizon; a
//! row the report does not reach is a row the lane is not given on. After the frame's update,
//! each lane that was updated or initialised on it is followed **upwards** from the top of its
//! points, row by row, along its parabola, as far as its mark is seen; the report's `rows`
//! then span its points and the marks found above them.
//!
//! On row `y` the mark is looked for within `±k` px of `x̂(y) + d` (`x̂` the lane's parabola,
//! `d` the offset the mark has drifted from it so far, `k = track.window_half_width_px`): a
//! column `c` brighter than both columns `m` px either side of it by at least [`MIN_CONTRAST`]
//! grey levels,
//!
//! ```text
//! I(c) − max(I(c − m), I(c + m)) ≥ MIN_CONTRAST,   m = max(2, ⌈w(y)/2⌉ + 1),
//! w(y) = gradient.stripe_max_width_px · (y − y_h)/(h − y_h),
//! ```
//!
//! the mark's width shrinking linearly towards the horizon row `y_h` (where the two lanes meet,
//! else the frame's top). A lane on a road's edge or a kerb has no such column: one side is
//! brighter. What the lane is on is read first on the near parabola's last [`PROBE_ROWS`] rows
//! (within ±3 px of it): where fewer than half hold a bright mark and at least half a step of
//! one sign, `s · (I(c + 2) − I(c − 2)) ≥ MIN_STEP` (`s = ±1`, [`MIN_STEP`] grey levels), the
//! walk looks for the strongest such step instead. The brightest (strongest) such column moves
//! `d` halfway to it (`|d| ≤ 2k`). The walk stops at `y_h` (without one — the lanes do not close
//! in upwards — at the top of the rows the working frame holds); the lane's rows then start at
//! the highest row where a mark was seen, if at least [`MIN_MARK_ROWS`] were. A gap does not stop
//! it: it used to stop after a tenth of the height without a mark, and dashes, worn paint and
//! shadows leave longer gaps (decision and figures: `docs/lanes/history/road-region.md`, "Past
//! gaps"). Going on past `y_h` as well gains little (on a curve the near tangents meet below
//! where the marks end, but that is rare on roads) and costs the walk through the sky on every
//! frame: the clip's tracked frame 21 → 32 µs.
//!
//! The marks followed make the lane's **far segment** ([`super::report::FarSegment`]): a
//! parabola joined to the near one at the top of its points `y_j` with the same column `x_j` and
//! slope `m_j`, its one free term the curvature fitted to the marks,
//!
//! ```text
//! x(y) = x_j + m_j·u + κ·u²,   u = y − y_j,   κ = (Σ r·u² + P·a1)/(Σ u⁴ + P),
//! r = x_mark − x_j − m_j·u,
//! ```
//!
//! (least squares in `κ` with the near curvature `a1` as a prior worth three marks ten rows up,
//! `P = 3·10⁴`; the walk looks for each next mark along it). It is reported only where it halves the squared residuals of the near
//! parabola's own curvature `a1` over the marks ([`MAX_RESIDUAL_RATIO`]): a far field that
//! continues the near one keeps the near parabola. The near field's coefficients are not
//! changed, and the near band's figures stay what they were; a lane's report reads the far
//! segment above `y_j`.

use vision_gradient::GreyImage;

use super::lane::Lanes;
use super::report::{FarSegment, Side};
use super::setup::{Rows, Setup};

/// Least step between a mark and the floor either side of it, grey levels.
pub(crate) const MIN_CONTRAST: i16 = 12;
/// Least step across a road's edge or a kerb, grey levels.
pub(crate) const MIN_STEP: i16 = 20;
/// Half the span a step is read across, px.
const STEP_HALF_PX: i64 = 2;
/// Rows of the near parabola below the join read for what the lane is on.
const PROBE_ROWS: usize = 8;
/// Columns either side of the near parabola a probe row looks at, px.
const PROBE_HALF_WIDTH_PX: i64 = 3;
/// Fewest rows with a mark for a reach to count.
pub(crate) const MIN_MARK_ROWS: usize = 3;
/// The near parabola's curvature weighs in the far fit as this many marks this many rows
/// above the join.
const PRIOR_MARKS: f64 = 3.0;
const PRIOR_ROWS: f64 = 10.0;
/// A far segment is reported only where its curvature explains the marks this much better than
/// the near parabola's: at most this fraction of the squared residuals.
pub(crate) const MAX_RESIDUAL_RATIO: f64 = 0.5;

/// Follow each lane updated or initialised on this frame upwards (module docs) on `image`,
/// valid on the working rows `rows`, no higher than `horizon_row` (working rows); extend its
/// rows' top to the highest mark found.
pub(super) fn reach_up(
    lanes: &mut Lanes,
    image: &GreyImage<'_>,
    rows: Rows,
    horizon_row: Option<f64>,
    setup: &Setup,
) {
    let h = image.height();
    // Without a horizon (the lanes do not close in upwards) up to the top row.
    let y_h = horizon_row.unwrap_or(0.0).max(0.0);
    let limit = (y_h.ceil() as usize).max(rows.0).max(1);
    let k = setup.cfg.track.window_half_width_px as i64;
    let max_width = f64::from(setup.cfg.gradient.stripe_max_width_px).max(4.0);
    for side in Side::BOTH {
        let lane = &mut lanes[side];
        if !(lane.updated_now || lane.initialised_now) || !lane.has_estimate() {
            continue;
        }
        let Some(filter) = lane.filter.as_ref() else {
            continue;
        };
        let start = lane.rows[0].floor();
        if !start.is_finite() || start <= limit as f64 {
            continue;
        }
        // The join: the near parabola's column and slope at the top of its points.
        let [a1, a2, _] = filter.coeffs();
        let (y_j, x_j) = (start, filter.col_at_row(start));
        let m_j = 2.0 * a1 * y_j + a2;
        let kind = MarkKind::of_near_field(image, filter_cols(filter, y_j), max_width, y_h, h);
        let mut far = FarFit::new(y_j, x_j, m_j, a1);
        let mut drift = 0.0f64;
        let mut top = None;
        let mut y = start as usize;
        while y > limit {
            y -= 1;
            let Some(line) = image.row(y) else { break };
            let depth = ((y as f64 - y_h) / (h as f64 - y_h)).clamp(0.0, 1.0);
            let m = ((max_width * depth / 2.0).ceil() as i64 + 1).max(2);
            let model = far.col_at_row(y as f64);
            let centre = model + drift;
            if !centre.is_finite() {
                break;
            }
            let centre = centre.round() as i64;
            if let Some((_, c)) = kind.strongest(line, centre, k, m) {
                far.add(y as f64, c as f64);
                let residual = c as f64 - far.col_at_row(y as f64);
                drift = (0.5 * residual).clamp(-2.0 * k as f64, 2.0 * k as f64);
                top = Some(y as f64);
            }
        }
        if let Some(top) = top.filter(|_| far.marks >= MIN_MARK_ROWS) {
            lane.rows[0] = lane.rows[0].min(top);
            lane.far = far.bends().then(|| FarSegment {
                coeffs: far.coeffs(),
                rows: [top, y_j],
            });
        }
    }
}

/// The columns of the near parabola on the [`PROBE_ROWS`] rows below `y_j` (its last rows).
fn filter_cols(filter: &super::lane::LaneFilter, y_j: f64) -> [(usize, f64); PROBE_ROWS] {
    std::array::from_fn(|i| {
        let y = y_j + 1.0 + i as f64;
        (y as usize, filter.col_at_row(y))
    })
}

/// What the lane is on, read on the near parabola's last rows: a bright mark (a ridge, the
/// default) or the step of a road's edge or a kerb (one side brighter: `+1` the right).
#[derive(Debug, Clone, Copy, PartialEq)]
enum MarkKind {
    Ridge,
    Step(i16),
}

impl MarkKind {
    /// A step of one sign on at least half of the probe rows where no ridge is: the lane is on
    /// an edge; else on a mark.
    fn of_near_field(
        image: &GreyImage<'_>,
        cols: [(usize, f64); PROBE_ROWS],
        max_width: f64,
        y_h: f64,
        h: usize,
    ) -> Self {
        let w = image.width() as i64;
        let (mut ridges, mut steps) = (0usize, [0usize; 2]);
        for (y, x) in cols {
            let Some(line) = image.row(y) else { continue };
            if !x.is_finite() {
                continue;
            }
            let depth = ((y as f64 - y_h) / (h as f64 - y_h)).clamp(0.0, 1.0);
            let m = ((max_width * depth / 2.0).ceil() as i64 + 1).max(2);
            let c = x.round() as i64;
            if MarkKind::Ridge
                .strongest(line, c, PROBE_HALF_WIDTH_PX, m)
                .is_some()
            {
                ridges += 1;
            } else {
                for (i, sign) in [-1i16, 1].into_iter().enumerate() {
                    let fits = (c - PROBE_HALF_WIDTH_PX..=c + PROBE_HALF_WIDTH_PX)
                        .filter(|&c| c >= STEP_HALF_PX && c < w - STEP_HALF_PX)
                        .any(|c| step_at(line, c, sign) >= MIN_STEP);
                    steps[i] += usize::from(fits);
                }
            }
        }
        let half = PROBE_ROWS / 2;
        match steps {
            [l, r] if ridges < half && l >= half && l > r => MarkKind::Step(-1),
            [l, r] if ridges < half && r >= half && r > l => MarkKind::Step(1),
            _ => MarkKind::Ridge,
        }
    }

    /// The strongest column of `line` within `centre ± k` of this kind, if any: a ridge at
    /// least [`MIN_CONTRAST`] above the floor `m` px either side; a step of this sign at least
    /// [`MIN_STEP`] across `±STEP_HALF_PX`.
    fn strongest(self, line: &[u8], centre: i64, k: i64, m: i64) -> Option<(i16, i64)> {
        let w = line.len() as i64;
        let (margin, least) = match self {
            MarkKind::Ridge => (m, MIN_CONTRAST),
            MarkKind::Step(_) => (STEP_HALF_PX, MIN_STEP),
        };
        let mut best: Option<(i16, i64)> = None;
        for c in (centre - k).max(margin)..=(centre + k).min(w - 1 - margin) {
            let strength = match self {
                MarkKind::Ridge => {
                    let at = |x: i64| i16::from(line[x as usize]);
                    at(c) - at(c - m).max(at(c + m))
                }
                MarkKind::Step(sign) => step_at(line, c, sign),
            };
            if strength >= least && best.is_none_or(|(s, _)| strength > s) {
                best = Some((strength, c));
            }
        }
        best
    }
}

/// `sign · (I(c + STEP_HALF_PX) − I(c − STEP_HALF_PX))` (`c` at least `STEP_HALF_PX` inside).
fn step_at(line: &[u8], c: i64, sign: i16) -> i16 {
    let at = |x: i64| i16::from(line[x as usize]);
    sign * (at(c + STEP_HALF_PX) - at(c - STEP_HALF_PX))
}

/// The far segment's least-squares fit (module docs): with `u = y − y_j`, the column
/// `x_j + m_j·u + κ·u²` joins the near parabola at row `y_j` with its column and slope, and
/// `κ = (Σ r·u² + P·a1) / (Σ u⁴ + P)` over the marks, `r = x − x_j − m_j·u`: least squares with
/// the near parabola's own curvature `a1` as a prior worth three marks ten rows up
/// (`P = 3·10⁴`), which the first marks above the join cannot outweigh.
struct FarFit {
    y_j: f64,
    x_j: f64,
    m_j: f64,
    /// The near parabola's `a1`.
    near_a1: f64,
    kappa: f64,
    sum_ru2: f64,
    sum_u4: f64,
    sum_r2: f64,
    marks: usize,
}

impl FarFit {
    fn new(y_j: f64, x_j: f64, m_j: f64, near_a1: f64) -> Self {
        FarFit {
            y_j,
            x_j,
            m_j,
            near_a1,
            kappa: near_a1,
            sum_ru2: 0.0,
            sum_u4: 0.0,
            sum_r2: 0.0,
            marks: 0,
        }
    }

    fn col_at_row(&self, y: f64) -> f64 {
        let u = y - self.y_j;
        self.x_j + self.m_j * u + self.kappa * u * u
    }

    fn add(&mut self, y: f64, x: f64) {
        let u = y - self.y_j;
        let r = x - self.x_j - self.m_j * u;
        self.sum_ru2 += r * u * u;
        self.sum_u4 += u.powi(4);
        self.sum_r2 += r * r;
        self.marks += 1;
        // The near curvature as a prior worth PRIOR_MARKS marks PRIOR_ROWS rows up: the few
        // marks just above the join do not set a curvature on their own.
        let prior = PRIOR_MARKS * PRIOR_ROWS.powi(4);
        self.kappa = (self.sum_ru2 + prior * self.near_a1) / (self.sum_u4 + prior);
    }

    /// Whether the marks bend away from the near parabola: it misses them by more than a pixel
    /// (RMS), and the fitted `κ` (without the prior) leaves at most [`MAX_RESIDUAL_RATIO`] of
    /// the squared residuals the near parabola's `a1` leaves, `Σ(r − κu²)² = Σr² − (Σru²)²/Σu⁴`
    /// against `Σ(r − a1·u²)²`.
    fn bends(&self) -> bool {
        if self.marks < MIN_MARK_ROWS || self.sum_u4 <= 0.0 {
            return false;
        }
        let fitted = (self.sum_r2 - self.sum_ru2 * self.sum_ru2 / self.sum_u4).max(0.0);
        let a = self.near_a1;
        let near = self.sum_r2 - 2.0 * a * self.sum_ru2 + a * a * self.sum_u4;
        // …and the near parabola misses the marks by more than a pixel (RMS).
        near > self.marks as f64 && fitted <= MAX_RESIDUAL_RATIO * near
    }

    /// `[a1, a2, a3]` of `x_j + m_j·(y − y_j) + κ·(y − y_j)²`.
    fn coeffs(&self) -> [f64; 3] {
        let (k, m, y, x) = (self.kappa, self.m_j, self.y_j, self.x_j);
        [k, m - 2.0 * k * y, x - m * y + k * y * y]
    }
}
