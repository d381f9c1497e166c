//! The ego lane on the ground plane from the two image parabolas, with its covariance.

use nalgebra::{Matrix2, Matrix3, Matrix4, SMatrix, Vector4};

use crate::{GeometryError, Homography};

/// Image rows at which each lane parabola is sampled and mapped to the ground.
pub const SAMPLE_ROWS: usize = 8;

const SAMPLES: usize = 2 * SAMPLE_ROWS;

/// The Jacobian of the ego-lane geometry `(lateral_offset_m, heading_rad, curvature_per_m,
/// lane_width_m)` with respect to the six pixel coefficients `(a1, a2, a3)` of the left lane
/// then the right lane.
pub type EgoJacobian = SMatrix<f64, 4, 6>;

/// The ego lane's geometry on the ground plane (see the crate documentation for the definitions).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EgoGeometry {
    /// Signed distance of the camera from the lane centre line, m; positive when the camera is
    /// right of the centre.
    pub lateral_offset_m: f64,
    /// Yaw of the vehicle's forward axis from the lane direction, rad; positive when the vehicle
    /// points to the right of the lane.
    pub heading_rad: f64,
    /// Curvature of the lane centre line at the camera, 1/m; positive when the lane bends to the
    /// right.
    pub curvature_per_m: f64,
    /// Distance between the two lane marks across the lane, m.
    pub lane_width_m: f64,
}

impl EgoGeometry {
    /// `(lateral_offset_m, heading_rad, curvature_per_m, lane_width_m)`.
    pub fn to_vector(&self) -> Vector4<f64> {
        Vector4::new(
            self.lateral_offset_m,
            self.heading_rad,
            self.curvature_per_m,
            self.lane_width_m,
        )
    }

    /// From `(lateral_offset_m, heading_rad, curvature_per_m, lane_width_m)`.
    pub fn from_vector(v: &Vector4<f64>) -> Self {
        Self {
            lateral_offset_m: v[0],
            heading_rad: v[1],
            curvature_per_m: v[2],
            lane_width_m: v[3],
        }
    }
}

/// The ego lane with the standard deviations and the covariance propagated from the two lanes'
/// coefficient covariances.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EgoLane {
    /// The geometry.
    pub geometry: EgoGeometry,
    /// The standard deviation of each field of [`Self::geometry`], in the same units.
    pub sigma: EgoGeometry,
    /// Covariance of `(lateral_offset_m, heading_rad, curvature_per_m, lane_width_m)`,
    /// `J·diag(P_left, P_right)·Jᵀ`.
    pub covariance: Matrix4<f64>,
}

/// Maps the two image parabolas of the ego lane to its ground-plane geometry (see the crate
/// documentation). Built once; [`Self::estimate`] does not allocate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EgoLaneEstimator {
    homography: Homography,
    rows_px: [f64; SAMPLE_ROWS],
}

impl EgoLaneEstimator {
    /// Samples the lanes at the [`SAMPLE_ROWS`] image rows where the ground points
    /// `(X, 0)`, `X` evenly spaced over `[near_m, far_m]` straight ahead of the camera, appear.
    ///
    /// # Errors
    /// [`GeometryError::InvalidParameter`] (`lookahead_near_m` not finite and > 0,
    /// `lookahead_far_m` not > near); [`GeometryError::BeyondHorizon`] if a look-ahead point is
    /// not in front of the camera; [`GeometryError::InvalidParameter`] (`lookahead_far_m`) if
    /// the look-ahead points fall on fewer than 3 distinct rows.
    pub fn new(homography: Homography, near_m: f64, far_m: f64) -> Result<Self, GeometryError> {
        if !(near_m.is_finite() && near_m > 0.0) {
            return Err(GeometryError::InvalidParameter {
                field: "lookahead_near_m",
                value: near_m,
                reason: "must be finite and > 0",
            });
        }
        if !(far_m.is_finite() && far_m > near_m) {
            return Err(GeometryError::InvalidParameter {
                field: "lookahead_far_m",
                value: far_m,
                reason: "must be finite and > lookahead_near_m",
            });
        }
        let mut rows_px = [0.0; SAMPLE_ROWS];
        for (k, row) in rows_px.iter_mut().enumerate() {
            let x = near_m + (far_m - near_m) * k as f64 / (SAMPLE_ROWS - 1) as f64;
            *row =
                homography
                    .ground_to_image([x, 0.0])
                    .map_err(|_| GeometryError::BeyondHorizon {
                        what: "look-ahead point",
                        x,
                        y: 0.0,
                    })?[1];
        }
        Self::from_rows(homography, rows_px)
    }

