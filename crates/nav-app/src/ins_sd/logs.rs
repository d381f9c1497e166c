//! Log formats of the INS/SD filter, export of a simulated run, and replay through the online
//! filter (`nav-app ins`).
//!
//! ## Files
//!
//! All CSV files are comma-separated with the header line below (checked), one record per line;
//! blank lines and lines starting with `#` are skipped. Floats are written with Rust's `{:e}`
//! (shortest representation that reads back to the same `f64`). Times are seconds on one time
//! base shared by all files.
//!
//! | file | header | rows |
//! |---|---|---|
//! | IMU | `t_s,dv_x_mps,dv_y_mps,dv_z_mps,dtheta_x_rad,dtheta_y_rad,dtheta_z_rad` | one per IMU sample: time stamp of the end of the sample interval, then the integrated specific force Δv = ∫f̃ dt (m/s) and angle Δθ = ∫ω̃_ib dt (rad) over (previous t, t], body axes FRD; strictly increasing t |
//! | sightings | `t_s,landmark_id,w_m,h_m` | one per sighting: epoch time, landmark id (integer, in the landmark table), offsets w (image right) and h (image down) of the landmark from the image centre, m at the landmark, with the camera pointed by the INS's own position and attitude; the rows of one epoch share t; epochs non-decreasing |
//! | truth | `t_s,lat_rad,lon_rad,alt_m,vel_n_mps,vel_e_mps,vel_d_mps,q_w,q_x,q_y,q_z` | true navigation state (WGS-84 geodetic, NED velocity, body→NED quaternion) at any times (the simulator writes 1 Hz) |
//! | solution (output) | the truth header plus `,sigma_n_m,sigma_e_m,sigma_d_m,nis,used,rejected` | the filter's navigation solution after each sighting epoch, its 1σ position uncertainty (NED, m), the epoch's NIS (empty when no sighting was used), sightings used and rejected by the gate |
//!
//! The landmark table is TOML, one `[[landmarks]]` table per landmark with `id` (integer),
//! `lat_deg`, `lon_deg` (WGS-84, degrees) and `alt_m` (above the ellipsoid, m). The INS's
//! initial state is TOML too: `t_s`, `lat_rad`, `lon_rad`, `alt_m`, `vel_ned_mps = [n, e, d]`,
//! `att_quat_wxyz = [w, x, y, z]` (body FRD → NED). The filter's settings come from a scenario
//! file (`[filter]`, `[sighting] update_period_s`, `[trajectory] step_s`; `configs/paper.toml`).
//!
//! ## Replay
//!
//! [`replay`] reads the IMU log sample by sample and hands each to
//! [`ins_sd_filter::InsSdFilter::propagate`]; a sighting epoch is applied at the first IMU time
//! at or after its time stamp (within the filter's time-stamp tolerance it is the same time).
//! Every malformed field, short line or filter rejection is an error naming the file, the line
//! (1-based) and the column (1-based start of the field).
//!
//! ## Export
//!
//! [`export_run`] simulates one run of a scenario (exactly [`super::run`]'s run) and writes the
//! logs its filter saw, the truth, and the solution the simulated filter computed. Replaying
//! the logs reproduces that solution to round-off (`tests/ins_sd_replay.rs`: the IMU samples go
//! through Δv/Δt once more).

use std::fs::File;
use std::io::{BufRead, BufReader, BufWriter, Write};
use std::path::{Path, PathBuf};

use ins_errors::earth::Geodetic;
use ins_errors::error_model;
use ins_errors::strapdown::NavState;
use ins_sd_filter::{
    FilterError, InsSdFilter, InsSdFilterConfig, LandmarkEntry, LandmarkTable, Sighting,
};
use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use serde::{Deserialize, Serialize};
use toml_config::TomlDoc;

use super::engine::{self, RunObserver};
use super::{Mode, RunError, RunOutcome, Sample, Scenario};

