//! Replaying logs through the online filter ([`replay`]), with the errors against a reference
//! trajectory computed on the way ([`ReplayMetrics`]), and comparing a solution with the truth
//! ([`compare_with_truth`]).
//!
//! ## Time
//!
//! IMU time stamps are used as logged (any rate, any jitter). A sighting epoch at t is applied
//! at t exactly: the IMU sample that spans t is cut there (its mean rates held on both sides), so
//! a sighting is never applied late. A sample more than [`GAP_FACTOR`] nominal steps after the
//! previous one is a **gap**: it is bridged by propagating its mean rates in nominal steps (the
//! covariance grows with the model's Q over the gap), counted and reported, and refused only
//! when longer than `max_gap_s`.

use std::io::Write;
use std::path::{Path, PathBuf};

use ins_errors::error_model;
use ins_errors::strapdown::NavState;
use ins_sd_filter::{InsSdFilter, InsSdFilterConfig, PointedSighting, Sighting, UpdateReport};
use nalgebra::{SMatrix, Vector3};

use super::imu::ImuStream;
use super::read::{CsvReader, InitialState, Record, io_err, read_landmarks, read_truth};
use super::reference::{ReferenceRow, interpolate};
use super::write::write_solution;
use super::{POINTED_SIGHTINGS_HEADER, SIGHTINGS_HEADER, SOLUTION_HEADER};
use crate::SimError;

/// A sample later than this many nominal IMU steps after the previous one is a gap.
pub const GAP_FACTOR: f64 = 2.0;

/// When the replay writes a solution row.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SolutionRate {
    /// After every sighting epoch only.
    Epochs,
    /// After every IMU sample (and at every epoch).
    EveryImu,
    /// At this rate, Hz (the first IMU time at or after each multiple of 1/rate).
    Hz(f64),
}

/// The inputs and settings of a replay.
#[derive(Clone, Debug)]
pub struct ReplayInputs {
    /// IMU log (CSV increments or rates, declared by its header; or a ROS 2 bag, `.mcap`).
    pub imu: PathBuf,
    /// With a bag: its `sensor_msgs/msg/Imu` topic (default: the only one).
    pub imu_topic: Option<String>,
    /// Sightings log (offsets, format 1, or pointed, format 2) and its landmark table; `None`:
    /// unaided.
    pub sightings: Option<(PathBuf, PathBuf)>,
    /// Initial state; IMU samples and sightings at or before its time are skipped.
    pub initial: InitialState,
    /// Filter settings.
    pub config: InsSdFilterConfig,
    /// The longest IMU gap bridged, s.
    pub max_gap_s: f64,
    /// When solution rows are written.
    pub rate: SolutionRate,
    /// Reference trajectory for [`ReplayMetrics`].
    pub reference: Option<Vec<ReferenceRow>>,
    /// Static alignment: the vehicle is at rest for this long after the initial time, s (0:
    /// none). The mean angular rate over it, less the Earth rate, is the initial gyro bias
    /// ([`align_at_rest`]).
    pub align_s: f64,
    /// With `align_s`: also take roll and pitch from the mean specific force (keeping the
    /// initial heading): for an initial attitude that did not come from a reference attitude.
    pub level: bool,
    /// Also write the solution (and the errors, with a reference) to this MCAP file
    /// ([`super::InsMcapSink`]).
    pub mcap_out: Option<PathBuf>,
}

/// What a static alignment found.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct Alignment {
    /// Samples averaged.
    pub samples: u64,
    /// Gyro bias, body rad/s (mean rate − Earth rate in body axes).
    pub gyro_bias_body_radps: [f64; 3],
    /// Mean specific force, body m/s².
    pub mean_specific_force_body_mps2: [f64; 3],
    /// Roll and pitch levelled from the specific force, rad (when levelled).
    pub roll_pitch_rad: Option<[f64; 2]>,
}

