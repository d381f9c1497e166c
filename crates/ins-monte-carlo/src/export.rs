//! `--export-logs DIR`: writes run index 0 of the KF and the AKF as the logs that `nav-app ins`
//! replays (formats: [`ins_sim::logs`]).

use std::path::{Path, PathBuf};

use super::{McError, Resolved};
use ins_sim::Mode;
use ins_sim::logs::{self, names};

/// One exported run.
#[derive(Clone, Debug)]
pub struct Exported {
    /// Configuration.
    pub mode: Mode,
    /// Its seed (`run_seed(master, 0)`).
    pub seed: u64,
    /// Seconds of flight written.
    pub duration_s: usize,
    /// Directory holding the logs.
    pub dir: PathBuf,
}

impl Exported {
    /// The `nav-app ins` command line that replays these logs.
    pub fn replay_command(&self) -> String {
        let p = |n: &str| self.dir.join(n).display().to_string();
        format!(
            "nav-app ins --imu {} --sightings {} --landmarks {} --init {} --config {} --filter {} --out {} --truth {}",
            p(names::IMU),
            p(names::SIGHTINGS),
            p(names::LANDMARKS),
            p(names::INITIAL),
            p(names::SCENARIO),
            self.mode.name(),
            p("solution.csv"),
            p(names::TRUTH),
        )
    }
}

/// Exports run 0 of KF and AKF into `dir/kf` and `dir/akf`.
pub fn export_logs(r: &Resolved, dir: &Path) -> Result<Vec<Exported>, McError> {
    let mut done = Vec::new();
    for mode in [Mode::Kf, Mode::Akf] {
        let sub = dir.join(mode.name());
        let seed = ins_sim::run_seed(r.seed, 0);
        let (outcome, _) =
            logs::export_run(&r.scenario, mode, seed, &sub).map_err(|source| McError::Export {
                mode: mode.name(),
                dir: sub.clone(),
                source: Box::new(source),
            })?;
        done.push(Exported {
            mode,
            seed,
            duration_s: outcome.samples_written.saturating_sub(1),
            dir: sub,
        });
    }
    Ok(done)
}
