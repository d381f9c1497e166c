//! `nav-app --camera`: the ego lane in metres on every frame with both lanes, a camera for
//! another frame size refused naming the field, a bad camera field named with its file, line and
//! column. The input is the real udacity clip from the data root (`lane_bench::data`; missing, it
//! fails these tests under CI and skips them, saying so, elsewhere).
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use std::process::Command;

use lane_tracker::camera::CAMERA_ROBOT_TOML;

/// The clip's path; `None` (skipped, said on stderr) when it is missing outside CI, a failure
/// naming it under CI.
fn udacity() -> Option<String> {
    lane_bench::data::test_data_file(lane_bench::data::UDACITY_CLIP)
        .unwrap_or_else(|e| panic!("{e}"))
        .map(|p| p.display().to_string())
}

#[test]
fn cli_prints_the_ego_lane_for_every_frame_with_both_lanes() {
    let Some(input) = udacity() else {
        return;
    };
    let camera = format!(
        "{}/../../configs/camera-highway.toml",
        env!("CARGO_MANIFEST_DIR")
    );
    let o = Command::new(env!("CARGO_BIN_EXE_nav-app"))
        .args([
            "--input",
            &input,
            "--camera",
            &camera,
            "--json",
            "--max-frames",
            "30",
        ])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = String::from_utf8(o.stdout).unwrap();
    let mut with_both = 0;
    for line in text.lines() {
        let v: serde_json::Value = serde_json::from_str(line).unwrap();
        if v.get("summary").is_some() {
            continue; // the run's last line
        }
        let lanes = v["lanes"].as_array().unwrap();
        let both = lanes.iter().all(|l| !l["coeffs"].is_null());
        let ego = &v["ego_lane"];
        assert_eq!(both, !ego.is_null(), "{line}");
        if both {
            with_both += 1;
            for key in [
                "lateral_offset_m",
                "heading_rad",
                "curvature_per_m",
                "lane_width_m",
            ] {
                let x = ego[key].as_f64().unwrap();
                let s = ego[format!("{key}_sigma")].as_f64().unwrap();
                assert!(
                    x.is_finite() && s.is_finite() && s > 0.0,
                    "{key}: {x} ± {s}"
                );
            }
            // The highway preset's height was estimated from a 3.7 m lane.
            let w = ego["lane_width_m"].as_f64().unwrap();
            assert!((w - 3.7).abs() < 0.3, "{w}");
            let cov = v["lane_cov_px"].as_array().unwrap();
            for c in cov {
                let m = c.as_array().unwrap();
                assert_eq!(m.len(), 3);
                let a11 = m[0][0].as_f64().unwrap();
                assert!(a11 > 0.0);
                assert!((m[0][2].as_f64().unwrap() - m[2][0].as_f64().unwrap()).abs() < 1e-9);
            }
        }
    }
    assert_eq!(with_both, 30);
}

#[test]
fn cli_refuses_a_camera_for_another_frame_size_naming_the_field() {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("camera-cli");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("cam640.toml");
    std::fs::write(
        &path,
        CAMERA_ROBOT_TOML.replace("image_size_px = [320, 240]", "image_size_px = [640, 480]"),
    )
    .unwrap();
    let Some(input) = udacity() else {
        return;
    };
    let o = Command::new(env!("CARGO_BIN_EXE_nav-app"))
        .args([
            "--input",
            &input,
            "--camera",
            path.to_str().unwrap(),
            "--json",
        ])
        .output()
        .unwrap();
    assert!(!o.status.success());
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(e.contains("image_size_px"), "{e}");
}
