//! The V4L2 mmap capture stream.

use std::io;
use std::os::raw::c_int;
use std::ptr::NonNull;
use std::time::{Duration, Instant};

use crate::raw::{self, InputInfo, StandardInfo};
use crate::{CaptureConfig, CaptureError, InputSelect, PixelFormat, VideoStd, convert};

/// `v4l2_buffer.flags` bit: the buffer's data may be corrupt (`V4L2_BUF_FLAG_ERROR`).
const BUF_FLAG_ERROR: u32 = v4l::v4l_sys::V4L2_BUF_FLAG_ERROR;

/// What one delivered frame was.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FrameInfo {
    /// Driver's frame sequence number (`v4l2_buffer.sequence`; restarts at 0 after a stream
    /// restart).
    pub sequence: u32,
    /// Driver timestamp (`v4l2_buffer.timestamp`, normally `CLOCK_MONOTONIC`), microseconds.
    pub timestamp_us: i64,
    /// Frame width, pixels.
    pub width: u32,
    /// Frame height, pixels.
    pub height: u32,
    /// The fourcc the driver delivered (before conversion to grey).
    pub pixel_format_fourcc: [u8; 4],
    /// Frames the driver skipped just before this one (sequence gap; 0 normally).
    pub frames_missed_before: u32,
    /// The input reported no power, no signal or no horizontal lock when this frame was taken.
    pub signal_lost: bool,
}

pub use crate::stats::CaptureStats;
pub use grey_frame::GreyFrame;

/// One mmap'd driver buffer.
struct Mapping {
    ptr: NonNull<u8>,
    len: usize,
}

/// An open, streaming V4L2 capture device delivering grey frames.
///
/// Opened with [`Capture::open`]; frames come from [`Capture::next_frame`]. Dropping it stops the
/// stream and unmaps the buffers.
pub struct Capture {
    /// Keeps the descriptor open (closed on drop, after our own `Drop` unmapped the ring).
    _device: v4l::Device,
    fd: c_int,
    path: String,
    ring: Vec<Mapping>,
    format: PixelFormat,
    width: u32,
    height: u32,
    stride_bytes: usize,
    input_index: u32,
    std_id: Option<u64>,
    timeout_ms: u32,
    streaming: bool,
    gone: bool,
    last_sequence: Option<u32>,
    stats: CaptureStats,
}

// SAFETY: the raw pointers in `ring` point into mmap'd regions owned exclusively by this value
// (nothing else holds them), so moving the whole `Capture` to another thread is sound; it is not
// `Sync` because `next_frame` needs `&mut self`.
unsafe impl Send for Capture {}

fn io_err(op: &'static str) -> impl FnOnce(io::Error) -> CaptureError {
    move |source| CaptureError::Ioctl { op, source }
}

