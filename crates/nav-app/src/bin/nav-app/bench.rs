//! `nav-app eval-lanes` and `nav-app import-lanes`: the labelled lane benchmark on a user's own
//! labelled frames (crate `lane-bench`, whose command lines these are; `cargo xtask eval-lanes`
//! runs the same with the workspace's defaults and the OpenCV peer).

use std::ffi::OsString;
use std::path::Path;
use std::process::ExitCode;

use clap::Parser;
use lane_bench::cli::{Context, EvalLanesArgs, ImportLanesArgs};

/// `nav-app eval-lanes`: score the lane tracker on labelled sets.
#[derive(Parser, Debug)]
#[command(
    name = "nav-app eval-lanes",
    bin_name = "nav-app eval-lanes",
    about = "Scores the lane tracker on labelled sets (a directory of sets, each a labels.json, \
             such as `nav-app import-lanes` writes from TuSimple or CULane labels) with the \
             TuSimple and Aly rules: per set and overall, development part (the first 70 % of \
             each set's frames) and hold-out part, the default configuration beside --config's",
    after_help = "Writes summary.md, summary.json, frames.csv and worst_frames.png into --out. A \
                  frame whose image cannot be read is reported and scored as no prediction.\n\n\
                  Exit codes: 0 success; 1 error (a missing or malformed set, an unreadable \
                  configuration, figures below the floors with --check); 2 bad command line."
)]
struct EvalCli {
    #[command(flatten)]
    args: EvalLanesArgs,
}

/// `nav-app import-lanes`: labels in TuSimple's or CULane's format as a set eval-lanes scores.
#[derive(Parser, Debug)]
#[command(
    name = "nav-app import-lanes",
    bin_name = "nav-app import-lanes",
    about = "Writes labels in TuSimple's or CULane's format as a labels.json that `nav-app \
             eval-lanes --data <its parent>` scores; the images stay where they are (named by \
             absolute path)",
    after_help = "A label record that cannot be read, a missing image or an image of another \
                  size than the first is skipped and reported.\n\n\
                  Exit codes: 0 success; 1 error (no frame could be imported, an unreadable \
                  label file, an existing set not written by import-lanes); 2 bad command line."
)]
struct ImportCli {
    #[command(flatten)]
    args: ImportLanesArgs,
}

/// The context of the user commands: paths from the current directory, no workspace defaults.
fn context(command: &'static str) -> Context<'static> {
    Context {
        command,
        score_with: "nav-app eval-lanes",
        base: None,
        default_out: Path::new("eval-lanes"),
        default_floors: None,
    }
}

/// The exit code of a finished command, its error printed with its causes.
fn finish(command: &str, result: Result<(), lane_bench::BenchError>) -> ExitCode {
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("{command}: error: {}", crate::error_chain(&e));
            ExitCode::from(1)
        }
    }
}

/// `nav-app eval-lanes …` (`args` from the subcommand's name on).
pub fn eval_main(args: impl IntoIterator<Item = OsString>) -> ExitCode {
    let cli = EvalCli::parse_from(args);
    let ctx = context("nav-app eval-lanes");
    finish(ctx.command, lane_bench::cli::eval_lanes(&cli.args, &ctx))
}

/// `nav-app import-lanes …` (`args` from the subcommand's name on).
pub fn import_main(args: impl IntoIterator<Item = OsString>) -> ExitCode {
    let cli = ImportCli::parse_from(args);
    let ctx = context("nav-app import-lanes");
    finish(ctx.command, lane_bench::cli::import_lanes(&cli.args, &ctx))
}
