//! The errors of a replay against a reference trajectory, accumulated on the way
//! ([`ReplayMetrics`]), and a solution compared with the truth file ([`compare_with_truth`]).

use std::path::Path;

use ins_errors::error_model;
use ins_errors::strapdown::NavState;
use ins_sd_filter::{InsSdFilter, UpdateReport};
use nalgebra::SMatrix;

use super::chi2_band;
use super::read::read_truth;
use super::reference::{ReferenceRow, interpolate};
use crate::SimError;

/// Error statistics of one 3-vector quantity (position m, velocity m/s, attitude rad).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct ErrorStats {
    /// RMS of the 3-D error norm.
    pub rms: f64,
    /// Largest 3-D error norm.
    pub max: f64,
    /// 3-D error norm at the last compared time.
    pub last: f64,
    /// RMS per axis (N, E, D).
    pub rms_axis: [f64; 3],
    /// Fraction of (time, axis) pairs with |error| ≤ 2σ.
    pub inside_2sigma: f64,
    /// Fraction of compared times whose 3-D error lies inside the filter's 2σ ellipsoid: the
    /// block's NEES `eᵀ P⁻¹ e` at or below χ²₃(0.9545) ≈ 8.02, the region a consistent filter's
    /// error falls in with the probability of a 1-D ±2σ interval. An epoch counts only if all
    /// three axes together are inside.
    pub inside_2sigma_epochs: f64,
}

/// One compared time: error (solution − reference: δp NED m, δv NED m/s, ψ rad; ψ NaN without
/// a reference attitude) and the filter's 1σ of each.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ErrorSample {
    /// Time, s.
    pub t_s: f64,
    /// Errors.
    pub error: [f64; 9],
    /// 1σ (NaN without an estimator).
    pub sigma: [f64; 9],
}

/// Errors of a replayed solution against a reference, and the filter's consistency.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct ReplayMetrics {
    /// Compared times (reference rows inside the replay).
    pub compared: usize,
    /// First and last compared time, s.
    pub span_s: [f64; 2],
    /// Position error, m.
    pub position_m: ErrorStats,
    /// Velocity error, m/s.
    pub velocity_mps: ErrorStats,
    /// Attitude error ψ, rad (`None` without reference attitude).
    pub attitude_rad: Option<ErrorStats>,
    /// Mean NEES per degree of freedom over the compared times (position and velocity, and
    /// attitude when the reference has it); 1 for a consistent filter.
    pub nees_per_dof: Option<f64>,
    /// Degrees of freedom of one NEES (6 or 9).
    pub nees_dof: usize,
    /// Compared times with a NEES.
    pub nees_times: usize,
    /// Integrated autocorrelation time of the NEES series, in compared times (module
    /// [`super::chi2_band`]).
    pub nees_autocorrelation_times: Option<f64>,
    /// The number of independent times whose mean NEES would vary as much as this one:
    /// `nees_times` / `nees_autocorrelation_times`, within [1, `nees_times`].
    pub nees_effective_times: Option<f64>,
    /// Two-sided 95 % band of the mean NEES per dof for `nees_effective_times` independent
    /// times (χ²(ν)/ν, ν = `nees_effective_times` · `nees_dof`; module [`super::chi2_band`]):
    /// consecutive errors are correlated, so the times are not independent.
    pub nees_band_95: Option<[f64; 2]>,
    /// The band if the compared times were independent (too narrow: for comparison only).
    pub nees_band_95_if_independent: Option<[f64; 2]>,
    /// Mean NIS per degree of freedom over the sighting epochs (Σ NIS / Σ 2·used).
    pub nis_per_dof: Option<f64>,
    /// Degrees of freedom summed over the epochs.
    pub nis_dof: u64,
    /// Two-sided 95 % χ² band of the mean NIS per dof, the epochs taken as independent (a
    /// consistent filter's innovations are white).
    pub nis_band_95: Option<[f64; 2]>,
    /// The compared times (for plots; not serialised).
    #[serde(skip)]
    pub series: Vec<ErrorSample>,
}

