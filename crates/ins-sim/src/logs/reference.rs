//! Reference trajectories (truth) as real systems give them: radians or degrees, attitude
//! optional; a TUM trajectory or an EuRoC/ASL ground truth in a local frame
//! ([`read_reference_in`], [`super::local`], [`super::asl`]); interpolation at any time; the
//! initial state of a replay taken from the reference.

use std::io::{BufRead, BufReader};
use std::path::Path;

use ins_errors::earth::Geodetic;
use ins_errors::strapdown::NavState;
use nalgebra::{Quaternion, UnitQuaternion, Vector3};

use super::asl::{asl_truth_file, read_asl_truth};
use super::csv::{CsvReader, io_err};
use super::local::{LocalFrame, read_tum};
use super::read::InitialState;
use super::{REFERENCE_DEG_HEADER, TRUTH_HEADER};
use crate::SimError;

/// One row of a reference trajectory.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReferenceRow {
    /// Time, s (the IMU log's time base).
    pub t_s: f64,
    /// WGS-84 position.
    pub pos: Geodetic,
    /// NED velocity, m/s.
    pub vel_ned_mps: Vector3<f64>,
    /// Attitude body FRD → NED, when the reference has one.
    pub att_b_to_n: Option<UnitQuaternion<f64>>,
}

impl ReferenceRow {
    /// The navigation state, with `fallback` attitude when the reference has none.
    pub fn nav_state(&self, fallback: UnitQuaternion<f64>) -> NavState {
        NavState {
            pos: self.pos,
            vel_ned_mps: self.vel_ned_mps,
            att_b_to_n: self.att_b_to_n.unwrap_or(fallback),
        }
    }
}

/// Reads a reference trajectory: the truth header of this project (radians, attitude required)
/// or the data sets' (`t_s,lat_deg,lon_deg,alt_m,vn_mps,ve_mps,vd_mps,qw,qx,qy,qz`, degrees, the
/// four quaternion fields all empty when there is no attitude). Times strictly increasing.
///
/// # Errors
/// [`SimError::LogIo`], [`SimError::LogParse`] naming the line and column of a bad field, a
/// partly empty quaternion, or a time not after the previous row's.
pub fn read_reference(path: &Path) -> Result<Vec<ReferenceRow>, SimError> {
    let (mut r, which) = CsvReader::open_any(path, &[TRUTH_HEADER, REFERENCE_DEG_HEADER])?;
    let names: Vec<&str> = [TRUTH_HEADER, REFERENCE_DEG_HEADER][which]
        .split(',')
        .collect();
    let scale = if which == 0 {
        1.0
    } else {
        std::f64::consts::PI / 180.0
    };
    let mut out: Vec<ReferenceRow> = Vec::new();
    while let Some(rec) = r.next()? {
        let mut v = [0.0; 7];
        for (i, x) in v.iter_mut().enumerate() {
            *x = r.f64(&rec, i, names[i])?;
        }
        let mut q = [None; 4];
        for (k, x) in q.iter_mut().enumerate() {
            *x = r.opt_f64(&rec, 7 + k, names[7 + k])?;
        }
        let att = match q {
            [Some(w), Some(x), Some(y), Some(z)] => {
                let quat = Quaternion::new(w, x, y, z);
                if !(quat.norm() > 0.5 && quat.norm() < 2.0) {
                    return Err(r.parse_err(
                        rec.line,
                        rec.starts[7] + 1,
                        format!("quaternion norm {} is not near 1", quat.norm()),
                    ));
                }
                Some(UnitQuaternion::new_normalize(quat))
            }
            [None, None, None, None] if which == 1 => None,
            _ => {
                return Err(r.parse_err(
                    rec.line,
                    rec.starts[7] + 1,
                    "the quaternion must have all four fields or (degrees header only) none".into(),
                ));
            }
        };
        if let Some(prev) = out.last()
            && v[0] <= prev.t_s
        {
            return Err(r.parse_err(
                rec.line,
                1,
                format!(
                    "t = {} s is not after the previous row ({} s)",
                    v[0], prev.t_s
                ),
            ));
        }
        out.push(ReferenceRow {
            t_s: v[0],
            pos: Geodetic {
                lat_rad: v[1] * scale,
                lon_rad: v[2] * scale,
                alt_m: v[3],
            },
            vel_ned_mps: Vector3::new(v[4], v[5], v[6]),
            att_b_to_n: att,
        });
    }
    Ok(out)
}

/// True when the first line of `path` that is neither blank nor a `#` comment has no comma: a
/// TUM trajectory (blank-separated), not a CSV file.
fn is_tum(path: &Path) -> Result<bool, SimError> {
    let file = std::fs::File::open(path).map_err(io_err(path))?;
    for line in BufReader::new(file).lines() {
        let line = line.map_err(io_err(path))?;
        let t = line.trim();
        if !(t.is_empty() || t.starts_with('#')) {
            return Ok(!t.contains(','));
        }
    }
    Ok(false)
}

