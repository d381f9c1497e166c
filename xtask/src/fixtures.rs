//! `cargo xtask fixtures`: render the deterministic synthetic lane sequences (320×240 grey
//! YUV4MPEG2 + ground-truth JSON, `lane_scenes::write_fixtures`) into a directory (default
//! `target/fixtures/synthetic`). Only the ground-truth JSON is committed (`fixtures/synthetic/*.json`,
//! the golden truth `cargo xtask regress` checks the renderer against); the frames are rendered
//! where they are needed.

use std::path::PathBuf;

use anyhow::Result;

use crate::paths::workspace_root;

/// Arguments of `cargo xtask fixtures`.
#[derive(clap::Args, Debug)]
pub struct FixturesArgs {
    /// Output directory.
    #[arg(long, default_value = "target/fixtures/synthetic")]
    pub out: PathBuf,
    /// Frame width, px.
    #[arg(long, default_value_t = 320)]
    pub width: usize,
    /// Frame height, px.
    #[arg(long, default_value_t = 240)]
    pub height: usize,
}

/// Run `cargo xtask fixtures`.
pub fn run(args: FixturesArgs) -> Result<()> {
    let out = workspace_root().join(&args.out);
    let written = lane_scenes::write_fixtures(&out, args.width, args.height)?;
    for (spec, size) in &written {
        println!(
            "fixtures: {} ({} frames, {} KiB) — {}",
            spec.name,
            spec.frames,
            size / 1024,
            spec.description
        );
    }
    let total: u64 = written.iter().map(|(_, size)| size).sum();
    println!(
        "fixtures: {} sequences, {:.1} MiB in {}",
        written.len(),
        total as f64 / 1048576.0,
        out.display()
    );
    Ok(())
}
