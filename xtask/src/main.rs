//! `cargo xtask`: project chores, reached through the cargo alias in `.cargo/config.toml`.
//!
//! `cargo xtask test` is the project's one test command (the README's and `.ci/run`'s).

use std::process::Command;
use std::time::{Duration, Instant};

use anyhow::{Context, Result, bail};
use clap::{Parser, Subcommand};

mod ablation;
mod eval_lanes;
mod fixtures;
mod halves;
mod ins_real;
mod monte_carlo;
mod packages;
mod paths;
mod python;
mod readme;
mod regress;
mod resample_lanes;

#[derive(Parser)]
#[command(
    name = "cargo xtask",
    about = "Project chores",
    after_help = "With no subcommand this help is printed and nothing runs; `cargo xtask test` is the \
                  project's one test command, `cargo xtask monte-carlo` its main job (the \
                  product binary's `nav-app monte-carlo` on configs/paper.toml when no --config \
                  is given).\n\n\
                  Exit codes: 0 success; 1 a command or a gate step failed (the gate names every \
                  failed step); 2 bad command line."
)]
struct Cli {
    #[command(subcommand)]
    cmd: Cmd,
}

#[derive(Subcommand)]
enum Cmd {
    /// Every check CI runs: formatting, clippy with warnings denied, all tests and doc tests,
    /// the lane regression, the real-data lane evaluation and the vivid V4L2 VM test.
    Test,
    /// Install the system packages a full build and the tests need (Debian `libclang-dev` for
    /// V4L2 capture, `ffmpeg` for video inputs).
    Setup,
    /// Boot Debian's kernel under qemu with the vivid V4L2 driver and run the capture cases:
    /// installs the host packages, then runs `cargo run -p vivid-vm -- ARGS` (`--help` there).
    Vivid {
        /// Passed to `vivid-vm` as they are (`--case NAME`, `--guest-bin PATH`, `--verbose`…).
        #[arg(trailing_var_arg = true, allow_hyphen_values = true)]
        args: Vec<String>,
    },
    /// Render the synthetic lane sequences with ground truth into fixtures/synthetic/.
    Fixtures(fixtures::FixturesArgs),
    /// Run the lane tracker over every fixture and compare with the recorded expectations.
    Regress(regress::RegressArgs),
    /// `nav-app eval-lanes` on the real labelled sets (--data, default ../shared/data/lanes) with
    /// the OpenCV peer beside it; writes summary.md, summary.json, frames.csv and a contact sheet
    /// of the worst frames into target/eval-lanes.
    EvalLanes(eval_lanes::EvalLanesCmd),
    /// `nav-app import-lanes`: a labelled set in TuSimple's or CULane's format as a labels.json
    /// that eval-lanes scores (`--data` its parent directory); the images stay where they are.
    ImportLanes(lane_bench::cli::ImportLanesArgs),
    /// Each lane mechanism beyond the paper off in turn and at other values, per labelled set,
    /// with its leave-one-set-out gain; writes target/ablation/ablation.md.
    Ablation(ablation::AblationArgs),
    /// Write the labelled sets enlarged K times (frames bicubic, labels mapped) into
    /// target/lanes-{K}x, for `eval-lanes --data` at another resolution.
    ResampleLanes(resample_lanes::ResampleLanesArgs),
    /// Check the crate boundaries: lane-tracker pulls in no image codec, V4L2, CLI, Monte Carlo or
    /// INS crate; lane-io, lane-scenes, lane-bench and lane-eval no INS, V4L2, CLI or Monte Carlo
    /// crate; nav-app not lane-eval; ins-sim neither rayon nor plotters.
    Halves,
    /// Every command the README shows, run as written (but `cargo xtask test` itself and the
    /// Python install, which the `python` step does in its own environment).
    Readme,
    /// Build the `ita_nav` Python wheel into target/py-venv and run its pytest suite.
    Python(python::PythonArgs),
    /// The INS/SD paper's Monte Carlo (stand-alone, KF, AKF) on configs/paper.toml: builds the
    /// product binary and runs `nav-app monte-carlo …` (arguments passed through; outputs under
    /// target/monte-carlo/).
    MonteCarlo(monte_carlo::MonteCarloArgs),
    /// The INS/SD filter on the real IMU logs (--data, default ../shared/data/ins) through
    /// `nav-app ins`: unaided, KF and AKF with the mems and paper presets; writes summary.md,
    /// the metrics and the KF's error plots into target/ins-real/.
    InsReal(ins_real::InsRealArgs),
}