    /// Samples the lanes at the given image rows.
    ///
    /// # Errors
    /// [`GeometryError::InvalidParameter`] (`rows_px`) if a row is not finite or fewer than 3 rows
    /// are distinct (by more than 0.5 px).
    pub fn from_rows(
        homography: Homography,
        rows_px: [f64; SAMPLE_ROWS],
    ) -> Result<Self, GeometryError> {
        if let Some(&bad) = rows_px.iter().find(|r| !r.is_finite()) {
            return Err(GeometryError::InvalidParameter {
                field: "rows_px",
                value: bad,
                reason: "must be finite",
            });
        }
        let (lo, hi) = rows_px
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &r| {
                (a.min(r), b.max(r))
            });
        if hi - lo < 1.0 {
            return Err(GeometryError::InvalidParameter {
                field: "rows_px",
                value: hi - lo,
                reason: "sample rows must span at least 1 px (3 distinct rows)",
            });
        }
        Ok(Self {
            homography,
            rows_px,
        })
    }

    /// The image rows the lanes are sampled at, px.
    pub fn rows_px(&self) -> &[f64; SAMPLE_ROWS] {
        &self.rows_px
    }

    /// The homography in use.
    pub fn homography(&self) -> &Homography {
        &self.homography
    }

    /// The geometry from the two lanes' coefficients `[a1, a2, a3]` (`x = a1·y² + a2·y + a3`,
    /// px), without uncertainty.
    ///
    /// # Errors
    /// As [`Self::geometry_with_jacobian`].
    pub fn geometry(
        &self,
        left_px: &[f64; 3],
        right_px: &[f64; 3],
    ) -> Result<EgoGeometry, GeometryError> {
        self.geometry_with_jacobian(left_px, right_px)
            .map(|(g, _)| g)
    }

    /// The geometry and its Jacobian with respect to `(a1, a2, a3)` of the left lane then the
    /// right lane.
    ///
    /// # Errors
    /// [`GeometryError::NonFinite`] for NaN/∞ coefficients; [`GeometryError::BeyondHorizon`] if
    /// a lane's sample point is at or above the horizon; [`GeometryError::SingularFit`] if the
    /// ground points do not determine the fit.
    pub fn geometry_with_jacobian(
        &self,
        left_px: &[f64; 3],
        right_px: &[f64; 3],
    ) -> Result<(EgoGeometry, EgoJacobian), GeometryError> {
        if left_px.iter().any(|v| !v.is_finite()) {
            return Err(GeometryError::NonFinite {
                what: "left lane coefficients",
            });
        }
        if right_px.iter().any(|v| !v.is_finite()) {
            return Err(GeometryError::NonFinite {
                what: "right lane coefficients",
            });
        }
        // Pass 1: ground points and their Jacobians; normal equations of the fit
        // Y_i = y0 + m·X_i + c·X_i² + s_i·W/2.
        let mut ground = [[0.0f64; 2]; SAMPLES];
        let mut dxy_du = [[0.0f64; 2]; SAMPLES];
        let mut n = Matrix4::<f64>::zeros();
        let mut rhs = Vector4::<f64>::zeros();
        for (lane, theta) in [left_px, right_px].into_iter().enumerate() {
            let side = if lane == 0 { -0.5 } else { 0.5 };
            for (k, &v) in self.rows_px.iter().enumerate() {
                let u = (theta[0] * v + theta[1]) * v + theta[2];
                let (p, j): ([f64; 2], Matrix2<f64>) = self
                    .homography
                    .image_to_ground_with_jacobian([u, v])
                    .map_err(|_| GeometryError::BeyondHorizon {
                        what: if lane == 0 {
                            "left lane sample"
                        } else {
                            "right lane sample"
                        },
                        x: u,
                        y: v,
                    })?;
                let i = lane * SAMPLE_ROWS + k;
                ground[i] = p;
                dxy_du[i] = [j[(0, 0)], j[(1, 0)]];
                let a = Vector4::new(1.0, p[0], p[0] * p[0], side);
                n += a * a.transpose();
                rhs += a * p[1];
            }
        }
        let chol = Chol4::new(&n)?;
        let params = chol.solve(&rhs);
        let (y0, m, c, w) = (params[0], params[1], params[2], params[3]);
        // Pass 2: ∂p/∂u_i = N⁻¹ g_i with
        // g_i = (0, r_i, 2X_i r_i, 0)·∂X_i/∂u + a_i·(∂Y_i/∂u − (m + 2c X_i)·∂X_i/∂u),
        // then ∂p/∂θ = Σ_i ∂p/∂u_i · (v_i², v_i, 1).
        let mut b = EgoJacobian::zeros();
        for lane in 0..2 {
            let side = if lane == 0 { -0.5 } else { 0.5 };
            for (k, &v) in self.rows_px.iter().enumerate() {
                let i = lane * SAMPLE_ROWS + k;
                let [x, y] = ground[i];
                let [xu, yu] = dxy_du[i];
                let a = Vector4::new(1.0, x, x * x, side);
                let r = y - a.dot(&params);
                let g = Vector4::new(0.0, r * xu, 2.0 * x * r * xu, 0.0)
                    + a * (yu - (m + 2.0 * c * x) * xu);
                let phi = [v * v, v, 1.0];
                for (col, f) in phi.iter().enumerate() {
                    for row in 0..4 {
                        b[(row, 3 * lane + col)] += g[row] * f;
                    }
                }
            }
        }
        let jp = chol.solve_cols(&b);
        // Outputs from (y0, m, c, W).
        let s2 = 1.0 + m * m;
        let s = s2.sqrt();
        let s3 = s2 * s;
        let geometry = EgoGeometry {
            lateral_offset_m: -y0 / s,
            heading_rad: -m.atan(),
            curvature_per_m: 2.0 * c / s3,
            lane_width_m: w / s,
        };
        #[rustfmt::skip]
        let jo = Matrix4::new(
            -1.0 / s, y0 * m / s3,                  0.0,       0.0,
            0.0,      -1.0 / s2,                    0.0,       0.0,
            0.0,      -6.0 * c * m / (s3 * s2),     2.0 / s3,  0.0,
            0.0,      -w * m / s3,                  0.0,       1.0 / s,
        );
        Ok((geometry, jo * jp))
    }

    /// The geometry with its covariance `J·diag(P_left, P_right)·Jᵀ` and standard deviations,
    /// from each lane's coefficients `[a1, a2, a3]` (px) and their 3×3 covariance (pixel
    /// parameterisation: entry `(i, j)` in units of `a_i·a_j`).
    ///
    /// # Errors
    /// As [`Self::geometry_with_jacobian`]; [`GeometryError::NonFinite`] for a covariance with a
    /// NaN/∞ entry.
    pub fn estimate(
        &self,
        left_px: &[f64; 3],
        left_cov_px: &Matrix3<f64>,
        right_px: &[f64; 3],
        right_cov_px: &Matrix3<f64>,
    ) -> Result<EgoLane, GeometryError> {
        if left_cov_px.iter().any(|v| !v.is_finite()) {
            return Err(GeometryError::NonFinite {
                what: "left lane covariance",
            });
        }
        if right_cov_px.iter().any(|v| !v.is_finite()) {
            return Err(GeometryError::NonFinite {
                what: "right lane covariance",
            });
        }
        let (geometry, j) = self.geometry_with_jacobian(left_px, right_px)?;
        let jl = j.fixed_columns::<3>(0);
        let jr = j.fixed_columns::<3>(3);
        let cov = jl * left_cov_px * jl.transpose() + jr * right_cov_px * jr.transpose();
        let cov = 0.5 * (cov + cov.transpose());
        let sd = |i: usize| cov[(i, i)].max(0.0).sqrt();
        Ok(EgoLane {
            geometry,
            sigma: EgoGeometry {
                lateral_offset_m: sd(0),
                heading_rad: sd(1),
                curvature_per_m: sd(2),
                lane_width_m: sd(3),
            },
            covariance: cov,
        })
    }
}

