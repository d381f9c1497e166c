//! Trajectories in a local Cartesian frame — TUM files (`t x y z qx qy qz qw`) and the ground
//! truth of EuRoC/ASL folders ([`super::asl`]) — turned into reference rows, and a solution or
//! reference written back as a TUM file (`nav-app ins --tum-out`, `--tum-truth-out`).
//!
//! ## The local frame and its maths
//!
//! A local frame is fixed to the Earth at a geodetic origin o (WGS-84) with its axes either
//! ENU (x east, y north, z up) or NED (x north, y east, z down) at o ([`LocalFrame`]). A local
//! position p_l is mapped to the Earth exactly, through ECEF (no flat-Earth approximation):
//!
//! ```text
//! C_n0^l   = I (NED)   or   [[0,1,0],[1,0,0],[0,0,−1]] (ENU; its own inverse)
//! r_e      = r_e(o) + C_e^n0 · C_n0^l · p_l          C_e^n0 = (ned_from_ecef(o))ᵀ
//! geodetic = ecef_to_geodetic(r_e)
//! ```
//!
//! and back, p_l = C_l^n0 · C_n0^e · (r_e(g) − r_e(o)). A vector v_l (velocity) or a rotation
//! C_l^b (attitude, body → local) at a point g of the trajectory is turned into the NED frame
//! *at g* (the reference's frame) by C_n^l(g) = C_n^e(g) · C_e^n0 · C_n0^l: v_n = C_n^l(g)·v_l,
//! C_n^b = C_n^l(g)·C_l^b. Over a trajectory a few kilometres long the two NED frames differ by
//! the angle between the verticals, distance/R (0.16 mrad per km), which is kept.
//!
//! ## TUM files
//!
//! One pose per line, `t x y z qx qy qz qw`, separated by blanks; `#` starts a comment line.
//! t is in seconds on the IMU log's time base; (x, y, z) the position of the body in the local
//! frame, m; (qx, qy, qz, qw) the rotation body → local (Hamilton, scalar last, as TUM and `evo`
//! write it). The body frame is taken to be the filter's (the IMU's axes, FRD; after
//! `--imu-to-body` for an ASL folder): a trajectory of another body frame must be rotated
//! first. TUM has no velocity: it is the central difference of the positions
//! (v_i = (p_{i+1} − p_{i−1})/(t_{i+1} − t_{i−1}); one-sided at the ends), exact for motion at
//! constant velocity between samples, in the local frame, then turned into NED as above.

use std::io::{BufRead, BufReader, Write};
use std::path::Path;

use ins_errors::earth::{Geodetic, ecef_to_geodetic, geodetic_to_ecef, ned_from_ecef};
use nalgebra::{Matrix3, Quaternion, Rotation3, UnitQuaternion, Vector3};

use super::csv::io_err;
use super::reference::ReferenceRow;
use crate::SimError;

/// The axes of a local frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LocalAxes {
    /// x east, y north, z up.
    Enu,
    /// x north, y east, z down.
    Ned,
}

impl LocalAxes {
    /// `enu` or `ned`.
    pub fn parse(text: &str) -> Option<Self> {
        match text {
            "enu" => Some(Self::Enu),
            "ned" => Some(Self::Ned),
            _ => None,
        }
    }

    /// `enu` or `ned`.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Enu => "enu",
            Self::Ned => "ned",
        }
    }

    /// C_n0^l: local axes → NED at the origin.
    fn ned_from_local(self) -> Matrix3<f64> {
        match self {
            Self::Ned => Matrix3::identity(),
            Self::Enu => Matrix3::new(0.0, 1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, -1.0),
        }
    }
}

/// A local Cartesian frame fixed to the Earth (module documentation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LocalFrame {
    /// The origin (WGS-84).
    pub origin: Geodetic,
    /// The axes at the origin.
    pub axes: LocalAxes,
}

impl LocalFrame {
    /// The origin from `LAT,LON,ALT` (degrees, degrees, m above the ellipsoid) and the axes.
    ///
    /// # Errors
    /// [`SimError::ScenarioInvalid`] (field `tum_origin`) for another text or a latitude
    /// outside ±90°.
    pub fn from_text(origin: &str, axes: LocalAxes) -> Result<Self, SimError> {
        let v: Vec<f64> = origin
            .split(',')
            .filter_map(|s| s.trim().parse::<f64>().ok())
            .filter(|x| x.is_finite())
            .collect();
        match v[..] {
            [lat, lon, alt] if lat.abs() <= 90.0 && origin.split(',').count() == 3 => Ok(Self {
                origin: Geodetic::from_deg(lat, lon, alt),
                axes,
            }),
            _ => Err(SimError::invalid(
                "tum_origin",
                "must be LAT,LON,ALT: latitude and longitude in degrees (|lat| <= 90), height \
                 above the WGS-84 ellipsoid in m",
                origin,
            )),
        }
    }

