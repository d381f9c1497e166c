//! Output types: edge pixels, the caller-owned edge buffer, per-call statistics.

/// Orientation class of a kept edge pixel. The discriminant is the value written into the
/// class image (`0` = not a candidate).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum EdgeClass {
    /// Edge running from bottom-left up to top-right in the image (`gx·gy > 0`).
    LeftLane = 1,
    /// Edge running from bottom-right up to top-left in the image (`gx·gy < 0`).
    RightLane = 2,
}

/// One lane-candidate pixel.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct EdgePixel {
    /// Column (x, to the right), pixels.
    pub col_px: u16,
    /// Row (y, downward), pixels.
    pub row_px: u16,
    /// `|gx| + |gy|` of the Sobel responses, grey levels, `0..=2040`.
    pub magnitude: u16,
    /// Orientation class.
    pub class: EdgeClass,
    /// Horizontal Sobel response `gx` (grey levels, positive when the image brightens to the
    /// right), `|gx| ≤ 1020`, never 0 for a kept pixel. With `magnitude` and `class` it gives
    /// the whole gradient: [`EdgePixel::gradient`].
    pub gx: i16,
}

impl EdgePixel {
    /// The Sobel gradient `(gx, gy)` of the pixel, grey levels (`gy` positive when the image
    /// brightens downwards): `|gy| = magnitude − |gx|`, and `gy` has the sign of `gx` for
    /// [`EdgeClass::LeftLane`] (`gx·gy > 0`) and the opposite sign for
    /// [`EdgeClass::RightLane`] — the Sobel gradient of the image at the pixel (tested), with
    /// no image access.
    #[inline]
    #[must_use]
    pub fn gradient(&self) -> (i16, i16) {
        let gy_abs = (self.magnitude as i16).saturating_sub(self.gx.saturating_abs());
        let same_sign = matches!(self.class, EdgeClass::LeftLane);
        let gy = if (self.gx >= 0) == same_sign {
            gy_abs
        } else {
            -gy_abs
        };
        (self.gx, gy)
    }
}

/// One past the last index of the row that starts at `start` in `pixels` (rows are stored
/// contiguously, [`EdgeBuffer`]); `start` must be `< pixels.len()`.
pub(crate) fn row_end(pixels: &[EdgePixel], start: usize) -> usize {
    let row = pixels[start].row_px;
    start
        + 1
        + pixels[start + 1..]
            .iter()
            .take_while(|p| p.row_px == row)
            .count()
}

impl grey_frame::PixelPoint for EdgePixel {
    #[inline]
    fn col_px(&self) -> f64 {
        f64::from(self.col_px)
    }
    #[inline]
    fn row_px(&self) -> f64 {
        f64::from(self.row_px)
    }
}

/// Caller-owned output list with a fixed capacity: allocated once, cleared and refilled by
/// every call, never grown. Pixels past the capacity are counted in [`EdgeBuffer::dropped`].
///
/// Pixels are stored **bottom row first** (rows in decreasing `row_px`, columns increasing
/// within a row), so a truncated buffer loses the far (top) rows, not the near road.
#[derive(Debug, Clone)]
pub struct EdgeBuffer {
    pixels: Vec<EdgePixel>,
    capacity: usize,
    dropped: usize,
}

impl EdgeBuffer {
    /// An empty buffer that holds at most `capacity` pixels (allocates here, never later).
    pub fn with_capacity(capacity: usize) -> Self {
        Self {
            pixels: Vec::with_capacity(capacity),
            capacity,
            dropped: 0,
        }
    }

    /// Maximum number of pixels stored.
    pub fn capacity(&self) -> usize {
        self.capacity
    }

    /// The stored pixels.
    pub fn pixels(&self) -> &[EdgePixel] {
        &self.pixels
    }

    /// Number of stored pixels.
    pub fn len(&self) -> usize {
        self.pixels.len()
    }

    /// `true` if no pixel is stored.
    pub fn is_empty(&self) -> bool {
        self.pixels.is_empty()
    }

    /// Number of kept pixels that did not fit by the last call.
    pub fn dropped(&self) -> usize {
        self.dropped
    }

    /// `true` if the last call kept more pixels than the capacity.
    pub fn is_truncated(&self) -> bool {
        self.dropped > 0
    }

    /// Stored pixels of one class.
    pub fn iter_class(&self, class: EdgeClass) -> impl Iterator<Item = &EdgePixel> + '_ {
        self.pixels.iter().filter(move |p| p.class == class)
    }

    /// Empties the buffer (keeps the allocation).
    pub fn clear(&mut self) {
        self.pixels.clear();
        self.dropped = 0;
    }

    /// The stored pixels, mutable (for in-crate post-filters).
    pub(crate) fn pixels_mut(&mut self) -> &mut [EdgePixel] {
        &mut self.pixels
    }

    /// Keeps the pixels whose `magnitude` has bit `flag` set, then masks every kept magnitude
    /// with `mask`; returns the number dropped. Order is preserved, no allocation.
    pub(crate) fn retain_flagged(&mut self, flag: u16, mask: u16) -> usize {
        let before = self.pixels.len();
        self.pixels.retain(|p| p.magnitude & flag != 0);
        for p in &mut self.pixels {
            p.magnitude &= mask;
        }
        before - self.pixels.len()
    }

    #[inline]
    pub(crate) fn push(&mut self, pixel: EdgePixel) {
        if self.pixels.len() < self.capacity {
            self.pixels.push(pixel);
        } else {
            self.dropped += 1;
        }
    }
}

/// What one call did.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct EdgeStats {
    /// Magnitude threshold applied (the fixed one, or the one chosen by the adaptive rule).
    pub threshold_magnitude: u16,
    /// Adaptive mode only: number of in-band pixels in the region (the histogram population).
    pub in_band_count: Option<usize>,
    /// Kept pixels of class [`EdgeClass::LeftLane`], stored or not.
    pub left_count: usize,
    /// Kept pixels of class [`EdgeClass::RightLane`], stored or not.
    pub right_count: usize,
    /// Pixels stored in the [`EdgeBuffer`].
    pub stored: usize,
    /// Kept pixels that did not fit in the [`EdgeBuffer`].
    pub dropped: usize,
}

#[cfg(test)]
mod tests {
    use grey_frame::PixelPoint;

    use super::{EdgeClass, EdgePixel};

    #[test]
    fn an_edge_pixel_is_the_workspaces_pixel_point() {
        let p = EdgePixel {
            col_px: 17,
            row_px: 203,
            magnitude: 90,
            class: EdgeClass::RightLane,
            gx: 40,
        };
        assert_eq!((p.col_px(), p.row_px()), (17.0, 203.0));
        // Taken as is where a point set is expected (a slice of edge pixels).
        let mean_col = [p, p].iter().map(PixelPoint::col_px).sum::<f64>() / 2.0;
        assert_eq!(mean_col, 17.0);
    }
}
