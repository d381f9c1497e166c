//! The crate's one error type.

use crate::PixelFormat;

/// Everything that can go wrong configuring, opening, streaming or converting.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum CaptureError {
    /// A configuration field is out of range or malformed.
    #[error("capture config field `{field}`: {reason}")]
    Config {
        /// The offending field (`"buffers"`, `"std"`, `"size"`…).
        field: &'static str,
        /// What is wrong with it.
        reason: String,
    },
    /// The caller's grey buffer does not hold exactly one frame.
    #[error("grey output buffer holds {got} bytes, a {width}x{height} frame needs {expected}")]
    OutputSize {
        /// `width·height`.
        expected: usize,
        /// The buffer's length.
        got: usize,
        /// Frame width, pixels.
        width: u32,
        /// Frame height, pixels.
        height: u32,
    },
    /// Rows of `stride_bytes` cannot hold `width` pixels of `format`.
    #[error(
        "{format}: stride {stride_bytes} B is shorter than a row of {width} px ({row_bytes} B)"
    )]
    StrideTooSmall {
        /// Source pixel format.
        format: PixelFormat,
        /// Frame width, pixels.
        width: u32,
        /// Row pitch given, bytes.
        stride_bytes: usize,
        /// Bytes one row needs.
        row_bytes: usize,
    },
    /// The source buffer (a driver buffer's `bytesused`) is shorter than the frame.
    #[error(
        "{format}: a {width}x{height} frame with stride {stride_bytes} B needs {needed} B, buffer has {got} B"
    )]
    SourceTooShort {
        /// Source pixel format.
        format: PixelFormat,
        /// Frame width, pixels.
        width: u32,
        /// Frame height, pixels.
        height: u32,
        /// Row pitch, bytes.
        stride_bytes: usize,
        /// Bytes the conversion reads.
        needed: usize,
        /// Bytes available.
        got: usize,
    },
    /// The device node could not be opened.
    #[error("cannot open {path}")]
    Open {
        /// Device path.
        path: String,
        /// The OS error.
        source: std::io::Error,
    },
    /// The device is not a video-capture device with streaming I/O.
    #[error(
        "{path}: driver {driver:?} card {card:?} lacks {missing} (device capabilities {caps:#010x})"
    )]
    NotCaptureDevice {
        /// Device path.
        path: String,
        /// `v4l2_capability.driver`.
        driver: String,
        /// `v4l2_capability.card`.
        card: String,
        /// The capability that is missing: `"video capture"` or `"streaming I/O"`.
        missing: &'static str,
        /// The capability bits examined.
        caps: u32,
    },
    /// An ioctl (or poll/mmap) failed with an unexpected error.
    #[error("{op} failed")]
    Ioctl {
        /// The operation (`"VIDIOC_S_FMT"`, `"mmap buffer 2"`…).
        op: &'static str,
        /// The OS error.
        source: std::io::Error,
    },
    /// No input has the requested name.
    #[error("no input named {name:?}; the device has {available:?}")]
    InputNotFound {
        /// The requested name.
        name: String,
        /// The inputs' names, by index.
        available: Vec<String>,
    },
    /// The requested input index does not exist.
    #[error("input index {index} out of range: the device has {count} inputs")]
    InputIndexOutOfRange {
        /// Requested index.
        index: u32,
        /// Number of inputs.
        count: u32,
    },
    /// The selected input does not support the requested standard.
    #[error(
        "input {input:?} does not support standard {std} (its standards mask is {supported:#x})"
    )]
    StdUnsupported {
        /// Input name.
        input: String,
        /// Requested standard.
        std: crate::VideoStd,
        /// The input's `v4l2_input.std`.
        supported: u64,
    },
    /// The driver accepts none of the convertible pixel formats asked for.
    #[error(
        "driver offers none of the wanted formats {wanted:?} at the requested size; it returned {returned:?}"
    )]
    NoSupportedFormat {
        /// The formats tried, as fourccs.
        wanted: Vec<String>,
        /// The fourccs the driver substituted, in order of the attempts.
        returned: Vec<String>,
    },
    /// The driver granted fewer mmap buffers than the minimum.
    #[error("driver granted {granted} mmap buffers, at least {min} are needed")]
    TooFewBuffers {
        /// Buffers granted.
        granted: u32,
        /// Minimum required.
        min: u32,
    },
    /// The driver returned a buffer index outside the mapped ring.
    #[error("driver returned buffer index {index}, only {count} are mapped")]
    BadBufferIndex {
        /// Index returned by `VIDIOC_DQBUF`.
        index: u32,
        /// Buffers mapped.
        count: usize,
    },
    /// No frame arrived within the timeout. The stream has been restarted (when `restarted`);
    /// calling `next_frame` again continues.
    #[error("no frame within {timeout_ms} ms (stream restarted: {restarted})")]
    Timeout {
        /// The timeout, milliseconds.
        timeout_ms: u32,
        /// Whether the stream restart succeeded.
        restarted: bool,
    },
    /// The device disappeared (`ENODEV`: unplugged, driver unbound, vivid "Disconnect").
    /// Fatal: every later call returns this again.
    #[error("device {path} is gone (ENODEV)")]
    DeviceGone {
        /// Device path.
        path: String,
    },
    /// No control has the requested name.
    #[error("no control named {name:?}")]
    ControlNotFound {
        /// Requested control name.
        name: String,
    },
}
