//! The measurement update of one sighting epoch ([`InsSdFilter::update`],
//! [`InsSdFilter::update_pointed`]): the prediction over the interval, the gate, the batched
//! Kalman update, the adaptive Q̂ and the feedback. Allocation-free.

use akf::KalmanFilter;
use ins_errors::error_model::Mat15;
use nalgebra::{Matrix2, SMatrix, SVector, Vector2};
use sighting_model::{Landmark, LosFrame, NavPose, PaperAlphaReading};

use super::{
    Adaptive, FEEDBACK_TIME_TOL_S, InsSdFilter, MAX_BATCH, PointedSighting, Sighting, UpdateReport,
    nav_pose,
};
use crate::FilterError;
use crate::config::MeasurementJacobian;
use crate::landmarks::LandmarkTable;

/// The sightings of one epoch, as the paper's offsets or as pointed directions.
#[derive(Clone, Copy)]
enum Epoch<'a> {
    Offsets(&'a [Sighting]),
    Pointed(&'a [PointedSighting]),
}

impl Epoch<'_> {
    fn len(&self) -> usize {
        match self {
            Epoch::Offsets(s) => s.len(),
            Epoch::Pointed(s) => s.len(),
        }
    }

    /// Sighting `i` as (landmark id, offsets z, frame of H), checked.
    fn get(
        &self,
        i: usize,
        t_s: f64,
        landmarks: &LandmarkTable,
        pose: &NavPose,
    ) -> Result<(u32, Vector2<f64>, LosFrame), FilterError> {
        let id = match self {
            Epoch::Offsets(s) => s[i].landmark_id,
            Epoch::Pointed(s) => s[i].landmark_id,
        };
        let Some(lm) = landmarks.get(id) else {
            return Err(FilterError::UnknownLandmark { t_s, id });
        };
        match self {
            Epoch::Offsets(s) => {
                let s = &s[i];
                if !(s.w_m.is_finite() && s.h_m.is_finite()) {
                    return Err(FilterError::NonFiniteInput {
                        what: "sighting w/h",
                        t_s,
                    });
                }
                Ok((id, Vector2::new(s.w_m, s.h_m), LosFrame::Body))
            }
            Epoch::Pointed(s) => {
                let s = &s[i];
                if !s.los.iter().all(|v| v.is_finite()) {
                    return Err(FilterError::NonFiniteInput {
                        what: "sighting direction",
                        t_s,
                    });
                }
                match sighting_model::offsets_from_los(pose, lm, s.frame, &s.los) {
                    Ok(z) => Ok((id, z, s.frame)),
                    // Seen from this INS the direction points away from the landmark: the
                    // INS is far off, or the record is wrong. Not a usable measurement:
                    // rejected like a gated outlier (NaN offsets).
                    Err(sighting_model::SightingError::BehindCamera { .. }) => {
                        Ok((id, Vector2::new(f64::NAN, f64::NAN), s.frame))
                    }
                    Err(source) => Err(FilterError::Sighting {
                        t_s,
                        landmark: id,
                        source,
                    }),
                }
            }
        }
    }
}

/// One landmark's accepted row pair.
#[derive(Clone, Copy)]
struct Row {
    h: SMatrix<f64, 2, 15>,
    z: Vector2<f64>,
}

fn batch_update<const M: usize>(
    kf: &mut KalmanFilter<15>,
    rows: &[Row],
    r_var_m2: f64,
) -> Result<f64, akf::AkfError> {
    let mut h = SMatrix::<f64, M, 15>::zeros();
    let mut z = SVector::<f64, M>::zeros();
    for (i, row) in rows.iter().enumerate() {
        h.fixed_view_mut::<2, 15>(2 * i, 0).copy_from(&row.h);
        z[2 * i] = row.z.x;
        z[2 * i + 1] = row.z.y;
    }
    let r = SMatrix::<f64, M, M>::identity() * r_var_m2;
    Ok(kf.update(&z, &h, &r)?.nis)
}

