//! The labelled sets at another resolution (`cargo xtask resample-lanes`), for measuring the
//! tracker on frames other than the 320-px ones it is tuned at (`frame.working_width_px`).
//!
//! Every set under a directory is written to another one with each frame enlarged `K` times
//! (Catmull-Rom bicubic, the `image` crate) and each label point mapped by the pixel-centre rule
//! `x' = (x + 0.5)·K − 0.5` (rows alike), then sampled again at one point per integer row
//! (linear between neighbours; points outside the image dropped, lanes left with fewer than 2
//! dropped). Score them with `eval-lanes --data` (`--census` too: it reads the edges on the
//! tracker's working frame, as the stages do).

use std::path::Path;

use serde_json::Value;

use crate::BenchError;

/// Write every set under `data` (each a sub-directory with a `labels.json`) enlarged `factor`
/// times (2..=8) into `out/<set name>/`; returns how many.
pub fn resample_sets(data: &Path, out: &Path, factor: u32) -> Result<usize, BenchError> {
    if !(2..=8).contains(&factor) {
        return Err(BenchError::Refused(format!(
            "the factor {factor} is not in 2..=8"
        )));
    }
    if std::fs::canonicalize(out).ok() == std::fs::canonicalize(data).ok() {
        return Err(BenchError::Refused(format!(
            "the output {} is the data directory itself",
            out.display()
        )));
    }
    let sets = crate::protocol::find_sets(data)?;
    for (dir, _) in &sets {
        resample_set(dir, out, factor)?;
    }
    Ok(sets.len())
}

/// One set: its frames enlarged, its labels mapped, into `out/<set name>/`.
fn resample_set(dir: &Path, out: &Path, factor: u32) -> Result<(), BenchError> {
    // The labels checked as `eval-lanes` reads them (schema, sizes, points inside, sorted):
    // the fields below are there.
    crate::labelled::LabelSet::load(dir)?;
    let labels_path = dir.join("labels.json");
    let bad = |what: String| BenchError::Labels {
        path: labels_path.display().to_string(),
        reason: what,
    };
    let name = dir
        .file_name()
        .ok_or_else(|| bad("a set directory without a name".to_owned()))?
        .to_owned();
    let text = std::fs::read_to_string(&labels_path)
        .map_err(|e| BenchError::io("read", &labels_path, e))?;
    let mut labels: Value = serde_json::from_str(&text)
        .map_err(|e| crate::error::labels_json(&labels_path.display().to_string(), &e))?;
    let size = |key: &str| -> Result<u64, BenchError> {
        labels[key]
            .as_u64()
            .ok_or_else(|| bad(format!("no `{key}`")))
    };
    let k = f64::from(factor);
    let (width, height) = (
        size("width")? * u64::from(factor),
        size("height")? * u64::from(factor),
    );
    let set_out = out.join(&name);
    let Some(frames) = labels["frames"].as_array_mut() else {
        return Err(bad("no `frames`".to_owned()));
    };
    for frame in frames.iter_mut() {
        let Some(file) = frame["file"].as_str().map(str::to_owned) else {
            return Err(bad("a frame without `file`".to_owned()));
        };
        let src = dir.join(&file);
        let img = image::open(&src)
            .map_err(|source| BenchError::Image {
                action: "read",
                path: src.display().to_string(),
                source,
            })?
            .to_luma8();
        if u64::from(img.width()) * u64::from(factor) != width
            || u64::from(img.height()) * u64::from(factor) != height
        {
            return Err(BenchError::Labels {
                path: src.display().to_string(),
                reason: format!(
                    "{}×{}, the set declares {}×{}",
                    img.width(),
                    img.height(),
                    width / u64::from(factor),
                    height / u64::from(factor)
                ),
            });
        }
        let big = image::imageops::resize(
            &img,
            img.width() * factor,
            img.height() * factor,
            image::imageops::FilterType::CatmullRom,
        );
        let dst = set_out.join(&file);
        if let Some(parent) = dst.parent() {
            std::fs::create_dir_all(parent).map_err(|e| BenchError::io("create", parent, e))?;
        }
        big.save(&dst).map_err(|source| BenchError::Image {
            action: "write",
            path: dst.display().to_string(),
            source,
        })?;
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
                    resample_points(&points, [k, k], width as f64, height as f64)
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
    std::fs::create_dir_all(&set_out).map_err(|e| BenchError::io("create", &set_out, e))?;
    let out_labels = set_out.join("labels.json");
    let json = serde_json::to_string(&labels).map_err(|source| BenchError::Json {
        path: out_labels.display().to_string(),
        source,
    })?;
    std::fs::write(&out_labels, json).map_err(|e| BenchError::io("write", &out_labels, e))?;
    let source = dir.join("SOURCE.md");
    if source.is_file() {
        std::fs::copy(&source, set_out.join("SOURCE.md"))
            .map_err(|e| BenchError::io("copy", &source, e))?;
    }
    Ok(())
}

/// Label points (sorted by row) mapped `x ↦ (x + 0.5)·kx − 0.5`, `y ↦ (y + 0.5)·ky − 0.5` (the
/// pixel-centre rule of a resize by `[kx, ky]`, `k > 0`) and sampled at every integer row they
/// span (linear between neighbours), the points inside `width × height` kept. Also the label
/// mapping of the resized perturbations ([`crate::perturb`]).
pub(crate) fn resample_points(
    points: &[[f64; 2]],
    [kx, ky]: [f64; 2],
    width: f64,
    height: f64,
) -> Vec<[f64; 2]> {
    let mapped: Vec<[f64; 2]> = points
        .iter()
        .map(|&[x, y]| [(x + 0.5) * kx - 0.5, (y + 0.5) * ky - 0.5])
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
        let p = resample_points(&[[10.0, 0.0], [12.0, 1.0]], [2.0, 2.0], 640.0, 360.0);
        assert_eq!(p, vec![[20.5 + 2.0 * 0.5, 1.0], [20.5 + 2.0 * 1.5, 2.0]]);
        // Outside the image: dropped (640.3 ≥ 640); a point left of column 0 but inside the
        // image's extent (−0.4 → −0.3) kept.
        assert!(
            resample_points(&[[319.9, 0.0], [319.9, 1.0]], [2.0, 2.0], 640.0, 360.0).is_empty()
        );
        assert_eq!(
            resample_points(&[[-0.4, 0.0], [-0.4, 1.0]], [2.0, 2.0], 640.0, 360.0).len(),
            2
        );
    }
}
