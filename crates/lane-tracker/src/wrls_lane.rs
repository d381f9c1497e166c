//! Adapter: one lane's WRLS estimator (the `wrls` crate's fast, information form) behind the
//! tracker's interface.
//!
//! The tracker uses [`wrls::WrlsFast`]: the same estimator as the paper's eqs. 25–27 (the `wrls`
//! crate tests the equality), with λ applied once per frame and no `N×N` inversion, so the
//! per-frame path stays allocation-free. The paper's `N×N` form ([`wrls::WrlsPaper`]) is what
//! the Table 1 bench times.

use info_filter::{RowNorm, ThetaCov};
use nalgebra::Vector3;
use wrls::{WrlsError, WrlsFast};

/// One lane's WRLS state.
#[derive(Debug, Clone)]
pub(crate) struct WrlsLane {
    inner: WrlsFast,
}

impl WrlsLane {
    pub(crate) fn new(
        theta0_px: &Vector3<f64>,
        p0: &ThetaCov,
        row_norm: RowNorm,
        lambda: f64,
    ) -> Result<Self, WrlsError> {
        Ok(WrlsLane {
            inner: WrlsFast::new(theta0_px, p0, lambda, row_norm)?,
        })
    }

    pub(crate) fn update(&mut self, points: &[(f32, f32)]) -> Result<(), WrlsError> {
        self.inner.update(points)
    }

    pub(crate) fn estimate(&self) -> Vector3<f64> {
        self.inner.estimate()
    }

    /// `P_px` of the WRLS recursion (a scaled inverse normal matrix, see `wrls`).
    pub(crate) fn covariance_px(&self) -> Option<nalgebra::Matrix3<f64>> {
        self.inner.covariance().ok()
    }

    pub(crate) fn col_at_row_px(&self, row_px: f64) -> f64 {
        let t = self.inner.estimate();
        hough_init::Parabola::from_coeffs([t[0], t[1], t[2]]).col_at_row(row_px)
    }
}