impl Capture {
    /// Open `path`, select the input and standard, negotiate the format, map the buffers and start
    /// streaming.
    ///
    /// # Errors
    /// [`CaptureError::Config`] for a bad config; [`CaptureError::Open`];
    /// [`CaptureError::NotCaptureDevice`] without video capture or streaming capability;
    /// [`CaptureError::InputNotFound`] / [`CaptureError::InputIndexOutOfRange`];
    /// [`CaptureError::StdUnsupported`]; [`CaptureError::NoSupportedFormat`];
    /// [`CaptureError::TooFewBuffers`]; [`CaptureError::DeviceGone`]; [`CaptureError::Ioctl`].
    pub fn open(path: &str, config: &CaptureConfig) -> Result<Capture, CaptureError> {
        config.validate()?;
        let device = v4l::Device::with_path(path).map_err(|source| CaptureError::Open {
            path: path.to_owned(),
            source,
        })?;
        let fd = device.handle().fd();
        let gone = |e: io::Error, op: &'static str| gone_or(e, op, path);

        let (driver, card, caps) = raw::query_caps(fd).map_err(|e| gone(e, "VIDIOC_QUERYCAP"))?;
        let not_capture = |missing| CaptureError::NotCaptureDevice {
            path: path.to_owned(),
            driver: driver.clone(),
            card: card.clone(),
            missing,
            caps,
        };
        if caps & v4l::v4l_sys::V4L2_CAP_VIDEO_CAPTURE == 0 {
            return Err(not_capture("video capture"));
        }
        if caps & v4l::v4l_sys::V4L2_CAP_STREAMING == 0 {
            return Err(not_capture("streaming I/O"));
        }

        // Input.
        let inputs = raw::enum_inputs(fd).map_err(|e| gone(e, "VIDIOC_ENUMINPUT"))?;
        let input_index = match &config.input {
            InputSelect::Current => raw::get_input(fd).map_err(|e| gone(e, "VIDIOC_G_INPUT"))?,
            InputSelect::Index(index) => {
                if !inputs.iter().any(|i| i.index == *index) {
                    return Err(CaptureError::InputIndexOutOfRange {
                        index: *index,
                        count: inputs.len() as u32,
                    });
                }
                *index
            }
            InputSelect::Name(name) => {
                find_input_by_name(&inputs, name).ok_or_else(|| CaptureError::InputNotFound {
                    name: name.clone(),
                    available: inputs.iter().map(|i| i.name.clone()).collect(),
                })?
            }
        };
        if !matches!(config.input, InputSelect::Current) {
            raw::set_input(fd, input_index).map_err(|e| gone(e, "VIDIOC_S_INPUT"))?;
        }

        // Standard (only for inputs that have standards).
        let input = inputs.iter().find(|i| i.index == input_index);
        let std_mask = input.map_or(0, |i| i.std_mask);
        let std_id = if std_mask != 0 {
            let wanted = config.std.v4l2_std_id();
            if wanted & std_mask == 0 {
                return Err(CaptureError::StdUnsupported {
                    input: input.map(|i| i.name.clone()).unwrap_or_default(),
                    std: config.std,
                    supported: std_mask,
                });
            }
            raw::set_std(fd, wanted & std_mask).map_err(|e| gone(e, "VIDIOC_S_STD"))?;
            Some(raw::get_std(fd).map_err(|e| gone(e, "VIDIOC_G_STD"))?)
        } else {
            None
        };

        // Format: first preference the driver accepts as is; else the first substitute we can
        // convert. Always use what the driver returns.
        let mut chosen = None;
        let mut substitute = None;
        let mut returned = Vec::new();
        for &want in &config.pixel_formats {
            let got = raw::set_format(fd, config.width_px, config.height_px, want.fourcc_u32())
                .map_err(|e| gone(e, "VIDIOC_S_FMT"))?;
            returned.push(convert::fourcc_string(got.fourcc));
            match PixelFormat::from_fourcc(got.fourcc) {
                Some(f) if f == want => {
                    chosen = Some((f, got));
                    break;
                }
                Some(f) if substitute.is_none() && config.pixel_formats.contains(&f) => {
                    substitute = Some((f, got));
                }
                _ => {}
            }
        }
        let (format, negotiated) = match chosen.or(substitute) {
            Some(pair) => pair,
            None => {
                return Err(CaptureError::NoSupportedFormat {
                    wanted: config.pixel_formats.iter().map(|f| f.to_string()).collect(),
                    returned,
                });
            }
        };
        // If a substitute was chosen the driver's current format may be a later attempt: set it.
        let negotiated = if chosen.is_none() {
            raw::set_format(fd, negotiated.width, negotiated.height, format.fourcc_u32())
                .map_err(|e| gone(e, "VIDIOC_S_FMT"))?
        } else {
            negotiated
        };
        let width = negotiated.width;
        let height = negotiated.height;
        let min_stride = width as usize * format.bytes_per_pixel();
        let stride_bytes = (negotiated.bytes_per_line as usize).max(min_stride);

        let mut capture = Capture {
            _device: device,
            fd,
            path: path.to_owned(),
            ring: Vec::new(),
            format,
            width,
            height,
            stride_bytes,
            input_index,
            std_id,
            timeout_ms: config.timeout_ms,
            streaming: false,
            gone: false,
            last_sequence: None,
            stats: CaptureStats::default(),
        };
        capture.map_buffers(config.buffers)?;
        capture.start()?;
        Ok(capture)
    }

    fn gone(&mut self, e: io::Error, op: &'static str) -> CaptureError {
        let err = gone_or(e, op, &self.path);
        if matches!(err, CaptureError::DeviceGone { .. }) {
            self.gone = true;
        }
        err
    }

