//! The ground-plane homography and its inverse.

use nalgebra::{Matrix2, Matrix3, SMatrix, SVector, Vector3};

use crate::GeometryError;

/// Smallest |w| (homogeneous scale) accepted for a point in front of the camera.
const MIN_SCALE: f64 = 1e-12;

/// The plane-to-plane map between ground points `(X fwd, Y right)` (m, vehicle frame) and image
/// points `(column, row)` (px):
///
/// ```text
/// w·(u, v, 1)ᵀ = H·(X, Y, 1)ᵀ,      λ·(X, Y, 1)ᵀ = G·(u, v, 1)ᵀ,   G = H⁻¹
/// ```
///
/// scaled so that `w > 0` (and so `λ = 1/w > 0`) for points in front of the camera; a point
/// with `w ≤ 0` (or `λ ≤ 0`) is at or beyond the horizon.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Homography {
    ground_to_image: Matrix3<f64>,
    image_to_ground: Matrix3<f64>,
}

fn non_finite(m: &Matrix3<f64>) -> bool {
    m.iter().any(|v| !v.is_finite())
}

impl Homography {
    /// From the ground→image matrix `H` (any non-zero scale; the sign must make `w > 0` in
    /// front of the camera, as [`crate::PinholeCamera::homography`] does).
    ///
    /// # Errors
    /// [`GeometryError::DegenerateHomography`] if `H` is not finite or is singular.
    pub fn from_ground_to_image(h: &Matrix3<f64>) -> Result<Self, GeometryError> {
        if non_finite(h) {
            return Err(GeometryError::DegenerateHomography {
                reason: "matrix has a non-finite entry",
            });
        }
        let norm = h.norm();
        // Relative determinant: |det H| / ‖H‖³ (1/√27 for a scaled rotation).
        if !crate::greater(norm, 0.0) || h.determinant().abs() / (norm * norm * norm) < 1e-14 {
            return Err(GeometryError::DegenerateHomography {
                reason: "matrix is singular",
            });
        }
        let Some(g) = h.try_inverse() else {
            return Err(GeometryError::DegenerateHomography {
                reason: "matrix is singular",
            });
        };
        if non_finite(&g) {
            return Err(GeometryError::DegenerateHomography {
                reason: "inverse has a non-finite entry",
            });
        }
        Ok(Self {
            ground_to_image: *h,
            image_to_ground: g,
        })
    }

    /// The homography through four image↔ground point pairs (direct linear transform with
    /// Hartley's normalisation of both point sets; `h33` fixed by the normalisation). The image
    /// points must lie below the horizon (in front of the camera); the sign is chosen so that
    /// they do.
    ///
    /// # Errors
    /// [`GeometryError::NonFinite`] for a NaN/∞ coordinate; [`GeometryError::DegenerateHomography`]
    /// when three points of either set are (nearly) collinear or the system is singular.
    pub fn from_point_pairs(
        image_px: &[[f64; 2]; 4],
        ground_m: &[[f64; 2]; 4],
    ) -> Result<Self, GeometryError> {
        if image_px
            .iter()
            .chain(ground_m)
            .flatten()
            .any(|v| !v.is_finite())
        {
            return Err(GeometryError::NonFinite {
                what: "homography point pair",
            });
        }
        let ti = normaliser(image_px)?;
        let tg = normaliser(ground_m)?;
        let mut a = SMatrix::<f64, 8, 8>::zeros();
        let mut b = SVector::<f64, 8>::zeros();
        for k in 0..4 {
            let p = tg * Vector3::new(ground_m[k][0], ground_m[k][1], 1.0);
            let q = ti * Vector3::new(image_px[k][0], image_px[k][1], 1.0);
            let (x, y) = (p.x / p.z, p.y / p.z);
            let (u, v) = (q.x / q.z, q.y / q.z);
            // u·(h31 x + h32 y + h33) = h11 x + h12 y + h13, likewise v; h33 = 1.
            let r = 2 * k;
            a.row_mut(r)
                .copy_from_slice(&[x, y, 1.0, 0.0, 0.0, 0.0, -u * x, -u * y]);
            b[r] = u;
            a.row_mut(r + 1)
                .copy_from_slice(&[0.0, 0.0, 0.0, x, y, 1.0, -v * x, -v * y]);
            b[r + 1] = v;
        }
        let Some(hv) = a.lu().solve(&b) else {
            return Err(GeometryError::DegenerateHomography {
                reason: "point-pair system is singular",
            });
        };
        let hn = Matrix3::new(hv[0], hv[1], hv[2], hv[3], hv[4], hv[5], hv[6], hv[7], 1.0);
        let Some(ti_inv) = ti.try_inverse() else {
            return Err(GeometryError::DegenerateHomography {
                reason: "image points coincide",
            });
        };
        let mut h = ti_inv * hn * tg;
        // Sign: w > 0 at the given points (they are in front of the camera).
        let w0 = (h * Vector3::new(ground_m[0][0], ground_m[0][1], 1.0)).z;
        if w0 < 0.0 {
            h = -h;
        }
        let out = Self::from_ground_to_image(&h)?;
        for g in ground_m {
            let w = (out.ground_to_image * Vector3::new(g[0], g[1], 1.0)).z;
            if !crate::greater(w, MIN_SCALE) {
                return Err(GeometryError::BeyondHorizon {
                    what: "homography ground point",
                    x: g[0],
                    y: g[1],
                });
            }
        }
        Ok(out)
    }

