//! The crate's one error type.

use std::io;

/// Everything that can go wrong around the tracker: opening and reading frames, loading a
/// configuration or camera file, tracking, and writing overlays.
///
/// Each variant names the file, the frame or the field concerned. [`LaneIoError::is_fatal`] tells a
/// frame loop whether to stop (fatal) or to report, count and skip one bad frame.
#[derive(Debug, thiserror::Error)]
pub enum LaneIoError {
    /// A file or stream could not be opened or read.
    #[error("{path}")]
    Io {
        /// File, directory or stream (`stdin`) concerned.
        path: String,
        /// The operating-system error.
        #[source]
        source: io::Error,
    },
    /// ffmpeg, needed to decode a video file, could not be started.
    #[error(
        "{input}: cannot start `{program}` to decode this video; install ffmpeg (Debian: apt-get install ffmpeg), set ITA_NAV_FFMPEG to its path, or convert the video to .y4m"
    )]
    FfmpegMissing {
        /// The video file.
        input: String,
        /// The program tried.
        program: String,
        /// Why it could not be started.
        #[source]
        source: io::Error,
    },
    /// ffmpeg could not decode a video file, or stopped part-way.
    #[error("{input}: ffmpeg cannot decode it: {reason}")]
    VideoDecode {
        /// The video file.
        input: String,
        /// ffmpeg's exit status and last message.
        reason: String,
        /// What the reader of ffmpeg's output found wrong with it, when that is where it failed
        /// (no stream header: ffmpeg wrote nothing, or something the reader refuses).
        #[source]
        source: Option<Box<LaneIoError>>,
    },
    /// A ROS 2 bag (MCAP) could not be read: the file, the container, or the topic (the error
    /// lists the bag's topics).
    #[error(transparent)]
    Bag {
        /// The bag reader's error.
        #[from]
        source: ros_bag::BagError,
    },
    /// An image message of a bag cannot be turned into a grey frame.
    #[error("topic {topic}")]
    BagImage {
        /// The topic.
        topic: String,
        /// What is wrong with the message.
        #[source]
        problem: BagImageProblem,
    },
    /// A still image could not be decoded (truncated, corrupt or of an unknown format).
    #[error("{path}: cannot decode image")]
    ImageDecode {
        /// The image file.
        path: String,
        /// What the decoder said.
        #[source]
        source: image::ImageError,
    },
    /// A directory given as a sequence holds a file that is not an image (by its extension).
    #[error(
        "{path}: not an image (expected .png, .jpg, .jpeg, .pgm, .pnm or .ppm) in an image directory"
    )]
    NotAnImage {
        /// The offending file.
        path: String,
    },
    /// A directory given as a sequence holds no image at all.
    #[error("{path}: directory holds no images")]
    EmptyDirectory {
        /// The directory.
        path: String,
    },
    /// An image or stream declares a zero width or height.
    #[error("{name}: zero-size frame ({width}×{height})")]
    ZeroSize {
        /// File or stream concerned.
        name: String,
        /// Declared width, px.
        width: usize,
        /// Declared height, px.
        height: usize,
    },
    /// A frame buffer could not take the size a source asked for (its `width × height` overflows,
    /// or a buffer of the wrong length).
    #[error("{name}")]
    FrameBuffer {
        /// File, stream or device concerned.
        name: String,
        /// What the frame type refused.
        #[source]
        source: grey_frame::FrameError,
    },
    /// A YUV4MPEG2 stream header is malformed.
    #[error("{name}: bad YUV4MPEG2 header: {reason}")]
    Y4mHeader {
        /// File or `stdin`.
        name: String,
        /// What is wrong with it.
        reason: String,
    },
    /// A YUV4MPEG2 stream uses a chroma layout this reader does not take.
    #[error(
        "{name}: unsupported YUV4MPEG2 chroma `C{chroma}` (supported: mono, 420, 420jpeg, 420paldv, 420mpeg2)"
    )]
    UnsupportedChroma {
        /// File or `stdin`.
        name: String,
        /// The `C` tag as found.
        chroma: String,
    },
    /// A YUV4MPEG2 stream was damaged where a `FRAME` header was expected: the reader skipped
    /// `skipped_bytes` bytes to the next `FRAME` marker (or to the end of the stream), losing
    /// `lost_frames` frames (see [`crate::y4m::Y4mSource`] for how they are counted). Not fatal:
    /// reported, counted, and the next `next_frame` delivers the frame after the marker.
    #[error(
        "{name}: frame {frame}: damaged stream, skipped {skipped_bytes} bytes ({lost_frames} \
         frames lost) to {}",
        if *end_of_stream { "the end of the stream" } else { "the next `FRAME` marker" }
    )]
    Y4mResync {
        /// File or `stdin`.
        name: String,
        /// Zero-based index of the first frame lost.
        frame: u64,
        /// Frames lost (not delivered).
        lost_frames: u64,
        /// Bytes skipped before the marker.
        skipped_bytes: u64,
        /// The scan reached the end of the stream instead of a marker.
        end_of_stream: bool,
    },
    /// The stream changed frame size in the middle (a second YUV4MPEG2 header with another size).
    #[error(
        "{name}: frame {frame}: frame size changed mid-stream from {from_w}×{from_h} to {to_w}×{to_h}"
    )]
    SizeChanged {
        /// File or `stdin`.
        name: String,
        /// Zero-based index of the first frame with the new size.
        frame: u64,
        /// Previous width, px.
        from_w: usize,
        /// Previous height, px.
        from_h: usize,
        /// New width, px.
        to_w: usize,
        /// New height, px.
        to_h: usize,
    },
    /// The last frame of a stream is shorter than the header says (not fatal: reported, counted and
    /// the stream ends there; one frame lost).
    #[error("{name}: frame {frame}: short frame, {got} of {expected} bytes before end of stream")]
    ShortFrame {
        /// File or `stdin`.
        name: String,
        /// Zero-based index of the short frame.
        frame: u64,
        /// Bytes a whole frame takes.
        expected: usize,
        /// Bytes present.
        got: usize,
    },
    /// One frame of a sequence is unusable (unreadable, corrupt, zero size). Not fatal: it is
    /// reported, counted and skipped; `source` is what reading it gave (it names the file, or
    /// the bag's topic).
    #[error("frame {frame}: skipped")]
    BadFrame {
        /// File of the frame.
        name: String,
        /// Zero-based index of the frame in the sequence.
        frame: u64,
        /// Why it is unusable: the error reading or decoding it gave.
        source: Box<LaneIoError>,
    },
    /// One frame of an image directory has another size than the sequence's first frame. Not
    /// fatal: it is reported, counted and skipped.
    #[error(
        "{name}: frame {frame}: skipped: frame size {got_w}×{got_h} differs from the sequence's \
         {want_w}×{want_h}"
    )]
    FrameSizeDiffers {
        /// File of the frame.
        name: String,
        /// Zero-based index of the frame in the sequence.
        frame: u64,
        /// Its width, px.
        got_w: usize,
        /// Its height, px.
        got_h: usize,
        /// The sequence's width, px.
        want_w: usize,
        /// The sequence's height, px.
        want_h: usize,
    },
    /// Live capture was requested but this build has none.
    #[error(
        "{device}: live capture is not available in this build (nav-app was built without its \
         `capture` feature; rebuild with `--features capture`, which needs libclang); use --input \
         with an image, a directory of images or a .y4m file"
    )]
    CaptureUnavailable {
        /// The device path asked for.
        device: String,
    },
    /// The capture device could not be opened or configured, or failed while streaming (bad
    /// device node, unknown input, unsupported standard or format, ioctl failure). Fatal.
    #[error("{device}")]
    Capture {
        /// The device path.
        device: String,
        /// What the capture layer reported (typed: match on it to tell an unknown input from a
        /// missing format, etc.).
        #[source]
        error: bt848_capture::CaptureError,
    },
    /// No frame arrived within the capture timeout; the stream has been restarted. Not fatal
    /// while `consecutive < limit` (the frame loop reports it and asks again); the
    /// `limit`-th timeout in a row is fatal.
    #[error(
        "{device}: no frame within {timeout_ms} ms (timeout {consecutive} of at most {limit} in a \
         row; stream restarted: {restarted})"
    )]
    CaptureTimeout {
        /// The device path.
        device: String,
        /// The timeout, ms.
        timeout_ms: u32,
        /// Timeouts in a row, this one included.
        consecutive: u32,
        /// Timeouts in a row that end the run.
        limit: u32,
        /// Whether the stream restart after the timeout succeeded.
        restarted: bool,
    },
    /// The capture device went away (`ENODEV`: unplugged, driver unbound). Fatal.
    #[error("{device}: capture device is gone (ENODEV)")]
    DeviceGone {
        /// The device path.
        device: String,
    },
    /// A capture option holds a value outside its valid range.
    #[error("configuration field `{field}` = {value}: {reason}")]
    ConfigField {
        /// Dotted field name, e.g. `track.window_half_width_px`.
        field: &'static str,
        /// The value found.
        value: String,
        /// The valid range.
        reason: String,
    },
    /// Writing an overlay or a report failed.
    #[error("{path}: cannot write")]
    Write {
        /// Output path.
        path: String,
        /// The operating-system error.
        #[source]
        source: io::Error,
    },
    /// Encoding and writing an image (a PNG overlay) failed.
    #[error("{path}: cannot write image")]
    WriteImage {
        /// Output path.
        path: String,
        /// What the encoder said.
        #[source]
        source: image::ImageError,
    },
    /// A Foxglove message of the lane channels could not be encoded as JSON.
    #[error("topic {topic}: cannot encode the message as JSON")]
    Encode {
        /// The channel's topic.
        topic: &'static str,
        /// The encoder's error.
        #[source]
        source: serde_json::Error,
    },
    /// The tracker, its configuration or the camera model refused (crate `lane-tracker`; a
    /// configuration text out of range names its file, line and column).
    #[error(transparent)]
    Tracker(#[from] lane_tracker::TrackerError),
}

