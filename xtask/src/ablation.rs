//! `cargo xtask ablation`: each lane mechanism beyond the paper off in turn and at other values,
//! per labelled set, with its leave-one-set-out gain (`lane_bench::ablation`, where the method is
//! described). Writes `ablation.json` (every variant's totals per set and part) and `ablation.md`
//! (the tables) to `--out` (default `target/ablation`); `docs/results/ablation.md` is that file.

use std::collections::BTreeMap;
use std::path::PathBuf;

use anyhow::{Context, Result, bail};
use lane_bench::ablation::{as_one_sequence, mechanisms, render, run_variant};
use lane_tracker::TrackerConfig;

use crate::paths::{resolve, workspace_root};

/// Arguments of `cargo xtask ablation`.
#[derive(clap::Args, Debug)]
pub struct AblationArgs {
    /// Directory of labelled sets (default: `lanes/` under the data root).
    #[arg(long)]
    data: Option<PathBuf>,
    /// Output directory (relative paths are taken from the workspace root).
    #[arg(long, default_value = "target/ablation")]
    out: PathBuf,
    /// Only the mechanisms whose name contains this.
    #[arg(long)]
    only: Option<String>,
}

/// Run `cargo xtask ablation`.
pub fn run(args: AblationArgs) -> Result<()> {
    let root = workspace_root();
    let sets_dir = match &args.data {
        Some(dir) => resolve(&root, dir),
        None => lane_bench::data::data_root().join(lane_bench::data::LANE_SETS),
    };
    if !sets_dir.is_dir() {
        bail!(
            "{}: missing the labelled lane sets (third-party data): pass --data DIR",
            sets_dir.display()
        );
    }
    let out = resolve(&root, &args.out);
    std::fs::create_dir_all(&out).with_context(|| format!("cannot create {}", out.display()))?;
    let sets = lane_bench::protocol::find_sets(&sets_dir)?;
    let one_sequence = as_one_sequence(&sets);
    let default = TrackerConfig::default_preset()?;
    let mechanisms: Vec<_> = mechanisms()
        .into_iter()
        .filter(|m| {
            args.only
                .as_ref()
                .is_none_or(|o| m.name.contains(o.as_str()))
        })
        .collect();
    let mut runs = BTreeMap::new();
    let mut variants = vec![("default".to_owned(), default)];
    for m in &mechanisms {
        for v in std::iter::once(&m.off).chain(m.others) {
            let mut cfg = default;
            (v.set)(&mut cfg);
            variants.push((format!("{} = {}", m.name, v.label), cfg));
        }
    }
    for (key, cfg) in &variants {
        let start = std::time::Instant::now();
        match run_variant(&sets, &one_sequence, cfg)? {
            Some(per_set) => {
                eprintln!("ablation: {key} ({:.1} s)", start.elapsed().as_secs_f64());
                runs.insert(key.clone(), per_set);
            }
            None => eprintln!("ablation: {key}: the configuration refuses it; left out"),
        }
    }
    std::fs::write(
        out.join("ablation.json"),
        serde_json::to_string_pretty(&runs)?,
    )?;
    let set_names: Vec<String> = sets.iter().map(|(_, s)| s.set.clone()).collect();
    let md = render(&mechanisms, &runs, &set_names);
    std::fs::write(out.join("ablation.md"), &md)?;
    print!("{md}");
    eprintln!("ablation: wrote {}", out.display());
    Ok(())
}
