//! # lane-io — the lane tracker's inputs and outputs
//!
//! Around the numeric `lane-tracker` crate: where frames come from ([`FrameSource`] and its
//! sources), the loop that feeds them to the tracker ([`frame_loop`]), configuration and camera
//! files ([`config`]), and what is drawn from the results ([`overlay`], [`birdseye`]). Only this
//! crate (with `bt848-capture` below it) touches files and devices on the lane side.
//!
//! ## Frame sources
//! [`FrameSource`] fills a caller-owned [`GreyFrame`]. [`sources::StillImage`] (PNG, JPEG,
//! PGM; colour → grey), [`sources::ImageDirectory`] (sorted), [`y4m::Y4mSource`] (file or
//! stdin; `C mono` and 4:2:0, Y plane), and live V4L2 capture from a BT848/878 card
//! ([`capture_source`]: `CaptureSource` over the `bt848-capture` crate, feature `capture`;
//! without it opening a device says capture is not in the build).
//! Errors are [`LaneIoError`]; [`LaneIoError::is_fatal`] separates a fatal error from one bad frame
//! (or one capture timeout) that is reported, counted and skipped, and
//! [`LaneIoError::lost_frames`] says how many input frames a non-fatal error stands for (a damaged
//! YUV4MPEG2 stream is resynchronised at the next `FRAME` marker: [`LaneIoError::Y4mResync`]).
//!
//! ## Configuration files
//! [`config::load_tracker_config`] and [`config::load_camera_config`] take a preset name or a
//! TOML file path; the text is parsed and validated by `lane-tracker`, whose errors name the
//! file, the line and the column.

pub mod birdseye;
pub mod capture_source;
pub mod config;
pub mod encode_thread;
mod error;
mod frame;
pub mod frame_loop;
pub mod lane_frame;
pub mod mcap_sink;
pub mod mcap_source;
pub mod overlay;
pub mod sources;
#[cfg(test)]
mod test_support;
pub mod video;
pub mod y4m;

/// The capture layer's option types (`--input-select`, `--std`, `--format`, `--size`), re-exported
/// so the binary needs no direct dependency on `bt848-capture`.
pub mod capture {
    pub use bt848_capture::{CaptureError, InputSelect, PixelFormat, VideoStd, parse_size};
}

pub use error::{BagImageProblem, LaneIoError};
pub use frame::{FrameError, FrameMeta, FrameSource, GreyFrame};
