//! `cargo xtask resample-lanes`: the labelled sets enlarged K times (`lane_bench::resample`) into
//! `target/lanes-{K}x` (inside the build directory: derived from third-party data, never in the
//! repository), for `cargo xtask eval-lanes --data target/lanes-{K}x`.

use std::path::PathBuf;

use anyhow::Result;

use crate::paths::{resolve, workspace_root};

/// Arguments of `cargo xtask resample-lanes`.
#[derive(clap::Args, Debug)]
pub struct ResampleLanesArgs {
    /// Enlargement factor, a whole number 2..=8.
    #[arg(long, default_value_t = 2)]
    factor: u32,
    /// Directory of labelled sets (as for `eval-lanes`); relative paths from the workspace
    /// root. Default: `lanes/` under the data root (`$ITA_NAV_DATA`, else `../shared/data`).
    #[arg(long)]
    data: Option<PathBuf>,
    /// Output directory; default `target/lanes-{factor}x`.
    #[arg(long)]
    out: Option<PathBuf>,
}

/// Run `cargo xtask resample-lanes`.
pub fn run(args: ResampleLanesArgs) -> Result<()> {
    let root = workspace_root();
    let data = args.data.map_or_else(
        || lane_bench::data::data_root().join(lane_bench::data::LANE_SETS),
        |d| resolve(&root, &d),
    );
    let out = args.out.map_or_else(
        || root.join(format!("target/lanes-{}x", args.factor)),
        |d| resolve(&root, &d),
    );
    let sets = lane_bench::resample::resample_sets(&data, &out, args.factor)?;
    println!(
        "resample-lanes: {sets} sets at {}x written to {}; score them with `cargo xtask \
         eval-lanes --data {}`",
        args.factor,
        out.display(),
        out.display()
    );
    Ok(())
}