/// Accumulates [`ReplayMetrics`].
pub(super) struct MetricsAcc {
    reference: Vec<ReferenceRow>,
    next: usize,
    cursor: usize,
    max_ref_gap_s: f64,
    sum2: [[f64; 3]; 3],
    sum2_norm: [f64; 3],
    max: [f64; 3],
    last: [f64; 3],
    inside: [u64; 3],
    sigma_count: [u64; 3],
    inside_epochs: [u64; 3],
    epoch_count: [u64; 3],
    nees_sum: f64,
    nees_n: u64,
    /// The NEES of each compared time (capacity: the reference's rows, one at most each).
    nees: Vec<f64>,
    nis_sum: f64,
    nis_dof: u64,
    pub(super) out: ReplayMetrics,
}

/// The metrics compare with the reference interpolated between rows at most this far apart, s.
pub const METRICS_MAX_REFERENCE_GAP_S: f64 = 1.5;

impl MetricsAcc {
    pub(super) fn new(reference: Vec<ReferenceRow>) -> Self {
        let n = reference.len();
        Self {
            reference,
            next: 0,
            cursor: 0,
            max_ref_gap_s: METRICS_MAX_REFERENCE_GAP_S,
            sum2: [[0.0; 3]; 3],
            sum2_norm: [0.0; 3],
            max: [0.0; 3],
            last: [0.0; 3],
            inside: [0; 3],
            sigma_count: [0; 3],
            inside_epochs: [0; 3],
            epoch_count: [0; 3],
            nees_sum: 0.0,
            nees_n: 0,
            nees: Vec::with_capacity(n),
            nis_sum: 0.0,
            nis_dof: 0,
            out: ReplayMetrics {
                series: Vec::with_capacity(n),
                ..Default::default()
            },
        }
    }

    /// The reference rows.
    pub(super) fn reference(&self) -> &[ReferenceRow] {
        &self.reference
    }

    /// Compares the filter at its time with the reference, once per reference row passed.
    pub(super) fn observe(&mut self, filter: &InsSdFilter) {
        let t = filter.time_s();
        let mut due = false;
        while self.next < self.reference.len() && self.reference[self.next].t_s <= t {
            self.next += 1;
            due = true;
        }
        if !due {
            return;
        }
        let Some(at) = interpolate(&self.reference, t, self.max_ref_gap_s, &mut self.cursor) else {
            return;
        };
        let sol = filter.navigation_solution();
        let has_att = at.att_b_to_n.is_some();
        let e = error_model::error_state(&at.nav_state(sol.att_b_to_n), &sol);
        let p = filter.predicted().map(|(_, p)| p);
        let mut sample = ErrorSample {
            t_s: t,
            error: [f64::NAN; 9],
            sigma: [f64::NAN; 9],
        };
        let blocks = if has_att { 3 } else { 2 };
        for b in 0..blocks {
            let mut norm2 = 0.0;
            for i in 0..3 {
                let k = 3 * b + i;
                let v = e[k];
                sample.error[k] = v;
                self.sum2[b][i] += v * v;
                norm2 += v * v;
                if let Some(p) = &p {
                    let s = p[(k, k)].max(0.0).sqrt();
                    sample.sigma[k] = s;
                    self.sigma_count[b] += 1;
                    if v.abs() <= 2.0 * s {
                        self.inside[b] += 1;
                    }
                }
            }
            if let Some(p) = &p {
                let block: SMatrix<f64, 3, 3> = p.fixed_view::<3, 3>(3 * b, 3 * b).into_owned();
                let eb: SMatrix<f64, 3, 1> = e.fixed_rows::<3>(3 * b).into_owned();
                if let Some(inside) = inside_ellipsoid(&block, &eb, CHI2_3_TWO_SIGMA) {
                    self.epoch_count[b] += 1;
                    if inside {
                        self.inside_epochs[b] += 1;
                    }
                }
            }
            let norm = norm2.sqrt();
            self.sum2_norm[b] += norm2;
            self.max[b] = self.max[b].max(norm);
            self.last[b] = norm;
        }
        if let Some(p) = &p {
            let nees = if has_att {
                let sub: SMatrix<f64, 9, 9> = p.fixed_view::<9, 9>(0, 0).into_owned();
                let ev: SMatrix<f64, 9, 1> = e.fixed_rows::<9>(0).into_owned();
                sub.cholesky()
                    .map(|c| (ev.transpose() * c.solve(&ev))[(0, 0)])
            } else {
                let sub: SMatrix<f64, 6, 6> = p.fixed_view::<6, 6>(0, 0).into_owned();
                let ev: SMatrix<f64, 6, 1> = e.fixed_rows::<6>(0).into_owned();
                sub.cholesky()
                    .map(|c| (ev.transpose() * c.solve(&ev))[(0, 0)])
            };
            if let Some(n) = nees {
                self.nees_sum += n;
                self.nees_n += 1;
                // At most one per reference row passed: within the capacity.
                self.nees.push(n);
            }
        }
        self.out.nees_dof = 3 * blocks;
        if self.out.compared == 0 {
            self.out.span_s[0] = t;
        }
        self.out.span_s[1] = t;
        self.out.compared += 1;
        self.out.series.push(sample);
    }

