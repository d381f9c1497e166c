//! What the filter exposes between updates: time, configuration, INS, estimates, covariance and
//! statistics. No allocation.

use ins_errors::error_model::Mat15;
use ins_errors::strapdown::{NavState, Strapdown};
use nalgebra::{SVector, Vector3};
use sighting_model::NavPose;

use super::{Est, FilterStatistics, InsSdFilter, UpdateReport, Vec15, nav_pose};
use crate::config::InsSdFilterConfig;
use crate::landmarks::LandmarkTable;

impl InsSdFilter {
    /// Time of the last IMU sample (the INS time), s.
    pub fn time_s(&self) -> f64 {
        self.t_s
    }

    /// The configuration.
    pub fn config(&self) -> &InsSdFilterConfig {
        &self.config
    }

    /// The landmark table.
    pub fn landmarks(&self) -> &LandmarkTable {
        &self.landmarks
    }

    /// The INS (uncorrected by the current x̂; corrected by every feedback so far).
    pub fn ins(&self) -> &Strapdown {
        &self.ins
    }

    /// The pose the camera must be pointed with for the next sighting: the INS's computed
    /// position and attitude. The measured (w, h) are offsets in that camera.
    pub fn pointing_pose(&self) -> NavPose {
        nav_pose(self.ins.state())
    }

    /// x̂ as of the last sighting epoch (zeros in feedback after the reset, and without an
    /// estimator). See [`InsSdFilter::predicted`] for x̂ and P at the INS time.
    pub fn error_state(&self) -> Vec15 {
        match &self.est {
            Some(e) => *e.kf.state(),
            None => Vec15::zeros(),
        }
    }

    /// P as of the last sighting epoch (`None` without an estimator).
    pub fn covariance(&self) -> Option<&Mat15> {
        self.est.as_deref().map(|e| e.kf.covariance())
    }

    /// (x̂, P) predicted from the last sighting epoch to the INS time with the a-priori model
    /// (or the adaptive Q̂, scaled to the fraction of the update interval elapsed): what the
    /// next update starts from, and the σ a solution at the INS time is reported with. `None`
    /// without an estimator.
    pub fn predicted(&self) -> Option<(Vec15, Mat15)> {
        let est = self.est.as_deref()?;
        if self.interval.steps_done() == 0 {
            // Nothing propagated since the epoch: x̂ and P as updated.
            return Some((*est.kf.state(), *est.kf.covariance()));
        }
        let (phi, q_model) = self.interval.peek();
        // The adaptive Q̂ is for one whole update interval: scaled to the part elapsed
        // (structured: the last fitted Σ q̂_k B_k, likewise).
        let elapsed =
            (self.interval.steps_done() as f64 / self.config.steps_per_update() as f64).min(1.0);
        let q = est.q_estimate().map_or(q_model, |q_hat| q_hat * elapsed);
        let x = phi * est.kf.state();
        let mut p = phi * est.kf.covariance() * phi.transpose() + q;
        p = 0.5 * (p + p.transpose());
        Some((x, p))
    }

    /// The navigation solution at the INS time: the INS corrected by the predicted x̂ (in
    /// feedback, x̂ = 0 after each reset, so this is the INS itself).
    pub fn navigation_solution(&self) -> NavState {
        let Some((x, _)) = self.predicted() else {
            return *self.ins.state();
        };
        if x.iter().all(|v| *v == 0.0) {
            return *self.ins.state();
        }
        let mut ins = self.ins.clone();
        let v = |i: usize| Vector3::new(x[i], x[i + 1], x[i + 2]);
        ins.apply_correction(&v(0), &v(3), &v(6));
        *ins.state()
    }

    /// Estimated sensor errors (accelerometer bias body m/s², gyro drift body rad/s): the INS's
    /// corrections plus the current x̂.
    pub fn sensor_error_estimates(&self) -> (Vector3<f64>, Vector3<f64>) {
        let (a, g) = self.ins.sensor_corrections();
        let x = self.error_state();
        (
            a + Vector3::new(x[9], x[10], x[11]),
            g + Vector3::new(x[12], x[13], x[14]),
        )
    }

    /// The fitted noise densities of the structured projection (accelerometer white
    /// (m/s²)²/Hz, gyro white rad²/s, bias RW (m/s²)²/s, drift RW (rad/s)²/s), once fitted.
    pub fn fitted_noise_densities(&self) -> Option<SVector<f64, 4>> {
        self.est.as_deref().and_then(|e| e.densities)
    }

    /// The adaptive Q̂ over one interval (`None` for the KF or before the window is full).
    pub fn q_estimate(&self) -> Option<&Mat15> {
        self.est.as_deref().and_then(Est::q_estimate)
    }

    /// What the last update with at least one sighting did.
    pub fn last_report(&self) -> &UpdateReport {
        &self.last_report
    }

    /// Totals since construction (sightings used and rejected, …).
    pub fn statistics(&self) -> &FilterStatistics {
        &self.stats
    }
}
