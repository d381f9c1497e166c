//! A kerb's foot as the boundary (an addition beyond the paper; `init.kerb_foot`).
//!
//! Where a raised kerb bounds the road, the strongest edge across it is the kerb's top edge:
//! the pavement on one side, the kerb's face on the other. Seen from the road at a slant, the
//! face is a band a few pixels wide on the road side of that edge, darker or lighter than the
//! road, often with a dark groove at its foot. The road ends at the foot, and lane labels put
//! the boundary there, while the Hough line and the windows lock onto the top edge. After a
//! fresh initialisation and its refinement (and the double line's middle, when that did not
//! move it), every row `y` of the rows searched is read across the lane's estimate `x̂(y)`,
//! grey levels `I(x)`, with `d = −1` for the left lane and `+1` for the right one (the side
//! the road does not lie on) and the gradient towards that side `g(x) = I(x + d) − I(x − d)`:
//!
//! 1. the step: `x_s`, the column of the largest `|g|` within `r = max(1, w_max/4)` px of
//!    `x̂(y)` (`w_max = gradient.stripe_max_width_px`; ties go to the road's side); its outer
//!    level `o = I(x_s + 2d)` and inner level `n = I(x_s − 2d)` differ by at least
//!    [`MIN_STEP_CONTRAST`] grey levels; `h = (o + n)/2`, `σ = sign(o − n)`;
//! 2. not a mark: the outer side stays past `h` (`σ·(I − h) ≥ 0`) at `x_s + k·d` for
//!    `k = 2 … 2·w_max` or up to the image's edge — a pavement, not a painted line or a tape;
//! 3. the foot: `x_f`, the column of the largest `σ·g` at `x_s − k·d`, `k = r … w_max` (in
//!    effect `k ≥ max(3, r)`: step 4 needs a column between; the
//!    same polarity as the step: the rise out of the groove, or from the road onto a lighter
//!    face), at least [`MIN_FOOT_GRADIENT`] grey levels and [`MIN_FOOT_RATIO`] of `|g(x_s)|`;
//!    the row gives nothing if that range leaves the image;
//! 4. a face between them: some column `x_s − k·d`, `2 ≤ k < k_f`, has `σ·g` below
//!    half the foot's (the foot is an edge of its own, not the tail of a blurred step), and
//!    every pixel from `x_s − 2d` up to (not including) `x_f` stays on the inner side of `h`;
//! 5. the row gives `t(y) = x_f* − x̂(y)`, `x_f*` the vertex of the parabola through `σ·g` at
//!    `x_f − 1, x_f, x_f + 1` (clamped to half a pixel of `x_f`: a sharp edge lies between two
//!    columns; the row gives nothing if those need pixels outside the image).
//!
//! The lane is bounded by a kerb if at least [`MIN_ROWS`] rows (4 when every eighth row is
//! read), and [`MIN_ROW_FRACTION`] of its rows read inside the image, give a foot that agrees
//! with `t(y) ≈ α + β·y` (least squares, refitted twice on the rows within `max(0.5, w_max/8)`
//! px of the last fit: the face widens towards the camera, linearly in `y` on a straight road),
//! and the fitted foot lies on the road's side between `r − 1` and `w_max + 1` px from the
//! estimate at the first and the last row searched. The lane's reported boundary then moves to
//! the foot, `(a1, a2 + β, a3 + α)`, while its filter keeps tracking the top edge — the edge
//! its windows measure; a filter restarted at the foot would be pulled back to it over the next
//! frames. On each tracked frame (after the crossing gate) the kerb is read again on every
//! [`TRACKED_ROW_STEP`]-th row (the face widens or narrows as the vehicle moves): the offset
//! follows the reading, and after `track.lost_after_frames` frames in a row without one (the
//! kerb has ended) it is dropped; the next initialisation starts without one, and a kerb that
//! appears while a lane is tracked is not picked up until then. The pixel distances scale with
//! `w_max` (16 px at 320 px width in the default; `TrackerConfig::scale_pixels` scales it with
//! the resolution). No allocation (the rows' offsets go to a buffer of the image's height).
//!
//! On the labelled `f1tenth` set (a scale-model city with raised kerbs) the labels of a kerb
//! lie on its foot in most frames and on its top edge in some (no face visible to the
//! labeller); measured on the development part, the rule moves 20 lanes closer to their labels
//! (18 of them now matched) and 5 off them (`docs/lanes/history/kerb-foot.md`, "Kerb: boundary on
//! its foot").

