//! The 15-state psi-angle error model, its discretisation and the covariance propagation.
//!
//! State x = (δp, δv, ψ, ∇, ε) (contract order, units m, m/s, rad, m/s², rad/s). Continuous
//! model ẋ = A x + G w, w = (w_a, w_g, w_∇, w_ε) (accelerometer noise, gyro noise, bias and drift
//! random-walk inputs; body axes), E[w wᵀ] = Q_c δ(t − s).
//!
//! # A(t) (built from the INS's own outputs: L̃, h̃, ṽ, f_n = C̃ f_b, C̃ = C̃_b^n)
//!
//! ```text
//! δṗ = −[ρ×] δp + δv
//! δv̇ = G_p δp − [(2Ω + ρ)×] δv + [f_n×] ψ + C̃ ∇          (−ψ×f = f×ψ)
//! ψ̇  = −[(Ω + ρ)×] ψ − C̃ ε
//! ∇̇ = w_∇,  ε̇ = w_ε
//!
//!       ⎡ −γ/(R_N+h)             0            0      ⎤
//! G_p = ⎢  0                −γ/(R_E+h)        0      ⎥   ≈ (g/R)·diag(−1, −1, +2)
//!       ⎣ (∂γ/∂L)/(R_N+h)        0        −∂γ/∂h     ⎦
//! ```
//!
//! Derivation (vector form in the computed local-level frame c, exact to first order in the
//! errors): δp is the vector r̃ − r, so ᶜd/dt δp = ᵉd/dt δp − ω_ec × δp = δv − ρ × δp; the velocity
//! error obeys ᵉd/dt δV = (Ã − A) + (g(r̃) − g(r)) − 2Ω × δV with Ã − A = −ψ×f + C̃∇; and
//! C̃ = (I − [ψ×]) C_b^c with both C̃ and C_b^c rotating at the same ω_ic = Ω + ρ gives
//! ψ̇ = −(Ω + ρ) × ψ − C̃ ε. The gravity error is g(r̃) expressed in c minus
//! C_t^c g(r): the horizontal part is −γ δθ-tilt (Schuler), the vertical part the gradient of
//! the normal gravity (∂γ/∂h ≈ −2γ/R: vertical instability). All of this is checked
//! numerically (tests in `tests/`): A's gravity block against finite differences of the
//! gravity model, and the whole linear propagation against the nonlinear INS.
//!
//! # Discretisation
//!
//! * Exact: [`van_loan`] — Φ = e^{A T}, Q_d = ∫₀ᵀ e^{As} G Q_c Gᵀ e^{Aᵀs} ds from the 30×30
//!   exponential of [[−A, GQ_cGᵀ], [0, Aᵀ]]·T ([`expm`]: nalgebra's scaling-and-squaring Padé
//!   exponential; the tests check it against an independent Taylor series and Rodrigues' formula).
//! * Fast (hot path, T = 0.01 s): [`Transition::series`] — third-order Taylor series exploiting the
//!   zero bias rows of A (Φ = [[Φ₁₁, Φ₁₂], [0, I]]); [`discretize_fast`] — Φ by that series and
//!   Q_d by Simpson's rule on [0, T] (nodes 0, T/2, T). Measured accuracy against Van Loan is in
//!   the crate doc and the tests.
//! * Covariance: [`propagate_covariance`] computes P ← Φ P Φᵀ + Q_d using the block structure.

use nalgebra::{Matrix3, SMatrix, SVector, UnitQuaternion, Vector3};

use crate::earth::{self, skew};
use crate::error::InsError;
use crate::strapdown::{LinearizationPoint, NavState};

/// 15×15 matrix.
pub type Mat15 = SMatrix<f64, 15, 15>;
/// 15×12 noise input matrix.
pub type Mat15x12 = SMatrix<f64, 15, 12>;
/// 12×12 continuous noise PSD matrix.
pub type Mat12 = SMatrix<f64, 12, 12>;