/// Header of the IMU log.
pub const IMU_HEADER: &str =
    "t_s,dv_x_mps,dv_y_mps,dv_z_mps,dtheta_x_rad,dtheta_y_rad,dtheta_z_rad";
/// Header of the sightings log.
pub const SIGHTINGS_HEADER: &str = "t_s,landmark_id,w_m,h_m";
/// Header of the truth log (and the first columns of the solution).
pub const TRUTH_HEADER: &str =
    "t_s,lat_rad,lon_rad,alt_m,vel_n_mps,vel_e_mps,vel_d_mps,q_w,q_x,q_y,q_z";
/// Header of the solution written by the replay and by the export.
pub const SOLUTION_HEADER: &str = "t_s,lat_rad,lon_rad,alt_m,vel_n_mps,vel_e_mps,vel_d_mps,q_w,q_x,q_y,q_z,sigma_n_m,sigma_e_m,sigma_d_m,nis,used,rejected";

/// File names [`export_run`] writes in its directory.
pub mod names {
    /// IMU log.
    pub const IMU: &str = "imu.csv";
    /// Sightings log.
    pub const SIGHTINGS: &str = "sightings.csv";
    /// Truth log.
    pub const TRUTH: &str = "truth.csv";
    /// Landmark table.
    pub const LANDMARKS: &str = "landmarks.toml";
    /// Initial state.
    pub const INITIAL: &str = "initial.toml";
    /// The scenario the run was simulated with (filter settings for the replay).
    pub const SCENARIO: &str = "scenario.toml";
    /// The simulated filter's own solution.
    pub const SOLUTION: &str = "solution_simulated.csv";
}

/// Errors of reading, writing and replaying logs; each names the file and, for content, the
/// line and column (both 1-based).
#[derive(Debug, thiserror::Error)]
pub enum LogError {
    /// The file could not be opened, read or written.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// A malformed, missing or out-of-range field.
    #[error("{}:{line}:{column}: {message}", path.display())]
    Parse {
        /// The file.
        path: PathBuf,
        /// Line, 1-based.
        line: usize,
        /// Column of the field's first character, 1-based.
        column: usize,
        /// What is wrong.
        message: String,
    },
    /// The filter rejected the record of this line.
    #[error("{}:{line}: {source}", path.display())]
    Filter {
        /// The file.
        path: PathBuf,
        /// Line, 1-based.
        line: usize,
        /// The filter's error.
        source: FilterError,
    },
    /// The simulation of an exported run failed.
    #[error("simulating the run to export: {0}")]
    Run(#[from] RunError),
}

fn io_err(path: &Path) -> impl Fn(std::io::Error) -> LogError + '_ {
    move |source| LogError::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// One parsed CSV line: the text and the start of each field.
struct Record {
    text: String,
    starts: Vec<usize>,
    line: usize,
}

/// A CSV file read line by line with its header checked.
struct CsvReader {
    path: PathBuf,
    lines: std::io::Lines<BufReader<File>>,
    line: usize,
    fields: usize,
}

impl CsvReader {
    fn open(path: &Path, header: &str) -> Result<Self, LogError> {
        let file = File::open(path).map_err(io_err(path))?;
        let mut r = Self {
            path: path.to_path_buf(),
            lines: BufReader::new(file).lines(),
            line: 0,
            fields: header.split(',').count(),
        };
        let Some(first) = r.next_raw()? else {
            return Err(r.parse_err(1, 1, format!("empty file, expected the header `{header}`")));
        };
        for ((got, want), start) in first
            .text
            .split(',')
            .zip(header.split(','))
            .zip(&first.starts)
        {
            if got.trim() != want {
                return Err(r.parse_err(
                    first.line,
                    start + 1,
                    format!(
                        "header field `{}`, expected `{want}` (header `{header}`)",
                        got.trim()
                    ),
                ));
            }
        }
        if first.starts.len() != r.fields {
            return Err(r.parse_err(
                first.line,
                first.text.len() + 1,
                format!(
                    "header has {} fields, expected `{header}`",
                    first.starts.len()
                ),
            ));
        }
        Ok(r)
    }

