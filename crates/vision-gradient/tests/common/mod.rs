//! Test helpers: anti-aliased rendering and an independent floating-point reference.
#![allow(dead_code, clippy::unwrap_used, clippy::expect_used)]

use vision_gradient::EdgeClass;

/// Renders `w`×`h` pixels: grey = `bg + (fg - bg)·coverage`, coverage by 16×16 supersampling of
/// `inside(x, y)` in continuous coordinates (pixel (c, r) covers [c, c+1)×[r, r+1)).
pub fn render(w: usize, h: usize, bg: f64, fg: f64, inside: impl Fn(f64, f64) -> bool) -> Vec<u8> {
    let mut out = vec![0u8; w * h];
    for r in 0..h {
        for c in 0..w {
            let mut n = 0;
            for i in 0..16 {
                for j in 0..16 {
                    let x = c as f64 + (f64::from(j) + 0.5) / 16.0;
                    let y = r as f64 + (f64::from(i) + 0.5) / 16.0;
                    if inside(x, y) {
                        n += 1;
                    }
                }
            }
            let cov = f64::from(n) / 256.0;
            out[r * w + c] = (bg + (fg - bg) * cov).round().clamp(0.0, 255.0) as u8;
        }
    }
    out
}

/// A straight stripe: centre line through `(x0, y0)` with unit direction `d`, half width `hw`.
#[derive(Clone, Copy, Debug)]
pub struct Stripe {
    pub x0: f64,
    pub y0: f64,
    pub dx: f64,
    pub dy: f64,
    pub hw: f64,
}

impl Stripe {
    /// Stripe whose edges make `alpha_deg` with the image horizontal; `left` = x grows as y
    /// shrinks (a left lane mark), otherwise x shrinks as y shrinks (right lane mark).
    pub fn new(x0: f64, y0: f64, alpha_deg: f64, left: bool, hw: f64) -> Self {
        let a = alpha_deg.to_radians();
        let dx = if left { a.cos() } else { -a.cos() };
        Self {
            x0,
            y0,
            dx,
            dy: -a.sin(),
            hw,
        }
    }

    /// Signed distance of `(x, y)` from the centre line.
    pub fn dist(&self, x: f64, y: f64) -> f64 {
        -self.dy * (x - self.x0) + self.dx * (y - self.y0)
    }

    pub fn inside(&self, x: f64, y: f64) -> bool {
        self.dist(x, y).abs() <= self.hw
    }
}

/// Reference Sobel at interior pixel (c, r), written as an explicit 3×3 correlation in f64.
pub fn ref_sobel(img: &[u8], w: usize, c: usize, r: usize) -> (f64, f64) {
    const KX: [[f64; 3]; 3] = [[-1.0, 0.0, 1.0], [-2.0, 0.0, 2.0], [-1.0, 0.0, 1.0]];
    const KY: [[f64; 3]; 3] = [[-1.0, -2.0, -1.0], [0.0, 0.0, 0.0], [1.0, 2.0, 1.0]];
    let (mut gx, mut gy) = (0.0, 0.0);
    for (i, (kx_row, ky_row)) in KX.iter().zip(KY.iter()).enumerate() {
        for j in 0..3 {
            let v = f64::from(img[(r + i - 1) * w + (c + j - 1)]);
            gx += kx_row[j] * v;
            gy += ky_row[j] * v;
        }
    }
    (gx, gy)
}

/// Reference decision: `None` if dropped, else the class; `ambiguous` if the edge angle is
/// within `tol_deg` of a band limit (fixed-point rounding may go either way there).
pub fn ref_classify(
    gx: f64,
    gy: f64,
    min_deg: f64,
    max_deg: f64,
    thr: f64,
    tol_deg: f64,
) -> (Option<EdgeClass>, bool) {
    if gx == 0.0 || gy == 0.0 || gx.abs() + gy.abs() < thr {
        return (None, false);
    }
    let alpha = gx.abs().atan2(gy.abs()).to_degrees();
    let ambiguous = (alpha - min_deg).abs() < tol_deg || (alpha - max_deg).abs() < tol_deg;
    if alpha < min_deg || alpha > max_deg {
        return (None, ambiguous);
    }
    let class = if gx * gy > 0.0 {
        EdgeClass::LeftLane
    } else {
        EdgeClass::RightLane
    };
    (Some(class), ambiguous)
}
