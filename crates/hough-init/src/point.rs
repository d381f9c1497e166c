//! The crate's own point type; every pixel point type of the workspace implements
//! [`grey_frame::PixelPoint`], which the Hough transform and the parabola fit take.

use grey_frame::PixelPoint;
use serde::{Deserialize, Serialize};

/// The crate's own edge-pixel type: a point in image coordinates, pixels.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Point {
    /// Column coordinate `x` (to the right), pixels.
    pub col_px: f64,
    /// Row coordinate `y` (downwards), pixels.
    pub row_px: f64,
}

impl Point {
    /// A point at column `col_px`, row `row_px`.
    #[must_use]
    pub const fn new(col_px: f64, row_px: f64) -> Self {
        Self { col_px, row_px }
    }
}

impl PixelPoint for Point {
    #[inline]
    fn col_px(&self) -> f64 {
        self.col_px
    }
    #[inline]
    fn row_px(&self) -> f64 {
        self.row_px
    }
}

/// An edge pixel with the normal angle of its edge (an addition beyond the paper, for
/// [`crate::HoughWorkspace::find_lines_oriented`]): image coordinates, pixels, and the angle
/// `θ` of the pixel's gradient from the column axis towards the (downward) row axis, folded
/// into `[−90°, 90°)` — the normal angle of the Hough line the edge is locally part of
/// (`vision_gradient::gradient_normal_deg` of `vision_gradient::EdgePixel::gradient` gives it).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OrientedPoint {
    /// Column coordinate `x` (to the right), pixels.
    pub col_px: f32,
    /// Row coordinate `y` (downwards), pixels.
    pub row_px: f32,
    /// Normal angle `θ` of the edge, degrees in `[−90, 90)`.
    pub normal_deg: f32,
    /// Votes the point casts in each of its θ bins (1 for a plain pixel; a pixel that counts
    /// more, such as the side of a bright stripe, casts several — in the accumulator the same as
    /// repeating it; 0 casts none).
    pub votes: u16,
}

impl PixelPoint for OrientedPoint {
    #[inline]
    fn col_px(&self) -> f64 {
        f64::from(self.col_px)
    }
    #[inline]
    fn row_px(&self) -> f64 {
        f64::from(self.row_px)
    }
}
