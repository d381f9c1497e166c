//! The labelled frames changed as other cameras would give them (`eval-lanes --perturb`,
//! [`crate::protocol`]'s perturbation table): each [`Perturbation`] is a pure function of a
//! frame and its labels to a frame, its labels and the near band to score
//! ([`Perturbation::apply`]); the random one is seeded.
//!
//! ## Geometry (the labels move with the content)
//!
//! A label point keeps its place on the image: a row `y` of the input is `y'` of the output
//! (below), a column `x` is `x' = (x + 0.5)·kx − 0.5` for a resize by `kx` (pixel centres at
//! `+0.5`), `x` otherwise. Points that leave the frame are dropped, lanes left with fewer than
//! 2 points too; a resized lane is sampled again at one point per integer row, linear between
//! its points (the conversion rule of the sets, `crate::resample`).
//!
//! - [`Perturbation::Horizon`]: the content moved up (`Up`: a camera pitched down, the horizon
//!   higher in the frame) or down by `d = round(f·H)` rows, `y' = y ∓ d`; the frame keeps its
//!   size, the rows that leave are cropped and the vacated rows are filled with one flat grey,
//!   the mean of the content row beside them (flat: no edge of any direction inside it, and
//!   the seam as faint as a flat fill makes it; replicated edge rows would draw a lane's last
//!   row down the fill as a vertical stripe).
//! - [`Perturbation::Bonnet`]: a camera that sees its bonnet. The road is kept whole and the
//!   frame is **extended** downward by `B = H₂ − H` rows, `H₂ = round(H / (1 − f))`, so the
//!   bonnet takes the fraction `f` of the new height at the centre column; then the `W × H₂`
//!   frame is resized back to `W × H` (the road compressed vertically, `ky = H/H₂`). The
//!   bonnet (`geometry`) has a curved top edge, `e(u) = H + 0.3·B·u²` at `u ∈ (−1, 1)` across the
//!   width (it touches the road at the centre and falls away to the sides), a dark paint
//!   shaded darker towards its bottom and its sides, and a soft highlight band (the sky's
//!   reflection) a third of the way down it; the strip between the road's last row and the
//!   edge, at the sides, is the road's shadow (70 % of the mean of that last row). The edge is
//!   anti-aliased by the pixel's coverage.
//! - [`Perturbation::Width`]: the frame resized to `W'` columns and `H' = round(H·W'/W)` rows
//!   (the same aspect), `kx = W'/W`, `ky = H'/H`; `W' = W` is the identity.
//!
//! **Resizing** (`geometry::resize`) is separable, one axis then the other. A reduction is area
//! (box) resampling: output pixel `i` of an axis `n → m` averages the input interval
//! `[i·n/m, (i+1)·n/m)`, each input pixel weighed by its overlap, so a flat image stays flat
//! and the mean is kept. An enlargement is bilinear: output `i` reads the input at
//! `u = (i + 0.5)·n/m − 0.5`, linear between its two neighbours (clamped at the borders), the
//! same pixel-centre rule as the labels'.
//!
//! **The near band** to score is the rows that were the near band before the perturbation
//! (label points below `eval_top_fraction · H`), mapped like the labels: the perturbed frame is
//! scored from the row [`Perturbation::map_row`] gives, not from its own
//! `eval_top_fraction · H'`, so a perturbation changes the image the tracker sees but not the
//! part of the road it is scored on (what leaves the frame is not scored).
//!
//! ## Photometry (the labels and the near band unchanged)
//!
//! Grey levels `v ∈ [0, 255]`, results rounded to the nearest level and clamped:
//! - [`Perturbation::Brightness`]: `v' = g·v`.
//! - [`Perturbation::Jpeg`]: encoded and decoded in memory by the `image` crate's JPEG codec at
//!   the given quality (its block artefacts and smoothing).
//! - [`Perturbation::Noise`]: `v' = v + n`, `n ~ N(0, σ²)` independent per pixel, drawn by a
//!   ChaCha8 generator seeded with the frame's seed ([`frame_seed`]: the table's seed, the set
//!   and the frame's position), so a run is repeatable and two frames differ.
//! - [`Perturbation::MotionBlur`]: a horizontal box filter of `n` taps (odd): `v'(x) =
//!   Σ_{|k| ≤ n/2} v(x + k) / n`, columns beyond the border clamped to it (a flat image stays
//!   flat).

