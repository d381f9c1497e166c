//! `cargo xtask halves`: nav-app's two halves build alone, and the lane half pulls in nothing of
//! the INS half, of V4L2 or of the command line (`cargo tree -p nav-app --no-default-features
//! --features lane` lists none of `ins-errors`, `sighting-model`, `akf`, `ins-sd-filter`, `v4l`,
//! `clap`, nor the Monte Carlo's `rayon` and `plotters`); the INS half builds alone and with the
//! Monte Carlo library (`--features monte-carlo`).

use std::process::Command;

use anyhow::{Context, Result, bail};

use crate::paths::workspace_root;

/// Crates the lane half alone must not depend on.
const NOT_IN_LANE: &[&str] = &[
    "ins-errors",
    "sighting-model",
    "akf",
    "ins-sd-filter",
    "v4l",
    "clap",
    "rayon",
    "plotters",
];

/// Run `cargo xtask halves`.
pub fn run() -> Result<()> {
    let root = workspace_root();
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".to_owned());
    let out = Command::new(&cargo)
        .current_dir(&root)
        .args([
            "tree",
            "-p",
            "nav-app",
            "--no-default-features",
            "--features",
            "lane",
            "-e",
            "normal",
            "--prefix",
            "none",
        ])
        .output()
        .context("cannot run cargo tree")?;
    if !out.status.success() {
        bail!(
            "cargo tree failed: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    let tree = String::from_utf8_lossy(&out.stdout);
    let found: Vec<&str> = NOT_IN_LANE
        .iter()
        .copied()
        .filter(|c| {
            tree.lines()
                .any(|l| l.split_whitespace().next() == Some(*c))
        })
        .collect();
    if !found.is_empty() {
        bail!(
            "nav-app with only the lane half depends on {}",
            found.join(", ")
        );
    }
    println!(
        "halves: the lane half depends on none of {} ({} crates in its tree)",
        NOT_IN_LANE.join(", "),
        tree.lines().count()
    );
    // The INS half alone, and with the Monte Carlo library (rayon, plotters) but no binary.
    for half in ["lane", "eval", "ins", "monte-carlo"] {
        eprintln!("halves: clippy -p nav-app --no-default-features --features {half}");
        let status = Command::new(&cargo)
            .current_dir(&root)
            .args([
                "clippy",
                "-p",
                "nav-app",
                "--no-default-features",
                "--features",
                half,
                "--all-targets",
                "--",
                "-D",
                "warnings",
            ])
            .status()
            .context("cannot run cargo clippy")?;
        if !status.success() {
            bail!("nav-app with only the {half} half does not build cleanly");
        }
    }
    Ok(())
}