/// 4×4 Cholesky with the failing pivot reported (no allocation).
struct Chol4 {
    l: Matrix4<f64>,
}

impl Chol4 {
    fn new(a: &Matrix4<f64>) -> Result<Self, GeometryError> {
        let mut l = Matrix4::<f64>::zeros();
        for j in 0..4 {
            let mut d = a[(j, j)];
            for k in 0..j {
                d -= l[(j, k)] * l[(j, k)];
            }
            // Relative pivot floor: singular if the pivot is negligible against its diagonal entry.
            if !crate::greater(d, 1e-12 * a[(j, j)].abs()) || !d.is_finite() {
                return Err(GeometryError::SingularFit { pivot: j, value: d });
            }
            let djj = d.sqrt();
            l[(j, j)] = djj;
            for i in j + 1..4 {
                let mut s = a[(i, j)];
                for k in 0..j {
                    s -= l[(i, k)] * l[(j, k)];
                }
                l[(i, j)] = s / djj;
            }
        }
        Ok(Self { l })
    }

    fn solve(&self, b: &Vector4<f64>) -> Vector4<f64> {
        let l = &self.l;
        let mut y = *b;
        for i in 0..4 {
            for k in 0..i {
                y[i] -= l[(i, k)] * y[k];
            }
            y[i] /= l[(i, i)];
        }
        for i in (0..4).rev() {
            for k in i + 1..4 {
                y[i] -= l[(k, i)] * y[k];
            }
            y[i] /= l[(i, i)];
        }
        y
    }

    fn solve_cols(&self, b: &EgoJacobian) -> EgoJacobian {
        let mut out = EgoJacobian::zeros();
        for c in 0..6 {
            let col = self.solve(&Vector4::new(b[(0, c)], b[(1, c)], b[(2, c)], b[(3, c)]));
            out.set_column(c, &col);
        }
        out
    }
}
