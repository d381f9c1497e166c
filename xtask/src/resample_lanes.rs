//! `cargo xtask resample-lanes`: the labelled sets at another resolution, for measuring the
//! tracker on frames other than the 320-px ones it is tuned at (`frame.working_width_px`).
//!
//! Every set under the data root (`--data DIR`, default `../shared/data/lanes`) is written to
//! `--out DIR` (default `target/lanes-{K}x`, inside the build directory: derived from
//! third-party data, never in the repository) with each frame enlarged `K` times (Catmull-Rom
//! bicubic, the `image` crate) and each label point mapped by the pixel-centre rule
//! `x' = (x + 0.5)·K − 0.5` (rows alike), then sampled again at one point per integer row
//! (linear between neighbours; points outside the image dropped, lanes left with fewer than 2
//! dropped). Score them with `cargo xtask eval-lanes --data target/lanes-{K}x` (`--census`
//! too: it reads the edges on the tracker's working frame, as the stages do).

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use serde_json::Value;

use crate::paths::workspace_root;

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
    if !(2..=8).contains(&args.factor) {
        bail!("resample-lanes: --factor {} is not in 2..=8", args.factor);
    }
    let root = workspace_root();
    let data = match &args.data {
        Some(d) if d.is_relative() => root.join(d),
        Some(d) => d.clone(),
        None => lane_eval::data::data_root().join(lane_eval::data::LANE_SETS),
    };
    let out = match &args.out {
        Some(d) if d.is_relative() => root.join(d),
        Some(d) => d.clone(),
        None => root.join(format!("target/lanes-{}x", args.factor)),
    };
    if std::fs::canonicalize(&out).ok() == std::fs::canonicalize(&data).ok() {
        bail!(
            "resample-lanes: --out {} is the data directory itself",
            out.display()
        );
    }
    let mut sets = 0;
    let mut entries: Vec<_> = std::fs::read_dir(&data)
        .with_context(|| {
            format!(
                "resample-lanes: no labelled sets at {} (third-party data, not in the \
                 repository: give --data DIR)",
                data.display()
            )
        })?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.join("labels.json").is_file())
        .collect();
    entries.sort();
    for dir in entries {
        resample_set(&dir, &out, args.factor)?;
        sets += 1;
    }
    if sets == 0 {
        bail!(
            "resample-lanes: no set with a labels.json under {}",
            data.display()
        );
    }
    println!(
        "resample-lanes: {sets} sets at {}x written to {}; score them with `cargo xtask \
         eval-lanes --data {}`",
        args.factor,
        out.display(),
        out.display()
    );
    Ok(())
}

