//! The ego lane on the ground plane from the two image parabolas, with its covariance.

use nalgebra::{Matrix2, Matrix3, Matrix4, SMatrix, Vector3, Vector4};

use crate::{GeometryError, Homography};

/// Image rows at which each lane parabola is sampled and mapped to the ground.
pub const SAMPLE_ROWS: usize = 8;

const SAMPLES: usize = 2 * SAMPLE_ROWS;

/// Rows per lane of the forward model's image-parabola fit (step 5 of the crate docs).
pub const FIT_SAMPLES: usize = 6;

/// How a tracker fitted one lane's image parabola: [`FIT_SAMPLES`] image rows and the total
/// least-squares weight of its points near each (e.g. the weighted mean row and the summed
/// weight of the points in each eighth of the fitted rows). Step 5 of the crate docs fits the
/// forward model's parabola with the same rows and weights.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FitRows {
    /// Image rows, px.
    pub rows_px: [f64; FIT_SAMPLES],
    /// Their weights (≥ 0; at least three rows with a positive weight).
    pub weights: [f64; FIT_SAMPLES],
}

impl FitRows {
    /// Points spread evenly over the rows `[first_px, last_px]`: equal weights on the centres
    /// of [`FIT_SAMPLES`] equal bins.
    pub fn uniform(first_px: f64, last_px: f64) -> Self {
        let mut rows_px = [0.0; FIT_SAMPLES];
        for (k, r) in rows_px.iter_mut().enumerate() {
            *r = first_px + (last_px - first_px) * (k as f64 + 0.5) / FIT_SAMPLES as f64;
        }
        Self {
            rows_px,
            weights: [1.0; FIT_SAMPLES],
        }
    }

    fn validate(&self) -> Result<(), GeometryError> {
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        let mut positive = 0;
        for (&r, &w) in self.rows_px.iter().zip(&self.weights) {
            if !(r.is_finite() && w.is_finite() && w >= 0.0) {
                return Err(GeometryError::InvalidParameter {
                    field: "fit_rows",
                    value: if r.is_finite() { w } else { r },
                    reason: "rows must be finite and weights finite and >= 0",
                });
            }
            if w > 0.0 {
                positive += 1;
                lo = lo.min(r);
                hi = hi.max(r);
            }
        }
        if positive < 3 || !crate::greater(hi - lo, 2.0) {
            return Err(GeometryError::InvalidParameter {
                field: "fit_rows",
                value: f64::from(positive),
                reason: "need at least 3 weighted rows spanning more than 2 px",
            });
        }
        Ok(())
    }
}