    /// C_e^l: local axes → ECEF.
    fn ecef_from_local(&self) -> Matrix3<f64> {
        ned_from_ecef(self.origin.lat_rad, self.origin.lon_rad).transpose()
            * self.axes.ned_from_local()
    }

    /// The geodetic position of a local position, m (exact, through ECEF).
    pub fn to_geodetic(&self, p_local_m: &Vector3<f64>) -> Geodetic {
        ecef_to_geodetic(&(geodetic_to_ecef(&self.origin) + self.ecef_from_local() * p_local_m))
    }

    /// The local position of a geodetic position, m.
    pub fn to_local_m(&self, g: &Geodetic) -> Vector3<f64> {
        self.ecef_from_local().transpose() * (geodetic_to_ecef(g) - geodetic_to_ecef(&self.origin))
    }

    /// C_n^l(g): local axes → NED at `g`.
    pub fn ned_from_local_at(&self, g: &Geodetic) -> Matrix3<f64> {
        ned_from_ecef(g.lat_rad, g.lon_rad) * self.ecef_from_local()
    }
}

/// Farthest a local position may lie from its origin, m: beyond, it is not in a local frame
/// (and through ECEF it would leave the Earth model's range).
pub(super) const MAX_LOCAL_DISTANCE_M: f64 = 1.0e6;

/// A rotation matrix as a unit quaternion.
pub(super) fn quat_of(m: &Matrix3<f64>) -> UnitQuaternion<f64> {
    UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(*m))
}

/// One pose of a local trajectory, before its velocity is known.
pub(super) struct LocalPose {
    pub(super) t_s: f64,
    pub(super) p_local_m: Vector3<f64>,
    /// Body → local.
    pub(super) q_local_body: UnitQuaternion<f64>,
    /// The velocity in local axes, when the file has it (ASL), m/s.
    pub(super) v_local_mps: Option<Vector3<f64>>,
}

/// Reference rows from local poses (module documentation): positions through ECEF, velocity
/// given or differenced, attitude body → NED at each point.
pub(super) fn rows_from_local(frame: &LocalFrame, poses: &[LocalPose]) -> Vec<ReferenceRow> {
    let n = poses.len();
    let mut out = Vec::with_capacity(n);
    for (i, pose) in poses.iter().enumerate() {
        let v_local = pose.v_local_mps.unwrap_or_else(|| {
            let (a, b) = (&poses[i.saturating_sub(1)], &poses[(i + 1).min(n - 1)]);
            if b.t_s > a.t_s {
                (b.p_local_m - a.p_local_m) / (b.t_s - a.t_s)
            } else {
                Vector3::zeros()
            }
        });
        let pos = frame.to_geodetic(&pose.p_local_m);
        let c_n_l = frame.ned_from_local_at(&pos);
        out.push(ReferenceRow {
            t_s: pose.t_s,
            pos,
            vel_ned_mps: c_n_l * v_local,
            att_b_to_n: Some(quat_of(&c_n_l) * pose.q_local_body),
        });
    }
    out
}

/// A TUM line's eight fields (module documentation) or an error naming the line and column.
fn tum_fields(path: &Path, line_no: usize, text: &str) -> Result<[f64; 8], SimError> {
    let err = |column: usize, message: String| SimError::LogParse {
        path: path.to_path_buf(),
        line: line_no,
        column,
        message,
    };
    // (1-based column, text) of each blank-separated field.
    let mut fields: Vec<(usize, &str)> = Vec::with_capacity(8);
    let mut start = None;
    for (i, c) in text
        .char_indices()
        .chain(std::iter::once((text.len(), ' ')))
    {
        match (c.is_whitespace(), start) {
            (false, None) => start = Some(i),
            (true, Some(s)) => {
                fields.push((s + 1, &text[s..i]));
                start = None;
            }
            _ => {}
        }
    }
    if fields.len() != 8 {
        return Err(err(
            text.len() + 1,
            format!(
                "expected the 8 fields of a TUM pose `t x y z qx qy qz qw`, found {}",
                fields.len()
            ),
        ));
    }
    let names = ["t", "x", "y", "z", "qx", "qy", "qz", "qw"];
    let mut v = [0.0; 8];
    for (k, (column, f)) in fields.iter().enumerate() {
        v[k] = match f.parse::<f64>() {
            Ok(x) if x.is_finite() => x,
            _ => {
                return Err(err(
                    *column,
                    format!("field `{}`: `{f}` is not a finite number", names[k]),
                ));
            }
        };
    }
    Ok(v)
}

