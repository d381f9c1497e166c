//! Orientation of an edge pixel: the direction of its Sobel gradient, in the Hough convention
//! of `hough-init` (an addition beyond the paper; used by the orientation-restricted Hough vote).
//!
//! The gradient `(gx, gy)` of the 3×3 Sobel operator (crate docs) is normal to the edge through
//! the pixel. Its angle from the column axis towards the (downward) row axis,
//!
//! ```text
//!     θ = atan2(gy, gx)   folded into [−90°, 90°)   (θ and θ ± 180° are the same line normal),
//! ```
//!
//! is the normal angle `θ` of the straight line `ρ = x·cos θ + y·sin θ` that the edge is locally
//! part of: the two sides of a bright stripe (gradients of opposite sign) give the same `θ`,
//! and a `/` mark (top leaning right) gives `θ > 0`, a `\` mark `θ < 0`, as the Hough bands of
//! `hough_init::AngleBand`. On a sampled edge the per-pixel angle spreads by several degrees
//! about the true one (the crate docs measure up to ~19° on the rim of an anti-aliased stripe),
//! so a consumer compares it with a tolerance. The detector stores each edge pixel's gradient
//! ([`crate::EdgePixel::gradient`]), so [`gradient_normal_deg`] needs no image access.

/// The normal angle of gradient `(gx, gy)` folded into `[−90°, 90°)`, degrees: `atan2(gy, gx)`
/// modulo 180°, which is `sign(gx·gy)·atan(|gy|/|gx|)` (`−90°` for `gx = 0`). The arctangent
/// of the ratio `z ≤ 1` is the polynomial `z·(45° + 15.64°·(1 − z))` (and `90° − ` that of
/// `1/z` above 1), within 0.25° of the exact angle (tested against `atan2` over every octant):
/// no transcendental call per pixel, for the Hough vote of whole frames. `None` for a zero
/// gradient.
#[inline]
#[must_use]
pub fn gradient_normal_deg(gx: i16, gy: i16) -> Option<f32> {
    if gx == 0 && gy == 0 {
        return None;
    }
    if gx == 0 {
        return Some(-90.0);
    }
    let (ax, ay) = (f32::from(gx.unsigned_abs()), f32::from(gy.unsigned_abs()));
    let atan_deg = |z: f32| z * (45.0 + 15.64 * (1.0 - z));
    // The smaller over the larger, one division, and a select (no branch to mispredict).
    let t = atan_deg(ay.min(ax) / ay.max(ax));
    let a = if ay <= ax { t } else { 90.0 - t };
    // a ∈ [0°, 90°]; the normal leans towards +y when gx and gy share their sign.
    Some(if (gx > 0) == (gy >= 0) {
        if a >= 90.0 { -90.0 } else { a }
    } else {
        -a
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::GreyImage;

    /// An independent reference (not the detector's kernel): the Sobel responses `(gx, gy)` at
    /// pixel `(col_px, row_px)` of `image` as the correlation of its 3×3 neighbourhood with the
    /// two Sobel masks (crate docs: `gx` grows to the right, `gy` downwards), grey levels.
    /// `None` without a whole 3×3 neighbourhood inside the image.
    fn sobel_gradient(image: &GreyImage<'_>, col_px: usize, row_px: usize) -> Option<(i16, i16)> {
        const MASK_X: [[i32; 3]; 3] = [[-1, 0, 1], [-2, 0, 2], [-1, 0, 1]];
        const MASK_Y: [[i32; 3]; 3] = [[-1, -2, -1], [0, 0, 0], [1, 2, 1]];
        let (mut gx, mut gy) = (0i32, 0i32);
        for (dr, (mx, my)) in MASK_X.iter().zip(&MASK_Y).enumerate() {
            let row = image.row((row_px + dr).checked_sub(1)?)?;
            for dc in 0..3 {
                let v = i32::from(*row.get((col_px + dc).checked_sub(1)?)?);
                gx += mx[dc] * v;
                gy += my[dc] * v;
            }
        }
        Some((i16::try_from(gx).ok()?, i16::try_from(gy).ok()?))
    }

    /// The normal angle `θ` of the edge through pixel `(col_px, row_px)` of `image`, degrees in
    /// `[−90, 90)` (module docs; [`gradient_normal_deg`] of [`sobel_gradient`]).
    fn edge_normal_deg(image: &GreyImage<'_>, col_px: usize, row_px: usize) -> Option<f32> {
        let (gx, gy) = sobel_gradient(image, col_px, row_px)?;
        gradient_normal_deg(gx, gy)
    }

    /// A `w × h` image, dark with a bright 3-px stripe along the line of normal angle `theta_deg`
    /// through the image centre.
    fn stripe(theta_deg: f64, w: usize, h: usize) -> Vec<u8> {
        let (s, c) = theta_deg.to_radians().sin_cos();
        let (cx, cy) = (0.5 * (w as f64 - 1.0), 0.5 * (h as f64 - 1.0));
        let mut data = vec![40u8; w * h];
        for y in 0..h {
            for x in 0..w {
                let d = (x as f64 - cx) * c + (y as f64 - cy) * s;
                // Anti-aliased: coverage of the pixel by the stripe |d| ≤ 1.5.
                let cover = (2.0 - d.abs()).clamp(0.0, 1.0);
                data[y * w + x] = (40.0 + 160.0 * cover).round() as u8;
            }
        }
        data
    }

    #[test]
    fn both_sides_of_a_stripe_give_the_line_normal_of_the_hough_convention() {
        let (w, h) = (64, 64);
        for theta in [-75.0, -40.0, -10.0, 0.0, 5.0, 30.0, 60.0, 80.0] {
            let data = stripe(theta, w, h);
            let img = GreyImage::new(&data, w, h, w).expect("valid image");
            let (s, c) = f64::to_radians(theta).sin_cos();
            // Pixels 2 px each side of the stripe's centre line, near the image centre: the
            // rising and the falling edge.
            for side in [-2.0, 2.0] {
                let (x, y) = (31.5 + side * c, 31.5 + side * s);
                let (xi, yi) = (x.round() as usize, y.round() as usize);
                let got = edge_normal_deg(&img, xi, yi).expect("an edge");
                // Folded difference: θ and θ ± 180° are one normal.
                let diff = (f64::from(got) - theta + 90.0).rem_euclid(180.0) - 90.0;
                assert!(diff.abs() < 12.0, "θ {theta}: side {side} gave {got}");
            }
        }
    }

    #[test]
    fn a_slash_mark_is_positive_and_a_backslash_mark_negative() {
        let (w, h) = (48, 48);
        // `/`: x grows as y falls; the normal leans into the first quadrant (θ > 0).
        let slash = stripe(35.0, w, h);
        let img = GreyImage::new(&slash, w, h, w).expect("valid image");
        assert!(edge_normal_deg(&img, 25, 25).is_some_and(|t| t > 0.0));
        let back = stripe(-35.0, w, h);
        let img = GreyImage::new(&back, w, h, w).expect("valid image");
        assert!(edge_normal_deg(&img, 25, 25).is_some_and(|t| t < 0.0));
    }

    #[test]
    fn the_gradient_matches_the_detectors_magnitude_and_the_stored_gradient() {
        use crate::{EdgeBuffer, GradientDetector, GradientParams, Region};
        let (w, h) = (40, 30);
        // A `\` and a `/` stripe: both classes, both signs of gx.
        let mut data = stripe(-25.0, w, h);
        for (d, s) in data.iter_mut().zip(stripe(35.0, w, h)) {
            *d = (*d).max(s);
        }
        let img = GreyImage::new(&data, w, h, w).expect("valid image");
        let mut edges = EdgeBuffer::with_capacity(w * h);
        GradientDetector::new(GradientParams::default())
            .expect("default parameters")
            .detect(&img, Region::Full, &mut edges, None)
            .expect("a whole image");
        for class in [crate::EdgeClass::LeftLane, crate::EdgeClass::RightLane] {
            for positive in [false, true] {
                assert!(
                    edges.iter_class(class).any(|p| (p.gx > 0) == positive),
                    "{class:?}, gx > 0: {positive}"
                );
            }
        }
        for p in edges.pixels() {
            let (gx, gy) = sobel_gradient(&img, usize::from(p.col_px), usize::from(p.row_px))
                .expect("edge pixels are interior");
            assert_eq!(gx.unsigned_abs() + gy.unsigned_abs(), p.magnitude, "{p:?}");
            assert_eq!(p.gradient(), (gx, gy), "{p:?}");
        }
    }

    #[test]
    fn the_polynomial_normal_is_within_a_quarter_degree_of_atan2_in_every_octant() {
        let mut worst = 0.0f64;
        for gx in (-1020i16..=1020).step_by(7) {
            for gy in (-1020i16..=1020).step_by(11) {
                let Some(got) = gradient_normal_deg(gx, gy) else {
                    assert_eq!((gx, gy), (0, 0));
                    continue;
                };
                assert!((-90.0..90.0).contains(&got), "({gx}, {gy}) → {got}");
                let exact = f64::from(gy).atan2(f64::from(gx)).to_degrees();
                let diff = (f64::from(got) - exact + 90.0).rem_euclid(180.0) - 90.0;
                worst = worst.max(diff.abs());
            }
        }
        assert!(worst <= 0.25, "worst error {worst}°");
        assert_eq!(gradient_normal_deg(0, 0), None);
        assert_eq!(gradient_normal_deg(0, 5), Some(-90.0));
        assert_eq!(gradient_normal_deg(5, 0), Some(0.0));
        assert_eq!(gradient_normal_deg(-5, 0), Some(0.0));
    }
}
