//! The lane-tracking hot path: the 3-parameter parabola `x = a1·y² + a2·y + a3` updated from
//! power sums of the measured pixels.

use nalgebra::{Matrix3, Vector3};

use crate::KifError;
use crate::chol::check_finite_vec;
use crate::generic::{InformationFilter, ProcessNoise, TimeUpdateForm};
use crate::rownorm::{RowNorm, ThetaCov};
/// The workspace's one pixel point type (crate `grey-frame`), re-exported.
pub use grey_frame::PixelPoint;

/// Power sums of one frame's points in the normalised row coordinate `u`:
/// `Σu⁰ … Σu⁴` and `Σx·u⁰ … Σx·u²`. With `R = σ²I`,
/// `φR⁻¹φᵀ = H/σ²` and `φR⁻¹x = b/σ²` where
///
/// ```text
///     ⎡ Σu⁴ Σu³ Σu² ⎤        ⎡ Σx·u² ⎤
/// H = ⎢ Σu³ Σu² Σu  ⎥,   b = ⎢ Σx·u  ⎥
///     ⎣ Σu² Σu  N   ⎦        ⎣ Σx    ⎦
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PowerSums {
    /// `N = Σu⁰` (number of points).
    pub count: f64,
    /// `Σu`.
    pub sum_u: f64,
    /// `Σu²`.
    pub sum_u2: f64,
    /// `Σu³`.
    pub sum_u3: f64,
    /// `Σu⁴`.
    pub sum_u4: f64,
    /// `Σx`, px.
    pub sum_x: f64,
    /// `Σx·u`, px.
    pub sum_xu: f64,
    /// `Σx·u²`, px.
    pub sum_xu2: f64,
}

impl PowerSums {
    /// Accumulates the sums over `points` (`x` = column px, `y` = row px) in one pass, no
    /// allocation.
    ///
    /// # Errors
    /// [`KifError::NonFinitePoint`] with the index of the first NaN/infinite point;
    /// [`KifError::PowerSumOverflow`] if finite points overflowed the sums.
    #[inline]
    pub fn from_points<P: PixelPoint>(points: &[P], row_norm: &RowNorm) -> Result<Self, KifError> {
        let c = row_norm.center_row_px;
        let inv_s = 1.0 / row_norm.scale_px;
        let mut s = Self {
            count: points.len() as f64,
            ..Self::default()
        };
        for p in points {
            let x = p.col_px();
            let u = (p.row_px() - c) * inv_s;
            let u2 = u * u;
            s.sum_u += u;
            s.sum_u2 += u2;
            s.sum_u3 += u2 * u;
            s.sum_u4 += u2 * u2;
            s.sum_x += x;
            s.sum_xu += x * u;
            s.sum_xu2 += x * u2;
        }
        // Any NaN/∞ coordinate poisons the sums, so one check after the loop suffices; the
        // rescan runs only on the error path.
        if !s.is_finite() {
            for (index, p) in points.iter().enumerate() {
                let (col_px, row_px) = (p.col_px(), p.row_px());
                if !col_px.is_finite() || !row_px.is_finite() {
                    return Err(KifError::NonFinitePoint {
                        index,
                        col_px,
                        row_px,
                    });
                }
            }
            return Err(KifError::PowerSumOverflow);
        }
        Ok(s)
    }

    /// Weighted power sums `Σw·u⁰ … Σw·u⁴`, `Σw·x·u⁰ … Σw·x·u²` (`count` is `Σw`): with
    /// [`ParabolaKif::update_sums`] and `sigma2_px2 = s²` the measurement noise is
    /// `R = s²·diag(1/w_i)` — points of unequal precision (e.g. sub-pixel mark centres whose
    /// variance depends on the mark's width and contrast). Weights must be finite and > 0;
    /// `points` and `weights` are paired up to the shorter of the two. No allocation.
    ///
    /// # Errors
    /// [`KifError::NonFinitePoint`] (index of the point) for a NaN/∞ coordinate, and
    /// [`KifError::InvalidVariance`] (`"weight"`) for a weight that is not finite and > 0.
    pub fn from_weighted_points<P: PixelPoint>(
        points: &[P],
        weights: &[f64],
        row_norm: &RowNorm,
    ) -> Result<Self, KifError> {
        let c = row_norm.center_row_px;
        let inv_s = 1.0 / row_norm.scale_px;
        let mut s = Self::default();
        for (index, (p, &w)) in points.iter().zip(weights).enumerate() {
            if !(w.is_finite() && w > 0.0) {
                return Err(KifError::InvalidVariance {
                    name: "weight",
                    value: w,
                });
            }
            let (x, y) = (p.col_px(), p.row_px());
            if !x.is_finite() || !y.is_finite() {
                return Err(KifError::NonFinitePoint {
                    index,
                    col_px: x,
                    row_px: y,
                });
            }
            let u = (y - c) * inv_s;
            let (wu, u2) = (w * u, u * u);
            s.count += w;
            s.sum_u += wu;
            s.sum_u2 += wu * u;
            s.sum_u3 += wu * u2;
            s.sum_u4 += w * u2 * u2;
            s.sum_x += w * x;
            s.sum_xu += wu * x;
            s.sum_xu2 += wu * u * x;
        }
        if !s.is_finite() || !s.count.is_finite() {
            return Err(KifError::PowerSumOverflow);
        }
        Ok(s)
    }

