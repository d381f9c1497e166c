//! `cargo xtask`: project chores, reached through the cargo alias in `.cargo/config.toml`.
//!
//! `cargo xtask test` is the project's one test command (the README's and `.ci/run`'s).

use std::process::Command;

use anyhow::{Context, Result, bail};
use clap::{Parser, Subcommand};

mod fixtures;
mod monte_carlo;
mod regress;
mod vivid;

#[derive(Parser)]
#[command(name = "cargo xtask", about = "Project chores")]
struct Cli {
    #[command(subcommand)]
    cmd: Cmd,
}

#[derive(Subcommand)]
enum Cmd {
    /// Every check CI runs: formatting, clippy with warnings denied, all tests and doc tests.
    Test,
    /// Boot Debian's kernel under qemu with the vivid V4L2 driver and run the capture cases.
    Vivid(vivid::VividArgs),
    /// Render the synthetic lane sequences with ground truth into fixtures/synthetic/.
    Fixtures(fixtures::FixturesArgs),
    /// Run the lane tracker over every fixture and compare with the recorded expectations.
    Regress(regress::RegressArgs),
    /// The paper's Monte Carlo experiment (stand-alone, KF, AKF): summaries, CSV, Figs. 1–6; `merge` combines shards.
    MonteCarlo(monte_carlo::MonteCarloArgs),
}

fn main() -> Result<()> {
    match Cli::parse().cmd {
        Cmd::Test => test(),
        Cmd::Vivid(args) => vivid::run(args),
        Cmd::Fixtures(args) => fixtures::run(args),
        Cmd::Regress(args) => regress::run(args),
        Cmd::MonteCarlo(args) => monte_carlo::run(args),
    }
}

/// One step of the test gate: a name and a cargo invocation.
struct Step {
    name: &'static str,
    args: &'static [&'static str],
}

const STEPS: &[Step] = &[
    Step {
        name: "fmt",
        args: &["fmt", "--all", "--", "--check"],
    },
    Step {
        name: "clippy",
        args: &[
            "clippy",
            "--workspace",
            "--all-targets",
            "--",
            "-D",
            "warnings",
        ],
    },
    Step {
        name: "test",
        args: &["test", "--workspace", "--all-targets"],
    },
    Step {
        name: "doctest",
        args: &["test", "--workspace", "--doc"],
    },
];

fn test() -> Result<()> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".to_owned());
    let mut failed = Vec::new();
    for step in STEPS {
        eprintln!("xtask: {} — cargo {}", step.name, step.args.join(" "));
        let status = Command::new(&cargo)
            .args(step.args)
            .status()
            .with_context(|| format!("could not start cargo for step `{}`", step.name))?;
        if !status.success() {
            failed.push(step.name);
        }
    }
    let passed = STEPS.len() - failed.len();
    println!("xtask: {passed} passed, {} failed", failed.len());
    if !failed.is_empty() {
        bail!("failed steps: {}", failed.join(", "));
    }
    Ok(())
}
