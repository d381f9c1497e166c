//! Live capture for `--device`: [`CaptureSource`] adapts `bt848_capture::Capture` (V4L2 mmap
//! streaming from a BT848/878 card, `bttv` driver, or any V4L2 capture node) to [`FrameSource`].
//!
//! The device layer is behind the crate feature `capture` (default on; the `v4l` crate it uses
//! needs libclang at build time). Without it [`open`] returns [`LaneIoError::CaptureUnavailable`];
//! the option types, the control-spec parser and the bookkeeping below build either way.
//!
//! # Behaviour
//!
//! * Opening ([`open`], [`CaptureSource::open`]): input by name or index, video standard (NTSC-M
//!   by default), size (320×240 by default) and pixel format are negotiated by bt848-capture;
//!   the size and format *the driver returns* are used. Any failure is [`LaneIoError::Capture`]
//!   (holding the typed capture error: unknown input, unsupported standard or format, not a
//!   capture device…) or [`LaneIoError::DeviceGone`].
//! * Each delivered frame is grey (converted from the driver's format, BT.601 luma), with a
//!   [`FrameMeta`] whose `index` counts the driver's frames (it jumps by the number of frames the
//!   driver dropped, see [`DeviceFrameInfo::missed`]) and whose `t_s` is the driver timestamp
//!   relative to the first frame, s. Per-frame device fields ([`DeviceFrameInfo`]) and running
//!   counters ([`DeviceStats`]) are published through a [`CaptureMonitor`].
//! * Buffers the driver flags `V4L2_BUF_FLAG_ERROR` are dropped and counted, never delivered;
//!   sequence gaps are counted; frames taken while the input reports no signal are delivered
//!   with `signal_lost = true` and counted (the tracker then simply finds no lanes).
//! * No frame within `timeout_ms`: the stream is restarted and [`LaneIoError::CaptureTimeout`] is
//!   returned, *not fatal* while it is not the `max_consecutive_timeouts`-th in a row (the frame
//!   loop reports it and asks again); the last one allowed is fatal.
//! * `ENODEV` (card unplugged, driver unbound, vivid's "Disconnect"): [`LaneIoError::DeviceGone`],
//!   fatal; the source is dropped cleanly.
//!
//! # Test hooks
//!
//! For the real-driver test (`cargo xtask vivid`), [`DeviceOptions::controls_at_frame`] sets a
//! V4L2 control by name once a number of frames has been delivered, and
//! [`DeviceOptions::controls_on_timeout`] sets controls at the first timeout (to end an injected
//! outage). `nav-app` exposes them as hidden flags `--ctrl NAME=VALUE@FRAME` and
//! `--ctrl-on-timeout NAME=VALUE` (spec syntax: [`parse_control_spec`]). A control that cannot be
//! set is a fatal [`LaneIoError::Capture`]; each one set is counted in
//! [`DeviceStats::controls_set`].
//!
//! # Example
//!
//! ```
//! use lane_io::capture_source::{parse_control_spec, DeviceOptions};
//!
//! let mut opts = DeviceOptions::default(); // current input, NTSC-M, 320×240, 3 timeouts in a row
//! opts.controls_at_frame.push(parse_control_spec("Disconnect=1@10")?);
//! assert_eq!(opts.controls_at_frame[0].at_frame, 10);
//! opts.validate()?;
//! # Ok::<(), lane_io::LaneIoError>(())
//! ```

use std::cell::{Cell, RefCell};
use std::path::Path;
use std::rc::Rc;

use bt848_capture::{CaptureConfig, CaptureError, CaptureStats, PixelFormat};
use serde::Serialize;

use crate::{FrameMeta, FrameSource, LaneIoError};

/// A V4L2 control to set by its driver name (test hook), e.g. vivid's `"Disconnect"`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ControlSet {
    /// Control name as the driver reports it (`VIDIOC_QUERYCTRL`), ASCII case-insensitive.
    pub name: String,
    /// Value to set (button controls ignore it).
    pub value: i32,
    /// Set it once this many frames have been delivered (0: before the first frame). Ignored for
    /// [`DeviceOptions::controls_on_timeout`].
    pub at_frame: u64,
}

