//! A small YUV4MPEG2 reader and writer.
//!
//! Stream layout: a header line `YUV4MPEG2 W<width> H<height> [F<n>:<d>] [I<i>] [A<n>:<d>]
//! [C<chroma>] [X<anything>]…\n`, then per frame a line `FRAME [params]\n` followed by the planes:
//! Y (`W × H` bytes), then for 4:2:0 Cb and Cr (`⌈W/2⌉ × ⌈H/2⌉` bytes each). Only 8-bit `C mono`
//! and the 4:2:0 family (`420`, `420jpeg` — the default when `C` is absent — `420paldv`,
//! `420mpeg2`) are read; only the Y plane is kept, the chroma planes are skipped.
//!
//! A stream that repeats a `YUV4MPEG2` header where a `FRAME` is expected (two files
//! concatenated) is accepted when the size is the same and rejected with
//! [`NavError::SizeChanged`] otherwise.
//!
//! A stream damaged where a `FRAME` header is expected (a flipped byte, a frame cut short, junk)
//! is resynchronised at the next `FRAME` marker: the frames lost are reported once as a
//! non-fatal [`NavError::Y4mResync`] and totalled in [`Y4mSource::losses`]; see [`Y4mSource`]
//! for how they are counted.

use std::io::{self, BufRead, Read, Write};

use crate::{FrameMeta, FrameSource, GreyFrame, NavError};

/// Longest header line accepted, bytes.
const MAX_HEADER_BYTES: usize = 4096;

/// Chroma layouts this reader accepts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Y4mChroma {
    /// `C mono`: Y plane only.
    Mono,
    /// `C 420`, `420jpeg`, `420paldv`, `420mpeg2` (or no `C` tag): Y plus two quarter-size planes.
    C420,
}

/// The parsed stream header.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Y4mHeader {
    /// Width, px.
    pub width: usize,
    /// Height, px.
    pub height: usize,
    /// Frame rate, frames/s (`F` tag; 0 when absent).
    pub fps: f64,
    /// Chroma layout.
    pub chroma: Y4mChroma,
}

impl Y4mHeader {
    /// Bytes of one frame's planes (without the `FRAME` line).
    pub fn frame_bytes(&self) -> usize {
        let luma = self.width * self.height;
        match self.chroma {
            Y4mChroma::Mono => luma,
            Y4mChroma::C420 => luma + 2 * self.width.div_ceil(2) * self.height.div_ceil(2),
        }
    }

    /// Parse a header line (without the trailing newline, with the `YUV4MPEG2` magic).
    pub fn parse(name: &str, line: &[u8]) -> Result<Self, NavError> {
        let bad = |reason: String| NavError::Y4mHeader {
            name: name.to_owned(),
            reason,
        };
        let text =
            std::str::from_utf8(line).map_err(|_| bad("header is not ASCII text".to_owned()))?;
        let mut tokens = text.split(' ').filter(|t| !t.is_empty());
        match tokens.next() {
            Some("YUV4MPEG2") => {}
            other => {
                return Err(bad(format!(
                    "missing `YUV4MPEG2` magic (found {:?})",
                    other.unwrap_or("").chars().take(16).collect::<String>()
                )));
            }
        }
        let (mut width, mut height, mut fps, mut chroma) = (None, None, 0.0, Y4mChroma::C420);
        for token in tokens {
            let (tag, value) = token.split_at(1);
            match tag {
                "W" => {
                    width = Some(
                        value
                            .parse::<usize>()
                            .map_err(|_| bad(format!("bad width `{token}`")))?,
                    )
                }
                "H" => {
                    height = Some(
                        value
                            .parse::<usize>()
                            .map_err(|_| bad(format!("bad height `{token}`")))?,
                    )
                }
                "F" => {
                    let (n, d) = value
                        .split_once(':')
                        .ok_or_else(|| bad(format!("bad frame rate `{token}`")))?;
                    let n: f64 = n
                        .parse()
                        .map_err(|_| bad(format!("bad frame rate `{token}`")))?;
                    let d: f64 = d
                        .parse()
                        .map_err(|_| bad(format!("bad frame rate `{token}`")))?;
                    fps = if d > 0.0 { n / d } else { 0.0 };
                }
                "C" => {
                    chroma = match value {
                        "mono" => Y4mChroma::Mono,
                        "420" | "420jpeg" | "420paldv" | "420mpeg2" => Y4mChroma::C420,
                        other => {
                            return Err(NavError::UnsupportedChroma {
                                name: name.to_owned(),
                                chroma: other.to_owned(),
                            });
                        }
                    }
                }
                "I" | "A" | "X" => {}
                _ => return Err(bad(format!("unknown tag `{token}`"))),
            }
        }
        let width = width.ok_or_else(|| bad("no width (`W`) tag".to_owned()))?;
        let height = height.ok_or_else(|| bad("no height (`H`) tag".to_owned()))?;
        if width == 0 || height == 0 {
            return Err(NavError::ZeroSize {
                name: name.to_owned(),
                width,
                height,
            });
        }
        if width.checked_mul(height).is_none_or(|n| n > (1 << 30)) {
            return Err(bad(format!(
                "frame size {width}×{height} is implausibly large"
            )));
        }
        Ok(Y4mHeader {
            width,
            height,
            fps,
            chroma,
        })
    }
}