use lane_io::GreyFrame;

use crate::BenchError;
use crate::labelled::{LabelFrame, LabelLane};

mod geometry;
mod photometric;
#[cfg(test)]
mod tests;

pub(crate) use geometry::resize;

/// Which way [`Perturbation::Horizon`] moves the content.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Direction {
    /// Up: the horizon higher in the frame (rows vacated at the bottom).
    Up,
    /// Down: the horizon lower in the frame (rows vacated at the top).
    Down,
}

/// One change of the frames (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Perturbation {
    /// The content moved up or down by `fraction` of the height (crop and flat fill).
    Horizon {
        /// Which way.
        direction: Direction,
        /// Of the height, in (0, 1).
        fraction: f64,
    },
    /// A bonnet below the road, taking `fraction` of the extended frame, resized back.
    Bonnet {
        /// Of the extended frame's height, in (0, 1).
        fraction: f64,
    },
    /// The frame resized to this width (the same aspect).
    Width {
        /// The new width, px.
        width_px: usize,
    },
    /// Grey levels multiplied by `gain` (clamped).
    Brightness {
        /// The factor, ≥ 0.
        gain: f64,
    },
    /// JPEG at this quality, encoded and decoded in memory.
    Jpeg {
        /// 1..=100.
        quality: u8,
    },
    /// Gaussian noise of this standard deviation, grey levels (seeded).
    Noise {
        /// σ, grey levels, ≥ 0.
        sigma_grey: f64,
    },
    /// A horizontal box filter of this many taps (odd).
    MotionBlur {
        /// Taps, odd.
        taps_px: usize,
    },
}

/// The perturbations of `eval-lanes --perturb`, in the table's order.
pub const TABLE: [Perturbation; 15] = [
    Perturbation::Horizon {
        direction: Direction::Up,
        fraction: 0.15,
    },
    Perturbation::Horizon {
        direction: Direction::Down,
        fraction: 0.15,
    },
    Perturbation::Bonnet { fraction: 0.20 },
    Perturbation::Bonnet { fraction: 0.35 },
    Perturbation::Width { width_px: 256 },
    Perturbation::Width { width_px: 320 },
    Perturbation::Width { width_px: 512 },
    Perturbation::Width { width_px: 640 },
    Perturbation::Width { width_px: 1280 },
    Perturbation::Width { width_px: 1920 },
    Perturbation::Brightness { gain: 0.5 },
    Perturbation::Brightness { gain: 1.6 },
    Perturbation::Jpeg { quality: 30 },
    Perturbation::Noise { sigma_grey: 8.0 },
    Perturbation::MotionBlur { taps_px: 7 },
];

/// The seed of the table's random perturbations ([`frame_seed`]).
pub const TABLE_SEED: u64 = 53;

/// A frame, its labels and its near band after a perturbation.
#[derive(Debug, Clone, PartialEq)]
pub struct Perturbed {
    /// The frame.
    pub frame: GreyFrame,
    /// Its labels, mapped.
    pub labels: LabelFrame,
    /// The top row of the near band to score, px of the perturbed frame (module docs).
    pub near_top_px: f64,
}

impl Perturbation {
    /// Short name, as in the reports (`horizon-up-15`, `bonnet-20`, `width-1920`,
    /// `brightness-0.5`, `jpeg-30`, `noise-8`, `blur-7`).
    pub fn name(&self) -> String {
        let pct = |f: f64| format!("{:.0}", 100.0 * f);
        match *self {
            Perturbation::Horizon {
                direction,
                fraction,
            } => {
                let way = match direction {
                    Direction::Up => "up",
                    Direction::Down => "down",
                };
                format!("horizon-{way}-{}", pct(fraction))
            }
            Perturbation::Bonnet { fraction } => format!("bonnet-{}", pct(fraction)),
            Perturbation::Width { width_px } => format!("width-{width_px}"),
            Perturbation::Brightness { gain } => format!("brightness-{gain}"),
            Perturbation::Jpeg { quality } => format!("jpeg-{quality}"),
            Perturbation::Noise { sigma_grey } => format!("noise-{sigma_grey}"),
            Perturbation::MotionBlur { taps_px } => format!("blur-{taps_px}"),
        }
    }

