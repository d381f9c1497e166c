//! Checks of user matrices, and the workspace's one Cholesky factorisation (`spd-linalg`, which
//! names the failing pivot and never allocates) with its error mapped into [`KifError`].

use nalgebra::{SMatrix, SVector};

use crate::KifError;

pub use spd_linalg::{Cholesky, symmetrise};

impl From<spd_linalg::NotPositiveDefinite> for KifError {
    fn from(e: spd_linalg::NotPositiveDefinite) -> Self {
        KifError::NotPositiveDefinite {
            matrix: e.matrix,
            pivot: e.pivot,
            value: e.value,
        }
    }
}

/// Checks every entry is finite.
pub(crate) fn check_finite<const R: usize, const C: usize>(
    a: &SMatrix<f64, R, C>,
    matrix: &'static str,
) -> Result<(), KifError> {
    for c in 0..C {
        for r in 0..R {
            let value = a[(r, c)];
            if !value.is_finite() {
                return Err(KifError::NonFiniteMatrix {
                    matrix,
                    row: r,
                    col: c,
                    value,
                });
            }
        }
    }
    Ok(())
}

/// Checks every entry is finite.
pub(crate) fn check_finite_vec<const R: usize>(
    v: &SVector<f64, R>,
    vector: &'static str,
) -> Result<(), KifError> {
    for (index, &value) in v.iter().enumerate() {
        if !value.is_finite() {
            return Err(KifError::NonFiniteVector {
                vector,
                index,
                value,
            });
        }
    }
    Ok(())
}

/// Validates a user-supplied symmetric positive definite matrix: finite entries, symmetric to a
/// relative 1e-9 per entry pair, and a successful Cholesky factorisation. Returns the exactly
/// symmetrised matrix and its factor. `matrix` names it in the error.
///
/// # Errors
/// [`KifError::NonFiniteMatrix`], [`KifError::NotSymmetric`] or
/// [`KifError::NotPositiveDefinite`] (with the failing pivot).
pub fn validate_spd<const N: usize>(
    a: &SMatrix<f64, N, N>,
    matrix: &'static str,
) -> Result<(SMatrix<f64, N, N>, Cholesky<N>), KifError> {
    check_finite(a, matrix)?;
    for i in 0..N {
        for j in (i + 1)..N {
            let (upper, lower) = (a[(i, j)], a[(j, i)]);
            let tol = 1e-9 * upper.abs().max(lower.abs());
            if (upper - lower).abs() > tol {
                return Err(KifError::NotSymmetric {
                    matrix,
                    row: i,
                    col: j,
                    upper,
                    lower,
                });
            }
        }
    }
    let mut s = *a;
    symmetrise(&mut s);
    let chol = Cholesky::new(&s, matrix)?;
    Ok((s, chol))
}
