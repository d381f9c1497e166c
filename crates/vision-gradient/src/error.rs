//! The crate's single error type.

use thiserror::Error;

/// Everything that can go wrong in this crate. Every variant carries the numbers that failed.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum GradientError {
    /// The image has zero width or zero height.
    #[error("empty image: width {width_px} px, height {height_px} px (both must be >= 1)")]
    EmptyImage {
        /// Requested width in pixels.
        width_px: usize,
        /// Requested height in pixels.
        height_px: usize,
    },
    /// Width or height does not fit the `u16` pixel coordinates of [`crate::EdgePixel`].
    #[error("image too large: {width_px}x{height_px} px, each side must be <= {max_px} px")]
    ImageTooLarge {
        /// Requested width in pixels.
        width_px: usize,
        /// Requested height in pixels.
        height_px: usize,
        /// Largest allowed side in pixels.
        max_px: usize,
    },
    /// The row stride is smaller than the width.
    #[error("row stride {stride} bytes is smaller than the width {width_px} px")]
    StrideTooSmall {
        /// Requested stride in bytes.
        stride: usize,
        /// Requested width in pixels.
        width_px: usize,
    },
    /// The pixel slice is shorter than `(height - 1) * stride + width`.
    #[error(
        "image data too short: {len} bytes, need {required} for {width_px}x{height_px} px with stride {stride}"
    )]
    DataTooShort {
        /// Length of the given slice in bytes.
        len: usize,
        /// Bytes needed.
        required: usize,
        /// Width in pixels.
        width_px: usize,
        /// Height in pixels.
        height_px: usize,
        /// Row stride in bytes.
        stride: usize,
    },
    /// A region-of-interest mask does not have `width * height` bytes.
    #[error("ROI mask has {len} bytes, expected width*height = {expected}")]
    MaskSizeMismatch {
        /// Length of the given mask.
        len: usize,
        /// `width * height` of the image.
        expected: usize,
    },
    /// A buffer given to a kernel writing into caller-owned buffers ([`crate::resample_rows`],
    /// [`crate::downscale_box`], [`crate::smooth_binomial`]) cannot hold what the call asks for.
    #[error("buffer `{buffer}` has {len} entries, the call needs {required}")]
    BufferTooSmall {
        /// Which buffer, by its parameter's name.
        buffer: &'static str,
        /// Its length, entries.
        len: usize,
        /// Entries needed.
        required: usize,
    },
    /// The class-image output buffer does not have `width * height` bytes.
    #[error("class image buffer has {len} bytes, expected width*height = {expected}")]
    ClassImageSizeMismatch {
        /// Length of the given buffer.
        len: usize,
        /// `width * height` of the image.
        expected: usize,
    },
    /// A row range is empty, reversed or reaches past the image.
    #[error(
        "row range {row_start_px}..{row_end_px} is invalid for an image of height {height_px} px"
    )]
    RowRangeInvalid {
        /// First row (inclusive).
        row_start_px: usize,
        /// Last row (exclusive).
        row_end_px: usize,
        /// Image height in pixels.
        height_px: usize,
    },
    /// The per-row span list does not have one entry per image row.
    #[error("span list has {len} entries, expected one per image row = {expected}")]
    SpansLengthMismatch {
        /// Number of spans given.
        len: usize,
        /// Image height in pixels.
        expected: usize,
    },
    /// A column span is reversed or reaches past the right image border.
    #[error(
        "span of row {row_px} is {col_start_px}..{col_end_px}: need start <= end <= width {width_px} px"
    )]
    SpanOutOfRange {
        /// Row of the offending span.
        row_px: usize,
        /// Span start column (inclusive).
        col_start_px: usize,
        /// Span end column (exclusive).
        col_end_px: usize,
        /// Image width in pixels.
        width_px: usize,
    },
    /// A parameter is out of its documented range.
    #[error("parameter `{field}` = {value} is invalid: {requirement}")]
    InvalidParam {
        /// Name of the field, as spelled in the configuration file.
        field: &'static str,
        /// The rejected value.
        value: f64,
        /// What the field must satisfy.
        requirement: &'static str,
    },
    /// A backend was requested that this CPU or target does not support.
    #[error("backend {backend} is not available on this CPU/target")]
    BackendUnavailable {
        /// Name of the requested backend.
        backend: &'static str,
    },
}