    fn map_buffers(&mut self, count: u32) -> Result<(), CaptureError> {
        let granted =
            raw::request_buffers(self.fd, count).map_err(|e| self.gone(e, "VIDIOC_REQBUFS"))?;
        if granted < crate::config::MIN_BUFFERS {
            return Err(CaptureError::TooFewBuffers {
                granted,
                min: crate::config::MIN_BUFFERS,
            });
        }
        for index in 0..granted {
            let (offset, len) =
                raw::query_buffer(self.fd, index).map_err(|e| self.gone(e, "VIDIOC_QUERYBUF"))?;
            // SAFETY: mapping a driver buffer: null hint, the length and offset VIDIOC_QUERYBUF
            // returned for this fd, shared read/write as V4L2 mmap streaming requires.
            let ptr = unsafe {
                v4l::v4l2::mmap(
                    std::ptr::null_mut(),
                    len,
                    libc::PROT_READ | libc::PROT_WRITE,
                    libc::MAP_SHARED,
                    self.fd,
                    libc::off_t::from(offset),
                )
            }
            .map_err(|e| self.gone(e, "mmap"))?;
            let ptr = NonNull::new(ptr.cast::<u8>())
                .ok_or_else(|| io_err("mmap")(io::Error::other("mmap returned null")))?;
            self.ring.push(Mapping { ptr, len });
        }
        Ok(())
    }

    /// Queue every buffer and STREAMON.
    fn start(&mut self) -> Result<(), CaptureError> {
        for index in 0..self.ring.len() as u32 {
            raw::queue_buffer(self.fd, index).map_err(|e| self.gone(e, "VIDIOC_QBUF"))?;
        }
        raw::stream(self.fd, true).map_err(|e| self.gone(e, "VIDIOC_STREAMON"))?;
        self.streaming = true;
        self.last_sequence = None;
        Ok(())
    }

    /// STREAMOFF (which returns every buffer to us), then queue all and STREAMON again.
    ///
    /// # Errors
    /// [`CaptureError::DeviceGone`] or [`CaptureError::Ioctl`].
    pub fn restart(&mut self) -> Result<(), CaptureError> {
        if self.gone {
            return Err(CaptureError::DeviceGone {
                path: self.path.clone(),
            });
        }
        raw::stream(self.fd, false).map_err(|e| self.gone(e, "VIDIOC_STREAMOFF"))?;
        self.streaming = false;
        self.stats.restarts += 1;
        self.start()
    }

