//! The command lines of `nav-app eval-lanes` and `nav-app import-lanes` (feature `cli`), shared
//! with `cargo xtask eval-lanes` and `cargo xtask import-lanes`, which give them the workspace's
//! defaults ([`Context`]) and, for the gate, the OpenCV peer's predictions.

use std::path::{Path, PathBuf};

use crate::BenchError;
use crate::import_set::{Format, import_set};
use crate::labelled::SceneKind;
use crate::labelled::import::Skipped;
use crate::protocol::{self, Options, floors};

/// Where a command runs: its name and its defaults.
#[derive(Debug, Clone, Copy)]
pub struct Context<'a> {
    /// The command as typed (`nav-app eval-lanes`): in messages and `summary.md`'s title.
    pub command: &'a str,
    /// The command that scores an imported set (`nav-app eval-lanes`), named by import-lanes.
    pub score_with: &'a str,
    /// Relative paths on the command line are taken from here (`None`: the current directory).
    pub base: Option<&'a Path>,
    /// `--out` when it is not given.
    pub default_out: &'a Path,
    /// `--floors` when it is not given.
    pub default_floors: Option<&'a Path>,
}

impl Context<'_> {
    /// `p` taken from [`Context::base`] when relative.
    pub fn resolve(&self, p: &Path) -> PathBuf {
        match self.base {
            Some(base) if p.is_relative() => base.join(p),
            _ => p.to_owned(),
        }
    }
}

/// Arguments of `eval-lanes`.
#[derive(clap::Args, Debug, Clone)]
pub struct EvalLanesArgs {
    /// Directory of labelled sets (one sub-directory per set with a `labels.json`, such as
    /// `import-lanes` writes). Default: `lanes/` under the data root (`$ITA_NAV_DATA`, else
    /// `../shared/data` beside the checkout).
    #[arg(long = "data", alias = "sets", value_name = "DIR")]
    pub data: Option<PathBuf>,
    /// Configurations scored beside the default: preset names or TOML files.
    #[arg(long = "config", value_name = "NAME|FILE",
          default_values_t = ["outdoor".to_owned(), "indoor".to_owned()])]
    pub configs: Vec<String>,
    /// Output directory (summary.md, summary.json, frames.csv, worst_frames.png). Default:
    /// `eval-lanes` (cargo xtask: `target/eval-lanes` in the workspace).
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Fail if the default configuration falls below the floors in the floors file.
    #[arg(long)]
    pub check: bool,
    /// Record the floors from this run (default configuration, all frames) into the floors file.
    #[arg(long)]
    pub record: bool,
    /// The floors file of --check and --record (JSON; cargo xtask:
    /// fixtures/expectations-lanes-real.json).
    #[arg(long, value_name = "FILE")]
    pub floors: Option<PathBuf>,
    /// Print the development part only and write only its `frames.csv` (what tuning may look
    /// at).
    #[arg(long)]
    pub dev_only: bool,
    /// Also report where the default configuration loses the ego label lanes of the development
    /// part, stage by stage (no Hough candidate — and of those, no edge near the label —
    /// candidate not chosen, lost after the choice, found by the refinement).
    #[arg(long)]
    pub census: bool,
    /// Track each set's frames as one sequence, in set order, never reset between clips: a
    /// stress test of the tracking path, not an accuracy figure. Not with --check or --record.
    #[arg(long)]
    pub one_sequence: bool,
    /// A directory of another method's predictions, `peer-<set>.json` per set (`{"frames":
    /// [{"index": i, "lanes": [left, right]}]}`, each lane `[a1, a2, a3]` of x = a1·y² + a2·y + a3
    /// or null), scored beside the tracker as `opencv-peer` (cargo xtask: the OpenCV pipeline's).
    #[arg(long, value_name = "DIR")]
    pub peer: Option<PathBuf>,
    /// Also run the default configuration on the frames changed as other cameras would give
    /// them — horizon shifted, a bonnet in view, other widths (256 to 1920 px), brightness,
    /// JPEG, noise, motion blur — and report its near-band TuSimple accuracy and false positives
    /// under each beside the unperturbed run (with --check, against their floors too).
    #[arg(long)]
    pub perturb: bool,
}

impl EvalLanesArgs {
    /// The directory of labelled sets, or an error naming it when it is not a directory.
    pub fn data_dir(&self, ctx: &Context<'_>) -> Result<PathBuf, BenchError> {
        let dir = match &self.data {
            Some(dir) => ctx.resolve(dir),
            None => crate::data::data_root().join(crate::data::LANE_SETS),
        };
        if dir.is_dir() {
            return Ok(dir);
        }
        let reason = if self.data.is_some() {
            "no such directory of labelled lane sets (--data)"
        } else {
            "missing the labelled lane sets (third-party evaluation data, not in the \
             repository): put the shared data root beside the checkout as ../shared/data, name \
             it with ITA_NAV_DATA, or pass --data DIR"
        };
        Err(BenchError::NoSets {
            dir: dir.display().to_string(),
            reason: reason.to_owned(),
        })
    }

    /// The output directory.
    pub fn out_dir(&self, ctx: &Context<'_>) -> PathBuf {
        ctx.resolve(self.out.as_deref().unwrap_or(ctx.default_out))
    }
}