/// Reads a reference in any layout `nav-app ins --truth` accepts: an EuRoC/ASL folder (`mav0`
/// or the folder holding it) or its `state_groundtruth_estimate0/data.csv`, a TUM trajectory
/// (lines without commas), or this project's CSV ([`read_reference`]). The first two are in a
/// local frame: `local` gives its origin and axes (an error naming the file without it; unused
/// for a CSV reference, which is geodetic); `body_from_imu` turns an ASL ground truth's sensor
/// attitude into the body's.
///
/// # Errors
/// As [`read_reference`]; [`SimError::LogParse`] naming the file and line for a missing local
/// frame, a bad TUM or ASL line.
pub fn read_reference_in(
    path: &Path,
    local: Option<&LocalFrame>,
    body_from_imu: Option<&nalgebra::Matrix3<f64>>,
) -> Result<Vec<ReferenceRow>, SimError> {
    if let Some(file) = asl_truth_file(path) {
        return read_asl_truth(&file, local, body_from_imu);
    }
    if path.is_file() && is_tum(path)? {
        return read_tum(path, local);
    }
    read_reference(path)
}

/// True when `path` is a reference in a local frame (an ASL folder or ground truth, or a TUM
/// trajectory), which [`read_reference_in`] reads only with a [`LocalFrame`].
///
/// # Errors
/// [`SimError::LogIo`] when the file cannot be read.
pub fn is_local_reference(path: &Path) -> Result<bool, SimError> {
    Ok(asl_truth_file(path).is_some() || (path.is_file() && is_tum(path)?))
}

/// The reference at `t_s` by linear interpolation between the rows around it (attitude by
/// slerp, present only when both rows have one); `None` outside the reference's span or across
/// a gap longer than `max_gap_s`. `cursor` remembers where the last search ended (start at 0;
/// searches at non-decreasing times are O(1)).
pub fn interpolate(
    rows: &[ReferenceRow],
    t_s: f64,
    max_gap_s: f64,
    cursor: &mut usize,
) -> Option<ReferenceRow> {
    if rows.is_empty() || t_s < rows[0].t_s || t_s > rows[rows.len() - 1].t_s {
        return None;
    }
    if *cursor >= rows.len() || rows[*cursor].t_s > t_s {
        *cursor = 0;
    }
    while *cursor + 1 < rows.len() && rows[*cursor + 1].t_s <= t_s {
        *cursor += 1;
    }
    let a = &rows[*cursor];
    let Some(b) = rows.get(*cursor + 1) else {
        return Some(*a);
    };
    if b.t_s - a.t_s > max_gap_s {
        return None;
    }
    let u = (t_s - a.t_s) / (b.t_s - a.t_s);
    let lerp = |x: f64, y: f64| x + (y - x) * u;
    Some(ReferenceRow {
        t_s,
        pos: Geodetic {
            lat_rad: lerp(a.pos.lat_rad, b.pos.lat_rad),
            lon_rad: lerp(a.pos.lon_rad, b.pos.lon_rad),
            alt_m: lerp(a.pos.alt_m, b.pos.alt_m),
        },
        vel_ned_mps: a.vel_ned_mps + (b.vel_ned_mps - a.vel_ned_mps) * u,
        att_b_to_n: match (a.att_b_to_n, b.att_b_to_n) {
            (Some(qa), Some(qb)) => Some(qa.slerp(&qb, u)),
            _ => None,
        },
    })
}

/// Attitude from the direction of motion: heading = course, pitch = grade (flight-path angle),
/// roll 0 — for a reference without attitude (a car that drives forward). `None` below
/// `min_speed_mps`.
pub fn attitude_from_motion(
    vel_ned_mps: &Vector3<f64>,
    min_speed_mps: f64,
) -> Option<UnitQuaternion<f64>> {
    let horizontal = vel_ned_mps.x.hypot(vel_ned_mps.y);
    if vel_ned_mps.norm() < min_speed_mps {
        return None;
    }
    let course = vel_ned_mps.y.atan2(vel_ned_mps.x);
    let grade = (-vel_ned_mps.z).atan2(horizontal);
    Some(UnitQuaternion::from_euler_angles(0.0, grade, course))
}

/// The initial state of a replay from the reference at `t_s` (interpolated). Without attitude in
/// the reference, the attitude comes from the first motion at or after `t_s` faster than
/// `min_speed_mps` (course and grade, roll 0: the vehicle is assumed not to turn before it moves);
/// its error is then covered by the filter file's `att_sigma_deg`.
///
/// # Errors
/// [`SimError::ReferenceSpan`] when `t_s` is outside the reference, or there is no attitude and
/// the vehicle never moves.
pub fn initial_from_reference(
    rows: &[ReferenceRow],
    t_s: f64,
    min_speed_mps: f64,
) -> Result<InitialState, SimError> {
    let mut cursor = 0;
    let at = interpolate(rows, t_s, f64::INFINITY, &mut cursor).ok_or(SimError::ReferenceSpan {
        t_s,
        what: "the start of the replay is outside the reference's time span",
    })?;
    let att = match at.att_b_to_n {
        Some(q) => q,
        None => rows
            .iter()
            .filter(|r| r.t_s >= t_s)
            .find_map(|r| attitude_from_motion(&r.vel_ned_mps, min_speed_mps))
            .ok_or(SimError::ReferenceSpan {
                t_s,
                what: "the reference has no attitude and never moves fast enough to take it from the motion",
            })?,
    };
    Ok(InitialState::new(t_s, &at.nav_state(att)))
}
