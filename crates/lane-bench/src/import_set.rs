//! A labelled set in TuSimple's or CULane's format, written as a `labels.json` (schema 1) that
//! [`crate::protocol`] scores like the shared sets (`nav-app import-lanes`). The formats and the
//! ego-pair rule are [`crate::labelled::import`]'s; this module does the file work around them.
//!
//! The images are not copied: each frame's `file` is the image's absolute path, so the set
//! directory holds only `labels.json` and the user's recording stays where it is. Every image's
//! size is read from its header; the set takes the first one's, and a frame of another size is
//! skipped and reported, like a label record that cannot be read or an image that is missing.
//! A `labels.json` already in the set directory is replaced only when this module wrote it.

use std::path::{Path, PathBuf};

use crate::BenchError;
use crate::labelled::import::{
    ImportedFrame, Skipped, assign_sides, culane_lines_file, parse_culane_lines, parse_culane_list,
    parse_tusimple,
};
use crate::labelled::{LABEL_SCHEMA, LabelFrame, LabelSet, SceneKind};

/// The `licence` of a set this module writes: it marks the `labels.json` files it may
/// overwrite (never another one, such as a shared set's).
pub const IMPORTED_LICENCE: &str = "not stated (imported by nav-app import-lanes)";
/// The mark of the sets written before the import moved into this crate (`cargo xtask
/// import-lanes`): they too may be overwritten.
const IMPORTED_LICENCE_BEFORE: &str = "not stated (imported by cargo xtask import-lanes)";

/// The label formats [`import_set`] reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum Format {
    /// TuSimple: JSON lines (`label_data_*.json`, `test_label.json`), images under the label
    /// file's directory.
    Tusimple,
    /// CULane: a list file (`list/test.txt`, …) and each image's `.lines.txt` beside it.
    Culane,
}