/// Read bytes into `buf` until it is full or the stream ends; returns how many were read.
fn read_fully<R: Read>(reader: &mut R, buf: &mut [u8]) -> io::Result<usize> {
    let mut got = 0;
    while got < buf.len() {
        match reader.read(&mut buf[got..]) {
            Ok(0) => break,
            Ok(n) => got += n,
            Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(got)
}

/// Read one `\n`-terminated line into `line` (without the newline), at most `MAX_HEADER_BYTES`.
/// Returns `Ok(false)` on a clean end of stream before any byte.
fn read_line<R: BufRead>(reader: &mut R, line: &mut Vec<u8>, name: &str) -> Result<bool, NavError> {
    line.clear();
    loop {
        let available = match reader.fill_buf() {
            Ok(b) => b,
            Err(e) if e.kind() == io::ErrorKind::Interrupted => continue,
            Err(e) => return Err(NavError::io(name, e)),
        };
        if available.is_empty() {
            return Ok(!line.is_empty());
        }
        let (take, done) = match available.iter().position(|&b| b == b'\n') {
            Some(i) => (i + 1, true),
            None => (available.len(), false),
        };
        let room = MAX_HEADER_BYTES.saturating_sub(line.len());
        line.extend_from_slice(&available[..take.min(room)]);
        reader.consume(take);
        if done {
            line.pop_if(|b| *b == b'\n');
            return Ok(true);
        }
        if line.len() >= MAX_HEADER_BYTES {
            return Ok(true);
        }
    }
}

/// What [`Y4mSource`] has lost to damage so far.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Y4mLosses {
    /// Frames of the stream not delivered (skipped while resynchronising, or short at the end).
    pub frames: u64,
    /// Bytes skipped: damaged headers, the data they announced, and short last frames.
    pub bytes: u64,
    /// Resynchronisations (each one a [`NavError::Y4mResync`] returned by `next_frame`).
    pub resyncs: u64,
}

/// The next marker found by [`Y4mSource::sync`].
enum Marker {
    /// `FRAME` followed by a space (parameters follow) or a newline (`line_done`).
    Frame { line_done: bool },
    /// `YUV4MPEG2 ` (a concatenated stream's header).
    Header,
    /// The end of the stream.
    End,
}

/// A YUV4MPEG2 stream (file or stdin) as a [`FrameSource`]; only the Y plane is delivered.
///
/// Reading a frame does not allocate once the caller's frame has the stream's size. The frame
/// buffer grows with the bytes actually read, so a header announcing a huge frame (up to the
/// 2³⁰-pixel cap of [`Y4mHeader::parse`]) over a short stream does not allocate the whole frame.
///
/// ## Damaged streams
/// Where a frame header is expected the reader scans forward to the next `FRAME` marker (`FRAME`
/// followed by a space or a newline), so a damaged `FRAME` header (a flipped byte), a frame short
/// of bytes in the middle of the stream, or garbage between frames costs the frames concerned, not
/// the rest of the stream. This works on pipes (no seeking) with bounded memory: the scan looks at
/// one byte at a time through the reader's buffer.
///
/// When `D > 0` bytes were skipped before the marker, `next_frame` returns one non-fatal
/// [`NavError::Y4mResync`] before the frame after the marker. The frames lost are counted as
/// `⌈D / L⌉`, with `L` the length of one frame record (its `FRAME` line and planes, as of the
/// last good header): exact when damage replaces or drops bytes (bit flips, a frame cut short,
/// lost packets) — the marker found is then the `⌈D/L⌉ + 1`-th after the last good frame, and
/// the frame indices (and time stamps) after the damage are the true ones. Inserted bytes can make
/// the count one too high. A frame that was cut short mid-stream swallows the next frame's header
/// into its planes and is delivered (damaged), and the frame whose header it swallowed is lost:
/// without reading ahead — which would delay every frame of a live pipe by one — the reader
/// cannot tell a short frame from good pixels. A short **last** frame is a non-fatal
/// [`NavError::ShortFrame`]. [`Y4mSource::losses`] keeps the totals.
#[derive(Debug)]
pub struct Y4mSource<R: BufRead> {
    reader: R,
    name: String,
    header: Y4mHeader,
    next_index: u64,
    line: Vec<u8>,
    /// A `FRAME` line has been consumed: the reader is at the planes of frame `next_index`.
    at_planes: bool,
    /// Bytes of the last good `FRAME` line, its newline included.
    frame_line_bytes: usize,
    losses: Y4mLosses,
    finished: bool,
}

impl<R: BufRead> Y4mSource<R> {
    /// Read the stream header. `name` (file name or `stdin`) is used in errors.
    pub fn new(mut reader: R, name: impl Into<String>) -> Result<Self, NavError> {
        let name = name.into();
        let mut line = Vec::with_capacity(128);
        if !read_line(&mut reader, &mut line, &name)? {
            return Err(NavError::Y4mHeader {
                name,
                reason: "empty stream".to_owned(),
            });
        }
        let header = Y4mHeader::parse(&name, &line)?;
        Ok(Y4mSource {
            reader,
            name,
            header,
            next_index: 0,
            line,
            at_planes: false,
            frame_line_bytes: b"FRAME\n".len(),
            losses: Y4mLosses::default(),
            finished: false,
        })
    }

    /// The stream header.
    pub fn header(&self) -> &Y4mHeader {
        &self.header
    }

    /// Frames and bytes lost to damage so far.
    pub fn losses(&self) -> Y4mLosses {
        self.losses
    }

    /// Consume bytes up to and including the next marker; returns it and how many bytes came
    /// before it (skipped).
    fn sync(&mut self) -> Result<(Marker, u64), NavError> {
        const FRAME_SP: &[u8] = b"FRAME ";
        const FRAME_NL: &[u8] = b"FRAME\n";
        const HEADER: &[u8] = b"YUV4MPEG2 ";
        // The last bytes seen, newest last (HEADER is the longest marker).
        let mut window = [0u8; 10];
        let mut seen = 0u64;
        loop {
            let available = match self.reader.fill_buf() {
                Ok(b) => b,
                Err(e) if e.kind() == io::ErrorKind::Interrupted => continue,
                Err(e) => return Err(NavError::io(self.name.clone(), e)),
            };
            if available.is_empty() {
                return Ok((Marker::End, seen));
            }
            let mut found = None;
            let mut used = 0;
            for &b in available {
                used += 1;
                seen += 1;
                window.copy_within(1.., 0);
                window[9] = b;
                if window.ends_with(FRAME_NL) {
                    found = Some((Marker::Frame { line_done: true }, FRAME_NL.len()));
                } else if window.ends_with(FRAME_SP) {
                    found = Some((Marker::Frame { line_done: false }, FRAME_SP.len()));
                } else if window.ends_with(HEADER) {
                    found = Some((Marker::Header, HEADER.len()));
                }
                if found.is_some() {
                    break;
                }
            }
            self.reader.consume(used);
            if let Some((marker, len)) = found {
                return Ok((marker, seen - len as u64));
            }
        }
    }

    /// Find and consume the next `FRAME` line, taking in concatenated stream headers of the same
    /// frame size on the way. Returns whether one was found (else the stream ended) and the bytes
    /// skipped before it.
    fn next_frame_line(&mut self) -> Result<(bool, u64), NavError> {
        let mut skipped = 0u64;
        loop {
            let (marker, before) = self.sync()?;
            skipped += before;
            match marker {
                Marker::End => return Ok((false, skipped)),
                Marker::Frame { line_done } => {
                    let mut len = b"FRAME\n".len();
                    if !line_done {
                        // Parameters: the rest of the line (bounded), ignored.
                        read_line(&mut self.reader, &mut self.line, &self.name)?;
                        len += self.line.len() + 1;
                    }
                    self.frame_line_bytes = len;
                    return Ok((true, skipped));
                }
                Marker::Header => {
                    read_line(&mut self.reader, &mut self.line, &self.name)?;
                    let mut text = Vec::with_capacity(10 + self.line.len());
                    text.extend_from_slice(b"YUV4MPEG2 ");
                    text.extend_from_slice(&self.line);
                    let new = Y4mHeader::parse(&self.name, &text)?;
                    if new.width != self.header.width || new.height != self.header.height {
                        self.finished = true;
                        return Err(NavError::SizeChanged {
                            name: self.name.clone(),
                            frame: self.next_index,
                            from_w: self.header.width,
                            from_h: self.header.height,
                            to_w: new.width,
                            to_h: new.height,
                        });
                    }
                    self.header = new;
                }
            }
        }
    }
}

/// Read `len` bytes into `data`, which ends up `len` bytes long when they were all there. The
/// buffer grows only as bytes arrive (doubling from 1 MiB), so a header announcing a huge frame
/// over a short stream costs at most twice the bytes actually present. Returns the bytes read.
fn read_plane<R: Read>(reader: &mut R, data: &mut Vec<u8>, len: usize) -> io::Result<usize> {
    const CHUNK: usize = 1 << 20;
    data.truncate(len);
    let mut got = 0;
    while got < len {
        let end = if data.len() >= len {
            len
        } else {
            len.min((2 * got).max(CHUNK)).max(data.len())
        };
        if data.len() < end {
            data.resize(end, 0);
        }
        let n = read_fully(reader, &mut data[got..end])?;
        got += n;
        if got < end {
            break;
        }
    }
    Ok(got)
}

impl<R: BufRead> FrameSource for Y4mSource<R> {
    fn next_frame(&mut self, frame: &mut GreyFrame) -> Result<Option<FrameMeta>, NavError> {
        if self.finished {
            return Ok(None);
        }
        if !self.at_planes {
            let first_lost = self.next_index;
            let (found, skipped) = match self.next_frame_line() {
                Ok(r) => r,
                Err(e) => {
                    self.finished = true;
                    return Err(e);
                }
            };
            self.at_planes = found;
            self.finished = !found;
            if skipped > 0 {
                let record = (self.frame_line_bytes + self.header.frame_bytes()) as u64;
                let lost = skipped.div_ceil(record);
                self.next_index += lost;
                self.losses.frames += lost;
                self.losses.bytes += skipped;
                self.losses.resyncs += 1;
                return Err(NavError::Y4mResync {
                    name: self.name.clone(),
                    frame: first_lost,
                    lost_frames: lost,
                    skipped_bytes: skipped,
                    end_of_stream: !found,
                });
            }
            if !found {
                return Ok(None);
            }
        }
        self.at_planes = false;
        let index = self.next_index;
        self.next_index += 1;
        let (w, h) = (self.header.width, self.header.height);
        let expected = self.header.frame_bytes();
        // The plane is read into the frame's own buffer (taken out and put back, so its capacity
        // is reused); the frame gets its size only when the whole plane is there.
        let mut buf = std::mem::take(frame).into_vec();
        let read = read_plane(&mut self.reader, &mut buf, w * h);
        let got = match read {
            Ok(got) if got == w * h => {
                *frame =
                    GreyFrame::from_vec(w, h, buf).map_err(|source| NavError::FrameBuffer {
                        name: self.name.clone(),
                        source,
                    })?;
                got
            }
            Ok(got) => {
                // Leave the caller a valid (empty) frame rather than a partial one.
                buf.clear();
                *frame = GreyFrame::from_vec(0, 0, buf).unwrap_or_default();
                got
            }
            Err(e) => {
                buf.clear();
                *frame = GreyFrame::from_vec(0, 0, buf).unwrap_or_default();
                return Err(NavError::io(self.name.clone(), e));
            }
        };
        let mut total = got;
        if got == w * h {
            let chroma = (expected - got) as u64;
            let skipped = io::copy(&mut (&mut self.reader).take(chroma), &mut io::sink())
                .map_err(|e| NavError::io(self.name.clone(), e))?;
            total += skipped as usize;
        }
        if total < expected {
            // Leave the caller a valid (empty) frame rather than a partial one.
            if got == w * h {
                let buf = std::mem::take(frame).into_vec();
                let mut buf = buf;
                buf.clear();
                *frame = GreyFrame::from_vec(0, 0, buf).unwrap_or_default();
            }
            self.finished = true;
            self.losses.frames += 1;
            self.losses.bytes += total as u64;
            return Err(NavError::ShortFrame {
                name: self.name.clone(),
                frame: index,
                expected,
                got: total,
            });
        }
        let t_s = if self.header.fps > 0.0 {
            index as f64 / self.header.fps
        } else {
            0.0
        };
        Ok(Some(FrameMeta { index, t_s }))
    }

    fn describe(&self) -> String {
        format!(
            "{} (YUV4MPEG2 {}×{}, {:?}, {:.2} fps)",
            self.name, self.header.width, self.header.height, self.header.chroma, self.header.fps
        )
    }

    fn frame_rate_hz(&self) -> Option<f64> {
        (self.header.fps > 0.0).then_some(self.header.fps)
    }
}

/// Writes a YUV4MPEG2 stream: grey frames as `C mono`, colour frames as `C 420jpeg`.
#[derive(Debug)]
pub struct Y4mWriter<W: Write> {
    writer: W,
    width: usize,
    height: usize,
    chroma: Y4mChroma,
    /// Scratch for the chroma planes (colour streams only).
    chroma_buf: Vec<u8>,
}

impl<W: Write> Y4mWriter<W> {
    /// Write the stream header. `fps` is written as an integer ratio `F<fps·1000>:1000`.
    pub fn new(
        mut writer: W,
        width: usize,
        height: usize,
        fps: f64,
        chroma: Y4mChroma,
    ) -> io::Result<Self> {
        let c = match chroma {
            Y4mChroma::Mono => "mono",
            Y4mChroma::C420 => "420jpeg",
        };
        let fps_milli = (fps * 1000.0).round().max(1.0) as u64;
        writeln!(
            writer,
            "YUV4MPEG2 W{width} H{height} F{fps_milli}:1000 Ip A1:1 C{c}"
        )?;
        let chroma_len = 2 * width.div_ceil(2) * height.div_ceil(2);
        let chroma_buf = match chroma {
            Y4mChroma::Mono => Vec::new(),
            Y4mChroma::C420 => vec![128; chroma_len],
        };
        Ok(Y4mWriter {
            writer,
            width,
            height,
            chroma,
            chroma_buf,
        })
    }

    /// Append a grey frame (`width × height` bytes). In a colour stream the chroma is neutral.
    pub fn write_grey(&mut self, grey: &[u8]) -> io::Result<()> {
        if grey.len() != self.width * self.height {
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                format!(
                    "frame of {} bytes, stream frames are {}",
                    grey.len(),
                    self.width * self.height
                ),
            ));
        }
        self.writer.write_all(b"FRAME\n")?;
        self.writer.write_all(grey)?;
        if self.chroma == Y4mChroma::C420 {
            self.chroma_buf.fill(128);
            self.writer.write_all(&self.chroma_buf)?;
        }
        Ok(())
    }

    /// Append an RGB frame (`width × height × 3` bytes), converted with BT.601 full-range
    /// (JPEG) coefficients; chroma is averaged over 2×2 blocks. In a mono stream only Y is kept.
    pub fn write_rgb(&mut self, rgb: &[u8], luma_scratch: &mut Vec<u8>) -> io::Result<()> {
        let (w, h) = (self.width, self.height);
        if rgb.len() != w * h * 3 {
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                format!(
                    "RGB frame of {} bytes, stream frames need {}",
                    rgb.len(),
                    w * h * 3
                ),
            ));
        }
        luma_scratch.resize(w * h, 0);
        for (y, px) in luma_scratch.iter_mut().zip(rgb.chunks_exact(3)) {
            let (r, g, b) = (f32::from(px[0]), f32::from(px[1]), f32::from(px[2]));
            *y = (0.299 * r + 0.587 * g + 0.114 * b)
                .round()
                .clamp(0.0, 255.0) as u8;
        }
        self.writer.write_all(b"FRAME\n")?;
        self.writer.write_all(luma_scratch)?;
        if self.chroma == Y4mChroma::C420 {
            let (cw, ch) = (w.div_ceil(2), h.div_ceil(2));
            let (cb_plane, cr_plane) = self.chroma_buf.split_at_mut(cw * ch);
            for cy in 0..ch {
                for cx in 0..cw {
                    let (mut cb, mut cr, mut n) = (0.0f32, 0.0f32, 0.0f32);
                    for y in (2 * cy)..(2 * cy + 2).min(h) {
                        for x in (2 * cx)..(2 * cx + 2).min(w) {
                            let i = 3 * (y * w + x);
                            let (r, g, b) = (
                                f32::from(rgb[i]),
                                f32::from(rgb[i + 1]),
                                f32::from(rgb[i + 2]),
                            );
                            cb += 128.0 - 0.168_736 * r - 0.331_264 * g + 0.5 * b;
                            cr += 128.0 + 0.5 * r - 0.418_688 * g - 0.081_312 * b;
                            n += 1.0;
                        }
                    }
                    cb_plane[cy * cw + cx] = (cb / n).round().clamp(0.0, 255.0) as u8;
                    cr_plane[cy * cw + cx] = (cr / n).round().clamp(0.0, 255.0) as u8;
                }
            }
            self.writer.write_all(&self.chroma_buf)?;
        }
        Ok(())
    }

    /// Flush and return the inner writer.
    pub fn finish(mut self) -> io::Result<W> {
        self.writer.flush()?;
        Ok(self.writer)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn stream(header: &str, frames: &[&[u8]]) -> Vec<u8> {
        let mut s = header.as_bytes().to_vec();
        s.push(b'\n');
        for f in frames {
            s.extend_from_slice(b"FRAME\n");
            s.extend_from_slice(f);
        }
        s
    }

    #[test]
    fn mono_frames_are_read_in_order_with_time_stamps() {
        let f0: Vec<u8> = (0..12).collect();
        let f1: Vec<u8> = (100..112).collect();
        let s = stream("YUV4MPEG2 W4 H3 F25:1 Ip A1:1 Cmono", &[&f0, &f1]);
        let mut src = Y4mSource::new(&s[..], "t").unwrap();
        let mut frame = GreyFrame::default();
        let m0 = src.next_frame(&mut frame).unwrap().unwrap();
        assert_eq!((frame.width(), frame.height()), (4, 3));
        assert_eq!(frame.data(), f0);
        assert_eq!(m0.index, 0);
        let m1 = src.next_frame(&mut frame).unwrap().unwrap();
        assert_eq!(frame.data(), f1);
        assert_eq!(m1.index, 1);
        assert!((m1.t_s - 0.04).abs() < 1e-12);
        assert!(src.next_frame(&mut frame).unwrap().is_none());
    }

    #[test]
    fn every_420_variant_yields_the_y_plane_and_skips_chroma() {
        // 5×3 → chroma planes 3×2 each.
        for c in ["", " C420", " C420jpeg", " C420paldv", " C420mpeg2"] {
            let mut f0: Vec<u8> = (0..15).collect();
            f0.extend(std::iter::repeat_n(200u8, 12));
            let mut f1: Vec<u8> = (50..65).collect();
            f1.extend(std::iter::repeat_n(7u8, 12));
            let s = stream(&format!("YUV4MPEG2 W5 H3 F30000:1001{c}"), &[&f0, &f1]);
            let mut src = Y4mSource::new(&s[..], "t").unwrap();
            assert_eq!(src.header().chroma, Y4mChroma::C420, "chroma tag {c:?}");
            let mut frame = GreyFrame::default();
            src.next_frame(&mut frame).unwrap().unwrap();
            assert_eq!(
                frame.data(),
                (0..15).collect::<Vec<u8>>(),
                "chroma tag {c:?}"
            );
            src.next_frame(&mut frame).unwrap().unwrap();
            assert_eq!(
                frame.data(),
                (50..65).collect::<Vec<u8>>(),
                "chroma tag {c:?}"
            );
            assert!(src.next_frame(&mut frame).unwrap().is_none());
        }
    }

    #[test]
    fn frame_parameters_after_frame_are_accepted() {
        let s = b"YUV4MPEG2 W2 H1 Cmono\nFRAME Ixyz\n\x01\x02".to_vec();
        let mut src = Y4mSource::new(&s[..], "t").unwrap();
        let mut frame = GreyFrame::default();
        src.next_frame(&mut frame).unwrap().unwrap();
        assert_eq!(frame.data(), vec![1, 2]);
    }

    #[test]
    fn bad_headers_are_typed_errors_naming_the_stream() {
        let cases: &[(&[u8], &str)] = &[
            (b"", "empty"),
            (b"YUV4MPEG W4 H3\n", "magic"),
            (b"YUV4MPEG2 H3 Cmono\n", "width"),
            (b"YUV4MPEG2 W4 Cmono\n", "height"),
            (b"YUV4MPEG2 Wx H3\n", "width"),
            (b"YUV4MPEG2 W4 H3 Fabc\n", "frame rate"),
            (b"YUV4MPEG2 W4 H3 Q9\n", "unknown tag"),
            (b"\xff\xfe\n", "ASCII"),
        ];
        for (bytes, what) in cases {
            let err = Y4mSource::new(*bytes, "clip.y4m").unwrap_err();
            let msg = err.to_string();
            assert!(matches!(err, NavError::Y4mHeader { .. }), "{msg}");
            assert!(
                msg.contains("clip.y4m") && msg.contains(what),
                "{msg} lacks {what}"
            );
            assert!(err.is_fatal());
        }
    }

    #[test]
    fn zero_size_is_refused() {
        let err = Y4mSource::new(&b"YUV4MPEG2 W0 H240 Cmono\n"[..], "z.y4m").unwrap_err();
        assert!(
            matches!(
                err,
                NavError::ZeroSize {
                    width: 0,
                    height: 240,
                    ..
                }
            ),
            "{err}"
        );
    }

    #[test]
    fn unsupported_chroma_is_named() {
        for c in ["422", "444", "444alpha", "411", "mono16", "420p10"] {
            let err =
                Y4mSource::new(format!("YUV4MPEG2 W4 H2 C{c}\n").as_bytes(), "c.y4m").unwrap_err();
            match &err {
                NavError::UnsupportedChroma { chroma, name } => {
                    assert_eq!(chroma, c);
                    assert_eq!(name, "c.y4m");
                }
                other => panic!("C{c}: {other}"),
            }
        }
    }

    #[test]
    fn short_last_frame_is_reported_non_fatal_then_the_stream_ends() {
        let mut s = stream("YUV4MPEG2 W4 H3 Cmono", &[&[9u8; 12]]);
        s.extend_from_slice(b"FRAME\n");
        s.extend_from_slice(&[1u8; 5]);
        let mut src = Y4mSource::new(&s[..], "short.y4m").unwrap();
        let mut frame = GreyFrame::default();
        assert!(src.next_frame(&mut frame).unwrap().is_some());
        let err = src.next_frame(&mut frame).unwrap_err();
        assert!(
            matches!(
                err,
                NavError::ShortFrame {
                    frame: 1,
                    expected: 12,
                    got: 5,
                    ..
                }
            ),
            "{err}"
        );
        assert!(!err.is_fatal());
        assert!(err.to_string().contains("short.y4m"));
        assert!(src.next_frame(&mut frame).unwrap().is_none());
    }

    #[test]
    fn short_chroma_in_a_420_frame_is_a_short_frame() {
        let mut s = b"YUV4MPEG2 W2 H2 C420jpeg\nFRAME\n".to_vec();
        s.extend_from_slice(&[1, 2, 3, 4, 128]); // Y plane + 1 of 2 chroma bytes
        let mut src = Y4mSource::new(&s[..], "t").unwrap();
        let err = src.next_frame(&mut GreyFrame::default()).unwrap_err();
        assert!(
            matches!(
                err,
                NavError::ShortFrame {
                    expected: 6,
                    got: 5,
                    ..
                }
            ),
            "{err}"
        );
    }

    /// Frames `0..n` of 4×3 mono, frame `i` filled with `i`.
    fn numbered(n: u8) -> Vec<u8> {
        let frames: Vec<Vec<u8>> = (0..n).map(|i| vec![i; 12]).collect();
        let refs: Vec<&[u8]> = frames.iter().map(Vec::as_slice).collect();
        stream("YUV4MPEG2 W4 H3 F25:1 Cmono", &refs)
    }

    /// Byte offset of frame `i`'s `FRAME` line in [`numbered`] (header 28 bytes, records 18).
    fn record(i: usize) -> usize {
        "YUV4MPEG2 W4 H3 F25:1 Cmono\n".len() + i * 18
    }

    /// Everything a source yields: delivered (index, first pixel), and the errors.
    fn drain<R: BufRead>(src: &mut Y4mSource<R>) -> (Vec<(u64, u8)>, Vec<NavError>) {
        let (mut frames, mut errors) = (Vec::new(), Vec::new());
        let mut frame = GreyFrame::default();
        for _ in 0..1000 {
            match src.next_frame(&mut frame) {
                Ok(Some(m)) => {
                    assert_eq!(frame.data().len(), frame.width() * frame.height());
                    frames.push((m.index, frame.data()[0]));
                }
                Ok(None) => return (frames, errors),
                Err(e) => {
                    assert!(!e.is_fatal(), "{e}");
                    errors.push(e);
                }
            }
        }
        panic!("source never ended");
    }

    #[test]
    fn a_flipped_byte_in_a_frame_header_loses_that_frame_only() {
        for offset in 0..6 {
            let mut s = numbered(8);
            s[record(3) + offset] ^= 0x20;
            let mut src = Y4mSource::new(&s[..], "flip.y4m").unwrap();
            let (frames, errors) = drain(&mut src);
            let want: Vec<(u64, u8)> = [0u8, 1, 2, 4, 5, 6, 7]
                .iter()
                .map(|&i| (u64::from(i), i))
                .collect();
            assert_eq!(frames, want, "byte {offset} of the header flipped");
            assert_eq!(errors.len(), 1);
            assert!(
                matches!(
                    errors[0],
                    NavError::Y4mResync {
                        frame: 3,
                        lost_frames: 1,
                        skipped_bytes: 18,
                        end_of_stream: false,
                        ..
                    }
                ),
                "{}",
                errors[0]
            );
            let msg = errors[0].to_string();
            assert!(msg.contains("flip.y4m") && msg.contains("frame 3"), "{msg}");
            assert_eq!(
                src.losses(),
                Y4mLosses {
                    frames: 1,
                    bytes: 18,
                    resyncs: 1
                }
            );
            // Time stamps stay those of the true indices.
            let mut src = Y4mSource::new(&s[..], "flip.y4m").unwrap();
            let mut frame = GreyFrame::default();
            let mut last = None;
            loop {
                match src.next_frame(&mut frame) {
                    Ok(Some(m)) => last = Some(m),
                    Ok(None) => break,
                    Err(_) => {}
                }
            }
            let last = last.unwrap();
            assert_eq!(last.index, 7);
            assert!((last.t_s - 7.0 / 25.0).abs() < 1e-12);
        }
    }

    #[test]
    fn garbage_of_several_frames_is_skipped_and_counted() {
        let mut s = numbered(10);
        // Frames 2, 3, 4 wholly overwritten with junk (no marker in it).
        for b in &mut s[record(2)..record(5)] {
            *b = b'x';
        }
        let mut src = Y4mSource::new(&s[..], "g.y4m").unwrap();
        let (frames, errors) = drain(&mut src);
        let idx: Vec<u64> = frames.iter().map(|f| f.0).collect();
        assert_eq!(idx, vec![0, 1, 5, 6, 7, 8, 9]);
        assert!(frames.iter().all(|&(i, v)| u64::from(v) == i));
        assert!(
            matches!(
                errors[..],
                [NavError::Y4mResync {
                    frame: 2,
                    lost_frames: 3,
                    skipped_bytes: 54,
                    ..
                }]
            ),
            "{errors:?}"
        );
    }

    #[test]
    fn a_frame_cut_short_mid_stream_costs_the_next_frame_and_indices_stay_true() {
        let mut s = numbered(8);
        // Frame 2 loses 5 of its 12 bytes: it swallows frame 3's `FRAME` line.
        s.drain(record(2) + 6..record(2) + 11);
        let mut src = Y4mSource::new(&s[..], "cut.y4m").unwrap();
        let (frames, errors) = drain(&mut src);
        let idx: Vec<u64> = frames.iter().map(|f| f.0).collect();
        assert_eq!(idx, vec![0, 1, 2, 4, 5, 6, 7]);
        assert!(frames[3..].iter().all(|&(i, v)| u64::from(v) == i));
        assert!(
            matches!(
                errors[..],
                [NavError::Y4mResync {
                    frame: 3,
                    lost_frames: 1,
                    ..
                }]
            ),
            "{errors:?}"
        );
    }

    #[test]
    fn damage_at_the_start_and_at_the_end_is_counted() {
        let mut s = numbered(5);
        s[record(0)] = b'G';
        s[record(4) + 2] = b'?';
        let mut src = Y4mSource::new(&s[..], "e.y4m").unwrap();
        let (frames, errors) = drain(&mut src);
        assert_eq!(
            frames.iter().map(|f| f.0).collect::<Vec<_>>(),
            vec![1, 2, 3]
        );
        assert!(
            matches!(
                errors[..],
                [
                    NavError::Y4mResync {
                        frame: 0,
                        lost_frames: 1,
                        end_of_stream: false,
                        ..
                    },
                    NavError::Y4mResync {
                        frame: 4,
                        lost_frames: 1,
                        skipped_bytes: 18,
                        end_of_stream: true,
                        ..
                    }
                ]
            ),
            "{errors:?}"
        );
        assert_eq!(src.losses().frames, 2);
    }

    #[test]
    fn a_huge_declared_frame_over_a_short_stream_allocates_what_is_there() {
        let mut s = b"YUV4MPEG2 W30000 H30000 Cmono\nFRAME\n".to_vec();
        s.extend_from_slice(&[7; 1000]);
        let mut src = Y4mSource::new(&s[..], "big.y4m").unwrap();
        let mut frame = GreyFrame::default();
        let err = src.next_frame(&mut frame).unwrap_err();
        assert!(
            matches!(err, NavError::ShortFrame { got: 1000, .. }),
            "{err}"
        );
        assert!(frame.capacity() <= 1 << 21, "{}", frame.capacity());
        assert_eq!(
            (frame.width(), frame.height(), frame.data().len()),
            (0, 0, 0)
        );
    }

    #[test]
    fn concatenated_streams_of_the_same_size_continue_and_a_new_size_is_an_error() {
        let mut same = stream("YUV4MPEG2 W2 H1 Cmono", &[&[1, 2]]);
        same.extend(stream("YUV4MPEG2 W2 H1 Cmono", &[&[3, 4]]));
        let mut src = Y4mSource::new(&same[..], "s").unwrap();
        let mut frame = GreyFrame::default();
        src.next_frame(&mut frame).unwrap().unwrap();
        let m = src.next_frame(&mut frame).unwrap().unwrap();
        assert_eq!((m.index, frame.data()), (1, &[3u8, 4][..]));

        let mut changed = stream("YUV4MPEG2 W2 H1 Cmono", &[&[1, 2]]);
        changed.extend(stream("YUV4MPEG2 W3 H1 Cmono", &[&[3, 4, 5]]));
        let mut src = Y4mSource::new(&changed[..], "c.y4m").unwrap();
        src.next_frame(&mut frame).unwrap().unwrap();
        let err = src.next_frame(&mut frame).unwrap_err();
        assert!(
            matches!(
                err,
                NavError::SizeChanged {
                    frame: 1,
                    from_w: 2,
                    to_w: 3,
                    ..
                }
            ),
            "{err}"
        );
        assert!(err.is_fatal());
    }

    #[test]
    fn writer_round_trips_grey_and_colour_streams() {
        let grey: Vec<u8> = (0..15).map(|i| i * 10).collect();
        for chroma in [Y4mChroma::Mono, Y4mChroma::C420] {
            let mut w = Y4mWriter::new(Vec::new(), 5, 3, 25.0, chroma).unwrap();
            w.write_grey(&grey).unwrap();
            let rgb: Vec<u8> = grey.iter().flat_map(|&g| [g, g, g]).collect();
            w.write_rgb(&rgb, &mut Vec::new()).unwrap();
            let bytes = w.finish().unwrap();
            let mut src = Y4mSource::new(&bytes[..], "rt").unwrap();
            assert_eq!(src.header().chroma, chroma);
            assert!((src.frame_rate_hz().unwrap() - 25.0).abs() < 1e-9);
            let mut frame = GreyFrame::default();
            src.next_frame(&mut frame).unwrap().unwrap();
            assert_eq!(frame.data(), grey);
            src.next_frame(&mut frame).unwrap().unwrap();
            assert_eq!(frame.data(), grey, "grey RGB → Y is the identity");
            assert!(src.next_frame(&mut frame).unwrap().is_none());
        }
    }

    #[test]
    fn writer_refuses_a_frame_of_the_wrong_size() {
        let mut w = Y4mWriter::new(Vec::new(), 4, 4, 30.0, Y4mChroma::Mono).unwrap();
        assert!(w.write_grey(&[0; 15]).is_err());
        assert!(w.write_rgb(&[0; 47], &mut Vec::new()).is_err());
    }
}
