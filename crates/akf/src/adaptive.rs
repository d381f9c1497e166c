//! Adaptive process-noise estimation (Mohamed & Schwarz 1999) and PSD projection of the estimate.

use nalgebra::{SMatrix, SVector};
use serde::{Deserialize, Serialize};

use crate::AkfError;
use crate::kf::{Innovation, KalmanFilter};
use crate::linalg::{check_finite, symmetric_eigen, symmetrise_in_place};

/// Default ring-buffer capacity (largest admissible window) of [`AdaptiveQ`].
pub const DEFAULT_WINDOW_CAPACITY: usize = 64;

/// How the symmetrised, generally indefinite Q̂ is made positive semi-definite.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum QProjection {
    /// Eigenvalue clipping: Q̂ = V diag(λ) Vᵀ → V diag(max(λᵢ, floor)) Vᵀ, the nearest matrix in
    /// Frobenius norm whose eigenvalues are ≥ floor. Keeps the correlations of Q̂. Not invariant
    /// under rescaling of individual states (eigenvalues mix units), so with mixed-unit states
    /// choose the floor in the smallest unit or use [`QProjection::Diagonal`].
    #[default]
    EigenClip,
    /// Keep only diag(Q̂), each entry raised to its own floor (see
    /// [`AdaptiveQ::set_diagonal_floors`]); off-diagonals set to 0. Unit-safe, drops correlations.
    Diagonal,
    /// Q̂ = Σ q̂_k B_k, q̂ ≥ 0: the non-negative least-squares fit of the raw estimate onto the
    /// noise matrices B_k of the model's noise inputs ([`crate::project_structured`]). It needs the
    /// caller's basis, so the estimators of this crate store the [`QProjection::Diagonal`]
    /// projection as their estimate and the caller fits the raw estimate itself.
    Structured,
}

/// Configuration of the adaptive Q̂ estimator.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AdaptiveQConfig {
    /// Window N_w: number of most recent updates whose Δx Δxᵀ are averaged (≥ 1, ≤ the
    /// estimator's capacity). Paper: 10. No estimate exists until N_w updates have been seen.
    pub window: usize,
    /// Projection applied to the symmetrised estimate.
    pub projection: QProjection,
    /// Floor (state units² per update interval, ≥ 0) on the eigenvalues ([`QProjection::EigenClip`])
    /// or on every diagonal entry ([`QProjection::Diagonal`], unless per-state floors are set).
    /// 0 gives the nearest PSD matrix.
    pub min_variance: f64,
}

impl Default for AdaptiveQConfig {
    fn default() -> Self {
        Self {
            window: 10,
            projection: QProjection::EigenClip,
            min_variance: 0.0,
        }
    }
}

impl AdaptiveQConfig {
    /// Checks every field; the error names the field. `capacity` is the estimator's ring size.
    pub fn validate(&self, capacity: usize) -> Result<(), AkfError> {
        if self.window == 0 || self.window > capacity {
            return Err(AkfError::InvalidParameter {
                field: "window",
                reason: format!("{} is outside 1..={capacity}", self.window),
            });
        }
        if !(self.min_variance.is_finite() && self.min_variance >= 0.0) {
            return Err(AkfError::InvalidParameter {
                field: "min_variance",
                reason: format!("{} must be finite and ≥ 0", self.min_variance),
            });
        }
        Ok(())
    }
}

/// Result of a PSD projection.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Projected<const N: usize> {
    /// The projected, exactly symmetric matrix.
    pub matrix: SMatrix<f64, N, N>,
    /// How many eigenvalues (EigenClip) or diagonal entries (Diagonal) were raised to the floor.
    pub clipped: usize,
    /// Smallest eigenvalue (EigenClip) or smallest diagonal entry (Diagonal) of the symmetrised
    /// input, before projection.
    pub smallest_before: f64,
}