/// Static alignment over `(t0, t0 + duration_s]` of the IMU log: the mean angular rate less the
/// Earth rate resolved in body axes with `initial`'s attitude is the gyro bias; with `level`, roll
/// and pitch come from the mean specific force f̄ (at rest f = −g in body axes:
/// roll = atan2(−f̄_y, −f̄_z), pitch = atan2(f̄_x, √(f̄_y² + f̄_z²))) and the heading is kept;
/// `initial` is updated in place. The accelerometer bias cannot be told from a tilt at rest and is
/// left to the filter.
///
/// # Errors
/// [`SimError::LogIo`], [`SimError::LogParse`] for a bad record or no sample in the window.
pub fn align_at_rest(
    imu_path: &Path,
    imu_topic: Option<&str>,
    initial: &mut InitialState,
    duration_s: f64,
    level: bool,
) -> Result<Alignment, SimError> {
    let mut imu = ImuStream::open(imu_path, imu_topic)?;
    let rates = imu.rates();
    let (t0, t1) = (initial.t_s, initial.t_s + duration_s);
    let (mut sum_f, mut sum_w, mut sum_dt, mut n) = (Vector3::zeros(), Vector3::zeros(), 0.0, 0u64);
    let mut prev = f64::NAN;
    let mut last_line = 1;
    while let Some(rec) = imu.next()? {
        let t = rec.t_s;
        last_line = rec.line;
        if t > t1 {
            break;
        }
        if t > t0 && prev.is_finite() && t > prev {
            let dt = t - prev;
            if rates {
                sum_f += rec.a * dt;
                sum_w += rec.b * dt;
            } else {
                sum_f += rec.a;
                sum_w += rec.b;
            }
            sum_dt += dt;
            n += 1;
        }
        prev = t;
    }
    if n == 0 || sum_dt <= 0.0 {
        return Err(imu.parse_err(
            last_line,
            1,
            format!("no IMU sample between t = {t0} s and {t1} s to align on"),
        ));
    }
    let f = sum_f / sum_dt;
    let w = sum_w / sum_dt;
    let mut out = Alignment {
        samples: n,
        mean_specific_force_body_mps2: [f.x, f.y, f.z],
        ..Default::default()
    };
    let mut state = initial.nav_state();
    if level {
        let roll = (-f.y).atan2(-f.z);
        let pitch = f.x.atan2(f.y.hypot(f.z));
        let (_, _, yaw) = state.att_b_to_n.euler_angles();
        state.att_b_to_n = nalgebra::UnitQuaternion::from_euler_angles(roll, pitch, yaw);
        out.roll_pitch_rad = Some([roll, pitch]);
        *initial = InitialState::new(initial.t_s, &state);
    }
    let w_ie_n = ins_errors::earth::earth_rate_ned_radps(state.pos.lat_rad);
    let bias = w - state.att_b_to_n.inverse() * w_ie_n;
    out.gyro_bias_body_radps = [bias.x, bias.y, bias.z];
    Ok(out)
}

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
    /// Two-sided 95 % χ² band of the mean NEES per dof if the compared times were independent
    /// (they are not: consecutive errors are correlated, so this band is only a guide).
    pub nees_band_95: Option<[f64; 2]>,
    /// Mean NIS per degree of freedom over the sighting epochs (Σ NIS / Σ 2·used).
    pub nis_per_dof: Option<f64>,
    /// Degrees of freedom summed over the epochs.
    pub nis_dof: u64,
    /// Two-sided 95 % χ² band of the mean NIS per dof (epochs' innovations are independent for a
    /// consistent filter).
    pub nis_band_95: Option<[f64; 2]>,
    /// The compared times (for plots; not serialised).
    #[serde(skip)]
    pub series: Vec<ErrorSample>,
}

/// What a replay did.
#[derive(Clone, Debug, Default)]
pub struct ReplaySummary {
    /// IMU samples propagated.
    pub imu_samples: u64,
    /// IMU samples at or before the initial time, skipped.
    pub imu_skipped: u64,
    /// Sighting epochs applied.
    pub epochs: u64,
    /// Sightings used.
    pub sightings_used: u64,
    /// Sightings rejected by the gate.
    pub sightings_rejected: u64,
    /// Sightings at or before the initial time, skipped.
    pub sightings_skipped: u64,
    /// True when the sightings were offsets (format 1): meaningful only to the filter that
    /// pointed the device.
    pub offset_sightings: bool,
    /// IMU gaps bridged.
    pub gaps: u64,
    /// The longest gap, s.
    pub longest_gap_s: f64,
    /// Time of the last IMU sample, s.
    pub end_t_s: f64,
    /// The solution after each epoch.
    pub solution: Vec<(f64, NavState)>,
    /// Against the reference, when one was given.
    pub metrics: Option<ReplayMetrics>,
    /// The static alignment, when asked for.
    pub alignment: Option<Alignment>,
    /// The initial state used (after levelling).
    pub initial: Option<InitialState>,
}

