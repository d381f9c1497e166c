//! `--export-logs DIR`: writes run index 0 of each filter configuration as the logs that
//! `nav-app ins` replays (formats: `nav_app::ins_sd::logs`).

use std::path::Path;

use anyhow::{Context, Result};
use nav_app::ins_sd::logs::{self, names};
use nav_app::ins_sd::{self, Mode};

use super::Resolved;

/// Exports run 0 of KF and AKF into `dir/kf` and `dir/akf` and prints the replay commands.
pub fn export_logs(r: &Resolved, dir: &Path) -> Result<()> {
    for mode in [Mode::Kf, Mode::Akf] {
        let sub = dir.join(mode.name());
        let seed = ins_sd::run_seed(r.seed, mode, 0);
        let (outcome, _) = logs::export_run(&r.scenario, mode, seed, &sub)
            .with_context(|| format!("exporting run 0 ({}) to {}", mode.name(), sub.display()))?;
        let p = |n: &str| sub.join(n).display().to_string();
        println!(
            "monte-carlo: exported run 0 ({}, {} s, seed {seed}) to {}; replay with:\n  cargo run --release -p nav-app -- ins --imu {} --sightings {} --landmarks {} --init {} --config {} --filter {} --out {} --truth {}",
            mode.name(),
            outcome.samples_written.saturating_sub(1),
            sub.display(),
            p(names::IMU),
            p(names::SIGHTINGS),
            p(names::LANDMARKS),
            p(names::INITIAL),
            p(names::SCENARIO),
            mode.name(),
            p("solution.csv"),
            p(names::TRUTH),
        );
    }
    Ok(())
}
