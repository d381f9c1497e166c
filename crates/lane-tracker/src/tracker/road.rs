//! # Where the road ends at the bottom of the frame (an addition beyond the paper;
//! `roi.road_bottom`)
//!
//! The paper's camera sees road down to the frame's last row, and the ROI is a band of rows
//! fixed as fractions of the height. A camera that sees its own bonnet or dashboard does not:
//! the band's lower rows are then a smooth, mostly dark surface with reflections on it, and the
//! lanes are fitted to those reflections while the marks run above. With
//! `roi.road_bottom = "found"` the lowest row of road is found on every frame that initialises
//! both lanes, and the working frame's rows are the road's rows, `[0, bottom)` of the input
//! stretched over the working height (module `view`): the ROI's fractions then hold for the
//! road seen, not for the frame.
//!
//! **The bonnet's edge.** A bonnet or a dashboard is a region at the bottom of the frame
//! (1) under a long, nearly horizontal boundary and (2) with no lane-like edges of its own. On
//! the lower half of the working frame (square pixels) each pixel is marked
//!
//! ```text
//! horizontal edge:  |I(x, y+1) − I(x, y−1)| ≥ T   and  ≥ 2·|I(x+1, y) − I(x−1, y)|,
//! lane-like edge:   |I(x+1, y) − I(x−1, y)| ≥ T   and  > |I(x, y+1) − I(x, y−1)|,
//! ```
//!
//! (`T` = [`EDGE_STEP`] grey levels; `T / gain` on a frame the exposure stage brightens by
//! `gain`, module `exposure`: the same as brightening it). Row `y` is a boundary when the columns holding a
//! horizontal edge within ±2 rows of it (a curved bonnet edge spans a few rows) cover at least
//! [`MIN_BOUNDARY_COVER`] of the width, and the rows under it (from `y + 3`, at least
//! [`MIN_BONNET_ROWS`] of the height) hold at most [`MAX_LANE_EDGES_BELOW`] lane-like edges per
//! pixel — a road's marks alone give about 1 % (four edges a row over 320 columns), its texture
//! more. The road's bottom is the boundary row with the widest cover (the highest among equals),
//! [`BOUNDARY_HALF_ROWS`] rows above it. Without such a boundary, a run of at least
//! [`MIN_FLAT_ROWS`] of the height at the bottom whose rows hold no edge of either kind (at most
//! [`MAX_FLAT_EDGES`] per column: a flat fill, a black band, a smooth bonnet whose edge is faint)
//! is no road either, and the road ends at its top; else the road reaches the frame's last row.
//!
//! Carried over a sequence: found again only on frames where neither lane has an estimate (a
//! view that changed under a tracked lane would move it), averaged with the last when the two
//! are within [`SAME_BOTTOM_FRACTION`] of the height of each other.

use vision_gradient::GreyImage;

use super::report::RoadReport;
use super::setup::Rows;

/// Step between the pixels either side of a pixel that makes it an edge, grey levels.
pub(crate) const EDGE_STEP: i16 = 20;
/// Fraction of the width a boundary's horizontal edges cover.
pub(crate) const MIN_BOUNDARY_COVER: f64 = 0.7;
/// Fewest rows under a boundary, as a fraction of the height.
pub(crate) const MIN_BONNET_ROWS: f64 = 0.04;
/// Most lane-like edges per pixel under a boundary.
pub(crate) const MAX_LANE_EDGES_BELOW: f64 = 0.0015;
/// Two bottoms within this fraction of the height are the same one seen again.
pub(crate) const SAME_BOTTOM_FRACTION: f64 = 0.05;
/// Fewest rows of a flat run at the bottom with no boundary above it, as a fraction of the height.
pub(crate) const MIN_FLAT_ROWS: f64 = 0.06;
/// Most edges of either kind per column in a row of a flat run.
pub(crate) const MAX_FLAT_EDGES: f64 = 0.003;
/// Rows either side of a row whose horizontal edges count for it.
const BOUNDARY_HALF_ROWS: usize = 4;

/// The road's bottom row finder: per-row counts over the lower half of a working frame.
#[derive(Debug)]
pub(super) struct RoadFinder {
    /// Per row looked at, a bit per column: a horizontal edge there (`words` words a row).
    horizontal: Vec<u64>,
    words: usize,
    /// Per row: columns with a horizontal edge within ±2 rows; lane-like edges.
    cover: Vec<u32>,
    lane_edges: Vec<u32>,
    /// The bottom found on the last frame that looked, working rows of the square view.
    bottom_row: Option<f64>,
    /// The last frame's region, input pixels.
    pub(super) last: RoadReport,
    /// What `last` is before the first frame.
    initial: RoadReport,
}

impl RoadFinder {
    /// A finder for `width × height` working frames, `initial` the region reported before
    /// the first frame.
    pub(super) fn new(width: usize, height: usize, initial: RoadReport) -> Self {
        let words = width.div_ceil(64);
        RoadFinder {
            horizontal: vec![0; words * height],
            words,
            cover: vec![0; height],
            lane_edges: vec![0; height],
            bottom_row: None,
            last: initial,
            initial,
        }
    }

