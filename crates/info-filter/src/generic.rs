//! Generic-dimension Kalman information filter for a random-walk parameter vector.
//!
//! State: information matrix `Y = P⁻¹` and information vector `ŷ = Y θ̂`.
//! See the crate documentation for the equations.

use nalgebra::{SMatrix, SVector};
use serde::{Deserialize, Serialize};

use crate::KifError;
use crate::chol::{Cholesky, check_finite, check_finite_vec, symmetrise, validate_spd};

/// Which algebraic form of the random-walk time update to use.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum TimeUpdateForm {
    /// Eq. (24), positive-definite ("Joseph-like") form:
    /// `Y ← (I − B) Y (I − B)ᵀ + B Q⁻¹ Bᵀ`, then exactly symmetrised. The default.
    #[default]
    PositiveDefinite,
    /// Eq. (7), plain form: `Y ← (I − B) Y`. Not symmetrised (kept literal, so tests can show
    /// what eq. 24 buys); only its lower triangle is read by later Cholesky factorisations.
    Plain,
}

/// A validated random-walk process-noise covariance `Q` (symmetric positive definite) with its
/// inverse precomputed, so that [`InformationFilter::predict`] does not refactorise `Q` each frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProcessNoise<const N: usize> {
    q: SMatrix<f64, N, N>,
    q_inv: SMatrix<f64, N, N>,
}

impl<const N: usize> ProcessNoise<N> {
    /// Validates `q` (finite, symmetric, positive definite) and inverts it.
    ///
    /// # Errors
    /// [`KifError::NonFiniteMatrix`], [`KifError::NotSymmetric`] or
    /// [`KifError::NotPositiveDefinite`] naming `"Q"`.
    pub fn new(q: &SMatrix<f64, N, N>) -> Result<Self, KifError> {
        let (q, chol) = validate_spd(q, "Q")?;
        let q_inv = chol.inverse();
        check_finite(&q_inv, "Q^-1")?;
        Ok(Self { q, q_inv })
    }

    /// `Q` (exactly symmetrised copy of the input).
    pub fn q(&self) -> &SMatrix<f64, N, N> {
        &self.q
    }

    /// `Q⁻¹`.
    pub fn q_inv(&self) -> &SMatrix<f64, N, N> {
        &self.q_inv
    }
}

/// Kalman information filter for `θ_{t+1} = θ_t + w_t`, `Cov(w) = Q`, with linear measurements
/// `x = φᵀ θ + v`, `Cov(v) = R`.
///
/// Invariant: `Y` is symmetric positive definite (checked by a Cholesky factorisation at every
/// measurement update) and `θ̂ = Y⁻¹ ŷ` is cached.
///
/// ```
/// use info_filter::{InformationFilter, ProcessNoise};
/// use nalgebra::{Matrix2, SMatrix, Vector2};
///
/// # fn main() -> Result<(), info_filter::KifError> {
/// // A 2-parameter random walk observed through three scalar measurements per step.
/// let mut f = InformationFilter::<2>::new(&Vector2::zeros(), &(Matrix2::identity() * 100.0))?;
/// let q = ProcessNoise::new(&(Matrix2::identity() * 1e-6))?;
/// let phi = SMatrix::<f64, 2, 3>::new(1.0, 1.0, 1.0, -1.0, 0.0, 1.0); // columns φ_j
/// let r = SMatrix::<f64, 3, 3>::identity() * 0.01;
/// let truth = Vector2::new(2.0, 0.5);
/// for _ in 0..20 {
///     f.predict(&q)?;
///     f.update(&phi, &r, &(phi.transpose() * truth))?;
/// }
/// assert!((f.estimate() - truth).norm() < 1e-4);
/// # Ok(())
/// # }
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct InformationFilter<const N: usize> {
    info: SMatrix<f64, N, N>,
    info_vec: SVector<f64, N>,
    theta: SVector<f64, N>,
    form: TimeUpdateForm,
}