use hough_init::Parabola;
use vision_gradient::GreyImage;

use super::double_line::LineSums;
use super::lane::Lane;
use super::report::Side;
use super::setup::Rows;
use crate::TrackerConfig;

/// Least grey-level difference across the step.
const MIN_STEP_CONTRAST: f64 = 20.0;
/// Least gradient `σ·g` of the foot, grey levels.
const MIN_FOOT_GRADIENT: f64 = 6.0;
/// Least gradient of the foot relative to the step's.
const MIN_FOOT_RATIO: f64 = 0.15;
/// Least number of rows whose foot agrees with the fit (on every row; on every `k`-th row,
/// `max(4, MIN_ROWS/k)` of them).
const MIN_ROWS: usize = 8;
/// Least fraction of the rows read inside the image whose foot agrees with the fit.
const MIN_ROW_FRACTION: f64 = 0.3;
/// On a tracked frame the kerb is read on every this-many-th row (an eighth of the cost of the
/// initialisation's reading; only for a lane with an offset).
const TRACKED_ROW_STEP: usize = 8;

/// The step's search radius `r` and the foot's least distance from the step (with step 4's
/// column between: `max(3, r)`), px: `max(1, w_max/4)`.
fn step_reach_px(max_width_px: i64) -> i64 {
    (max_width_px / 4).max(1)
}

/// A row's foot agrees with the fit within this many pixels: `max(0.5, w_max/8)`.
fn inlier_px(max_width_px: i64) -> f64 {
    (max_width_px as f64 / 8.0).max(0.5)
}

/// Row `row`'s kerb foot relative to `x_hat` for a boundary whose outer side is towards `dir`
/// (`±1`), steps 1–5 of the module docs; `None` if the row shows no kerb or `x_hat` is not a
/// column of the row.
pub(super) fn kerb_foot(row: &[u8], x_hat: f64, dir: i64, max_width_px: i64) -> Option<f64> {
    let w = row.len() as i64;
    if !(0.0..w as f64).contains(&x_hat) {
        return None;
    }
    let at = |x: i64| (0..w).contains(&x).then(|| f64::from(row[x as usize]));
    let g = |x: i64| Some(at(x + dir)? - at(x - dir)?);
    let x0 = x_hat.round() as i64;
    let reach = step_reach_px(max_width_px);
    // 1. The step, scanned from the road's side outwards (a tie goes to the road's side).
    let (mut xs, mut gs) = (None, 0.0f64);
    for k in -reach..=reach {
        let x = x0 + k * dir;
        if let Some(v) = g(x).filter(|v| v.abs() > gs.abs()) {
            (xs, gs) = (Some(x), v);
        }
    }
    let xs = xs?;
    let (outer, inner) = (at(xs + 2 * dir)?, at(xs - 2 * dir)?);
    if (outer - inner).abs() < MIN_STEP_CONTRAST {
        return None;
    }
    let half = 0.5 * (outer + inner);
    let sign = (outer - inner).signum();
    // 2. A pavement, not a mark: the outer side stays past the half level.
    for k in 2..=2 * max_width_px {
        match at(xs + k * dir) {
            Some(v) if (v - half) * sign < 0.0 => return None,
            Some(_) => {}
            None => break,
        }
    }
    // 3. The foot: the strongest gradient of the step's polarity on the road side.
    let (mut kf, mut gf) = (None, 0.0f64);
    for k in reach..=max_width_px {
        let v = g(xs - k * dir)? * sign;
        if v > gf {
            (kf, gf) = (Some(k), v);
        }
    }
    let kf = kf?;
    if gf < MIN_FOOT_GRADIENT || gf < MIN_FOOT_RATIO * gs.abs() {
        return None;
    }
    // 4. A face: the gradient dips between the step and the foot, and the levels stay on the
    // inner side of the half level.
    let mut dip = false;
    for k in 2..kf {
        dip |= g(xs - k * dir)? * sign < 0.5 * gf;
        if (at(xs - k * dir)? - half) * sign > 0.0 {
            return None;
        }
    }
    if !dip {
        return None;
    }
    // 5. The foot to a fraction of a pixel: the vertex of the parabola through σ·g at the
    // columns x_f − 1, x_f, x_f + 1.
    let xf = xs - kf * dir;
    let v = |x: i64| g(x).map(|v| v * sign);
    let (a, b, c) = (v(xf - 1)?, gf, v(xf + 1)?);
    let curvature = a - 2.0 * b + c;
    let vertex = if curvature < 0.0 {
        (0.5 * (a - c) / curvature).clamp(-0.5, 0.5)
    } else {
        0.0
    };
    Some(xf as f64 + vertex - x_hat)
}