    pub(super) fn epoch(&mut self, report: &UpdateReport) {
        if let Some(nis) = report.nis {
            self.nis_sum += nis;
            self.nis_dof += 2 * report.used as u64;
        }
    }

    pub(super) fn finish(mut self) -> ReplayMetrics {
        let n = self.out.compared.max(1) as f64;
        let stats = |b: usize, acc: &Self| ErrorStats {
            rms: (acc.sum2_norm[b] / n).sqrt(),
            max: acc.max[b],
            last: acc.last[b],
            rms_axis: [
                (acc.sum2[b][0] / n).sqrt(),
                (acc.sum2[b][1] / n).sqrt(),
                (acc.sum2[b][2] / n).sqrt(),
            ],
            inside_2sigma: if acc.sigma_count[b] > 0 {
                acc.inside[b] as f64 / acc.sigma_count[b] as f64
            } else {
                f64::NAN
            },
            inside_2sigma_epochs: if acc.epoch_count[b] > 0 {
                acc.inside_epochs[b] as f64 / acc.epoch_count[b] as f64
            } else {
                f64::NAN
            },
        };
        self.out.position_m = stats(0, &self);
        self.out.velocity_mps = stats(1, &self);
        self.out.attitude_rad = (self.out.nees_dof == 9).then(|| stats(2, &self));
        let band = |dof: f64| -> Option<[f64; 2]> {
            let lo = akf::chi_square_quantile(0.025, dof).ok()? / dof;
            let hi = akf::chi_square_quantile(0.975, dof).ok()? / dof;
            Some([lo, hi])
        };
        if self.nees_n > 0 {
            let dof = (self.nees_n * self.out.nees_dof as u64) as f64;
            self.out.nees_per_dof = Some(self.nees_sum / dof);
            self.out.nees_times = self.nees.len();
            self.out.nees_band_95_if_independent = band(dof);
            if let Some(b) = chi2_band::nees_band(&self.nees, self.out.nees_dof as f64) {
                self.out.nees_band_95 = Some(b.band);
                self.out.nees_effective_times = Some(b.effective_times);
                self.out.nees_autocorrelation_times = Some(b.autocorrelation_times);
            }
        }
        if self.nis_dof > 0 {
            self.out.nis_per_dof = Some(self.nis_sum / self.nis_dof as f64);
            self.out.nis_dof = self.nis_dof;
            self.out.nis_band_95 = band(self.nis_dof as f64);
        }
        self.out
    }
}

/// χ²₃ quantile at the probability of ±2σ in one dimension (erf(√2) = 0.954 499 7): the 2σ
/// ellipsoid of a 3-vector (checked against `akf::chi_square_quantile` in the tests).
const CHI2_3_TWO_SIGMA: f64 = 8.024_881_760_266_3;

