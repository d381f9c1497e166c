//! The paper's WRLS form (eqs. 25–27, corrected) with the `N×N` factorisation.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt;
use faer::{Mat, Par};
use info_filter::{Cholesky, KifError, PixelPoint, RowNorm, ThetaCov, symmetrise, validate_spd};
use nalgebra::{Matrix3, Vector3};

use crate::WrlsError;
use crate::config::validate_lambda;

/// Caller-invisible, preallocated faer buffers for up to `cap` points.
struct Workspace {
    cap: usize,
    /// `Φᵀ`, `cap×3`: row `i` is `φ_iᵀ = (u_i², u_i, 1)`.
    phi_t: Mat<f64>,
    /// `A = ΦᵀP` (`cap×3`), overwritten in place by `Kᵀ = S⁻¹ A`.
    a: Mat<f64>,
    /// `S = λI + ΦᵀPΦ` (`cap×cap`), overwritten in place by its Cholesky factor.
    s: Mat<f64>,
    /// Measured columns `x_i`, px.
    x: Vec<f64>,
    /// Scratch for the faer Cholesky.
    mem: MemBuffer,
}

impl Workspace {
    fn new(cap: usize) -> Self {
        let cap = cap.max(1);
        Self {
            cap,
            phi_t: Mat::zeros(cap, 3),
            a: Mat::zeros(cap, 3),
            s: Mat::zeros(cap, cap),
            x: vec![0.0; cap],
            mem: MemBuffer::new(llt::factor::cholesky_in_place_scratch::<f64>(
                cap,
                Par::Seq,
                Default::default(),
            )),
        }
    }
}

impl Clone for Workspace {
    fn clone(&self) -> Self {
        Self::new(self.cap)
    }
}

impl std::fmt::Debug for Workspace {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Workspace")
            .field("cap", &self.cap)
            .finish_non_exhaustive()
    }
}

/// Exponentially weighted RLS for the lane parabola in the paper's form (eqs. 25–27, with the
/// corrected eq. 27):
///
/// ```text
/// K = P φ (λ I_N + φᵀ P φ)⁻¹                                 (eq. 26, 3×N)
/// θ̂ ← θ̂ + K (x − φᵀ θ̂)                                       (eq. 25)
/// P ← λ⁻¹ (I − Kφᵀ) P (I − Kφᵀ)ᵀ + K Kᵀ                       (eq. 27, corrected)
/// ```
///
/// `(λ I_N + φᵀPφ)` is factorised by a faer Cholesky (`O(N³/3)`) rather than explicitly
/// inverted; it is this `N×N` step that the paper's 22.2 ms measures. All buffers are
/// preallocated for `max_points`; a frame with more points grows them once (that call
/// allocates), later frames up to the new size do not. The first update in the process also
/// allocates once inside faer (lazily initialised state); a test checks that later updates
/// allocate nothing. `clone()` allocates fresh buffers of the same capacity.
#[derive(Debug, Clone)]
pub struct WrlsPaper {
    theta: Vector3<f64>,
    p: Matrix3<f64>,
    lambda: f64,
    row_norm: RowNorm,
    ws: Workspace,
}

impl WrlsPaper {
    /// Starts from `theta0_px = (a1 [1/px], a2 [1], a3 [px])` with covariance `p0`, forgetting
    /// factor `lambda ∈ (0, 1]`, and buffers for `max_points` points per frame.
    ///
    /// # Errors
    /// As [`WrlsFast::new`](crate::WrlsFast::new).
    pub fn new(
        theta0_px: &Vector3<f64>,
        p0: &ThetaCov,
        lambda: f64,
        row_norm: RowNorm,
        max_points: usize,
    ) -> Result<Self, WrlsError> {
        validate_lambda(lambda)?;
        row_norm.validate()?;
        let (theta, p0_u) = crate::prior_normalised(theta0_px, p0, &row_norm)?;
        let (p, _) = validate_spd(&p0_u, "P0")?;
        Ok(Self {
            theta,
            p,
            lambda,
            row_norm,
            ws: Workspace::new(max_points),
        })
    }