    fn is_finite(&self) -> bool {
        [
            self.sum_u,
            self.sum_u2,
            self.sum_u3,
            self.sum_u4,
            self.sum_x,
            self.sum_xu,
            self.sum_xu2,
        ]
        .iter()
        .all(|v| v.is_finite())
    }

    /// `H = Σ φ_u φ_uᵀ` (unweighted normal matrix, normalised parameterisation).
    #[inline]
    pub fn normal_matrix(&self) -> Matrix3<f64> {
        Matrix3::new(
            self.sum_u4,
            self.sum_u3,
            self.sum_u2,
            self.sum_u3,
            self.sum_u2,
            self.sum_u,
            self.sum_u2,
            self.sum_u,
            self.count,
        )
    }

    /// `b = Σ φ_u x` (unweighted, normalised parameterisation), px.
    #[inline]
    pub fn normal_vector(&self) -> Vector3<f64> {
        Vector3::new(self.sum_xu2, self.sum_xu, self.sum_x)
    }
}

fn check_variance(name: &'static str, value: f64) -> Result<(), KifError> {
    if value > 0.0 && value.is_finite() {
        Ok(())
    } else {
        Err(KifError::InvalidVariance { name, value })
    }
}

/// Kalman information filter for one lane's parabola `x = a1·y² + a2·y + a3`.
///
/// Internally an [`InformationFilter<3>`] over the normalised coefficients `θ_u = M θ_px`
/// (see [`RowNorm`]); inputs and outputs are in the paper's pixel convention unless a method's
/// name says `normalised`.
#[derive(Debug, Clone, PartialEq)]
pub struct ParabolaKif {
    filter: InformationFilter<3>,
    row_norm: RowNorm,
}

impl ParabolaKif {
    /// Creates the filter from a prior `theta0_px = (a1 [1/px], a2 [1], a3 [px])` and its
    /// covariance `p0` (either parameterisation), using the eq. (24) time update.
    ///
    /// # Errors
    /// Invalid `row_norm`, non-finite `theta0_px`, or `p0` not symmetric positive definite
    /// (named `"P0"`, with the failing pivot, in the normalised parameterisation).
    pub fn new(
        theta0_px: &Vector3<f64>,
        p0: &ThetaCov,
        row_norm: RowNorm,
    ) -> Result<Self, KifError> {
        row_norm.validate()?;
        check_finite_vec(theta0_px, "theta0_px")?;
        let theta0_u = row_norm.theta_to_normalised(theta0_px);
        let filter = InformationFilter::new(&theta0_u, &p0.to_normalised(&row_norm))?;
        Ok(Self { filter, row_norm })
    }

    /// Selects eq. (24) (default) or eq. (7) for subsequent time updates.
    pub fn set_time_update_form(&mut self, form: TimeUpdateForm) {
        self.filter.set_time_update_form(form);
    }

    /// The row normalisation in use.
    pub fn row_norm(&self) -> &RowNorm {
        &self.row_norm
    }

    /// Validates and pre-inverts a process-noise covariance given in either parameterisation,
    /// for use with [`Self::predict`] (build it once, reuse every frame).
    ///
    /// # Errors
    /// `q` not finite / symmetric / positive definite (named `"Q"`).
    pub fn process_noise(&self, q: &ThetaCov) -> Result<ProcessNoise<3>, KifError> {
        ProcessNoise::new(&q.to_normalised(&self.row_norm))
    }

    /// Random-walk time update (eqs. 7/24, 8, 11). `q` must have been built for this filter's
    /// row normalisation (by [`Self::process_noise`], or [`ProcessNoise::new`] on a normalised
    /// `Q`).
    ///
    /// # Errors
    /// See [`InformationFilter::predict`].
    #[inline]
    pub fn predict(&mut self, q: &ProcessNoise<3>) -> Result<(), KifError> {
        self.filter.predict(q)
    }