/// Parse `NAME=VALUE[@FRAME]` (the name may contain spaces and `=`; the last `=` splits).
///
/// # Errors
/// [`LaneIoError::ConfigField`] (field `control`) naming the spec and what is wrong.
pub fn parse_control_spec(spec: &str) -> Result<ControlSet, LaneIoError> {
    let bad = |reason: &str| LaneIoError::ConfigField {
        field: "control",
        value: format!("{spec:?}"),
        reason: format!("{reason} (expected NAME=VALUE or NAME=VALUE@FRAME)"),
    };
    let (name, rest) = spec.rsplit_once('=').ok_or_else(|| bad("no '='"))?;
    let name = name.trim();
    if name.is_empty() {
        return Err(bad("empty control name"));
    }
    let (value, at_frame) = match rest.split_once('@') {
        Some((v, at)) => (
            v,
            at.trim()
                .parse::<u64>()
                .map_err(|_| bad("FRAME is not a non-negative integer"))?,
        ),
        None => (rest, 0),
    };
    let value = value
        .trim()
        .parse::<i32>()
        .map_err(|_| bad("VALUE is not a 32-bit integer"))?;
    Ok(ControlSet {
        name: name.to_owned(),
        value,
        at_frame,
    })
}

/// Everything `--device` needs besides the path.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct DeviceOptions {
    /// Input, standard, size (px), pixel formats, buffers, timeout (ms): see
    /// [`bt848_capture::CaptureConfig`]. Default: current input, NTSC-M, 320×240, every
    /// convertible format (GREY first), 4 buffers, 1000 ms.
    pub capture: CaptureConfig,
    /// Timeouts in a row that end the run (≥ 1; default 3). Each earlier one restarts the stream
    /// and is reported as a non-fatal [`LaneIoError::CaptureTimeout`].
    pub max_consecutive_timeouts: u32,
    /// Test hook: controls set once `at_frame` frames have been delivered.
    pub controls_at_frame: Vec<ControlSet>,
    /// Test hook: controls set at the first timeout.
    pub controls_on_timeout: Vec<ControlSet>,
}

impl Default for DeviceOptions {
    fn default() -> Self {
        Self {
            capture: CaptureConfig::default(),
            max_consecutive_timeouts: 3,
            controls_at_frame: Vec::new(),
            controls_on_timeout: Vec::new(),
        }
    }
}

impl DeviceOptions {
    /// Check every field.
    ///
    /// # Errors
    /// [`LaneIoError::ConfigField`] naming the field (`max_consecutive_timeouts`, or the capture
    /// config's field as `capture.<field>`).
    pub fn validate(&self) -> Result<(), LaneIoError> {
        if self.max_consecutive_timeouts == 0 {
            return Err(LaneIoError::ConfigField {
                field: "max_consecutive_timeouts",
                value: "0".into(),
                reason: "must be at least 1".into(),
            });
        }
        match self.capture.validate() {
            Ok(()) => Ok(()),
            Err(CaptureError::Config { field, reason }) => Err(LaneIoError::ConfigField {
                field: capture_field_name(field),
                value: String::new(),
                reason,
            }),
            Err(e) => Err(LaneIoError::ConfigField {
                field: "capture",
                value: String::new(),
                reason: e.to_string(),
            }),
        }
    }
}

/// `capture.<field>` for the capture config's field names (static strings, as
/// [`LaneIoError::ConfigField`] wants).
fn capture_field_name(field: &str) -> &'static str {
    match field {
        "input" => "capture.input",
        "std" => "capture.std",
        "width_px" => "capture.width_px",
        "height_px" => "capture.height_px",
        "size" => "capture.size",
        "pixel_formats" => "capture.pixel_formats",
        "buffers" => "capture.buffers",
        "timeout_ms" => "capture.timeout_ms",
        _ => "capture",
    }
}

/// The device as opened: what the driver agreed to.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct DeviceSetup {
    /// Device path.
    pub device: String,
    /// Selected input's index (`VIDIOC_G_INPUT`/`S_INPUT`).
    pub input_index: u32,
    /// Standard the driver reports as set (`v4l2_std_id` bits); `None` for inputs without
    /// standards.
    pub std_id: Option<u64>,
    /// Frame width, px.
    pub width_px: u32,
    /// Frame height, px.
    pub height_px: u32,
    /// Pixel format the driver delivers (converted to grey).
    pub format: PixelFormat,
    /// Row pitch of the driver's buffers, bytes.
    pub stride_bytes: usize,
    /// mmap buffers in the ring.
    pub buffers: usize,
}