impl InsSdFilter {
    /// Measurement update at epoch `t_s` (the INS time, within the time-stamp tolerance) with
    /// 0, 1 or more sightings: predicts over the interval since the last epoch (a-priori Q, or
    /// the adaptive Q̂), gates each sighting on its 2-dof NIS against the prior, updates with the
    /// accepted ones (batches of ≤ [`MAX_BATCH`] landmarks), pushes the correction to the
    /// adaptive estimator, and feeds back at or after `open_loop_until_s`. An empty slice does
    /// nothing (the interval continues). Allocation-free.
    ///
    /// # Errors
    /// Checked before anything changes: [`FilterError::OutOfOrder`] (epoch before the last
    /// one), [`FilterError::NotAtInsTime`], [`FilterError::UnknownLandmark`],
    /// [`FilterError::NonFiniteInput`]. During the update, after the prediction has been made
    /// (x̂ and P stay a valid prediction): [`FilterError::Sighting`] (geometry of a landmark,
    /// e.g. straight below the vehicle), [`FilterError::Akf`] (S not positive definite),
    /// [`FilterError::NonFiniteState`].
    pub fn update(
        &mut self,
        t_s: f64,
        sightings: &[Sighting],
    ) -> Result<UpdateReport, FilterError> {
        self.update_epoch(t_s, Epoch::Offsets(sightings))
    }

    /// As [`InsSdFilter::update`] with sightings that carry their pointing: each direction is
    /// turned into the offsets a camera pointed with this filter's INS would have seen
    /// (`sighting_model::offsets_from_los`), and linearised with H of its frame (ψ columns zero
    /// for local-level directions, `sighting_model::jacobian_for_frame`). Allocation-free.
    ///
    /// # Errors
    /// As [`InsSdFilter::update`]; also [`FilterError::NonFiniteInput`] for a NaN/∞ direction.
    /// A direction that points away from its landmark as seen from the INS (behind the camera)
    /// is not an error: it is counted as rejected, like a gated outlier.
    pub fn update_pointed(
        &mut self,
        t_s: f64,
        sightings: &[PointedSighting],
    ) -> Result<UpdateReport, FilterError> {
        self.update_epoch(t_s, Epoch::Pointed(sightings))
    }

