//! Normalised row coordinate `u = (y − y_c)/s` and the linear maps between the pixel and the
//! normalised parabola parameterisations.

use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};

use crate::KifError;

/// Row normalisation `u = (row_px − center_row_px) / scale_px`.
///
/// The parabola `x = a1·y² + a2·y + a3` (pixels) equals `x = b1·u² + b2·u + b3` with
/// `θ_u = (b1, b2, b3) = M θ_px`, `θ_px = T θ_u`,
///
/// ```text
///     ⎡ s²      0    0 ⎤          ⎡  1/s²       0     0 ⎤
/// M = ⎢ 2 s y_c  s    0 ⎥,   T = M⁻¹ = ⎢ −2 y_c/s²   1/s    0 ⎥
///     ⎣ y_c²    y_c  1 ⎦          ⎣  y_c²/s²  −y_c/s  1 ⎦
/// ```
///
/// Covariances map as `P_px = T P_u Tᵀ` (so `Q_px = T Q_u Tᵀ`), information as
/// `Y_px = Mᵀ Y_u M`, information vectors as `ŷ_px = Mᵀ ŷ_u`. The regressor maps as
/// `φ_u = Tᵀ φ_px` (`φ_px = (y², y, 1)`, `φ_u = (u², u, 1)`). The measurement `x` (column, px)
/// and its variance `R` (px²) are the same in both parameterisations.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RowNorm {
    /// Row mapped to `u = 0`, pixels. Any finite value; the image's middle row is a good choice.
    pub center_row_px: f64,
    /// Rows per unit of `u`, pixels; finite and `> 0`. Half the image height maps the image to
    /// `u ∈ [−1, 1]`. `1.0` with `center_row_px = 0.0` disables normalisation (badly conditioned).
    pub scale_px: f64,
}

impl Default for RowNorm {
    /// The paper's 320×240 frames: `center_row_px = 120`, `scale_px = 120`.
    fn default() -> Self {
        Self {
            center_row_px: 120.0,
            scale_px: 120.0,
        }
    }
}

impl RowNorm {
    /// Validated constructor.
    ///
    /// # Errors
    /// [`KifError::InvalidRowNorm`] naming the field.
    pub fn new(center_row_px: f64, scale_px: f64) -> Result<Self, KifError> {
        let n = Self {
            center_row_px,
            scale_px,
        };
        n.validate()?;
        Ok(n)
    }

    /// Maps an image of `height_px` rows onto `u ∈ [−1, 1]`
    /// (`center_row_px = (height_px − 1)/2`, `scale_px = height_px/2`).
    ///
    /// # Errors
    /// [`KifError::InvalidRowNorm`] if `height_px` is 0.
    pub fn for_image_height(height_px: u32) -> Result<Self, KifError> {
        let h = f64::from(height_px);
        Self::new(0.5 * (h - 1.0), 0.5 * h)
    }

    /// Checks `center_row_px` is finite and `scale_px` is finite and `> 0`.
    ///
    /// # Errors
    /// [`KifError::InvalidRowNorm`] naming the field.
    pub fn validate(&self) -> Result<(), KifError> {
        if !self.center_row_px.is_finite() {
            return Err(KifError::InvalidRowNorm {
                field: "center_row_px",
                value: self.center_row_px,
                reason: "must be finite",
            });
        }
        if !(self.scale_px.is_finite() && self.scale_px > 0.0) {
            return Err(KifError::InvalidRowNorm {
                field: "scale_px",
                value: self.scale_px,
                reason: "must be finite and > 0",
            });
        }
        Ok(())
    }

    /// `u = (row_px − center_row_px) / scale_px`.
    #[inline]
    pub fn normalise_row(&self, row_px: f64) -> f64 {
        (row_px - self.center_row_px) / self.scale_px
    }

    /// `M` with `θ_u = M θ_px` (see the type documentation).
    pub fn px_to_normalised_matrix(&self) -> Matrix3<f64> {
        let (s, c) = (self.scale_px, self.center_row_px);
        Matrix3::new(s * s, 0.0, 0.0, 2.0 * s * c, s, 0.0, c * c, c, 1.0)
    }

    /// `T = M⁻¹` with `θ_px = T θ_u` (see the type documentation).
    pub fn normalised_to_px_matrix(&self) -> Matrix3<f64> {
        let (s, c) = (self.scale_px, self.center_row_px);
        let s2 = s * s;
        Matrix3::new(
            1.0 / s2,
            0.0,
            0.0,
            -2.0 * c / s2,
            1.0 / s,
            0.0,
            c * c / s2,
            -c / s,
            1.0,
        )
    }

    /// `θ_px = T θ_u`.
    pub fn theta_to_px(&self, theta_u: &Vector3<f64>) -> Vector3<f64> {
        self.normalised_to_px_matrix() * theta_u
    }

    /// `θ_u = M θ_px`.
    pub fn theta_to_normalised(&self, theta_px: &Vector3<f64>) -> Vector3<f64> {
        self.px_to_normalised_matrix() * theta_px
    }

    /// `P_px = T P_u Tᵀ` (covariances of θ, including `Q`).
    pub fn cov_to_px(&self, p_u: &Matrix3<f64>) -> Matrix3<f64> {
        let t = self.normalised_to_px_matrix();
        t * p_u * t.transpose()
    }

    /// `P_u = M P_px Mᵀ` (covariances of θ, including `Q`).
    pub fn cov_to_normalised(&self, p_px: &Matrix3<f64>) -> Matrix3<f64> {
        let m = self.px_to_normalised_matrix();
        m * p_px * m.transpose()
    }

    /// `Y_px = Mᵀ Y_u M` (information matrices).
    pub fn info_to_px(&self, y_u: &Matrix3<f64>) -> Matrix3<f64> {
        let m = self.px_to_normalised_matrix();
        m.transpose() * y_u * m
    }

    /// `ŷ_px = Mᵀ ŷ_u` (information vectors).
    pub fn info_vec_to_px(&self, y_hat_u: &Vector3<f64>) -> Vector3<f64> {
        self.px_to_normalised_matrix().transpose() * y_hat_u
    }
}

/// A covariance of the parabola coefficients θ, tagged with its parameterisation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ThetaCov {
    /// In the paper's pixel convention `(a1 [px⁻¹], a2 [1], a3 [px])`: entry `(i,j)` has units
    /// of `a_i · a_j`.
    Px(Matrix3<f64>),
    /// In the normalised convention `(b1, b2, b3)`, all in pixels of column (`x`): units px².
    Normalised(Matrix3<f64>),
}

impl ThetaCov {
    /// The covariance in the normalised parameterisation of `row_norm`.
    pub fn to_normalised(&self, row_norm: &RowNorm) -> Matrix3<f64> {
        match self {
            Self::Px(p) => row_norm.cov_to_normalised(p),
            Self::Normalised(p) => *p,
        }
    }
}
