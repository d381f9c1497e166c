//! Replaying logs through the online filter ([`replay`]), with the errors against a reference
//! trajectory computed on the way ([`super::ReplayMetrics`], module `metrics`) after an optional
//! static alignment ([`super::align_at_rest`]).
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

use ins_errors::strapdown::NavState;
use ins_sd_filter::{InsSdFilter, InsSdFilterConfig, PointedSighting, Sighting};
use nalgebra::Vector3;

use super::align::{Alignment, align_at_rest};
use super::csv::{CsvReader, Record, io_err};
use super::imu::ImuLog;
use super::metrics::{MetricsAcc, ReplayMetrics};
use super::read::{InitialState, read_landmarks};
use super::reference::ReferenceRow;
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

/// The inputs and settings of a replay (consumed by it: the IMU log is read once).
#[derive(Debug)]
pub struct ReplayInputs {
    /// IMU log (CSV increments or rates, declared by its header; or a ROS 2 bag, `.mcap`, with
    /// its `sensor_msgs/msg/Imu` topic), read once: samples already read ahead (the nominal step
    /// of [`super::ReplayRequest::inputs`]) are replayed from memory.
    pub imu: ImuLog,
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

/// Mutable state of one replay besides the filter.
struct Run<'a, W: Write> {
    rate: SolutionRate,
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
        let write = match self.rate {
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
    inputs: ReplayInputs,
    out: &mut impl Write,
    out_path: &Path,
) -> Result<ReplaySummary, SimError> {
    let ReplayInputs {
        mut imu,
        sightings,
        initial,
        config,
        max_gap_s,
        rate,
        reference,
        align_s,
        level,
        mcap_out,
    } = inputs;
    let (table, sightings) = match &sightings {
        Some((log, landmarks)) => (read_landmarks(landmarks)?, Some(SightingStream::open(log)?)),
        None => (
            ins_sd_filter::LandmarkTable::new(&[]).map_err(|source| SimError::LogFilter {
                path: imu.path().to_path_buf(),
                line: 0,
                source,
            })?,
            None,
        ),
    };
    let mut initial = initial;
    let alignment = if align_s > 0.0 {
        Some(align_at_rest(&mut imu, &mut initial, align_s, level)?)
    } else {
        None
    };
    let init = &initial;
    let imu_path = imu.path().to_path_buf();
    let filter_err0 = |source| SimError::LogFilter {
        path: imu_path.clone(),
        line: 0,
        source,
    };
    let mut filter =
        InsSdFilter::new(config, table, init.nav_state(), init.t_s).map_err(filter_err0)?;
    if let Some(a) = &alignment {
        filter
            .set_sensor_corrections(&Vector3::zeros(), &Vector3::from(a.gyro_bias_body_radps))
            .map_err(filter_err0)?;
    }
    writeln!(out, "{SOLUTION_HEADER}").map_err(io_err(out_path))?;
    let rates = imu.rates()?;
    let step = config.imu_step_s;
    let mut run = Run {
        rate,
        out,
        out_path,
        summary: ReplaySummary {
            offset_sightings: sightings.as_ref().is_some_and(|s| !s.pointed),
            ..Default::default()
        },
        sightings,
        metrics: reference.map(MetricsAcc::new),
        next_output_s: init.t_s,
        t0_s: init.t_s,
        mcap: match &mcap_out {
            Some(p) => Some(super::InsMcapSink::create(p)?),
            None => None,
        },
        tol: config.timestamp_tolerance_s.max(1e-9),
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
        if dt > max_gap_s {
            return Err(imu.parse_err(
                rec.line,
                1,
                format!(
                    "IMU gap of {dt} s after t = {now} s is longer than the {} s bridged (max_gap_s)",
                    max_gap_s
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