/// The device fields of one delivered frame (the `"capture"` object of `nav-app --json`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct DeviceFrameInfo {
    /// Driver sequence number (restarts at 0 after a stream restart).
    pub sequence: u32,
    /// Driver timestamp (`CLOCK_MONOTONIC` on bttv and vivid), µs.
    pub timestamp_us: i64,
    /// Pixel format the driver delivered.
    pub format: PixelFormat,
    /// Frame width, px.
    pub width_px: u32,
    /// Frame height, px.
    pub height_px: u32,
    /// Frames the driver dropped just before this one (sequence gap).
    pub missed: u32,
    /// The input reported no signal / no lock for this frame.
    pub signal_lost: bool,
    /// Mean grey level of the frame (0–255), a cheap exposure / signal check.
    pub mean_grey: f64,
}

/// Running counters since the device was opened (the summary of `nav-app --json`): the capture
/// layer's own counters ([`CaptureStats`], flattened into the same JSON object) and what this
/// source adds.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct DeviceStats {
    /// The capture layer's counters (frames, dropped buffers, sequence gaps, timeouts, restarts,
    /// frames with signal loss).
    #[serde(flatten)]
    pub capture: CaptureStats,
    /// Test-hook controls set.
    pub controls_set: u64,
    /// Wall time since the device was opened, s.
    pub elapsed_s: f64,
    /// Delivered frames per second of wall time since opening.
    pub fps: f64,
}

#[derive(Debug, Default)]
struct MonitorShared {
    setup: RefCell<Option<DeviceSetup>>,
    last: Cell<Option<DeviceFrameInfo>>,
    stats: Cell<DeviceStats>,
}

/// A read-only view of a [`CaptureSource`] that stays with the caller after the source has been
/// boxed as a `dyn FrameSource`: the setup, the last frame's device fields and the counters.
/// Cheap to clone (shared, single-threaded).
#[derive(Debug, Clone, Default)]
pub struct CaptureMonitor {
    shared: Rc<MonitorShared>,
}

impl CaptureMonitor {
    /// The device as opened (`None` before a successful open).
    pub fn setup(&self) -> Option<DeviceSetup> {
        self.shared.setup.borrow().clone()
    }

    /// Device fields of the last delivered frame.
    pub fn last_frame(&self) -> Option<DeviceFrameInfo> {
        self.shared.last.get()
    }

    /// Counters so far.
    pub fn stats(&self) -> DeviceStats {
        self.shared.stats.get()
    }
}

/// Frame index and time bookkeeping: the index advances by `1 + missed` per delivered frame (so
/// dropped frames leave holes, as [`FrameMeta::index`] documents), time is the driver timestamp
/// relative to the first frame.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Timeline {
    index: Option<u64>,
    first_timestamp_us: Option<i64>,
}

impl Timeline {
    /// The [`FrameMeta`] of a delivered frame with `missed` frames dropped before it.
    pub fn advance(&mut self, timestamp_us: i64, missed: u32) -> FrameMeta {
        let index = match self.index {
            None => 0,
            Some(i) => i + 1 + u64::from(missed),
        };
        self.index = Some(index);
        let first = *self.first_timestamp_us.get_or_insert(timestamp_us);
        FrameMeta {
            index,
            t_s: (timestamp_us - first) as f64 * 1e-6,
        }
    }
}

/// Consecutive-timeout accounting: [`TimeoutGate::timeout`] builds the error (fatal at the
/// limit), [`TimeoutGate::frame`] resets the count.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TimeoutGate {
    consecutive: u32,
    limit: u32,
}

impl TimeoutGate {
    /// A gate ending the run at the `limit`-th timeout in a row (`limit` ≥ 1).
    pub fn new(limit: u32) -> Self {
        Self {
            consecutive: 0,
            limit: limit.max(1),
        }
    }

    /// A frame arrived.
    pub fn frame(&mut self) {
        self.consecutive = 0;
    }

    /// A timeout of `timeout_ms` happened on `device`; `restarted` whether the stream restarted.
    pub fn timeout(&mut self, device: &str, timeout_ms: u32, restarted: bool) -> LaneIoError {
        self.consecutive = self.consecutive.saturating_add(1);
        LaneIoError::CaptureTimeout {
            device: device.to_owned(),
            timeout_ms,
            consecutive: self.consecutive,
            limit: self.limit,
            restarted,
        }
    }
}

/// A capture-layer error as a [`LaneIoError`]: `ENODEV` → [`LaneIoError::DeviceGone`], anything else
/// → [`LaneIoError::Capture`] (timeouts go through [`TimeoutGate`]).
pub fn capture_error(device: &str, e: CaptureError) -> LaneIoError {
    match e {
        CaptureError::DeviceGone { .. } => LaneIoError::DeviceGone {
            device: device.to_owned(),
        },
        error => LaneIoError::Capture {
            device: device.to_owned(),
            error,
        },
    }
}