    /// One frame of eqs. (25)–(27) with this frame's `N` points. `N = 0` gives `K` empty:
    /// `θ̂` unchanged, `P ← P/λ`.
    ///
    /// # Errors
    /// Non-finite point (index), `λI + φᵀPφ` failing Cholesky (pivot), or the new `P` failing
    /// its positive-definiteness check. On error the state is unchanged.
    pub fn update<P: PixelPoint>(&mut self, points: &[P]) -> Result<(), WrlsError> {
        let n = points.len();
        if n > self.ws.cap {
            self.ws = Workspace::new(n);
        }
        let lambda = self.lambda;
        let (c, inv_s) = (self.row_norm.center_row_px, 1.0 / self.row_norm.scale_px);
        let ws = &mut self.ws;
        for (i, pt) in points.iter().enumerate() {
            let (col_px, row_px) = (pt.col_px(), pt.row_px());
            if !col_px.is_finite() || !row_px.is_finite() {
                return Err(KifError::NonFinitePoint {
                    index: i,
                    col_px,
                    row_px,
                }
                .into());
            }
            let u = (row_px - c) * inv_s;
            ws.phi_t[(i, 0)] = u * u;
            ws.phi_t[(i, 1)] = u;
            ws.phi_t[(i, 2)] = 1.0;
            ws.x[i] = col_px;
        }
        // A = Φᵀ P (N×3).
        let p = self.p;
        for i in 0..n {
            for j in 0..3 {
                ws.a[(i, j)] = ws.phi_t[(i, 0)] * p[(0, j)]
                    + ws.phi_t[(i, 1)] * p[(1, j)]
                    + ws.phi_t[(i, 2)] * p[(2, j)];
            }
        }
        // S = λ I_N + Φᵀ P Φ, lower triangle only (all the Cholesky reads).
        for j in 0..n {
            for i in j..n {
                ws.s[(i, j)] = ws.a[(i, 0)] * ws.phi_t[(j, 0)]
                    + ws.a[(i, 1)] * ws.phi_t[(j, 1)]
                    + ws.a[(i, 2)] * ws.phi_t[(j, 2)];
            }
            ws.s[(j, j)] += lambda;
        }
        let mut k_phi_t = Matrix3::zeros();
        let mut k_k_t = Matrix3::zeros();
        let mut theta = self.theta;
        if n > 0 {
            let stack = MemStack::new(&mut ws.mem);
            let mut s = ws.s.as_mut().submatrix_mut(0, 0, n, n);
            llt::factor::cholesky_in_place(
                s.as_mut(),
                Default::default(),
                Par::Seq,
                stack,
                Default::default(),
            )
            .map_err(|e| match e {
                llt::factor::LltError::NonPositivePivot { index } => {
                    WrlsError::InnovationNotPositiveDefinite { n, pivot: index }
                }
            })?;
            // Kᵀ = S⁻¹ A (S symmetric), in place over A.
            llt::solve::solve_in_place(
                s.as_ref(),
                ws.a.as_mut().submatrix_mut(0, 0, n, 3),
                Par::Seq,
                stack,
            );
            // Innovations use the prior θ̂ (eq. 25), so accumulate the correction separately.
            let mut correction = Vector3::zeros();
            for i in 0..n {
                let k_i = Vector3::new(ws.a[(i, 0)], ws.a[(i, 1)], ws.a[(i, 2)]);
                let phi_i = Vector3::new(ws.phi_t[(i, 0)], ws.phi_t[(i, 1)], ws.phi_t[(i, 2)]);
                let innovation = ws.x[i] - phi_i.dot(&self.theta);
                correction += k_i * innovation;
                k_phi_t += k_i * phi_i.transpose();
                k_k_t += k_i * k_i.transpose();
            }
            theta += correction;
        }
        let i_kf = Matrix3::identity() - k_phi_t;
        let mut p_new = i_kf * p * i_kf.transpose() / lambda + k_k_t;
        symmetrise(&mut p_new);
        Cholesky::new(&p_new, "P").map_err(KifError::from)?;
        self.p = p_new;
        self.theta = theta;
        Ok(())
    }

    /// Estimate `θ̂_px = (a1 [1/px], a2 [1], a3 [px])`.
    pub fn estimate(&self) -> Vector3<f64> {
        self.row_norm.theta_to_px(&self.theta)
    }

    /// Estimate in the normalised parameterisation (px).
    pub fn estimate_normalised(&self) -> Vector3<f64> {
        self.theta
    }

    /// `P_u` (normalised parameterisation).
    pub fn covariance_normalised(&self) -> Matrix3<f64> {
        self.p
    }

    /// `P_px = T P_u Tᵀ`.
    pub fn covariance(&self) -> Matrix3<f64> {
        self.row_norm.cov_to_px(&self.p)
    }

    /// The forgetting factor λ.
    pub fn lambda(&self) -> f64 {
        self.lambda
    }

    /// The row normalisation in use.
    pub fn row_norm(&self) -> &RowNorm {
        &self.row_norm
    }

    /// Points per frame the buffers currently hold without reallocating.
    pub fn capacity(&self) -> usize {
        self.ws.cap
    }

    /// Restarts from a new prior, keeping λ, the row normalisation and the buffers.
    ///
    /// # Errors
    /// As [`Self::new`]; on error the state is unchanged.
    pub fn reset(&mut self, theta0_px: &Vector3<f64>, p0: &ThetaCov) -> Result<(), WrlsError> {
        let (theta, p0_u) = crate::prior_normalised(theta0_px, p0, &self.row_norm)?;
        let (p, _) = validate_spd(&p0_u, "P0")?;
        self.theta = theta;
        self.p = p;
        Ok(())
    }
}
