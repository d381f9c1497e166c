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
/// The Hough candidates of an initialisation, by angle band (`/` left, `\` right): dotted.
const CANDIDATE_RGB: [[u8; 3]; 2] = [[200, 90, 200], [90, 200, 120]];
/// Rows between two dots of a candidate's curve.
const CANDIDATE_DOT_ROWS: usize = 3;
/// The road region (`LaneTracker::road`): the road's bottom when it ends above the frame's
/// (a bonnet or a dashboard), and the horizon the lanes show; dashed across the frame.
const ROAD_BOTTOM_RGB: [u8; 3] = [255, 255, 0];
const HORIZON_RGB: [u8; 3] = [0, 255, 255];
/// Columns of a dash, and between two.
const DASH_PX: usize = 6;

/// Draw the tracker's last frame into `rgb` (`width·height·3` bytes, reshaped): the grey frame,
/// on a frame that ran the joint initialisation its Hough candidates (their least-squares
/// parabolas, or the lines themselves with `init.candidate_coverage` off; dotted: magenta the
/// `/` band, green the `\` band; `LaneTracker::init_candidates`),
/// then each lane's window borders, its points, and its parabola over the ROI rows (left red,
/// right blue; orange while coasting), and the road region: its bottom dashed yellow where a
/// bonnet or a dashboard ends it above the frame's last row, the horizon the lanes show dashed
/// cyan.
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
    let road = tracker.road();
    let lines = [
        (
            road.bottom_row_px - 1.0,
            ROAD_BOTTOM_RGB,
            road.bottom_row_px < h as f64,
        ),
        (
            road.horizon_row_px.unwrap_or(-1.0),
            HORIZON_RGB,
            road.horizon_row_px.is_some(),
        ),
    ];
    for (row, colour, shown) in lines {
        if shown && row.is_finite() {
            let y = row.round() as i64;
            for x in (0..w).filter(|x| (x / DASH_PX).is_multiple_of(2)) {
                put(x as i64, y, colour);
            }
        }
    }
    let (top, bottom) = tracker.roi_rows();
    for c in tracker.init_candidates() {
        let colour = CANDIDATE_RGB[usize::from(c.band == Side::Right)];
        for row in (top..bottom).step_by(CANDIDATE_DOT_ROWS) {
            let y = row as f64;
            let x = c.coeffs[0] * y * y + c.coeffs[1] * y + c.coeffs[2];
            if x.is_finite() {
                put(x.round() as i64, row as i64, colour);
            }
        }
    }
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

#[cfg(test)]
mod tests {
    use super::*;
    use lane_tracker::{Estimator, TrackerConfig};

    /// Two bright marks 5 px wide on a dark floor, `/` left and `\` right.
    fn two_marks(w: usize, h: usize) -> GreyFrame {
        let left = |y: f64| 100.0 - 0.45 * (y - 239.0);
        let right = |y: f64| 220.0 + 0.45 * (y - 239.0);
        let mut pixels = vec![60u8; w * h];
        for (i, p) in pixels.iter_mut().enumerate() {
            let (x, y) = ((i % w) as f64, (i / w) as f64);
            if (x - left(y)).abs() < 2.5 || (x - right(y)).abs() < 2.5 {
                *p = 200;
            }
        }
        GreyFrame::from_vec(w, h, pixels).expect("a whole frame")
    }

    fn count(rgb: &[u8], colour: [u8; 3]) -> usize {
        rgb.chunks_exact(3).filter(|px| *px == colour).count()
    }

    #[test]
    fn an_initialisation_frame_shows_its_candidates_and_a_tracking_frame_does_not() {
        let frame = two_marks(320, 240);
        let cfg = TrackerConfig::default_preset().expect("the default preset");
        let mut tracker = LaneTracker::new(&cfg, Estimator::Kif, 320, 240).expect("a tracker");
        let mut rgb = Vec::new();
        tracker.track(&frame).expect("a frame");
        assert!(!tracker.init_candidates().is_empty());
        render_overlay(&frame, &tracker, &mut rgb);
        // Both bands' candidates leave dots beside the lanes' own curves.
        assert!(count(&rgb, CANDIDATE_RGB[0]) > 0 && count(&rgb, CANDIDATE_RGB[1]) > 0);
        assert!(count(&rgb, CURVE_RGB[0]) > 0 && count(&rgb, CURVE_RGB[1]) > 0);
        tracker.track(&frame).expect("a frame");
        render_overlay(&frame, &tracker, &mut rgb);
        assert_eq!(
            count(&rgb, CANDIDATE_RGB[0]) + count(&rgb, CANDIDATE_RGB[1]),
            0
        );
        assert!(count(&rgb, CURVE_RGB[0]) > 0);
    }

    #[test]
    fn the_road_bottom_is_drawn_where_a_bonnet_ends_the_road_and_the_horizon_with_both_lanes() {
        let cfg = TrackerConfig::default_preset().expect("the default preset");
        let mut tracker = LaneTracker::new(&cfg, Estimator::Kif, 320, 240).expect("a tracker");
        let mut rgb = Vec::new();
        let frame = two_marks(320, 240);
        tracker.track(&frame).expect("a frame");
        render_overlay(&frame, &tracker, &mut rgb);
        // The road reaches the bottom: no bottom line; both lanes meet upwards: a horizon.
        assert_eq!(count(&rgb, ROAD_BOTTOM_RGB), 0);
        assert!(tracker.road().horizon_row_px.is_some());
        assert!(count(&rgb, HORIZON_RGB) > 100);
        // A flat dark bonnet from row 200 down.
        let mut pixels = frame.data().to_vec();
        pixels[200 * 320..].fill(30);
        let bonnet = GreyFrame::from_vec(320, 240, pixels).expect("a whole frame");
        tracker.reset();
        tracker.track(&bonnet).expect("a frame");
        render_overlay(&bonnet, &tracker, &mut rgb);
        let bottom = tracker.road().bottom_row_px;
        assert!((190.0..=200.0).contains(&bottom), "bottom {bottom}");
        assert!(count(&rgb, ROAD_BOTTOM_RGB) > 100);
    }
}