/// Whether the error `e` lies inside the ellipsoid `eᵀ P⁻¹ e ≤ threshold` of the covariance `p`;
/// `None` when `p` is not positive definite.
fn inside_ellipsoid(
    p: &SMatrix<f64, 3, 3>,
    e: &SMatrix<f64, 3, 1>,
    threshold: f64,
) -> Option<bool> {
    let c = p.cholesky()?;
    Some((e.transpose() * c.solve(e))[(0, 0)] <= threshold)
}

/// Errors of a solution against the truth at the common times.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TruthComparison {
    /// Solution rows with a truth row at the same time (within 1 µs).
    pub matched: usize,
    /// Time of the last matched row, s.
    pub last_t_s: f64,
    /// Position error (solution − truth, NED, m) at the last matched row.
    pub last_pos_err_ned_m: [f64; 3],
    /// RMS over the matched rows of the 3-D position error, m.
    pub rms_pos_3d_m: f64,
    /// Largest 3-D position error, m.
    pub max_pos_3d_m: f64,
    /// Misalignment ψ at the last matched row, rad.
    pub last_psi_rad: [f64; 3],
}

/// Compares a solution with the truth file at the common times.
///
/// # Errors
/// As [`read_truth`].
pub fn compare_with_truth(
    truth: &Path,
    solution: &[(f64, NavState)],
) -> Result<TruthComparison, SimError> {
    let truth = read_truth(truth)?;
    let mut c = TruthComparison::default();
    let mut sum2 = 0.0;
    let mut j = 0;
    for (t, s) in solution {
        while j < truth.len() && truth[j].0 < t - 1e-6 {
            j += 1;
        }
        let Some((tt, ts)) = truth.get(j) else { break };
        if (tt - t).abs() > 1e-6 {
            continue;
        }
        let e = error_model::error_state(ts, s);
        let p = e.fixed_rows::<3>(0).norm();
        sum2 += p * p;
        c.max_pos_3d_m = c.max_pos_3d_m.max(p);
        c.matched += 1;
        c.last_t_s = *t;
        c.last_pos_err_ned_m = [e[0], e[1], e[2]];
        c.last_psi_rad = [e[6], e[7], e[8]];
    }
    if c.matched > 0 {
        c.rms_pos_3d_m = (sum2 / c.matched as f64).sqrt();
    }
    Ok(c)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_distr::{Distribution, StandardNormal};

    /// Errors drawn from N(0, P) fall inside the 2σ ellipsoid with the probability of ±2σ in one
    /// dimension (0.9545); errors twice too large far less often; a singular P is not judged.
    #[test]
    fn the_two_sigma_ellipsoid_holds_its_probability_for_a_correlated_covariance() {
        let quantile = akf::chi_square_quantile(0.954_499_736_103_641_6, 3.0).unwrap();
        assert!((quantile - CHI2_3_TWO_SIGMA).abs() < 1e-9, "{quantile}");
        let threshold = CHI2_3_TWO_SIGMA;
        let l = SMatrix::<f64, 3, 3>::new(2.0, 0.0, 0.0, 1.5, 0.5, 0.0, -0.7, 0.3, 0.1);
        let p = l * l.transpose();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(2026);
        let n = 20_000;
        let (mut inside, mut inside_doubled) = (0, 0);
        for _ in 0..n {
            let z = SMatrix::<f64, 3, 1>::from_fn(|_, _| StandardNormal.sample(&mut rng));
            let e = l * z;
            inside += usize::from(inside_ellipsoid(&p, &e, threshold).unwrap());
            inside_doubled += usize::from(inside_ellipsoid(&p, &(2.0 * e), threshold).unwrap());
        }
        let frac = inside as f64 / n as f64;
        // Binomial σ at n = 20 000: 0.0015.
        assert!((frac - 0.9545).abs() < 0.006, "{frac}");
        assert!((inside_doubled as f64 / n as f64) < 0.6, "{inside_doubled}");
        let singular = SMatrix::<f64, 3, 3>::from_diagonal_element(0.0);
        assert_eq!(
            inside_ellipsoid(&singular, &SMatrix::zeros(), threshold),
            None
        );
    }
}
