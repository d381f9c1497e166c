//! Still images, directories of images, and the `--input` / `--device` dispatch.

use std::fs::File;
use std::io::{BufReader, Read};
use std::path::{Path, PathBuf};

use crate::y4m::Y4mSource;
use lane_tracker::GreyFrame;

use crate::{FrameMeta, FrameSource, LaneIoError};

/// File extensions taken as images (case-insensitive).
pub const IMAGE_EXTENSIONS: &[&str] = &["png", "jpg", "jpeg", "pgm", "pnm", "ppm"];

fn is_image_path(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| IMAGE_EXTENSIONS.iter().any(|x| x.eq_ignore_ascii_case(e)))
}

/// Decode an image file (PNG, JPEG, PGM/PNM, by content) into a grey frame. A grey image is taken
/// as it is; colour is converted with BT.601 luma, `Y' = 0.299 R' + 0.587 G' + 0.114 B'`
/// ([`bt848_capture::convert::luma_bt601`]), the conversion of capture and of y4m (whose Y plane is
/// BT.601), so one scene gives one grey whatever the input kind.
///
/// Errors: [`LaneIoError::Io`] when the file cannot be read, [`LaneIoError::ImageDecode`] when it is
/// truncated or corrupt, [`LaneIoError::ZeroSize`].
pub fn decode_image_file(path: &Path, frame: &mut GreyFrame) -> Result<(), LaneIoError> {
    let name = path.display().to_string();
    let mut bytes = Vec::new();
    File::open(path)
        .and_then(|mut f| f.read_to_end(&mut bytes))
        .map_err(|e| LaneIoError::io(name.clone(), e))?;
    decode_image_bytes(&name, &bytes, frame)
}

/// Decode an in-memory image (see [`decode_image_file`]); `name` is used in errors.
pub fn decode_image_bytes(
    name: &str,
    bytes: &[u8],
    frame: &mut GreyFrame,
) -> Result<(), LaneIoError> {
    let img = image::load_from_memory(bytes).map_err(|source| LaneIoError::ImageDecode {
        path: name.to_owned(),
        source,
    })?;
    let (w, h) = (img.width() as usize, img.height() as usize);
    if w == 0 || h == 0 {
        return Err(LaneIoError::ZeroSize {
            name: name.to_owned(),
            width: w,
            height: h,
        });
    }
    frame
        .reshape(w, h)
        .map_err(|source| LaneIoError::FrameBuffer {
            name: name.to_owned(),
            source,
        })?;
    if img.color().has_color() {
        let rgb = img.into_rgb8();
        for (y, p) in frame
            .data_mut()
            .iter_mut()
            .zip(rgb.as_raw().chunks_exact(3))
        {
            *y = bt848_capture::convert::luma_bt601(p[0], p[1], p[2]);
        }
    } else {
        // Grey (with or without alpha, 8 or 16 bit): its luma as it is.
        frame.data_mut().copy_from_slice(img.into_luma8().as_raw());
    }
    Ok(())
}

/// One still image as a one-frame sequence. A bad image is fatal (there is nothing else to run).
#[derive(Debug)]
pub struct StillImage {
    path: PathBuf,
    done: bool,
}

impl StillImage {
    /// A source delivering the image at `path` once. The file is read on the first `next_frame`.
    pub fn new(path: impl Into<PathBuf>) -> Self {
        StillImage {
            path: path.into(),
            done: false,
        }
    }
}

impl FrameSource for StillImage {
    fn next_frame(&mut self, frame: &mut GreyFrame) -> Result<Option<FrameMeta>, LaneIoError> {
        if self.done {
            return Ok(None);
        }
        self.done = true;
        decode_image_file(&self.path, frame)?;
        Ok(Some(FrameMeta { index: 0, t_s: 0.0 }))
    }

    fn describe(&self) -> String {
        format!("{} (still image)", self.path.display())
    }
}

/// A directory of images, read in file-name order as a sequence.
///
/// Opening fails ([`LaneIoError::NotAnImage`]) if the directory holds a regular file without an
/// image extension (hidden files, starting with `.`, and sub-directories are ignored), and
/// ([`LaneIoError::EmptyDirectory`]) if it holds no image. While reading, an image that cannot be
/// decoded is a non-fatal [`LaneIoError::BadFrame`] (holding the decoding error), one whose size
/// differs from the first frame's a non-fatal [`LaneIoError::FrameSizeDiffers`]: reported,
/// counted and skipped.
#[derive(Debug)]
pub struct ImageDirectory {
    dir: PathBuf,
    files: Vec<PathBuf>,
    next: usize,
    size: Option<(usize, usize)>,
    fps: f64,
    scratch: GreyFrame,
}

