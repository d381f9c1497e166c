//! `cargo xtask halves`: the crate boundaries hold. The numeric lane tracker (`lane-tracker`)
//! depends on no image codec (`image`), no V4L2 (`v4l`), no CLI (`clap`), not on the Monte
//! Carlo's `rayon` and `plotters` and on no INS crate; the lane I/O (`lane-io` without
//! `capture`), the rendered scenes (`lane-scenes`), the benchmark (`lane-bench` without `cli`)
//! and the evaluation (`lane-eval`) on no INS crate, no V4L2, no CLI, no Monte Carlo; the
//! product binary (`nav-app`) not on the evaluation (`lane-eval`);
//! `lane-tracker` and `lane-io` build cleanly alone; the INS simulation, crate `ins-sim` (used by
//! the Python package), builds and depends on neither `rayon` nor `plotters` (they belong to
//! `ins-monte-carlo`); the INS figures, crate `ins-plot` (the replay's error figure), do not
//! depend on the Monte Carlo; the live Foxglove server (`foxglove-live`, shared) depends on no
//! lane or INS crate and on no async runtime, TLS or native code, and only the binary serves
//! live (`lane-io` and `ins-sim`, the libraries the Python package uses, do not depend on it).
//! Each check reads `cargo tree -p CRATE -e normal`.

use std::process::Command;

use anyhow::{Context, Result, bail};

use crate::paths::workspace_root;

/// Crates the numeric lane tracker (`lane-tracker`) must not depend on: image codecs, V4L2, the
/// CLI, the Monte Carlo's pool and figures, the INS crates.
const NOT_IN_LANE_TRACKER: &[&str] = &[
    "image",
    "v4l",
    "clap",
    "rayon",
    "plotters",
    "ins-errors",
    "sighting-model",
    "akf",
    "ins-sd-filter",
    "ins-sim",
];

/// Crates the lane I/O, scenes, benchmark and evaluation (`lane-io` without `capture`,
/// `lane-scenes`, `lane-bench` without `cli`, `lane-eval`) must not depend on.
const NOT_IN_LANE: &[&str] = &[
    "ins-errors",
    "sighting-model",
    "akf",
    "ins-sd-filter",
    "ins-sim",
    "v4l",
    "clap",
    "rayon",
    "plotters",
];

/// Crates the INS simulation (`ins-sim`) must not depend on: the Monte Carlo's pool and figures.
const NOT_IN_INS_SIM: &[&str] = &["rayon", "plotters"];

/// Crates the INS figures (`ins-plot`: the replay's error figure, `nav-app ins --plot`) must not
/// depend on: the Monte Carlo and its pool.
const NOT_IN_INS_PLOT: &[&str] = &["ins-monte-carlo", "rayon"];

/// Crates the live Foxglove server (`foxglove-live`) must not depend on: either half, an async
/// runtime, TLS or native code (it builds on a fresh machine with the toolchain alone).
const NOT_IN_FOXGLOVE_LIVE: &[&str] = &[
    "lane-tracker",
    "lane-io",
    "ins-sd-filter",
    "ins-sim",
    "tokio",
    "rustls",
    "native-tls",
    "openssl-sys",
    "ring",
    "aws-lc-sys",
];

/// Crates the libraries (`lane-io`, `ins-sim`) must not depend on: the live server belongs to
/// the binary, which composes it.
const LIVE_SERVER: &[&str] = &["foxglove-live", "tungstenite"];

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

/// Clippy (`-D warnings`, all targets) on `package` built alone, with `args` (features).
fn clippy_alone(cargo: &str, package: &str, args: &[&str]) -> Result<()> {
    eprintln!("halves: clippy -p {package} {}", args.join(" "));
    let status = Command::new(cargo)
        .current_dir(workspace_root())
        .args(["clippy", "-p", package])
        .args(args)
        .args(["--all-targets", "--", "-D", "warnings"])
        .status()
        .context("cannot run cargo clippy")?;
    if !status.success() {
        bail!("{package} built alone does not build cleanly");
    }
    Ok(())
}

/// `package` (with `args`) depends on none of `forbidden`.
fn check_deps(cargo: &str, package: &str, args: &[&str], forbidden: &[&str]) -> Result<()> {
    let deps = normal_deps(cargo, package, args)?;
    let found = found_in(&deps, forbidden);
    if !found.is_empty() {
        bail!("{package} depends on {}", found.join(", "));
    }
    println!(
        "halves: {package} {}depends on none of {} ({} crates in its tree)",
        if args.is_empty() {
            String::new()
        } else {
            format!("({}) ", args.join(" "))
        },
        forbidden.join(", "),
        deps.len()
    );
    Ok(())
}

/// Run `cargo xtask halves`.
pub fn run() -> Result<()> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".to_owned());
    // The numeric tracker: no image codecs, no device, no CLI, no Monte Carlo, no INS.
    check_deps(&cargo, "lane-tracker", &[], NOT_IN_LANE_TRACKER)?;
    // Its I/O: no INS, no CLI, no Monte Carlo; no V4L2 without the `capture` feature.
    check_deps(&cargo, "lane-io", &["--no-default-features"], NOT_IN_LANE)?;
    for lane_crate in ["lane-scenes", "lane-bench", "lane-eval"] {
        check_deps(&cargo, lane_crate, &[], NOT_IN_LANE)?;
    }
    // The product binary: its sample input and the benchmark, not the evaluation crate.
    check_deps(
        &cargo,
        "nav-app",
        &["--no-default-features"],
        &["lane-eval"],
    )?;
    // The live server: shared, no half, no runtime or TLS; the libraries do not serve.
    check_deps(&cargo, "foxglove-live", &[], NOT_IN_FOXGLOVE_LIVE)?;
    check_deps(&cargo, "lane-io", &["--no-default-features"], LIVE_SERVER)?;
    check_deps(&cargo, "ins-sim", &[], LIVE_SERVER)?;
    clippy_alone(&cargo, "lane-tracker", &[])?;
    clippy_alone(&cargo, "lane-io", &["--no-default-features"])?;
    // The INS half: the simulation without the Monte Carlo's rayon and plotters; the replay's
    // figure without the Monte Carlo.
    check_deps(&cargo, "ins-plot", &[], NOT_IN_INS_PLOT)?;
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
