//! Static alignment at rest ([`align_at_rest`]): the gyro bias, and roll and pitch, from the
//! first seconds of an IMU log, after checking that the vehicle is at rest over them
//! ([`AlignLimits`]).

use std::path::Path;

use nalgebra::Vector3;

use super::imu::ImuLog;
use super::read::InitialState;
use super::reference::{ReferenceRow, interpolate};
use crate::SimError;

/// Length of the blocks whose means the rest check compares, s: long enough to average out
/// sensor noise and engine or rotor vibration (tens of hertz and up), short against a vehicle's
/// turns, accelerations and braking (seconds).
pub const ALIGN_BLOCK_S: f64 = 1.0;

/// The rest check of a static alignment: the largest spread allowed over the window (filter
/// file section `[align]`, [`crate::filter_file`], where the defaults are justified).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct AlignLimits {
    /// Largest standard deviation of the accelerometer's [`ALIGN_BLOCK_S`] means, any axis,
    /// m/s².
    pub max_accel_spread_mps2: f64,
    /// Largest standard deviation of the gyro's [`ALIGN_BLOCK_S`] means, any axis, °/s.
    pub max_gyro_spread_deg_per_s: f64,
    /// Largest speed of the reference over the window (when there is one), m/s.
    pub max_speed_mps: f64,
}

impl Default for AlignLimits {
    /// 0.05 m/s², 0.25 °/s, 0.3 m/s (the filter file's defaults).
    fn default() -> Self {
        Self {
            max_accel_spread_mps2: 0.05,
            max_gyro_spread_deg_per_s: 0.25,
            max_speed_mps: 0.3,
        }
    }
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
    /// The accelerometer's spread: the largest per-axis standard deviation of its
    /// [`ALIGN_BLOCK_S`] means over the window, m/s².
    pub accel_spread_mps2: f64,
    /// The gyro's spread, likewise, rad/s.
    pub gyro_spread_radps: f64,
    /// The reference's largest speed over the window, m/s (with a reference).
    pub reference_max_speed_mps: Option<f64>,
}

/// Per-axis running sums of block means: the standard deviation of the means, largest axis.
#[derive(Default)]
struct BlockSpread {
    n: u64,
    sum: [Vector3<f64>; 2],
    sum2: [Vector3<f64>; 2],
}

impl BlockSpread {
    fn add(&mut self, mean_f: Vector3<f64>, mean_w: Vector3<f64>) {
        self.n += 1;
        for (k, m) in [mean_f, mean_w].into_iter().enumerate() {
            self.sum[k] += m;
            self.sum2[k] += m.component_mul(&m);
        }
    }

    /// (accelerometer, gyro) spreads; `None` with fewer than two blocks.
    fn spreads(&self) -> Option<(f64, f64)> {
        if self.n < 2 {
            return None;
        }
        let n = self.n as f64;
        let sd = |k: usize| {
            let mean = self.sum[k] / n;
            let var = (self.sum2[k] - mean.component_mul(&mean) * n) / (n - 1.0);
            var.map(|v| v.max(0.0).sqrt()).max()
        };
        Some((sd(0), sd(1)))
    }
}

/// The reference's largest speed over `[t0, t1]`: the rows inside, and the reference
/// interpolated at both ends; `None` when the reference does not cover the window.
fn reference_max_speed_mps(rows: &[ReferenceRow], t0: f64, t1: f64) -> Option<f64> {
    let mut cursor = 0;
    let ends = [t0, t1]
        .map(|t| interpolate(rows, t, f64::INFINITY, &mut cursor).map(|r| r.vel_ned_mps.norm()));
    let [Some(a), Some(b)] = ends else {
        return None;
    };
    Some(
        rows.iter()
            .filter(|r| r.t_s > t0 && r.t_s < t1)
            .map(|r| r.vel_ned_mps.norm())
            .fold(a.max(b), f64::max),
    )
}

/// The rest check ([`align_at_rest`]): the first quantity over its limit, as an error.
fn check_rest(
    path: &Path,
    (t0_s, t1_s): (f64, f64),
    a: &Alignment,
    limits: &AlignLimits,
) -> Result<(), SimError> {
    let refuse = |quantity: &'static str, measured: f64, limit: f64, field, unit| {
        Err(SimError::NotAtRest {
            path: path.to_path_buf(),
            t0_s,
            t1_s,
            quantity,
            measured,
            limit,
            field,
            unit,
        })
    };
    // A NaN (a non-finite sample) is over any limit.
    let over = |v: f64, limit: f64| v.is_nan() || v > limit;
    if let Some(v) = a.reference_max_speed_mps
        && over(v, limits.max_speed_mps)
    {
        return refuse(
            "the reference's speed reaches",
            v,
            limits.max_speed_mps,
            "max_speed_mps",
            "m/s",
        );
    }
    if over(
        a.gyro_spread_radps.to_degrees(),
        limits.max_gyro_spread_deg_per_s,
    ) {
        return refuse(
            "the gyro's spread (largest per-axis standard deviation of its 1-s means) is",
            a.gyro_spread_radps.to_degrees(),
            limits.max_gyro_spread_deg_per_s,
            "max_gyro_spread_deg_per_s",
            "°/s",
        );
    }
    if over(a.accel_spread_mps2, limits.max_accel_spread_mps2) {
        return refuse(
            "the accelerometer's spread (largest per-axis standard deviation of its 1-s means) is",
            a.accel_spread_mps2,
            limits.max_accel_spread_mps2,
            "max_accel_spread_mps2",
            "m/s²",
        );
    }
    Ok(())
}