/// `(α, β)` of `t ≈ α + β·y` by least squares over `rows` `(y, t)` within `inlier_px` of
/// `fit` (all of them without one), and how many there were; `None` if they do not
/// determine it.
fn line_fit(
    rows: &[(f64, f64)],
    fit: Option<(f64, f64)>,
    inlier_px: f64,
) -> Option<((f64, f64), usize)> {
    let mut sums = LineSums::default();
    for &(y, t) in rows {
        if !fit.is_some_and(|(a, b)| (t - a - b * y).abs() > inlier_px) {
            sums.add(y, t);
        }
    }
    Some((sums.fit()?, sums.rows))
}

/// The kerb stage: reads a kerb's foot beside a lane (its buffer of feet per row sized once).
#[derive(Debug)]
pub(super) struct KerbReader {
    /// The rows' kerb feet `(row, offset)` of the last reading (capacity: the height).
    feet: Vec<(f64, f64)>,
}

impl KerbReader {
    /// A reader for frames `height_px` rows tall.
    pub(super) fn new(height_px: usize) -> Self {
        KerbReader {
            feet: Vec::with_capacity(height_px),
        }
    }

    /// The reported boundary of the lane on `side` moved to the foot of a kerb after its
    /// initialisation, if `rows` show one (module docs; the filter keeps the top edge).
    /// Returns whether it moved.
    pub(super) fn onto_kerb_foot(
        &mut self,
        lane: &mut Lane,
        side: Side,
        image: &GreyImage<'_>,
        rows: Rows,
        cfg: &TrackerConfig,
    ) -> bool {
        let Some(offset) = self.read(lane, side, image, 1, rows, cfg) else {
            return false;
        };
        lane.kerb_offset_px = offset;
        lane.kerb_misses = 0;
        true
    }

    /// On a tracked frame, the kerb of the lane on `side` read again on every
    /// [`TRACKED_ROW_STEP`]-th row (the face widens or narrows as the vehicle moves; the kerb
    /// may end): the offset follows the reading, and after `track.lost_after_frames` frames in
    /// a row without one it is dropped and the lane reported on the edge it tracks. Only for a
    /// lane with an offset.
    pub(super) fn recheck_kerb_foot(
        &mut self,
        lane: &mut Lane,
        side: Side,
        image: &GreyImage<'_>,
        rows: Rows,
        cfg: &TrackerConfig,
    ) {
        if lane.kerb_offset_px == [0.0; 2] {
            return;
        }
        let reading = self.read(lane, side, image, TRACKED_ROW_STEP, rows, cfg);
        let lost_after = cfg.track.lost_after_frames;
        if let Some(offset) = reading {
            lane.kerb_offset_px = offset;
            lane.kerb_misses = 0;
        } else {
            lane.kerb_misses += 1;
            if lane.kerb_misses >= lost_after {
                lane.kerb_offset_px = [0.0; 2];
                lane.kerb_misses = 0;
            }
        }
    }

