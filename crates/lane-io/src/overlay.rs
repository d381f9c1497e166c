//! Annotated frames: edge points, windows of interest and fitted parabolas over the grey frame,
//! written as a PNG directory or a colour `.y4m`.

use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

use crate::y4m::{Y4mChroma, Y4mWriter};
use lane_tracker::{GreyFrame, LaneState, LaneTracker, Side};

use crate::LaneIoError;

const WINDOW_RGB: [[u8; 3]; 2] = [[120, 120, 0], [0, 110, 130]];
const POINT_RGB: [[u8; 3]; 2] = [[255, 230, 0], [0, 230, 255]];
const CURVE_RGB: [[u8; 3]; 2] = [[255, 40, 40], [60, 90, 255]];
const COAST_RGB: [u8; 3] = [255, 140, 0];

/// Draw the tracker's last frame into `rgb` (`width·height·3` bytes, reshaped): the grey frame,
/// each lane's window borders, its points, and its parabola over the ROI rows (left red, right
/// blue; orange while coasting).
pub fn render_overlay(frame: &GreyFrame, tracker: &LaneTracker, rgb: &mut Vec<u8>) {
    let (w, h) = (frame.width(), frame.height());
    rgb.resize(w * h * 3, 0);
    for (px, &g) in rgb.chunks_exact_mut(3).zip(frame.data().iter()) {
        px.copy_from_slice(&[g, g, g]);
    }
    let mut put = |x: i64, y: i64, c: [u8; 3]| {
        if x >= 0 && y >= 0 && (x as usize) < w && (y as usize) < h {
            let i = 3 * (y as usize * w + x as usize);
            rgb[i..i + 3].copy_from_slice(&c);
        }
    };
    let (top, bottom) = tracker.roi_rows();
    for (k, side) in [Side::Left, Side::Right].into_iter().enumerate() {
        let view = tracker.lane_view(side);
        for (row, span) in view.spans.iter().enumerate() {
            if span.col_end_px > span.col_start_px {
                put(i64::from(span.col_start_px), row as i64, WINDOW_RGB[k]);
                put(i64::from(span.col_end_px) - 1, row as i64, WINDOW_RGB[k]);
            }
        }
        for &(x, y) in view.points {
            put(x as i64, y as i64, POINT_RGB[k]);
        }
        if view.report.coeffs.is_some() {
            let colour = if view.report.state == LaneState::Coasting {
                COAST_RGB
            } else {
                CURVE_RGB[k]
            };
            let mut prev: Option<i64> = None;
            for row in top..bottom {
                let Some(x) = view.report.col_at_row(row as f64) else {
                    break;
                };
                if !x.is_finite() {
                    break;
                }
                let x = x.round() as i64;
                // Join consecutive rows so shallow curves stay continuous.
                let (a, b) = match prev {
                    Some(p) if (p - x).abs() > 1 => (p.min(x), p.max(x)),
                    _ => (x, x),
                };
                for xx in a..=b {
                    put(xx, row as i64, colour);
                    put(xx + 1, row as i64, colour);
                }
                prev = Some(x);
            }
        }
    }
}

/// Where annotated frames go.
#[derive(Debug)]
pub enum OverlaySink {
    /// `frame_000123.png` files in a directory.
    PngDir {
        /// The directory (created if missing).
        dir: PathBuf,
    },
    /// A colour YUV4MPEG2 file (`C420jpeg`).
    Y4m {
        /// Path, for errors.
        path: String,
        /// The writer (created on the first frame, when the size is known).
        writer: Option<Y4mWriter<BufWriter<File>>>,
        /// Frame rate written in the header, frames/s.
        fps: f64,
        /// Scratch for the luma plane.
        luma: Vec<u8>,
    },
}

impl OverlaySink {
    /// A `.y4m` path gives a colour stream, anything else a PNG directory.
    pub fn open(path: &Path, fps: f64) -> Result<Self, LaneIoError> {
        let name = path.display().to_string();
        if path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("y4m"))
        {
            return Ok(OverlaySink::Y4m {
                path: name,
                writer: None,
                fps,
                luma: Vec::new(),
            });
        }
        std::fs::create_dir_all(path).map_err(|e| LaneIoError::io(name, e))?;
        Ok(OverlaySink::PngDir {
            dir: path.to_owned(),
        })
    }

    /// Write one annotated frame (`rgb` as filled by [`render_overlay`]).
    pub fn write(
        &mut self,
        index: u64,
        rgb: &[u8],
        width: usize,
        height: usize,
    ) -> Result<(), LaneIoError> {
        match self {
            OverlaySink::PngDir { dir } => {
                let path = dir.join(format!("frame_{index:06}.png"));
                image::save_buffer(
                    &path,
                    rgb,
                    width as u32,
                    height as u32,
                    image::ExtendedColorType::Rgb8,
                )
                .map_err(|source| LaneIoError::WriteImage {
                    path: path.display().to_string(),
                    source,
                })
            }
            OverlaySink::Y4m {
                path,
                writer,
                fps,
                luma,
            } => {
                let werr = |source: std::io::Error| LaneIoError::Write {
                    path: path.clone(),
                    source,
                };
                if writer.is_none() {
                    let file = File::create(&*path).map_err(werr)?;
                    *writer = Some(
                        Y4mWriter::new(BufWriter::new(file), width, height, *fps, Y4mChroma::C420)
                            .map_err(werr)?,
                    );
                }
                match writer.as_mut() {
                    Some(w) => w.write_rgb(rgb, luma).map_err(werr),
                    None => Ok(()),
                }
            }
        }
    }

    /// Flush (for `.y4m`).
    pub fn finish(self) -> Result<(), LaneIoError> {
        if let OverlaySink::Y4m {
            path,
            writer: Some(w),
            ..
        } = self
        {
            w.finish()
                .map_err(|source| LaneIoError::Write { path, source })?;
        }
        Ok(())
    }
}