impl<const N: usize> InformationFilter<N> {
    /// Starts from prior mean `theta0` and prior covariance `p0` (symmetric positive definite):
    /// `Y = P0⁻¹`, `ŷ = Y θ0`. The time update uses eq. (24) unless changed with
    /// [`Self::set_time_update_form`].
    ///
    /// # Errors
    /// `theta0` not finite, or `p0` not finite / symmetric / positive definite (named `"P0"`).
    pub fn new(theta0: &SVector<f64, N>, p0: &SMatrix<f64, N, N>) -> Result<Self, KifError> {
        check_finite_vec(theta0, "theta0")?;
        let (_, chol) = validate_spd(p0, "P0")?;
        let info = chol.inverse();
        check_finite(&info, "P0^-1")?;
        // Factorise Y itself so the invariant "Y is PD" is established in the filter's own state.
        Cholesky::new(&info, "Y")?;
        Ok(Self {
            info,
            info_vec: info * theta0,
            theta: *theta0,
            form: TimeUpdateForm::default(),
        })
    }

    /// Starts from an information pair `(Y, ŷ)` directly (`Y` symmetric positive definite).
    ///
    /// # Errors
    /// Non-finite entries, or `y` not symmetric / positive definite (named `"Y"`).
    pub fn from_information(
        y: &SMatrix<f64, N, N>,
        y_hat: &SVector<f64, N>,
    ) -> Result<Self, KifError> {
        check_finite_vec(y_hat, "y_hat")?;
        let (info, chol) = validate_spd(y, "Y")?;
        Ok(Self {
            info,
            info_vec: *y_hat,
            theta: chol.solve(y_hat),
            form: TimeUpdateForm::default(),
        })
    }

    /// Selects eq. (24) (default) or eq. (7) for subsequent time updates.
    pub fn set_time_update_form(&mut self, form: TimeUpdateForm) {
        self.form = form;
    }

    /// The time-update form in use.
    pub fn time_update_form(&self) -> TimeUpdateForm {
        self.form
    }

    /// Random-walk time update (eqs. 7, 8, 11, 24):
    /// `B = Y (Y + Q⁻¹)⁻¹`, `Y ← (I−B) Y (I−B)ᵀ + B Q⁻¹ Bᵀ` (or `(I−B) Y`), `ŷ ← (I−B) ŷ`.
    /// The estimate `θ̂` is unchanged by a random walk and stays cached.
    ///
    /// # Errors
    /// [`KifError::NotPositiveDefinite`] naming `"Y + Q^-1"` if round-off made it indefinite; the
    /// state is then left unchanged.
    #[inline]
    pub fn predict(&mut self, q: &ProcessNoise<N>) -> Result<(), KifError> {
        let q_inv = &q.q_inv;
        let s = self.info + q_inv;
        let chol = Cholesky::new(&s, "Y + Q^-1")?;
        // B = Y S⁻¹ with Y, S symmetric  ⇒  Bᵀ = S⁻¹ Y.
        let b = chol.solve_matrix(&self.info).transpose();
        let i_minus_b = SMatrix::<f64, N, N>::identity() - b;
        self.info = match self.form {
            TimeUpdateForm::PositiveDefinite => {
                let mut y =
                    i_minus_b * self.info * i_minus_b.transpose() + b * q_inv * b.transpose();
                symmetrise(&mut y);
                y
            }
            TimeUpdateForm::Plain => i_minus_b * self.info,
        };
        self.info_vec = i_minus_b * self.info_vec;
        Ok(())
    }

