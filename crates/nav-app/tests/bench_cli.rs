//! `nav-app import-lanes` and `nav-app eval-lanes` end to end on a labelled set the test draws
//! itself (TuSimple format, no third-party data), run from another working directory: the
//! figures are what the drawn marks give, a still that cannot be decoded is reported and scored
//! as no prediction, and a missing `--data` directory is an error naming it.
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn nav_app(cwd: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_nav-app"))
        .current_dir(cwd)
        .args(args)
        .output()
        .unwrap()
}

fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("nav-app-bench-cli")
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The size of the drawn stills of the import test.
const W: u32 = 160;
const H: u32 = 90;

/// The two marks of the ego lane at row `y` of a `w × h` still: columns of the left and the
/// right one.
fn marks(y: u32, w: u32, h: u32) -> (u32, u32) {
    let lean = (h - 1 - y) * w / 640;
    (w / 4 + lean, 3 * w / 4 - lean)
}

/// A grey `w × h` PNG with the two marks drawn bright on a dark road.
fn write_frame(path: &Path, w: u32, h: u32) {
    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
    image::GrayImage::from_fn(w, h, |x, y| {
        let (l, r) = marks(y, w, h);
        let on = x.abs_diff(l) <= 1 || x.abs_diff(r) <= 1;
        image::Luma([if on { 220 } else { 60 }])
    })
    .save(path)
    .unwrap();
}

/// One TuSimple label record of a `w × h` still: both marks on every fifth row of its lower
/// half.
fn record(file: &str, w: u32, h: u32) -> String {
    let rows: Vec<u32> = (h / 2 + h / 18..h).step_by(5).collect();
    let left: Vec<u32> = rows.iter().map(|&y| marks(y, w, h).0).collect();
    let right: Vec<u32> = rows.iter().map(|&y| marks(y, w, h).1).collect();
    serde_json::json!({"lanes": [left, right], "h_samples": rows, "raw_file": file}).to_string()
}

/// `nav-app eval-lanes` run in `cwd` on its `sets/` with the `outdoor` preset beside the
/// default, into `report/`, with `extra` options.
fn eval_sets(cwd: &Path, extra: &[&str]) -> Output {
    let mut args = vec![
        "eval-lanes",
        "--data",
        "sets",
        "--out",
        "report",
        "--config",
        "outdoor",
    ];
    args.extend_from_slice(extra);
    nav_app(cwd, &args)
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

#[test]
fn an_imported_tusimple_set_is_scored_from_any_directory() {
    let dir = scratch("tusimple");
    let data = dir.join("data");
    let files = ["clips/a/1/20.png", "clips/b/1/20.png", "clips/c/1/20.png"];
    for f in files {
        write_frame(&data.join(f), W, H);
    }
    // The fourth still (held out: the last of four) is cut short: its size reads,
    // its pixels do not decode.
    write_frame(&data.join("clips/d/1/20.png"), W, H);
    let bad = data.join("clips/d/1/20.png");
    let bytes = std::fs::read(&bad).unwrap();
    std::fs::write(&bad, &bytes[..bytes.len() - 24]).unwrap();
    let text: Vec<String> = files
        .iter()
        .chain(&["clips/d/1/20.png"])
        .map(|f| record(f, W, H))
        .collect();
    std::fs::write(data.join("label_data.json"), text.join("\n")).unwrap();
    let work = dir.join("work");
    std::fs::create_dir_all(&work).unwrap();

    // Relative paths are the working directory's.
    let import = nav_app(
        &work,
        &[
            "import-lanes",
            "--format",
            "tusimple",
            "--out",
            "sets/drawn",
            "../data/label_data.json",
        ],
    );
    assert!(import.status.success(), "{}", stderr(&import));
    let said = String::from_utf8_lossy(&import.stdout);
    assert!(said.contains("4 frames (160×90)"), "{said}");
    assert!(work.join("sets/drawn/labels.json").is_file());

    let eval = eval_sets(&work, &[]);
    assert!(eval.status.success(), "{}", stderr(&eval));
    // The bad still is reported, naming it, and the run goes on.
    let err = stderr(&eval);
    assert!(
        err.contains("clips/d/1/20.png") && err.contains("skipped"),
        "{err}"
    );
    for f in [
        "summary.json",
        "summary.md",
        "frames.csv",
        "worst_frames.png",
    ] {
        assert!(work.join("report").join(f).is_file(), "{f}");
    }
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(work.join("report/summary.json")).unwrap())
            .unwrap();
    let set = &summary["sets"][0];
    assert_eq!(set["set"], "drawn");
    assert_eq!(set["frames"], 4);
    let default = &set["results"]["default"];
    let rate = |split: &str, key: &str| default[split][key].as_f64().unwrap();
    // Development part (the first three stills): both drawn marks found, no false positive.
    assert_eq!(rate("dev", "label_lanes"), 6.0);
    assert_eq!(rate("dev", "predicted_lanes"), 6.0);
    assert!(rate("dev", "tusimple_accuracy") > 0.95, "{default}");
    assert_eq!(rate("dev", "tusimple_fn"), 0.0);
    assert_eq!(rate("dev", "tusimple_fp"), 0.0);
    assert_eq!(rate("dev", "aly_detection_rate"), 1.0);
    // Held out: the undecodable still, scored as no prediction (both label lanes missed).
    assert_eq!(rate("holdout", "label_lanes"), 2.0);
    assert_eq!(rate("holdout", "predicted_lanes"), 0.0);
    assert_eq!(rate("holdout", "tusimple_fn"), 1.0);
    assert!(set["results"]["outdoor"].is_object());
    // frames.csv: one row per scored side of each frame, the bad still's unpredicted.
    let csv = std::fs::read_to_string(work.join("report/frames.csv")).unwrap();
    let rows: Vec<&str> = csv.lines().skip(1).collect();
    assert_eq!(rows.len(), 8, "{csv}");
    assert!(
        rows.iter()
            .filter(|r| r.contains("clips/d/1/20.png"))
            .all(|r| r.contains(",hold-out,") && r.contains(",1,0,")),
        "{csv}"
    );
    let md = std::fs::read_to_string(work.join("report/summary.md")).unwrap();
    assert!(md.starts_with("# Lane tracker on real labelled frames (`nav-app eval-lanes`)"));
}

