//! Frames and the frame-source trait.

use crate::NavError;

/// An 8-bit grey frame owned by the caller and refilled by a [`FrameSource`].
///
/// `data` holds `width × height` bytes, row-major, no padding (row `y`, column `x` at
/// `data[y * width + x]`). A source only reallocates `data` when the frame size changes, so a loop
/// over a stream of constant size does not allocate.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct GreyFrame {
    /// Width, px (columns).
    pub width: usize,
    /// Height, px (rows).
    pub height: usize,
    /// Pixels, `width × height` bytes, row-major.
    pub data: Vec<u8>,
}

impl GreyFrame {
    /// An all-black frame of the given size.
    pub fn new(width: usize, height: usize) -> Self {
        GreyFrame {
            width,
            height,
            data: vec![0; width * height],
        }
    }

    /// Set the size, reusing the buffer (allocates only when it grows).
    pub fn reshape(&mut self, width: usize, height: usize) {
        self.width = width;
        self.height = height;
        self.data.resize(width * height, 0);
    }

    /// Pixel at column `col_px`, row `row_px` (`None` outside the frame).
    pub fn get(&self, col_px: usize, row_px: usize) -> Option<u8> {
        if col_px < self.width && row_px < self.height {
            self.data.get(row_px * self.width + col_px).copied()
        } else {
            None
        }
    }
}

/// What a source says about the frame it just delivered.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrameMeta {
    /// Zero-based index of the frame in the source (bad frames that were skipped keep their index,
    /// so indices may jump).
    pub index: u64,
    /// Time stamp of the frame, s from the first frame (index / frame rate; 0 for still images).
    pub t_s: f64,
}

/// A source of grey frames: a still image, a directory of images, a YUV4MPEG2 stream, a camera.
///
/// `next_frame` fills the caller's frame and returns its [`FrameMeta`], `Ok(None)` at the end of
/// the stream, or an error. An error with [`NavError::is_fatal`] `== false` concerns one frame
/// only (it has been skipped); the caller reports it, counts it and calls `next_frame` again.
pub trait FrameSource {
    /// Fill `frame` with the next frame.
    fn next_frame(&mut self, frame: &mut GreyFrame) -> Result<Option<FrameMeta>, NavError>;

    /// A short human-readable description (file name, size, frame rate) for logs.
    fn describe(&self) -> String;

    /// Nominal frame rate, frames/s, if the source knows it.
    fn frame_rate_hz(&self) -> Option<f64> {
        None
    }
}

impl<S: FrameSource + ?Sized> FrameSource for Box<S> {
    fn next_frame(&mut self, frame: &mut GreyFrame) -> Result<Option<FrameMeta>, NavError> {
        (**self).next_frame(frame)
    }
    fn describe(&self) -> String {
        (**self).describe()
    }
    fn frame_rate_hz(&self) -> Option<f64> {
        (**self).frame_rate_hz()
    }
}