/// Nominal frame rate of a `v4l2_std_id`, frames/s: 30000/1001 for the 525-line standards
/// (NTSC, PAL-M, PAL-60), 25 for the others; `None` without a standard.
pub fn std_frame_rate_hz(std_id: Option<u64>) -> Option<f64> {
    // V4L2_STD_525_60 = PAL_M | PAL_60 | NTSC (M, M_JP, 443, M_KR).
    const STD_525_60: u64 = 0x0000_0100 | 0x0000_0800 | 0x0000_f000;
    let id = std_id.filter(|&id| id != 0)?;
    Some(if id & STD_525_60 != 0 && id & !STD_525_60 == 0 {
        30_000.0 / 1001.0
    } else {
        25.0
    })
}

/// Open `path` for `--device`: the source (boxed) and its monitor.
///
/// # Errors
/// [`LaneIoError::CaptureUnavailable`] in a build without the `capture` feature;
/// [`LaneIoError::ConfigField`] for bad options; [`LaneIoError::Capture`] / [`LaneIoError::DeviceGone`]
/// when the device cannot be opened or configured.
#[cfg(feature = "capture")]
pub fn open(
    path: &Path,
    opts: &DeviceOptions,
) -> Result<(Box<dyn FrameSource>, CaptureMonitor), LaneIoError> {
    let source = CaptureSource::open(path, opts)?;
    let monitor = source.monitor();
    Ok((Box::new(source), monitor))
}

/// Open `path` for `--device`: the source (boxed) and its monitor.
///
/// # Errors
/// Always [`LaneIoError::CaptureUnavailable`]: this build has no `capture` feature.
#[cfg(not(feature = "capture"))]
pub fn open(
    path: &Path,
    opts: &DeviceOptions,
) -> Result<(Box<dyn FrameSource>, CaptureMonitor), LaneIoError> {
    let _ = opts;
    Err(LaneIoError::CaptureUnavailable {
        device: path.display().to_string(),
    })
}

#[cfg(feature = "capture")]
pub use device::CaptureSource;

#[cfg(feature = "capture")]
mod device {
    use std::path::Path;
    use std::time::Instant;

    use bt848_capture::{Capture, CaptureError, CaptureStats};

    use super::{
        CaptureMonitor, ControlSet, DeviceFrameInfo, DeviceOptions, DeviceSetup, DeviceStats,
        Timeline, TimeoutGate, capture_error, std_frame_rate_hz,
    };
    use lane_tracker::GreyFrame;

    use crate::{FrameMeta, FrameSource, LaneIoError};

    /// A V4L2 capture device as a [`FrameSource`] (feature `capture`). See the module docs.
    pub struct CaptureSource {
        cap: Capture,
        device: String,
        controls_at_frame: Vec<ControlSet>,
        next_control: usize,
        controls_on_timeout: Vec<ControlSet>,
        timeout_controls_done: bool,
        controls_set: u64,
        timeline: Timeline,
        gate: TimeoutGate,
        opened: Instant,
        monitor: CaptureMonitor,
    }