    /// Wait for the next good frame and write it as grey into `dst_grey` (`width·height` bytes).
    ///
    /// Buffers flagged `V4L2_BUF_FLAG_ERROR` (or shorter than a frame) are re-queued, counted in
    /// [`CaptureStats::errored_dropped`] and skipped; sequence gaps are counted. No allocation.
    ///
    /// # Errors
    /// [`CaptureError::OutputSize`] if `dst_grey` has the wrong length;
    /// [`CaptureError::Timeout`] when no good frame arrives within `timeout_ms` (the stream is
    /// restarted; call again to continue); [`CaptureError::DeviceGone`] on `ENODEV` (fatal);
    /// [`CaptureError::Ioctl`] for other driver errors.
    pub fn next_frame(&mut self, dst_grey: &mut [u8]) -> Result<FrameInfo, CaptureError> {
        if self.gone {
            return Err(CaptureError::DeviceGone {
                path: self.path.clone(),
            });
        }
        let expected = self.width as usize * self.height as usize;
        if dst_grey.len() != expected {
            return Err(CaptureError::OutputSize {
                expected,
                got: dst_grey.len(),
                width: self.width,
                height: self.height,
            });
        }
        if !self.streaming {
            self.start()?;
        }
        let deadline = Instant::now() + Duration::from_millis(u64::from(self.timeout_ms));
        loop {
            let remaining = deadline.saturating_duration_since(Instant::now());
            let ready = !remaining.is_zero()
                && raw::poll_readable(self.fd, remaining.as_millis().min(60_000) as c_int)
                    .map_err(|e| self.gone(e, "poll"))?;
            if !ready {
                self.stats.timeouts += 1;
                let restarted = match self.restart() {
                    Ok(()) => true,
                    Err(e @ CaptureError::DeviceGone { .. }) => return Err(e),
                    Err(_) => false,
                };
                return Err(CaptureError::Timeout {
                    timeout_ms: self.timeout_ms,
                    restarted,
                });
            }
            let buf = match raw::dequeue_buffer(self.fd) {
                Ok(buf) => buf,
                Err(e) if e.kind() == io::ErrorKind::WouldBlock => continue,
                Err(e) => return Err(self.gone(e, "VIDIOC_DQBUF")),
            };
            let index = buf.index;
            let Some(mapping) = self.ring.get(index as usize) else {
                return Err(CaptureError::BadBufferIndex {
                    index,
                    count: self.ring.len(),
                });
            };

            let missed = match self.last_sequence {
                // A gap larger than 2^31 is a wrap or a driver reset, not a real gap.
                Some(last) => match buf.sequence.wrapping_sub(last).wrapping_sub(1) {
                    g if g < 1 << 31 => g,
                    _ => 0,
                },
                None => 0,
            };
            self.last_sequence = Some(buf.sequence);
            self.stats.sequence_gaps += u64::from(missed);

            let used = (buf.bytesused as usize).min(mapping.len);
            // SAFETY: `mapping` is a live MAP_SHARED mapping of `mapping.len` bytes of this
            // buffer, just dequeued, so the driver is not writing it until we re-queue it below;
            // `used ≤ mapping.len`.
            let data = unsafe { std::slice::from_raw_parts(mapping.ptr.as_ptr(), used) };
            let converted = if buf.flags & BUF_FLAG_ERROR != 0 {
                None
            } else {
                convert::to_grey(
                    self.format,
                    data,
                    self.width,
                    self.height,
                    self.stride_bytes,
                    dst_grey,
                )
                .ok()
            };
            raw::queue_buffer(self.fd, index).map_err(|e| self.gone(e, "VIDIOC_QBUF"))?;
            if converted.is_none() {
                self.stats.errored_dropped += 1;
                continue;
            }

            let signal_lost = match raw::enum_input(self.fd, self.input_index) {
                Ok(Some(info)) => info.signal_lost(),
                Ok(None) => false,
                Err(e) => return Err(self.gone(e, "VIDIOC_ENUMINPUT")),
            };
            self.stats.frames += 1;
            if signal_lost {
                self.stats.signal_lost_frames += 1;
            }
            let ts = buf.timestamp;
            return Ok(FrameInfo {
                sequence: buf.sequence,
                timestamp_us: timeval_us(ts.tv_sec, ts.tv_usec),
                width: self.width,
                height: self.height,
                pixel_format_fourcc: self.format.fourcc(),
                frames_missed_before: missed,
                signal_lost,
            });
        }
    }

    /// [`Capture::next_frame`] into a [`GreyFrame`] of this capture's size.
    ///
    /// # Errors
    /// As [`Capture::next_frame`]; [`CaptureError::OutputSize`] if `frame`'s size differs.
    pub fn next_grey_frame(&mut self, frame: &mut GreyFrame) -> Result<FrameInfo, CaptureError> {
        let (w, h) = (self.width as usize, self.height as usize);
        if (frame.width(), frame.height()) != (w, h) {
            return Err(CaptureError::OutputSize {
                expected: w * h,
                got: frame.data().len(),
                width: self.width,
                height: self.height,
            });
        }
        self.next_frame(frame.data_mut())
    }

    /// Counters since open.
    pub fn stats(&self) -> CaptureStats {
        self.stats
    }

    /// Frame width the driver delivers, pixels.
    pub fn width_px(&self) -> u32 {
        self.width
    }

    /// Frame height the driver delivers, pixels.
    pub fn height_px(&self) -> u32 {
        self.height
    }

    /// The pixel format the driver delivers (converted to grey by `next_frame`).
    pub fn pixel_format(&self) -> PixelFormat {
        self.format
    }

    /// Row pitch of the driver's buffers, bytes.
    pub fn stride_bytes(&self) -> usize {
        self.stride_bytes
    }

    /// Number of mmap buffers in the ring.
    pub fn buffer_count(&self) -> usize {
        self.ring.len()
    }

    /// The selected input's index.
    pub fn input_index(&self) -> u32 {
        self.input_index
    }

    /// The standard the driver reports as set (`VIDIOC_G_STD` after `S_STD`); `None` for inputs
    /// without standards.
    pub fn std_id(&self) -> Option<u64> {
        self.std_id
    }

