//! `cargo xtask regress`: the lane regression (`lane_eval::regress`) on the workspace's fixtures.

use anyhow::{Result, bail};
use lane_tracker::Estimator;

use crate::paths::workspace_root;

/// Arguments of `cargo xtask regress`.
#[derive(clap::Args, Debug)]
pub struct RegressArgs {
    /// Write the figures of this run as the expectations instead of comparing.
    #[arg(long)]
    record: bool,
    /// Estimator to run (the expectations are recorded for kif).
    #[arg(long, default_value = "kif")]
    estimator: String,
}

/// Run `cargo xtask regress`.
pub fn run(args: RegressArgs) -> Result<()> {
    let estimator = match args.estimator.as_str() {
        "kif" => Estimator::Kif,
        "wrls" => Estimator::Wrls,
        other => bail!("--estimator must be kif or wrls, got {other}"),
    };
    let outcome = lane_eval::regress::run(&workspace_root(), estimator, args.record)?;
    print!("{}", outcome.report);
    for f in &outcome.failures {
        println!("regress: REGRESSION {f}");
    }
    if !outcome.failures.is_empty() {
        bail!("{} regression(s)", outcome.failures.len());
    }
    Ok(())
}
