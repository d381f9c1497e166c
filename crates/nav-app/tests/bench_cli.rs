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

const W: u32 = 160;
const H: u32 = 90;

/// The two marks of the ego lane at row `y`: columns of the left and the right one.
fn marks(y: u32) -> (u32, u32) {
    (W / 4 + (H - 1 - y) / 4, 3 * W / 4 - (H - 1 - y) / 4)
}

/// A grey PNG with the two marks drawn bright on a dark road.
fn write_frame(path: &Path) {
    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
    image::GrayImage::from_fn(W, H, |x, y| {
        let (l, r) = marks(y);
        let on = x.abs_diff(l) <= 1 || x.abs_diff(r) <= 1;
        image::Luma([if on { 220 } else { 60 }])
    })
    .save(path)
    .unwrap();
}

/// One TuSimple label record: both marks on rows 50, 55, …, 85.
fn record(file: &str) -> String {
    let rows: Vec<u32> = (50..H).step_by(5).collect();
    let left: Vec<u32> = rows.iter().map(|&y| marks(y).0).collect();
    let right: Vec<u32> = rows.iter().map(|&y| marks(y).1).collect();
    serde_json::json!({"lanes": [left, right], "h_samples": rows, "raw_file": file}).to_string()
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
        write_frame(&data.join(f));
    }
    // The fourth still (held out: the last of four) is cut short: its size reads,
    // its pixels do not decode.
    write_frame(&data.join("clips/d/1/20.png"));
    let bad = data.join("clips/d/1/20.png");
    let bytes = std::fs::read(&bad).unwrap();
    std::fs::write(&bad, &bytes[..bytes.len() - 24]).unwrap();
    let text: Vec<String> = files
        .iter()
        .chain(&["clips/d/1/20.png"])
        .map(|f| record(f))
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

    let eval = nav_app(
        &work,
        &[
            "eval-lanes",
            "--data",
            "sets",
            "--out",
            "report",
            "--config",
            "outdoor",
        ],
    );
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
