//! Reading the logs: the landmark table and the initial state (TOML), and the truth and solution
//! files (through the shared CSV reader, [`super::csv`]).

use std::path::Path;

use ins_errors::earth::Geodetic;
use ins_errors::strapdown::NavState;
use ins_sd_filter::{FilterError, LandmarkEntry, LandmarkTable};
use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use serde::{Deserialize, Serialize};
use toml_config::TomlDoc;

use super::csv::{CsvReader, Record, io_err};
use super::{SOLUTION_HEADER, TRUTH_HEADER};
use crate::SimError;

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
pub(super) struct LandmarkFile {
    pub(super) landmarks: Vec<LandmarkEntry>,
}

pub(super) fn toml_err(path: &Path, error: toml_config::TomlError) -> SimError {
    SimError::LogToml {
        path: path.to_path_buf(),
        error,
    }
}

/// Reads a landmark table file.
///
/// # Errors
/// [`SimError::LogIo`], [`SimError::LogToml`] (TOML errors with their line and column, through the
/// workspace's one TOML loader `toml-config`; a duplicate id or a bad coordinate at the
/// `[[landmarks]]` entry concerned).
pub fn read_landmarks(path: &Path) -> Result<LandmarkTable, SimError> {
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
        toml_err(path, doc.error_at(&at, crate::error::with_causes(&e)))
    })
}

/// Reads an initial-state file.
///
/// # Errors
/// [`SimError::LogIo`], [`SimError::LogToml`].
pub fn read_initial(path: &Path) -> Result<InitialState, SimError> {
    let text = std::fs::read_to_string(path).map_err(io_err(path))?;
    let doc = TomlDoc::parse(path.display().to_string(), &text).map_err(|e| toml_err(path, e))?;
    doc.deserialize().map_err(|e| toml_err(path, e))
}

/// Reads a navigation-state row (truth or the first columns of a solution).
pub(super) fn read_nav(r: &CsvReader, rec: &Record) -> Result<(f64, NavState), SimError> {
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
/// [`SimError::LogIo`], [`SimError::LogParse`] naming the line and column.
pub fn read_truth(path: &Path) -> Result<Vec<(f64, NavState)>, SimError> {
    let mut r = CsvReader::open(path, TRUTH_HEADER)?;
    let mut out = Vec::new();
    while let Some(rec) = r.next()? {
        out.push(read_nav(&r, &rec)?);
    }
    Ok(out)
}

/// Reads a solution file written by [`super::replay`] or [`super::export_run`]: (t, state) per row.
///
/// # Errors
/// As [`read_truth`].
pub fn read_solution(path: &Path) -> Result<Vec<(f64, NavState)>, SimError> {
    let mut r = CsvReader::open(path, SOLUTION_HEADER)?;
    let mut out = Vec::new();
    while let Some(rec) = r.next()? {
        out.push(read_nav(&r, &rec)?);
        r.opt_f64(&rec, 20, "nis")?;
    }
    Ok(out)
}

/// The filter's 1σ at one row of a solution file: position (N, E, D, m), velocity (N, E, D, m/s)
/// and misalignment ψ (N, E, D, rad), in the file's column order (`sigma_n_m` … `sigma_psi_d_rad`);
/// NaN where the row has none (a run without an estimator).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolutionSigma {
    /// Time of the row, s.
    pub t_s: f64,
    /// The nine σ.
    pub sigma: [f64; 9],
}

/// Column of `sigma_n_m`, the first σ, in a solution file.
const SOLUTION_SIGMA_COLUMN: usize = 11;

/// Reads the σ columns of a solution file written by [`super::replay`] or
/// [`super::export_run`]: one [`SolutionSigma`] per row.
///
/// # Errors
/// As [`read_truth`].
pub fn read_solution_sigma(path: &Path) -> Result<Vec<SolutionSigma>, SimError> {
    let mut r = CsvReader::open(path, SOLUTION_HEADER)?;
    let names: Vec<&str> = SOLUTION_HEADER.split(',').collect();
    let mut out = Vec::new();
    while let Some(rec) = r.next()? {
        let mut row = SolutionSigma {
            t_s: r.f64(&rec, 0, names[0])?,
            sigma: [f64::NAN; 9],
        };
        for (k, s) in row.sigma.iter_mut().enumerate() {
            let i = SOLUTION_SIGMA_COLUMN + k;
            if let Some(v) = r.opt_f64(&rec, i, names.get(i).copied().unwrap_or("sigma"))? {
                *s = v;
            }
        }
        out.push(row);
    }
    Ok(out)
}

/// Writes a landmark table file (the format [`read_landmarks`] reads).
///
/// # Errors
/// [`SimError::LogWrite`] or [`SimError::LogIo`].
pub fn write_landmarks(path: &Path, entries: &[LandmarkEntry]) -> Result<(), SimError> {
    let file = LandmarkFile {
        landmarks: entries.to_vec(),
    };
    let text = toml::to_string(&file).map_err(|source| SimError::LogWrite {
        path: path.to_path_buf(),
        source,
    })?;
    std::fs::write(
        path,
        format!("# Landmark table (WGS-84): id, latitude/longitude in degrees, height above the ellipsoid in m.\n{text}"),
    )
    .map_err(io_err(path))
}
