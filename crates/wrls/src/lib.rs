//! Exponentially weighted recursive least squares (WRLS) for the lane parabola — the comparison
//! method of Pimentel & Hemerly (ITA), "lane-mark detection and tracking", §IV, eqs. (25)–(27).
//!
//! # Model
//!
//! Each frame `t = 1…T` gives `N_t` lane pixels `(x_ti, y_ti)` (column, row; px) and the
//! parabola `x = a1·y² + a2·y + a3` (eq. 1) is fitted by minimising
//!
//! ```text
//! J_T(θ) = Σ_t λ^{T−t} Σ_i (x_ti − φ_tiᵀ θ)²  +  λ^T (θ − θ0)ᵀ P0⁻¹ (θ − θ0)
//! ```
//!
//! with `φ = (y², y, 1)`, forgetting factor `λ ∈ (0, 1]` (dimensionless; the paper's best is
//! 0.70, [`PAPER_LAMBDA`]). **λ applies once per frame, not per point**: all points of a frame
//! have the same weight, and a frame with no points still ages the past by λ.
//!
//! # Two forms, the same estimator
//!
//! [`WrlsPaper`] — the paper's form, eqs. (25)–(27), with an `N×N` factorisation per frame:
//!
//! ```text
//! K_{t+1} = P_t φ (λ I_N + φᵀ P_t φ)⁻¹                                       (26)
//! θ̂_{t+1} = θ̂_t + K_{t+1} (x − φᵀ θ̂_t)                                      (25)
//! P_{t+1} = λ⁻¹ (I − K φᵀ) P_t (I − K φᵀ)ᵀ + K Kᵀ                            (27, corrected)
//! ```
//!
//! [`WrlsFast`] — the information form with power sums (as the KIF in `info-filter`):
//!
//! ```text
//! P_{t+1}⁻¹ = λ P_t⁻¹ + φ φᵀ,   P_{t+1}⁻¹ θ̂_{t+1} = λ P_t⁻¹ θ̂_t + φ x
//! ```
//!
//! They are equal because, by the matrix inversion lemma,
//! `(λ P⁻¹ + φφᵀ)⁻¹ = λ⁻¹ (P − Pφ(λI + φᵀPφ)⁻¹φᵀP) = λ⁻¹ (I − Kφᵀ) P`, and the Joseph-like
//! right-hand side of eq. (27) equals `λ⁻¹ (I − Kφᵀ) P` (it is the Joseph form with `R = λI`,
//! divided by λ). Both minimise `J_T` exactly (tests check this against the batch solution).
//!
//! # Corrections to the printed paper
//!
//! * Printed eq. (27) reads `P = λ⁻¹(I − Kxᵀ)P(I − Kxᵀ)ᵀ + λ K Kᵀ`. The algebra gives
//!   `λ⁻¹[(I − Kφᵀ)P(I − Kφᵀ)ᵀ + λ K Kᵀ] = λ⁻¹(I − Kφᵀ)P(I − Kφᵀ)ᵀ + K Kᵀ`: the λ on `KKᵀ`
//!   cancels. The printed placement differs from the correct `P` by `(λ − 1) K Kᵀ` (a test
//!   shows this is not round-off: with λ = 0.7 it changes `P` visibly).
//! * Eqs. (25) and (27) print `x_{t+1}` where the regressor `φ_{t+1}` is meant.
//! * "λ = I" in the text means λ = 1 (ordinary RLS).
//!
//! # Units and parameterisation
//!
//! As in `info-filter`, both forms work internally in the normalised row `u = (y − y_c)/s`
//! ([`RowNorm`]) on `θ_u = M θ_px`, and report `θ_px = (a1 [1/px], a2 [1], a3 [px])`. `P0` is given
//! as a [`ThetaCov`] in either parameterisation; `P` maps as `P_px = T P_u Tᵀ`. The WRLS cost is
//! unweighted, so `P` is an inverse normal matrix (a covariance only up to the residual variance,
//! px²). The estimate does not depend on the normalisation; the conditioning does.
//!
//! # Which form a timing measures
//!
//! The paper's 22.2 ms (table 1) is the form with the `N×N` inversion — [`WrlsPaper`]. The
//! benches measure both.
//!
//! # Example
//!
//! ```
//! use info_filter::{RowNorm, ThetaCov};
//! use nalgebra::{Matrix3, Vector3};
//! use wrls::{PAPER_LAMBDA, WrlsFast, WrlsPaper};
//!
//! # fn main() -> Result<(), wrls::WrlsError> {
//! let truth = Vector3::new(1e-3, -0.5, 200.0); // x = 0.001·y² − 0.5·y + 200, px
//! let frame: Vec<[f64; 2]> = (0..60)
//!     .map(|i| {
//!         let y = 60.0 + 3.0 * f64::from(i);
//!         [truth[0] * y * y + truth[1] * y + truth[2], y]
//!     })
//!     .collect();
//! let p0 = ThetaCov::Normalised(Matrix3::identity() * 1e6); // a weak prior, px²
//! let theta0 = Vector3::new(0.0, 0.0, 160.0);
//! let mut paper = WrlsPaper::new(&theta0, &p0, PAPER_LAMBDA, RowNorm::default(), 150)?;
//! let mut fast = WrlsFast::new(&theta0, &p0, PAPER_LAMBDA, RowNorm::default())?;
//! for _ in 0..5 {
//!     paper.update(&frame)?;
//!     fast.update(&frame)?;
//! }
//! assert!((paper.estimate() - truth).norm() < 1e-6 * truth.norm());
//! assert!((paper.estimate() - fast.estimate()).norm() < 1e-9 * truth.norm());
//! # Ok(())
//! # }
//! ```

mod config;
mod error;
mod fast;
mod paper;

pub use config::{PAPER_LAMBDA, WrlsConfig};
pub use error::WrlsError;
pub use fast::WrlsFast;
pub use info_filter::{PixelPoint, PowerSums, RowNorm, ThetaCov};
pub use paper::WrlsPaper;

use info_filter::KifError;
use nalgebra::{Matrix3, Vector3};

/// Checks `theta0_px` and maps the prior to the normalised parameterisation.
fn prior_normalised(
    theta0_px: &Vector3<f64>,
    p0: &ThetaCov,
    row_norm: &RowNorm,
) -> Result<(Vector3<f64>, Matrix3<f64>), WrlsError> {
    for (index, &value) in theta0_px.iter().enumerate() {
        if !value.is_finite() {
            return Err(KifError::NonFiniteVector {
                vector: "theta0_px",
                index,
                value,
            }
            .into());
        }
    }
    Ok((
        row_norm.theta_to_normalised(theta0_px),
        p0.to_normalised(row_norm),
    ))
}