/// Run `eval-lanes`: score the sets, write and print the reports, check or record the floors.
pub fn eval_lanes(args: &EvalLanesArgs, ctx: &Context<'_>) -> Result<(), BenchError> {
    let command = ctx.command;
    let sets_dir = args.data_dir(ctx)?;
    let out = args.out_dir(ctx);
    if args.one_sequence && (args.check || args.record) {
        return Err(BenchError::Refused(
            "--one-sequence is a stress test: the floors (--check, --record) are for the stills"
                .to_owned(),
        ));
    }
    let floors_path = match (&args.floors, ctx.default_floors) {
        (Some(p), _) => Some(ctx.resolve(p)),
        (None, p) => p.map(Path::to_path_buf),
    };
    let floors_path = match floors_path {
        Some(p) => p,
        None if args.check || args.record => {
            return Err(BenchError::Refused(
                "--check and --record need the floors file: give --floors FILE".to_owned(),
            ));
        }
        None => PathBuf::new(),
    };
    let sets = protocol::find_sets(&sets_dir)?;
    let mut configs = Vec::with_capacity(args.configs.len());
    for c in &args.configs {
        configs.push((c.clone(), lane_io::config::load_tracker_config(c)?));
    }
    let options = Options {
        configs,
        dev_only: args.dev_only,
        census: args.census,
        one_sequence: args.one_sequence,
        peer: args.peer.as_deref().map(|p| ctx.resolve(p)),
        perturb: args.perturb,
    };
    let evaluation = protocol::evaluate(sets, &options)?;
    for (set, skipped) in &evaluation.skipped {
        eprintln!("{command}: set {set}: {skipped}");
    }
    if !evaluation.perturb_times.is_empty() {
        let total: std::time::Duration = evaluation.perturb_times.iter().map(|(_, t)| *t).sum();
        let each: Vec<String> = evaluation
            .perturb_times
            .iter()
            .map(|(name, t)| format!("{name} {:.1} s", t.as_secs_f64()))
            .collect();
        eprintln!(
            "{command}: --perturb took {:.1} s ({})",
            total.as_secs_f64(),
            each.join(", ")
        );
    }
    let md = evaluation.write(&out, command)?;
    print!("{md}");
    println!("{command}: wrote {}", out.display());
    if args.record {
        floors::record(&evaluation.summary, &floors_path)?;
        println!("{command}: recorded {}", floors_path.display());
    }
    if args.check {
        let checked = floors::check(&evaluation.summary, &floors_path)?;
        println!("{command}: {} floors held", checked.held);
        if checked.not_run > 0 {
            println!(
                "{command}: {} perturbation floors not checked (run with --perturb)",
                checked.not_run
            );
        }
    }
    Ok(())
}

/// Arguments of `import-lanes`.
#[derive(clap::Args, Debug, Clone)]
pub struct ImportLanesArgs {
    /// The labels' format.
    #[arg(long, value_enum)]
    pub format: Format,
    /// The set directory to write (`labels.json` in it); its name is the set's. Score it with
    /// `eval-lanes --data <its parent>`.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// CULane's data root, the directory the list's image paths start from. Default: the list
    /// file's directory's parent (CULane's own layout, `ROOT/list/test.txt`).
    #[arg(long, value_name = "DIR")]
    pub root: Option<PathBuf>,
    /// Scene kind written into the set.
    #[arg(long, value_enum, default_value = "road")]
    pub kind: SceneKind,
    /// The label files: TuSimple's JSON-lines files (several are one set), or one CULane list.
    #[arg(required = true, value_name = "FILE")]
    pub labels: Vec<PathBuf>,
}

/// The skipped records shown one per line, at most this many (a wrong `--root` skips every image).
const SKIPPED_SHOWN: usize = 20;

/// Print what was skipped: the first [`SKIPPED_SHOWN`] records, then how many more.
fn report_skipped(command: &str, skipped: &[Skipped]) {
    for s in skipped.iter().take(SKIPPED_SHOWN) {
        eprintln!("{command}: skipped {s}");
    }
    if skipped.len() > SKIPPED_SHOWN {
        eprintln!(
            "{command}: … and {} more skipped",
            skipped.len() - SKIPPED_SHOWN
        );
    }
}

/// Run `import-lanes`: write the set and report what was skipped.
pub fn import_lanes(args: &ImportLanesArgs, ctx: &Context<'_>) -> Result<(), BenchError> {
    let command = ctx.command;
    let labels: Vec<PathBuf> = args.labels.iter().map(|p| ctx.resolve(p)).collect();
    let out = ctx.resolve(&args.out);
    if args.root.is_some() && args.format != Format::Culane {
        return Err(BenchError::Refused(
            "--root is CULane's data root (TuSimple's images are under its label file's \
             directory)"
                .to_owned(),
        ));
    }
    let culane_root = args.root.as_deref().map(|r| ctx.resolve(r));
    let (set, skipped) = match import_set(
        args.format,
        &labels,
        culane_root.as_deref(),
        &out,
        args.kind,
    ) {
        Ok(imported) => imported,
        Err(BenchError::NothingImported(skipped)) => {
            report_skipped(command, &skipped);
            return Err(BenchError::NothingImported(skipped));
        }
        Err(e) => return Err(e),
    };
    report_skipped(command, &skipped);
    println!(
        "{command}: {} frames ({}×{}) into {} ({} skipped); score with `{} --data {}`",
        set.frames.len(),
        set.width,
        set.height,
        out.join("labels.json").display(),
        skipped.len(),
        ctx.score_with,
        out.parent().unwrap_or(&out).display()
    );
    Ok(())
}
