//! Small allocation-free dense kernels on fixed-size nalgebra types: checks, adapters over the
//! workspace's one Cholesky factorisation (`spd-linalg`), and a cyclic Jacobi symmetric eigensolver.
//!
//! Why not `nalgebra::SymmetricEigen`: for a generic `const N: usize` it needs
//! `Const<N>: DimSub<U1>` plus an allocator bound on `DimDiff<Const<N>, U1>`, which would leak into
//! every public signature of this crate. Cyclic Jacobi is short, needs no bounds, is accurate to
//! high relative precision for symmetric matrices, and the tests check it against `SymmetricEigen`
//! at concrete sizes.

use nalgebra::{SMatrix, SVector};
use spd_linalg::Cholesky;

use crate::AkfError;

/// Relative tolerance for symmetry checks of input covariances: `|a_ij − a_ji| ≤ tol · max|a|`.
pub const SYMMETRY_REL_TOL: f64 = 1e-9;

/// Maximum number of cyclic Jacobi sweeps (convergence is quadratic; 6–10 is typical for N = 15).
const MAX_JACOBI_SWEEPS: usize = 60;

/// Returns the first non-finite entry (column-major scan) as an error.
pub(crate) fn check_finite<const R: usize, const C: usize>(
    what: &'static str,
    m: &SMatrix<f64, R, C>,
) -> Result<(), AkfError> {
    for col in 0..C {
        for row in 0..R {
            if !m[(row, col)].is_finite() {
                return Err(AkfError::NonFinite { what, row, col });
            }
        }
    }
    Ok(())
}

/// Largest absolute entry.
pub(crate) fn max_abs<const R: usize, const C: usize>(m: &SMatrix<f64, R, C>) -> f64 {
    m.iter().fold(0.0_f64, |acc, v| acc.max(v.abs()))
}

/// Checks `|a_ij − a_ji| ≤ SYMMETRY_REL_TOL · max|a|` and reports the worst pair.
pub(crate) fn check_symmetric<const N: usize>(
    what: &'static str,
    m: &SMatrix<f64, N, N>,
) -> Result<(), AkfError> {
    let tolerance = SYMMETRY_REL_TOL * max_abs(m);
    let mut worst = (0.0_f64, 0, 0);
    for col in 0..N {
        for row in (col + 1)..N {
            let d = (m[(row, col)] - m[(col, row)]).abs();
            if d > worst.0 {
                worst = (d, row, col);
            }
        }
    }
    if worst.0 > tolerance {
        return Err(AkfError::NotSymmetric {
            what,
            row: worst.1,
            col: worst.2,
            difference: worst.0,
            tolerance,
        });
    }
    Ok(())
}

/// `(A + Aᵀ)/2` in place; the result is exactly symmetric (the workspace's one, `spd-linalg`).
pub(crate) use spd_linalg::symmetrise as symmetrise_in_place;

impl From<spd_linalg::NotPositiveDefinite> for AkfError {
    fn from(e: spd_linalg::NotPositiveDefinite) -> Self {
        AkfError::NotPositiveDefinite {
            what: e.matrix,
            pivot: e.pivot,
            pivot_value: e.value,
        }
    }
}

/// Cholesky factor of `a` (lower triangle read) by the workspace's one factorisation
/// (`spd-linalg`); the error names `what` and the first pivot that is not finite and > 0.
pub(crate) fn cholesky_lower<const M: usize>(
    what: &'static str,
    a: &SMatrix<f64, M, M>,
) -> Result<Cholesky<M>, AkfError> {
    Ok(Cholesky::new(a, what)?)
}

/// Solves `(L Lᵀ) X = B` column by column.
pub(crate) fn cholesky_solve_matrix<const M: usize, const C: usize>(
    l: &Cholesky<M>,
    b: &SMatrix<f64, M, C>,
) -> SMatrix<f64, M, C> {
    l.solve_matrix(b)
}

/// `vᵀ (L Lᵀ)⁻¹ v = ‖L⁻¹ v‖²`.
pub(crate) fn mahalanobis_squared<const M: usize>(l: &Cholesky<M>, v: &SVector<f64, M>) -> f64 {
    l.mahalanobis_squared(v)
}