    /// The offset `[α, β]` of a kerb's foot from the tracked edge of the lane on `side`, read
    /// on every `row_step`-th row of `rows` (module docs), or `None`.
    fn read(
        &mut self,
        lane: &Lane,
        side: Side,
        image: &GreyImage<'_>,
        row_step: usize,
        rows: Rows,
        cfg: &TrackerConfig,
    ) -> Option<[f64; 2]> {
        let c = lane.filter.as_ref().map(|f| f.coeffs())?;
        let p = Parabola::from_coeffs(c);
        let (top, bottom) = rows;
        let max_width_px = i64::from(cfg.gradient.stripe_max_width_px.max(1));
        let dir = match side {
            Side::Left => -1,
            Side::Right => 1,
        };
        let feet = &mut self.feet;
        feet.clear();
        let mut inside = 0usize;
        for y in (top..bottom).step_by(row_step.max(1)) {
            let Some(row) = image.row(y) else { continue };
            let x = p.col_at_row(y as f64);
            if !(0.0..row.len() as f64).contains(&x) {
                continue;
            }
            inside += 1;
            if let Some(t) = kerb_foot(row, x, dir, max_width_px)
                && feet.len() < feet.capacity()
            {
                feet.push((y as f64, t));
            }
        }
        let min_rows = (MIN_ROWS / row_step.max(1)).max(4);
        let enough = |n: usize| n >= min_rows && n as f64 >= MIN_ROW_FRACTION * inside as f64;
        let inlier = inlier_px(max_width_px);
        let mut fit = None;
        for _ in 0..3 {
            match line_fit(feet, fit, inlier) {
                Some((f, n)) if enough(n) => fit = Some(f),
                _ => return None,
            }
        }
        let (alpha, beta) = fit?;
        // The fitted foot on the road's side of the estimate, within the reach of a row's, at
        // both ends of the rows searched.
        let reach = step_reach_px(max_width_px) as f64;
        let plausible = |y: usize| {
            let inward = -(dir as f64) * (alpha + beta * y as f64);
            (reach - 1.0..=max_width_px as f64 + 1.0).contains(&inward)
        };
        (plausible(top) && plausible(bottom - 1)).then_some([alpha, beta])
    }
}

#[cfg(test)]
mod tests {
    use super::{kerb_foot, line_fit};

    /// A row of 60 columns seen across a right-hand kerb: road (level 55) up to column 30, a
    /// groove (44) on 30..32, the face (55) on 32..40, the pavement (100) from 40 on.
    fn kerb_row() -> Vec<u8> {
        let mut r = vec![55u8; 60];
        r[30..32].fill(44);
        r[40..].fill(100);
        r
    }

