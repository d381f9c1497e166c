//! Static alignment at rest ([`align_at_rest`]): the gyro bias, and roll and pitch, from the
//! first seconds of an IMU log.

use nalgebra::Vector3;

use super::imu::ImuLog;
use super::read::InitialState;
use crate::SimError;

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
}

/// Static alignment over `(t0, t0 + duration_s]` of the IMU log (the samples are read ahead and
/// kept in `imu` for the replay): the mean angular rate less the
/// Earth rate resolved in body axes with `initial`'s attitude is the gyro bias; with `level`, roll
/// and pitch come from the mean specific force f̄ (at rest f = −g in body axes:
/// roll = atan2(−f̄_y, −f̄_z), pitch = atan2(f̄_x, √(f̄_y² + f̄_z²))) and the heading is kept;
/// `initial` is updated in place. The accelerometer bias cannot be told from a tilt at rest and is
/// left to the filter.
///
/// # Errors
/// [`SimError::LogIo`], [`SimError::LogParse`] for a bad record or no sample in the window.
pub fn align_at_rest(
    imu: &mut ImuLog,
    initial: &mut InitialState,
    duration_s: f64,
    level: bool,
) -> Result<Alignment, SimError> {
    let rates = imu.rates()?;
    let (t0, t1) = (initial.t_s, initial.t_s + duration_s);
    let (mut sum_f, mut sum_w, mut sum_dt, mut n) = (Vector3::zeros(), Vector3::zeros(), 0.0, 0u64);
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
            if rates {
                sum_f += rec.a * dt;
                sum_w += rec.b * dt;
            } else {
                sum_f += rec.a;
                sum_w += rec.b;
            }
            sum_dt += dt;
            n += 1;
        }
        prev = t;
    }
    if n == 0 || sum_dt <= 0.0 {
        return Err(imu.parse_err(
            last_line,
            1,
            format!("no IMU sample between t = {t0} s and {t1} s to align on"),
        ));
    }
    let f = sum_f / sum_dt;
    let w = sum_w / sum_dt;
    let mut out = Alignment {
        samples: n,
        mean_specific_force_body_mps2: [f.x, f.y, f.z],
        ..Default::default()
    };
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