    /// What it does, in a few words.
    pub fn describe(&self) -> String {
        let pct = |f: f64| format!("{:.0} %", 100.0 * f);
        match *self {
            Perturbation::Horizon {
                direction: Direction::Up,
                fraction,
            } => format!("content moved up {} of the height", pct(fraction)),
            Perturbation::Horizon {
                direction: Direction::Down,
                fraction,
            } => format!("content moved down {} of the height", pct(fraction)),
            Perturbation::Bonnet { fraction } => {
                format!("bonnet over the bottom {}, road compressed", pct(fraction))
            }
            Perturbation::Width { width_px } => format!("resized to {width_px} px wide"),
            Perturbation::Brightness { gain } => format!("brightness ×{gain}"),
            Perturbation::Jpeg { quality } => format!("JPEG quality {quality}"),
            Perturbation::Noise { sigma_grey } => {
                format!("Gaussian noise σ {sigma_grey} grey levels")
            }
            Perturbation::MotionBlur { taps_px } => {
                format!("horizontal motion blur {taps_px} px")
            }
        }
    }

    /// Refuses parameters out of their ranges (the variants' docs), naming the perturbation.
    pub fn validate(&self) -> Result<(), BenchError> {
        let ok = match *self {
            Perturbation::Horizon { fraction, .. } | Perturbation::Bonnet { fraction } => {
                fraction > 0.0 && fraction < 1.0
            }
            Perturbation::Width { width_px } => {
                (1..=hough_init::MAX_IMAGE_SIDE_PX).contains(&width_px)
            }
            Perturbation::Brightness { gain } => gain.is_finite() && gain >= 0.0,
            Perturbation::Jpeg { quality } => (1..=100).contains(&quality),
            Perturbation::Noise { sigma_grey } => sigma_grey.is_finite() && sigma_grey >= 0.0,
            Perturbation::MotionBlur { taps_px } => taps_px % 2 == 1,
        };
        if ok {
            Ok(())
        } else {
            Err(BenchError::Refused(format!(
                "perturbation {self:?}: a parameter out of its range"
            )))
        }
    }

    /// The size of a perturbed `width × height` frame, px.
    pub fn size(&self, width: usize, height: usize) -> (usize, usize) {
        match *self {
            Perturbation::Width { width_px } => (width_px, scaled_height(width, height, width_px)),
            _ => (width, height),
        }
    }

    /// Row `y_px` of a `width × height` frame as a row of the perturbed frame (module docs).
    pub fn map_row(&self, y_px: f64, width: usize, height: usize) -> f64 {
        match self.row_map(width, height) {
            RowMap::Shift(d) => y_px + d as f64,
            RowMap::Scale(ky) => (y_px + 0.5) * ky - 0.5,
            RowMap::Same => y_px,
        }
    }

    /// The labels of a `width × height` frame mapped onto the perturbed frame (module docs).
    pub fn map_labels(&self, labels: &LabelFrame, width: usize, height: usize) -> LabelFrame {
        let (w2, h2) = self.size(width, height);
        let (kx, map) = match *self {
            Perturbation::Width { width_px } => {
                (width_px as f64 / width as f64, self.row_map(width, height))
            }
            _ => (1.0, self.row_map(width, height)),
        };
        let lanes = labels
            .lanes
            .iter()
            .map(|lane| LabelLane {
                side: lane.side,
                points: match map {
                    RowMap::Same => lane.points.clone(),
                    RowMap::Shift(d) => lane
                        .points
                        .iter()
                        .map(|&[x, y]| [x, y + d as f64])
                        .filter(|&[_, y]| (0.0..h2 as f64).contains(&y))
                        .collect(),
                    RowMap::Scale(ky) => crate::resample::resample_points(
                        &lane.points,
                        [kx, ky],
                        w2 as f64,
                        h2 as f64,
                    ),
                },
            })
            .filter(|lane| lane.points.len() >= 2)
            .collect();
        LabelFrame {
            lanes,
            ..labels.clone()
        }
    }