    fn parse_err(&self, line: usize, column: usize, message: String) -> LogError {
        LogError::Parse {
            path: self.path.clone(),
            line,
            column,
            message,
        }
    }

    /// Next non-blank, non-comment line, split.
    fn next_raw(&mut self) -> Result<Option<Record>, LogError> {
        for text in self.lines.by_ref() {
            self.line += 1;
            let text = text.map_err(|source| LogError::Io {
                path: self.path.clone(),
                source,
            })?;
            let t = text.trim_end_matches('\r');
            if t.trim().is_empty() || t.trim_start().starts_with('#') {
                continue;
            }
            let mut starts = vec![0];
            starts.extend(t.match_indices(',').map(|(i, _)| i + 1));
            return Ok(Some(Record {
                text: t.to_string(),
                starts,
                line: self.line,
            }));
        }
        Ok(None)
    }

    /// Next data record, with exactly the header's number of fields.
    fn next(&mut self) -> Result<Option<Record>, LogError> {
        let Some(rec) = self.next_raw()? else {
            return Ok(None);
        };
        if rec.starts.len() != self.fields {
            return Err(self.parse_err(
                rec.line,
                rec.text.len() + 1,
                format!(
                    "expected {} fields, found {} (truncated or malformed line)",
                    self.fields,
                    rec.starts.len()
                ),
            ));
        }
        Ok(Some(rec))
    }

    fn field<'a>(&self, rec: &'a Record, i: usize) -> &'a str {
        let end = rec.starts.get(i + 1).map_or(rec.text.len(), |e| e - 1);
        &rec.text[rec.starts[i]..end]
    }

    fn f64(&self, rec: &Record, i: usize, name: &str) -> Result<f64, LogError> {
        let s = self.field(rec, i).trim();
        match s.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            _ => Err(self.parse_err(
                rec.line,
                rec.starts[i] + 1,
                format!("field `{name}`: `{s}` is not a finite number"),
            )),
        }
    }

    fn opt_f64(&self, rec: &Record, i: usize, name: &str) -> Result<Option<f64>, LogError> {
        if self.field(rec, i).trim().is_empty() {
            Ok(None)
        } else {
            self.f64(rec, i, name).map(Some)
        }
    }

    fn u32(&self, rec: &Record, i: usize, name: &str) -> Result<u32, LogError> {
        let s = self.field(rec, i).trim();
        s.parse::<u32>().map_err(|_| {
            self.parse_err(
                rec.line,
                rec.starts[i] + 1,
                format!("field `{name}`: `{s}` is not a non-negative integer"),
            )
        })
    }
}

/// The initial navigation state file.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InitialState {
    /// Time of the state, s (the IMU log starts after it).
    pub t_s: f64,
    /// Geodetic latitude, rad.
    pub lat_rad: f64,
    /// Longitude, rad.
    pub lon_rad: f64,
    /// Height above the WGS-84 ellipsoid, m.
    pub alt_m: f64,
    /// NED velocity, m/s.
    pub vel_ned_mps: [f64; 3],
    /// Attitude body FRD → NED as a unit quaternion (w, x, y, z).
    pub att_quat_wxyz: [f64; 4],
}

impl InitialState {
    /// From a navigation state at time `t_s`.
    pub fn new(t_s: f64, s: &NavState) -> Self {
        let q = s.att_b_to_n.quaternion();
        Self {
            t_s,
            lat_rad: s.pos.lat_rad,
            lon_rad: s.pos.lon_rad,
            alt_m: s.pos.alt_m,
            vel_ned_mps: [s.vel_ned_mps.x, s.vel_ned_mps.y, s.vel_ned_mps.z],
            att_quat_wxyz: [q.w, q.i, q.j, q.k],
        }
    }

