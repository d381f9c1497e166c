//! Structured projection of an estimated process noise onto the model's noise inputs, by
//! non-negative least squares.
//!
//! The filter's process noise over an interval is linear in the continuous noise densities of
//! its K noise inputs: Q(q) = Σ_k q_k B_k, B_k the interval noise matrix of input k at unit
//! density (for white noise entering through the columns g_k of G, B_k = ∫ Φ g_k g_kᵀ Φᵀ dt).
//! A raw estimate Q̂ (indefinite in general) is projected onto this cone:
//!
//! ```text
//! q̂ = argmin_{q ≥ 0} ‖ D^{−1/2} (Q̂ − Σ_k q_k B_k) D^{−1/2} ‖_F ,      Q̂_s = Σ_k q̂_k B_k
//! ```
//!
//! with D = diag(scale) a positive per-state scale (e.g. diag P) that makes the mixed-unit
//! residual dimensionless. Q̂_s is PSD by construction, keeps the model's correlations, and q̂
//! are physical noise densities. The normal equations have the K×K Gram matrix
//! G_ij = ⟨B̃_i, B̃_j⟩_F and right-hand side r_i = ⟨B̃_i, Q̃⟩_F (B̃ = D^{−1/2} B D^{−1/2}); the
//! NNLS problem min ½ qᵀ G q − rᵀ q, q ≥ 0 is solved by the Lawson–Hanson active-set method
//! ([`nnls_gram`]), checked against enumeration of all 2^K active sets on small cases.

use nalgebra::{SMatrix, SVector};

use crate::AkfError;
use crate::linalg::check_finite;

/// Result of [`project_structured`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StructuredFit<const N: usize, const K: usize> {
    /// Σ q̂_k B_k (PSD, symmetric).
    pub matrix: SMatrix<f64, N, N>,
    /// The fitted non-negative densities q̂.
    pub densities: SVector<f64, K>,
}

/// Solves min ½ qᵀ G q − rᵀ q subject to q ≥ 0 for a symmetric positive semi-definite Gram
/// matrix G (Lawson & Hanson 1974, ch. 23, on the normal equations). Inputs with a singular
/// passive set fall back to dropping the dependent variable. Allocation-free.
pub fn nnls_gram<const K: usize>(g: &SMatrix<f64, K, K>, r: &SVector<f64, K>) -> SVector<f64, K> {
    // Work in variables scaled to a unit-diagonal Gram matrix (the basis matrices can differ by
    // many orders of magnitude); a variable with G_kk = 0 has no effect and stays 0.
    let mut s = SVector::<f64, K>::zeros();
    for k in 0..K {
        let d = g[(k, k)];
        s[k] = if d.is_finite() && d > 0.0 {
            d.sqrt()
        } else {
            0.0
        };
    }
    let gs = SMatrix::<f64, K, K>::from_fn(|i, j| {
        if s[i] > 0.0 && s[j] > 0.0 {
            g[(i, j)] / (s[i] * s[j])
        } else {
            0.0
        }
    });
    let rs = SVector::<f64, K>::from_fn(|i, _| if s[i] > 0.0 { r[i] / s[i] } else { 0.0 });
    let q = nnls_unit(&gs, &rs, &s);
    SVector::<f64, K>::from_fn(|i, _| if s[i] > 0.0 { q[i] / s[i] } else { 0.0 })
}

/// Lawson–Hanson on a unit-diagonal Gram matrix; variables with `s == 0` never enter.
fn nnls_unit<const K: usize>(
    g: &SMatrix<f64, K, K>,
    r: &SVector<f64, K>,
    s: &SVector<f64, K>,
) -> SVector<f64, K> {
    let mut passive = [false; K];
    let mut q = SVector::<f64, K>::zeros();
    let tol = 1e-12 * r.amax();
    for _outer in 0..(3 * K + 3) {
        // Negative gradient of the objective: w = r − G q.
        let w = r - g * q;
        let mut best = None;
        for i in 0..K {
            if !passive[i] && s[i] > 0.0 && w[i] > tol && best.is_none_or(|(_, v)| w[i] > v) {
                best = Some((i, w[i]));
            }
        }
        let Some((j, _)) = best else { break };
        passive[j] = true;
        for _inner in 0..(3 * K + 3) {
            let z = solve_passive(g, r, &passive);
            if (0..K).all(|i| !passive[i] || z[i] > 0.0) {
                q = z;
                break;
            }
            // Step from q towards z until a passive variable hits zero.
            let mut alpha = 1.0_f64;
            for i in 0..K {
                if passive[i] && z[i] <= 0.0 {
                    let a = q[i] / (q[i] - z[i]);
                    if a < alpha {
                        alpha = a;
                    }
                }
            }
            q += (z - q) * alpha;
            for i in 0..K {
                if passive[i] && q[i] <= 1e-15 * (1.0 + q.amax()) {
                    passive[i] = false;
                    q[i] = 0.0;
                }
            }
        }
    }
    q
}

