//! Safe wrappers over the raw V4L2 ioctls the `v4l` crate has no high-level call for: inputs
//! (`VIDIOC_ENUMINPUT`, `G_INPUT`, `S_INPUT`), standards (`VIDIOC_ENUMSTD`, `G_STD`, `S_STD`,
//! `QUERYSTD`), controls by name (`VIDIOC_QUERYCTRL`, `S_CTRL`), and the mmap streaming ioctls.
//!
//! Every function takes a file descriptor that must stay open for the call; the ioctl argument
//! structs are the `v4l` crate's bindgen bindings of `linux/videodev2.h`, so their sizes match the
//! request codes in `v4l::v4l2::vidioc`.

use std::io;
use std::os::raw::c_int;

use v4l::v4l_sys;
use v4l::v4l2::vidioc;

/// `V4L2_BUF_TYPE_VIDEO_CAPTURE`.
pub(crate) const BUF_TYPE_VIDEO_CAPTURE: u32 = v4l_sys::v4l2_buf_type_V4L2_BUF_TYPE_VIDEO_CAPTURE;
/// `V4L2_MEMORY_MMAP`.
pub(crate) const MEMORY_MMAP: u32 = v4l_sys::v4l2_memory_V4L2_MEMORY_MMAP;
/// `V4L2_FIELD_ANY`.
pub(crate) const FIELD_ANY: u32 = v4l_sys::v4l2_field_V4L2_FIELD_ANY;

/// Input status bits meaning "no usable signal": `V4L2_IN_ST_NO_POWER | NO_SIGNAL | NO_H_LOCK`.
pub(crate) const IN_ST_SIGNAL_LOST: u32 =
    v4l_sys::V4L2_IN_ST_NO_POWER | v4l_sys::V4L2_IN_ST_NO_SIGNAL | v4l_sys::V4L2_IN_ST_NO_H_LOCK;

/// `ioctl(fd, request, arg)`, retried on `EINTR`.
///
/// # Safety
/// `T` must be the argument type the kernel expects for `request` (the request code encodes its
/// size, and the bindings come from the same header), and `fd` must be an open descriptor.
pub(crate) unsafe fn xioctl<T>(
    fd: c_int,
    request: vidioc::_IOC_TYPE,
    arg: &mut T,
) -> io::Result<()> {
    loop {
        let ptr = (arg as *mut T).cast::<std::os::raw::c_void>();
        // SAFETY: forwarded from the caller: `arg` is a live, exclusive `T` of the type `request`
        // expects, so the kernel reads/writes only within it.
        match unsafe { v4l::v4l2::ioctl(fd, request, ptr) } {
            Err(e) if e.kind() == io::ErrorKind::Interrupted => continue,
            other => return other,
        }
    }
}

/// Zero-initialised bindgen struct.
fn zeroed<T: Copy>() -> T {
    // SAFETY: only used for the plain-old-data `v4l2_*` C structs of the bindings (integers,
    // arrays, unions of integers and raw pointers), for which all-zero bytes are a valid value
    // (it is how C code initialises them with memset).
    unsafe { std::mem::zeroed() }
}

/// A NUL-terminated C name array as a `String`.
pub(crate) fn c_name(bytes: &[u8]) -> String {
    let end = bytes.iter().position(|&b| b == 0).unwrap_or(bytes.len());
    String::from_utf8_lossy(&bytes[..end]).into_owned()
}

/// One video input, from `VIDIOC_ENUMINPUT`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct InputInfo {
    /// Input index (for `S_INPUT`).
    pub index: u32,
    /// Driver's name for it (`"Composite0"`, `"S-Video"`…).
    pub name: String,
    /// Whether it is a tuner (`V4L2_INPUT_TYPE_TUNER`) rather than a camera/baseband input.
    pub is_tuner: bool,
    /// Standards it supports (`v4l2_std_id` mask; 0 = none apply).
    pub std_mask: u64,
    /// Raw `V4L2_IN_ST_*` status bits (valid for the current input only).
    pub status: u32,
}

impl InputInfo {
    /// Whether the status reports no power, no signal or no horizontal lock.
    pub fn signal_lost(&self) -> bool {
        self.status & IN_ST_SIGNAL_LOST != 0
    }
}

