//! Synthetic edge-pixel scenes shared by the integration tests (seeded, deterministic).
#![allow(dead_code)]

use hough_init::{Parabola, Point};
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

/// A rasterised straight line plus its ground truth.
pub struct DrawnLine {
    /// Rasterised (integer) pixels plus noise, all inside the image.
    pub points: Vec<Point>,
    /// Mean of the true (unrounded, noiseless) positions of the drawn pixels: a point on the line.
    pub mid: (f64, f64),
}

/// Rasterise the line through `(anchor_col, anchor_row)` with normal angle `theta_deg`
/// (`dx/dy = −tan θ`) restricted to rows `[row_lo, height − 1]`, stepping along the dominant
/// axis and rounding the other coordinate, then add N(0, σ²) to both coordinates.
#[allow(clippy::too_many_arguments)]
pub fn draw_line(
    width: usize,
    height: usize,
    theta_deg: f64,
    anchor_col: f64,
    anchor_row: f64,
    row_lo: f64,
    sigma_px: f64,
    rng: &mut ChaCha8Rng,
) -> DrawnLine {
    let t = theta_deg.to_radians().tan(); // x = anchor_col − t·(y − anchor_row)
    let (w, h) = (width as f64, height as f64);
    let mut truth = Vec::new();
    if t.abs() <= 1.0 {
        let mut y = row_lo.ceil();
        while y <= h - 1.0 {
            let x = anchor_col - t * (y - anchor_row);
            if x.round() >= 0.0 && x.round() <= w - 1.0 {
                truth.push((x, y, x.round(), y));
            }
            y += 1.0;
        }
    } else {
        for xi in 0..width {
            let x = xi as f64;
            let y = anchor_row - (x - anchor_col) / t;
            if y.round() >= row_lo && y.round() <= h - 1.0 {
                truth.push((x, y, x, y.round()));
            }
        }
    }
    let n = truth.len().max(1) as f64;
    let mid = (
        truth.iter().map(|p| p.0).sum::<f64>() / n,
        truth.iter().map(|p| p.1).sum::<f64>() / n,
    );
    let noise = Normal::new(0.0, sigma_px.max(1e-12)).unwrap();
    let points = truth
        .iter()
        .map(|&(_, _, xr, yr)| {
            if sigma_px > 0.0 {
                Point::new(xr + noise.sample(rng), yr + noise.sample(rng))
            } else {
                Point::new(xr, yr)
            }
        })
        .filter(|p| inside(p, w, h))
        .collect();
    DrawnLine { points, mid }
}

fn inside(p: &Point, w: f64, h: f64) -> bool {
    p.col_px >= -0.5 && p.col_px <= w - 0.5 && p.row_px >= -0.5 && p.row_px <= h - 0.5
}

/// `count` integer pixels uniformly over the image.
pub fn clutter(width: usize, height: usize, count: usize, rng: &mut ChaCha8Rng) -> Vec<Point> {
    (0..count)
        .map(|_| {
            Point::new(
                rng.random_range(0..width) as f64,
                rng.random_range(0..height) as f64,
            )
        })
        .collect()
}

/// Pixels of a painted mark following `lane` on rows `[row_lo, height − 1]`: for every row,
/// every integer column within `half_width_px` of the curve (and of the span to the next row's
/// column, so steep curves stay connected), with N(0, σ²) noise on the column.
pub fn draw_mark(
    width: usize,
    height: usize,
    lane: &Parabola,
    row_lo: usize,
    half_width_px: f64,
    sigma_px: f64,
    rng: &mut ChaCha8Rng,
) -> Vec<Point> {
    let noise = Normal::new(0.0, sigma_px.max(1e-12)).unwrap();
    let mut out = Vec::new();
    for r in row_lo..height {
        let y = r as f64;
        let x0 = lane.col_at_row(y);
        let x1 = lane.col_at_row(y + 0.5);
        let lo = (x0.min(x1) - half_width_px).round();
        let hi = (x0.max(x1) + half_width_px).round();
        let mut x = lo;
        while x <= hi {
            let xn = if sigma_px > 0.0 {
                x + noise.sample(rng)
            } else {
                x
            };
            let p = Point::new(xn, y);
            if inside(&p, width as f64, height as f64) {
                out.push(p);
            }
            x += 1.0;
        }
    }
    out
}
