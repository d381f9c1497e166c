//! Video files (MP4, MKV, AVI, MOV, WebM, …: whatever ffmpeg decodes) through `ffmpeg` as a
//! child process that writes grey YUV4MPEG2 into the crate's y4m reader, so its
//! resynchronisation and loss reporting apply unchanged.
//!
//! The child runs `ffmpeg -hide_banner -nostdin -v error -i FILE -map 0:v:0 -f yuv4mpegpipe
//! -pix_fmt gray -` (the first video stream, BT.601 luma). The frame rate comes from the stream
//! (the y4m header ffmpeg writes), and frame i is at i / rate. The binary is `ffmpeg` on the
//! `PATH`, or the file named by `$ITA_NAV_FFMPEG`. A missing ffmpeg is
//! [`LaneIoError::FfmpegMissing`]; a file ffmpeg cannot decode, or a decode that fails part-way,
//! is [`LaneIoError::VideoDecode`] with ffmpeg's own message. The child is always reaped: killed
//! and waited for when the source is dropped (`--max-frames`, an error, the end of the run); on
//! Ctrl-C the terminal's SIGINT reaches it too (same process group) and the parent's exit
//! leaves no zombie behind.

use std::io::{BufReader, Read};
use std::path::Path;
use std::process::{Child, ChildStdout, Command, Stdio};
use std::thread::JoinHandle;

use grey_frame::GreyFrame;

use crate::LaneIoError;
use crate::frame::{FrameMeta, FrameSource};
use crate::y4m::Y4mSource;

/// Extensions taken as video files (case-insensitive).
pub const VIDEO_EXTENSIONS: [&str; 14] = [
    "mp4", "m4v", "mkv", "webm", "avi", "mov", "mpg", "mpeg", "ts", "mts", "m2ts", "flv", "wmv",
    "ogv",
];

/// Environment variable naming the ffmpeg binary (default: `ffmpeg` on the `PATH`).
pub const FFMPEG_ENV: &str = "ITA_NAV_FFMPEG";

/// True when `path`'s extension is one of [`VIDEO_EXTENSIONS`].
pub fn is_video(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| VIDEO_EXTENSIONS.iter().any(|v| v.eq_ignore_ascii_case(e)))
}

/// The last lines ffmpeg wrote to stderr (at most this many bytes are kept).
const STDERR_KEEP: usize = 4096;

/// A video file decoded by an ffmpeg child process (module documentation).
#[derive(Debug)]
pub struct VideoSource {
    name: String,
    child: Child,
    stderr: Option<JoinHandle<String>>,
    y4m: Option<Y4mSource<BufReader<ChildStdout>>>,
    finished: bool,
}

fn ffmpeg_binary() -> std::ffi::OsString {
    std::env::var_os(FFMPEG_ENV).unwrap_or_else(|| "ffmpeg".into())
}

impl VideoSource {
    /// Starts ffmpeg on `path` and reads the stream header.
    ///
    /// # Errors
    /// [`LaneIoError::FfmpegMissing`] when ffmpeg cannot be started, [`LaneIoError::VideoDecode`]
    /// when it produces no stream (not a video, unsupported codec, unreadable file).
    pub fn open(path: &Path) -> Result<Self, LaneIoError> {
        let name = path.display().to_string();
        let program = ffmpeg_binary();
        let mut child = Command::new(&program)
            .args(["-hide_banner", "-nostdin", "-v", "error", "-i"])
            .arg(path)
            .args([
                "-map",
                "0:v:0",
                "-f",
                "yuv4mpegpipe",
                "-pix_fmt",
                "gray",
                "-",
            ])
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .map_err(|source| LaneIoError::FfmpegMissing {
                input: name.clone(),
                program: program.to_string_lossy().into_owned(),
                source,
            })?;
        // Drain stderr on a thread so that a chatty ffmpeg never blocks on a full pipe.
        let stderr = child.stderr.take().map(|mut err| {
            std::thread::spawn(move || {
                let mut text = String::new();
                let mut buf = [0u8; 1024];
                while let Ok(n) = err.read(&mut buf) {
                    if n == 0 {
                        break;
                    }
                    text.push_str(&String::from_utf8_lossy(&buf[..n]));
                    if text.len() > 2 * STDERR_KEEP {
                        let cut = text.len() - STDERR_KEEP;
                        let cut = (cut..text.len())
                            .find(|i| text.is_char_boundary(*i))
                            .unwrap_or(0);
                        text.drain(..cut);
                    }
                }
                text
            })
        });
        let mut source = VideoSource {
            name,
            child,
            stderr,
            y4m: None,
            finished: false,
        };
        let Some(stdout) = source.child.stdout.take() else {
            return Err(source.decode_error("ffmpeg's output pipe is missing", None));
        };
        match Y4mSource::new(
            BufReader::with_capacity(1 << 16, stdout),
            source.name.clone(),
        ) {
            Ok(y4m) => {
                source.y4m = Some(y4m);
                Ok(source)
            }
            Err(e) => Err(source.decode_error("no video stream", Some(e))),
        }
    }

    /// Waits for the child and turns its exit status and stderr into a decode error, with the
    /// reader's own error as its source where there is one.
    fn decode_error(&mut self, what: &str, source: Option<LaneIoError>) -> LaneIoError {
        let _ = self.child.kill();
        let status = self.child.wait().ok();
        let stderr = self
            .stderr
            .take()
            .and_then(|h| h.join().ok())
            .unwrap_or_default();
        LaneIoError::VideoDecode {
            input: self.name.clone(),
            reason: format!(
                "{what}{}{}",
                status.map_or(String::new(), |s| format!(" (ffmpeg {s})")),
                match stderr.trim() {
                    "" => String::new(),
                    text => format!(": {}", text.lines().last().unwrap_or(text)),
                }
            ),
            source: source.map(Box::new),
        }
    }

    /// The id of the ffmpeg child process.
    pub fn child_id(&self) -> u32 {
        self.child.id()
    }
}

impl FrameSource for VideoSource {
    fn next_frame(&mut self, frame: &mut GreyFrame) -> Result<Option<FrameMeta>, LaneIoError> {
        if self.finished {
            return Ok(None);
        }
        let Some(y4m) = self.y4m.as_mut() else {
            return Ok(None);
        };
        match y4m.next_frame(frame)? {
            Some(meta) => Ok(Some(meta)),
            None => {
                // End of ffmpeg's output: a clean end only if ffmpeg says so.
                self.finished = true;
                self.y4m = None;
                match self.child.wait() {
                    Ok(status) if status.success() => Ok(None),
                    _ => Err(self.decode_error("decoding stopped", None)),
                }
            }
        }
    }

    fn describe(&self) -> String {
        match &self.y4m {
            Some(y) => {
                let h = y.header();
                format!(
                    "{} (ffmpeg, {}×{} at {:.3} frames/s)",
                    self.name, h.width, h.height, h.fps
                )
            }
            None => format!("{} (ffmpeg)", self.name),
        }
    }

    fn frame_rate_hz(&self) -> Option<f64> {
        self.y4m.as_ref().and_then(|y| y.frame_rate_hz())
    }
}

impl Drop for VideoSource {
    fn drop(&mut self) {
        // Close our end first so that ffmpeg stops on a broken pipe if the kill is refused.
        self.y4m = None;
        let _ = self.child.kill();
        let _ = self.child.wait();
        if let Some(h) = self.stderr.take() {
            let _ = h.join();
        }
    }
}