/// Index of δp (m, NED) in the state.
pub const IDX_POS: usize = 0;
/// Index of δv (m/s, NED).
pub const IDX_VEL: usize = 3;
/// Index of ψ (rad).
pub const IDX_PSI: usize = 6;
/// Index of the accelerometer bias ∇ (m/s², body).
pub const IDX_ACCEL_BIAS: usize = 9;
/// Index of the gyro drift ε (rad/s, body).
pub const IDX_GYRO_DRIFT: usize = 12;

/// Gravity-error block G_p = ∂δg/∂δp (s⁻²) at a computed position (see module doc).
pub fn gravity_gradient_block(lat_rad: f64, alt_m: f64) -> Matrix3<f64> {
    let (r_n, r_e) = earth::radii_of_curvature_m(lat_rad);
    let gamma = earth::normal_gravity_mps2(lat_rad, alt_m);
    let (dg_dlat, dg_dh) = earth::normal_gravity_partials(lat_rad, alt_m);
    Matrix3::new(
        -gamma / (r_n + alt_m),
        0.0,
        0.0,
        0.0,
        -gamma / (r_e + alt_m),
        0.0,
        dg_dlat / (r_n + alt_m),
        0.0,
        -dg_dh,
    )
}

/// The continuous system matrix A (15×15) at a linearisation point.
pub fn system_matrix(lp: &LinearizationPoint) -> Mat15 {
    let (lat, h) = (lp.pos.lat_rad, lp.pos.alt_m);
    let omega = earth::earth_rate_ned_radps(lat);
    let rho = earth::transport_rate_ned_radps(lat, h, &lp.vel_ned_mps);
    let mut a = Mat15::zeros();
    a.fixed_view_mut::<3, 3>(IDX_POS, IDX_POS)
        .copy_from(&(-skew(&rho)));
    a.fixed_view_mut::<3, 3>(IDX_POS, IDX_VEL)
        .copy_from(&Matrix3::identity());
    a.fixed_view_mut::<3, 3>(IDX_VEL, IDX_POS)
        .copy_from(&gravity_gradient_block(lat, h));
    a.fixed_view_mut::<3, 3>(IDX_VEL, IDX_VEL)
        .copy_from(&(-skew(&(2.0 * omega + rho))));
    a.fixed_view_mut::<3, 3>(IDX_VEL, IDX_PSI)
        .copy_from(&skew(&lp.specific_force_ned_mps2));
    a.fixed_view_mut::<3, 3>(IDX_VEL, IDX_ACCEL_BIAS)
        .copy_from(&lp.c_b_to_n);
    a.fixed_view_mut::<3, 3>(IDX_PSI, IDX_PSI)
        .copy_from(&(-skew(&(omega + rho))));
    a.fixed_view_mut::<3, 3>(IDX_PSI, IDX_GYRO_DRIFT)
        .copy_from(&(-lp.c_b_to_n));
    a
}

/// Noise input matrix G (15×12) for w = (w_a, w_g, w_∇, w_ε), body axes:
/// accelerometer noise → δv through C̃, gyro noise → ψ through −C̃, random walks → ∇, ε.
pub fn noise_input_matrix(c_b_to_n: &Matrix3<f64>) -> Mat15x12 {
    let mut g = Mat15x12::zeros();
    g.fixed_view_mut::<3, 3>(IDX_VEL, 0).copy_from(c_b_to_n);
    g.fixed_view_mut::<3, 3>(IDX_PSI, 3).copy_from(&(-c_b_to_n));
    g.fixed_view_mut::<3, 3>(IDX_ACCEL_BIAS, 6)
        .copy_from(&Matrix3::identity());
    g.fixed_view_mut::<3, 3>(IDX_GYRO_DRIFT, 9)
        .copy_from(&Matrix3::identity());
    g
}

