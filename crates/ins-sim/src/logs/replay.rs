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
//! when longer than `max_gap_s`. The first sample after the start is bridged the same way when
//! it is that far from the start, but that is the **lead-in** ([`ReplaySummary::lead_in_s`],
//! e.g. a reference whose first row, the default start, precedes the IMU log), not a gap.
//!
//! ## Inputs that cannot be right
//!
//! The IMU log, the reference and the sightings must overlap in time: a replay is refused
//! ([`SimError::InputSpans`], naming each file with its first and last stamp) when no IMU
//! sample follows the start, when the first one after the start comes later than `max_gap_s`,
//! when no reference row falls inside the replay (after the start, up to the IMU's last
//! sample), and when a filter with sightings used none of them, unless
//! [`ReplayInputs::allow_unaided`]. Every input row not used is counted ([`UnusedRows`]).

use std::io::Write;
use std::path::{Path, PathBuf};

use ins_errors::strapdown::NavState;
use ins_sd_filter::{InsSdFilter, InsSdFilterConfig, PointedSighting, Sighting};
use nalgebra::Vector3;

use super::align::{AlignLimits, Alignment, align_at_rest};
use super::csv::{CsvReader, Record, io_err};
use super::imu::ImuLog;
use super::metrics::{MetricsAcc, ReplayMetrics};
use super::read::{InitialState, read_landmarks};
use super::reference::ReferenceRow;
use super::spans::{InputSpan, UnusedRows};
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
    /// Reference trajectory (the file, named in errors, and its rows) for [`ReplayMetrics`].
    pub reference: Option<(PathBuf, Vec<ReferenceRow>)>,
    /// Static alignment: the vehicle is at rest for this long after the initial time, s (0:
    /// none). The rest is checked against `align_limits`; the mean angular rate over it, less
    /// the Earth rate, is the initial gyro bias ([`align_at_rest`]).
    pub align_s: f64,
    /// The rest check of the static alignment.
    pub align_limits: AlignLimits,
    /// A filter with sightings that used none of them is an error unless this is set.
    pub allow_unaided: bool,
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
    /// Start of the replay (the initial state's time), s.
    pub start_t_s: f64,
    /// The input files and their time spans (IMU log, reference, sightings).
    pub spans: Vec<InputSpan>,
    /// Input rows not used, by reason.
    pub unused: UnusedRows,
    /// Sighting epochs applied.
    pub epochs: u64,
    /// Sightings used.
    pub sightings_used: u64,
    /// Sightings rejected by the gate.
    pub sightings_rejected: u64,
    /// True when the sightings were offsets (format 1): meaningful only to the filter that
    /// pointed the device.
    pub offset_sightings: bool,
    /// Time from the start to the first IMU sample propagated, s (bridged in nominal steps
    /// when longer than [`GAP_FACTOR`] of them, but not an IMU gap: e.g. a reference whose
    /// first row, the default start, precedes the IMU log).
    pub lead_in_s: f64,
    /// IMU gaps bridged (between two IMU samples).
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
    first_t_s: Option<f64>,
    rows: u64,
}

impl SightingStream {
    fn open(path: &Path) -> Result<Self, SimError> {
        let (mut reader, which) =
            CsvReader::open_any(path, &[SIGHTINGS_HEADER, POINTED_SIGHTINGS_HEADER])?;
        let pending = reader.next()?;
        let mut stream = Self {
            path: path.to_path_buf(),
            reader,
            pointed: which == 1,
            pending,
            offsets: Vec::new(),
            directions: Vec::new(),
            last_epoch_s: f64::NEG_INFINITY,
            first_t_s: None,
            rows: 0,
        };
        stream.first_t_s = stream.next_time()?;
        Ok(stream)
    }

    /// Reads the epochs left (checked as any), returns their rows.
    fn drain(&mut self) -> Result<u64, SimError> {
        let mut rows = 0;
        while self.take_epoch()?.is_some() {
            rows += (self.offsets.len() + self.directions.len()) as u64;
        }
        Ok(rows)
    }

