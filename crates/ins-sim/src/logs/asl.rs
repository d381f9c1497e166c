//! EuRoC / ASL dataset folders read as they are shipped: the IMU (`mav0/imu0/data.csv`), its
//! extrinsics (`mav0/imu0/sensor.yaml`, `T_BS`) and the ground-truth estimate
//! (`mav0/state_groundtruth_estimate0/data.csv`).
//!
//! ## Layout and conversions
//!
//! | file | header (units in brackets) | converted to |
//! |---|---|---|
//! | `imu0/data.csv` | `#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y,w_RS_S_z,a_RS_S_x [m s^-2],a_RS_S_y,a_RS_S_z` | an IMU log of rates: t_s, ω_b = C_B^S·ω_S, f_b = C_B^S·a_S |
//! | `imu0/sensor.yaml` | `T_BS: {rows: 4, cols: 4, data: [16 numbers, row-major]}` | C_B^S, its upper-left 3×3 (the sensor S → body B rotation) |
//! | `state_groundtruth_estimate0/data.csv` | `#timestamp,p_RS_R_x [m],…,q_RS_w,q_RS_x,q_RS_y,q_RS_z,v_RS_R_x [m s^-1],…` (then biases, ignored) | a reference: the local frame R ([`super::LocalFrame`], `--tum-origin`, `--tum-frame`) to WGS-84, v_R to NED, attitude C_R^S·(C_B^S)ᵀ to body → NED |
//!
//! - **Stamps**: integer nanoseconds, strictly increasing (checked). Up to 2⁵³ ns (104 days)
//!   t_s = ns/10⁹ in one correctly rounded division, so a stamp reads as the same f64 as its
//!   decimal seconds would (12.34 s written as `12340000000` is exactly `12.34`: the same log
//!   in the project's CSV and as an ASL folder replays to the same bytes); above (EuRoC's
//!   Unix-epoch stamps, 1.4·10¹⁸ ns) t_s = ⌊ns/10⁹⌋ + (ns mod 10⁹)/10⁹, whose f64 resolution at
//!   1.4·10⁹ s is 0.24 µs, far below a 5 ms IMU step.
//! - **Units**: rad/s and m/s² as the filter's rate logs; ω and a are the sensor's samples at
//!   the stamp, used as the mean over (previous t, t] like any rate log.
//! - **Axes**: the filter's body frame is B = the IMU's axes rotated by C_B^S, given
//!   (`--imu-to-body`, 9 numbers row-major) or read from `sensor.yaml`'s `T_BS` (the identity in
//!   EuRoC, whose body frame is the IMU's). It is checked to be a rotation (‖CᵀC − I‖ < 10⁻⁶,
//!   det > 0). A folder with neither is refused: the rotation is not guessed. The ground truth's
//!   attitude q_RS is of the sensor S, so body → R is C_R^S·(C_B^S)ᵀ; positions and velocities
//!   are the sensor's (the lever arm of T_BS is not applied: EuRoC's is zero).
//!
//! Folders are found from `mav0` itself or the folder holding it; a `data.csv` given directly
//! is recognised by its `#timestamp` header.

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};

use nalgebra::{Matrix3, Quaternion, UnitQuaternion, Vector3};

use super::csv::{CsvReader, Record, io_err};
use super::imu::ImuRecord;
use super::local::{LocalFrame, LocalPose, MAX_LOCAL_DISTANCE_M, quat_of, rows_from_local};
use super::reference::ReferenceRow;
use crate::SimError;

/// The IMU file's column names (units stripped).
pub const ASL_IMU_NAMES: [&str; 7] = [
    "timestamp",
    "w_RS_S_x",
    "w_RS_S_y",
    "w_RS_S_z",
    "a_RS_S_x",
    "a_RS_S_y",
    "a_RS_S_z",
];
/// The ground truth's first column names (units stripped; further columns are ignored).
pub const ASL_TRUTH_NAMES: [&str; 11] = [
    "timestamp",
    "p_RS_R_x",
    "p_RS_R_y",
    "p_RS_R_z",
    "q_RS_w",
    "q_RS_x",
    "q_RS_y",
    "q_RS_z",
    "v_RS_R_x",
    "v_RS_R_y",
    "v_RS_R_z",
];

