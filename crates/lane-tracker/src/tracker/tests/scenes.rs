//! The synthetic frames the tests draw, and the lanes they set by hand.

use super::*;

/// The centre of `two_marks`' left (`/`) mark at row `y`, px.
pub(super) fn mark_left(y: f64) -> f64 {
    100.0 - 0.45 * (y - 239.0)
}

/// The centre of `two_marks`' right (`\`) mark at row `y`, px.
pub(super) fn mark_right(y: f64) -> f64 {
    220.0 + 0.45 * (y - 239.0)
}

/// Two bright marks (`/` left, `\` right) 5 px wide on a dark floor.
pub(super) fn two_marks(w: usize, h: usize) -> GreyFrame {
    let (left, right) = (mark_left, mark_right);
    let mut pixels = vec![60u8; w * h];
    for (i, p) in pixels.iter_mut().enumerate() {
        let (x, y) = ((i % w) as f64, (i / w) as f64);
        if (x - left(y)).abs() < 2.5 || (x - right(y)).abs() < 2.5 {
            *p = 200;
        }
    }
    GreyFrame::from_vec(w, h, pixels).expect("a whole frame")
}

/// `two_marks` with a bright bar 5 px wide leaning the left mark's way but much flatter
/// (`dx/dy = −2.5`, 22° from the horizontal against the mark's 66°), crossing the left mark
/// around row 190: the same edge class, another direction (a crosswalk stripe, a car's rear).
pub(super) fn two_marks_and_a_crossing_bar(w: usize, h: usize) -> GreyFrame {
    let clean = two_marks(w, h);
    let bar = |y: f64| 100.0 - 0.45 * (190.0 - 239.0) - 2.5 * (y - 190.0);
    let mut pixels = clean.data().to_vec();
    for (i, p) in pixels.iter_mut().enumerate() {
        let (x, y) = ((i % w) as f64, (i / w) as f64);
        if (x - bar(y)).abs() < 6.0 && (170.0..210.0).contains(&y) {
            *p = 200;
        }
    }
    GreyFrame::from_vec(w, h, pixels).expect("a whole frame")
}

/// Two bright marks 5 px wide on a dark floor, their vanishing point above the image, the right
/// one painted only on rows 80..140, above the default ROI (from row 148 at 240 rows): a dash
/// whose near field falls in the gap before the next one.
pub(super) fn left(y: f64) -> f64 {
    60.0 - 0.3 * (y - 239.0)
}

pub(super) fn right(y: f64) -> f64 {
    260.0 + 0.3 * (y - 239.0)
}

pub(super) fn right_mark_above_the_roi(w: usize, h: usize) -> GreyFrame {
    right_dash_on_rows(w, h, 80.0..140.0)
}

pub(super) fn right_dash_on_rows(w: usize, h: usize, rows: std::ops::Range<f64>) -> GreyFrame {
    right_dash_shifted(w, h, rows, 0.0)
}

/// [`right_dash_on_rows`] with the right mark `shift_px` to the right of `right`.
pub(super) fn right_dash_shifted(
    w: usize,
    h: usize,
    rows: std::ops::Range<f64>,
    shift_px: f64,
) -> GreyFrame {
    let mut pixels = vec![60u8; w * h];
    for (i, p) in pixels.iter_mut().enumerate() {
        let (x, y) = ((i % w) as f64, (i / w) as f64);
        let on_right = (x - right(y) - shift_px).abs() < 2.5 && rows.contains(&y);
        if (x - left(y)).abs() < 2.5 || on_right {
            *p = 200;
        }
    }
    GreyFrame::from_vec(w, h, pixels).expect("a whole frame")
}

/// The foot of `kerb_above_the_roi`'s kerb, whose top edge is `right(y)`: its face widens
/// from 5 px at row 76 to 8 px at row 146.
pub(super) fn tall_kerb_foot_col(y: f64) -> f64 {
    right(y) - (5.0 + 3.0 * (y - 76.0) / 70.0)
}

/// On a road of level 55, the left mark of [`right_mark_above_the_roi`] on every row, and on
/// the right a kerb (`kerb_level`: top edge `right(y)`, foot `tall_kerb_foot_col(y)`) seen only
/// on rows 76..146, above the default ROI (from row 148): plain road below.
pub(super) fn kerb_above_the_roi(w: usize, h: usize) -> GreyFrame {
    let mut pixels = vec![55u8; w * h];
    for (i, p) in pixels.iter_mut().enumerate() {
        let (x, y) = ((i % w) as f64, (i / w) as f64);
        if (x - left(y)).abs() < 2.5 {
            *p = 200;
        } else if (76.0..146.0).contains(&y) {
            *p = kerb_level(x, right(y), tall_kerb_foot_col(y), true);
        }
    }
    GreyFrame::from_vec(w, h, pixels).expect("a whole frame")
}