/// Read `labels` in `format`, write `out/labels.json` and return the set and what was skipped.
/// `culane_root` is CULane's data root (default: the list file's directory's parent, CULane's
/// own layout `ROOT/list/test.txt`); TuSimple's images are under each label file's directory.
pub fn import_set(
    format: Format,
    labels: &[PathBuf],
    culane_root: Option<&Path>,
    out: &Path,
    kind: SceneKind,
) -> Result<(LabelSet, Vec<Skipped>), BenchError> {
    let mut skipped = Vec::new();
    // Each frame with the directory its image path is relative to.
    let mut read: Vec<(PathBuf, ImportedFrame)> = Vec::new();
    match format {
        Format::Tusimple => {
            for file in labels {
                let text =
                    std::fs::read_to_string(file).map_err(|e| BenchError::io("read", file, e))?;
                let (frames, bad) = parse_tusimple(&file.display().to_string(), &text);
                skipped.extend(bad);
                let dir = file.parent().map_or_else(PathBuf::new, Path::to_path_buf);
                read.extend(frames.into_iter().map(|f| (dir.clone(), f)));
            }
        }
        Format::Culane => {
            let [list] = labels else {
                return Err(BenchError::Refused(format!(
                    "the CULane format takes one list file, got {}",
                    labels.len()
                )));
            };
            let text =
                std::fs::read_to_string(list).map_err(|e| BenchError::io("read", list, e))?;
            let data_root = match culane_root {
                Some(r) => r.to_path_buf(),
                None => list
                    .parent()
                    .and_then(Path::parent)
                    .map_or_else(PathBuf::new, Path::to_path_buf),
            };
            for image in parse_culane_list(&text) {
                let lines = data_root.join(culane_lines_file(&image));
                let lanes = match std::fs::read_to_string(&lines) {
                    Ok(t) => parse_culane_lines(&lines.display().to_string(), &t),
                    Err(e) => Err(Skipped {
                        path: lines.display().to_string(),
                        line: 0,
                        reason: format!("cannot read the image's labels: {e}"),
                    }),
                };
                match lanes {
                    Ok(lanes) => read.push((data_root.clone(), ImportedFrame::new(image, lanes))),
                    Err(s) => skipped.push(s),
                }
            }
        }
    }
    // One clip's frames consecutive, in their images' order (a video's frames by name).
    read.sort_by(|a, b| (&a.1.clip, &a.1.image).cmp(&(&b.1.clip, &b.1.image)));

    let mut size: Option<(usize, usize)> = None;
    let mut frames = Vec::with_capacity(read.len());
    for (dir, f) in read {
        let path = dir.join(&f.image);
        let absolute = std::path::absolute(&path).unwrap_or_else(|_| path.clone());
        let dims = match image::image_dimensions(&absolute) {
            Ok((w, h)) => (w as usize, h as usize),
            Err(e) => {
                skipped.push(Skipped {
                    path: absolute.display().to_string(),
                    line: 0,
                    reason: format!("cannot read the image: {e}"),
                });
                continue;
            }
        };
        let (width, height) = *size.get_or_insert(dims);
        if dims != (width, height) {
            skipped.push(Skipped {
                path: absolute.display().to_string(),
                line: 0,
                reason: format!(
                    "image is {}×{}, the set's first is {width}×{height}",
                    dims.0, dims.1
                ),
            });
            continue;
        }
        frames.push(LabelFrame {
            index: frames.len() as u64,
            file: absolute.display().to_string(),
            clip: f.clip,
            lanes: assign_sides(&f.lanes, width, height),
        });
    }
    // Set by the first readable image, which is always kept: no size, no frame.
    let Some((width, height)) = size else {
        return Err(BenchError::NothingImported(skipped));
    };
    let name = out.file_name().map_or_else(
        || "imported".to_owned(),
        |n| n.to_string_lossy().into_owned(),
    );
    let set = LabelSet {
        schema: LABEL_SCHEMA,
        set: name,
        kind,
        source: format!(
            "{} labels: {}",
            match format {
                Format::Tusimple => "TuSimple",
                Format::Culane => "CULane",
            },
            labels
                .iter()
                .map(|p| p.display().to_string())
                .collect::<Vec<_>>()
                .join(", ")
        ),
        licence: IMPORTED_LICENCE.to_owned(),
        width,
        height,
        frames,
    };
    let path = out.join("labels.json");
    let text = serde_json::to_string_pretty(&set).map_err(|source| BenchError::Json {
        path: path.display().to_string(),
        source,
    })?;
    // What eval-lanes will read: checked by its own reader before it is written.
    LabelSet::from_json_str(&path.display().to_string(), &text)
        .map_err(|e| e.during("the imported set does not read back"))?;
    if path.exists() {
        let ours = LabelSet::load(out).is_ok_and(|old| {
            old.licence == IMPORTED_LICENCE || old.licence == IMPORTED_LICENCE_BEFORE
        });
        if !ours {
            return Err(BenchError::Refused(format!(
                "{} exists and was not written by import-lanes: give another output directory",
                path.display()
            )));
        }
    }
    std::fs::create_dir_all(out).map_err(|e| BenchError::io("create", out, e))?;
    std::fs::write(&path, text).map_err(|e| BenchError::io("write", &path, e))?;
    Ok((set, skipped))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::labelled::{LabelSide, ScoringRules, score_frame, track_label_set};
    use lane_tracker::{Estimator, TrackerConfig};

    /// A fresh scratch directory under the build directory.
    fn scratch(name: &str) -> PathBuf {
        let dir = std::env::temp_dir()
            .join(format!("lane-bench-tests-{}", std::process::id()))
            .join(name);
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("scratch directory");
        dir
    }

    /// A grey `w × h` PNG with two bright vertical-ish stripes (a lane's two marks).
    fn write_frame(path: &Path, w: u32, h: u32) {
        std::fs::create_dir_all(path.parent().expect("parent")).expect("image directory");
        let img = image::GrayImage::from_fn(w, h, |x, y| {
            let left = w / 4 + (h - 1 - y) / 4;
            let right = 3 * w / 4 - (h - 1 - y) / 4;
            let on = x.abs_diff(left) <= 1 || x.abs_diff(right) <= 1;
            image::Luma([if on { 220 } else { 60 }])
        });
        img.save(path).expect("png");
    }

    #[test]
    fn a_tusimple_file_imports_as_a_set_eval_lanes_reads_and_reports_what_it_skips() {
        let dir = scratch("import-tusimple");
        let data = dir.join("tusimple");
        write_frame(&data.join("clips/b/1/20.png"), 160, 90);
        write_frame(&data.join("clips/a/7/20.png"), 160, 90);
        write_frame(&data.join("clips/c/1/20.png"), 80, 90);
        let h: Vec<u32> = (50..90).step_by(5).collect();
        let record = |file: &str| {
            // Lanes at the stripes' columns on rows 50, 55, …, 85; a far lane (x > 100 at the
            // bottom) is `other`, and −2 marks rows without a point.
            let left: Vec<i64> = h.iter().map(|&y| i64::from(40 + (89 - y) / 4)).collect();
            let right: Vec<i64> = h.iter().map(|&y| i64::from(120 - (89 - y) / 4)).collect();
            let mut far: Vec<i64> = h.iter().map(|&y| i64::from(150 - (89 - y) / 8)).collect();
            far[0] = -2;
            serde_json::json!({"lanes": [right, far, left], "h_samples": h, "raw_file": file})
                .to_string()
        };
        let text = [
            record("clips/b/1/20.png"),
            "{\"lanes\": oops".to_owned(),
            record("clips/a/7/20.png"),
            record("clips/missing/20.png"),
            record("clips/c/1/20.png"),
        ]
        .join("\n");
        let labels = data.join("label_data_x.json");
        std::fs::write(&labels, text).expect("labels");
        let out = dir.join("sets/mine");

        let (set, skipped) = import_set(
            Format::Tusimple,
            std::slice::from_ref(&labels),
            None,
            &out,
            SceneKind::Road,
        )
        .expect("import");
        // Two frames kept, in clip order; the bad line, the missing image and the image of
        // another size reported, each with where it is.
        assert_eq!((set.width, set.height, set.frames.len()), (160, 90, 2));
        assert_eq!(set.set, "mine");
        assert_eq!(
            set.frames
                .iter()
                .map(|f| f.clip.as_str())
                .collect::<Vec<_>>(),
            ["clips/a/7", "clips/b/1"]
        );
        assert_eq!(skipped.len(), 3, "{skipped:?}");
        assert_eq!(skipped[0].line, 2);
        // The images in clip order: c/1 before missing.
        assert!(skipped[1].reason.contains("80×90"), "{}", skipped[1]);
        assert!(
            skipped[2].path.ends_with("missing/20.png"),
            "{}",
            skipped[2]
        );
        let sides: Vec<LabelSide> = set.frames[0].lanes.iter().map(|l| l.side).collect();
        assert_eq!(sides, [LabelSide::Left, LabelSide::Right, LabelSide::Other]);
        assert_eq!(set.frames[0].lanes[2].points.len(), h.len() - 1);
        // What was written is what eval-lanes reads, and its frames are found and tracked.
        let back = LabelSet::load(&out).expect("written set");
        assert_eq!(back, set);
        let cfg = TrackerConfig::default_preset().expect("default");
        let predictions = track_label_set(&out, &back, &cfg, Estimator::Kif)
            .expect("tracked")
            .predictions;
        assert_eq!(predictions.len(), 2);
        // The labels were written on the drawn stripes, so the tracker's two lanes match them.
        for (frame, prediction) in back.frames.iter().zip(&predictions) {
            let t = score_frame(frame, 160, 90, prediction, &ScoringRules::default());
            assert_eq!(
                (t.label_lanes, t.tusimple_matched),
                (2, 2),
                "{}: {prediction:?}",
                frame.file
            );
        }
    }

    #[test]
    fn a_culane_list_imports_each_video_as_one_clip_and_skips_a_bad_lines_file() {
        let dir = scratch("import-culane");
        let root = dir.join("culane");
        let lines = "40 89 45 70 50 50\n120 89 115 70 110 50\n";
        for (video, frame) in [
            ("v2.MP4", "00000"),
            ("v1.MP4", "00030"),
            ("v1.MP4", "00000"),
        ] {
            let image = root.join(format!("driver_1/{video}/{frame}.png"));
            write_frame(&image, 160, 90);
            std::fs::write(image.with_extension("lines.txt"), lines).expect("lines");
        }
        write_frame(&root.join("driver_1/v3.MP4/00000.png"), 160, 90);
        std::fs::write(root.join("driver_1/v3.MP4/00000.lines.txt"), "1 2 3\n").expect("bad");
        std::fs::create_dir_all(root.join("list")).expect("list dir");
        let list = root.join("list/test.txt");
        std::fs::write(
            &list,
            "/driver_1/v2.MP4/00000.png\n/driver_1/v1.MP4/00030.png\n\
             /driver_1/v3.MP4/00000.png\n/driver_1/v1.MP4/00000.png\n",
        )
        .expect("list");
        let out = dir.join("sets/culane-mine");

        // The data root defaults to the list's directory's parent.
        let (set, skipped) = import_set(
            Format::Culane,
            std::slice::from_ref(&list),
            None,
            &out,
            SceneKind::Road,
        )
        .expect("import");
        let clips: Vec<(&str, bool)> = set
            .frames
            .iter()
            .map(|f| (f.clip.as_str(), f.file.ends_with("00000.png")))
            .collect();
        assert_eq!(
            clips,
            [
                ("driver_1/v1.MP4", true),
                ("driver_1/v1.MP4", false),
                ("driver_1/v2.MP4", true)
            ]
        );
        assert_eq!(skipped.len(), 1, "{skipped:?}");
        assert!(
            skipped[0]
                .to_string()
                .contains("00000.lines.txt:1: 3 numbers"),
            "{}",
            skipped[0]
        );
        let sides: Vec<LabelSide> = set.frames[0].lanes.iter().map(|l| l.side).collect();
        assert_eq!(sides, [LabelSide::Left, LabelSide::Right]);
        assert_eq!(LabelSet::load(&out).expect("written"), set);
        // Importing again over its own set is allowed; over a set it did not write, refused,
        // and that set is left as it was.
        assert!(
            import_set(
                Format::Culane,
                std::slice::from_ref(&list),
                None,
                &out,
                SceneKind::Road
            )
            .is_ok()
        );
        let theirs = dir.join("sets/theirs");
        std::fs::create_dir_all(&theirs).expect("their set");
        let their_text = std::fs::read_to_string(out.join("labels.json"))
            .expect("labels")
            .replace(IMPORTED_LICENCE, "CC-BY-4.0");
        std::fs::write(theirs.join("labels.json"), &their_text).expect("their labels");
        let over = import_set(
            Format::Culane,
            std::slice::from_ref(&list),
            None,
            &theirs,
            SceneKind::Road,
        )
        .expect_err("not ours");
        assert!(
            over.to_string().contains("not written by import-lanes"),
            "{over}"
        );
        assert_eq!(
            std::fs::read_to_string(theirs.join("labels.json")).expect("kept"),
            their_text
        );
        // Two list files are refused: one CULane list is one set.
        let two = import_set(
            Format::Culane,
            &[list.clone(), list],
            None,
            &out,
            SceneKind::Road,
        );
        assert!(two.is_err());
    }
}