/// The first existing `sub` under `path` or under `path/mav0`, for a folder.
fn in_folder(path: &Path, sub: &str) -> Option<PathBuf> {
    if !path.is_dir() {
        return None;
    }
    [path.join(sub), path.join("mav0").join(sub)]
        .into_iter()
        .find(|p| p.is_file())
}

/// True when `path` is a regular file whose first line starts with `#timestamp` (an ASL
/// `data.csv`). Only regular files are looked into: a pipe's first line would be consumed
/// (a log read from a pipe is read once, by its reader, as this project's CSV).
fn has_asl_header(path: &Path) -> bool {
    if !path.is_file() {
        return false;
    }
    let Ok(file) = std::fs::File::open(path) else {
        return false;
    };
    let mut first = String::new();
    BufReader::new(file).read_line(&mut first).is_ok() && first.starts_with("#timestamp")
}

/// The IMU `data.csv` of an ASL folder (`mav0` or the folder holding it) or the file itself
/// when it has the ASL header; `None` for any other log.
pub fn asl_imu_file(path: &Path) -> Option<PathBuf> {
    in_folder(path, "imu0/data.csv").or_else(|| has_asl_header(path).then(|| path.to_path_buf()))
}

/// The ground-truth `data.csv` of an ASL folder, or the file itself when it has the ASL header.
pub(super) fn asl_truth_file(path: &Path) -> Option<PathBuf> {
    in_folder(path, "state_groundtruth_estimate0/data.csv")
        .or_else(|| has_asl_header(path).then(|| path.to_path_buf()))
}

/// Checks that `m` is a rotation (module documentation); `what` names it in the error.
///
/// # Errors
/// [`SimError::ScenarioInvalid`] (field `what`).
pub fn check_rotation(m: Matrix3<f64>, what: &str) -> Result<Matrix3<f64>, SimError> {
    let off = (m.transpose() * m - Matrix3::identity()).abs().max();
    if m.iter().all(|x| x.is_finite()) && off < 1e-6 && m.determinant() > 0.0 {
        Ok(m)
    } else {
        Err(SimError::invalid(
            what,
            "must be a rotation matrix (orthonormal to 1e-6, determinant +1)",
            m.as_slice(),
        ))
    }
}

/// C_B^S from an ASL `sensor.yaml` (`T_BS`'s upper-left 3×3).
///
/// # Errors
/// [`SimError::LogIo`]; [`SimError::LogParse`] naming the line of a missing `T_BS`, a `data`
/// list that is not 16 numbers, or a matrix that is not a rotation.
pub fn read_sensor_yaml(path: &Path) -> Result<Matrix3<f64>, SimError> {
    let text = std::fs::read_to_string(path).map_err(io_err(path))?;
    let err = |line: usize, message: String| SimError::LogParse {
        path: path.to_path_buf(),
        line,
        column: 1,
        message,
    };
    let lines: Vec<&str> = text.lines().collect();
    let Some(t_bs) = lines.iter().position(|l| l.trim_end() == "T_BS:") else {
        return Err(err(
            1,
            "no `T_BS:` (the sensor's extrinsics) in the file".into(),
        ));
    };
    let Some(data) = (t_bs..lines.len()).find(|&i| lines[i].trim_start().starts_with("data:"))
    else {
        return Err(err(t_bs + 1, "`T_BS` has no `data:` list".into()));
    };
    let mut list = String::new();
    for line in &lines[data..] {
        list.push_str(line);
        if line.contains(']') {
            break;
        }
    }
    let inner = list
        .split_once('[')
        .and_then(|(_, rest)| rest.split_once(']'))
        .map(|(inner, _)| inner);
    let numbers: Vec<f64> = inner
        .map(|s| s.split(',').filter_map(|x| x.trim().parse().ok()).collect())
        .unwrap_or_default();
    if numbers.len() != 16 {
        return Err(err(
            data + 1,
            format!(
                "`T_BS` `data` must be a list of 16 numbers (4×4, row-major), found {}",
                numbers.len()
            ),
        ));
    }
    let m = Matrix3::from_fn(|r, c| numbers[4 * r + c]);
    check_rotation(m, "T_BS").map_err(|e| err(data + 1, e.to_string()))
}

