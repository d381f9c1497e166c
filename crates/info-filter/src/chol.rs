//! Fixed-size Cholesky factorisation `A = L Lᵀ` that reports which pivot failed.
//!
//! nalgebra's `Cholesky::new` only says "not positive definite"; the filters need the pivot for
//! their error messages, and a factorisation that never allocates. Only the lower triangle of `A`
//! is read.

use nalgebra::{SMatrix, SVector};

use crate::KifError;

/// Lower-triangular Cholesky factor `L` of a symmetric positive definite `N×N` matrix.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cholesky<const N: usize> {
    l: SMatrix<f64, N, N>,
}

impl<const N: usize> Cholesky<N> {
    /// Factorises `a` (lower triangle read). `matrix` names it in the error.
    ///
    /// # Errors
    /// [`KifError::NotPositiveDefinite`] with the first pivot that is not finite and `> 0`.
    #[inline]
    pub fn new(a: &SMatrix<f64, N, N>, matrix: &'static str) -> Result<Self, KifError> {
        let mut l = SMatrix::<f64, N, N>::zeros();
        for j in 0..N {
            let mut d = a[(j, j)];
            for k in 0..j {
                d -= l[(j, k)] * l[(j, k)];
            }
            // `!(d > 0)` also rejects NaN.
            if !(d.is_finite() && d > 0.0) {
                return Err(KifError::NotPositiveDefinite {
                    matrix,
                    pivot: j,
                    value: d,
                });
            }
            let ljj = d.sqrt();
            l[(j, j)] = ljj;
            let inv = 1.0 / ljj;
            for i in (j + 1)..N {
                let mut s = a[(i, j)];
                for k in 0..j {
                    s -= l[(i, k)] * l[(j, k)];
                }
                l[(i, j)] = s * inv;
            }
        }
        Ok(Self { l })
    }

    /// The factor `L` (lower triangular, positive diagonal).
    #[inline]
    pub fn l(&self) -> &SMatrix<f64, N, N> {
        &self.l
    }

    /// Solves `L z = b` (forward substitution).
    #[inline]
    pub fn solve_lower(&self, b: &SVector<f64, N>) -> SVector<f64, N> {
        let mut z = *b;
        for i in 0..N {
            let mut s = z[i];
            for k in 0..i {
                s -= self.l[(i, k)] * z[k];
            }
            z[i] = s / self.l[(i, i)];
        }
        z
    }

    /// Solves `A x = b`.
    #[inline]
    pub fn solve(&self, b: &SVector<f64, N>) -> SVector<f64, N> {
        let mut x = self.solve_lower(b);
        for i in (0..N).rev() {
            let mut s = x[i];
            for k in (i + 1)..N {
                s -= self.l[(k, i)] * x[k];
            }
            x[i] = s / self.l[(i, i)];
        }
        x
    }

    /// Solves `A X = B` column by column.
    #[inline]
    pub fn solve_matrix<const C: usize>(&self, b: &SMatrix<f64, N, C>) -> SMatrix<f64, N, C> {
        let mut x = SMatrix::<f64, N, C>::zeros();
        for c in 0..C {
            let col = self.solve(&b.column(c).into_owned());
            x.set_column(c, &col);
        }
        x
    }

    /// `A⁻¹`, exactly symmetric (the upper triangle is mirrored from the lower).
    #[inline]
    pub fn inverse(&self) -> SMatrix<f64, N, N> {
        let mut inv = self.solve_matrix(&SMatrix::<f64, N, N>::identity());
        symmetrise(&mut inv);
        inv
    }

    /// `log det A = 2 Σ log L_ii`.
    #[inline]
    pub fn log_det(&self) -> f64 {
        2.0 * (0..N).map(|i| self.l[(i, i)].ln()).sum::<f64>()
    }
}

/// Replaces `a` by `(a + aᵀ)/2`.
#[inline]
pub fn symmetrise<const N: usize>(a: &mut SMatrix<f64, N, N>) {
    for i in 0..N {
        for j in (i + 1)..N {
            let m = 0.5 * (a[(i, j)] + a[(j, i)]);
            a[(i, j)] = m;
            a[(j, i)] = m;
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