impl ImageDirectory {
    /// List `dir`; `fps` (frames/s, > 0) sets the time stamps.
    pub fn open(dir: impl Into<PathBuf>, fps: f64) -> Result<Self, LaneIoError> {
        let dir = dir.into();
        let name = dir.display().to_string();
        let entries = std::fs::read_dir(&dir).map_err(|e| LaneIoError::io(name.clone(), e))?;
        let mut files = Vec::new();
        for entry in entries {
            let entry = entry.map_err(|e| LaneIoError::io(name.clone(), e))?;
            let path = entry.path();
            let hidden = entry.file_name().to_string_lossy().starts_with('.');
            let is_dir = entry
                .file_type()
                .map_err(|e| LaneIoError::io(name.clone(), e))?
                .is_dir();
            if hidden || is_dir {
                continue;
            }
            if !is_image_path(&path) {
                return Err(LaneIoError::NotAnImage {
                    path: path.display().to_string(),
                });
            }
            files.push(path);
        }
        if files.is_empty() {
            return Err(LaneIoError::EmptyDirectory { path: name });
        }
        files.sort();
        Ok(ImageDirectory {
            dir,
            files,
            next: 0,
            size: None,
            fps,
            scratch: GreyFrame::default(),
        })
    }

    /// The image files, in the order they are delivered.
    pub fn files(&self) -> &[PathBuf] {
        &self.files
    }
}

impl FrameSource for ImageDirectory {
    fn next_frame(&mut self, frame: &mut GreyFrame) -> Result<Option<FrameMeta>, LaneIoError> {
        let Some(path) = self.files.get(self.next) else {
            return Ok(None);
        };
        let index = self.next as u64;
        self.next += 1;
        let name = || path.display().to_string();
        if let Err(e) = decode_image_file(path, &mut self.scratch) {
            return Err(LaneIoError::BadFrame {
                name: name(),
                frame: index,
                source: Box::new(e),
            });
        }
        let size = (self.scratch.width(), self.scratch.height());
        match self.size {
            None => self.size = Some(size),
            Some(first) if first != size => {
                return Err(LaneIoError::FrameSizeDiffers {
                    name: name(),
                    frame: index,
                    got_w: size.0,
                    got_h: size.1,
                    want_w: first.0,
                    want_h: first.1,
                });
            }
            Some(_) => {}
        }
        std::mem::swap(frame, &mut self.scratch);
        let t_s = if self.fps > 0.0 {
            index as f64 / self.fps
        } else {
            0.0
        };
        Ok(Some(FrameMeta { index, t_s }))
    }

    fn describe(&self) -> String {
        format!("{} ({} images)", self.dir.display(), self.files.len())
    }

    fn frame_rate_hz(&self) -> Option<f64> {
        (self.fps > 0.0).then_some(self.fps)
    }
}

/// Open `--input PATH`: `-` is a YUV4MPEG2 stream on stdin, a directory is an image sequence
/// (at `dir_fps` frames/s), a `.mcap` file is a ROS 2 bag read on its only image topic
/// ([`crate::mcap_source`]), a video file (by its extension, [`crate::video::VIDEO_EXTENSIONS`])
/// is decoded by ffmpeg ([`crate::video`]), a `.y4m` file (or any file starting with
/// `YUV4MPEG2`) is a stream, anything else a still image.
pub fn open_input(path: &Path, dir_fps: f64) -> Result<Box<dyn FrameSource>, LaneIoError> {
    if path.as_os_str() == "-" {
        let stdin = BufReader::with_capacity(1 << 16, std::io::stdin());
        return Ok(Box::new(Y4mSource::new(stdin, "stdin")?));
    }
    let name = path.display().to_string();
    let meta = std::fs::metadata(path).map_err(|e| LaneIoError::io(name.clone(), e))?;
    if meta.is_dir() {
        return Ok(Box::new(ImageDirectory::open(path, dir_fps)?));
    }
    if crate::mcap_source::is_mcap(path) {
        return Ok(Box::new(crate::mcap_source::McapImageSource::open(
            path, None,
        )?));
    }
    if crate::video::is_video(path) {
        return Ok(Box::new(crate::video::VideoSource::open(path)?));
    }
    let mut magic = [0u8; 9];
    let n = File::open(path)
        .and_then(|mut f| f.read(&mut magic))
        .map_err(|e| LaneIoError::io(name.clone(), e))?;
    let y4m_ext = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("y4m"));
    if y4m_ext || &magic[..n] == b"YUV4MPEG2" {
        let file = File::open(path).map_err(|e| LaneIoError::io(name.clone(), e))?;
        return Ok(Box::new(Y4mSource::new(
            BufReader::with_capacity(1 << 16, file),
            name,
        )?));
    }
    Ok(Box::new(StillImage::new(path)))
}

/// Open `--device PATH` with the default capture options (current input, NTSC-M, 320×240; see
/// [`crate::capture_source`] for the options and the per-frame device fields). Without the
/// `capture` feature always [`LaneIoError::CaptureUnavailable`].
pub fn open_device(path: &Path) -> Result<Box<dyn FrameSource>, LaneIoError> {
    crate::capture_source::open(path, &crate::capture_source::DeviceOptions::default())
        .map(|(source, _monitor)| source)
}