    /// Measurement update with a general linear measurement `x = φᵀ θ + v`, `Cov(v) = R`
    /// (eqs. 6, 12): `Y ← Y + φ R⁻¹ φᵀ`, `ŷ ← ŷ + φ R⁻¹ x`, `θ̂ = Y⁻¹ ŷ`.
    ///
    /// `phi` is `N×M` (one column per scalar measurement).
    ///
    /// # Errors
    /// Non-finite `phi`/`x`, `R` not symmetric positive definite, or the updated `Y` failing its
    /// Cholesky factorisation. On error the state is unchanged.
    pub fn update<const M: usize>(
        &mut self,
        phi: &SMatrix<f64, N, M>,
        r: &SMatrix<f64, M, M>,
        x: &SVector<f64, M>,
    ) -> Result<(), KifError> {
        check_finite(phi, "phi")?;
        check_finite_vec(x, "x")?;
        let (_, r_chol) = validate_spd(r, "R")?;
        // With R = L Lᵀ: φ R⁻¹ φᵀ = (L⁻¹ φᵀ)ᵀ (L⁻¹ φᵀ), φ R⁻¹ x = (L⁻¹ φᵀ)ᵀ (L⁻¹ x).
        let mut w = SMatrix::<f64, M, N>::zeros();
        for c in 0..N {
            let col = r_chol.solve_lower(&phi.row(c).transpose());
            w.set_column(c, &col);
        }
        let z = r_chol.solve_lower(x);
        let mut d_info = w.transpose() * w;
        symmetrise(&mut d_info);
        let d_info_vec = w.transpose() * z;
        self.update_information(&d_info, &d_info_vec)
    }

    /// Adds an information increment `(ΔY, Δŷ)` (e.g. `φR⁻¹φᵀ`, `φR⁻¹x` from power sums) and
    /// recomputes `θ̂ = Y⁻¹ ŷ` by Cholesky. The increment must be symmetric positive
    /// semi-definite; that is the caller's responsibility (a non-PSD increment is detected only if
    /// it makes `Y` indefinite).
    ///
    /// # Errors
    /// Non-finite increments, or [`KifError::NotPositiveDefinite`] naming `"Y"` (which pivot). On
    /// error the state is unchanged.
    #[inline]
    pub fn update_information(
        &mut self,
        d_info: &SMatrix<f64, N, N>,
        d_info_vec: &SVector<f64, N>,
    ) -> Result<(), KifError> {
        check_finite(d_info, "delta Y")?;
        check_finite_vec(d_info_vec, "delta y_hat")?;
        let info = self.info + d_info;
        let info_vec = self.info_vec + d_info_vec;
        let chol = Cholesky::new(&info, "Y")?;
        self.theta = chol.solve(&info_vec);
        self.info = info;
        self.info_vec = info_vec;
        Ok(())
    }

    /// Current estimate `θ̂` (`Y⁻¹ ŷ`, computed at the last measurement update or construction).
    #[inline]
    pub fn estimate(&self) -> SVector<f64, N> {
        self.theta
    }

    /// Information matrix `Y = P⁻¹`.
    #[inline]
    pub fn information(&self) -> SMatrix<f64, N, N> {
        self.info
    }

    /// Information vector `ŷ = Y θ̂`.
    #[inline]
    pub fn information_vector(&self) -> SVector<f64, N> {
        self.info_vec
    }

    /// Covariance `P = Y⁻¹` (by Cholesky).
    ///
    /// # Errors
    /// [`KifError::NotPositiveDefinite`] naming `"Y"` (possible only after eq. 7 time updates have
    /// let round-off destroy positive definiteness).
    pub fn covariance(&self) -> Result<SMatrix<f64, N, N>, KifError> {
        Ok(Cholesky::new(&self.info, "Y")?.inverse())
    }

    /// Restarts from a new prior, keeping the time-update form.
    ///
    /// # Errors
    /// As [`Self::new`]; on error the state is unchanged.
    pub fn reset(
        &mut self,
        theta0: &SVector<f64, N>,
        p0: &SMatrix<f64, N, N>,
    ) -> Result<(), KifError> {
        let form = self.form;
        *self = Self::new(theta0, p0)?;
        self.form = form;
        Ok(())
    }
}