impl LaneIoError {
    /// `false` for errors that concern frames of a stream ([`LaneIoError::BadFrame`],
    /// [`LaneIoError::ShortFrame`], [`LaneIoError::Y4mResync`]) and for a capture timeout that is not yet the `limit`-th in a row
    /// ([`LaneIoError::CaptureTimeout`]): the caller reports and counts it and asks for the next frame.
    /// `true` for everything else: the run cannot go on.
    pub fn is_fatal(&self) -> bool {
        match self {
            LaneIoError::BadFrame { .. }
            | LaneIoError::FrameSizeDiffers { .. }
            | LaneIoError::ShortFrame { .. }
            | LaneIoError::Y4mResync { .. } => false,
            LaneIoError::CaptureTimeout {
                consecutive, limit, ..
            } => consecutive >= limit,
            _ => true,
        }
    }

    /// Frames of the input this error stands for, lost (not delivered): 1 for
    /// [`LaneIoError::BadFrame`], [`LaneIoError::FrameSizeDiffers`] and [`LaneIoError::ShortFrame`], `lost_frames` for
    /// [`LaneIoError::Y4mResync`], 0 for everything else.
    pub fn lost_frames(&self) -> u64 {
        match self {
            LaneIoError::BadFrame { .. }
            | LaneIoError::FrameSizeDiffers { .. }
            | LaneIoError::ShortFrame { .. } => 1,
            LaneIoError::Y4mResync { lost_frames, .. } => *lost_frames,
            _ => 0,
        }
    }

