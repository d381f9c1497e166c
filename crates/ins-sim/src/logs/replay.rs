//! Replaying logs through the online filter ([`replay`]) and comparing a solution with the truth
//! ([`compare_with_truth`]).

use std::io::Write;
use std::path::{Path, PathBuf};

use ins_errors::error_model;
use ins_errors::strapdown::NavState;
use ins_sd_filter::{InsSdFilter, InsSdFilterConfig, Sighting};
use nalgebra::Vector3;

use super::read::{CsvReader, Record, io_err, read_initial, read_landmarks, read_truth};
use super::write::write_solution;
use super::{IMU_HEADER, SIGHTINGS_HEADER, SOLUTION_HEADER};
use crate::SimError;

/// The log files and filter settings of a replay.
#[derive(Clone, Debug)]
pub struct ReplayInputs {
    /// IMU log.
    pub imu: PathBuf,
    /// Sightings log.
    pub sightings: PathBuf,
    /// Landmark table.
    pub landmarks: PathBuf,
    /// Initial state.
    pub initial: PathBuf,
    /// Filter settings.
    pub config: InsSdFilterConfig,
}

/// What a replay did.
#[derive(Clone, Debug, Default)]
pub struct ReplaySummary {
    /// IMU samples propagated.
    pub imu_samples: u64,
    /// Sighting epochs applied.
    pub epochs: u64,
    /// Sightings used.
    pub sightings_used: u64,
    /// Sightings rejected by the gate.
    pub sightings_rejected: u64,
    /// The solution after each epoch (as written).
    pub solution: Vec<(f64, NavState)>,
}

/// Replays logs through the online filter, writing the solution CSV to `out`.
///
/// # Errors
/// [`SimError`] naming the file, line and column of the first bad record, or the line whose
/// record the filter rejected.
pub fn replay(
    inputs: &ReplayInputs,
    out: &mut impl Write,
    out_path: &Path,
) -> Result<ReplaySummary, SimError> {
    let table = read_landmarks(&inputs.landmarks)?;
    let init = read_initial(&inputs.initial)?;
    let mut filter =
        InsSdFilter::new(inputs.config, table, init.nav_state(), init.t_s).map_err(|source| {
            SimError::LogFilter {
                path: inputs.initial.clone(),
                line: 1,
                source,
            }
        })?;
    let wio = io_err(out_path);
    writeln!(out, "{SOLUTION_HEADER}").map_err(&wio)?;
    let mut imu = CsvReader::open(&inputs.imu, IMU_HEADER)?;
    let mut sr = CsvReader::open(&inputs.sightings, SIGHTINGS_HEADER)?;
    let tol = inputs.config.timestamp_tolerance_s.max(1e-9);
    let mut summary = ReplaySummary::default();
    // The next sighting record (read ahead) and the current epoch's sightings.
    let mut pending = sr.next()?;
    let mut epoch: Vec<Sighting> = Vec::new();
    let mut last_epoch_t = f64::NEG_INFINITY;
    let mut flush = |filter: &mut InsSdFilter,
                     pending: &mut Option<Record>,
                     summary: &mut ReplaySummary,
                     out: &mut dyn Write|
     -> Result<(), SimError> {
        loop {
            let Some(rec) = pending.as_ref() else {
                return Ok(());
            };
            let t = sr.f64(rec, 0, "t_s")?;
            if t > filter.time_s() + tol {
                return Ok(());
            }
            if t < last_epoch_t {
                return Err(sr.parse_err(
                    rec.line,
                    1,
                    format!("epoch t = {t} s is before the previous one ({last_epoch_t} s)"),
                ));
            }
            last_epoch_t = t;
            // Gather every row with this time stamp.
            epoch.clear();
            let first_line = rec.line;
            while let Some(rec) = pending.as_ref() {
                if sr.f64(rec, 0, "t_s")? != t {
                    break;
                }
                epoch.push(Sighting {
                    landmark_id: sr.u32(rec, 1, "landmark_id")?,
                    w_m: sr.f64(rec, 2, "w_m")?,
                    h_m: sr.f64(rec, 3, "h_m")?,
                });
                *pending = sr.next()?;
            }
            let now = filter.time_s();
            let report = filter
                .update(now, &epoch)
                .map_err(|source| SimError::LogFilter {
                    path: inputs.sightings.clone(),
                    line: first_line,
                    source,
                })?;
            summary.epochs += 1;
            summary.sightings_used += report.used as u64;
            summary.sightings_rejected += report.rejected as u64;
            write_solution(out, now, filter).map_err(io_err(out_path))?;
            summary.solution.push((now, filter.navigation_solution()));
        }
    };
    flush(&mut filter, &mut pending, &mut summary, out)?;
    let names: Vec<&str> = IMU_HEADER.split(',').collect();
    while let Some(rec) = imu.next()? {
        let mut v = [0.0; 7];
        for (i, x) in v.iter_mut().enumerate() {
            *x = imu.f64(&rec, i, names[i])?;
        }
        filter
            .propagate(
                v[0],
                &Vector3::new(v[1], v[2], v[3]),
                &Vector3::new(v[4], v[5], v[6]),
            )
            .map_err(|source| SimError::LogFilter {
                path: inputs.imu.clone(),
                line: rec.line,
                source,
            })?;
        summary.imu_samples += 1;
        flush(&mut filter, &mut pending, &mut summary, out)?;
    }
    out.flush().map_err(io_err(out_path))?;
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