/// The next sighting epoch, read ahead.
struct SightingStream {
    path: PathBuf,
    reader: CsvReader,
    pointed: bool,
    pending: Option<Record>,
    offsets: Vec<Sighting>,
    directions: Vec<PointedSighting>,
    last_epoch_s: f64,
}

impl SightingStream {
    fn open(path: &Path) -> Result<Self, SimError> {
        let (mut reader, which) =
            CsvReader::open_any(path, &[SIGHTINGS_HEADER, POINTED_SIGHTINGS_HEADER])?;
        let pending = reader.next()?;
        Ok(Self {
            path: path.to_path_buf(),
            reader,
            pointed: which == 1,
            pending,
            offsets: Vec::new(),
            directions: Vec::new(),
            last_epoch_s: f64::NEG_INFINITY,
        })
    }

    fn next_time(&self) -> Result<Option<f64>, SimError> {
        match &self.pending {
            Some(rec) => self.reader.f64(rec, 0, "t_s").map(Some),
            None => Ok(None),
        }
    }

    /// Reads every row of the next epoch into the buffers; returns (t, first line).
    fn take_epoch(&mut self) -> Result<Option<(f64, usize)>, SimError> {
        let Some(rec) = self.pending.as_ref() else {
            return Ok(None);
        };
        let r = &self.reader;
        let t = r.f64(rec, 0, "t_s")?;
        if t < self.last_epoch_s {
            return Err(r.parse_err(
                rec.line,
                1,
                format!(
                    "epoch t = {t} s is before the previous one ({} s)",
                    self.last_epoch_s
                ),
            ));
        }
        self.last_epoch_s = t;
        let first_line = rec.line;
        self.offsets.clear();
        self.directions.clear();
        while let Some(rec) = self.pending.as_ref() {
            let r = &self.reader;
            if r.f64(rec, 0, "t_s")? != t {
                break;
            }
            let landmark_id = r.u32(rec, 1, "landmark_id")?;
            if self.pointed {
                let name = r.field(rec, 2).trim();
                let Some(frame) = ins_sd_filter::LosFrame::parse(name) else {
                    return Err(r.parse_err(
                        rec.line,
                        rec.starts[2] + 1,
                        format!("field `frame`: `{name}` is not body or ned"),
                    ));
                };
                let los = Vector3::new(
                    r.f64(rec, 3, "los_x")?,
                    r.f64(rec, 4, "los_y")?,
                    r.f64(rec, 5, "los_z")?,
                );
                if los.norm() == 0.0 {
                    return Err(r.parse_err(
                        rec.line,
                        rec.starts[3] + 1,
                        "the line of sight (los_x, los_y, los_z) is zero".into(),
                    ));
                }
                self.directions.push(PointedSighting {
                    landmark_id,
                    frame,
                    los,
                });
            } else {
                self.offsets.push(Sighting {
                    landmark_id,
                    w_m: r.f64(rec, 2, "w_m")?,
                    h_m: r.f64(rec, 3, "h_m")?,
                });
            }
            self.pending = self.reader.next()?;
        }
        Ok(Some((t, first_line)))
    }
}

/// Accumulates [`ReplayMetrics`].
struct MetricsAcc {
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
    nis_sum: f64,
    nis_dof: u64,
    out: ReplayMetrics,
}

impl MetricsAcc {
    fn new(reference: Vec<ReferenceRow>) -> Self {
        let n = reference.len();
        Self {
            reference,
            next: 0,
            cursor: 0,
            max_ref_gap_s: 1.5,
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
            nis_sum: 0.0,
            nis_dof: 0,
            out: ReplayMetrics {
                series: Vec::with_capacity(n),
                ..Default::default()
            },
        }
    }

