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

/// Header of the IMU log.
pub const IMU_HEADER: &str =
    "t_s,dv_x_mps,dv_y_mps,dv_z_mps,dtheta_x_rad,dtheta_y_rad,dtheta_z_rad";
/// Header of the sightings log.
pub const SIGHTINGS_HEADER: &str = "t_s,landmark_id,w_m,h_m";
/// Header of an IMU log of rates: angular rate (rad/s) and specific force (m/s²) in body FRD,
/// each row the mean over (previous t, t] (what most IMUs write; the data sets' `imu.csv`).
pub const IMU_RATES_HEADER: &str =
    "t_s,gyro_x_radps,gyro_y_radps,gyro_z_radps,accel_x_mps2,accel_y_mps2,accel_z_mps2";
/// Header of the sightings log with pointing (format 2): the measured line of sight to the
/// landmark, `frame` `body` (FRD) or `ned` (local level), any length > 0.
pub const POINTED_SIGHTINGS_HEADER: &str = "t_s,landmark_id,frame,los_x,los_y,los_z";
/// Header of a reference trajectory in degrees, attitude optional (the data sets' `truth.csv`).
pub const REFERENCE_DEG_HEADER: &str = "t_s,lat_deg,lon_deg,alt_m,vn_mps,ve_mps,vd_mps,qw,qx,qy,qz";
/// Header of the truth log (and the first columns of the solution).
pub const TRUTH_HEADER: &str =
    "t_s,lat_rad,lon_rad,alt_m,vel_n_mps,vel_e_mps,vel_d_mps,q_w,q_x,q_y,q_z";
/// Header of the solution written by the replay and by the export.
pub const SOLUTION_HEADER: &str = "t_s,lat_rad,lon_rad,alt_m,vel_n_mps,vel_e_mps,vel_d_mps,q_w,q_x,q_y,q_z,sigma_n_m,sigma_e_m,sigma_d_m,sigma_vn_mps,sigma_ve_mps,sigma_vd_mps,sigma_psi_n_rad,sigma_psi_e_rad,sigma_psi_d_rad,nis,used,rejected";

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

mod read;
mod reference;
mod replay;
mod request;
mod sightings;
mod write;

pub use read::*;
pub use reference::*;
pub use replay::*;
pub use request::*;
pub use sightings::*;
pub use write::*;
