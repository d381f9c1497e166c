//! Edge-pixel coordinates accepted by the Hough transform and the parabola fit.

use serde::{Deserialize, Serialize};

/// Anything that carries an edge pixel's image coordinates, in pixels.
///
/// Convention (whole crate): `col_px` grows to the right, `row_px` grows downwards, the centre of
/// the top-left pixel is `(0, 0)`. Tuples and arrays are read as **(column, row)**, i.e. `(x, y)`
/// of eq. 1, *not* `(row, column)`.
pub trait EdgePoint {
    /// Column coordinate `x`, pixels.
    fn col_px(&self) -> f64;
    /// Row coordinate `y`, pixels.
    fn row_px(&self) -> f64;
}

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

impl EdgePoint for Point {
    #[inline]
    fn col_px(&self) -> f64 {
        self.col_px
    }
    #[inline]
    fn row_px(&self) -> f64 {
        self.row_px
    }
}

impl<P: EdgePoint + ?Sized> EdgePoint for &P {
    #[inline]
    fn col_px(&self) -> f64 {
        (**self).col_px()
    }
    #[inline]
    fn row_px(&self) -> f64 {
        (**self).row_px()
    }
}

macro_rules! impl_edge_point_pair {
    ($($t:ty),*) => {$(
        /// `(column, row)` in pixels.
        impl EdgePoint for ($t, $t) {
            #[inline]
            fn col_px(&self) -> f64 {
                f64::from(self.0)
            }
            #[inline]
            fn row_px(&self) -> f64 {
                f64::from(self.1)
            }
        }
        /// `[column, row]` in pixels.
        impl EdgePoint for [$t; 2] {
            #[inline]
            fn col_px(&self) -> f64 {
                f64::from(self[0])
            }
            #[inline]
            fn row_px(&self) -> f64 {
                f64::from(self[1])
            }
        }
    )*};
}

impl_edge_point_pair!(f32, f64, u16, u32, i32);
