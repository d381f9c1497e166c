//! Reading the logs: the CSV reader (header check, located errors), the landmark table and the
//! initial state (TOML), and the truth and solution files.

use std::fs::File;
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};

use ins_errors::earth::Geodetic;
use ins_errors::strapdown::NavState;
use ins_sd_filter::{FilterError, LandmarkEntry, LandmarkTable};
use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use serde::{Deserialize, Serialize};
use toml_config::TomlDoc;

use super::{SOLUTION_HEADER, TRUTH_HEADER};
use crate::SimError;

pub(super) fn io_err(path: &Path) -> impl Fn(std::io::Error) -> SimError + '_ {
    move |source| SimError::LogIo {
        path: path.to_path_buf(),
        source,
    }
}

/// One parsed CSV line: the text and the start of each field.
pub(super) struct Record {
    pub(super) text: String,
    pub(super) starts: Vec<usize>,
    pub(super) line: usize,
}

/// A CSV file read line by line with its header checked.
pub(super) struct CsvReader {
    pub(super) path: PathBuf,
    pub(super) lines: std::io::Lines<BufReader<File>>,
    pub(super) line: usize,
    pub(super) fields: usize,
}

impl CsvReader {
    /// Opens a file whose header is one of `headers`; returns the reader and the index of the
    /// header found. The error for another header lists the accepted ones.
    pub(super) fn open_any(path: &Path, headers: &[&str]) -> Result<(Self, usize), SimError> {
        let file = File::open(path).map_err(io_err(path))?;
        let mut r = Self {
            path: path.to_path_buf(),
            lines: BufReader::new(file).lines(),
            line: 0,
            fields: 0,
        };
        let accepted = headers
            .iter()
            .map(|h| format!("`{h}`"))
            .collect::<Vec<_>>()
            .join(" or ");
        let Some(first) = r.next_raw()? else {
            return Err(r.parse_err(1, 1, format!("empty file, expected the header {accepted}")));
        };
        let got: Vec<&str> = first.text.split(',').map(str::trim).collect();
        for (i, h) in headers.iter().enumerate() {
            if got.iter().copied().eq(h.split(',')) {
                r.fields = h.split(',').count();
                return Ok((r, i));
            }
        }
        // Name the first field that differs from the closest accepted header.
        let common = |h: &str| {
            got.iter()
                .zip(h.split(','))
                .take_while(|(a, b)| *a == b)
                .count()
        };
        let closest = headers
            .iter()
            .copied()
            .max_by_key(|h| common(h))
            .unwrap_or("");
        let k = common(closest);
        let column = first.starts.get(k).map_or(first.text.len(), |s| *s) + 1;
        let message = match (got.get(k), closest.split(',').nth(k)) {
            (Some(g), Some(want)) => {
                format!("header field `{g}`, expected `{want}` (header {accepted})")
            }
            (None, Some(want)) => format!("header ends before `{want}` (header {accepted})"),
            _ => format!("header has extra fields (header {accepted})"),
        };
        Err(r.parse_err(first.line, column, message))
    }

    pub(super) fn open(path: &Path, header: &str) -> Result<Self, SimError> {
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

    pub(super) fn parse_err(&self, line: usize, column: usize, message: String) -> SimError {
        SimError::LogParse {
            path: self.path.clone(),
            line,
            column,
            message,
        }
    }

    /// Next non-blank, non-comment line, split.
    pub(super) fn next_raw(&mut self) -> Result<Option<Record>, SimError> {
        for text in self.lines.by_ref() {
            self.line += 1;
            let text = text.map_err(|source| SimError::LogIo {
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
    pub(super) fn next(&mut self) -> Result<Option<Record>, SimError> {
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

    pub(super) fn field<'a>(&self, rec: &'a Record, i: usize) -> &'a str {
        let end = rec.starts.get(i + 1).map_or(rec.text.len(), |e| e - 1);
        &rec.text[rec.starts[i]..end]
    }

    pub(super) fn f64(&self, rec: &Record, i: usize, name: &str) -> Result<f64, SimError> {
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

    pub(super) fn opt_f64(
        &self,
        rec: &Record,
        i: usize,
        name: &str,
    ) -> Result<Option<f64>, SimError> {
        if self.field(rec, i).trim().is_empty() {
            Ok(None)
        } else {
            self.f64(rec, i, name).map(Some)
        }
    }

    pub(super) fn u32(&self, rec: &Record, i: usize, name: &str) -> Result<u32, SimError> {
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

/// The nominal step of an IMU log (either header, or a bag's IMU `topic`): the median interval
/// of its first 200 samples, s.
///
/// # Errors
/// [`SimError::LogIo`], [`SimError::LogParse`] for a bad header or time field, or fewer than two
/// samples.
pub fn imu_nominal_step_s(path: &Path, topic: Option<&str>) -> Result<f64, SimError> {
    let mut r = super::imu::ImuStream::open(path, topic)?;
    let mut times = Vec::with_capacity(201);
    let mut line = 1;
    while times.len() < 201 {
        let Some(rec) = r.next()? else { break };
        times.push(rec.t_s);
        line = rec.line;
    }
    let mut dts: Vec<f64> = times
        .windows(2)
        .map(|w| w[1] - w[0])
        .filter(|d| *d > 0.0)
        .collect();
    if dts.is_empty() {
        return Err(r.parse_err(
            line,
            1,
            "fewer than two increasing IMU time stamps: no sample rate".into(),
        ));
    }
    dts.sort_by(f64::total_cmp);
    Ok(dts[dts.len() / 2])
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
