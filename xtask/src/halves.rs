//! `cargo xtask halves`: nav-app's two halves build alone, and the lane half pulls in nothing of
//! the INS half, of V4L2 or of the command line (`cargo tree -p nav-app --no-default-features
//! --features lane` lists none of `ins-errors`, `sighting-model`, `akf`, `ins-sd-filter`, `v4l`,
//! `clap`, nor the Monte Carlo's `rayon` and `plotters`); the INS simulation, crate `ins-sim`
//! (used by the Python package), builds and depends on neither `rayon` nor `plotters`
//! (`cargo tree -p ins-sim -e normal`; they belong to `ins-monte-carlo`).

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

/// Crates the INS simulation (`ins-sim`) must not depend on: the Monte Carlo's pool and figures.
const NOT_IN_INS_SIM: &[&str] = &["rayon", "plotters"];

/// The crates `cargo tree -p PACKAGE -e normal ARGS…` lists (one name per line, no prefix).
fn normal_deps(cargo: &str, package: &str, args: &[&str]) -> Result<Vec<String>> {
    let out = Command::new(cargo)
        .current_dir(workspace_root())
        .args(["tree", "-p", package])
        .args(args)
        .args(["-e", "normal", "--prefix", "none"])
        .output()
        .context("cannot run cargo tree")?;
    if !out.status.success() {
        bail!(
            "cargo tree -p {package} failed: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    Ok(String::from_utf8_lossy(&out.stdout)
        .lines()
        .filter_map(|l| l.split_whitespace().next().map(str::to_owned))
        .collect())
}

/// `forbidden` crates found in `deps`.
fn found_in<'a>(deps: &[String], forbidden: &[&'a str]) -> Vec<&'a str> {
    forbidden
        .iter()
        .copied()
        .filter(|c| deps.iter().any(|d| d == c))
        .collect()
}

/// `ins-sim` depends on neither `rayon` nor `plotters`, and builds cleanly (all targets).
fn check_ins_sim(cargo: &str) -> Result<()> {
    let deps = normal_deps(cargo, "ins-sim", &[])?;
    let found = found_in(&deps, NOT_IN_INS_SIM);
    if !found.is_empty() {
        bail!("ins-sim depends on {}", found.join(", "));
    }
    println!(
        "halves: ins-sim depends on none of {} ({} crates in its tree)",
        NOT_IN_INS_SIM.join(", "),
        deps.len()
    );
    eprintln!("halves: clippy -p ins-sim --all-targets");
    let status = Command::new(cargo)
        .current_dir(workspace_root())
        .args([
            "clippy",
            "-p",
            "ins-sim",
            "--all-targets",
            "--",
            "-D",
            "warnings",
        ])
        .status()
        .context("cannot run cargo clippy")?;
    if !status.success() {
        bail!("ins-sim does not build cleanly");
    }
    Ok(())
}

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
    // The lane half alone and with its evaluation, no binary.
    for half in ["lane", "eval"] {
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
    // The INS half: the simulation without the Monte Carlo's rayon and plotters.
    check_ins_sim(&cargo)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn forbidden_crates_are_found_by_exact_name() {
        let deps: Vec<String> = ["ins-sim", "rayon-core", "plotters", "serde"]
            .map(str::to_owned)
            .to_vec();
        assert_eq!(found_in(&deps, NOT_IN_INS_SIM), vec!["plotters"]);
        assert!(found_in(&deps[..2], NOT_IN_INS_SIM).is_empty());
    }
}