/// One standard the current input supports, from `VIDIOC_ENUMSTD`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct StandardInfo {
    /// Enumeration index.
    pub index: u32,
    /// `v4l2_std_id` bits.
    pub id: u64,
    /// Driver's name (`"NTSC-M"`, `"PAL-BG"`…).
    pub name: String,
    /// Frame period numerator, seconds (e.g. 1001 for NTSC).
    pub frame_period_num: u32,
    /// Frame period denominator (e.g. 30000 for NTSC).
    pub frame_period_den: u32,
    /// Lines per frame (525 or 625).
    pub frame_lines: u32,
}

/// `VIDIOC_ENUMINPUT` for one index; `Ok(None)` past the last input (`EINVAL`).
pub(crate) fn enum_input(fd: c_int, index: u32) -> io::Result<Option<InputInfo>> {
    let mut input: v4l_sys::v4l2_input = zeroed();
    input.index = index;
    // SAFETY: VIDIOC_ENUMINPUT takes a `struct v4l2_input`, which `input` is.
    match unsafe { xioctl(fd, vidioc::VIDIOC_ENUMINPUT, &mut input) } {
        Ok(()) => Ok(Some(InputInfo {
            index: input.index,
            name: c_name(&input.name),
            is_tuner: input.type_ == v4l_sys::V4L2_INPUT_TYPE_TUNER,
            std_mask: input.std,
            status: input.status,
        })),
        Err(e) if e.raw_os_error() == Some(libc::EINVAL) => Ok(None),
        Err(e) => Err(e),
    }
}

/// All inputs, by index.
pub(crate) fn enum_inputs(fd: c_int) -> io::Result<Vec<InputInfo>> {
    let mut inputs = Vec::new();
    // VIDIOC_ENUMINPUT indices are dense from 0; bound the loop anyway against a broken driver.
    for index in 0..256 {
        match enum_input(fd, index)? {
            Some(info) => inputs.push(info),
            None => break,
        }
    }
    Ok(inputs)
}

/// `VIDIOC_G_INPUT`.
pub(crate) fn get_input(fd: c_int) -> io::Result<u32> {
    let mut index: c_int = 0;
    // SAFETY: VIDIOC_G_INPUT takes an `int`, which `index` is.
    unsafe { xioctl(fd, vidioc::VIDIOC_G_INPUT, &mut index) }?;
    Ok(index.unsigned_abs())
}

/// `VIDIOC_S_INPUT`.
pub(crate) fn set_input(fd: c_int, index: u32) -> io::Result<()> {
    let mut arg = c_int::try_from(index).map_err(|_| io::Error::from_raw_os_error(libc::EINVAL))?;
    // SAFETY: VIDIOC_S_INPUT takes an `int`, which `arg` is.
    unsafe { xioctl(fd, vidioc::VIDIOC_S_INPUT, &mut arg) }
}

/// All standards of the current input (`VIDIOC_ENUMSTD`); empty if the input has none
/// (`ENODATA`/`EINVAL`/`ENOTTY` at index 0).
pub(crate) fn enum_stds(fd: c_int) -> io::Result<Vec<StandardInfo>> {
    let mut out = Vec::new();
    for index in 0..256 {
        let mut std: v4l_sys::v4l2_standard = zeroed();
        std.index = index;
        // SAFETY: VIDIOC_ENUMSTD takes a `struct v4l2_standard`, which `std` is.
        match unsafe { xioctl(fd, vidioc::VIDIOC_ENUMSTD, &mut std) } {
            Ok(()) => out.push(StandardInfo {
                index: std.index,
                id: std.id,
                name: c_name(&std.name),
                frame_period_num: std.frameperiod.numerator,
                frame_period_den: std.frameperiod.denominator,
                frame_lines: std.framelines,
            }),
            Err(e)
                if matches!(
                    e.raw_os_error(),
                    Some(libc::EINVAL | libc::ENODATA | libc::ENOTTY)
                ) =>
            {
                break;
            }
            Err(e) => return Err(e),
        }
    }
    Ok(out)
}

/// `VIDIOC_G_STD`.
pub(crate) fn get_std(fd: c_int) -> io::Result<u64> {
    let mut id: v4l_sys::v4l2_std_id = 0;
    // SAFETY: VIDIOC_G_STD takes a `v4l2_std_id` (u64), which `id` is.
    unsafe { xioctl(fd, vidioc::VIDIOC_G_STD, &mut id) }?;
    Ok(id)
}