/// Eigenvalue clipping: symmetrise, decompose, raise eigenvalues below `min_eigenvalue` to it.
///
/// If no eigenvalue is below the floor the symmetrised input is returned unchanged (bit-exact),
/// so an already-PSD input comes back as itself. Otherwise the result is V diag(max(λ, floor)) Vᵀ,
/// the Frobenius-nearest symmetric matrix with all eigenvalues ≥ floor (Higham 1988).
pub fn project_psd<const N: usize>(
    q: &SMatrix<f64, N, N>,
    min_eigenvalue: f64,
) -> Result<Projected<N>, AkfError> {
    if !(min_eigenvalue.is_finite() && min_eigenvalue >= 0.0) {
        return Err(AkfError::InvalidParameter {
            field: "min_eigenvalue",
            reason: format!("{min_eigenvalue} must be finite and ≥ 0"),
        });
    }
    check_finite("q", q)?;
    let mut sym = *q;
    symmetrise_in_place(&mut sym);
    let (mut lambda, v) = symmetric_eigen(&sym)?;
    let smallest_before = lambda.min();
    let mut clipped = 0;
    for l in lambda.iter_mut() {
        if *l < min_eigenvalue {
            *l = min_eigenvalue;
            clipped += 1;
        }
    }
    if clipped == 0 {
        return Ok(Projected {
            matrix: sym,
            clipped,
            smallest_before,
        });
    }
    let mut out = v * SMatrix::<f64, N, N>::from_diagonal(&lambda) * v.transpose();
    symmetrise_in_place(&mut out);
    Ok(Projected {
        matrix: out,
        clipped,
        smallest_before,
    })
}

/// Checks the inputs of one adaptive-estimator push (shared by [`AdaptiveQ::push`] and
/// `SageHusaQ::push`): every one finite, else the error names it.
pub(crate) fn check_push_inputs<const N: usize>(
    dx: &SVector<f64, N>,
    p_post: &SMatrix<f64, N, N>,
    p_post_prev: &SMatrix<f64, N, N>,
    phi_interval: &SMatrix<f64, N, N>,
) -> Result<(), AkfError> {
    check_finite("dx", dx)?;
    check_finite("p_post", p_post)?;
    check_finite("p_post_prev", p_post_prev)?;
    check_finite("phi_interval", phi_interval)
}

/// Projects a symmetrised Q̂ as `projection` says: eigenvalue clipping at `min_eigenvalue`, or
/// the diagonal with per-state `floors` (the structured projection starts from the diagonal one
/// too). Shared by every adaptive estimator.
pub(crate) fn apply_projection<const N: usize>(
    raw: &SMatrix<f64, N, N>,
    projection: QProjection,
    min_eigenvalue: f64,
    floors: &SVector<f64, N>,
) -> Result<Projected<N>, AkfError> {
    match projection {
        QProjection::EigenClip => project_psd(raw, min_eigenvalue),
        QProjection::Diagonal | QProjection::Structured => project_diagonal(raw, floors),
    }
}

/// Diagonal projection: `out = diag(max(q_ii, floors_i))`, off-diagonals dropped.
pub fn project_diagonal<const N: usize>(
    q: &SMatrix<f64, N, N>,
    floors: &SVector<f64, N>,
) -> Result<Projected<N>, AkfError> {
    check_finite("q", q)?;
    check_floors(floors)?;
    let mut out = SMatrix::<f64, N, N>::zeros();
    let mut clipped = 0;
    let mut smallest_before = f64::INFINITY;
    for i in 0..N {
        let d = q[(i, i)];
        smallest_before = smallest_before.min(d);
        out[(i, i)] = if d < floors[i] {
            clipped += 1;
            floors[i]
        } else {
            d
        };
    }
    Ok(Projected {
        matrix: out,
        clipped,
        smallest_before,
    })
}

fn check_floors<const N: usize>(floors: &SVector<f64, N>) -> Result<(), AkfError> {
    for (i, f) in floors.iter().enumerate() {
        if !(f.is_finite() && *f >= 0.0) {
            return Err(AkfError::InvalidParameter {
                field: "floors",
                reason: format!("entry {i} is {f}; floors must be finite and ≥ 0"),
            });
        }
    }
    Ok(())
}

/// Windowed estimator of the process noise over one update interval (Mohamed & Schwarz 1999):
///
/// Q̂_k = (1/N_w) Σ_{j=k−N_w+1..k} Δx_j Δx_jᵀ + P_k⁺ − Φ P_{k−1}⁺ Φᵀ,  Δx_j = x̂_j⁺ − x̂_j⁻,
///
/// with Φ the transition over the interval from update k−1 to update k. The Δx are kept in a ring
/// buffer of capacity `CAP` (no allocation); the sum is recomputed from the buffer each time (no
/// running-sum drift). Until N_w updates have been pushed there is no estimate
/// ([`AdaptiveQ::estimate`] is `None`) and the caller keeps its own Q.
#[derive(Debug, Clone)]
pub struct AdaptiveQ<const N: usize, const CAP: usize = DEFAULT_WINDOW_CAPACITY> {
    config: AdaptiveQConfig,
    floors: SVector<f64, N>,
    ring: [SVector<f64, N>; CAP],
    next: usize,
    len: usize,
    raw: Option<SMatrix<f64, N, N>>,
    projected: Option<Projected<N>>,
}

