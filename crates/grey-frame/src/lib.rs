//! The workspace's one 8-bit grey frame type, [`GreyFrame`]: what every frame source fills (still
//! images, directories, YUV4MPEG2 streams, the V4L2 capture of `bt848-capture`, the synthetic
//! renderers) and what the lane tracker reads.
//!
//! **Invariant:** `data().len() == width() · height()` — row `y`, column `x` at
//! `data()[y · width + x]`, row-major, no padding. The fields are private and every way to change
//! the size ([`GreyFrame::reshape`], [`GreyFrame::from_vec`]) checks it, so code that receives a
//! `GreyFrame` never has to. The buffer is owned by the caller and refilled in place: `reshape`
//! reallocates only when the frame grows, so a loop over a stream of constant size does not
//! allocate.
//!
//! ```
//! use grey_frame::GreyFrame;
//! let mut f = GreyFrame::new(4, 2);
//! f.data_mut()[5] = 200; // column 1 of row 1
//! assert_eq!(f.get(1, 1), Some(200));
//! assert!(GreyFrame::from_vec(4, 2, vec![0; 7]).is_err());
//! ```
//!
//! Colour becomes grey in one way everywhere (capture, still images, the Python package, colour
//! YUV4MPEG2 output): [`luma_bt601`], in integers.

/// A size that cannot hold a frame, or a buffer of the wrong length.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum FrameError {
    /// `width × height` does not fit in memory (`usize` overflow).
    #[error("frame size {width}×{height} overflows the address space")]
    TooLarge {
        /// Width asked for, px.
        width: usize,
        /// Height asked for, px.
        height: usize,
    },
    /// A buffer handed to [`GreyFrame::from_vec`] does not hold `width × height` bytes.
    #[error("{width}×{height} frame needs {} bytes, the buffer holds {len}", width * height)]
    Length {
        /// Width, px.
        width: usize,
        /// Height, px.
        height: usize,
        /// Bytes in the buffer.
        len: usize,
    },
}

/// An 8-bit grey frame: `width × height` bytes, row-major (see the crate doc for the invariant).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct GreyFrame {
    width: usize,
    height: usize,
    data: Vec<u8>,
}

fn area(width: usize, height: usize) -> Result<usize, FrameError> {
    width
        .checked_mul(height)
        .filter(|&n| n <= isize::MAX as usize)
        .ok_or(FrameError::TooLarge { width, height })
}

impl GreyFrame {
    /// An all-black frame of a size known to be sensible (a constant, or one already checked).
    /// For sizes read from input use [`GreyFrame::reshape`] or [`GreyFrame::zeroed`], which
    /// return an error instead.
    ///
    /// # Panics
    /// If `width × height` overflows `usize`, as `vec!` would for such a length.
    #[allow(clippy::expect_used)]
    pub fn new(width: usize, height: usize) -> Self {
        Self::zeroed(width, height).expect("GreyFrame::new: width × height overflows")
    }

    /// An all-black frame, or [`FrameError::TooLarge`].
    pub fn zeroed(width: usize, height: usize) -> Result<Self, FrameError> {
        Ok(GreyFrame {
            width,
            height,
            data: vec![0; area(width, height)?],
        })
    }

    /// A frame over `data` (row-major), which must hold exactly `width × height` bytes.
    pub fn from_vec(width: usize, height: usize, data: Vec<u8>) -> Result<Self, FrameError> {
        let n = area(width, height)?;
        if data.len() != n {
            return Err(FrameError::Length {
                width,
                height,
                len: data.len(),
            });
        }
        Ok(GreyFrame {
            width,
            height,
            data,
        })
    }

    /// Sets the size, reusing the buffer (allocates only when it grows). Pixels keep whatever
    /// bytes the buffer held; a source overwrites them all. On error the frame is unchanged.
    pub fn reshape(&mut self, width: usize, height: usize) -> Result<(), FrameError> {
        let n = area(width, height)?;
        self.data.resize(n, 0);
        self.width = width;
        self.height = height;
        Ok(())
    }

    /// Width, px (columns).
    pub fn width(&self) -> usize {
        self.width
    }

    /// Height, px (rows).
    pub fn height(&self) -> usize {
        self.height
    }

    /// The pixels, `width × height` bytes, row-major.
    pub fn data(&self) -> &[u8] {
        &self.data
    }

    /// The pixels, writable (the length is fixed: the size changes only through
    /// [`GreyFrame::reshape`]).
    pub fn data_mut(&mut self) -> &mut [u8] {
        &mut self.data
    }

    /// Bytes the buffer can hold without reallocating (for tests of bounded memory).
    pub fn capacity(&self) -> usize {
        self.data.capacity()
    }

    /// The buffer, giving the frame up.
    pub fn into_vec(self) -> Vec<u8> {
        self.data
    }