/// Diagonal continuous noise PSD Q_c (12×12): accelerometer (m/s²)²/Hz, gyro rad²/s, bias and
/// drift random-walk PSDs ((m/s²)²/s, (rad/s)²/s; 0 for pure random constants).
pub fn continuous_noise_psd(
    accel_psd: f64,
    gyro_psd: f64,
    accel_bias_rw_psd: f64,
    gyro_drift_rw_psd: f64,
) -> Mat12 {
    let mut q = Mat12::zeros();
    for i in 0..3 {
        q[(i, i)] = accel_psd;
        q[(3 + i, 3 + i)] = gyro_psd;
        q[(6 + i, 6 + i)] = accel_bias_rw_psd;
        q[(9 + i, 9 + i)] = gyro_drift_rw_psd;
    }
    q
}

/// Matrix exponential e^M of a fixed-size square matrix (nalgebra's `exp`: scaling and squaring
/// with Padé approximants of degree chosen from ‖M‖₁, Higham 2005 / Al-Mohy & Higham 2009). Errors
/// for a non-finite entry.
pub fn expm<const N: usize>(m: &SMatrix<f64, N, N>) -> Result<SMatrix<f64, N, N>, InsError>
where
    nalgebra::Const<N>: nalgebra::DimMin<nalgebra::Const<N>, Output = nalgebra::Const<N>>,
{
    if !m.iter().all(|x| x.is_finite()) {
        return Err(InsError::InvalidArgument {
            func: "expm",
            arg: "m",
            requirement: "must be finite",
            value: "non-finite entry".to_string(),
        });
    }
    Ok(m.exp())
}

/// Exact discretisation by Van Loan's method: returns (Φ = e^{A T}, Q_d) for the continuous
/// model ẋ = A x + G w, E[w wᵀ] = Q_c δ, over `dt_s` (30×30 matrix exponential).
pub fn van_loan(
    a: &Mat15,
    g: &Mat15x12,
    qc: &Mat12,
    dt_s: f64,
) -> Result<(Mat15, Mat15), InsError> {
    if !(dt_s.is_finite() && dt_s > 0.0) {
        return Err(InsError::InvalidArgument {
            func: "van_loan",
            arg: "dt_s",
            requirement: "must be finite and > 0",
            value: format!("{dt_s:?}"),
        });
    }
    let w = g * qc * g.transpose();
    let mut f = SMatrix::<f64, 30, 30>::zeros();
    f.fixed_view_mut::<15, 15>(0, 0).copy_from(&(-a * dt_s));
    f.fixed_view_mut::<15, 15>(0, 15).copy_from(&(w * dt_s));
    f.fixed_view_mut::<15, 15>(15, 15)
        .copy_from(&(a.transpose() * dt_s));
    let e = expm(&f)?;
    let phi: Mat15 = e.fixed_view::<15, 15>(15, 15).transpose();
    let qd: Mat15 = phi * e.fixed_view::<15, 15>(0, 15);
    Ok((phi, 0.5 * (qd + qd.transpose())))
}

/// Block form of a transition matrix whose last 6 rows are [0 I] (bias states are random
/// constants/random walks): Φ = [[Φ₁₁ (9×9), Φ₁₂ (9×6)], [0, I₆]].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transition {
    /// Block (δp, δv, ψ) → (δp, δv, ψ).
    pub phi11: SMatrix<f64, 9, 9>,
    /// Block (∇, ε) → (δp, δv, ψ).
    pub phi12: SMatrix<f64, 9, 6>,
}

impl Transition {
    /// Third-order Taylor series Φ ≈ I + AT + (AT)²/2 + (AT)³/6 using the block structure
    /// (rows 9..15 of `a` are assumed zero, as produced by [`system_matrix`]):
    /// Φ₁₁ = I + M(I + M/2 (I + M/3)), Φ₁₂ = (I + M/2 (I + M/3)) M₁₂ with M = A₁₁T.
    /// At T = 0.01 s on the paper's flight it matches e^{AT} to ~1e-12 (tests).
    pub fn series(a: &Mat15, dt_s: f64) -> Self {
        let m11: SMatrix<f64, 9, 9> = a.fixed_view::<9, 9>(0, 0) * dt_s;
        let m12: SMatrix<f64, 9, 6> = a.fixed_view::<9, 6>(0, 9) * dt_s;
        let i9 = SMatrix::<f64, 9, 9>::identity();
        let s = i9 + m11 * (1.0 / 3.0);
        let t = i9 + (m11 * s) * 0.5;
        Self {
            phi11: i9 + m11 * t,
            phi12: t * m12,
        }
    }

