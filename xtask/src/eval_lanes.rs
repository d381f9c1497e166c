//! `cargo xtask eval-lanes` and `import-lanes`: `nav-app eval-lanes` and `import-lanes` (crate
//! `lane-bench`) with the workspace's defaults — `--out target/eval-lanes`, relative paths from the workspace
//! root, the floors of `--check` / `--record` in `fixtures/expectations-lanes-real.json` — and the
//! classic OpenCV pipeline scored beside the tracker (`bench/opencv_peer.py`, in
//! `target/opencv-venv`, made from PyPI on first use; `--no-peer` leaves it out). The gate runs
//! `cargo xtask eval-lanes --check --perturb` (a README command, the `readme` step): the near
//! band's, the full rule's and the perturbations' floors.

use std::path::Path;
use std::process::Command;

use anyhow::{Context as _, Result, bail};
use lane_bench::cli::Context;

use crate::paths::workspace_root;

/// Arguments of `cargo xtask eval-lanes`: those of `nav-app eval-lanes`, and `--no-peer`.
#[derive(clap::Args, Debug)]
pub struct EvalLanesCmd {
    #[command(flatten)]
    lanes: lane_bench::cli::EvalLanesArgs,
    /// Do not run the OpenCV peer even if its venv exists.
    #[arg(long)]
    no_peer: bool,
}

/// What the OpenCV peer's virtual environment (`target/opencv-venv`) holds, from PyPI.
const PEER_REQUIREMENTS: &[&str] = &["opencv-python-headless<5", "numpy"];

/// The context of the xtask commands: the workspace's defaults.
pub fn context<'a>(command: &'a str, root: &'a Path, floors: &'a Path) -> Context<'a> {
    Context {
        command,
        score_with: "cargo xtask eval-lanes --no-peer",
        base: Some(root),
        default_out: Path::new("target/eval-lanes"),
        default_floors: Some(floors),
    }
}

/// Run the peer on the set in `set_dir`, writing its predictions to `out` (its virtual
/// environment made on first use).
fn run_peer(root: &Path, set_dir: &Path, out: &Path) -> Result<()> {
    let python = crate::python::ensure_venv_with(
        root,
        "opencv-venv",
        PEER_REQUIREMENTS,
        "import cv2, numpy",
        None,
    )?;
    let status = Command::new(&python)
        .arg(root.join("bench/opencv_peer.py"))
        .arg("--predict-set")
        .arg(set_dir)
        .arg("--out")
        .arg(out)
        .status()
        .with_context(|| format!("cannot start {}", python.display()))?;
    if !status.success() {
        bail!("opencv peer failed on {} ({status})", set_dir.display());
    }
    Ok(())
}

/// Run `cargo xtask eval-lanes`.
pub fn run(args: EvalLanesCmd) -> Result<()> {
    let root = workspace_root();
    let floors = root.join("fixtures/expectations-lanes-real.json");
    let ctx = context("cargo xtask eval-lanes", &root, &floors);
    let mut lanes = args.lanes;
    if !args.no_peer && lanes.peer.is_none() {
        // The peer's predictions, `peer-<set>.json` per set, beside the reports.
        let out = lanes.out_dir(&ctx);
        std::fs::create_dir_all(&out)
            .with_context(|| format!("cannot create {}", out.display()))?;
        for (dir, set) in lane_bench::protocol::find_sets(&lanes.data_dir(&ctx)?)? {
            run_peer(&root, &dir, &out.join(format!("peer-{}.json", set.set)))?;
        }
        lanes.peer = Some(out);
    }
    lane_bench::cli::eval_lanes(&lanes, &ctx)
        .map_err(|e| anyhow::Error::new(e).context("eval-lanes"))
}

/// Run `cargo xtask import-lanes`: `nav-app import-lanes` with relative paths from the workspace
/// root.
pub fn import(args: lane_bench::cli::ImportLanesArgs) -> Result<()> {
    let root = workspace_root();
    let floors = root.join("fixtures/expectations-lanes-real.json");
    let ctx = context("cargo xtask import-lanes", &root, &floors);
    lane_bench::cli::import_lanes(&args, &ctx)
        .map_err(|e| anyhow::Error::new(e).context("import-lanes"))
}