    /// Bytes of a stream this error skipped: `skipped_bytes` of [`LaneIoError::Y4mResync`], the
    /// bytes present of a [`LaneIoError::ShortFrame`]; 0 for everything else.
    pub fn skipped_bytes(&self) -> u64 {
        match self {
            LaneIoError::Y4mResync { skipped_bytes, .. } => *skipped_bytes,
            LaneIoError::ShortFrame { got, .. } => *got as u64,
            _ => 0,
        }
    }

    pub(crate) fn io(path: impl Into<String>, source: io::Error) -> Self {
        LaneIoError::Io {
            path: path.into(),
            source,
        }
    }
}

/// Why one image message of a bag cannot become a grey frame.
#[derive(Debug, thiserror::Error)]
pub enum BagImageProblem {
    /// The CDR payload does not decode as the topic's message type.
    #[error(transparent)]
    Message(#[from] ros_bag::BagError),
    /// An uncompressed image in a pixel encoding the source does not convert.
    #[error("pixel encoding `{encoding}` is not mono8, mono16, rgb8, bgr8, rgba8 or bgra8")]
    PixelEncoding {
        /// The message's `encoding`.
        encoding: String,
    },
    /// An image with no pixels.
    #[error("zero-size image {width_px}×{height_px}")]
    ZeroSize {
        /// Columns.
        width_px: usize,
        /// Rows.
        height_px: usize,
    },
    /// Fewer data bytes than the size, encoding and step declare.
    #[error("{len} bytes of data for {width_px}×{height_px} {encoding} with step {step} bytes")]
    ShortData {
        /// Bytes present.
        len: usize,
        /// Columns.
        width_px: usize,
        /// Rows.
        height_px: usize,
        /// Pixel encoding.
        encoding: String,
        /// Bytes per row declared.
        step: usize,
    },
    /// A compressed image in a format other than JPEG or PNG.
    #[error("compressed format `{format}` is not jpeg or png")]
    CompressedFormat {
        /// The message's `format`.
        format: String,
    },
    /// The JPEG or PNG does not decode.
    #[error("cannot decode the compressed image")]
    Decode(#[source] image::ImageError),
    /// The frame buffer cannot take the image's size.
    #[error("frame buffer")]
    FrameBuffer(#[source] grey_frame::FrameError),
}