    #[test]
    fn a_row_reads_the_foot_of_a_kerb_and_nothing_else() {
        // The step lies between 39 and 40; the foot, the rise out of the groove, between
        // 31 and 32 (g = I(x + 1) − I(x − 1) is 11 at both: the vertex is their middle).
        let kerb = kerb_row();
        assert_eq!(kerb_foot(&kerb, 39.5, 1, 12), Some(31.5 - 39.5));
        // Mirrored: a left-hand kerb, the road to the right; the same foot, mirrored.
        let mirrored: Vec<u8> = kerb.iter().rev().copied().collect();
        assert_eq!(kerb_foot(&mirrored, 19.5, -1, 12), Some(27.5 - 19.5));
        // A lighter face (no groove) rising from a darker road: the foot is that rise.
        let mut face = vec![85u8; 60];
        face[32..40].fill(104);
        face[40..].fill(150);
        assert_eq!(kerb_foot(&face, 39.5, 1, 12), Some(31.5 - 39.5));
        // A soft foot: σ·g = 6, 8, 5 at columns 31, 32, 33, the vertex at 32 − 0.1 (inside the
        // half-pixel clamp); mirrored, the same foot on the other side.
        let mut soft = kerb_row();
        soft[31] = 47;
        soft[32] = 50;
        let t = kerb_foot(&soft, 39.5, 1, 12).expect("a foot");
        assert!((t - (31.9 - 39.5)).abs() < 0.05, "{t}");
        let soft_mirrored: Vec<u8> = soft.iter().rev().copied().collect();
        let t = kerb_foot(&soft_mirrored, 19.5, -1, 12).expect("a foot");
        assert!((t - (27.1 - 19.5)).abs() < 0.05, "{t}");
        // The estimate outside the row (or not a number): nothing read, no overflow.
        for x_hat in [-1.0, 60.0, f64::INFINITY, 1e19, f64::NAN] {
            assert_eq!(kerb_foot(&kerb, x_hat, 1, 12), None, "{x_hat}");
        }
        // A plain step (no face), a painted mark 8 px wide, a tape 20 px wide (< 2·w_max)
        // with a groove beside it, a low step, a face as bright as the pavement: no kerb.
        let mut step = vec![55u8; 60];
        step[40..].fill(100);
        assert_eq!(kerb_foot(&step, 39.5, 1, 12), None);
        let mut mark = kerb_row();
        mark[48..].fill(55);
        assert_eq!(kerb_foot(&mark, 39.5, 1, 12), None);
        let mut tape = vec![55u8; 80];
        tape[30..32].fill(44);
        tape[40..60].fill(100);
        assert_eq!(kerb_foot(&tape, 39.5, 1, 12), None);
        let mut low = kerb_row();
        low[40..].fill(70);
        assert_eq!(kerb_foot(&low, 39.5, 1, 12), None);
        let mut lit = kerb_row();
        lit[32..40].fill(90);
        assert_eq!(kerb_foot(&lit, 39.5, 1, 12), None);
        // A foot farther than w_max from the step is not this kerb's.
        assert_eq!(kerb_foot(&kerb, 39.5, 1, 6), None);
        // A bright mark on the road side of a pavement's edge is no face (the face stays on
        // the inner side of the step's half level), whatever its edges' gradient.
        let mut beside = step.clone();
        beside[33..36].fill(100);
        assert_eq!(kerb_foot(&beside, 39.5, 1, 12), None);
        // A faint seam beside a strong step: its edge is below the ratio to the step's.
        let mut strong = kerb_row();
        strong[40..].fill(200);
        assert_eq!(kerb_foot(&strong, 39.5, 1, 12), None);
        // A blurred plain step, on either side: its tail is no foot (no face between; at
        // σ = 2 and 3 px the dip test refuses it, at 1.5 px the tail is already below the
        // foot's least gradient).
        for (sigma_px, contrast) in [(1.5, 45.0), (2.0, 70.0), (3.0, 90.0)] {
            let blurred: Vec<u8> = (0..60)
                .map(|x| {
                    let z = (f64::from(x) - 39.5) / sigma_px;
                    (55.0 + contrast / (1.0 + (-1.7 * z).exp())).round() as u8
                })
                .collect();
            assert_eq!(kerb_foot(&blurred, 39.5, 1, 12), None, "σ {sigma_px}");
            let mirrored: Vec<u8> = blurred.iter().rev().copied().collect();
            assert_eq!(kerb_foot(&mirrored, 19.5, -1, 12), None, "σ {sigma_px}");
        }
    }

    #[test]
    fn the_feet_are_fitted_on_the_rows_that_agree() {
        // t = 1 + 0.1·y on ten rows, one row's foot 6 px off.
        let mut rows: Vec<(f64, f64)> = (0..10)
            .map(|k| (f64::from(k), 1.0 + 0.1 * f64::from(k)))
            .collect();
        rows[4].1 += 6.0;
        let ((a, b), n) = line_fit(&rows, None, 1.5).expect("a fit");
        assert_eq!(n, 10);
        assert!((a - 1.0).abs() > 0.1, "the first fit takes every row");
        let ((a, b2), n) = line_fit(&rows, Some((a, b)), 1.5).expect("a fit");
        assert_eq!(n, 9, "the row 6 px off is dropped");
        assert!(
            (a - 1.0).abs() < 1e-9 && (b2 - 0.1).abs() < 1e-9,
            "{a} {b2}"
        );
        assert_eq!(
            line_fit(&rows[..1], None, 1.5),
            None,
            "one row does not fix a line"
        );
    }
}