    /// Compares the filter at its time with the reference, once per reference row passed.
    fn observe(&mut self, filter: &InsSdFilter) {
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

    fn epoch(&mut self, report: &UpdateReport) {
        if let Some(nis) = report.nis {
            self.nis_sum += nis;
            self.nis_dof += 2 * report.used as u64;
        }
    }

    fn finish(mut self) -> ReplayMetrics {
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
            self.out.nees_band_95 = band(dof);
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

/// Mutable state of one replay besides the filter.
struct Run<'a, W: Write> {
    inputs: &'a ReplayInputs,
    out: &'a mut W,
    out_path: &'a Path,
    sightings: Option<SightingStream>,
    metrics: Option<MetricsAcc>,
    summary: ReplaySummary,
    next_output_s: f64,
    tol: f64,
    t0_s: f64,
    mcap: Option<super::InsMcapSink>,
}

impl<W: Write> Run<'_, W> {
    /// After the filter reached a new time: applies the epochs due, writes the row, compares.
    fn after(&mut self, filter: &mut InsSdFilter) -> Result<(), SimError> {
        let now = filter.time_s();
        let mut report = None;
        if let Some(s) = self.sightings.as_mut() {
            while let Some(t) = s.next_time()? {
                if t > now + self.tol {
                    break;
                }
                let Some((t, line)) = s.take_epoch()? else {
                    break;
                };
                if t <= self.t0_s {
                    self.summary.sightings_skipped += (s.offsets.len() + s.directions.len()) as u64;
                    continue;
                }
                let r = if s.pointed {
                    filter.update_pointed(now, &s.directions)
                } else {
                    filter.update(now, &s.offsets)
                }
                .map_err(|source| SimError::LogFilter {
                    path: s.path.clone(),
                    line,
                    source,
                })?;
                self.summary.epochs += 1;
                self.summary.sightings_used += r.used as u64;
                self.summary.sightings_rejected += r.rejected as u64;
                self.summary
                    .solution
                    .push((now, filter.navigation_solution()));
                if let Some(m) = self.metrics.as_mut() {
                    m.epoch(&r);
                }
                report = Some(r);
            }
        }
        let write = match self.inputs.rate {
            SolutionRate::Epochs => report.is_some(),
            SolutionRate::EveryImu => true,
            SolutionRate::Hz(hz) => {
                let due = now + self.tol >= self.next_output_s;
                if due {
                    while self.next_output_s <= now + self.tol {
                        self.next_output_s += 1.0 / hz;
                    }
                }
                due || report.is_some()
            }
        };
        if write {
            write_solution(self.out, now, filter, report.as_ref())
                .map_err(io_err(self.out_path))?;
            if let Some(sink) = self.mcap.as_mut() {
                sink.solution(filter, report.as_ref())?;
            }
        }
        if let Some(m) = self.metrics.as_mut() {
            let before = m.out.series.len();
            m.observe(filter);
            if let (Some(sink), Some(e)) = (self.mcap.as_mut(), m.out.series.get(before)) {
                sink.errors(e)?;
            }
        }
        Ok(())
    }

    /// Time of the next sighting epoch strictly inside (now, t − tol), if any.
    fn epoch_inside(&self, now: f64, t: f64) -> Result<Option<f64>, SimError> {
        let Some(s) = self.sightings.as_ref() else {
            return Ok(None);
        };
        Ok(s.next_time()?
            .filter(|&te| te > now + self.tol && te < t - self.tol))
    }
}

/// Replays logs through the online filter, writing the solution CSV to `out` (module
/// documentation for the time handling).
///
/// # Errors
/// [`SimError`] naming the file, line and column of the first bad record, the line whose record
/// the filter rejected, or the IMU line after a gap longer than `max_gap_s`.
pub fn replay(
    inputs: &ReplayInputs,
    out: &mut impl Write,
    out_path: &Path,
) -> Result<ReplaySummary, SimError> {
    let (table, sightings) = match &inputs.sightings {
        Some((log, landmarks)) => (read_landmarks(landmarks)?, Some(SightingStream::open(log)?)),
        None => (
            ins_sd_filter::LandmarkTable::new(&[]).map_err(|source| SimError::LogFilter {
                path: inputs.imu.clone(),
                line: 0,
                source,
            })?,
            None,
        ),
    };
    let mut initial = inputs.initial;
    let alignment = if inputs.align_s > 0.0 {
        Some(align_at_rest(
            &inputs.imu,
            inputs.imu_topic.as_deref(),
            &mut initial,
            inputs.align_s,
            inputs.level,
        )?)
    } else {
        None
    };
    let init = &initial;
    let filter_err0 = |source| SimError::LogFilter {
        path: inputs.imu.clone(),
        line: 0,
        source,
    };
    let mut filter =
        InsSdFilter::new(inputs.config, table, init.nav_state(), init.t_s).map_err(filter_err0)?;
    if let Some(a) = &alignment {
        filter
            .set_sensor_corrections(&Vector3::zeros(), &Vector3::from(a.gyro_bias_body_radps))
            .map_err(filter_err0)?;
    }
    writeln!(out, "{SOLUTION_HEADER}").map_err(io_err(out_path))?;
    let mut imu = ImuStream::open(&inputs.imu, inputs.imu_topic.as_deref())?;
    let rates = imu.rates();
    let imu_path = imu.path();
    let step = inputs.config.imu_step_s;
    let mut run = Run {
        inputs,
        out,
        out_path,
        summary: ReplaySummary {
            offset_sightings: sightings.as_ref().is_some_and(|s| !s.pointed),
            ..Default::default()
        },
        sightings,
        metrics: inputs.reference.clone().map(MetricsAcc::new),
        next_output_s: init.t_s,
        t0_s: init.t_s,
        mcap: match &inputs.mcap_out {
            Some(p) => Some(super::InsMcapSink::create(p)?),
            None => None,
        },
        tol: inputs.config.timestamp_tolerance_s.max(1e-9),
    };
    run.after(&mut filter)?;
    while let Some(rec) = imu.next()? {
        let t = rec.t_s;
        if t <= init.t_s {
            run.summary.imu_skipped += 1;
            continue;
        }
        // (specific force or Δv, angular rate or Δθ)
        let (a, b) = (rec.a, rec.b);
        let now = filter.time_s();
        let dt = t - now;
        if dt > inputs.max_gap_s {
            return Err(imu.parse_err(
                rec.line,
                1,
                format!(
                    "IMU gap of {dt} s after t = {now} s is longer than the {} s bridged (max_gap_s)",
                    inputs.max_gap_s
                ),
            ));
        }
        let gap = dt > GAP_FACTOR * step;
        if gap {
            run.summary.gaps += 1;
            run.summary.longest_gap_s = run.summary.longest_gap_s.max(dt);
        }
        let filter_err = |source| SimError::LogFilter {
            path: imu_path.clone(),
            line: rec.line,
            source,
        };
        if !gap && run.epoch_inside(now, t)?.is_none() {
            // One step, as logged.
            if rates {
                filter.propagate_rates(t, &a, &b).map_err(filter_err)?;
            } else {
                filter.propagate(t, &a, &b).map_err(filter_err)?;
            }
            run.summary.imu_samples += 1;
            run.after(&mut filter)?;
            continue;
        }
        // Cut at the epochs inside the sample and, in a gap, every nominal step; the sample's
        // mean rates are held across the cuts.
        let (f, w) = if rates {
            (a, b)
        } else if dt > 0.0 {
            (a / dt, b / dt)
        } else {
            (a, b) // t ≤ now: the filter refuses it below
        };
        loop {
            let now = filter.time_s();
            let mut cut = t;
            if gap {
                cut = cut.min(now + step);
            }
            if let Some(te) = run.epoch_inside(now, t)? {
                cut = cut.min(te);
            }
            if t - cut <= run.tol {
                cut = t;
            }
            filter.propagate_rates(cut, &f, &w).map_err(filter_err)?;
            if cut >= t {
                break;
            }
            run.after(&mut filter)?;
        }
        run.summary.imu_samples += 1;
        run.after(&mut filter)?;
    }
    run.summary.end_t_s = filter.time_s();
    run.out.flush().map_err(io_err(out_path))?;
    if let Some(sink) = run.mcap.take() {
        sink.finish()?;
    }
    let mut summary = run.summary;
    summary.metrics = run.metrics.map(MetricsAcc::finish);
    summary.alignment = alignment;
    summary.initial = Some(initial);
    Ok(summary)
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