    /// Whether the device has gone away (`ENODEV` seen).
    pub fn is_gone(&self) -> bool {
        self.gone
    }

    /// All inputs of the device (`VIDIOC_ENUMINPUT`); `status` is meaningful for the current one.
    ///
    /// # Errors
    /// [`CaptureError::DeviceGone`] or [`CaptureError::Ioctl`].
    pub fn inputs(&mut self) -> Result<Vec<InputInfo>, CaptureError> {
        raw::enum_inputs(self.fd).map_err(|e| self.gone(e, "VIDIOC_ENUMINPUT"))
    }

    /// The standards the current input supports (`VIDIOC_ENUMSTD`).
    ///
    /// # Errors
    /// [`CaptureError::DeviceGone`] or [`CaptureError::Ioctl`].
    pub fn standards(&mut self) -> Result<Vec<StandardInfo>, CaptureError> {
        raw::enum_stds(self.fd).map_err(|e| self.gone(e, "VIDIOC_ENUMSTD"))
    }

    /// The standards the hardware detects now (`VIDIOC_QUERYSTD`); 0 means no signal.
    ///
    /// # Errors
    /// [`CaptureError::DeviceGone`] or [`CaptureError::Ioctl`] (e.g. `ENODATA` where the input
    /// cannot detect standards).
    pub fn query_std(&mut self) -> Result<u64, CaptureError> {
        raw::query_std(self.fd).map_err(|e| self.gone(e, "VIDIOC_QUERYSTD"))
    }

    /// Whether the selected input reports signal loss now (no power / no signal / no H lock).
    ///
    /// # Errors
    /// [`CaptureError::DeviceGone`] or [`CaptureError::Ioctl`].
    pub fn signal_lost(&mut self) -> Result<bool, CaptureError> {
        match raw::enum_input(self.fd, self.input_index) {
            Ok(info) => Ok(info.is_some_and(|i| i.signal_lost())),
            Err(e) => Err(self.gone(e, "VIDIOC_ENUMINPUT")),
        }
    }

    /// Set a control by its driver name (ASCII case-insensitive), e.g. bttv's `"Brightness"` or
    /// vivid's `"Disconnect"`; button controls ignore `value`.
    ///
    /// # Errors
    /// [`CaptureError::ControlNotFound`], [`CaptureError::DeviceGone`] or
    /// [`CaptureError::Ioctl`].
    pub fn set_control(&mut self, name: &str, value: i32) -> Result<(), CaptureError> {
        let id = raw::find_control(self.fd, name)
            .map_err(|e| self.gone(e, "VIDIOC_QUERYCTRL"))?
            .ok_or_else(|| CaptureError::ControlNotFound {
                name: name.to_owned(),
            })?;
        raw::set_control(self.fd, id, value).map_err(|e| self.gone(e, "VIDIOC_S_CTRL"))
    }

    /// The standard `std` resolved against this device: `true` if the input supports it.
    ///
    /// # Errors
    /// [`CaptureError::DeviceGone`] or [`CaptureError::Ioctl`].
    pub fn supports_std(&mut self, std: VideoStd) -> Result<bool, CaptureError> {
        let input = raw::enum_input(self.fd, self.input_index)
            .map_err(|e| self.gone(e, "VIDIOC_ENUMINPUT"))?;
        Ok(input.is_some_and(|i| i.std_mask & std.v4l2_std_id() != 0))
    }
}

impl Drop for Capture {
    fn drop(&mut self) {
        // Errors are ignored: after ENODEV these fail, and there is nobody to report to.
        if self.streaming && !self.gone {
            let _ = raw::stream(self.fd, false);
        }
        for m in self.ring.drain(..) {
            // SAFETY: `m` is a mapping this value created with exactly this pointer and length
            // and never handed out beyond a `next_frame` call.
            let _ = unsafe { v4l::v4l2::munmap(m.ptr.as_ptr().cast(), m.len) };
        }
        if !self.gone {
            let _ = raw::request_buffers(self.fd, 0);
        }
    }
}

/// A `struct timeval` in microseconds (`time_t`/`suseconds_t` are `i64` on x86-64, narrower on
/// some 32-bit targets, hence the conversions).
#[allow(clippy::useless_conversion)]
fn timeval_us(tv_sec: libc::time_t, tv_usec: libc::suseconds_t) -> i64 {
    i64::from(tv_sec) * 1_000_000 + i64::from(tv_usec)
}