/// The rotation of an ASL IMU whose `data.csv` is `imu_file`: `given`, else its `sensor.yaml`.
///
/// # Errors
/// [`SimError::LogParse`] for a missing or bad `sensor.yaml` (naming it), or as
/// [`read_sensor_yaml`].
pub fn asl_body_from_imu(
    imu_file: &Path,
    given: Option<Matrix3<f64>>,
) -> Result<Matrix3<f64>, SimError> {
    if let Some(m) = given {
        return check_rotation(m, "imu_to_body");
    }
    let yaml = imu_file.with_file_name("sensor.yaml");
    if !yaml.is_file() {
        return Err(SimError::LogParse {
            path: yaml,
            line: 1,
            column: 1,
            message: "missing: the IMU-to-body rotation of an ASL folder comes from its \
                      sensor.yaml (T_BS) or from --imu-to-body"
                .into(),
        });
    }
    read_sensor_yaml(&yaml)
}

/// Opens an ASL `data.csv` whose first columns are `names` (header `#`-prefixed, units in
/// brackets ignored); the reader takes every column of the header.
pub(super) fn open_asl(path: &Path, names: &[&str]) -> Result<CsvReader, SimError> {
    let file = std::fs::File::open(path).map_err(io_err(path))?;
    let mut r = CsvReader {
        path: path.to_path_buf(),
        lines: BufReader::new(file).lines(),
        line: 1,
        fields: 0,
    };
    let header = match r.lines.next() {
        Some(line) => line.map_err(io_err(path))?,
        None => String::new(),
    };
    let header = header.trim_end_matches('\r');
    let got: Vec<(usize, &str)> = {
        let mut column = 1;
        header
            .split(',')
            .map(|f| {
                let start = column;
                column += f.len() + 1;
                let name = f.trim().trim_start_matches('#');
                (start, name.split('[').next().unwrap_or("").trim())
            })
            .collect()
    };
    let expected = format!("#{}", names.join(","));
    for (k, want) in names.iter().enumerate() {
        match got.get(k) {
            Some((_, name)) if name == want => {}
            Some((column, name)) => {
                return Err(r.parse_err(
                    1,
                    *column,
                    format!("header field `{name}`, expected `{want}` (ASL header `{expected}`, units in brackets)"),
                ));
            }
            None => {
                return Err(r.parse_err(
                    1,
                    header.len() + 1,
                    format!(
                        "header ends before `{want}` (ASL header `{expected}`, units in brackets)"
                    ),
                ));
            }
        }
    }
    r.fields = got.len();
    Ok(r)
}

/// A stamp in nanoseconds as seconds (module documentation), strictly after `prev_ns`.
pub(super) fn stamp_s(
    r: &CsvReader,
    rec: &Record,
    prev_ns: &mut Option<u64>,
) -> Result<f64, SimError> {
    let s = r.field(rec, 0).trim();
    let Ok(ns) = s.parse::<u64>() else {
        return Err(r.parse_err(
            rec.line,
            1,
            format!("field `timestamp`: `{s}` is not a whole number of nanoseconds"),
        ));
    };
    if let Some(p) = *prev_ns
        && ns <= p
    {
        return Err(r.parse_err(
            rec.line,
            1,
            format!("timestamp {ns} ns is not after the previous row's ({p} ns)"),
        ));
    }
    *prev_ns = Some(ns);
    // Below 2⁵³ ns (104 days) ns is exact as f64 and one division rounds correctly; above,
    // whole seconds and the fraction are converted apart (module documentation).
    const EXACT_NS: u64 = 1 << 53;
    Ok(if ns <= EXACT_NS {
        ns as f64 / 1e9
    } else {
        (ns / 1_000_000_000) as f64 + (ns % 1_000_000_000) as f64 / 1e9
    })
}