/// One set: its frames enlarged, its labels mapped, into `out/<set name>/`.
fn resample_set(dir: &Path, out: &Path, factor: u32) -> Result<()> {
    // The labels checked as `eval-lanes` reads them (schema, sizes, points inside, sorted).
    lane_eval::labelled::LabelSet::load(dir)
        .with_context(|| format!("resample-lanes: {}", dir.display()))?;
    let name = dir
        .file_name()
        .context("a set directory without a name")?
        .to_owned();
    let labels_path = dir.join("labels.json");
    let text = std::fs::read_to_string(&labels_path)
        .with_context(|| format!("cannot read {}", labels_path.display()))?;
    let mut labels: Value = serde_json::from_str(&text)
        .with_context(|| format!("{}: not JSON", labels_path.display()))?;
    let size = |key: &str| -> Result<u64> {
        labels[key]
            .as_u64()
            .with_context(|| format!("{}: no `{key}`", labels_path.display()))
    };
    let k = f64::from(factor);
    let (width, height) = (
        size("width")? * u64::from(factor),
        size("height")? * u64::from(factor),
    );
    let set_out = out.join(&name);
    let frames = labels["frames"]
        .as_array_mut()
        .with_context(|| format!("{}: no `frames`", labels_path.display()))?;
    for frame in frames.iter_mut() {
        let file = frame["file"]
            .as_str()
            .with_context(|| format!("{}: a frame without `file`", labels_path.display()))?
            .to_owned();
        let src = dir.join(&file);
        let img = image::open(&src)
            .with_context(|| format!("cannot read {}", src.display()))?
            .to_luma8();
        if u64::from(img.width()) * u64::from(factor) != width
            || u64::from(img.height()) * u64::from(factor) != height
        {
            bail!(
                "{}: {}×{}, the set declares {}×{}",
                src.display(),
                img.width(),
                img.height(),
                width / u64::from(factor),
                height / u64::from(factor)
            );
        }
        let big = image::imageops::resize(
            &img,
            img.width() * factor,
            img.height() * factor,
            image::imageops::FilterType::CatmullRom,
        );
        let dst = set_out.join(&file);
        if let Some(parent) = dst.parent() {
            std::fs::create_dir_all(parent)
                .with_context(|| format!("cannot create {}", parent.display()))?;
        }
        big.save(&dst)
            .with_context(|| format!("cannot write {}", dst.display()))?;
        if let Some(lanes) = frame["lanes"].as_array_mut() {
            for lane in lanes.iter_mut() {
                let points: Vec<[f64; 2]> = lane["points"]
                    .as_array()
                    .map(|ps| {
                        ps.iter()
                            .filter_map(|p| Some([p[0].as_f64()?, p[1].as_f64()?]))
                            .collect()
                    })
                    .unwrap_or_default();
                lane["points"] = Value::from(
                    resample_points(&points, k, width as f64, height as f64)
                        .into_iter()
                        .map(|[x, y]| Value::from(vec![x, y]))
                        .collect::<Vec<_>>(),
                );
            }
            lanes.retain(|l| l["points"].as_array().is_some_and(|p| p.len() >= 2));
        }
    }
    labels["width"] = Value::from(width);
    labels["height"] = Value::from(height);
    std::fs::create_dir_all(&set_out)
        .with_context(|| format!("cannot create {}", set_out.display()))?;
    let json = serde_json::to_string(&labels)?;
    std::fs::write(set_out.join("labels.json"), json)
        .with_context(|| format!("cannot write {}", set_out.join("labels.json").display()))?;
    let source = dir.join("SOURCE.md");
    if source.is_file() {
        std::fs::copy(&source, set_out.join("SOURCE.md"))
            .with_context(|| format!("cannot copy {}", source.display()))?;
    }
    Ok(())
}

/// Label points (sorted by row) mapped `v ↦ (v + 0.5)·k − 0.5` and sampled at every integer row
/// they span (linear between neighbours), the points inside `width × height` kept.
fn resample_points(points: &[[f64; 2]], k: f64, width: f64, height: f64) -> Vec<[f64; 2]> {
    let mapped: Vec<[f64; 2]> = points
        .iter()
        .map(|&[x, y]| [(x + 0.5) * k - 0.5, (y + 0.5) * k - 0.5])
        .collect();
    let mut out = Vec::new();
    for pair in mapped.windows(2) {
        let ([x0, y0], [x1, y1]) = (pair[0], pair[1]);
        if y1 <= y0 {
            continue;
        }
        let mut r = y0.ceil();
        while r < y1 {
            let t = (r - y0) / (y1 - y0);
            out.push([x0 + t * (x1 - x0), r]);
            r += 1.0;
        }
    }
    if let Some(&[x, y]) = mapped.last()
        && y.fract() == 0.0
    {
        out.push([x, y]);
    }
    // Inside the image as the loader has it: columns [−0.5, W), rows [0, H).
    out.retain(|&[x, y]| (-0.5..width).contains(&x) && (0.0..height).contains(&y));
    out
}

#[cfg(test)]
mod tests {
    use super::resample_points;

    #[test]
    fn label_points_map_by_pixel_centres_one_per_row() {
        // Two points a row apart at 1x become rows 0.5·2 − 0.5 = 0.5 → 2.5: rows 1 and 2.
        let p = resample_points(&[[10.0, 0.0], [12.0, 1.0]], 2.0, 640.0, 360.0);
        assert_eq!(p, vec![[20.5 + 2.0 * 0.5, 1.0], [20.5 + 2.0 * 1.5, 2.0]]);
        // Outside the image: dropped (640.3 ≥ 640); a point left of column 0 but inside the
        // image's extent (−0.4 → −0.3) kept.
        assert!(resample_points(&[[319.9, 0.0], [319.9, 1.0]], 2.0, 640.0, 360.0).is_empty());
        assert_eq!(
            resample_points(&[[-0.4, 0.0], [-0.4, 1.0]], 2.0, 640.0, 360.0).len(),
            2
        );
    }
}