/// Eigen-decomposition of a symmetric matrix by cyclic Jacobi rotations.
///
/// Returns `(λ, V)` with `A = V diag(λ) Vᵀ`, `V` orthogonal; eigenvalues unsorted. Only the
/// symmetric part of `A` matters (the input is symmetrised first). Errors on non-finite input or
/// if the off-diagonal mass does not fall below `ε·‖A‖_F` within the sweep limit.
pub fn symmetric_eigen<const N: usize>(
    a: &SMatrix<f64, N, N>,
) -> Result<(SVector<f64, N>, SMatrix<f64, N, N>), AkfError> {
    check_finite("matrix to decompose", a)?;
    let mut a = *a;
    symmetrise_in_place(&mut a);
    let mut v = SMatrix::<f64, N, N>::identity();
    let scale = a.norm();
    if scale == 0.0 {
        return Ok((SVector::zeros(), v));
    }
    let threshold = f64::EPSILON * scale;
    let mut off = off_diagonal_norm(&a);
    for _sweep in 0..MAX_JACOBI_SWEEPS {
        if off <= threshold {
            return Ok((a.diagonal(), v));
        }
        for p in 0..N {
            for q in (p + 1)..N {
                let apq = a[(p, q)];
                if apq == 0.0 {
                    continue;
                }
                let tau = (a[(q, q)] - a[(p, p)]) / (2.0 * apq);
                let t = if tau.abs() > 1e150 {
                    0.5 / tau
                } else {
                    let sign = if tau >= 0.0 { 1.0 } else { -1.0 };
                    sign / (tau.abs() + (1.0 + tau * tau).sqrt())
                };
                let c = 1.0 / (1.0 + t * t).sqrt();
                let s = t * c;
                // A ← A J (columns p, q), then A ← Jᵀ A (rows p, q), V ← V J.
                for k in 0..N {
                    let akp = a[(k, p)];
                    let akq = a[(k, q)];
                    a[(k, p)] = c * akp - s * akq;
                    a[(k, q)] = s * akp + c * akq;
                }
                for k in 0..N {
                    let apk = a[(p, k)];
                    let aqk = a[(q, k)];
                    a[(p, k)] = c * apk - s * aqk;
                    a[(q, k)] = s * apk + c * aqk;
                }
                // The rotation annihilates (p, q) exactly in exact arithmetic; set it so.
                a[(p, q)] = 0.0;
                a[(q, p)] = 0.0;
                for k in 0..N {
                    let vkp = v[(k, p)];
                    let vkq = v[(k, q)];
                    v[(k, p)] = c * vkp - s * vkq;
                    v[(k, q)] = s * vkp + c * vkq;
                }
            }
        }
        off = off_diagonal_norm(&a);
    }
    if off <= threshold {
        return Ok((a.diagonal(), v));
    }
    Err(AkfError::NotConverged {
        algorithm: "Jacobi eigenvalue sweeps",
        iterations: MAX_JACOBI_SWEEPS,
        residual: off / scale,
    })
}

fn off_diagonal_norm<const N: usize>(a: &SMatrix<f64, N, N>) -> f64 {
    let mut s = 0.0;
    for col in 0..N {
        for row in 0..N {
            if row != col {
                s += a[(row, col)] * a[(row, col)];
            }
        }
    }
    s.sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix3, Matrix4, Vector4};

    #[test]
    fn cholesky_names_the_failing_pivot() {
        // Leading 2×2 block is PD; the 3×3 block is singular-indefinite: pivot 2 fails.
        let a = Matrix3::new(4.0, 2.0, 2.0, 2.0, 2.0, 1.0, 2.0, 1.0, 0.5);
        match cholesky_lower("r", &a) {
            Err(AkfError::NotPositiveDefinite { what, pivot, .. }) => {
                assert_eq!(what, "r");
                assert_eq!(pivot, 2);
            }
            other => panic!("expected pivot error, got {other:?}"),
        }
        let b = Matrix3::new(1.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0, 0.0, 1.0);
        assert!(matches!(
            cholesky_lower("r", &b),
            Err(AkfError::NotPositiveDefinite { pivot: 1, .. })
        ));
    }

    #[test]
    fn cholesky_solve_inverts_a_pd_matrix() {
        let a = Matrix4::new(
            5.0, 1.0, 0.5, 0.2, 1.0, 4.0, 0.3, 0.1, 0.5, 0.3, 3.0, 0.4, 0.2, 0.1, 0.4, 2.0,
        );
        let l = cholesky_lower("a", &a).unwrap();
        assert!((l.l() * l.l().transpose() - a).norm() < 1e-14 * a.norm());
        let b = Vector4::new(1.0, -2.0, 0.5, 3.0);
        let x = l.solve(&b);
        assert!((a * x - b).norm() < 1e-13);
        let m = cholesky_solve_matrix(&l, &Matrix4::identity());
        assert!((a * m - Matrix4::identity()).norm() < 1e-13);
        let q = mahalanobis_squared(&l, &b);
        let reference = b.dot(&(a.try_inverse().unwrap() * b));
        assert!((q - reference).abs() < 1e-13 * reference);
    }

    #[test]
    fn symmetry_check_reports_worst_pair() {
        let mut a = Matrix3::new(1.0, 0.2, 0.3, 0.2, 1.0, 0.4, 0.3, 0.4, 1.0);
        assert!(check_symmetric("q", &a).is_ok());
        a[(2, 0)] = 0.31;
        assert!(matches!(
            check_symmetric("q", &a),
            Err(AkfError::NotSymmetric { row: 2, col: 0, .. })
        ));
    }
}
