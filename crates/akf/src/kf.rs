//! The discrete Kalman filter: predict, Joseph-form update, accessors, error-state reset.

use nalgebra::{SMatrix, SVector};

use crate::AkfError;
use crate::linalg::{
    check_finite, check_symmetric, cholesky_lower, cholesky_solve_matrix, mahalanobis_squared,
    max_abs, symmetric_eigen, symmetrise_in_place,
};

/// Relative tolerance for the PSD check of a covariance handed to [`KalmanFilter::new`] /
/// [`KalmanFilter::set_covariance`]: the smallest eigenvalue must be ≥ `−tol · max|P|`.
pub const PSD_REL_TOL: f64 = 1e-12;

/// What one measurement update produced.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Innovation<const M: usize> {
    /// ν = z − H x̂⁻ (measurement units).
    pub innovation: SVector<f64, M>,
    /// S = H P⁻ Hᵀ + R (measurement units²), exactly symmetric.
    pub innovation_covariance: SMatrix<f64, M, M>,
    /// Normalised innovation squared, νᵀ S⁻¹ ν (dimensionless; χ²(M) for a consistent filter).
    pub nis: f64,
}

/// Discrete linear Kalman filter with state dimension `N`, on stack-allocated nalgebra types.
///
/// * predict: x̂⁻ = Φ x̂⁺, P⁻ = Φ P⁺ Φᵀ + Q_d
/// * update: ν = z − H x̂⁻, S = H P⁻ Hᵀ + R, K = P⁻ Hᵀ S⁻¹ (via Cholesky of S),
///   x̂⁺ = x̂⁻ + K ν, P⁺ = (I − K H) P⁻ (I − K H)ᵀ + K R Kᵀ (Joseph form), symmetrised.
///
/// Units are whatever the caller's state uses; every method is allocation-free. A method that
/// returns an error leaves the filter unchanged.
#[derive(Debug, Clone, PartialEq)]
pub struct KalmanFilter<const N: usize> {
    x: SVector<f64, N>,
    p: SMatrix<f64, N, N>,
}

/// Validates a covariance: finite, symmetric (within round-off), PSD (smallest Jacobi eigenvalue
/// ≥ −PSD_REL_TOL·max|P|). Singular P (e.g. a perfectly known initial position) is allowed.
fn validate_covariance<const N: usize>(
    what: &'static str,
    p: &SMatrix<f64, N, N>,
) -> Result<(), AkfError> {
    check_finite(what, p)?;
    check_symmetric(what, p)?;
    let (eigenvalues, _) = symmetric_eigen(p)?;
    let min = eigenvalues.min();
    if min < -PSD_REL_TOL * max_abs(p) {
        return Err(AkfError::NotPositiveSemiDefinite {
            what,
            detail: "smallest eigenvalue",
            value: min,
        });
    }
    Ok(())
}

impl<const N: usize> KalmanFilter<N> {
    /// A filter with initial estimate `x0` and covariance `p0` (finite, symmetric, PSD).
    pub fn new(x0: SVector<f64, N>, p0: SMatrix<f64, N, N>) -> Result<Self, AkfError> {
        check_finite("x0", &x0)?;
        validate_covariance("p0", &p0)?;
        let mut p = p0;
        symmetrise_in_place(&mut p);
        Ok(Self { x: x0, p })
    }

    /// Current state estimate x̂ (after the last predict or update).
    pub fn state(&self) -> &SVector<f64, N> {
        &self.x
    }

    /// Current covariance P (exactly symmetric).
    pub fn covariance(&self) -> &SMatrix<f64, N, N> {
        &self.p
    }

    /// Overwrites the state estimate (e.g. after an external correction).
    pub fn set_state(&mut self, x: SVector<f64, N>) -> Result<(), AkfError> {
        check_finite("x", &x)?;
        self.x = x;
        Ok(())
    }

    /// Overwrites the covariance (finite, symmetric, PSD).
    pub fn set_covariance(&mut self, p: SMatrix<f64, N, N>) -> Result<(), AkfError> {
        validate_covariance("p", &p)?;
        self.p = p;
        symmetrise_in_place(&mut self.p);
        Ok(())
    }

    /// Error-state feedback reset: x̂ ← 0, P unchanged.
    ///
    /// Use after the caller has applied the estimated errors to its nominal (e.g. INS) solution;
    /// to first order the reset leaves P unchanged.
    pub fn reset_error_state(&mut self) {
        self.x.fill(0.0);
    }

    /// Time update with transition `phi` (Φ) and discrete process noise `q_d` (Q_d, state units²).
    ///
    /// Checks: Φ and Q_d finite, Q_d symmetric within round-off, diag(Q_d) ≥ 0. (A full PSD check
    /// of Q_d would cost an eigen-decomposition per step; the caller owns Q_d's PSD-ness.)
    pub fn predict(
        &mut self,
        phi: &SMatrix<f64, N, N>,
        q_d: &SMatrix<f64, N, N>,
    ) -> Result<(), AkfError> {
        check_finite("phi", phi)?;
        check_finite("q_d", q_d)?;
        check_symmetric("q_d", q_d)?;
        for i in 0..N {
            if q_d[(i, i)] < 0.0 {
                return Err(AkfError::NotPositiveSemiDefinite {
                    what: "q_d",
                    detail: "a diagonal entry",
                    value: q_d[(i, i)],
                });
            }
        }
        let x = phi * self.x;
        let mut p = phi * self.p * phi.transpose() + q_d;
        symmetrise_in_place(&mut p);
        check_finite("predicted covariance", &p)?;
        self.x = x;
        self.p = p;
        Ok(())
    }

    /// Measurement update with `z` (M measurements), `h` (H, M×N) and `r` (R, M×M, PD), Joseph form.
    ///
    /// Errors: non-finite `z`/`h`/`r`; `r` not symmetric; `r` or S not PD (the failing Cholesky
    /// pivot is named). On error the filter is unchanged.
    pub fn update<const M: usize>(
        &mut self,
        z: &SVector<f64, M>,
        h: &SMatrix<f64, M, N>,
        r: &SMatrix<f64, M, M>,
    ) -> Result<Innovation<M>, AkfError> {
        check_finite("z", z)?;
        check_finite("h", h)?;
        check_finite("r", r)?;
        check_symmetric("r", r)?;
        cholesky_lower("r", r)?;

        let innovation = z - h * self.x;
        let hp: SMatrix<f64, M, N> = h * self.p; // = (P Hᵀ)ᵀ since P is symmetric
        let mut s = hp * h.transpose() + r;
        symmetrise_in_place(&mut s);
        let l = cholesky_lower("innovation covariance S", &s)?;
        // S Kᵀ = H P  ⇒  Kᵀ = S⁻¹ H P.
        let k_t = cholesky_solve_matrix(&l, &hp);
        let k: SMatrix<f64, N, M> = k_t.transpose();

        let x = self.x + k * innovation;
        let i_kh = SMatrix::<f64, N, N>::identity() - k * h;
        let mut p = i_kh * self.p * i_kh.transpose() + k * r * k_t;
        symmetrise_in_place(&mut p);
        check_finite("updated covariance", &p)?;
        check_finite("updated state", &x)?;
        let nis = mahalanobis_squared(&l, &innovation);

        self.x = x;
        self.p = p;
        Ok(Innovation {
            innovation,
            innovation_covariance: s,
            nis,
        })
    }
}
