//! Adapter: one lane's WRLS estimator (the `wrls` crate) behind the tracker's interface.

use info_filter::{RowNorm, ThetaCov};
use nalgebra::Vector3;

/// One lane's WRLS state (placeholder until the `wrls` crate lands).
#[derive(Debug, Clone)]
pub(crate) struct WrlsLane {
    theta_px: Vector3<f64>,
}

impl WrlsLane {
    pub(crate) fn new(
        _theta0_px: &Vector3<f64>,
        _p0: &ThetaCov,
        _row_norm: RowNorm,
        _lambda: f64,
    ) -> Result<Self, String> {
        Err("the wrls estimator is not available yet in this build".to_owned())
    }
    pub(crate) fn update(&mut self, _points: &[(f32, f32)]) -> Result<(), String> {
        Err("unavailable".to_owned())
    }
    pub(crate) fn estimate(&self) -> Vector3<f64> {
        self.theta_px
    }
    pub(crate) fn col_at_row_px(&self, row_px: f64) -> f64 {
        (self.theta_px[0] * row_px + self.theta_px[1]) * row_px + self.theta_px[2]
    }
}