/// Reads a TUM trajectory in `frame` (module documentation); `frame` `None` is an error naming
/// the file's first pose: a TUM file has no geodetic origin of its own.
///
/// # Errors
/// [`SimError::LogIo`]; [`SimError::LogParse`] naming the line and column of a short line, a
/// bad number, a quaternion far from unit norm, a time not after the previous one, fewer than
/// two poses, or the missing origin.
pub(super) fn read_tum(
    path: &Path,
    frame: Option<&LocalFrame>,
) -> Result<Vec<ReferenceRow>, SimError> {
    let file = std::fs::File::open(path).map_err(io_err(path))?;
    let mut poses: Vec<LocalPose> = Vec::new();
    let mut last_line = 0;
    for (i, text) in BufReader::new(file).lines().enumerate() {
        let text = text.map_err(io_err(path))?;
        let line_no = i + 1;
        let t = text.trim();
        if t.is_empty() || t.starts_with('#') {
            continue;
        }
        let err = |column: usize, message: String| SimError::LogParse {
            path: path.to_path_buf(),
            line: line_no,
            column,
            message,
        };
        if frame.is_none() {
            return Err(err(
                1,
                "a TUM trajectory holds positions in a local frame: give its geodetic origin and \
                 axes with --tum-origin LAT,LON,ALT --tum-frame enu|ned"
                    .into(),
            ));
        }
        let v = tum_fields(path, line_no, &text)?;
        let p_local_m = Vector3::new(v[1], v[2], v[3]);
        if p_local_m.norm() > MAX_LOCAL_DISTANCE_M {
            return Err(err(
                1,
                format!(
                    "position {:.0} m from the origin: beyond {MAX_LOCAL_DISTANCE_M:e} m, not a local frame",
                    p_local_m.norm()
                ),
            ));
        }
        let q = Quaternion::new(v[7], v[4], v[5], v[6]);
        if !(q.norm() > 0.5 && q.norm() < 2.0) {
            return Err(err(
                1,
                format!("quaternion norm {} is not near 1", q.norm()),
            ));
        }
        if let Some(prev) = poses.last()
            && v[0] <= prev.t_s
        {
            return Err(err(
                1,
                format!(
                    "t = {} s is not after the previous pose ({} s)",
                    v[0], prev.t_s
                ),
            ));
        }
        poses.push(LocalPose {
            t_s: v[0],
            p_local_m,
            q_local_body: UnitQuaternion::new_normalize(q),
            v_local_mps: None,
        });
        last_line = line_no;
    }
    let Some(frame) = frame else {
        return Err(SimError::LogParse {
            path: path.to_path_buf(),
            line: 1,
            column: 1,
            message: "no pose in the TUM trajectory".into(),
        });
    };
    if poses.len() < 2 {
        return Err(SimError::LogParse {
            path: path.to_path_buf(),
            line: last_line.max(1),
            column: 1,
            message: format!(
                "a TUM trajectory needs at least two poses (its velocity is differenced), found {}",
                poses.len()
            ),
        });
    }
    Ok(rows_from_local(frame, &poses))
}

/// Writes `rows` (t, position, attitude body → NED) as a TUM trajectory in `frame`, with a
/// header comment naming the frame and its origin; `what` says what the poses are.
///
/// # Errors
/// [`SimError::LogIo`] when writing fails (`path` names the file).
pub fn write_tum(
    out: &mut impl Write,
    path: &Path,
    frame: &LocalFrame,
    what: &str,
    rows: impl IntoIterator<Item = (f64, Geodetic, UnitQuaternion<f64>)>,
) -> Result<usize, SimError> {
    let wio = io_err(path);
    let o = frame.origin;
    writeln!(
        out,
        "# {what}: TUM poses `t x y z qx qy qz qw`, t in s; position of the body in the local \
         {} frame (m) with origin lat {:.9}°, lon {:.9}°, alt {:.4} m (WGS-84); rotation body \
         (FRD) → local",
        frame.axes.as_str().to_uppercase(),
        o.lat_rad.to_degrees(),
        o.lon_rad.to_degrees(),
        o.alt_m
    )
    .map_err(&wio)?;
    let c_l_n0 = frame.axes.ned_from_local().transpose();
    let mut count = 0;
    for (t_s, pos, q_n_b) in rows {
        let p = frame.to_local_m(&pos);
        // C_l^b = C_l^n(g) · C_n^b, C_l^n(g) = C_l^n0 · C_n0^e · C_e^n(g).
        let c_l_n = c_l_n0
            * ned_from_ecef(o.lat_rad, o.lon_rad)
            * ned_from_ecef(pos.lat_rad, pos.lon_rad).transpose();
        let q = (quat_of(&c_l_n) * q_n_b).into_inner();
        writeln!(
            out,
            "{t_s:e} {:e} {:e} {:e} {:e} {:e} {:e} {:e}",
            p.x, p.y, p.z, q.i, q.j, q.k, q.w
        )
        .map_err(&wio)?;
        count += 1;
    }
    out.flush().map_err(&wio)?;
    Ok(count)
}