    /// `H` (ground → image).
    pub fn ground_to_image_matrix(&self) -> &Matrix3<f64> {
        &self.ground_to_image
    }

    /// `G = H⁻¹` (image → ground).
    pub fn image_to_ground_matrix(&self) -> &Matrix3<f64> {
        &self.image_to_ground
    }

    /// Image point `[column, row]` (px) of a ground point `[X fwd, Y right]` (m).
    ///
    /// # Errors
    /// [`GeometryError::BeyondHorizon`] if the ground point is not in front of the camera.
    #[inline]
    pub fn ground_to_image(&self, ground_m: [f64; 2]) -> Result<[f64; 2], GeometryError> {
        let q = self.ground_to_image * Vector3::new(ground_m[0], ground_m[1], 1.0);
        if !crate::greater(q.z, MIN_SCALE) {
            return Err(GeometryError::BeyondHorizon {
                what: "ground point",
                x: ground_m[0],
                y: ground_m[1],
            });
        }
        Ok([q.x / q.z, q.y / q.z])
    }

    /// Ground point `[X fwd, Y right]` (m) seen at the image point `[column, row]` (px).
    ///
    /// # Errors
    /// [`GeometryError::BeyondHorizon`] if the pixel is at or above the horizon.
    #[inline]
    pub fn image_to_ground(&self, image_px: [f64; 2]) -> Result<[f64; 2], GeometryError> {
        self.image_to_ground_with_jacobian(image_px).map(|(p, _)| p)
    }

    /// Ground point of an image point and the Jacobian `∂(X, Y)/∂(u, v)` (m/px):
    /// with `q = G·(u, v, 1)ᵀ`, `X = q₀/q₂`, `Y = q₁/q₂`,
    /// `∂X/∂u = (G₀₀ − X·G₂₀)/q₂`, `∂X/∂v = (G₀₁ − X·G₂₁)/q₂`, and likewise for `Y` with row 1.
    ///
    /// # Errors
    /// As [`Self::image_to_ground`].
    #[inline]
    pub fn image_to_ground_with_jacobian(
        &self,
        image_px: [f64; 2],
    ) -> Result<([f64; 2], Matrix2<f64>), GeometryError> {
        let g = &self.image_to_ground;
        let q = g * Vector3::new(image_px[0], image_px[1], 1.0);
        if !crate::greater(q.z, MIN_SCALE * g.norm()) || !q.z.is_finite() {
            return Err(GeometryError::BeyondHorizon {
                what: "image point",
                x: image_px[0],
                y: image_px[1],
            });
        }
        let inv = 1.0 / q.z;
        let (x, y) = (q.x * inv, q.y * inv);
        let j = Matrix2::new(
            (g[(0, 0)] - x * g[(2, 0)]) * inv,
            (g[(0, 1)] - x * g[(2, 1)]) * inv,
            (g[(1, 0)] - y * g[(2, 0)]) * inv,
            (g[(1, 1)] - y * g[(2, 1)]) * inv,
        );
        Ok(([x, y], j))
    }
}

/// Hartley's normalisation: centroid to the origin, mean distance √2. Refuses three collinear
/// points (relative area below 1e-9).
fn normaliser(points: &[[f64; 2]; 4]) -> Result<Matrix3<f64>, GeometryError> {
    let (mut cx, mut cy) = (0.0, 0.0);
    for p in points {
        cx += p[0] / 4.0;
        cy += p[1] / 4.0;
    }
    let mean_dist = points
        .iter()
        .map(|p| ((p[0] - cx).powi(2) + (p[1] - cy).powi(2)).sqrt())
        .sum::<f64>()
        / 4.0;
    if !crate::greater(mean_dist, 0.0) {
        return Err(GeometryError::DegenerateHomography {
            reason: "points coincide",
        });
    }
    for (i, j, k) in [(0, 1, 2), (0, 1, 3), (0, 2, 3), (1, 2, 3)] {
        let (a, b, c) = (points[i], points[j], points[k]);
        let area = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
        if area.abs() < 1e-9 * mean_dist * mean_dist {
            return Err(GeometryError::DegenerateHomography {
                reason: "three of the four points are collinear",
            });
        }
    }
    let s = std::f64::consts::SQRT_2 / mean_dist;
    Ok(Matrix3::new(
        s,
        0.0,
        -s * cx,
        0.0,
        s,
        -s * cy,
        0.0,
        0.0,
        1.0,
    ))
}
