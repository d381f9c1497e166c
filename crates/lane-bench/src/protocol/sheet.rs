//! The contact sheet `worst_frames.png`: the worst frames of the default run.

use std::path::{Path, PathBuf};

use crate::BenchError;
use crate::labelled::{EgoPrediction, LabelFrame, LabelSet, LabelSide, ScoringRules};

use super::FrameRank;

/// Draw `ranks` (worst first) as a 4-column grid of 320×240 tiles at `path`: label points (ego
/// green, others dark green), the default's lanes red, the peer's blue.
pub(super) fn contact_sheet(
    sets: &[(PathBuf, LabelSet)],
    drawn: &[(Vec<EgoPrediction>, Option<Vec<EgoPrediction>>)],
    ranks: &[&FrameRank],
    rules: &ScoringRules,
    path: &Path,
) -> Result<(), BenchError> {
    const TW: u32 = 320;
    const TH: u32 = 240;
    const COLS: u32 = 4;
    let rows = (ranks.len() as u32).div_ceil(COLS).max(1);
    let mut sheet = image::RgbImage::new(TW * COLS, TH * rows);
    for (k, r) in ranks.iter().enumerate() {
        let (dir, set) = &sets[r.set];
        let f: &LabelFrame = &set.frames[r.frame];
        // A frame whose image could not be read (skipped by the run) is drawn on black.
        let grey = image::open(LabelSet::frame_path(dir, f))
            .map_or_else(|_| image::GrayImage::new(0, 0), |i| i.to_luma8());
        let (ox, oy) = ((k as u32 % COLS) * TW, (k as u32 / COLS) * TH);
        let mut put = |x: f64, y: f64, c: [u8; 3]| {
            if x >= 0.0 && y >= 0.0 && x < f64::from(TW) && y < f64::from(TH) {
                sheet.put_pixel(ox + x as u32, oy + y as u32, image::Rgb(c));
            }
        };
        for (x, y, p) in grey.enumerate_pixels() {
            if x < TW && y < TH {
                put(f64::from(x), f64::from(y), [p[0]; 3]);
            }
        }
        let y_top = rules.eval_top_fraction * set.height as f64;
        // A dotted line marks the top of the scored band.
        for x in (0..set.width).step_by(4) {
            put(x as f64, y_top, [255, 255, 0]);
        }
        for lane in &f.lanes {
            let c = if lane.side == LabelSide::Other {
                [0, 120, 0]
            } else {
                [0, 255, 0]
            };
            for &[x, y] in &lane.points {
                for (dx, dy) in [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)] {
                    put(x + dx, y + dy, c);
                }
            }
        }
        let (ours, peer) = &drawn[r.set];
        let mut curves: Vec<([f64; 3], [u8; 3])> = Vec::new();
        for lane in ours[r.frame].iter().flatten() {
            curves.push((lane.coeffs, [255, 40, 40]));
        }
        if let Some(p) = peer {
            for lane in p[r.frame].iter().flatten() {
                curves.push((lane.coeffs, [60, 120, 255]));
            }
        }
        for ([a1, a2, a3], col) in curves {
            let y0 = (0.4 * set.height as f64) as usize;
            for y in y0..set.height {
                let yf = y as f64;
                put((a1 * yf + a2) * yf + a3, yf, col);
            }
        }
    }
    sheet.save(path).map_err(|source| BenchError::Image {
        action: "write",
        path: path.display().to_string(),
        source,
    })?;
    Ok(())
}
