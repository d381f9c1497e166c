//! `cargo xtask import-lanes`: `nav-app import-lanes` (crate `lane-bench`) with relative paths
//! from the workspace root.

use anyhow::Result;

use crate::paths::workspace_root;

/// Run `cargo xtask import-lanes`.
pub fn run(args: lane_bench::cli::ImportLanesArgs) -> Result<()> {
    let root = workspace_root();
    let floors = root.join("fixtures/expectations-lanes-real.json");
    let ctx = crate::eval_lanes::context("cargo xtask import-lanes", &root, &floors);
    lane_bench::cli::import_lanes(&args, &ctx)
        .map_err(|e| anyhow::Error::new(e).context("import-lanes"))
}
