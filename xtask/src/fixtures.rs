//! `cargo xtask fixtures`: render the deterministic synthetic lane sequences (320×240 grey
//! YUV4MPEG2 + ground-truth JSON) into `fixtures/synthetic/`.

use std::fs::File;
use std::io::BufWriter;
use std::path::PathBuf;

use anyhow::{Context, Result};
use lane_eval::synth::{SCENES, SceneRenderer};
use lane_io::y4m::{Y4mChroma, Y4mWriter};
use lane_tracker::GreyFrame;

use crate::paths::workspace_root;

/// Arguments of `cargo xtask fixtures`.
#[derive(clap::Args, Debug)]
pub struct FixturesArgs {
    /// Output directory.
    #[arg(long, default_value = "fixtures/synthetic")]
    out: PathBuf,
    /// Frame width, px.
    #[arg(long, default_value_t = 320)]
    width: usize,
    /// Frame height, px.
    #[arg(long, default_value_t = 240)]
    height: usize,
}

/// The workspace root (xtask's parent directory).
pub fn run(args: FixturesArgs) -> Result<()> {
    let out = workspace_root().join(&args.out);
    std::fs::create_dir_all(&out).with_context(|| format!("cannot create {}", out.display()))?;
    let mut frame = GreyFrame::default();
    let mut total = 0u64;
    for spec in SCENES {
        let mut renderer = SceneRenderer::new(*spec, args.width, args.height);
        let y4m_path = out.join(format!("{}.y4m", spec.name));
        let file = File::create(&y4m_path)
            .with_context(|| format!("cannot create {}", y4m_path.display()))?;
        let mut writer = Y4mWriter::new(
            BufWriter::new(file),
            args.width,
            args.height,
            25.0,
            Y4mChroma::Mono,
        )?;
        for i in 0..spec.frames {
            renderer.render(i, &mut frame);
            writer.write_grey(frame.data())?;
        }
        writer.finish()?;
        let truth_path = out.join(format!("{}.json", spec.name));
        let text = serde_json::to_string_pretty(&renderer.sequence_truth())?;
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
