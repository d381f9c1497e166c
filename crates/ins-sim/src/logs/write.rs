//! Writing the logs: navigation and solution rows, and the export of a simulated run
//! ([`export_run`]) through a [`RunObserver`] that records what the closed loop sees.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use ins_errors::strapdown::NavState;
use ins_sd_filter::{InsSdFilter, Sighting, UpdateReport};
use nalgebra::{Vector2, Vector3};
use sighting_model::NavPose;

use super::csv::io_err;
use super::read::{InitialState, LandmarkFile};
use super::{IMU_HEADER, POINTED_SIGHTINGS_HEADER, SOLUTION_HEADER, TRUTH_HEADER, names};
use crate::engine::{self, RunObserver};
use crate::{Mode, Sample, Scenario, SimError, SimRunOutcome};

pub(super) fn write_nav<W: Write + ?Sized>(
    w: &mut W,
    t_s: f64,
    s: &NavState,
) -> std::io::Result<()> {
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

/// Writes the solution row of the filter at `t_s`: the navigation solution, the 1σ of the
/// position, velocity and attitude errors from P at that time (empty without an estimator), and,
/// after an epoch (`report`), its NIS, used and rejected counts (empty otherwise).
pub(super) fn write_solution<W: Write + ?Sized>(
    w: &mut W,
    t_s: f64,
    filter: &InsSdFilter,
    report: Option<&UpdateReport>,
) -> std::io::Result<()> {
    write_nav(w, t_s, &filter.navigation_solution())?;
    match filter.predicted() {
        Some((_, p)) => {
            for i in 0..9 {
                write!(w, ",{:e}", p[(i, i)].max(0.0).sqrt())?;
            }
        }
        None => write!(w, ",,,,,,,,,")?,
    }
    match report {
        Some(r) => {
            let nis = r.nis.map(|v| format!("{v:e}")).unwrap_or_default();
            writeln!(w, ",{nis},{},{}", r.used, r.rejected)
        }
        None => writeln!(w, ",,,"),
    }
}

/// The observer that writes a simulated run as logs.
pub(super) struct LogWriter {
    pub(super) dir: PathBuf,
    pub(super) imu: BufWriter<File>,
    pub(super) sightings: BufWriter<File>,
    pub(super) truth: BufWriter<File>,
    pub(super) solution: BufWriter<File>,
    pub(super) step_s: f64,
    pub(super) initial: Option<InitialState>,
    pub(super) pointing: Option<NavPose>,
    pub(super) error: Option<SimError>,
}

impl LogWriter {
    pub(super) fn create(dir: &Path, step_s: f64) -> Result<Self, SimError> {
        std::fs::create_dir_all(dir).map_err(io_err(dir))?;
        let open = |name: &str, header: &str| -> Result<BufWriter<File>, SimError> {
            let path = dir.join(name);
            let mut w = BufWriter::new(File::create(&path).map_err(io_err(&path))?);
            writeln!(w, "{header}").map_err(io_err(&path))?;
            Ok(w)
        };
        Ok(Self {
            dir: dir.to_path_buf(),
            imu: open(names::IMU, IMU_HEADER)?,
            sightings: open(names::SIGHTINGS, POINTED_SIGHTINGS_HEADER)?,
            truth: open(names::TRUTH, TRUTH_HEADER)?,
            solution: open(names::SOLUTION, SOLUTION_HEADER)?,
            step_s,
            initial: None,
            pointing: None,
            error: None,
        })
    }

    pub(super) fn keep(&mut self, name: &str, r: std::io::Result<()>) {
        if let (Err(source), None) = (r, &self.error) {
            self.error = Some(SimError::LogIo {
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

    fn before_epoch(&mut self, filter: &InsSdFilter) {
        self.pointing = Some(filter.pointing_pose());
    }

    fn epoch(&mut self, t_s: f64, sightings: &[Sighting], filter: &InsSdFilter) {
        // The offsets the simulated device measured with the camera pointed by this filter's
        // INS, written as body directions (format 2): any filter can replay them.
        for s in sightings {
            let u = match (
                self.pointing.as_ref(),
                filter.landmarks().get(s.landmark_id),
            ) {
                (Some(pose), Some(lm)) => {
                    sighting_model::los_from_offsets(pose, lm, &Vector2::new(s.w_m, s.h_m))
                        .map_err(|source| SimError::Sighting { t_s, source })
                }
                _ => Err(SimError::ReferenceSpan {
                    t_s,
                    what: "sighting epoch without the pointing pose or landmark",
                }),
            };
            let r = match u {
                Ok(u) => writeln!(
                    self.sightings,
                    "{:e},{},body,{:e},{:e},{:e}",
                    t_s, s.landmark_id, u.x, u.y, u.z
                ),
                Err(e) => {
                    if self.error.is_none() {
                        self.error = Some(e);
                    }
                    Ok(())
                }
            };
            self.keep(names::SIGHTINGS, r);
        }
        let r = write_solution(&mut self.solution, t_s, filter, Some(filter.last_report()));
        self.keep(names::SOLUTION, r);
    }

    fn truth(&mut self, t_s: f64, truth: &NavState) {
        let r = write_nav(&mut self.truth, t_s, truth).and_then(|_| writeln!(self.truth));
        self.keep(names::TRUTH, r);
    }
}

pub(super) fn ser_err(path: &Path) -> impl Fn(toml::ser::Error) -> SimError + '_ {
    move |source| SimError::LogWrite {
        path: path.to_path_buf(),
        source,
    }
}

pub(super) fn write_text(path: &Path, text: &str) -> Result<(), SimError> {
    std::fs::write(path, text).map_err(io_err(path))
}

/// Simulates run `seed` of `scenario` in `mode` (a filter mode) and writes its logs into `dir`
/// ([`names`]): IMU, sightings, truth, landmark table, initial state, the scenario, and the
/// simulated filter's own solution. Returns the run's outcome and 1 Hz records.
///
/// # Errors
/// [`SimError::ExportRun`] when the simulation fails, [`SimError::LogIo`] or
/// [`SimError::LogWrite`] when a file cannot be written or serialised.
pub fn export_run(
    scenario: &Scenario,
    mode: Mode,
    seed: u64,
    dir: &Path,
) -> Result<(SimRunOutcome, Vec<Sample>), SimError> {
    let mut w = LogWriter::create(dir, scenario.trajectory.step_s)?;
    let mut out = vec![Sample::default(); scenario.samples_per_run()];
    let outcome = engine::run_observed(scenario, mode, seed, &mut out, &mut w).map_err(|e| {
        SimError::ExportRun {
            source: Box::new(e),
        }
    })?;
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