impl<const N: usize, const CAP: usize> AdaptiveQ<N, CAP> {
    /// An empty estimator; `config` is validated against the capacity `CAP`.
    pub fn new(config: AdaptiveQConfig) -> Result<Self, AkfError> {
        config.validate(CAP)?;
        Ok(Self {
            config,
            floors: SVector::repeat(config.min_variance),
            ring: [SVector::zeros(); CAP],
            next: 0,
            len: 0,
            raw: None,
            projected: None,
        })
    }

    /// The configuration in use.
    pub fn config(&self) -> &AdaptiveQConfig {
        &self.config
    }

    /// Per-state floors for [`QProjection::Diagonal`] (state units² per interval, finite, ≥ 0).
    /// Defaults to `min_variance` for every state. Ignored by [`QProjection::EigenClip`].
    pub fn set_diagonal_floors(&mut self, floors: SVector<f64, N>) -> Result<(), AkfError> {
        check_floors(&floors)?;
        self.floors = floors;
        Ok(())
    }

    /// Number of Δx currently in the window (≤ N_w).
    pub fn len(&self) -> usize {
        self.len
    }

    /// True before the first push.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// True once N_w updates have been pushed (an estimate exists).
    pub fn is_full(&self) -> bool {
        self.len == self.config.window
    }

    /// Forgets the window and the estimate (e.g. after a filter re-initialisation).
    pub fn clear(&mut self) {
        self.next = 0;
        self.len = 0;
        self.raw = None;
        self.projected = None;
    }

    /// Pushes one update's data and, when the window is full, recomputes Q̂.
    ///
    /// * `dx` — Δx_k = x̂_k⁺ − x̂_k⁻ (state units),
    /// * `p_post` — P_k⁺, `p_post_prev` — P_{k−1}⁺,
    /// * `phi_interval` — Φ from update k−1 to update k (product of all step Φs in between).
    ///
    /// Returns the projected estimate if available. On a non-finite input nothing changes.
    pub fn push(
        &mut self,
        dx: &SVector<f64, N>,
        p_post: &SMatrix<f64, N, N>,
        p_post_prev: &SMatrix<f64, N, N>,
        phi_interval: &SMatrix<f64, N, N>,
    ) -> Result<Option<&SMatrix<f64, N, N>>, AkfError> {
        check_push_inputs(dx, p_post, p_post_prev, phi_interval)?;
        let w = self.config.window;
        self.ring[self.next] = *dx;
        self.next = (self.next + 1) % w;
        self.len = (self.len + 1).min(w);
        if self.len < w {
            return Ok(None);
        }
        let mut sum = SMatrix::<f64, N, N>::zeros();
        for d in &self.ring[..w] {
            sum += d * d.transpose();
        }
        let mut raw =
            sum / (w as f64) + p_post - phi_interval * p_post_prev * phi_interval.transpose();
        symmetrise_in_place(&mut raw);
        let projected = apply_projection(
            &raw,
            self.config.projection,
            self.config.min_variance,
            &self.floors,
        )?;
        self.raw = Some(raw);
        self.projected = Some(projected);
        Ok(self.projected.as_ref().map(|p| &p.matrix))
    }

    /// Latest projected (PSD) Q̂ over one update interval, or `None` before the window is full.
    pub fn estimate(&self) -> Option<&SMatrix<f64, N, N>> {
        self.projected.as_ref().map(|p| &p.matrix)
    }

    /// Latest symmetrised but unprojected Q̂ (indefinite in general), for diagnostics.
    pub fn raw_estimate(&self) -> Option<&SMatrix<f64, N, N>> {
        self.raw.as_ref()
    }

    /// Details of the latest projection (how many eigenvalues/diagonals were clipped).
    pub fn last_projection(&self) -> Option<&Projected<N>> {
        self.projected.as_ref()
    }
}