    /// Measurement update with this frame's pixels, `R = sigma2_px2 · I` (eqs. 6, 12), built from
    /// power sums — no `N×N` or `3×N` matrix, no allocation.
    ///
    /// An empty `points` slice is a measurement carrying no information: the state is left
    /// unchanged and `Ok(())` is returned (after `sigma2_px2` is validated).
    ///
    /// # Errors
    /// [`KifError::InvalidVariance`] (`"sigma2_px2"` NaN, ∞ or ≤ 0), [`KifError::NonFinitePoint`]
    /// (index of the point), or the updated information matrix failing Cholesky. On error the
    /// state is unchanged.
    #[inline]
    pub fn update<P: PixelPoint>(&mut self, points: &[P], sigma2_px2: f64) -> Result<(), KifError> {
        check_variance("sigma2_px2", sigma2_px2)?;
        if points.is_empty() {
            return Ok(());
        }
        let sums = PowerSums::from_points(points, &self.row_norm)?;
        self.update_sums(&sums, sigma2_px2)
    }

    /// Measurement update from precomputed power sums (normalised with this filter's
    /// [`RowNorm`]), `R = sigma2_px2 · I`.
    ///
    /// # Errors
    /// As [`Self::update`].
    #[inline]
    pub fn update_sums(&mut self, sums: &PowerSums, sigma2_px2: f64) -> Result<(), KifError> {
        check_variance("sigma2_px2", sigma2_px2)?;
        let w = 1.0 / sigma2_px2;
        self.filter
            .update_information(&(sums.normal_matrix() * w), &(sums.normal_vector() * w))
    }

    /// Estimate `θ̂_px = (a1 [1/px], a2 [1], a3 [px])`.
    #[inline]
    pub fn estimate(&self) -> Vector3<f64> {
        self.row_norm.theta_to_px(&self.filter.estimate())
    }

    /// Estimate in the normalised parameterisation `θ̂_u = (b1, b2, b3)`, px.
    #[inline]
    pub fn estimate_normalised(&self) -> Vector3<f64> {
        self.filter.estimate()
    }

    /// Predicted column `x = a1·y² + a2·y + a3` at `row_px`, px.
    #[inline]
    pub fn col_at_row_px(&self, row_px: f64) -> f64 {
        let u = self.row_norm.normalise_row(row_px);
        let t = self.filter.estimate();
        (t[0] * u + t[1]) * u + t[2]
    }

    /// Covariance of `θ̂_px`, `T Y_u⁻¹ Tᵀ`.
    ///
    /// # Errors
    /// See [`InformationFilter::covariance`].
    pub fn covariance(&self) -> Result<Matrix3<f64>, KifError> {
        Ok(self.row_norm.cov_to_px(&self.filter.covariance()?))
    }

    /// Covariance of `θ̂_u`, px².
    ///
    /// # Errors
    /// See [`InformationFilter::covariance`].
    pub fn covariance_normalised(&self) -> Result<Matrix3<f64>, KifError> {
        self.filter.covariance()
    }

    /// Information matrix in the pixel parameterisation, `Mᵀ Y_u M` (badly conditioned; for
    /// reporting).
    pub fn information(&self) -> Matrix3<f64> {
        self.row_norm.info_to_px(&self.filter.information())
    }

    /// Information matrix `Y_u` actually propagated.
    pub fn information_normalised(&self) -> Matrix3<f64> {
        self.filter.information()
    }

    /// Information vector `ŷ_u` actually propagated.
    pub fn information_vector_normalised(&self) -> Vector3<f64> {
        self.filter.information_vector()
    }

    /// The underlying generic filter (normalised parameterisation).
    pub fn filter(&self) -> &InformationFilter<3> {
        &self.filter
    }

    /// Restarts from a new prior (e.g. after Hough + least-squares re-initialisation), keeping the
    /// row normalisation and time-update form.
    ///
    /// # Errors
    /// As [`Self::new`]; on error the state is unchanged.
    pub fn reset(&mut self, theta0_px: &Vector3<f64>, p0: &ThetaCov) -> Result<(), KifError> {
        check_finite_vec(theta0_px, "theta0_px")?;
        let theta0_u = self.row_norm.theta_to_normalised(theta0_px);
        self.filter
            .reset(&theta0_u, &p0.to_normalised(&self.row_norm))
    }
}