#[test]
fn a_missing_data_directory_is_an_error_naming_it() {
    let work = scratch("missing");
    let o = nav_app(&work, &["eval-lanes", "--data", "no-such-sets"]);
    assert_eq!(o.status.code(), Some(1));
    let err = stderr(&o);
    assert!(
        err.starts_with("nav-app eval-lanes: error: ") && err.contains("no-such-sets"),
        "{err}"
    );
    // --check needs a floors file: the user command has none of its own.
    let o = nav_app(&work, &["eval-lanes", "--data", ".", "--check"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("--floors FILE"), "{}", stderr(&o));
    // import-lanes with nothing importable fails, saying so.
    std::fs::write(work.join("empty.json"), "").unwrap();
    let o = nav_app(
        &work,
        &[
            "import-lanes",
            "--format",
            "tusimple",
            "--out",
            "s/x",
            "empty.json",
        ],
    );
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr(&o).contains("no frame could be imported"),
        "{}",
        stderr(&o)
    );
}

/// A `w × h` still with the ego lane's two marks and a third mark right of the right one (the
/// next lane's outer boundary), and its TuSimple record labelling that third mark as the right
/// ego lane: the tracker's right lane misses its label, one of its candidates does not.
fn write_relabelled(data: &Path, file: &str, w: u32, h: u32) -> String {
    let outer = |y: u32| 3 * w / 4 + w / 5 - (h - 1 - y) * w / 1280;
    let path = data.join(file);
    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
    image::GrayImage::from_fn(w, h, |x, y| {
        let (l, r) = marks(y, w, h);
        let on = x.abs_diff(l) <= 1 || x.abs_diff(r) <= 1 || x.abs_diff(outer(y)) <= 1;
        image::Luma([if on { 220 } else { 60 }])
    })
    .save(&path)
    .unwrap();
    let rows: Vec<u32> = (h / 2 + h / 18..h).step_by(5).collect();
    let left: Vec<u32> = rows.iter().map(|&y| marks(y, w, h).0).collect();
    let right: Vec<u32> = rows.iter().map(|&y| outer(y)).collect();
    serde_json::json!({"lanes": [left, right], "h_samples": rows, "raw_file": file}).to_string()
}

#[test]
fn under_each_perturbation_the_bound_of_the_choice_is_reported_and_bounds_the_default() {
    let (w, h) = (320, 180);
    let dir = scratch("perturb");
    let data = dir.join("data");
    let files = [
        "clips/a/1/20.png",
        "clips/b/1/20.png",
        "clips/c/1/20.png",
        "clips/d/1/20.png",
    ];
    let text: Vec<String> = files
        .iter()
        .map(|f| write_relabelled(&data, f, w, h))
        .collect();
    std::fs::write(data.join("label_data.json"), text.join("\n")).unwrap();
    let import = nav_app(
        &dir,
        &[
            "import-lanes",
            "--format",
            "tusimple",
            "--out",
            "sets/drawn",
            "data/label_data.json",
        ],
    );
    assert!(import.status.success(), "{}", stderr(&import));
    let eval = eval_sets(&dir, &["--perturb"]);
    assert!(eval.status.success(), "{}", stderr(&eval));
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("report/summary.json")).unwrap())
            .unwrap();
    assert_eq!(summary["schema"], 4, "the bound's fields are schema 4's");
    let acc = |rates: &serde_json::Value, split: &str| {
        rates[split]["tusimple_accuracy"].as_f64().unwrap()
    };
    let unperturbed_bound = &summary["overall"]["best-of-candidates"];
    let perturbations = summary["perturbations"].as_array().unwrap();
    assert_eq!(perturbations.len(), 15);
    for p in perturbations {
        let name = p["perturbation"].as_str().unwrap();
        let bound = &p["best_of_candidates"];
        for split in ["dev", "holdout"] {
            // The output's right lane is on the ego mark, off its label; the candidate on the
            // labelled mark is the bound's, under every perturbation of these stills.
            assert!(acc(&p["overall"], split) < 0.6, "{name} {split}: {p}");
            assert!(acc(bound, split) > 0.99, "{name} {split}: {p}");
            assert_eq!(
                acc(&p["best_of_candidates_sets"]["drawn"], split),
                acc(bound, split),
                "{name}: one set, its figures are the pooled ones"
            );
        }
        if name == "width-320" {
            // The stills' own width: the frames as they are, so the bound as it is.
            for split in ["dev", "holdout", "all"] {
                assert_eq!(acc(bound, split), acc(unperturbed_bound, split), "{p}");
            }
        }
    }
    let md = std::fs::read_to_string(dir.join("report/summary.md")).unwrap();
    assert!(
        md.contains("The bound of the default's choice under each perturbation"),
        "{md}"
    );
    assert!(md.contains("| perturbation | hold-out best | Δ | bound on the default's Δ |"));
    // Per set: the default / the bound under the stills' own width, the bound 100 %.
    assert!(
        md.contains("Per set, hold-out part: the default / the bound of its choice"),
        "{md}"
    );
    assert!(md.contains("| width-320 | 50.0 / 100.0 (+50.0) |"), "{md}");
}
