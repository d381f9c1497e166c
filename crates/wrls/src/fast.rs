//! Fast WRLS: information form driven by power sums.

use info_filter::{
    Cholesky, KifError, PixelPoint, PowerSums, RowNorm, ThetaCov, symmetrise, validate_spd,
};
use nalgebra::{Matrix3, Vector3};

use crate::WrlsError;
use crate::config::validate_lambda;

/// Exponentially weighted RLS for the lane parabola in information form:
///
/// ```text
/// Y_t = λ Y_{t−1} + Σ_i φ_i φ_iᵀ,   ŷ_t = λ ŷ_{t−1} + Σ_i φ_i x_i,   θ̂_t = Y_t⁻¹ ŷ_t
/// ```
///
/// with `Y = P⁻¹`, the sums built from [`PowerSums`] (no `N×N` matrix, no allocation) and λ
/// applied once per frame. This is algebraically the same estimator as
/// [`WrlsPaper`](crate::WrlsPaper) (eqs. 25–27, corrected), by the matrix inversion lemma.
#[derive(Debug, Clone, PartialEq)]
pub struct WrlsFast {
    info: Matrix3<f64>,
    info_vec: Vector3<f64>,
    theta: Vector3<f64>,
    lambda: f64,
    row_norm: RowNorm,
}

impl WrlsFast {
    /// Starts from `theta0_px = (a1 [1/px], a2 [1], a3 [px])` with covariance `p0` and
    /// forgetting factor `lambda ∈ (0, 1]`.
    ///
    /// # Errors
    /// [`WrlsError::InvalidForgettingFactor`]; invalid `row_norm`, non-finite `theta0_px` or
    /// `p0` not symmetric positive definite (as [`WrlsError::Filter`]).
    pub fn new(
        theta0_px: &Vector3<f64>,
        p0: &ThetaCov,
        lambda: f64,
        row_norm: RowNorm,
    ) -> Result<Self, WrlsError> {
        validate_lambda(lambda)?;
        row_norm.validate()?;
        let (theta, p0_u) = crate::prior_normalised(theta0_px, p0, &row_norm)?;
        let (_, chol) = validate_spd(&p0_u, "P0")?;
        let info = chol.inverse();
        Ok(Self {
            info,
            info_vec: info * theta,
            theta,
            lambda,
            row_norm,
        })
    }

    /// One frame: forget once (`Y ← λY`, `ŷ ← λŷ`), then add every point with unit weight.
    /// A frame with no points only forgets (θ̂ unchanged, `P ← P/λ`), exactly as eqs. 25–27
    /// with `N = 0`.
    ///
    /// # Errors
    /// Non-finite point (index), or the new `Y` failing Cholesky. On error the state is unchanged.
    #[inline]
    pub fn update<P: PixelPoint>(&mut self, points: &[P]) -> Result<(), WrlsError> {
        let sums = PowerSums::from_points(points, &self.row_norm)?;
        self.update_sums(&sums)
    }

    /// One frame from precomputed power sums (normalised with this estimator's [`RowNorm`]).
    ///
    /// # Errors
    /// The new `Y` failing Cholesky (pivot reported). On error the state is unchanged.
    #[inline]
    pub fn update_sums(&mut self, sums: &PowerSums) -> Result<(), WrlsError> {
        let mut info = self.info * self.lambda + sums.normal_matrix();
        symmetrise(&mut info);
        let info_vec = self.info_vec * self.lambda + sums.normal_vector();
        let chol = Cholesky::new(&info, "Y").map_err(KifError::from)?;
        self.theta = chol.solve(&info_vec);
        self.info = info;
        self.info_vec = info_vec;
        Ok(())
    }

    /// Estimate `θ̂_px = (a1 [1/px], a2 [1], a3 [px])`.
    pub fn estimate(&self) -> Vector3<f64> {
        self.row_norm.theta_to_px(&self.theta)
    }

    /// Estimate in the normalised parameterisation (px).
    pub fn estimate_normalised(&self) -> Vector3<f64> {
        self.theta
    }

    /// `P_u = Y⁻¹` (normalised parameterisation). For WRLS `P` is a scaled inverse normal
    /// matrix, not a covariance in px² unless the residual variance is 1 px².
    ///
    /// # Errors
    /// `Y` failing Cholesky (cannot happen after a successful update).
    pub fn covariance_normalised(&self) -> Result<Matrix3<f64>, WrlsError> {
        Ok(Cholesky::new(&self.info, "Y")
            .map_err(KifError::from)?
            .inverse())
    }

    /// `P_px = T P_u Tᵀ`.
    ///
    /// # Errors
    /// As [`Self::covariance_normalised`].
    pub fn covariance(&self) -> Result<Matrix3<f64>, WrlsError> {
        Ok(self.row_norm.cov_to_px(&self.covariance_normalised()?))
    }

    /// Information matrix `Y_u = P_u⁻¹`.
    pub fn information_normalised(&self) -> Matrix3<f64> {
        self.info
    }

    /// The forgetting factor λ.
    pub fn lambda(&self) -> f64 {
        self.lambda
    }

    /// The row normalisation in use.
    pub fn row_norm(&self) -> &RowNorm {
        &self.row_norm
    }

    /// Restarts from a new prior, keeping λ and the row normalisation.
    ///
    /// # Errors
    /// As [`Self::new`]; on error the state is unchanged.
    pub fn reset(&mut self, theta0_px: &Vector3<f64>, p0: &ThetaCov) -> Result<(), WrlsError> {
        *self = Self::new(theta0_px, p0, self.lambda, self.row_norm)?;
        Ok(())
    }
}