    /// Extracts the blocks of a dense Φ (its last 6 rows are ignored).
    pub fn from_dense(phi: &Mat15) -> Self {
        Self {
            phi11: phi.fixed_view::<9, 9>(0, 0).into_owned(),
            phi12: phi.fixed_view::<9, 6>(0, 9).into_owned(),
        }
    }

    /// Dense 15×15 Φ.
    pub fn to_dense(&self) -> Mat15 {
        let mut p = Mat15::identity();
        p.fixed_view_mut::<9, 9>(0, 0).copy_from(&self.phi11);
        p.fixed_view_mut::<9, 6>(0, 9).copy_from(&self.phi12);
        p
    }
}

/// acc[0..L] += c[0..L]·s (fixed length so that the compiler unrolls and vectorises it).
#[inline(always)]
fn axpy<const L: usize>(acc: &mut [f64; 9], c: &[f64], s: f64) {
    for (a, &v) in acc[..L].iter_mut().zip(&c[..L]) {
        *a += v * s;
    }
}

/// P ← Φ P Φᵀ + Q_d in place, exploiting Φ's structure: the bias rows are [0 I], and the ψ
/// rows are coupled only to ψ and ε (exact for [`system_matrix`]: ψ̇ has no δp, δv or ∇
/// terms, so Φ's (ψ; δp, δv, ∇) entries are zero and are ignored here). With Φ_top = Φ[0..9, :]:
/// X = Φ_top P (9×15, ≈ 1600 multiply-adds), the 9×9 block X Φ_topᵀ (≈ 970), the 9×6 cross
/// block X[:, 9..15] (Φ's bias rows are [0 I]) and P₂₂ unchanged, instead of 6750 multiply-adds
/// for the dense form. The 9×9 block is symmetrised, so the result is exactly symmetric for
/// symmetric Q_d.
#[allow(clippy::needless_range_loop)] // index loops over fixed column ranges read clearest here
pub fn propagate_covariance(p: &mut Mat15, phi: &Transition, qd: &Mat15) {
    let f11 = phi.phi11.as_slice(); // column-major 9×9
    let f12 = phi.phi12.as_slice(); // column-major 9×6
    let col = |k: usize| -> &[f64] {
        if k < 9 {
            &f11[9 * k..9 * k + 9]
        } else {
            &f12[9 * (k - 9)..9 * (k - 9) + 9]
        }
    };
    // X = Φ_top P, column by column (column j of X = Σ_k Φ_top[:, k] P[k, j]); Φ_top's columns
    // for δp, δv, ∇ have zero ψ rows (length 6), those for ψ, ε are full (length 9).
    let mut x = [[0.0f64; 9]; 15];
    {
        let ps = p.as_slice();
        for j in 0..15 {
            let pj = &ps[15 * j..15 * j + 15];
            let acc = &mut x[j];
            for k in 0..6 {
                axpy::<6>(acc, col(k), pj[k]);
            }
            for k in 6..9 {
                axpy::<9>(acc, col(k), pj[k]);
            }
            for k in 9..12 {
                axpy::<6>(acc, col(k), pj[k]);
            }
            for k in 12..15 {
                axpy::<9>(acc, col(k), pj[k]);
            }
        }
    }
    // N = X Φ_topᵀ (9×9): column i of N = Σ_k X[:, k] Φ_top[i, k].
    let mut n = [[0.0f64; 9]; 9];
    for i in 0..9 {
        let acc = &mut n[i];
        if i < 6 {
            for k in 0..15 {
                axpy::<9>(acc, &x[k], col(k)[i]);
            }
        } else {
            for k in (6..9).chain(12..15) {
                axpy::<9>(acc, &x[k], col(k)[i]);
            }
        }
    }
    for i in 0..9 {
        for r in 0..=i {
            let v = 0.5 * (n[i][r] + n[r][i]);
            p[(r, i)] = v + qd[(r, i)];
            p[(i, r)] = v + qd[(i, r)];
        }
    }
    for j in 9..15 {
        for r in 0..9 {
            p[(r, j)] = x[j][r] + qd[(r, j)];
            p[(j, r)] = x[j][r] + qd[(j, r)];
        }
        for i in 9..15 {
            p[(i, j)] += qd[(i, j)];
        }
    }
}