/// The forward model's samples of one lane (step 5 of the crate docs).
#[derive(Debug, Clone, Copy)]
struct Samples {
    /// Forward distances, m.
    xs_m: [f64; 2 * FIT_SAMPLES],
    /// Least-squares weights.
    weights: [f64; 2 * FIT_SAMPLES],
    /// Row normalisation of the fit, px.
    centre_px: f64,
    scale_px: f64,
}

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
        let (p, jp) = self.params_with_jacobian(left_px, right_px)?;
        Ok(Self::outputs(&p, &jp))
    }

    /// [`Self::geometry_with_jacobian`] with the image-parabola model error removed (step 5 of
    /// the crate docs): `fit` says over which rows, with which weights, the tracker fitted the
    /// left and the right parabola.
    ///
    /// # Errors
    /// As [`Self::geometry_with_jacobian`]; [`GeometryError::InvalidParameter`] (`fit_rows`)
    /// for non-finite rows or weights, or fewer than 3 weighted rows spanning 2 px;
    /// [`GeometryError::BeyondHorizon`] / [`GeometryError::SingularFit`] if the forward model
    /// leaves the ground.
    pub fn geometry_with_jacobian_fitted(
        &self,
        left_px: &[f64; 3],
        right_px: &[f64; 3],
        fit: &[FitRows; 2],
    ) -> Result<(EgoGeometry, EgoJacobian), GeometryError> {
        let (p_e, jp) = self.params_with_jacobian(left_px, right_px)?;
        let (p, d_inv) = self.model_consistent(&p_e, fit)?;
        Ok(Self::outputs(&p, &(d_inv * jp)))
    }

    fn params_with_jacobian(
        &self,
        left_px: &[f64; 3],
        right_px: &[f64; 3],
    ) -> Result<(Vector4<f64>, EgoJacobian), GeometryError> {
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
        let (m, c) = (params[1], params[2]);
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
        Ok((params, jp))
    }

    /// The ground-model parameters `p = (y0, m, c, W)` of step 3 (crate docs) fitted to the two
    /// image parabolas, without the Jacobian (the forward model's inner loop).
    fn params_only(
        &self,
        left_px: &[f64; 3],
        right_px: &[f64; 3],
    ) -> Result<Vector4<f64>, GeometryError> {
        let mut n = Matrix4::<f64>::zeros();
        let mut rhs = Vector4::<f64>::zeros();
        for (lane, theta) in [left_px, right_px].into_iter().enumerate() {
            let side = if lane == 0 { -0.5 } else { 0.5 };
            for &v in &self.rows_px {
                let u = (theta[0] * v + theta[1]) * v + theta[2];
                let p = self.homography.image_to_ground([u, v])?;
                let a = Vector4::new(1.0, p[0], p[0] * p[0], side);
                n += a * a.transpose();
                rhs += a * p[1];
            }
        }
        Ok(Chol4::new(&n)?.solve(&rhs))
    }

    /// The image parabola the tracker would fit, by least squares with the rows and weights of
    /// `fit`, to the image of the mark
    /// `Y = y0 + m·X + c·X² + side·W` of the ground model `p` (`side` = ∓½). `xs_m` are the
    /// forward distances of the sample rows on the line `Y = 0`.
    fn image_parabola_of(
        &self,
        p: &Vector4<f64>,
        side: f64,
        samples: &Samples,
    ) -> Result<[f64; 3], GeometryError> {
        let (vc, vs) = (samples.centre_px, samples.scale_px);
        let mut n = Matrix3::<f64>::zeros();
        let mut rhs = Vector3::<f64>::zeros();
        for (&x, &w) in samples.xs_m.iter().zip(&samples.weights) {
            let y = p[0] + (p[1] + p[2] * x) * x + side * p[3];
            let [u, v] = self.homography.ground_to_image([x, y])?;
            let t = (v - vc) / vs;
            let phi = Vector3::new(t * t, t, 1.0);
            n += w * phi * phi.transpose();
            rhs += w * u * phi;
        }
        let b = n
            .cholesky()
            .ok_or(GeometryError::SingularFit {
                pivot: 0,
                value: 0.0,
            })?
            .solve(&rhs);
        let (b1, b2, b3) = (b[0] / (vs * vs), b[1] / vs, b[2]);
        Ok([b1, b2 - 2.0 * b1 * vc, (b1 * vc - b2) * vc + b3])
    }

    /// `G(p)`: the ground model `p` seen as the two image parabolas the tracker fits over
    /// `fit` (left, right) and mapped back by step 3.
    fn round_trip(
        &self,
        p: &Vector4<f64>,
        samples: &[Samples; 2],
    ) -> Result<Vector4<f64>, GeometryError> {
        let l = self.image_parabola_of(p, -0.5, &samples[0])?;
        let r = self.image_parabola_of(p, 0.5, &samples[1])?;
        self.params_only(&l, &r)
    }

    /// The forward model's samples of one lane's fit: two rows per row of `fit`, at
    /// `±h/(2√3)` (`h` the spacing of the rows of `fit`, so each pair has the second moment of
    /// the points spread evenly over its bin) with half its weight each, and their forward
    /// distances on the line `Y = 0`.
    fn samples(&self, fit: &FitRows) -> Result<Samples, GeometryError> {
        let (lo, hi) = fit
            .rows_px
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &r| {
                (a.min(r), b.max(r))
            });
        let half = 0.5 * (hi - lo) / (FIT_SAMPLES - 1) as f64 / 3f64.sqrt();
        // The image of the ground line Y = 0 through two of its points.
        let [u1, v1] = self.homography.ground_to_image([1.0, 0.0])?;
        let [u2, v2] = self.homography.ground_to_image([2.0, 0.0])?;
        let mut out = Samples {
            xs_m: [0.0; 2 * FIT_SAMPLES],
            weights: [0.0; 2 * FIT_SAMPLES],
            centre_px: 0.5 * (lo + hi),
            scale_px: (0.5 * (hi - lo) + half).max(1.0),
        };
        for (k, (&r, &w)) in fit.rows_px.iter().zip(&fit.weights).enumerate() {
            for (j, v) in [r - half, r + half].into_iter().enumerate() {
                let u = u1 + (u2 - u1) * (v - v1) / (v2 - v1);
                out.xs_m[2 * k + j] = self.homography.image_to_ground([u, v])?[0];
                out.weights[2 * k + j] = 0.5 * w;
            }
        }
        Ok(out)
    }

    /// Step 5 (crate docs): the ground model `p*` whose image parabolas, fitted over the rows
    /// and weights the tracker fitted with (`fit`, left and right), map back to the same `p_E`
    /// as the tracked parabolas; and the factor `D⁻¹` that carries the Jacobian.
    fn model_consistent(
        &self,
        p_e: &Vector4<f64>,
        fit: &[FitRows; 2],
    ) -> Result<(Vector4<f64>, Matrix4<f64>), GeometryError> {
        fit[0].validate()?;
        fit[1].validate()?;
        let samples = [self.samples(&fit[0])?, self.samples(&fit[1])?];
        // One Newton step on G(p) = p_E from p_E, with D = ∂G/∂p ≈ I + β·e_cᵀ (G is exact for
        // straight lanes, so only the curvature column departs from the identity; β by a
        // forward difference in c): p* = p_E + D⁻¹·(p_E − G(p_E)), D⁻¹ = I − β·e_cᵀ/(1 + β_c).
        let g = self.round_trip(p_e, &samples)?;
        let far = samples
            .iter()
            .flat_map(|s| s.xs_m.iter())
            .fold(1e-3f64, |a, &x| a.max(x.abs()));
        let dc = 0.01 / far;
        let mut pd = *p_e;
        pd[2] += dc;
        let beta = (self.round_trip(&pd, &samples)? - g) / dc - Vector4::new(0.0, 0.0, 1.0, 0.0);
        let mut d_inv = Matrix4::<f64>::identity();
        let denom = 1.0 + beta[2];
        if !crate::greater(denom.abs(), 1e-6) {
            return Err(GeometryError::SingularFit {
                pivot: 2,
                value: denom,
            });
        }
        for r in 0..4 {
            d_inv[(r, 2)] -= beta[r] / denom;
        }
        Ok((p_e + d_inv * (p_e - g), d_inv))
    }

    /// Outputs of step 4 and their Jacobian from `p = (y0, m, c, W)` and `∂p/∂θ`.
    fn outputs(params: &Vector4<f64>, jp: &EgoJacobian) -> (EgoGeometry, EgoJacobian) {
        let (y0, m, c, w) = (params[0], params[1], params[2], params[3]);
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
        (geometry, jo * jp)
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
        self.estimate_impl(left_px, left_cov_px, right_px, right_cov_px, None)
    }

    /// [`Self::estimate`] with the image-parabola model error removed (step 5 of the crate
    /// docs, [`Self::geometry_with_jacobian_fitted`]): `fit` says over which rows, with which
    /// weights, the tracker fitted the left and the right parabola. The covariance is
    /// propagated through the corrected map.
    ///
    /// # Errors
    /// As [`Self::estimate`] and [`Self::geometry_with_jacobian_fitted`].
    pub fn estimate_fitted(
        &self,
        left_px: &[f64; 3],
        left_cov_px: &Matrix3<f64>,
        right_px: &[f64; 3],
        right_cov_px: &Matrix3<f64>,
        fit: &[FitRows; 2],
    ) -> Result<EgoLane, GeometryError> {
        self.estimate_impl(left_px, left_cov_px, right_px, right_cov_px, Some(fit))
    }

    fn estimate_impl(
        &self,
        left_px: &[f64; 3],
        left_cov_px: &Matrix3<f64>,
        right_px: &[f64; 3],
        right_cov_px: &Matrix3<f64>,
        fit: Option<&[FitRows; 2]>,
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
        let (geometry, j) = match fit {
            Some(rows) => self.geometry_with_jacobian_fitted(left_px, right_px, rows)?,
            None => self.geometry_with_jacobian(left_px, right_px)?,
        };
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