/// `left(y) ± s(y)` for the two lines of a double line, `2·h(y)` wide, both growing towards
/// the camera as on a real road (`s` 3.3 → 7 px, `h` 1.5 → 2.5 px over the ROI), on the left
/// of `two_marks`' geometry, with its single right mark; `inner_only` paints only the line
/// `left(y) + s(y)`.
pub(super) fn double_line_left(w: usize, h: usize, inner_only: bool) -> GreyFrame {
    double_line_shifted(w, h, inner_only, 0.0)
}

/// [`double_line_left`] with the double line `shift_px` further left.
pub(super) fn double_line_shifted(
    w: usize,
    h: usize,
    inner_only: bool,
    shift_px: f64,
) -> GreyFrame {
    let (left, right) = (mark_left, mark_right);
    let mut pixels = vec![60u8; w * h];
    for (i, p) in pixels.iter_mut().enumerate() {
        let (x, y) = ((i % w) as f64, (i / w) as f64);
        let (s, half) = (3.0 + 4.0 * (y - 140.0) / 100.0, 1.5 + (y - 140.0) / 100.0);
        let d = x - left(y) + shift_px;
        let outer = !inner_only && (d + s).abs() < half;
        if (d - s).abs() < half || outer || (x - right(y)).abs() < 2.5 {
            *p = 200;
        }
    }
    GreyFrame::from_vec(w, h, pixels).expect("a whole frame")
}

/// A default tracker for 320 × 240 frames and its ROI's top, middle and bottom rows.
pub(super) fn default_tracker_and_rows() -> (LaneTracker, [f64; 3]) {
    let cfg = TrackerConfig::default_preset().expect("the default preset");
    let tracker = LaneTracker::new(&cfg, Estimator::Kif, 320, 240).expect("a tracker");
    let (top, bottom) = tracker.setup.roi;
    let rows = [top as f64, 0.5 * (top + bottom) as f64, (bottom - 1) as f64];
    (tracker, rows)
}

/// The filter of the lane on `side` set to the straight line through `(row, col)` points `a`
/// and `b`.
pub(super) fn set_lane_line(tracker: &mut LaneTracker, side: Side, a: (f64, f64), b: (f64, f64)) {
    let slope = (b.1 - a.1) / (b.0 - a.0);
    let theta = Vector3::new(0.0, slope, a.1 - slope * a.0);
    tracker.lanes[side].filter = Some(tracker.setup.new_filter(&theta).expect("a filter"));
}

/// A steep double line near the left border, `two_marks`' right mark on the right: lines 3 px
/// wide (bright 200 on a floor of 60, horizontal runs `|x − c| < 1.5`) at `middle(y) ± 3`,
/// `middle(y) = col_at_top_px − 2·(y − 148)` (2 px a row to the left going down: it leaves
/// the image through its left side within a few rows of the ROI's top row, 148).
pub(super) fn steep_double_line(col_at_top_px: f64) -> GreyFrame {
    let (w, h) = (320usize, 240usize);
    let middle = |y: f64| col_at_top_px - 2.0 * (y - 148.0);
    let mut pixels = vec![60u8; w * h];
    for (i, p) in pixels.iter_mut().enumerate() {
        let (x, y) = ((i % w) as f64, (i / w) as f64);
        let d = x - middle(y);
        if (d - 3.0).abs() < 1.5 || (d + 3.0).abs() < 1.5 || (x - mark_right(y)).abs() < 2.5 {
            *p = 200;
        }
    }
    GreyFrame::from_vec(w, h, pixels).expect("a whole frame")
}