    /// The perturbed image of `frame`; `seed` drives the random perturbations (the table uses
    /// [`frame_seed`]), `name` names the frame in errors.
    ///
    /// # Errors
    /// Parameters out of range ([`Perturbation::validate`]); the JPEG codec's failure.
    pub fn perturb_image(
        &self,
        frame: &GreyFrame,
        seed: u64,
        name: &str,
    ) -> Result<GreyFrame, BenchError> {
        self.validate()?;
        let (w, h) = (frame.width(), frame.height());
        Ok(match *self {
            Perturbation::Horizon {
                direction,
                fraction,
            } => geometry::shift_rows(frame, signed_shift(direction, fraction, h)),
            Perturbation::Bonnet { fraction } => geometry::with_bonnet(frame, fraction),
            Perturbation::Width { width_px } => {
                resize(frame, width_px, scaled_height(w, h, width_px))
            }
            Perturbation::Brightness { gain } => photometric::brightness(frame, gain),
            Perturbation::Jpeg { quality } => photometric::jpeg(frame, quality, name)?,
            Perturbation::Noise { sigma_grey } => photometric::noise(frame, sigma_grey, seed),
            Perturbation::MotionBlur { taps_px } => photometric::box_blur_rows(frame, taps_px),
        })
    }

    /// The whole perturbation of one frame: its image ([`Perturbation::perturb_image`]), its
    /// labels ([`Perturbation::map_labels`]) and the top row of its near band
    /// ([`Perturbation::map_row`] of `near_top_px`).
    pub fn apply(
        &self,
        frame: &GreyFrame,
        labels: &LabelFrame,
        near_top_px: f64,
        seed: u64,
    ) -> Result<Perturbed, BenchError> {
        let (w, h) = (frame.width(), frame.height());
        Ok(Perturbed {
            frame: self.perturb_image(frame, seed, &labels.file)?,
            labels: self.map_labels(labels, w, h),
            near_top_px: self.map_row(near_top_px, w, h),
        })
    }

    /// How rows move.
    fn row_map(&self, width: usize, height: usize) -> RowMap {
        match *self {
            Perturbation::Horizon {
                direction,
                fraction,
            } => RowMap::Shift(signed_shift(direction, fraction, height)),
            Perturbation::Bonnet { fraction } => RowMap::Scale(
                height as f64 / geometry::bonnet_frame_height(height, fraction) as f64,
            ),
            Perturbation::Width { width_px } if width_px != width => {
                RowMap::Scale(scaled_height(width, height, width_px) as f64 / height as f64)
            }
            _ => RowMap::Same,
        }
    }
}

/// How a perturbation moves rows.
#[derive(Debug, Clone, Copy)]
enum RowMap {
    /// Unchanged.
    Same,
    /// `y' = y + d`.
    Shift(isize),
    /// `y' = (y + 0.5)·k − 0.5`.
    Scale(f64),
}

/// The rows a horizon shift moves the content by: `−round(f·H)` up, `+round(f·H)` down.
fn signed_shift(direction: Direction, fraction: f64, height: usize) -> isize {
    let d = (fraction * height as f64).round() as isize;
    match direction {
        Direction::Up => -d,
        Direction::Down => d,
    }
}

/// The height of a `width × height` frame resized to `width_px` columns, the same aspect.
fn scaled_height(width: usize, height: usize, width_px: usize) -> usize {
    if width_px == width {
        return height;
    }
    ((height as f64 * width_px as f64 / width as f64).round() as usize).max(1)
}

/// The seed of the frame at `position` of set `set` from the table's `seed`: an FNV-1a hash of
/// the set's name, the position and the seed mixed by SplitMix64's finaliser (independent
/// streams per frame, the same every run).
pub fn frame_seed(seed: u64, set: &str, position: usize) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in set.bytes() {
        h = (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3);
    }
    let mut z = seed ^ h ^ (position as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}