/// A [`KalmanFilter`] with an [`AdaptiveQ`] estimator attached.
///
/// Between updates it multiplies the step transitions into Φ_interval and accumulates the
/// filter's own process noise over the interval (Q_model = Σ Φ_{k←i} Q_d,i Φ_{k←i}ᵀ, the quantity
/// Q̂ estimates); at each update it pushes Δx, P_k⁺, P_{k−1}⁺ and Φ_interval to the estimator.
/// It never changes Q by itself: the caller reads [`AdaptiveKalmanFilter::q_estimate`], converts
/// it to its per-step Q_d (crate docs; `ins-sd-filter` predicts once per interval and needs no
/// conversion) and passes that to the next
/// [`AdaptiveKalmanFilter::predict`] calls.
#[derive(Debug, Clone)]
pub struct AdaptiveKalmanFilter<const N: usize, const CAP: usize = DEFAULT_WINDOW_CAPACITY> {
    kf: KalmanFilter<N>,
    estimator: AdaptiveQ<N, CAP>,
    phi_interval: SMatrix<f64, N, N>,
    q_model_interval: SMatrix<f64, N, N>,
    p_post_prev: SMatrix<f64, N, N>,
    steps_since_update: usize,
}

impl<const N: usize, const CAP: usize> AdaptiveKalmanFilter<N, CAP> {
    /// Filter with initial estimate and covariance (P_0 serves as P_0⁺ for the first Q̂ term).
    pub fn new(
        x0: SVector<f64, N>,
        p0: SMatrix<f64, N, N>,
        config: AdaptiveQConfig,
    ) -> Result<Self, AkfError> {
        let kf = KalmanFilter::new(x0, p0)?;
        let estimator = AdaptiveQ::new(config)?;
        let p_post_prev = *kf.covariance();
        Ok(Self {
            kf,
            estimator,
            phi_interval: SMatrix::identity(),
            q_model_interval: SMatrix::zeros(),
            p_post_prev,
            steps_since_update: 0,
        })
    }

    /// The underlying filter (state, covariance).
    pub fn filter(&self) -> &KalmanFilter<N> {
        &self.kf
    }

    /// The estimator (window fill, raw estimate, projection details).
    pub fn estimator(&self) -> &AdaptiveQ<N, CAP> {
        &self.estimator
    }

    /// Mutable estimator access (per-state floors, clearing the window).
    pub fn estimator_mut(&mut self) -> &mut AdaptiveQ<N, CAP> {
        &mut self.estimator
    }

    /// Latest projected Q̂ over one update interval (`None` until N_w updates have happened).
    pub fn q_estimate(&self) -> Option<&SMatrix<f64, N, N>> {
        self.estimator.estimate()
    }

    /// Φ accumulated since the last update.
    pub fn phi_interval(&self) -> &SMatrix<f64, N, N> {
        &self.phi_interval
    }

    /// The filter's own process noise accumulated since the last update, Σ Φ Q_d Φᵀ.
    pub fn q_model_interval(&self) -> &SMatrix<f64, N, N> {
        &self.q_model_interval
    }

    /// Number of predict steps since the last update.
    pub fn steps_since_update(&self) -> usize {
        self.steps_since_update
    }

    /// See [`KalmanFilter::reset_error_state`].
    pub fn reset_error_state(&mut self) {
        self.kf.reset_error_state();
    }

    /// One prediction step (see [`KalmanFilter::predict`]); also accumulates Φ_interval and
    /// Q_model over the interval.
    pub fn predict(
        &mut self,
        phi: &SMatrix<f64, N, N>,
        q_d: &SMatrix<f64, N, N>,
    ) -> Result<(), AkfError> {
        self.kf.predict(phi, q_d)?;
        self.phi_interval = phi * self.phi_interval;
        self.q_model_interval = phi * self.q_model_interval * phi.transpose() + q_d;
        symmetrise_in_place(&mut self.q_model_interval);
        self.steps_since_update += 1;
        Ok(())
    }

    /// Measurement update (see [`KalmanFilter::update`]) followed by a push to the estimator.
    ///
    /// If the filter update fails nothing changes. The estimator push can only fail on a
    /// non-converging eigen-decomposition (not observed for finite input); the filter has then
    /// been updated and the previous estimate is kept.
    pub fn update<const M: usize>(
        &mut self,
        z: &SVector<f64, M>,
        h: &SMatrix<f64, M, N>,
        r: &SMatrix<f64, M, M>,
    ) -> Result<Innovation<M>, AkfError> {
        let x_prior = *self.kf.state();
        let innovation = self.kf.update(z, h, r)?;
        let dx = self.kf.state() - x_prior;
        let p_post = *self.kf.covariance();
        let pushed = self
            .estimator
            .push(&dx, &p_post, &self.p_post_prev, &self.phi_interval)
            .map(|_| ());
        self.p_post_prev = p_post;
        self.phi_interval = SMatrix::identity();
        self.q_model_interval = SMatrix::zeros();
        self.steps_since_update = 0;
        pushed?;
        Ok(innovation)
    }
}