    /// Forget the bottom carried and the last region.
    pub(super) fn reset(&mut self) {
        self.bottom_row = None;
        self.last = self.initial;
    }

    /// The road's bottom, `[0, h]` working rows of the square view (one past the last row of
    /// road), found on `image` (the square view's working frame, valid on `rows`) and carried
    /// over the sequence (module docs), for a frame the exposure stage brightens by `gain` (1:
    /// read as it is): `None` when the road reaches the frame's bottom.
    pub(super) fn find(&mut self, image: &GreyImage<'_>, rows: Rows, gain: f64) -> Option<f64> {
        let h = image.height();
        // Rounded, at least one grey level (`gain` is 1..=2).
        let step = ((f64::from(EDGE_STEP) / gain.max(1.0)).round() as i16).max(1);
        let found = self.boundary(image, rows, step).map(|b| b as f64);
        self.bottom_row = match (self.bottom_row, found) {
            (Some(last), Some(now)) if (last - now).abs() <= SAME_BOTTOM_FRACTION * h as f64 => {
                Some(0.5 * (last + now))
            }
            (_, now) => now,
        };
        self.bottom_row
    }

    /// The boundary row's road bottom on this frame alone, `step` its edges' step (module docs).
    fn boundary(&mut self, image: &GreyImage<'_>, rows: Rows, step: i16) -> Option<usize> {
        let (w, h) = (image.width(), image.height());
        let first = (h / 2).max(rows.0 + 1);
        let last = h.min(rows.1).saturating_sub(1);
        let words = self.words;
        if w < 3 || first + 4 > last || self.horizontal.len() < words * h {
            return None;
        }
        // Marks, then per-row counts.
        for y in first..last {
            let (Some(up), Some(mid), Some(down)) =
                (image.row(y - 1), image.row(y), image.row(y + 1))
            else {
                return None;
            };
            let bits = &mut self.horizontal[y * words..(y + 1) * words];
            bits.fill(0);
            let mut lane_edges = 0;
            for x in 1..w - 1 {
                let gv = (i16::from(down[x]) - i16::from(up[x])).abs();
                let gh = (i16::from(mid[x + 1]) - i16::from(mid[x - 1])).abs();
                let horizontal = gv >= step && gv >= 2 * gh;
                bits[x / 64] |= u64::from(horizontal) << (x % 64);
                lane_edges += u32::from(gh >= step && gh > gv);
            }
            self.lane_edges[y] = lane_edges;
        }
        // A column covers row y when one of rows y ± BOUNDARY_HALF_ROWS has a horizontal edge
        // there: the OR of those rows' bits, counted.
        for y in first..last {
            let lo = y.saturating_sub(BOUNDARY_HALF_ROWS).max(first);
            let hi = (y + BOUNDARY_HALF_ROWS + 1).min(last);
            let mut cover = 0;
            for word in 0..words {
                let any = (lo..hi).fold(0u64, |acc, r| acc | self.horizontal[r * words + word]);
                cover += any.count_ones();
            }
            self.cover[y] = cover;
        }
        let min_rows = ((MIN_BONNET_ROWS * h as f64).ceil() as usize).max(3);
        let mut best: Option<(u32, usize)> = None;
        let mut below = 0u64;
        // From the bottom up: `below` holds the lane-like edges of rows y + 3 … last − 1.
        for y in (first..last.saturating_sub(3)).rev() {
            below += u64::from(self.lane_edges[y + 3]);
            let under = last - (y + 3);
            if under < min_rows {
                continue;
            }
            let covered = f64::from(self.cover[y]) >= MIN_BOUNDARY_COVER * w as f64;
            let smooth = below as f64 <= MAX_LANE_EDGES_BELOW * (under * w) as f64;
            if covered && smooth && best.is_none_or(|(c, _)| self.cover[y] >= c) {
                best = Some((self.cover[y], y));
            }
        }
        if let Some((_, y)) = best {
            return Some(y.saturating_sub(BOUNDARY_HALF_ROWS));
        }
        // No boundary: a run of rows at the bottom with no edge of either kind (a flat fill,
        // a black band, a smooth bonnet whose edge is faint) is no road either.
        let flat_rows = ((MIN_FLAT_ROWS * h as f64).ceil() as usize).max(3);
        let mut top = last;
        for y in (first..last).rev() {
            let horizontal: u32 = self.horizontal[y * words..(y + 1) * words]
                .iter()
                .map(|b| b.count_ones())
                .sum();
            if f64::from(horizontal + self.lane_edges[y]) > MAX_FLAT_EDGES * w as f64 {
                break;
            }
            top = y;
        }
        (last - top >= flat_rows).then_some(top)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const W: usize = 320;
    const H: usize = 180;

    /// A road frame: grey asphalt with two bright marks converging upwards, `texture` a
    /// deterministic ±amplitude pattern on the asphalt (lattice hash, no randomness).
    fn road(texture: i32) -> Vec<u8> {
        let mut img = vec![0u8; W * H];
        for y in 0..H {
            for x in 0..W {
                let hash = ((x * 7919 + y * 104_729) % 13) as i32 - 6;
                let mut v = 110 + texture * hash / 6;
                let yf = y as f64;
                let left = 160.0 - 1.1 * (yf - 40.0).max(0.0);
                let right = 160.0 + 1.1 * (yf - 40.0).max(0.0);
                for mark in [left, right] {
                    if y > 60 && (x as f64 - mark).abs() < 3.0 {
                        v = 220;
                    }
                }
                img[y * W + x] = v.clamp(0, 255) as u8;
            }
        }
        img
    }

    /// `img` with a smooth dark bonnet from `top` down, its edge bowed up by `bow` rows in the
    /// middle, a soft highlight across it.
    fn with_bonnet(mut img: Vec<u8>, top: usize, bow: f64) -> Vec<u8> {
        for x in 0..W {
            let u = (x as f64 - W as f64 / 2.0) / (W as f64 / 2.0);
            let edge = top as f64 - bow * (1.0 - u * u);
            for y in 0..H {
                if y as f64 >= edge {
                    let t = (y as f64 - edge) / (H as f64 - edge);
                    let v = 40.0 + 20.0 * t + 25.0 * (-((t - 0.3) / 0.1).powi(2)).exp();
                    img[y * W + x] = v as u8;
                }
            }
        }
        img
    }

    fn finder() -> RoadFinder {
        let whole = RoadReport {
            bottom_row_px: H as f64,
            search_rows_px: [0.0, H as f64],
            horizon_row_px: None,
            refused: None,
        };
        RoadFinder::new(W, H, whole)
    }

    fn find(img: &[u8]) -> Option<f64> {
        let image = GreyImage::new(img, W, H, W).expect("image");
        finder().find(&image, (0, H), 1.0)
    }

    #[test]
    fn a_bonnets_edge_is_the_roads_bottom() {
        for (top, bow) in [(144usize, 0.0), (117, 6.0), (150, 10.0)] {
            let b = find(&with_bonnet(road(4), top, bow)).expect("a bonnet found");
            // Within the bowed edge's rows, and above its flat part.
            assert!(
                b <= top as f64 && b >= top as f64 - bow - 2.0 * BOUNDARY_HALF_ROWS as f64,
                "edge at {top} bowed {bow}: bottom {b}"
            );
        }
    }

    #[test]
    fn a_road_down_to_the_last_row_has_no_bottom() {
        assert_eq!(find(&road(0)), None);
        assert_eq!(find(&road(30)), None);
    }

    #[test]
    fn a_flat_band_at_the_bottom_ends_the_road_without_a_boundary() {
        // The bottom 20 rows one flat grey the road's own (no edge at the seam), and a road
        // whose marks reach the last row: only the first has a bottom.
        let mut img = road(0);
        img[160 * W..].fill(110);
        let b = find(&img).expect("a flat band found");
        assert!((155.0..=161.0).contains(&b), "bottom {b}");
        assert_eq!(find(&road(0)), None);
    }

    #[test]
    fn a_shadow_across_the_road_is_not_a_bonnet() {
        // A dark band across the whole road from row 130 down, the marks and the asphalt's
        // texture going on under it: a long horizontal edge, but lane-like edges below.
        let mut img = road(30);
        for v in &mut img[130 * W..] {
            *v = (*v as f64 * 0.55) as u8;
        }
        assert_eq!(find(&img), None);
    }

    #[test]
    fn an_under_exposed_road_read_with_its_gain_is_not_taken_for_a_bonnet() {
        // The road at a tenth of its exposure: the marks' step (11 grey levels) is under the
        // edge step, and the rows read as a flat run. Brightened twofold (the step halved) the
        // marks are lane-like edges again and the road reaches the frame's bottom.
        let dark: Vec<u8> = road(0).iter().map(|&v| v / 10).collect();
        let image = GreyImage::new(&dark, W, H, W).expect("image");
        assert!(finder().find(&image, (0, H), 1.0).is_some());
        assert_eq!(finder().find(&image, (0, H), 2.0), None);
    }

    #[test]
    fn a_bottom_seen_again_is_averaged_and_a_new_one_replaces_it() {
        let mut finder = finder();
        let mut at = |top| {
            let img = with_bonnet(road(4), top, 0.0);
            let image = GreyImage::new(&img, W, H, W).expect("image");
            finder.find(&image, (0, H), 1.0)
        };
        let first = at(140).expect("found");
        let again = at(142).expect("found");
        assert!(
            (again - (first + first + 2.0) / 2.0).abs() <= 1.0,
            "{first} {again}"
        );
        let moved = at(110).expect("found");
        assert!(
            (moved - 110.0).abs() <= 2.0 * BOUNDARY_HALF_ROWS as f64,
            "{moved}"
        );
    }
}