/// `two_marks`' left mark, and on the right a raised kerb: the road (55) up to a groove (45)
/// 2 px wide at the foot `kerb_foot_col(y)`, the face (55) from the foot to the top edge
/// `kerb_top(y)`, the pavement (100) beyond it, each pixel the area average of what it covers
/// (the levels and the soft edges of a real kerb: the groove's edges stay below the gradient
/// threshold); the face widens towards the camera as on a real kerb (5 → 9 px over the ROI),
/// `extra_px` wider still. `plain`: the same step with no face and no groove. Positions are
/// continuous, pixel `x` covering `[x, x + 1)`: an edge at `e` lies between the pixels
/// around `e − ½` in the tracker's column coordinates.
pub(super) fn kerb_right(w: usize, h: usize, plain: bool, extra_px: f64) -> GreyFrame {
    let left = mark_left;
    let mut pixels = vec![55u8; w * h];
    for (i, p) in pixels.iter_mut().enumerate() {
        let (x, y) = ((i % w) as f64, (i / w) as f64);
        *p = if (x - left(y)).abs() < 2.5 {
            200
        } else {
            kerb_level(x, kerb_top(y), kerb_foot_col(y, extra_px), !plain)
        };
    }
    GreyFrame::from_vec(w, h, pixels).expect("a whole frame")
}

/// Pixel `x`'s level across a right-hand kerb whose top edge is at column `top` and foot at
/// `foot` (continuous, pixel `x` covering `[x, x + 1)`): road and face 55, the groove (45,
/// 2 px wide, ending at the foot) if `groove`, the pavement 100, each pixel the area average.
pub(super) fn kerb_level(x: f64, top: f64, foot: f64, groove: bool) -> u8 {
    let overlap = |a: f64, b: f64| (b.min(x + 1.0) - a.max(x)).clamp(0.0, 1.0);
    let pavement = overlap(top, f64::INFINITY);
    let groove = if groove {
        overlap(foot - 2.0, foot)
    } else {
        0.0
    };
    (55.0 + 45.0 * pavement - 10.0 * groove).round() as u8
}

pub(super) fn kerb_top(y: f64) -> f64 {
    230.0 + 0.45 * (y - 239.0)
}

/// The foot's column: the face starts there, the groove ends there.
pub(super) fn kerb_foot_col(y: f64, extra_px: f64) -> f64 {
    kerb_top(y) - (5.0 + extra_px + 4.0 * (y - 140.0) / 100.0)
}

/// A frame as the tracker's image type.
pub(super) fn image_of(f: &GreyFrame) -> GreyImage<'_> {
    GreyImage::new(f.data(), f.width(), f.height(), f.width()).expect("an image")
}

/// A bright road between the outer edges of `two_marks`' marks on a dark floor: the same
/// rising and falling edge pixels as those marks' outer sides, but each the side of a region
/// far wider than a mark (no stripe pairs them).
pub(super) fn road_between_marks(w: usize, h: usize) -> GreyFrame {
    let (left, right) = (mark_left, mark_right);
    let mut pixels = vec![60u8; w * h];
    for (i, p) in pixels.iter_mut().enumerate() {
        let (x, y) = ((i % w) as f64, (i / w) as f64);
        if x > left(y) - 2.5 && x < right(y) + 2.5 {
            *p = 200;
        }
    }
    GreyFrame::from_vec(w, h, pixels).expect("a whole frame")
}

/// The fraction of pixel `(x, y)` that `inside` covers, sampled on a 4×4 grid: a painted shape
/// anti-aliased as a lens and sensor blur its edges.
pub(super) fn cover(inside: &dyn Fn(f64, f64) -> bool, x: f64, y: f64) -> f64 {
    (0..16)
        .filter(|s| {
            inside(
                x - 0.375 + 0.25 * f64::from(s % 4),
                y - 0.375 + 0.25 * f64::from(s / 4),
            )
        })
        .count() as f64
        / 16.0
}

/// A crosswalk across the near rows (165..225) of a dark floor, right of the camera: five
/// bright stripes along the road (towards a vanishing point at (160, 100)), 14 px wide and 16 px
/// apart at the bottom row from column 185, narrowing with distance, anti-aliased; with `marks`,
/// over `two_marks` (painted over the right mark, as a real crosswalk is). Every stripe leans
/// (≥ 10° from the vertical): a vertical stripe's edges have no lean and are no edge pixels, so
/// it would leave the chain (the module docs of `vision_gradient::drop_periodic_stripes`).
pub(super) fn crosswalk(w: usize, h: usize, marks: bool) -> GreyFrame {
    let mut pixels = if marks {
        two_marks(w, h).data().to_vec()
    } else {
        vec![60u8; w * h]
    };
    // Column scaled back to the bottom row, where the stripes start every 30 px from 185.
    let on_stripe = |x: f64, y: f64| {
        let x_bottom = 160.0 + (x - 160.0) * 139.0 / (y - 100.0);
        let k = ((x_bottom - 185.0) / 30.0).floor();
        (0.0..5.0).contains(&k) && x_bottom - (185.0 + 30.0 * k) < 14.0
    };
    for (i, p) in pixels.iter_mut().enumerate() {
        let (x, y) = ((i % w) as f64, (i / w) as f64);
        if !(165.0..225.0).contains(&y) {
            continue;
        }
        let cover = cover(&on_stripe, x, y);
        *p = (f64::from(*p) + cover * (220.0 - f64::from(*p))).round() as u8;
    }
    GreyFrame::from_vec(w, h, pixels).expect("a whole frame")
}