/// `VIDIOC_S_STD`.
pub(crate) fn set_std(fd: c_int, id: u64) -> io::Result<()> {
    let mut arg: v4l_sys::v4l2_std_id = id;
    // SAFETY: VIDIOC_S_STD takes a `v4l2_std_id` (u64), which `arg` is.
    unsafe { xioctl(fd, vidioc::VIDIOC_S_STD, &mut arg) }
}

/// `VIDIOC_QUERYSTD`: the standards the hardware detects on the current input (0 = no signal).
pub(crate) fn query_std(fd: c_int) -> io::Result<u64> {
    let mut id: v4l_sys::v4l2_std_id = 0;
    // SAFETY: VIDIOC_QUERYSTD takes a `v4l2_std_id` (u64), which `id` is.
    unsafe { xioctl(fd, vidioc::VIDIOC_QUERYSTD, &mut id) }?;
    Ok(id)
}

/// `VIDIOC_QUERYCAP`: (driver, card, capability bits that apply to this node).
pub(crate) fn query_caps(fd: c_int) -> io::Result<(String, String, u32)> {
    let mut caps: v4l_sys::v4l2_capability = zeroed();
    // SAFETY: VIDIOC_QUERYCAP takes a `struct v4l2_capability`, which `caps` is.
    unsafe { xioctl(fd, vidioc::VIDIOC_QUERYCAP, &mut caps) }?;
    let node_caps = if caps.capabilities & v4l_sys::V4L2_CAP_DEVICE_CAPS != 0 {
        caps.device_caps
    } else {
        caps.capabilities
    };
    Ok((c_name(&caps.driver), c_name(&caps.card), node_caps))
}

/// The pixel format the driver settled on.
#[derive(Debug, Clone, Copy)]
pub(crate) struct NegotiatedFormat {
    pub(crate) width: u32,
    pub(crate) height: u32,
    pub(crate) fourcc: [u8; 4],
    pub(crate) bytes_per_line: u32,
}

/// `VIDIOC_S_FMT` (single-planar capture), returning what the driver actually set.
pub(crate) fn set_format(
    fd: c_int,
    width: u32,
    height: u32,
    fourcc: u32,
) -> io::Result<NegotiatedFormat> {
    let mut fmt: v4l_sys::v4l2_format = zeroed();
    fmt.type_ = BUF_TYPE_VIDEO_CAPTURE;
    // Writing the `pix` union member (safe for `Copy` unions): the one the kernel reads for
    // single-planar capture.
    fmt.fmt.pix.width = width;
    fmt.fmt.pix.height = height;
    fmt.fmt.pix.pixelformat = fourcc;
    fmt.fmt.pix.field = FIELD_ANY;
    // SAFETY: VIDIOC_S_FMT takes a `struct v4l2_format`, which `fmt` is.
    unsafe { xioctl(fd, vidioc::VIDIOC_S_FMT, &mut fmt) }?;
    // SAFETY: for `type_ == V4L2_BUF_TYPE_VIDEO_CAPTURE` the kernel fills the `pix` member.
    let pix = unsafe { fmt.fmt.pix };
    Ok(NegotiatedFormat {
        width: pix.width,
        height: pix.height,
        fourcc: pix.pixelformat.to_le_bytes(),
        bytes_per_line: pix.bytesperline,
    })
}

/// Find a control's id by its name (ASCII case-insensitive), walking `VIDIOC_QUERYCTRL` with
/// `V4L2_CTRL_FLAG_NEXT_CTRL`. Disabled controls are skipped.
pub(crate) fn find_control(fd: c_int, name: &str) -> io::Result<Option<u32>> {
    let mut id = 0u32;
    // Bounded: a driver has far fewer than 4096 controls.
    for _ in 0..4096 {
        let mut q: v4l_sys::v4l2_queryctrl = zeroed();
        q.id = id | v4l_sys::V4L2_CTRL_FLAG_NEXT_CTRL;
        // SAFETY: VIDIOC_QUERYCTRL takes a `struct v4l2_queryctrl`, which `q` is.
        match unsafe { xioctl(fd, vidioc::VIDIOC_QUERYCTRL, &mut q) } {
            Ok(()) => {
                if q.flags & v4l_sys::V4L2_CTRL_FLAG_DISABLED == 0
                    && c_name(&q.name).eq_ignore_ascii_case(name)
                {
                    return Ok(Some(q.id));
                }
                id = q.id;
            }
            Err(e) if e.raw_os_error() == Some(libc::EINVAL) => return Ok(None),
            Err(e) => return Err(e),
        }
    }
    Ok(None)
}

