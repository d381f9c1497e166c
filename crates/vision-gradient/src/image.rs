//! Borrowed 8-bit grey image view.

use crate::GradientError;

/// Largest image side accepted, in pixels (edge coordinates are `u16`).
pub const MAX_SIDE_PX: usize = u16::MAX as usize;

/// A borrowed 8-bit grey image: `height` rows of `width` pixels, row `r` starting at byte
/// `r * stride` of `data` (row-major, `x` = column to the right, `y` = row downward).
#[derive(Debug, Clone, Copy)]
pub struct GreyImage<'a> {
    data: &'a [u8],
    width: usize,
    height: usize,
    stride: usize,
}

impl<'a> GreyImage<'a> {
    /// Wraps `data` as a `width` × `height` image whose rows are `stride` bytes apart.
    ///
    /// # Errors
    /// [`GradientError::EmptyImage`] for a zero side, [`GradientError::ImageTooLarge`] for a side
    /// above [`MAX_SIDE_PX`], [`GradientError::StrideTooSmall`] for `stride < width`,
    /// [`GradientError::DataTooShort`] if `data.len() < (height - 1) * stride + width`.
    pub fn new(
        data: &'a [u8],
        width: usize,
        height: usize,
        stride: usize,
    ) -> Result<Self, GradientError> {
        if width == 0 || height == 0 {
            return Err(GradientError::EmptyImage {
                width_px: width,
                height_px: height,
            });
        }
        if width > MAX_SIDE_PX || height > MAX_SIDE_PX {
            return Err(GradientError::ImageTooLarge {
                width_px: width,
                height_px: height,
                max_px: MAX_SIDE_PX,
            });
        }
        if stride < width {
            return Err(GradientError::StrideTooSmall {
                stride,
                width_px: width,
            });
        }
        // Cannot overflow: height, width <= 65535 and a slice of `stride * 65535` bytes would
        // have to exist for the product to be large; use checked maths anyway.
        let required = (height - 1)
            .checked_mul(stride)
            .and_then(|v| v.checked_add(width))
            .unwrap_or(usize::MAX);
        if data.len() < required {
            return Err(GradientError::DataTooShort {
                len: data.len(),
                required,
                width_px: width,
                height_px: height,
                stride,
            });
        }
        Ok(Self {
            data,
            width,
            height,
            stride,
        })
    }

    /// Width in pixels.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> usize {
        self.height
    }

    /// Row stride in bytes.
    pub fn stride(&self) -> usize {
        self.stride
    }

    /// Row `row_px` as a slice of `width` pixels, or `None` past the last row.
    pub fn row(&self, row_px: usize) -> Option<&'a [u8]> {
        if row_px >= self.height {
            return None;
        }
        let start = row_px * self.stride;
        self.data.get(start..start + self.width)
    }
}