/// A mark straight ahead of the camera (vertical, columns 141..147) and a `\` mark on the right
/// (centre `220 + 0.45·(y − 239)`), both 6 px wide and grey 200, anti-aliased, on a floor of
/// grey 60 with a deterministic texture of ±3 grey levels: along the vertical mark's edges
/// `gy` is that texture, so its sign — the pixel's class — is random.
pub(super) fn mark_straight_ahead(w: usize, h: usize) -> GreyFrame {
    let on_mark = |x: f64, y: f64| (141.0..147.0).contains(&x) || (x - mark_right(y)).abs() < 3.0;
    let pixels = (0..w * h)
        .map(|i| {
            let (x, y) = ((i % w) as f64, (i / w) as f64);
            // A splitmix64 finaliser of the pixel index: no pattern along rows or columns.
            let mut hash = (i as u64).wrapping_add(0x9E37_79B9_7F4A_7C15);
            hash = (hash ^ (hash >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            hash = (hash ^ (hash >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            hash = (hash ^ (hash >> 31)) % 7;
            let floor = 60.0 + hash as f64 - 3.0;
            (floor + cover(&on_mark, x, y) * (200.0 - floor)).round() as u8
        })
        .collect();
    GreyFrame::from_vec(w, h, pixels).expect("a whole frame")
}

/// Two marks 5 px wide on a dark floor meeting at the vanishing point `(160, meet_row)`, from
/// columns 60 and 260 at the bottom row; nothing is painted above that row.
pub(super) fn marks_meeting_at(w: usize, h: usize, meet_row: f64) -> GreyFrame {
    let mark = |bottom_col: f64, y: f64| {
        160.0 + (bottom_col - 160.0) * (y - meet_row) / (239.0 - meet_row)
    };
    let mut pixels = vec![60u8; w * h];
    for (i, p) in pixels.iter_mut().enumerate() {
        let (x, y) = ((i % w) as f64, (i / w) as f64);
        if y > meet_row && ((x - mark(60.0, y)).abs() < 2.5 || (x - mark(260.0, y)).abs() < 2.5) {
            *p = 200;
        }
    }
    GreyFrame::from_vec(w, h, pixels).expect("a whole frame")
}

/// `two_marks` with a bright bar 5 px wide left of the left mark, leaning outwards upwards
/// (column 80 at the bottom row, 30 at row 148): with the right mark it would make a lane
/// wider at the top of the ROI than at its bottom.
pub(super) fn two_marks_and_an_outward_bar(w: usize, h: usize) -> GreyFrame {
    let mut pixels = two_marks(w, h).data().to_vec();
    for (i, p) in pixels.iter_mut().enumerate() {
        let (x, y) = ((i % w) as f64, (i / w) as f64);
        if (x - outward_bar(y)).abs() < 2.5 {
            *p = 200;
        }
    }
    GreyFrame::from_vec(w, h, pixels).expect("a whole frame")
}

pub(super) fn outward_bar(y: f64) -> f64 {
    80.0 + 50.0 / 91.0 * (y - 239.0)
}

/// `two_marks` with a faint dashed line 25 px left of the left mark and parallel to it: 2 px
/// wide, 30 grey levels above the floor, dashes 6 rows long every 24 rows (a seam, a worn
/// line): enough edge pixels to hold a tracked lane, a quarter of a mark's row coverage.
pub(super) fn two_marks_and_a_faint_dashed_line(w: usize, h: usize) -> GreyFrame {
    let mut pixels = two_marks(w, h).data().to_vec();
    for (i, p) in pixels.iter_mut().enumerate() {
        let (x, y) = ((i % w) as f64, (i / w) as f64);
        if (x - faint_line(y)).abs() < 1.0 && (i / w) % 24 < 6 {
            *p = 90;
        }
    }
    GreyFrame::from_vec(w, h, pixels).expect("a whole frame")
}

pub(super) fn faint_line(y: f64) -> f64 {
    75.0 - 0.45 * (y - 239.0)
}

/// Three marks 5 px wide towards a vanishing point (`mark_towards_vp`), 160 px apart at the
/// bottom row, at bottom columns 80, 240 and 400 less `shift_px` (the camera moved right).
/// Anti-aliased (`cover`): a mark near the vertical still has edge pixels that lean.
pub(super) fn three_marks_shifted(w: usize, h: usize, shift_px: f64) -> GreyFrame {
    let on_mark = |x: f64, y: f64| {
        y > 100.0
            && [80.0, 240.0, 400.0]
                .iter()
                .any(|&b| (x - mark_towards_vp(b - shift_px, y)).abs() < 2.5)
    };
    let mut pixels = vec![60u8; w * h];
    for (i, p) in pixels.iter_mut().enumerate() {
        let (x, y) = ((i % w) as f64, (i / w) as f64);
        *p = (60.0 + 140.0 * cover(&on_mark, x, y)).round() as u8;
    }
    GreyFrame::from_vec(w, h, pixels).expect("a whole frame")
}

/// Column at row `y` of a mark through `bottom_col` at row 239 and the vanishing point (150, 100)
/// (off the middle column: a mark crossing it is never exactly vertical, which the gradient
/// does not see).
pub(super) fn mark_towards_vp(bottom_col: f64, y: f64) -> f64 {
    150.0 + (bottom_col - 150.0) * (y - 100.0) / 139.0
}

/// `two_marks`' geometry with a wide left mark, as a tape beside a small robot's camera: `2·h(y)`
/// px wide, 6 px at row 140 growing to 15 px at the bottom row (the default's widest stripe is
/// 16 px), each pixel the area average of what it covers (grey 60 floor, 200 mark).
pub(super) fn wide_left_mark(w: usize, h: usize) -> GreyFrame {
    let (left, right) = (mark_left, mark_right);
    let mut pixels = vec![60u8; w * h];
    for (i, p) in pixels.iter_mut().enumerate() {
        let (x, y) = ((i % w) as f64, (i / w) as f64);
        let half = 3.0 + 4.5 * (y - 140.0).max(0.0) / 99.0;
        let (lo, hi) = (left(y) - half, left(y) + half);
        let cover = ((x + 0.5).min(hi) - (x - 0.5).max(lo)).clamp(0.0, 1.0);
        let right_cover =
            ((x + 0.5).min(right(y) + 2.5) - (x - 0.5).max(right(y) - 2.5)).clamp(0.0, 1.0);
        *p = (60.0 + 140.0 * cover.max(right_cover)).round() as u8;
    }
    GreyFrame::from_vec(w, h, pixels).expect("a whole frame")
}

/// A default tracker (with `track.stripe_middles` and `init.stripe_trace` as given) after its
/// first frame of `wide_left_mark` — the initialisation and its refinements on the same frame
/// — and the reported left lane's largest offset from the mark's middle at the ROI's top,
/// middle and bottom rows, px.
pub(super) fn initialised_on_wide_mark(
    frame: &GreyFrame,
    middles: bool,
    trace: bool,
) -> (LaneTracker, f64) {
    let mut cfg = TrackerConfig::default_preset().expect("the default preset");
    cfg.track.stripe_middles = middles;
    cfg.init.stripe_trace = trace;
    let mut tracker = LaneTracker::new(&cfg, Estimator::Kif, 320, 240).expect("a tracker");
    let (top, bottom) = tracker.setup.roi;
    let report = tracker.track(frame).expect("a frame");
    assert!(report.lanes[0].initialised);
    let c = report.lanes[0].coeffs.expect("a left lane");
    let off = [top as f64, 0.5 * (top + bottom) as f64, (bottom - 1) as f64]
        .iter()
        .map(|&y| (c[0] * y * y + c[1] * y + c[2] - mark_left(y)).abs())
        .fold(0.0, f64::max);
    (tracker, off)
}

/// The centre of `curved_dash_left`'s dash at row `y`: a parabola whose vertex (vertical
/// tangent) lies at row 225, px.
pub(super) fn curved_dash_col(y: f64) -> f64 {
    0.01 * (y - 225.0) * (y - 225.0) + 90.0
}

/// A left dash 5 px wide drawn on rows 150–199 only, along [`curved_dash_col`] (it bends
/// towards the vertical at its lower end), and `two_marks`' straight right mark.
pub(super) fn curved_dash_left(w: usize, h: usize) -> GreyFrame {
    let mut pixels = vec![60u8; w * h];
    for (i, p) in pixels.iter_mut().enumerate() {
        let (x, y) = ((i % w) as f64, (i / w) as f64);
        let dash = (150.0..200.0).contains(&y) && (x - curved_dash_col(y)).abs() < 2.5;
        if dash || (x - mark_right(y)).abs() < 2.5 {
            *p = 200;
        }
    }
    GreyFrame::from_vec(w, h, pixels).expect("a whole frame")
}

/// A frame of grey 60 with `mark_left`'s line drawn 200 bright and `2·half_px` wide (area
/// average) on the rows `rows`, and, when `step`, the floor right of the line 200 bright as
/// well (a step, not a stripe).
pub(super) fn left_line(rows: std::ops::Range<f64>, half_px: f64, step: bool) -> GreyFrame {
    line_frame(mark_left, half_px, |y| rows.contains(&y), step)
}

/// A frame of grey 60 with a line 200 bright and `2·half_px` wide (area average) along each
/// row's `col(y)`, on the rows for which `drawn(y)` holds; when `step`, the floor right of the
/// line as bright as well (a step, not a stripe).
pub(super) fn line_frame(
    col: impl Fn(f64) -> f64,
    half_px: f64,
    drawn: impl Fn(f64) -> bool,
    step: bool,
) -> GreyFrame {
    let (w, h) = (320, 240);
    let mut pixels = vec![60u8; w * h];
    for (i, p) in pixels.iter_mut().enumerate() {
        let (x, y) = ((i % w) as f64, (i / w) as f64);
        if !drawn(y) {
            continue;
        }
        let (lo, hi) = (col(y) - half_px, col(y) + if step { 1e9 } else { half_px });
        let cover = ((x + 0.5).min(hi) - (x - 0.5).max(lo)).clamp(0.0, 1.0);
        *p = (60.0 + 140.0 * cover).round() as u8;
    }
    GreyFrame::from_vec(w, h, pixels).expect("a whole frame")
}

/// Lane 0 of a default tracker as a refinement that was pulled off `mark_left` would leave
/// it: updated on this frame with points on a parabola that follows the line at the ROI's
/// top row and bends `bend_px` off it at the bottom row.
pub(super) fn lane_bent_off_the_line(bend_px: f64) -> LaneTracker {
    let (mut tracker, _) = default_tracker_and_rows();
    let (top, bottom) = tracker.setup.roi;
    let (t, b) = (top as f64, (bottom - 1) as f64);
    let c = bend_px / ((b - t) * (b - t));
    // x = mark_left(y) + c·(y − t)²
    let bent = Vector3::new(c, -0.45 - 2.0 * c * t, 100.0 + 0.45 * 239.0 + c * t * t);
    tracker.lanes[Side::Left].filter = Some(tracker.setup.new_filter(&bent).expect("a filter"));
    let lane = &mut tracker.lanes[Side::Left];
    lane.points.clear();
    for r in top..bottom {
        let y = r as f64;
        lane.points
            .push(((mark_left(y) + c * (y - t) * (y - t)) as f32, y as f32));
    }
    let Some(LaneFilter::Kif(kif)) = lane.filter.as_mut() else {
        panic!("a KIF lane")
    };
    kif.update(&lane.points, 4.0).expect("an update");
    lane.state = LaneState::Tracking;
    lane.updated_now = true;
    lane.rows = [t, b];
    tracker
}

/// The lane's offset from `mark_left` at row `y`, px.
pub(super) fn left_offset(tracker: &LaneTracker, y: f64) -> f64 {
    let c = tracker.lanes[Side::Left]
        .filter
        .as_ref()
        .map(LaneFilter::coeffs)
        .expect("a left lane");
    c[0] * y * y + c[1] * y + c[2] - mark_left(y)
}

/// Lane 0 of a default tracker updated on this frame with points on rows `rows` of `col`,
/// its filter the straight line tangent to `col` at `row`.
pub(super) fn lane_tangent_at(
    col: impl Fn(f64) -> f64,
    row: f64,
    rows: std::ops::Range<usize>,
) -> LaneTracker {
    let (mut tracker, _) = default_tracker_and_rows();
    let slope = col(row + 0.5) - col(row - 0.5);
    set_lane_line(
        &mut tracker,
        Side::Left,
        (row, col(row)),
        (row + 1.0, col(row) + slope),
    );
    let lane = &mut tracker.lanes[Side::Left];
    lane.points.clear();
    for r in rows {
        lane.points.push((col(r as f64) as f32, r as f32));
    }
    lane.state = LaneState::Tracking;
    lane.updated_now = true;
    tracker
}