/// `VIDIOC_S_CTRL`.
pub(crate) fn set_control(fd: c_int, id: u32, value: i32) -> io::Result<()> {
    let mut c = v4l_sys::v4l2_control { id, value };
    // SAFETY: VIDIOC_S_CTRL takes a `struct v4l2_control`, which `c` is.
    unsafe { xioctl(fd, vidioc::VIDIOC_S_CTRL, &mut c) }
}

/// `VIDIOC_REQBUFS` for mmap capture buffers; returns the count granted.
pub(crate) fn request_buffers(fd: c_int, count: u32) -> io::Result<u32> {
    let mut req: v4l_sys::v4l2_requestbuffers = zeroed();
    req.count = count;
    req.type_ = BUF_TYPE_VIDEO_CAPTURE;
    req.memory = MEMORY_MMAP;
    // SAFETY: VIDIOC_REQBUFS takes a `struct v4l2_requestbuffers`, which `req` is.
    unsafe { xioctl(fd, vidioc::VIDIOC_REQBUFS, &mut req) }?;
    Ok(req.count)
}

/// A capture `struct v4l2_buffer` for mmap memory with the given index.
pub(crate) fn capture_buffer(index: u32) -> v4l_sys::v4l2_buffer {
    let mut buf: v4l_sys::v4l2_buffer = zeroed();
    buf.index = index;
    buf.type_ = BUF_TYPE_VIDEO_CAPTURE;
    buf.memory = MEMORY_MMAP;
    buf
}

/// `VIDIOC_QUERYBUF`: (mmap offset, length in bytes).
pub(crate) fn query_buffer(fd: c_int, index: u32) -> io::Result<(u32, usize)> {
    let mut buf = capture_buffer(index);
    // SAFETY: VIDIOC_QUERYBUF takes a `struct v4l2_buffer`, which `buf` is.
    unsafe { xioctl(fd, vidioc::VIDIOC_QUERYBUF, &mut buf) }?;
    // SAFETY: for `memory == V4L2_MEMORY_MMAP` the kernel fills the `offset` member.
    let offset = unsafe { buf.m.offset };
    Ok((offset, buf.length as usize))
}

/// `VIDIOC_QBUF` of mmap buffer `index`.
pub(crate) fn queue_buffer(fd: c_int, index: u32) -> io::Result<()> {
    let mut buf = capture_buffer(index);
    // SAFETY: VIDIOC_QBUF takes a `struct v4l2_buffer`, which `buf` is.
    unsafe { xioctl(fd, vidioc::VIDIOC_QBUF, &mut buf) }
}

/// `VIDIOC_DQBUF` (the fd is non-blocking: `EAGAIN` when nothing is ready).
pub(crate) fn dequeue_buffer(fd: c_int) -> io::Result<v4l_sys::v4l2_buffer> {
    let mut buf = capture_buffer(0);
    // SAFETY: VIDIOC_DQBUF takes a `struct v4l2_buffer`, which `buf` is.
    unsafe { xioctl(fd, vidioc::VIDIOC_DQBUF, &mut buf) }?;
    Ok(buf)
}

/// `VIDIOC_STREAMON` / `VIDIOC_STREAMOFF` for video capture.
pub(crate) fn stream(fd: c_int, on: bool) -> io::Result<()> {
    let mut typ: c_int = BUF_TYPE_VIDEO_CAPTURE as c_int;
    let request = if on {
        vidioc::VIDIOC_STREAMON
    } else {
        vidioc::VIDIOC_STREAMOFF
    };
    // SAFETY: VIDIOC_STREAMON/OFF take an `int` buffer type, which `typ` is.
    unsafe { xioctl(fd, request, &mut typ) }
}

/// `poll(fd, POLLIN)` for up to `timeout_ms`; `Ok(true)` when readable or in error (the next
/// `DQBUF` reports which), `Ok(false)` on timeout.
pub(crate) fn poll_readable(fd: c_int, timeout_ms: c_int) -> io::Result<bool> {
    let mut pfd = libc::pollfd {
        fd,
        events: libc::POLLIN,
        revents: 0,
    };
    loop {
        // SAFETY: `pfd` is one valid `pollfd` and we pass a count of 1.
        let n = unsafe { libc::poll(&mut pfd, 1, timeout_ms) };
        if n < 0 {
            let e = io::Error::last_os_error();
            if e.kind() == io::ErrorKind::Interrupted {
                continue;
            }
            return Err(e);
        }
        return Ok(n > 0);
    }
}