/// The next ASL IMU row: t, specific force and angular rate in body axes.
pub(super) fn next_imu(
    r: &mut CsvReader,
    body_from_imu: &Matrix3<f64>,
    prev_ns: &mut Option<u64>,
) -> Result<Option<ImuRecord>, SimError> {
    let Some(rec) = r.next()? else {
        return Ok(None);
    };
    let t_s = stamp_s(r, &rec, prev_ns)?;
    let mut v = [0.0; 6];
    for (i, x) in v.iter_mut().enumerate() {
        *x = r.f64(&rec, i + 1, ASL_IMU_NAMES[i + 1])?;
    }
    let (w, a) = (
        Vector3::new(v[0], v[1], v[2]),
        Vector3::new(v[3], v[4], v[5]),
    );
    // The identity is skipped, not multiplied: the samples stay bit for bit as logged.
    let (f_b, w_b) = if *body_from_imu == Matrix3::identity() {
        (a, w)
    } else {
        (body_from_imu * a, body_from_imu * w)
    };
    Ok(Some(ImuRecord {
        t_s,
        a: f_b,
        b: w_b,
        line: rec.line,
    }))
}

/// Reads an ASL ground truth (module documentation) in `frame`, the IMU's rotation
/// `body_from_imu` (identity when `None`).
///
/// # Errors
/// [`SimError::LogIo`]; [`SimError::LogParse`] naming the line and column of a bad header,
/// field, stamp or quaternion, or the missing local frame.
pub(super) fn read_asl_truth(
    path: &Path,
    frame: Option<&LocalFrame>,
    body_from_imu: Option<&Matrix3<f64>>,
) -> Result<Vec<ReferenceRow>, SimError> {
    let mut r = open_asl(path, &ASL_TRUTH_NAMES)?;
    let Some(frame) = frame else {
        return Err(r.parse_err(
            1,
            1,
            "an ASL ground truth holds positions in a local frame: give its geodetic origin and \
             axes with --tum-origin LAT,LON,ALT --tum-frame enu|ned"
                .into(),
        ));
    };
    let q_s_b = quat_of(
        &body_from_imu
            .copied()
            .unwrap_or_else(Matrix3::identity)
            .transpose(),
    );
    let mut prev = None;
    let mut poses = Vec::new();
    while let Some(rec) = r.next()? {
        let t_s = stamp_s(&r, &rec, &mut prev)?;
        let mut v = [0.0; 10];
        for (i, x) in v.iter_mut().enumerate() {
            *x = r.f64(&rec, i + 1, ASL_TRUTH_NAMES[i + 1])?;
        }
        let p_local_m = Vector3::new(v[0], v[1], v[2]);
        if p_local_m.norm() > MAX_LOCAL_DISTANCE_M {
            return Err(r.parse_err(
                rec.line,
                rec.starts[1] + 1,
                format!(
                    "position {:.0} m from the origin: beyond {MAX_LOCAL_DISTANCE_M:e} m, not a local frame",
                    p_local_m.norm()
                ),
            ));
        }
        let q = Quaternion::new(v[3], v[4], v[5], v[6]);
        if !(q.norm() > 0.5 && q.norm() < 2.0) {
            return Err(r.parse_err(
                rec.line,
                rec.starts[4] + 1,
                format!("quaternion norm {} is not near 1", q.norm()),
            ));
        }
        poses.push(LocalPose {
            t_s,
            p_local_m,
            q_local_body: UnitQuaternion::new_normalize(q) * q_s_b,
            v_local_mps: Some(Vector3::new(v[7], v[8], v[9])),
        });
    }
    Ok(rows_from_local(frame, &poses))
}
