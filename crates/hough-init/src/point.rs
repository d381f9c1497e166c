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
