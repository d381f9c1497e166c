//! A road of known geometry: the ground truth for rendering and testing.

use crate::EgoGeometry;

/// A flat road whose centre line is a circular arc (a straight line for zero curvature) and a
/// camera posed on it, described by the same quantities the estimator reports
/// ([`EgoGeometry`]): the camera `lateral_offset_m` right of the centre line (measured
/// perpendicularly), its forward axis `heading_rad` to the right of the centre line's tangent
/// at the nearest point, the centre line's `curvature_per_m` (bending right > 0) and the lane
/// width. The marks are the curves parallel to the centre line at `∓lane_width_m/2`.
///
/// Road frame: origin at the centre-line point nearest the camera, `x` along its tangent, `y`
/// right. A vehicle-frame ground point `(X, Y)` is at
/// `(x, y) = (X cos ψ − Y sin ψ, d + X sin ψ + Y cos ψ)` (ψ heading, d offset), and its signed
/// distance right of the centre line is (circle of centre `(0, 1/κ)`, written without the
/// cancellation at small κ)
///
/// ```text
/// n = (2y − κ(x² + y²)) / (1 + √(κ²x² + (1 − κy)²)),     n = y when κ = 0,
/// ```
///
/// its arc length along the centre line `s = atan2(κx, 1 − κy)/κ` (`x` when κ = 0).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ArcRoad {
    /// The true geometry.
    pub geometry: EgoGeometry,
}

impl ArcRoad {
    /// Road-frame coordinates `(x, y)` (m) of a vehicle-frame ground point `[X fwd, Y right]`.
    #[inline]
    pub fn road_frame(&self, ground_m: [f64; 2]) -> [f64; 2] {
        let (s, c) = self.geometry.heading_rad.sin_cos();
        let [x, y] = ground_m;
        [
            x * c - y * s,
            self.geometry.lateral_offset_m + x * s + y * c,
        ]
    }

    /// `(s, n)`: arc length along the centre line (m, from the point nearest the camera) and
    /// signed distance right of it (m) of a vehicle-frame ground point `[X fwd, Y right]`.
    #[inline]
    pub fn along_across(&self, ground_m: [f64; 2]) -> [f64; 2] {
        let [x, y] = self.road_frame(ground_m);
        let k = self.geometry.curvature_per_m;
        let n = (2.0 * y - k * (x * x + y * y))
            / (1.0 + (k * k * x * x + (1.0 - k * y) * (1.0 - k * y)).sqrt());
        let s = if k.abs() < 1e-12 {
            x
        } else {
            (k * x).atan2(1.0 - k * y) / k
        };
        [s, n]
    }

    /// The vehicle-frame ground point `[X, Y]` (m) at arc length `s_m` along the centre line and
    /// `n_m` right of it (a mark is `n_m = ∓lane_width_m/2`).
    pub fn point(&self, s_m: f64, n_m: f64) -> [f64; 2] {
        let k = self.geometry.curvature_per_m;
        let a = k * s_m;
        // Centre line point and right normal in the road frame.
        let (cx, cy) = if k.abs() < 1e-12 {
            (s_m, 0.5 * k * s_m * s_m)
        } else {
            (a.sin() / k, (1.0 - a.cos()) / k)
        };
        let (nx, ny) = (-a.sin(), a.cos());
        let (x, y) = (
            cx + n_m * nx,
            cy + n_m * ny - self.geometry.lateral_offset_m,
        );
        let (sn, cs) = self.geometry.heading_rad.sin_cos();
        [x * cs + y * sn, -x * sn + y * cs]
    }
}