    /// Pixel at column `col_px`, row `row_px` (`None` outside the frame).
    pub fn get(&self, col_px: usize, row_px: usize) -> Option<u8> {
        if col_px < self.width && row_px < self.height {
            self.data.get(row_px * self.width + col_px).copied()
        } else {
            None
        }
    }

    /// Row `row_px` (`None` below the frame).
    pub fn row(&self, row_px: usize) -> Option<&[u8]> {
        (row_px < self.height)
            .then(|| {
                self.data
                    .get(row_px * self.width..(row_px + 1) * self.width)
            })
            .flatten()
    }
}

/// BT.601 luma of one gamma-encoded R'G'B' pixel, `Y' = 0.299 R' + 0.587 G' + 0.114 B'`, rounded
/// to nearest, in 16-bit fixed point (weights 19 595, 38 470, 7 471 of 65 536): the workspace's
/// one colour → grey conversion.
#[inline]
pub fn luma_bt601(r: u8, g: u8, b: u8) -> u8 {
    let y = (19_595 * u32::from(r) + 38_470 * u32::from(g) + 7_471 * u32::from(b) + 32_768) >> 16;
    // The weights sum to 65 536, so y ≤ 255 and the cast is exact.
    y as u8
}

/// Anything that carries a pixel's image coordinates, in pixels: the workspace's one point type
/// for a pixel (what the Hough transform and the parabola fit of `hough-init`, the filters of
/// `info-filter` and `wrls` take; `vision_gradient::EdgePixel`, `hough_init::Point` and
/// `(column, row)` tuples and arrays implement it).
///
/// Convention: `col_px` grows to the right, `row_px` grows downwards, the centre of the top-left
/// pixel is `(0, 0)`. Tuples and arrays are read as **(column, row)**, i.e. `(x, y)` of the lane
/// paper's eq. 1, *not* `(row, column)`.
pub trait PixelPoint {
    /// Column coordinate `x`, pixels.
    fn col_px(&self) -> f64;
    /// Row coordinate `y`, pixels.
    fn row_px(&self) -> f64;
}

impl<P: PixelPoint + ?Sized> PixelPoint for &P {
    #[inline]
    fn col_px(&self) -> f64 {
        (**self).col_px()
    }
    #[inline]
    fn row_px(&self) -> f64 {
        (**self).row_px()
    }
}

macro_rules! impl_pixel_point_pair {
    ($($t:ty),*) => {$(
        /// `(column, row)` in pixels.
        impl PixelPoint for ($t, $t) {
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
        impl PixelPoint for [$t; 2] {
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

impl_pixel_point_pair!(f32, f64, u16, u32, i32);

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn tuples_and_arrays_are_column_then_row() {
        fn both<P: PixelPoint>(p: P) -> (f64, f64) {
            (p.col_px(), p.row_px())
        }
        assert_eq!(both((3.5f32, 7.0f32)), (3.5, 7.0));
        assert_eq!(both([4u16, 9]), (4.0, 9.0));
        let borrowed: &(i32, i32) = &(-2, 5);
        assert_eq!(both(borrowed), (-2.0, 5.0));
    }

    #[test]
    fn every_constructor_and_reshape_keeps_length_equal_to_width_times_height() {
        let mut f = GreyFrame::new(5, 3);
        assert_eq!(f.data().len(), 15);
        f.reshape(2, 2).unwrap();
        assert_eq!((f.width(), f.height(), f.data().len()), (2, 2, 4));
        f.reshape(0, 7).unwrap();
        assert_eq!(f.data().len(), 0);
        assert_eq!(
            GreyFrame::from_vec(3, 2, vec![1; 5]),
            Err(FrameError::Length {
                width: 3,
                height: 2,
                len: 5
            })
        );
        assert_eq!(
            GreyFrame::from_vec(3, 2, vec![1; 6]).unwrap().data(),
            &[1; 6]
        );
    }

    #[test]
    fn an_overflowing_size_is_an_error_and_leaves_the_frame_unchanged() {
        let mut f = GreyFrame::new(4, 4);
        f.data_mut()[3] = 9;
        let e = f.reshape(usize::MAX, 2).unwrap_err();
        assert_eq!(
            e,
            FrameError::TooLarge {
                width: usize::MAX,
                height: 2
            }
        );
        assert_eq!((f.width(), f.height(), f.get(3, 0)), (4, 4, Some(9)));
        assert!(GreyFrame::zeroed(1 << 40, 1 << 40).is_err());
    }

    #[test]
    fn pixels_and_rows_are_addressed_row_major() {
        let f = GreyFrame::from_vec(3, 2, vec![0, 1, 2, 10, 11, 12]).unwrap();
        assert_eq!(f.get(2, 1), Some(12));
        assert_eq!(f.get(3, 0), None);
        assert_eq!(f.get(0, 2), None);
        assert_eq!(f.row(1), Some(&[10, 11, 12][..]));
        assert_eq!(f.row(2), None);
    }
}
