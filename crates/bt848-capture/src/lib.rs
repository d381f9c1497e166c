//! V4L2 capture for the lane tracker's frame grabber: a Brooktree BT848/878 card (Linux `bttv`
//! driver) with an NTSC camera, delivering 320×240 8-bit grey frames.
//!
//! The paper (lanes, §2: the image acquisition) grabs 320×240 grey fields from a BT848 board; it
//! says nothing about the driver interface, so everything below is this crate's design, proven
//! against the kernel's `vivid` driver by `cargo xtask vivid`.
//!
//! # Model
//!
//! [`Capture::open`] runs the standard V4L2 sequence on the `v4l` crate's device handle and
//! bindings:
//!
//! 1. `VIDIOC_QUERYCAP`: the node must offer video capture and streaming I/O, else
//!    [`CaptureError::NotCaptureDevice`].
//! 2. Input: `VIDIOC_ENUMINPUT`, then `VIDIOC_S_INPUT` by index or by name (bttv: `"Television"`,
//!    `"Composite0"`…, `"S-Video"`), see [`InputSelect`].
//! 3. Standard: `VIDIOC_S_STD` with the [`VideoStd`] bits masked by the input's supported set
//!    (NTSC-M by default; bttv starts in PAL so it must be set), read back with `VIDIOC_G_STD`.
//! 4. Format: `VIDIOC_S_FMT` with each preferred fourcc in turn (GREY, YUYV, UYVY, YU12, BGR24,
//!    RGB565, BGR32 by default) at the requested size; the size, fourcc and `bytesperline` the
//!    driver *returns* are used. At ≤ 240 lines bttv delivers single fields (no combing).
//! 5. `VIDIOC_REQBUFS` ≥ 4 mmap buffers, `VIDIOC_QUERYBUF` + `mmap`, `VIDIOC_QBUF` all,
//!    `VIDIOC_STREAMON`.
//!
//! [`Capture::next_frame`] polls for at most `timeout_ms`, dequeues, and with the driver's
//! `bytesused`, `sequence`, `flags` and `timestamp`:
//!
//! * a buffer flagged `V4L2_BUF_FLAG_ERROR` (or shorter than a frame) is re-queued and counted in
//!   [`CaptureStats::errored_dropped`], never delivered;
//! * a jump of the sequence number, `gap = seq − last − 1 > 0`, is added to
//!   [`CaptureStats::sequence_gaps`] and reported in [`FrameInfo::frames_missed_before`];
//! * the frame is converted to grey (see [`convert`]: BT.601 luma
//!   `Y' = 0.299 R' + 0.587 G' + 0.114 B'` for RGB formats, the Y' plane for Y'CbCr ones) into the
//!   caller's buffer, and the buffer re-queued;
//! * the input status (`VIDIOC_ENUMINPUT` of the selected input: no power / no signal / no
//!   horizontal lock) sets [`FrameInfo::signal_lost`];
//! * no frame within `timeout_ms` → `STREAMOFF`, re-queue all, `STREAMON` and
//!   [`CaptureError::Timeout`] (the caller may simply call again);
//! * `ENODEV` from any call (device unplugged, vivid's "Disconnect") → [`CaptureError::DeviceGone`],
//!   fatal, returned again by every later call; dropping the `Capture` is clean.
//!
//! Signal loss is reported, not treated as an error: bttv (and vivid) keep delivering frames
//! (noise) while the input has no signal, so they are delivered with `signal_lost = true` and
//! counted in [`CaptureStats::signal_lost_frames`]; the caller decides whether to track on them.
//!
//! Timestamps are the driver's (`v4l2_buffer.timestamp`, `CLOCK_MONOTONIC` on both bttv and
//! vivid), in microseconds.
//!
//! # Proof against a real driver
//!
//! `cargo xtask vivid` boots Debian's kernel under qemu with the `vivid` driver (input 1
//! `"S-Video 0"`, NTSC) and runs the real `nav-app --device` (statically linked; it reads frames
//! through this crate and tracks lanes on each) through: 60 frames of
//! 320×240 in each of GREY, YUYV, YU12, UYVY, BGR24, RGB565 and BGR32 with sequence numbers in
//! order (vivid may repeat one when its thread wakes twice in a frame period), increasing
//! timestamps and mean grey levels consistent with GREY's; PAL; input by index;
//! an unknown input name (typed error); vivid's "Inject V4L2_BUF_FLAG_ERROR" (frames dropped and
//! counted), "Percentage of Dropped Buffers" (sequence gaps counted), "Standard Signal Mode" =
//! No Signal (frames flagged, then restored), 100 % dropped (timeout, restart, recovery) and
//! "Disconnect" (`ENODEV`: clean exit, no panic).
//!
//! # Units
//!
//! Sizes in pixels (`width_px`, `height_px`), row pitch in bytes (`stride_bytes`), timeouts in
//! milliseconds, timestamps in microseconds.
//!
//! # Features
//!
//! `v4l` (default): the device layer ([`Capture`]). The `v4l` crate generates its bindings with
//! bindgen at build time, which needs libclang (Debian `libclang-dev`). Without the feature only
//! the configuration and the [`convert`] module build, with no native dependency.
//!
//! # Example
//!
//! Converting a driver buffer by hand (what `next_frame` does internally):
//!
//! ```
//! use bt848_capture::{convert, CaptureConfig, PixelFormat};
//!
//! let cfg = CaptureConfig::default(); // NTSC-M, 320×240, 4 buffers
//! cfg.validate()?;
//! // A 2×1 BGR24 frame: pure red, then pure white.
//! let src = [0, 0, 255, 255, 255, 255];
//! let mut grey = [0u8; 2];
//! convert::to_grey(PixelFormat::Bgr24, &src, 2, 1, 6, &mut grey)?;
//! assert_eq!(grey, [76, 255]); // 0.299·255 = 76.2
//! # Ok::<(), bt848_capture::CaptureError>(())
//! ```
//!
//! Streaming from the card (needs the device, so not run here):
//!
//! ```no_run
//! # #[cfg(feature = "v4l")] {
//! use bt848_capture::{Capture, CaptureConfig, GreyFrame, InputSelect};
//!
//! let cfg = CaptureConfig { input: InputSelect::Name("Composite0".into()), ..Default::default() };
//! let mut cap = Capture::open("/dev/video0", &cfg)?;
//! let mut frame = GreyFrame::new(cap.width_px() as usize, cap.height_px() as usize);
//! let info = cap.next_grey_frame(&mut frame)?;
//! println!("seq {} at {} µs, signal lost: {}", info.sequence, info.timestamp_us, info.signal_lost);
//! # }
//! # Ok::<(), bt848_capture::CaptureError>(())
//! ```

pub mod config;
pub mod convert;
mod error;
mod stats;

#[cfg(feature = "v4l")]
mod capture;
#[cfg(feature = "v4l")]
mod raw;

pub use config::{CaptureConfig, InputSelect, VideoStd, parse_size};
pub use convert::PixelFormat;
pub use error::CaptureError;
pub use stats::CaptureStats;

#[cfg(feature = "v4l")]
pub use capture::{Capture, FrameInfo, GreyFrame, list_inputs, set_control};
#[cfg(feature = "v4l")]
pub use raw::{InputInfo, StandardInfo};