fn main() -> Result<()> {
    match Cli::parse().cmd {
        Cmd::Test => test(),
        Cmd::Setup => packages::ensure_test_packages(),
        Cmd::Vivid { args } => vivid(&args),
        Cmd::Fixtures(args) => fixtures::run(args),
        Cmd::Regress(args) => regress::run(args),
        Cmd::EvalLanes(args) => eval_lanes::run(args),
        Cmd::Ablation(args) => ablation::run(args),
        Cmd::ImportLanes(args) => eval_lanes::import(args),
        Cmd::ResampleLanes(args) => resample_lanes::run(args),
        Cmd::Python(args) => python::run(args),
        Cmd::Readme => readme::run(),
        Cmd::Halves => halves::run(),
        Cmd::MonteCarlo(args) => monte_carlo::run(args),
        Cmd::InsReal(args) => ins_real::run(args),
    }
}

/// What one step of the test gate runs.
enum Run {
    /// `cargo <args>`.
    Cargo(&'static [&'static str]),
    /// This xtask binary again, `cargo xtask <args>` (in release, like the alias).
    Xtask(&'static [&'static str]),
}

/// One step of the test gate: a name and what it runs.
struct Step {
    name: &'static str,
    run: Run,
}

/// The test gate, in order. Steps run even when an earlier one failed, so one CI run reports all.
const STEPS: &[Step] = &[
    Step {
        name: "fmt",
        run: Run::Cargo(&["fmt", "--all", "--", "--check"]),
    },
    Step {
        name: "clippy",
        run: Run::Cargo(&[
            "clippy",
            "--workspace",
            "--all-targets",
            "--all-features",
            "--",
            "-D",
            "warnings",
        ]),
    },
    Step {
        name: "test",
        run: Run::Cargo(&["test", "--workspace", "--all-targets", "--all-features"]),
    },
    Step {
        // The build a user without libclang gets: `--device` must say capture is not built in.
        // `-p nav-app` alone, its dependencies' features unified for nav-app only: they are
        // compiled again here (2026-12-02: 4 min 29 s of the 2-core gate), but the Python
        // step's wheel then reuses them (3 min 42 s). With `--workspace --no-default-features`
        // and only nav-app's `cli` and `capture_cli` tests this step took 2 min 45 s and the
        // Python step 7 min 04 s, its wheel compiling them itself: 2 min more in all.
        name: "test-no-capture",
        run: Run::Cargo(&["test", "-p", "nav-app", "--no-default-features"]),
    },
    Step {
        // The crate boundaries: the lane crates and ins-sim pull in nothing they must not.
        name: "halves",
        run: Run::Xtask(&["halves"]),
    },
    Step {
        name: "doctest",
        run: Run::Cargo(&["test", "--workspace", "--doc", "--all-features"]),
    },
    Step {
        // The API docs build, every intra-doc link resolving (workspace rustdoc lints: deny).
        name: "doc",
        run: Run::Cargo(&["doc", "--workspace", "--no-deps", "--all-features"]),
    },
    Step {
        name: "regress",
        run: Run::Xtask(&["regress"]),
    },
    Step {
        // Every command the README shows, as written: the main job, the lane examples, the
        // tracker's default on the real labelled sets against the recorded floors
        // (`eval-lanes --check --perturb`, which was a step of its own without --perturb: about
        // 30 s, 18 s of it the perturbations), the INS examples.
        name: "readme",
        run: Run::Xtask(&["readme"]),
    },
    Step {
        // The Python package: wheel built by maturin, pytest against the nav-app binary.
        name: "python",
        run: Run::Xtask(&["python"]),
    },
    Step {
        name: "vivid",
        run: Run::Xtask(&["vivid"]),
    },
];

