//! Kalman information filter (KIF) in positive-definite form, for tracking a lane mark's
//! parabola frame to frame — Pimentel & Hemerly (ITA), "lane-mark detection and tracking",
//! §III, eqs. (2)–(12) and (24).
//!
//! # Model (eqs. 2–5)
//!
//! Per lane, the coefficients `θ = (a1, a2, a3)` of `x = a1·y² + a2·y + a3` (eq. 1; `x` column,
//! `y` row, both in pixels; `a1` in px⁻¹, `a2` dimensionless, `a3` in px) follow a random walk and
//! are observed through the `N` lane pixels of each frame:
//!
//! ```text
//! θ_{t+1} = θ_t + w_t,        Cov(w_t) = Q            (3×3)
//! x_t     = φ_tᵀ θ_t + v_t,   Cov(v_t) = R = σ² I_N   (σ² in px²)
//! ```
//!
//! where row `i` of `φ_tᵀ` is `(y_i², y_i, 1)`.
//!
//! # Filter (information form)
//!
//! With `Y = P⁻¹` and `ŷ = Y θ̂`:
//!
//! ```text
//! measurement update (eqs. 6, 12):  Y_{t|t} = Y_{t|t−1} + φ R⁻¹ φᵀ
//!                                   ŷ_{t|t} = ŷ_{t|t−1} + φ R⁻¹ x
//!                                   θ̂_{t|t} = Y_{t|t}⁻¹ ŷ_{t|t}        (3×3 Cholesky solve)
//! time update (eqs. 8, 11, 24):     B = Y_{t|t} (Y_{t|t} + Q⁻¹)⁻¹
//!                                   Y_{t+1|t} = (I−B) Y_{t|t} (I−B)ᵀ + B Q⁻¹ Bᵀ     (eq. 24)
//!                                   ŷ_{t+1|t} = (I−B) ŷ_{t|t}
//! ```
//!
//! Eq. (7), `Y_{t+1|t} = (I−B) Y_{t|t}`, is algebraically equal to eq. (24) because
//! `B (Y + Q⁻¹) = Y`; both are `(Y⁻¹ + Q)⁻¹`. Eq. (24) is the default
//! ([`TimeUpdateForm::PositiveDefinite`]); eq. (7) is available as [`TimeUpdateForm::Plain`].
//!
//! With `R = σ² I` the products `φR⁻¹φᵀ` and `φR⁻¹x` are built from the power sums
//! `Σy⁰…Σy⁴` and `Σx·y⁰…Σx·y²` ([`PowerSums`]) in one pass over the points: no `N×N` or `3×N`
//! matrix, no allocation. That, and the single 3×3 solve, is the KIF's speed advantage.
//!
//! # Corrections to the printed paper
//!
//! * Eqs. (11) and (12) as printed propagate `θ̂`; the vector propagated is the information
//!   vector `ŷ = Y θ̂` (as printed, `θ̂` and `φR⁻¹x` would be added in different units).
//! * Eq. (10), the "gain", is dimensionally inconsistent as printed and is not needed.
//! * Eq. (24) is printed as one step including the next measurement; here it is split into the
//!   time update above followed by the measurement update, which is the same thing.
//!
//! # Row normalisation (conditioning)
//!
//! With rows up to 480 px, `y⁴ ≈ 5·10¹⁰` sits next to `1` in `φR⁻¹φᵀ`. The filter therefore runs
//! internally in `u = (y − y_c)/s` ([`RowNorm`]; default `y_c = s = 120` px for 240-row frames),
//! on `θ_u = M θ_px`, and reports `θ_px = T θ_u` (`T = M⁻¹`, written out in [`RowNorm`]).
//! Covariances (`P0`, `Q`, the reported `P`) map as `P_px = T P_u Tᵀ`; information as
//! `Y_px = Mᵀ Y_u M`; `R` (px²) and `x` (px) do not change. [`ThetaCov`] says which
//! parameterisation a `P0` or `Q` is given in. In the normalised parameterisation all three
//! coefficients are in px of column, so `Q_u = q² I` means "each coefficient drifts by about `q`
//! px per frame" — the natural way to tune.
//!
//! # Errors
//!
//! Every failure is a [`KifError`]: NaN/∞/non-positive variance, NaN points (with their index),
//! `P0`/`Q`/`R` not symmetric positive definite (with the failing Cholesky pivot). An empty
//! point slice is a no-op update (it carries no information). On error the filter state is left
//! unchanged.
//!
//! # Example
//!
//! ```
//! use info_filter::{ParabolaKif, RowNorm, ThetaCov};
//! use nalgebra::{Matrix3, Vector3};
//!
//! # fn main() -> Result<(), info_filter::KifError> {
//! // A lane x = 0.001·y² − 0.5·y + 200 (pixels), seen for 10 frames, 40 points per frame.
//! let truth = Vector3::new(0.001, -0.5, 200.0);
//! let points: Vec<(f32, f32)> = (0..40)
//!     .map(|i| {
//!         let y = 60.0 + 4.5 * f64::from(i);
//!         ((truth[0] * y * y + truth[1] * y + truth[2]) as f32, y as f32)
//!     })
//!     .collect();
//!
//! let row_norm = RowNorm::default(); // u = (y − 120)/120
//! let p0 = ThetaCov::Normalised(Matrix3::identity() * 100.0); // ±10 px on each b_i
//! let mut kif = ParabolaKif::new(&Vector3::new(0.0, 0.0, 160.0), &p0, row_norm)?;
//! let q = kif.process_noise(&ThetaCov::Normalised(Matrix3::identity() * 0.25))?;
//! for _ in 0..10 {
//!     kif.predict(&q)?;
//!     kif.update(&points, 1.0)?; // σ² = 1 px²
//! }
//! let theta_px = kif.estimate();
//! assert!((theta_px - truth).norm() < 1e-3 * truth.norm());
//! assert!((kif.col_at_row_px(200.0) - (0.001 * 200.0 * 200.0 - 0.5 * 200.0 + 200.0)).abs() < 0.05);
//! # Ok(())
//! # }
//! ```

mod chol;
mod error;
mod generic;
mod parabola;
mod rownorm;

pub use chol::{Cholesky, symmetrise, validate_spd};
pub use error::KifError;
pub use generic::{InformationFilter, ProcessNoise, TimeUpdateForm};
pub use parabola::{ParabolaKif, PixelPoint, PowerSums};
pub use rownorm::{RowNorm, ThetaCov};