    fn update_epoch(
        &mut self,
        t_s: f64,
        sightings: Epoch<'_>,
    ) -> Result<UpdateReport, FilterError> {
        if !t_s.is_finite() {
            return Err(FilterError::NonFiniteInput {
                what: "time stamp",
                t_s,
            });
        }
        if t_s < self.last_epoch_s {
            return Err(FilterError::OutOfOrder {
                what: "sighting epoch",
                t_s,
                previous_s: self.last_epoch_s,
            });
        }
        let tol = self.config.timestamp_tolerance_s.max(1e-9);
        if (t_s - self.t_s).abs() > tol {
            return Err(FilterError::NotAtInsTime {
                t_s,
                ins_time_s: self.t_s,
                tolerance_s: tol,
            });
        }
        let pose = nav_pose(self.ins.state());
        for i in 0..sightings.len() {
            sightings.get(i, t_s, &self.landmarks, &pose)?;
        }
        let mut report = UpdateReport::default();
        if sightings.len() == 0 {
            return Ok(report);
        }
        self.last_epoch_s = t_s;
        let Some(est) = self.est.as_deref_mut() else {
            return Ok(report);
        };
        let ae = |source| FilterError::Akf { t_s, source };
        let pos = self.ins.state().pos;
        let mut rows = [Row {
            h: SMatrix::zeros(),
            z: Vector2::zeros(),
        }; MAX_BATCH];
        // Predict over the interval.
        let (phi, q_model) = self.interval.take();
        let q = match est.q_for_prediction(self.interval.noise_basis()) {
            Some(q_hat) => {
                report.adaptive_q = true;
                q_hat
            }
            None => q_model,
        };
        est.kf.predict(&phi, &q).map_err(ae)?;
        est.phi_since_push = Some(match est.phi_since_push {
            None => phi,
            Some(prev) => phi * prev,
        });
        if report.adaptive_q {
            self.stats.adaptive_q_used += 1;
        }
        self.stats.epochs += 1;
        let x_prior = *est.kf.state();
        let p_prior = *est.kf.covariance();
        let r = self.config.r_var_m2;
        let mut n = 0usize;
        let mut nis_sum = 0.0;
        let mut any_used = false;
        for i in 0..sightings.len() {
            let (id, z, frame) = sightings.get(i, t_s, &self.landmarks, &pose)?;
            let Some(lm) = self.landmarks.get(id) else {
                continue; // checked above
            };
            let mut h = jacobian(self.config.jacobian, &pos, lm).map_err(|source| {
                FilterError::Sighting {
                    t_s,
                    landmark: id,
                    source,
                }
            })?;
            if frame == LosFrame::LocalLevel {
                h.fixed_view_mut::<2, 3>(0, sighting_model::PSI_COL)
                    .fill(0.0);
            }
            if z.x.is_nan() {
                // A pointed sighting behind the camera (Epoch::get).
                report.rejected += 1;
                continue;
            }
            if let Some(threshold) = self.gate_threshold {
                let nu = z - h * x_prior;
                let s2: Matrix2<f64> = h * p_prior * h.transpose() + Matrix2::identity() * r;
                let nis = s2
                    .try_inverse()
                    .map(|si| (nu.transpose() * si * nu)[(0, 0)])
                    .unwrap_or(f64::INFINITY);
                if nis.is_nan() || nis > threshold {
                    report.rejected += 1;
                    continue;
                }
            }
            rows[n] = Row { h, z };
            n += 1;
            report.used += 1;
            if n == MAX_BATCH {
                nis_sum += batch(&mut est.kf, &rows[..n], r).map_err(ae)?;
                any_used = true;
                n = 0;
            }
        }
        if n > 0 {
            nis_sum += batch(&mut est.kf, &rows[..n], r).map_err(ae)?;
            any_used = true;
        }
        self.stats.sightings_used += report.used as u64;
        self.stats.sightings_rejected += report.rejected as u64;
        if any_used {
            report.nis = Some(nis_sum);
            let dx = est.kf.state() - x_prior;
            let p_post = *est.kf.covariance();
            let phi_push = est.phi_since_push.take().unwrap_or_else(Mat15::identity);
            let pushed = match &mut est.adaptive {
                Adaptive::None => Ok(()),
                Adaptive::MohamedSchwarz(a) => a
                    .push(&dx, &p_post, &est.p_post_prev, &phi_push)
                    .map(|_| ()),
                Adaptive::SageHusa(a) => a
                    .push(&dx, &p_post, &est.p_post_prev, &phi_push)
                    .map(|_| ()),
            };
            pushed.map_err(ae)?;
            if est.structured
                && let Some(raw) = est.raw_when_ready()
            {
                // Fit on this interval's noise basis, residual scaled by the previous P⁺.
                let scale = est.p_post_prev.diagonal();
                let fit = akf::project_structured(raw, self.interval.noise_basis(), &scale)
                    .map_err(ae)?;
                est.densities = Some(fit.densities);
                est.structured_q = Some(fit.matrix);
            }
            est.p_post_prev = p_post;
        }
        if !est.kf.state().iter().all(|x| x.is_finite()) || !nis_sum.is_finite() {
            return Err(FilterError::NonFiniteState {
                what: "filter state",
                t_s,
            });
        }
        if t_s >= self.config.open_loop_until_s - FEEDBACK_TIME_TOL_S {
            self.feedback();
            report.fed_back = true;
        }
        self.last_report = report;
        Ok(report)
    }
}

/// Dispatches a batch of 1..=MAX_BATCH landmarks to the fixed-size update.
fn batch(kf: &mut KalmanFilter<15>, rows: &[Row], r: f64) -> Result<f64, akf::AkfError> {
    match rows.len() {
        1 => batch_update::<2>(kf, rows, r),
        2 => batch_update::<4>(kf, rows, r),
        3 => batch_update::<6>(kf, rows, r),
        4 => batch_update::<8>(kf, rows, r),
        5 => batch_update::<10>(kf, rows, r),
        6 => batch_update::<12>(kf, rows, r),
        7 => batch_update::<14>(kf, rows, r),
        _ => batch_update::<16>(kf, &rows[..MAX_BATCH.min(rows.len())], r),
    }
}

/// H of one landmark (2×15) at the computed position.
fn jacobian(
    which: MeasurementJacobian,
    pos: &ins_errors::earth::Geodetic,
    lm: &Landmark,
) -> Result<SMatrix<f64, 2, 15>, sighting_model::SightingError> {
    match which {
        MeasurementJacobian::Verified => sighting_model::sighting_jacobian(pos, lm),
        MeasurementJacobian::PaperPrinted => sighting_model::paper_printed_jacobian(pos, lm),
        MeasurementJacobian::PaperPrintedElevation => {
            sighting_model::paper_eq15_jacobian(pos, lm, PaperAlphaReading::Elevation)
        }
    }
}