    impl std::fmt::Debug for CaptureSource {
        fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
            f.debug_struct("CaptureSource")
                .field("device", &self.device)
                .field("setup", &self.monitor.setup())
                .finish_non_exhaustive()
        }
    }

    impl CaptureSource {
        /// Open and start streaming from `path` with `opts`.
        ///
        /// # Errors
        /// [`LaneIoError::ConfigField`] for bad options; [`LaneIoError::Capture`] (holding the capture
        /// layer's typed error) or [`LaneIoError::DeviceGone`].
        pub fn open(path: &Path, opts: &DeviceOptions) -> Result<Self, LaneIoError> {
            opts.validate()?;
            let device = path.display().to_string();
            let cap =
                Capture::open(&device, &opts.capture).map_err(|e| capture_error(&device, e))?;
            let monitor = CaptureMonitor::default();
            *monitor.shared.setup.borrow_mut() = Some(DeviceSetup {
                device: device.clone(),
                input_index: cap.input_index(),
                std_id: cap.std_id(),
                width_px: cap.width_px(),
                height_px: cap.height_px(),
                format: cap.pixel_format(),
                stride_bytes: cap.stride_bytes(),
                buffers: cap.buffer_count(),
            });
            let mut controls_at_frame = opts.controls_at_frame.clone();
            controls_at_frame.sort_by_key(|c| c.at_frame);
            Ok(Self {
                cap,
                device,
                controls_at_frame,
                next_control: 0,
                controls_on_timeout: opts.controls_on_timeout.clone(),
                timeout_controls_done: false,
                controls_set: 0,
                timeline: Timeline::default(),
                gate: TimeoutGate::new(opts.max_consecutive_timeouts),
                opened: Instant::now(),
                monitor,
            })
        }

        /// A handle on the setup, the last frame's device fields and the counters.
        pub fn monitor(&self) -> CaptureMonitor {
            self.monitor.clone()
        }

        /// Counters so far.
        pub fn stats(&self) -> DeviceStats {
            let s: CaptureStats = self.cap.stats();
            let elapsed_s = self.opened.elapsed().as_secs_f64();
            DeviceStats {
                capture: s,
                controls_set: self.controls_set,
                elapsed_s,
                fps: if elapsed_s > 0.0 {
                    s.frames as f64 / elapsed_s
                } else {
                    0.0
                },
            }
        }

        /// Set a control by its driver name (e.g. bttv's `"Brightness"`).
        ///
        /// # Errors
        /// [`LaneIoError::Capture`] (unknown control, ioctl failure) or [`LaneIoError::DeviceGone`].
        pub fn set_control(&mut self, name: &str, value: i32) -> Result<(), LaneIoError> {
            let result = self
                .cap
                .set_control(name, value)
                .map_err(|e| capture_error(&self.device, e));
            if result.is_ok() {
                self.controls_set += 1;
            }
            self.publish_stats();
            result
        }

        fn publish_stats(&self) {
            self.monitor.shared.stats.set(self.stats());
        }

        fn apply_due_controls(&mut self) -> Result<(), LaneIoError> {
            let delivered = self.cap.stats().frames;
            while let Some(c) = self.controls_at_frame.get(self.next_control) {
                if c.at_frame > delivered {
                    break;
                }
                let (name, value) = (c.name.clone(), c.value);
                self.next_control += 1;
                self.set_control(&name, value)?;
            }
            Ok(())
        }

        fn on_timeout(&mut self, timeout_ms: u32, restarted: bool) -> LaneIoError {
            let err = self.gate.timeout(&self.device, timeout_ms, restarted);
            if !self.timeout_controls_done {
                self.timeout_controls_done = true;
                for c in std::mem::take(&mut self.controls_on_timeout) {
                    if let Err(e) = self.set_control(&c.name, c.value) {
                        return e;
                    }
                }
            }
            self.publish_stats();
            err
        }
    }

    impl FrameSource for CaptureSource {
        fn next_frame(&mut self, frame: &mut GreyFrame) -> Result<Option<FrameMeta>, LaneIoError> {
            self.apply_due_controls()?;
            frame
                .reshape(self.cap.width_px() as usize, self.cap.height_px() as usize)
                .map_err(|source| LaneIoError::FrameBuffer {
                    name: self.device.clone(),
                    source,
                })?;
            match self.cap.next_frame(frame.data_mut()) {
                Ok(info) => {
                    self.gate.frame();
                    let meta = self
                        .timeline
                        .advance(info.timestamp_us, info.frames_missed_before);
                    let sum: u64 = frame.data().iter().map(|&p| u64::from(p)).sum();
                    let mean_grey = sum as f64 / frame.data().len().max(1) as f64;
                    self.monitor.shared.last.set(Some(DeviceFrameInfo {
                        sequence: info.sequence,
                        timestamp_us: info.timestamp_us,
                        format: self.cap.pixel_format(),
                        width_px: info.width,
                        height_px: info.height,
                        missed: info.frames_missed_before,
                        signal_lost: info.signal_lost,
                        mean_grey,
                    }));
                    self.publish_stats();
                    Ok(Some(meta))
                }
                Err(CaptureError::Timeout {
                    timeout_ms,
                    restarted,
                }) => Err(self.on_timeout(timeout_ms, restarted)),
                Err(e) => {
                    self.publish_stats();
                    Err(capture_error(&self.device, e))
                }
            }
        }

        fn describe(&self) -> String {
            let std = match self.cap.std_id() {
                Some(id) => format!("std {id:#x}"),
                None => "no standard".to_owned(),
            };
            format!(
                "{} (V4L2 capture: input {}, {}×{} {}, {std}, stride {} B, {} buffers)",
                self.device,
                self.cap.input_index(),
                self.cap.width_px(),
                self.cap.height_px(),
                self.cap.pixel_format(),
                self.cap.stride_bytes(),
                self.cap.buffer_count()
            )
        }

        fn frame_rate_hz(&self) -> Option<f64> {
            std_frame_rate_hz(self.cap.std_id())
        }
    }
}

#[cfg(test)]
mod tests;
