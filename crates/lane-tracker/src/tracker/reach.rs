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
//! else the frame's top). The brightest such column moves `d` halfway to it (`|d| ≤ 2k`). The
//! walk stops at `y_h` (without one — the lanes do not close in upwards — at the top of the
//! second search's rows, `roi.fallback_top_row_fraction`), at the top of the rows the working
//! frame holds, or after [`MAX_GAP_FRACTION`] of the
//! height without a mark (a dash's gap is shorter); the lane's rows then start at the highest
//! row where a mark was seen, if at least [`MIN_MARK_ROWS`] were.
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
/// Longest run of rows without a mark before the walk stops, as a fraction of the height.
pub(crate) const MAX_GAP_FRACTION: f64 = 0.1;
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
    let (w, h) = (image.width(), image.height());
    // Without a horizon (the lanes do not close in upwards) no higher than the second search's
    // rows, or the ROI's.
    let unknown = setup.fallback_roi.unwrap_or(setup.roi).0 as f64;
    let y_h = horizon_row.unwrap_or(unknown).max(0.0);
    let limit = (y_h.ceil() as usize).max(rows.0).max(1);
    let k = setup.cfg.track.window_half_width_px as i64;
    let max_width = f64::from(setup.cfg.gradient.stripe_max_width_px).max(4.0);
    let max_gap = ((MAX_GAP_FRACTION * h as f64).ceil() as usize).max(4);
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
        let mut far = FarFit::new(y_j, x_j, m_j, a1);
        let mut drift = 0.0f64;
        let (mut gap, mut top) = (0usize, None);
        let mut y = start as usize;
        while y > limit && gap <= max_gap {
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
            let mut best: Option<(i16, i64)> = None;
            for c in (centre - k).max(m)..=(centre + k).min(w as i64 - 1 - m) {
                let at = |x: i64| i16::from(line[x as usize]);
                let step = at(c) - at(c - m).max(at(c + m));
                if step >= MIN_CONTRAST && best.is_none_or(|(s, _)| step > s) {
                    best = Some((step, c));
                }
            }
            match best {
                Some((_, c)) => {
                    far.add(y as f64, c as f64);
                    let residual = c as f64 - far.col_at_row(y as f64);
                    drift = (0.5 * residual).clamp(-2.0 * k as f64, 2.0 * k as f64);
                    gap = 0;
                    top = Some(y as f64);
                }
                None => gap += 1,
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