/// The index of the input called `name`: an exact (ASCII case-insensitive) match, else the only
/// input whose name is `name` followed by a space and a suffix (vivid calls its inputs
/// `"S-Video 0"`, `"TV 0"`; bttv's `"Composite0"` needs the exact name).
fn find_input_by_name(inputs: &[InputInfo], name: &str) -> Option<u32> {
    let name = name.trim();
    if let Some(exact) = inputs.iter().find(|i| i.name.eq_ignore_ascii_case(name)) {
        return Some(exact.index);
    }
    let mut prefixed = inputs.iter().filter(|i| {
        i.name.len() > name.len()
            && i.name.is_char_boundary(name.len())
            && i.name[..name.len()].eq_ignore_ascii_case(name)
            && i.name[name.len()..].starts_with(' ')
    });
    match (prefixed.next(), prefixed.next()) {
        (Some(only), None) => Some(only.index),
        _ => None,
    }
}

/// `ENODEV` → [`CaptureError::DeviceGone`], anything else → [`CaptureError::Ioctl`].
fn gone_or(e: io::Error, op: &'static str, path: &str) -> CaptureError {
    if e.raw_os_error() == Some(libc::ENODEV) {
        CaptureError::DeviceGone {
            path: path.to_owned(),
        }
    } else {
        CaptureError::Ioctl { op, source: e }
    }
}

/// Set a control by name on a device without streaming from it (opens `path` briefly). Useful
/// for driving vivid's test controls from a second descriptor.
///
/// # Errors
/// [`CaptureError::Open`], [`CaptureError::ControlNotFound`], [`CaptureError::DeviceGone`],
/// [`CaptureError::Ioctl`].
pub fn set_control(path: &str, name: &str, value: i32) -> Result<(), CaptureError> {
    let device = v4l::Device::with_path(path).map_err(|source| CaptureError::Open {
        path: path.to_owned(),
        source,
    })?;
    let fd = device.handle().fd();
    let id = raw::find_control(fd, name)
        .map_err(|e| gone_or(e, "VIDIOC_QUERYCTRL", path))?
        .ok_or_else(|| CaptureError::ControlNotFound {
            name: name.to_owned(),
        })?;
    raw::set_control(fd, id, value).map_err(|e| gone_or(e, "VIDIOC_S_CTRL", path))
}

/// List a device's inputs without streaming (opens `path` briefly).
///
/// # Errors
/// [`CaptureError::Open`], [`CaptureError::DeviceGone`], [`CaptureError::Ioctl`].
pub fn list_inputs(path: &str) -> Result<Vec<InputInfo>, CaptureError> {
    let device = v4l::Device::with_path(path).map_err(|source| CaptureError::Open {
        path: path.to_owned(),
        source,
    })?;
    raw::enum_inputs(device.handle().fd()).map_err(|e| gone_or(e, "VIDIOC_ENUMINPUT", path))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn input(index: u32, name: &str) -> InputInfo {
        InputInfo {
            index,
            name: name.into(),
            is_tuner: false,
            std_mask: 0xb0ff,
            status: 0,
        }
    }

    #[test]
    fn input_name_matching_exact_then_unique_space_suffix() {
        let bttv = [
            input(0, "Television"),
            input(1, "Composite1"),
            input(2, "S-Video"),
            input(3, "Composite3"),
        ];
        assert_eq!(find_input_by_name(&bttv, "s-video"), Some(2));
        assert_eq!(find_input_by_name(&bttv, "Composite3"), Some(3));
        // "Composite" is a prefix of two names without a space separator: no match.
        assert_eq!(find_input_by_name(&bttv, "Composite"), None);
        let vivid = [input(0, "TV 0"), input(1, "S-Video 0")];
        assert_eq!(find_input_by_name(&vivid, "S-Video"), Some(1));
        assert_eq!(find_input_by_name(&vivid, "TV"), Some(0));
        assert_eq!(find_input_by_name(&vivid, "S-Vid"), None);
        let ambiguous = [input(0, "S-Video 0"), input(1, "S-Video 1")];
        assert_eq!(find_input_by_name(&ambiguous, "S-Video"), None);
        assert_eq!(find_input_by_name(&ambiguous, "S-Video 1"), Some(1));
    }
}