    fn span(&self) -> InputSpan {
        InputSpan {
            role: "sightings",
            path: self.path.clone(),
            span_s: self.first_t_s.map(|a| [a, self.last_epoch_s]),
            rows: self.rows,
        }
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
            self.rows += 1;
            self.pending = self.reader.next()?;
        }
        Ok(Some((t, first_line)))
    }
}

/// Mutable state of one replay besides the filter.
struct Run<'a, 't, W: Write> {
    rate: SolutionRate,
    out: &'a mut W,
    out_path: &'a Path,
    sightings: Option<SightingStream>,
    metrics: Option<MetricsAcc>,
    summary: ReplaySummary,
    next_output_s: f64,
    tol: f64,
    t0_s: f64,
    sink: super::mcap_out::InsSink<'t>,
}

impl<W: Write> Run<'_, '_, W> {
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
                    self.summary.unused.sightings_before_start +=
                        (s.offsets.len() + s.directions.len()) as u64;
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
            self.sink.solution(filter, report.as_ref())?;
        }
        if let Some(m) = self.metrics.as_mut() {
            let before = m.out.series.len();
            m.observe(filter);
            if let Some(e) = m.out.series.get(before) {
                self.sink.errors(e)?;
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
    replay_with_tap(inputs, out, out_path, None)
}

/// [`replay`], handing every message of the `--mcap-out` channels ([`super::ins_channels`]) to
/// `tap` as well (a live viewer), which also paces the replay and can end it early (then the
/// replay ends as if its IMU log ended there).
///
/// # Errors
/// As [`replay`].
pub fn replay_with_tap(
    inputs: ReplayInputs,
    out: &mut impl Write,
    out_path: &Path,
    tap: Option<&mut dyn super::ReplayTap>,
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
        align_limits,
        allow_unaided,
        level,
        mcap_out,
    } = inputs;
    let (reference_path, reference) = reference.unzip();
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
        Some(align_at_rest(
            &mut imu,
            &mut initial,
            align_s,
            level,
            &align_limits,
            reference.as_deref(),
        )?)
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
    let imu_first_s = imu.peek(0)?.map(|r| r.t_s);
    let (mut imu_last_s, mut imu_rows) = (f64::NAN, 0u64);
    let mut run = Run {
        rate,
        out,
        out_path,
        summary: ReplaySummary {
            start_t_s: init.t_s,
            offset_sightings: sightings.as_ref().is_some_and(|s| !s.pointed),
            ..Default::default()
        },
        sightings,
        metrics: reference.map(MetricsAcc::new),
        next_output_s: init.t_s,
        t0_s: init.t_s,
        sink: super::mcap_out::InsSink::new(
            match &mcap_out {
                Some(p) => Some(super::InsMcapSink::create(p)?),
                None => None,
            },
            tap,
        ),
        tol: config.timestamp_tolerance_s.max(1e-9),
    };
    run.after(&mut filter)?;
    while let Some(rec) = imu.next()? {
        let t = rec.t_s;
        if let Some(tap) = run.sink.tap() {
            if tap.stop() {
                break;
            }
            tap.pace(t);
        }
        imu_rows += 1;
        imu_last_s = t;
        if t <= init.t_s {
            run.summary.unused.imu_before_start += 1;
            continue;
        }
        // (specific force or Δv, angular rate or Δθ)
        let (a, b) = (rec.a, rec.b);
        let now = filter.time_s();
        let dt = t - now;
        if dt > max_gap_s && run.summary.imu_samples == 0 {
            // The IMU starts (or resumes) long after the start: the logs are on other clocks.
            while let Some(r) = imu.next()? {
                imu_rows += 1;
                imu_last_s = r.t_s;
            }
            if let Some(s) = run.sightings.as_mut() {
                run.summary.unused.sightings_after_end = s.drain()?;
            }
            let problem = format!(
                "the inputs do not overlap in time: the first IMU sample after the start of the replay (t = {:.3} s) comes {dt:.3} s later, more than the {max_gap_s} s bridged (max_gap_s)",
                init.t_s
            );
            let spans = input_spans(
                (&imu_path, imu_first_s, imu_last_s, imu_rows),
                reference_path
                    .as_deref()
                    .zip(run.metrics.as_ref().map(MetricsAcc::reference)),
                run.sightings.as_ref(),
            );
            return Err(SimError::InputSpans { problem, spans });
        }
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
        // Bridged in nominal steps when longer than GAP_FACTOR of them; counted as a gap only
        // between two samples: the first sample's distance from the start is the lead-in.
        let gap = dt > GAP_FACTOR * step;
        if run.summary.imu_samples == 0 {
            run.summary.lead_in_s = dt;
        } else if gap {
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
    check_overlap(
        &mut run,
        (&imu_path, imu_first_s, imu_last_s, imu_rows),
        reference_path.as_deref(),
        allow_unaided,
    )?;
    let mut summary = run.summary;
    run.sink.finish()?;
    summary.metrics = run.metrics.map(MetricsAcc::finish);
    summary.alignment = alignment;
    summary.initial = Some(initial);
    Ok(summary)
}

/// The spans of the inputs: the IMU log (path, first and last stamp, rows), the reference
/// (path and rows) and the sightings read so far.
fn input_spans(
    (imu_path, first_s, last_s, rows): (&Path, Option<f64>, f64, u64),
    reference: Option<(&Path, &[ReferenceRow])>,
    sightings: Option<&SightingStream>,
) -> Vec<InputSpan> {
    let mut spans = vec![InputSpan {
        role: "IMU log",
        path: imu_path.to_path_buf(),
        span_s: first_s.map(|a| [a, last_s]),
        rows,
    }];
    if let Some((path, r)) = reference {
        spans.push(InputSpan {
            role: "reference",
            path: path.to_path_buf(),
            span_s: r.first().zip(r.last()).map(|(a, b)| [a.t_s, b.t_s]),
            rows: r.len() as u64,
        });
    }
    if let Some(s) = sightings {
        spans.push(s.span());
    }
    spans
}

/// After the IMU's last sample: counts the sightings and reference rows not used, records the
/// spans, and refuses inputs that do not overlap (module documentation).
fn check_overlap<W: Write>(
    run: &mut Run<'_, '_, W>,
    imu: (&Path, Option<f64>, f64, u64),
    reference_path: Option<&Path>,
    allow_unaided: bool,
) -> Result<(), SimError> {
    let (t0, end) = (run.t0_s, run.summary.end_t_s);
    if let Some(s) = run.sightings.as_mut() {
        run.summary.unused.sightings_after_end = s.drain()?;
    }
    let mut reference_inside = 0;
    if let Some(m) = run.metrics.as_ref() {
        for r in m.reference() {
            if r.t_s < t0 {
                run.summary.unused.reference_before_start += 1;
            } else if r.t_s > end {
                run.summary.unused.reference_after_end += 1;
            } else if r.t_s > t0 {
                reference_inside += 1;
            }
        }
    }
    let reference = reference_path.zip(run.metrics.as_ref().map(MetricsAcc::reference));
    run.summary.spans = input_spans(imu, reference, run.sightings.as_ref());
    let s = &run.summary;
    let problem = if s.imu_samples == 0 {
        format!(
            "the inputs do not overlap in time: no IMU sample after the start of the replay at t = {t0:.3} s"
        )
    } else if reference.is_some() && reference_inside == 0 {
        format!(
            "the inputs do not overlap in time: no reference row inside the replay, t = {t0:.3}–{end:.3} s"
        )
    } else if run.sightings.is_some() && s.sightings_used == 0 && !allow_unaided {
        format!(
            "the filter used no sighting ({} epochs applied, {} sightings rejected by the gate; {} sightings at or before the start at t = {t0:.3} s, {} after the IMU's last sample at t = {end:.3} s): an unaided run is refused unless allowed (allow_unaided; nav-app ins --allow-unaided)",
            s.epochs,
            s.sightings_rejected,
            s.unused.sightings_before_start,
            s.unused.sightings_after_end
        )
    } else {
        return Ok(());
    };
    Err(SimError::InputSpans {
        problem,
        spans: s.spans.clone(),
    })
}
