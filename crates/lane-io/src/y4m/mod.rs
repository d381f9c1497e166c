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
//! [`LaneIoError::SizeChanged`] otherwise.
//!
//! A stream damaged where a `FRAME` header is expected (a flipped byte, a frame cut short, junk)
//! is resynchronised at the next `FRAME` marker: the frames lost are reported once as a
//! non-fatal [`LaneIoError::Y4mResync`] and totalled in [`Y4mSource::losses`]; see [`Y4mSource`]
//! for how they are counted.

use std::io::{self, BufRead, Read, Write};

use lane_tracker::GreyFrame;

use crate::{FrameMeta, FrameSource, LaneIoError};

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
    pub fn parse(name: &str, line: &[u8]) -> Result<Self, LaneIoError> {
        let bad = |reason: String| LaneIoError::Y4mHeader {
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
            // A token whose first character is not ASCII has no tag: the whole token is
            // refused below as an unknown tag (splitting inside a character would panic).
            let (tag, value) = token.split_at_checked(1).unwrap_or((token, ""));
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
                            return Err(LaneIoError::UnsupportedChroma {
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
            return Err(LaneIoError::ZeroSize {
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
fn read_line<R: BufRead>(
    reader: &mut R,
    line: &mut Vec<u8>,
    name: &str,
) -> Result<bool, LaneIoError> {
    line.clear();
    loop {
        let available = match reader.fill_buf() {
            Ok(b) => b,
            Err(e) if e.kind() == io::ErrorKind::Interrupted => continue,
            Err(e) => return Err(LaneIoError::io(name, e)),
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
    /// Resynchronisations (each one a [`LaneIoError::Y4mResync`] returned by `next_frame`).
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
/// [`LaneIoError::Y4mResync`] before the frame after the marker. The frames lost are counted as
/// `⌈D / L⌉`, with `L` the length of one frame record (its `FRAME` line and planes, as of the
/// last good header): exact when damage replaces or drops bytes (bit flips, a frame cut short,
/// lost packets) — the marker found is then the `⌈D/L⌉ + 1`-th after the last good frame, and
/// the frame indices (and time stamps) after the damage are the true ones. Inserted bytes can make
/// the count one too high. A frame that was cut short mid-stream swallows the next frame's header
/// into its planes and is delivered (damaged), and the frame whose header it swallowed is lost:
/// without reading ahead — which would delay every frame of a live pipe by one — the reader
/// cannot tell a short frame from good pixels. A short **last** frame is a non-fatal
/// [`LaneIoError::ShortFrame`]. [`Y4mSource::losses`] keeps the totals.
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
    pub fn new(mut reader: R, name: impl Into<String>) -> Result<Self, LaneIoError> {
        let name = name.into();
        let mut line = Vec::with_capacity(128);
        if !read_line(&mut reader, &mut line, &name)? {
            return Err(LaneIoError::Y4mHeader {
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
    fn sync(&mut self) -> Result<(Marker, u64), LaneIoError> {
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
                Err(e) => return Err(LaneIoError::io(self.name.clone(), e)),
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
    fn next_frame_line(&mut self) -> Result<(bool, u64), LaneIoError> {
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
                        return Err(LaneIoError::SizeChanged {
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
    fn next_frame(&mut self, frame: &mut GreyFrame) -> Result<Option<FrameMeta>, LaneIoError> {
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
                return Err(LaneIoError::Y4mResync {
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
                    GreyFrame::from_vec(w, h, buf).map_err(|source| LaneIoError::FrameBuffer {
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
                return Err(LaneIoError::io(self.name.clone(), e));
            }
        };
        let mut total = got;
        if got == w * h {
            let chroma = (expected - got) as u64;
            let skipped = io::copy(&mut (&mut self.reader).take(chroma), &mut io::sink())
                .map_err(|e| LaneIoError::io(self.name.clone(), e))?;
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
            return Err(LaneIoError::ShortFrame {
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
    /// (JPEG) coefficients (luma: [`grey_frame::luma_bt601`], the workspace's one conversion); chroma is averaged over 2×2 blocks. In a mono stream only Y is kept.
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
            *y = grey_frame::luma_bt601(px[0], px[1], px[2]);
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
mod tests;
