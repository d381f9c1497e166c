//! # spd-linalg — the one Cholesky factorisation of the workspace
//!
//! `A = L Lᵀ` for a symmetric positive definite `N×N` matrix on fixed-size nalgebra types, with
//! no allocation, reading only the lower triangle of `A`, and an error that says which matrix and
//! which pivot failed (nalgebra's own `Cholesky::new` only says "not positive definite"). The
//! lane filters (`info-filter`, `wrls`), the parabola fit of `hough-init` and the Kalman filters of
//! `akf` all factorise through it.
//!
//! ## The recurrence (column j = 0 … N−1)
//! ```text
//! d_j  = A_jj − Σ_{k<j} L_jk²          (the pivot: Schur complement of the leading j×j block)
//! L_jj = √d_j                          (fails unless d_j is finite and > floor_j)
//! L_ij = (A_ij − Σ_{k<j} L_ik L_jk) / L_jj,   i > j
//! ```
//! The floor is 0 for [`Cholesky::new`]; [`Cholesky::with_relative_floor`] raises it to
//! `ρ·A_jj`, a rank test for normal equations (a pivot that lost all but a fraction ρ of its
//! diagonal entry to elimination means a regressor is numerically a combination of the others).
//!
//! ## Example
//! ```
//! use nalgebra::{Matrix2, Vector2};
//! use spd_linalg::Cholesky;
//!
//! let a = Matrix2::new(4.0, 2.0, 2.0, 3.0);
//! let c = Cholesky::new(&a, "A")?;
//! let x = c.solve(&Vector2::new(2.0, 1.0));
//! assert!((a * x - Vector2::new(2.0, 1.0)).norm() < 1e-12);
//! let e = Cholesky::new(&Matrix2::new(1.0, 2.0, 2.0, 1.0), "B").unwrap_err();
//! assert_eq!((e.matrix, e.pivot), ("B", 1)); // 1 − 2² = −3 at the second pivot
//! # Ok::<(), spd_linalg::NotPositiveDefinite>(())
//! ```

use nalgebra::{SMatrix, SVector};

/// A factorisation failed: pivot `pivot` (0-based) of `matrix` is `value`, not above `floor`.
/// The leading `pivot × pivot` block is positive definite, the leading `(pivot+1)²` block is not.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[error(
    "{matrix} is not positive definite: Cholesky pivot {pivot} (0-based) is {value:e}, must be finite and > {floor:e}"
)]
pub struct NotPositiveDefinite {
    /// Which matrix (named by the caller).
    pub matrix: &'static str,
    /// Index of the failing pivot.
    pub pivot: usize,
    /// The Schur complement found there (NaN for non-finite input).
    pub value: f64,
    /// The floor it had to exceed (0, or `ρ·A_jj` with a relative floor).
    pub floor: f64,
}

/// Lower-triangular Cholesky factor `L` (positive diagonal) of a symmetric positive definite
/// `N×N` matrix.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cholesky<const N: usize> {
    l: SMatrix<f64, N, N>,
}

impl<const N: usize> Cholesky<N> {
    /// Factorises `a` (lower triangle read); `matrix` names it in the error.
    ///
    /// # Errors
    /// [`NotPositiveDefinite`] at the first pivot that is not finite and `> 0`.
    #[inline]
    pub fn new(a: &SMatrix<f64, N, N>, matrix: &'static str) -> Result<Self, NotPositiveDefinite> {
        Self::factor(a, matrix, 0.0)
    }

    /// As [`Cholesky::new`], but pivot `j` must exceed `relative_floor · A_jj` (a rank test).
    ///
    /// # Errors
    /// [`NotPositiveDefinite`] at the first pivot at or below its floor (or not finite).
    #[inline]
    pub fn with_relative_floor(
        a: &SMatrix<f64, N, N>,
        matrix: &'static str,
        relative_floor: f64,
    ) -> Result<Self, NotPositiveDefinite> {
        Self::factor(a, matrix, relative_floor)
    }

    #[inline]
    fn factor(
        a: &SMatrix<f64, N, N>,
        matrix: &'static str,
        relative_floor: f64,
    ) -> Result<Self, NotPositiveDefinite> {
        let mut l = SMatrix::<f64, N, N>::zeros();
        for j in 0..N {
            let mut d = a[(j, j)];
            for k in 0..j {
                d -= l[(j, k)] * l[(j, k)];
            }
            let floor = if relative_floor > 0.0 {
                relative_floor * a[(j, j)]
            } else {
                0.0
            };
            // `!(d > floor)` also rejects NaN.
            if !(d.is_finite() && d > floor) {
                return Err(NotPositiveDefinite {
                    matrix,
                    pivot: j,
                    value: d,
                    floor,
                });
            }
            let ljj = d.sqrt();
            l[(j, j)] = ljj;
            for i in (j + 1)..N {
                let mut s = a[(i, j)];
                for k in 0..j {
                    s -= l[(i, k)] * l[(j, k)];
                }
                l[(i, j)] = s / ljj;
            }
        }
        Ok(Self { l })
    }

    /// The factor `L` (lower triangular, positive diagonal, zeros above).
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

    /// Solves `Lᵀ x = z` (back substitution).
    #[inline]
    pub fn solve_lower_transpose(&self, z: &SVector<f64, N>) -> SVector<f64, N> {
        let mut x = *z;
        for i in (0..N).rev() {
            let mut s = x[i];
            for k in (i + 1)..N {
                s -= self.l[(k, i)] * x[k];
            }
            x[i] = s / self.l[(i, i)];
        }
        x
    }

    /// Solves `A x = b`.
    #[inline]
    pub fn solve(&self, b: &SVector<f64, N>) -> SVector<f64, N> {
        self.solve_lower_transpose(&self.solve_lower(b))
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

    /// `A⁻¹`, exactly symmetric (the upper triangle mirrors the lower).
    #[inline]
    pub fn inverse(&self) -> SMatrix<f64, N, N> {
        let mut inv = self.solve_matrix(&SMatrix::<f64, N, N>::identity());
        symmetrise(&mut inv);
        inv
    }

    /// `vᵀ A⁻¹ v = ‖L⁻¹ v‖²` (a Mahalanobis distance squared, e.g. NIS or NEES).
    #[inline]
    pub fn mahalanobis_squared(&self, v: &SVector<f64, N>) -> f64 {
        self.solve_lower(v).norm_squared()
    }

    /// `log det A = 2 Σ log L_jj`.
    #[inline]
    pub fn log_det(&self) -> f64 {
        2.0 * (0..N).map(|i| self.l[(i, i)].ln()).sum::<f64>()
    }
}

/// Replaces `a` by `(a + aᵀ)/2`: exactly symmetric afterwards (floating-point addition commutes).
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