/// Fast discretisation for short steps: Φ by [`Transition::series`], and
/// Q_d ≈ T/6 [W + 4 Φ(T/2) W Φ(T/2)ᵀ + Φ(T) W Φ(T)ᵀ] (Simpson), W = G Q_c Gᵀ.
pub fn discretize_fast(a: &Mat15, w: &Mat15, dt_s: f64) -> (Transition, Mat15) {
    let phi = Transition::series(a, dt_s);
    let phi_h = Transition::series(a, 0.5 * dt_s);
    let mut q_full = *w;
    propagate_covariance(&mut q_full, &phi, &Mat15::zeros());
    let mut q_half = *w;
    propagate_covariance(&mut q_half, &phi_h, &Mat15::zeros());
    let qd = (w + 4.0 * q_half + q_full) * (dt_s / 6.0);
    (phi, qd)
}

/// The (δp, δv, ψ) error of a computed state w.r.t. the truth in the contract's conventions:
/// δp = [`earth::pos_err_ned_m`], δv = ṽ − C_t^c v, ψ from C̃ = exp(−[ψ×]) C_t^c C_b^t, with C_t^c
/// the exact rotation between the true and computed local-level frames.
pub fn error_state(truth: &NavState, computed: &NavState) -> SVector<f64, 9> {
    let dp = earth::pos_err_ned_m(&computed.pos, &truth.pos);
    let c_tc = earth::ned_from_ecef(computed.pos.lat_rad, computed.pos.lon_rad)
        * earth::ned_from_ecef(truth.pos.lat_rad, truth.pos.lon_rad).transpose();
    let dv = computed.vel_ned_mps - c_tc * truth.vel_ned_mps;
    let q_tc = UnitQuaternion::from_matrix(&c_tc);
    let m = computed.att_b_to_n * (q_tc * truth.att_b_to_n).inverse();
    let psi = -m.scaled_axis();
    let mut x = SVector::<f64, 9>::zeros();
    x.fixed_rows_mut::<3>(0).copy_from(&dp);
    x.fixed_rows_mut::<3>(3).copy_from(&dv);
    x.fixed_rows_mut::<3>(6).copy_from(&psi);
    x
}

/// Inverse of [`error_state`]: the computed state whose errors w.r.t. `truth` are
/// (`pos_err_ned_m`, `vel_err_ned_mps`, `psi_rad`).
pub fn inject_errors(
    truth: &NavState,
    pos_err_ned_m: &Vector3<f64>,
    vel_err_ned_mps: &Vector3<f64>,
    psi_rad: &Vector3<f64>,
) -> NavState {
    let pos = earth::displace_by_ned_m(&truth.pos, pos_err_ned_m);
    let c_tc = earth::ned_from_ecef(pos.lat_rad, pos.lon_rad)
        * earth::ned_from_ecef(truth.pos.lat_rad, truth.pos.lon_rad).transpose();
    let q_tc = UnitQuaternion::from_matrix(&c_tc);
    NavState {
        pos,
        vel_ned_mps: c_tc * truth.vel_ned_mps + vel_err_ned_mps,
        att_b_to_n: UnitQuaternion::from_scaled_axis(-psi_rad) * q_tc * truth.att_b_to_n,
    }
}
