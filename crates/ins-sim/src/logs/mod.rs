//! Log formats of the INS/SD filter, export of a simulated run, sightings written from a
//! reference, and replay through the online filter (`nav-app ins`).
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
//! | IMU, increments | `t_s,dv_x_mps,dv_y_mps,dv_z_mps,dtheta_x_rad,dtheta_y_rad,dtheta_z_rad` | one per IMU sample: time stamp of the end of the sample interval, then the integrated specific force Δv = ∫f̃ dt (m/s) and angle Δθ = ∫ω̃_ib dt (rad) over (previous t, t], body axes FRD; strictly increasing t, any rate and jitter |
//! | IMU, rates | `t_s,gyro_x_radps,gyro_y_radps,gyro_z_radps,accel_x_mps2,accel_y_mps2,accel_z_mps2` | the same as mean angular rate (rad/s) and specific force (m/s²) over (previous t, t] (what most IMUs and the data sets write) |
//! | sightings, format 2 | `t_s,landmark_id,frame,los_x,los_y,los_z` | one per sighting: epoch time, landmark id (in the landmark table), `frame` `body` (FRD) or `ned` (local level), and the measured line of sight to the landmark in that frame (any length > 0): the device's pointing and image offset combined (`sighting_model::pointed`), so any filter predicts it from its own state; rows of one epoch share t; epochs non-decreasing |
//! | sightings, format 1 | `t_s,landmark_id,w_m,h_m` | the paper's offsets w (image right), h (image down) of the landmark from the image centre, m at the landmark, with the camera pointed by the recording INS's own position and attitude: still read, but meaningful only to the filter that recorded them (the replay says so) |
//! | truth / reference | `t_s,lat_rad,lon_rad,alt_m,vel_n_mps,vel_e_mps,vel_d_mps,q_w,q_x,q_y,q_z` or `t_s,lat_deg,lon_deg,alt_m,vn_mps,ve_mps,vd_mps,qw,qx,qy,qz` | navigation state (WGS-84 geodetic, NED velocity, body→NED quaternion) at any increasing times; in the degrees form the four quaternion fields may all be empty (no attitude) |
//! | solution (output) | the truth header plus `,sigma_n_m,sigma_e_m,sigma_d_m,sigma_vn_mps,sigma_ve_mps,sigma_vd_mps,sigma_psi_n_rad,sigma_psi_e_rad,sigma_psi_d_rad,nis,used,rejected` | the navigation solution at every IMU sample, at a rate, or after each epoch ([`SolutionRate`]), with the 1σ of its position, velocity and attitude (ψ) errors from P at that time (empty without an estimator); `nis`, `used`, `rejected` after an epoch, empty otherwise |
//!
//! An EuRoC/ASL folder is read as an IMU log (`imu0/data.csv`, rotated by `T_BS`) and as a
//! reference (its ground truth), and a TUM trajectory as a reference, both in a local frame
//! given by its geodetic origin and axes: modules [`asl`] and [`local`] ([`asl_imu_file`],
//! [`read_reference_in`], [`LocalFrame`]) document the stamps, units and axes converted.
//!
//! The landmark table is TOML, one `[[landmarks]]` table per landmark with `id` (integer),
//! `lat_deg`, `lon_deg` (WGS-84, degrees) and `alt_m` (above the ellipsoid, m). The INS's
//! initial state is TOML too: `t_s`, `lat_rad`, `lon_rad`, `alt_m`, `vel_ned_mps = [n, e, d]`,
//! `att_quat_wxyz = [w, x, y, z]` (body FRD → NED), or is taken from the reference
//! ([`initial_from_reference`]). The filter's settings come from a filter file
//! ([`crate::filter_file`]) or, the older way, a scenario's `[filter]` ([`FilterSettings`]).
//!
//! ## Replay
//!
//! [`replay`] reads the IMU log ([`ImuLog`], opened once per replay) sample by sample and hands
//! each to the online filter
//! ([`ins_sd_filter::InsSdFilter`]); a sighting epoch is applied at its own time (the sample that
//! spans it is cut there), gaps are bridged ([`GAP_FACTOR`]), the solution is written at the
//! requested rate and compared with a reference on the way ([`ReplayMetrics`]); an optional
//! static alignment ([`align_at_rest`]) takes the gyro bias (and without a reference attitude,
//! roll and pitch) from a rest period, after checking the rest ([`AlignLimits`]). Inputs that do
//! not overlap in time, and a filter that used no sighting unless allowed, are refused naming
//! each file's span ([`InputSpan`]); the rows not used are counted ([`UnusedRows`]). [`ReplayRequest`] turns what a user gives (`nav-app ins`,
//! the Python package) into [`ReplayInputs`]. Every malformed field, short line or filter
//! rejection is an error naming the file, the line (1-based) and the column (1-based start of
//! the field).
//!
//! ## Sightings from a reference
//!
//! [`write_sightings`] writes a format-2 sightings log from a reference trajectory and a
//! landmark table (σ, period, ranges, field of regard, seed); [`landmarks_around`] places a
//! seeded table around a reference (`nav-app ins sightings`).
//!
//! ## Export
//!
//! [`export_run`] simulates one run of a scenario (exactly [`super::run`]'s run) and writes the
//! logs its filter saw, the truth, and the solution the simulated filter computed. The
//! sightings are written in format 2 (the simulated offsets as body directions through the
//! pointing of the simulated INS, `sighting_model::los_from_offsets`), so any filter can replay
//! them; the same filter reproduces the simulated solution to round-off
//! (`tests/ins_sd_replay.rs`).

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

mod align;
pub mod asl;
pub mod chi2_band;
mod csv;
mod imu;
pub mod local;
mod mcap_out;
mod metrics;
mod read;
mod reference;
mod replay;
mod request;
mod sightings;
mod spans;
mod write;

pub use align::*;
pub use asl::{
    ASL_IMU_NAMES, ASL_TRUTH_NAMES, asl_body_from_imu, asl_imu_file, check_rotation,
    read_sensor_yaml,
};
pub use imu::{ImuLog, imu_nominal_step_s, is_bag};
pub use local::{LocalAxes, LocalFrame, write_tum};
pub use mcap_out::{
    EPOCHS_CHANNEL, ERRORS_CHANNEL, FIX_CHANNEL, InsMcapSink, ReplayTap, SOLUTION_CHANNEL,
    ins_channels,
};
pub use metrics::*;
pub use read::*;
pub use reference::*;
pub use replay::*;
pub use request::*;
pub use sightings::*;
pub use spans::*;
pub use write::*;