/// Unconstrained minimiser over the passive set (others 0): G_PP z_P = r_P, by Gaussian
/// elimination with partial pivoting; a (numerically) singular pivot fixes its variable at 0.
fn solve_passive<const K: usize>(
    g: &SMatrix<f64, K, K>,
    r: &SVector<f64, K>,
    passive: &[bool; K],
) -> SVector<f64, K> {
    let mut a = SMatrix::<f64, K, K>::zeros();
    let mut b = SVector::<f64, K>::zeros();
    for i in 0..K {
        if passive[i] {
            for j in 0..K {
                if passive[j] {
                    a[(i, j)] = g[(i, j)];
                }
            }
            b[i] = r[i];
        } else {
            a[(i, i)] = 1.0;
        }
    }
    let scale = a.amax().max(f64::MIN_POSITIVE);
    let mut x = SVector::<f64, K>::zeros();
    let mut free = [true; K];
    // Forward elimination.
    let mut order = [0usize; K];
    for (i, o) in order.iter_mut().enumerate() {
        *o = i;
    }
    for col in 0..K {
        let mut piv = col;
        for row in col + 1..K {
            if a[(order[row], col)].abs() > a[(order[piv], col)].abs() {
                piv = row;
            }
        }
        order.swap(col, piv);
        let p = a[(order[col], col)];
        if p.abs() <= 1e-13 * scale {
            free[col] = false;
            continue;
        }
        for row in col + 1..K {
            let f = a[(order[row], col)] / p;
            if f != 0.0 {
                for c in col..K {
                    a[(order[row], c)] -= f * a[(order[col], c)];
                }
                b[order[row]] -= f * b[order[col]];
            }
        }
    }
    for col in (0..K).rev() {
        if !free[col] {
            continue;
        }
        let mut s = b[order[col]];
        for c in col + 1..K {
            s -= a[(order[col], c)] * x[c];
        }
        x[col] = s / a[(order[col], col)];
    }
    for i in 0..K {
        if !passive[i] {
            x[i] = 0.0;
        }
    }
    x
}

/// Projects `q_raw` onto {Σ q_k B_k : q ≥ 0} in the scaled Frobenius norm (module doc).
///
/// # Errors
/// [`AkfError::NonFinite`] for non-finite input; [`AkfError::InvalidParameter`] (`scale`) for a
/// non-positive scale.
pub fn project_structured<const N: usize, const K: usize>(
    q_raw: &SMatrix<f64, N, N>,
    basis: &[SMatrix<f64, N, N>; K],
    scale: &SVector<f64, N>,
) -> Result<StructuredFit<N, K>, AkfError> {
    check_finite("q", q_raw)?;
    for b in basis {
        check_finite("basis", b)?;
    }
    let mut inv_sqrt = SVector::<f64, N>::zeros();
    for i in 0..N {
        if !(scale[i].is_finite() && scale[i] > 0.0) {
            return Err(AkfError::InvalidParameter {
                field: "scale",
                reason: format!("entry {i} is {}; must be finite and > 0", scale[i]),
            });
        }
        inv_sqrt[i] = 1.0 / scale[i].sqrt();
    }
    let w = |m: &SMatrix<f64, N, N>, i: usize, j: usize| m[(i, j)] * inv_sqrt[i] * inv_sqrt[j];
    let mut g = SMatrix::<f64, K, K>::zeros();
    let mut r = SVector::<f64, K>::zeros();
    for i in 0..N {
        for j in 0..N {
            let y = w(q_raw, i, j);
            for a in 0..K {
                let ba = w(&basis[a], i, j);
                r[a] += ba * y;
                for b in a..K {
                    g[(a, b)] += ba * w(&basis[b], i, j);
                }
            }
        }
    }
    for a in 0..K {
        for b in 0..a {
            g[(a, b)] = g[(b, a)];
        }
    }
    let q = nnls_gram(&g, &r);
    let mut matrix = SMatrix::<f64, N, N>::zeros();
    for k in 0..K {
        matrix += basis[k] * q[k];
    }
    let m2 = matrix.transpose();
    matrix = (matrix + m2) * 0.5;
    Ok(StructuredFit {
        matrix,
        densities: q,
    })
}