/// `cargo xtask test`: the README's test command and `.ci/run`'s.
///
/// First makes sure the system packages the workspace build and tests need are present (Debian
/// `libclang-dev`, for the `v4l` crate's bindgen step, and `ffmpeg`, for video inputs; installed
/// with apt-get when missing and running as root or under CI with passwordless sudo), then runs
/// every step, printing each one's wall time as it ends, and closes with a table of the steps'
/// wall times (`timing_table`) and one `xtask: N passed, M failed` line.
fn test() -> Result<()> {
    packages::ensure_test_packages()
        .context("the workspace build and tests need libclang-dev and ffmpeg (Debian)")?;
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".to_owned());
    let this = std::env::current_exe().context("cannot locate the xtask binary")?;
    let mut failed = Vec::new();
    let mut timings = Vec::with_capacity(STEPS.len());
    let gate_start = Instant::now();
    for step in STEPS {
        let (program, args) = match &step.run {
            Run::Cargo(args) => (std::ffi::OsStr::new(&cargo), *args),
            Run::Xtask(args) => (this.as_os_str(), *args),
        };
        eprintln!(
            "xtask: {} — {} {}",
            step.name,
            program.to_string_lossy(),
            args.join(" ")
        );
        let mut command = Command::new(program);
        command.args(args);
        // A CI run builds everything once: incremental caches would only take disk (gigabytes
        // over the gate's profiles), never time. A user's own setting wins.
        if std::env::var_os("CI").is_some() && std::env::var_os("CARGO_INCREMENTAL").is_none() {
            command.env("CARGO_INCREMENTAL", "0");
        }
        let step_start = Instant::now();
        let status = command
            .status()
            .with_context(|| format!("could not start step `{}`", step.name))?;
        let took = step_start.elapsed();
        if status.success() {
            eprintln!("xtask: step `{}` passed in {}", step.name, wall_time(took));
        } else {
            eprintln!(
                "xtask: step `{}` FAILED ({status}) after {}",
                step.name,
                wall_time(took)
            );
            failed.push(step.name);
        }
        timings.push((step.name, took));
    }
    eprint!("{}", timing_table(&timings, gate_start.elapsed()));
    let passed = STEPS.len() - failed.len();
    println!("xtask: {passed} passed, {} failed", failed.len());
    if !failed.is_empty() {
        bail!("failed steps: {}", failed.join(", "));
    }
    Ok(())
}

/// `cargo xtask vivid ARGS`: the VM test's host packages, then the `vivid-vm` tool with `ARGS`.
fn vivid(args: &[String]) -> Result<()> {
    packages::ensure_vivid_packages()?;
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".to_owned());
    let status = Command::new(cargo)
        .current_dir(paths::workspace_root())
        .args(["run", "--quiet", "-p", "vivid-vm", "--"])
        .args(args)
        .status()
        .context("cannot run cargo run -p vivid-vm")?;
    if !status.success() {
        bail!("the vivid VM test failed ({status})");
    }
    Ok(())
}

/// A wall time as the gate prints it: `42 s` under a minute, else `6 min 31 s` (whole seconds,
/// rounded down: a CI budget is read in minutes).
fn wall_time(took: Duration) -> String {
    let secs = took.as_secs();
    if secs < 60 {
        format!("{secs} s")
    } else {
        format!("{} min {:02} s", secs / 60, secs % 60)
    }
}

/// The gate's closing table: each step's wall time and its share of the whole, then the total, so
/// a CI run shows which step to make faster when the gate nears its budget (docs/testing.md:
/// well inside 90 minutes, kept under 45).
fn timing_table(timings: &[(&str, Duration)], total: Duration) -> String {
    let width = timings
        .iter()
        .map(|(name, _)| name.len())
        .chain(["total".len()])
        .max()
        .unwrap_or(0);
    let total_secs = total.as_secs_f64();
    let mut out = String::from("xtask: wall time per step\n");
    for (name, took) in timings {
        let share = if total_secs > 0.0 {
            100.0 * took.as_secs_f64() / total_secs
        } else {
            0.0
        };
        out.push_str(&format!(
            "  {name:<width$}  {:>12}  {share:5.1} %\n",
            wall_time(*took)
        ));
    }
    out.push_str(&format!(
        "  {:<width$}  {:>12}\n",
        "total",
        wall_time(total)
    ));
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wall_times_read_in_seconds_then_minutes() {
        assert_eq!(wall_time(Duration::from_millis(59_999)), "59 s");
        assert_eq!(wall_time(Duration::from_secs(60)), "1 min 00 s");
        assert_eq!(wall_time(Duration::from_secs(391)), "6 min 31 s");
        assert_eq!(wall_time(Duration::from_secs(2361)), "39 min 21 s");
    }

    #[test]
    fn the_timing_table_gives_each_step_its_share_and_the_total() {
        let table = timing_table(
            &[
                ("fmt", Duration::from_secs(3)),
                ("clippy", Duration::from_secs(391)),
                ("vivid", Duration::from_secs(206)),
            ],
            Duration::from_secs(600),
        );
        let lines: Vec<&str> = table.lines().collect();
        assert_eq!(lines.len(), 5, "{table}");
        assert_eq!(lines[0], "xtask: wall time per step");
        // Names padded to the longest, times right-aligned, shares of the total.
        assert_eq!(lines[1], "  fmt              3 s    0.5 %");
        assert_eq!(lines[2], "  clippy    6 min 31 s   65.2 %");
        assert_eq!(lines[3], "  vivid     3 min 26 s   34.3 %");
        assert_eq!(lines[4], "  total    10 min 00 s");
    }
}