/// Static alignment over `(t0, t0 + duration_s]` of the IMU log (the samples are read ahead and
/// kept in `imu` for the replay).
///
/// First the vehicle must be at rest over the window (`limits`): the window is cut into
/// [`ALIGN_BLOCK_S`] blocks (a shorter last block is averaged but not judged; at least two whole
/// blocks are needed), and the standard deviation of the block means, per axis, must stay within
/// the accelerometer's and the gyro's limits; with a `reference`, its speed over the window
/// within `max_speed_mps`. Otherwise the alignment is refused ([`SimError::NotAtRest`]): a
/// moving vehicle's turns would be taken as gyro bias, and its accelerations as tilt.
///
/// Then the mean angular rate less the Earth rate resolved in body axes with `initial`'s
/// attitude is the gyro bias; with `level`, roll and pitch come from the mean specific force f̄
/// (at rest f = −g in body axes: roll = atan2(−f̄_y, −f̄_z), pitch = atan2(f̄_x, √(f̄_y² + f̄_z²)))
/// and the heading is kept; `initial` is updated in place. The accelerometer bias cannot be
/// told from a tilt at rest and is left to the filter.
///
/// # Errors
/// [`SimError::LogIo`], [`SimError::LogParse`] for a bad record, no sample in the window or a
/// window shorter than two blocks; [`SimError::NotAtRest`].
pub fn align_at_rest(
    imu: &mut ImuLog,
    initial: &mut InitialState,
    duration_s: f64,
    level: bool,
    limits: &AlignLimits,
    reference: Option<&[ReferenceRow]>,
) -> Result<Alignment, SimError> {
    let rates = imu.rates()?;
    let (t0, t1) = (initial.t_s, initial.t_s + duration_s);
    let whole_blocks = (duration_s / ALIGN_BLOCK_S + 1e-9).floor() as u64;
    let (mut sum_f, mut sum_w, mut sum_dt, mut n) = (Vector3::zeros(), Vector3::zeros(), 0.0, 0u64);
    // The current block: its index and sums.
    let (mut block, mut bf, mut bw, mut bdt) = (0u64, Vector3::zeros(), Vector3::zeros(), 0.0);
    let mut spread = BlockSpread::default();
    let mut prev = f64::NAN;
    let mut last_line = 1;
    // Read ahead, not taken: the replay propagates these samples too.
    let mut ahead = 0;
    while let Some(rec) = imu.peek(ahead)? {
        ahead += 1;
        let t = rec.t_s;
        last_line = rec.line;
        if t > t1 {
            break;
        }
        if t > t0 && prev.is_finite() && t > prev {
            let dt = t - prev;
            let (df, dw) = if rates {
                (rec.a * dt, rec.b * dt)
            } else {
                (rec.a, rec.b)
            };
            sum_f += df;
            sum_w += dw;
            sum_dt += dt;
            n += 1;
            // The sample belongs to the block its end falls in.
            let k = (((t - t0) / ALIGN_BLOCK_S) - 1e-9).floor().max(0.0) as u64;
            if k != block {
                if block < whole_blocks && bdt > 0.0 {
                    spread.add(bf / bdt, bw / bdt);
                }
                (block, bf, bw, bdt) = (k, Vector3::zeros(), Vector3::zeros(), 0.0);
            }
            bf += df;
            bw += dw;
            bdt += dt;
        }
        prev = t;
    }
    if block < whole_blocks && bdt > 0.0 {
        spread.add(bf / bdt, bw / bdt);
    }
    if n == 0 || sum_dt <= 0.0 {
        return Err(imu.parse_err(
            last_line,
            1,
            format!("no IMU sample between t = {t0} s and {t1} s to align on"),
        ));
    }
    let Some((accel_spread_mps2, gyro_spread_radps)) = spread.spreads() else {
        return Err(imu.parse_err(
            last_line,
            1,
            format!(
                "the alignment window t = {t0} s to {t1} s holds fewer than two whole {ALIGN_BLOCK_S} s blocks of IMU samples: the rest check needs at least two (align over 2 s or more)"
            ),
        ));
    };
    let f = sum_f / sum_dt;
    let w = sum_w / sum_dt;
    let mut out = Alignment {
        samples: n,
        mean_specific_force_body_mps2: [f.x, f.y, f.z],
        accel_spread_mps2,
        gyro_spread_radps,
        reference_max_speed_mps: reference.and_then(|r| reference_max_speed_mps(r, t0, t1)),
        ..Default::default()
    };
    check_rest(imu.path(), (t0, t1), &out, limits)?;
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