    /// The navigation state.
    pub fn nav_state(&self) -> NavState {
        let [w, x, y, z] = self.att_quat_wxyz;
        NavState {
            pos: Geodetic {
                lat_rad: self.lat_rad,
                lon_rad: self.lon_rad,
                alt_m: self.alt_m,
            },
            vel_ned_mps: Vector3::from(self.vel_ned_mps),
            att_b_to_n: UnitQuaternion::new_unchecked(Quaternion::new(w, x, y, z)),
        }
    }
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct LandmarkFile {
    landmarks: Vec<LandmarkEntry>,
}

fn toml_err(path: &Path, e: toml_config::TomlError) -> LogError {
    LogError::Parse {
        path: path.to_path_buf(),
        line: e.line.unwrap_or(1),
        column: e.column.unwrap_or(1),
        message: e.message,
    }
}

/// Reads a landmark table file.
///
/// # Errors
/// [`LogError::Io`], [`LogError::Parse`] (TOML errors with their line and column, through the
/// workspace's one TOML loader `toml-config`; a duplicate id or a bad coordinate at the
/// `[[landmarks]]` entry concerned).
pub fn read_landmarks(path: &Path) -> Result<LandmarkTable, LogError> {
    let text = std::fs::read_to_string(path).map_err(io_err(path))?;
    let doc = TomlDoc::parse(path.display().to_string(), &text).map_err(|e| toml_err(path, e))?;
    let file: LandmarkFile = doc.deserialize().map_err(|e| toml_err(path, e))?;
    LandmarkTable::new(&file.landmarks).map_err(|e| {
        // Locate the entry the table refused: the last one with a repeated id, or the one with
        // the bad coordinate.
        let id = match &e {
            FilterError::DuplicateLandmark { id } => Some(*id),
            FilterError::Sighting { landmark, .. } => Some(*landmark),
            _ => None,
        };
        let at = id
            .and_then(|id| file.landmarks.iter().rposition(|l| l.id == id))
            .map_or_else(|| "landmarks".to_owned(), |i| format!("landmarks[{i}]"));
        toml_err(path, doc.error_at(&at, e.to_string()))
    })
}

/// Reads an initial-state file.
///
/// # Errors
/// [`LogError::Io`], [`LogError::Parse`].
pub fn read_initial(path: &Path) -> Result<InitialState, LogError> {
    let text = std::fs::read_to_string(path).map_err(io_err(path))?;
    let doc = TomlDoc::parse(path.display().to_string(), &text).map_err(|e| toml_err(path, e))?;
    doc.deserialize().map_err(|e| toml_err(path, e))
}

fn write_nav<W: Write + ?Sized>(w: &mut W, t_s: f64, s: &NavState) -> std::io::Result<()> {
    let q = s.att_b_to_n.quaternion();
    write!(
        w,
        "{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e}",
        t_s,
        s.pos.lat_rad,
        s.pos.lon_rad,
        s.pos.alt_m,
        s.vel_ned_mps.x,
        s.vel_ned_mps.y,
        s.vel_ned_mps.z,
        q.w,
        q.i,
        q.j,
        q.k
    )
}

/// Writes the solution row of the filter after an epoch at `t_s`.
fn write_solution<W: Write + ?Sized>(
    w: &mut W,
    t_s: f64,
    filter: &InsSdFilter,
) -> std::io::Result<()> {
    write_nav(w, t_s, &filter.navigation_solution())?;
    let sigma = |i: usize| filter.covariance().map_or(f64::NAN, |p| p[(i, i)].sqrt());
    let r = filter.last_report();
    let nis = r.nis.map(|v| format!("{v:e}")).unwrap_or_default();
    writeln!(
        w,
        ",{:e},{:e},{:e},{nis},{},{}",
        sigma(0),
        sigma(1),
        sigma(2),
        r.used,
        r.rejected
    )
}

/// Reads a navigation-state row (truth or the first columns of a solution).
fn read_nav(r: &CsvReader, rec: &Record) -> Result<(f64, NavState), LogError> {
    let names = TRUTH_HEADER.split(',').collect::<Vec<_>>();
    let mut v = [0.0; 11];
    for (i, x) in v.iter_mut().enumerate() {
        *x = r.f64(rec, i, names[i])?;
    }
    let s = NavState {
        pos: Geodetic {
            lat_rad: v[1],
            lon_rad: v[2],
            alt_m: v[3],
        },
        vel_ned_mps: Vector3::new(v[4], v[5], v[6]),
        att_b_to_n: UnitQuaternion::new_normalize(Quaternion::new(v[7], v[8], v[9], v[10])),
    };
    Ok((v[0], s))
}

/// Reads a truth (or solution) file: (t, state) per row.
///
/// # Errors
/// [`LogError::Io`], [`LogError::Parse`] naming the line and column.
pub fn read_truth(path: &Path) -> Result<Vec<(f64, NavState)>, LogError> {
    let mut r = CsvReader::open(path, TRUTH_HEADER)?;
    let mut out = Vec::new();
    while let Some(rec) = r.next()? {
        out.push(read_nav(&r, &rec)?);
    }
    Ok(out)
}

/// Reads a solution file written by [`replay`] or [`export_run`]: (t, state) per row.
///
/// # Errors
/// As [`read_truth`].
pub fn read_solution(path: &Path) -> Result<Vec<(f64, NavState)>, LogError> {
    let mut r = CsvReader::open(path, SOLUTION_HEADER)?;
    let mut out = Vec::new();
    while let Some(rec) = r.next()? {
        out.push(read_nav(&r, &rec)?);
        r.opt_f64(&rec, 14, "nis")?;
    }
    Ok(out)
}

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
/// [`LogError`] naming the file, line and column of the first bad record, or the line whose
/// record the filter rejected.
pub fn replay(
    inputs: &ReplayInputs,
    out: &mut impl Write,
    out_path: &Path,
) -> Result<ReplaySummary, LogError> {
    let table = read_landmarks(&inputs.landmarks)?;
    let init = read_initial(&inputs.initial)?;
    let mut filter =
        InsSdFilter::new(inputs.config, table, init.nav_state(), init.t_s).map_err(|source| {
            LogError::Filter {
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
     -> Result<(), LogError> {
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
                .map_err(|source| LogError::Filter {
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
            .map_err(|source| LogError::Filter {
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
) -> Result<TruthComparison, LogError> {
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

/// The observer that writes a simulated run as logs.
struct LogWriter {
    dir: PathBuf,
    imu: BufWriter<File>,
    sightings: BufWriter<File>,
    truth: BufWriter<File>,
    solution: BufWriter<File>,
    step_s: f64,
    initial: Option<InitialState>,
    error: Option<LogError>,
}

impl LogWriter {
    fn create(dir: &Path, step_s: f64) -> Result<Self, LogError> {
        std::fs::create_dir_all(dir).map_err(io_err(dir))?;
        let open = |name: &str, header: &str| -> Result<BufWriter<File>, LogError> {
            let path = dir.join(name);
            let mut w = BufWriter::new(File::create(&path).map_err(io_err(&path))?);
            writeln!(w, "{header}").map_err(io_err(&path))?;
            Ok(w)
        };
        Ok(Self {
            dir: dir.to_path_buf(),
            imu: open(names::IMU, IMU_HEADER)?,
            sightings: open(names::SIGHTINGS, SIGHTINGS_HEADER)?,
            truth: open(names::TRUTH, TRUTH_HEADER)?,
            solution: open(names::SOLUTION, SOLUTION_HEADER)?,
            step_s,
            initial: None,
            error: None,
        })
    }

    fn keep(&mut self, name: &str, r: std::io::Result<()>) {
        if let (Err(source), None) = (r, &self.error) {
            self.error = Some(LogError::Io {
                path: self.dir.join(name),
                source,
            });
        }
    }
}

impl RunObserver for LogWriter {
    fn start(&mut self, initial: &NavState) {
        self.initial = Some(InitialState::new(0.0, initial));
    }

    fn imu(&mut self, t_s: f64, f: &Vector3<f64>, w: &Vector3<f64>) {
        let (dv, dth) = (f * self.step_s, w * self.step_s);
        let r = writeln!(
            self.imu,
            "{:e},{:e},{:e},{:e},{:e},{:e},{:e}",
            t_s, dv.x, dv.y, dv.z, dth.x, dth.y, dth.z
        );
        self.keep(names::IMU, r);
    }

    fn epoch(&mut self, t_s: f64, sightings: &[Sighting], filter: &InsSdFilter) {
        for s in sightings {
            let r = writeln!(
                self.sightings,
                "{:e},{},{:e},{:e}",
                t_s, s.landmark_id, s.w_m, s.h_m
            );
            self.keep(names::SIGHTINGS, r);
        }
        let r = write_solution(&mut self.solution, t_s, filter);
        self.keep(names::SOLUTION, r);
    }

    fn truth(&mut self, t_s: f64, truth: &NavState) {
        let r = write_nav(&mut self.truth, t_s, truth).and_then(|_| writeln!(self.truth));
        self.keep(names::TRUTH, r);
    }
}

fn ser_err(path: &Path) -> impl Fn(toml::ser::Error) -> LogError + '_ {
    move |e| LogError::Io {
        path: path.to_path_buf(),
        source: std::io::Error::other(e.to_string()),
    }
}

fn write_text(path: &Path, text: &str) -> Result<(), LogError> {
    std::fs::write(path, text).map_err(io_err(path))
}

/// Simulates run `seed` of `scenario` in `mode` (a filter mode) and writes its logs into `dir`
/// ([`names`]): IMU, sightings, truth, landmark table, initial state, the scenario, and the
/// simulated filter's own solution. Returns the run's outcome and 1 Hz records.
///
/// # Errors
/// [`LogError::Run`] when the simulation fails, [`LogError::Io`] when a file cannot be written.
pub fn export_run(
    scenario: &Scenario,
    mode: Mode,
    seed: u64,
    dir: &Path,
) -> Result<(RunOutcome, Vec<Sample>), LogError> {
    let mut w = LogWriter::create(dir, scenario.trajectory.step_s)?;
    let mut out = vec![Sample::default(); scenario.samples_per_run()];
    let outcome = engine::run_observed(scenario, mode, seed, &mut out, &mut w)?;
    if let Some(e) = w.error.take() {
        return Err(e);
    }
    for (name, buf) in [
        (names::IMU, &mut w.imu),
        (names::SIGHTINGS, &mut w.sightings),
        (names::TRUTH, &mut w.truth),
        (names::SOLUTION, &mut w.solution),
    ] {
        buf.flush().map_err(io_err(&dir.join(name)))?;
    }
    let landmarks = LandmarkFile {
        landmarks: engine::landmark_entries(scenario),
    };
    write_text(
        &dir.join(names::LANDMARKS),
        &format!(
            "# Landmark table (WGS-84): id, latitude/longitude in degrees, height above the ellipsoid in m.\n{}",
            toml::to_string(&landmarks).map_err(ser_err(&dir.join(names::LANDMARKS)))?
        ),
    )?;
    if let Some(init) = &w.initial {
        write_text(
            &dir.join(names::INITIAL),
            &format!(
                "# Initial INS state: time s, latitude/longitude rad, height m, NED velocity m/s, body FRD -> NED quaternion (w, x, y, z).\n{}",
                toml::to_string(init).map_err(ser_err(&dir.join(names::INITIAL)))?
            ),
        )?;
    }
    let path = dir.join(names::SCENARIO);
    write_text(&path, &scenario.to_toml_string().map_err(ser_err(&path))?)?;
    Ok((outcome, out))
}
