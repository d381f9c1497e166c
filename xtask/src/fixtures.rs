//! `cargo xtask fixtures`: render the deterministic synthetic lane sequences (320×240 grey
//! YUV4MPEG2 + ground-truth JSON) into a directory (default `target/fixtures/synthetic`). Only the
//! ground-truth JSON is committed (`fixtures/synthetic/*.json`, the golden truth `cargo xtask
//! regress` checks the renderer against); the frames are rendered where they are needed.

use std::fs::File;
use std::io::BufWriter;
use std::path::PathBuf;

use anyhow::{Context, Result};
use lane_scenes::{SCENES, SceneSource, write_scene_y4m};

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

/// The workspace root (xtask's parent directory).
pub fn run(args: FixturesArgs) -> Result<()> {
    let out = workspace_root().join(&args.out);
    std::fs::create_dir_all(&out).with_context(|| format!("cannot create {}", out.display()))?;
    let mut total = 0u64;
    for spec in SCENES {
        let y4m_path = out.join(format!("{}.y4m", spec.name));
        let file = File::create(&y4m_path)
            .with_context(|| format!("cannot create {}", y4m_path.display()))?;
        write_scene_y4m(
            *spec,
            args.width,
            args.height,
            BufWriter::new(file),
            &y4m_path.display().to_string(),
        )?;
        let truth_path = out.join(format!("{}.json", spec.name));
        let truth = SceneSource::new(*spec, args.width, args.height).truth();
        let text = serde_json::to_string_pretty(&truth)?;
        std::fs::write(&truth_path, text + "\n")
            .with_context(|| format!("cannot write {}", truth_path.display()))?;
        let size = std::fs::metadata(&y4m_path)?.len();
        total += size;
        println!(
            "fixtures: {} ({} frames, {} KiB) — {}",
            spec.name,
            spec.frames,
            size / 1024,
            spec.description
        );
    }
    println!(
        "fixtures: {} sequences, {:.1} MiB in {}",
        SCENES.len(),
        total as f64 / 1048576.0,
        out.display()
    );
    Ok(())
}
