//! Frames and the frame-source trait.

use crate::LaneIoError;

/// The workspace's one grey frame (crate `grey-frame`): `width × height` bytes, row-major, its
/// length checked by every way to change its size. A source refills the caller's frame and
/// reallocates only when the size changes, so a loop over a stream of constant size does not
/// allocate.
pub use grey_frame::{FrameError, GreyFrame};

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
/// the stream, or an error. An error with [`LaneIoError::is_fatal`] `== false` concerns one frame
/// only (it has been skipped); the caller reports it, counts it and calls `next_frame` again.
pub trait FrameSource {
    /// Fill `frame` with the next frame.
    fn next_frame(&mut self, frame: &mut GreyFrame) -> Result<Option<FrameMeta>, LaneIoError>;

    /// A short human-readable description (file name, size, frame rate) for logs.
    fn describe(&self) -> String;

    /// Nominal frame rate, frames/s, if the source knows it.
    fn frame_rate_hz(&self) -> Option<f64> {
        None
    }
}

impl<S: FrameSource + ?Sized> FrameSource for Box<S> {
    fn next_frame(&mut self, frame: &mut GreyFrame) -> Result<Option<FrameMeta>, LaneIoError> {
        (**self).next_frame(frame)
    }
    fn describe(&self) -> String {
        (**self).describe()
    }
    fn frame_rate_hz(&self) -> Option<f64> {
        (**self).frame_rate_hz()
    }
}
