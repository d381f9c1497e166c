//! `nav-app ins` reads the data sets' own layouts (issue 54, item 6): an EuRoC/ASL `mav0`
//! folder as `--imu` (nanosecond stamps, ω then a, the IMU's axes rotated into the body's by
//! `sensor.yaml`'s T_BS or `--imu-to-body`), its ground truth and a TUM trajectory as `--truth`
//! (`--tum-origin`, `--tum-frame`). The same log written in the project's CSV and in those
//! layouts replays to the same solution; bad input is an error naming the file and line.
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

mod ins_common;

use std::fmt::Write as _;
use std::path::Path;

use ins_common::{nav_app, scratch, stderr, write_imu, write_reference, write_sightings};

/// C_B^S of the test folders: 90° about z (entries 0 and ±1, so rotating is exact).
const T_BS_ROWS: [[i32; 3]; 3] = [[0, -1, 0], [1, 0, 0], [0, 0, 1]];

fn sensor_yaml(rows: [[i32; 3]; 3]) -> String {
    let r = |i: usize| format!("{}.0, {}.0, {}.0, 0.0", rows[i][0], rows[i][1], rows[i][2]);
    format!(
        "# General sensor definitions.\nsensor_type: imu\ncomment: VI-Sensor IMU (ADIS16448)\n\n\
         # Sensor extrinsics wrt. the body-frame.\nT_BS:\n  cols: 4\n  rows: 4\n  data: [{},\n         {},\n         {},\n         0.0, 0.0, 0.0, 1.0]\nrate_hz: 200\n",
        r(0),
        r(1),
        r(2)
    )
}

/// The project's rates CSV at `csv` written again as `root/mav0/imu0/data.csv` in the sensor's
/// axes (a_S = C_S^B·a_B with C_B^S = `T_BS_ROWS`: exact sign flips and swaps), stamps in ns.
fn write_asl_imu(csv: &Path, root: &Path, yaml: bool) {
    let dir = root.join("mav0/imu0");
    std::fs::create_dir_all(&dir).unwrap();
    let mut text = String::from(
        "#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],a_RS_S_x [m s^-2],a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]\n",
    );
    let src = std::fs::read_to_string(csv).unwrap();
    // Rows of C_S^B = (C_B^S)ᵀ as (index, sign) of the body component.
    let s_from_b = |f: &[&str], i: usize| -> String {
        let (k, sign) = (0..3)
            .find_map(|k| {
                let c = T_BS_ROWS[k][i];
                (c != 0).then_some((k, c))
            })
            .unwrap();
        let v = f[k];
        match (sign, v.strip_prefix('-')) {
            (1, _) => v.to_string(),
            (_, Some(pos)) => pos.to_string(),
            _ => format!("-{v}"),
        }
    };
    for line in src.lines().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        let hundredths: u64 = f[0].replace('.', "").parse().unwrap();
        let ns = hundredths * 10_000_000;
        let (g, a) = (&f[1..4], &f[4..7]);
        writeln!(
            text,
            "{ns},{},{},{},{},{},{}",
            s_from_b(g, 0),
            s_from_b(g, 1),
            s_from_b(g, 2),
            s_from_b(a, 0),
            s_from_b(a, 1),
            s_from_b(a, 2)
        )
        .unwrap();
    }
    std::fs::write(dir.join("data.csv"), text).unwrap();
    if yaml {
        std::fs::write(dir.join("sensor.yaml"), sensor_yaml(T_BS_ROWS)).unwrap();
    }
}

fn run(args: &[&str]) -> std::process::Output {
    let mut all = vec!["ins"];
    all.extend_from_slice(args);
    nav_app(&all)
}

/// Solution CSV rows as numbers.
fn solution(path: &Path) -> Vec<Vec<f64>> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .skip(1)
        .map(|l| {
            l.split(',')
                .map(|x| x.parse().unwrap_or(f64::NAN))
                .collect()
        })
        .collect()
}

#[test]
fn ins_an_asl_folder_replays_to_the_same_solution_as_the_project_csv_byte_for_byte() {
    let dir = scratch("asl-imu");
    let p = |n: &str| dir.join(n).display().to_string();
    write_imu(&dir.join("imu.csv"));
    write_reference(&dir.join("truth.csv"), 0.0, 0.0);
    let (s, lm) = write_sightings(&dir);
    write_asl_imu(&dir.join("imu.csv"), &dir.join("asl"), true);
    write_asl_imu(&dir.join("imu.csv"), &dir.join("asl_no_yaml"), false);
    let common = |imu: String, out: &str| -> Vec<String> {
        [
            "--imu",
            &imu,
            "--truth",
            &p("truth.csv"),
            "--sightings",
            &s,
            "--landmarks",
            &lm,
            "--out",
            &p(out),
        ]
        .map(String::from)
        .to_vec()
    };
    let go = |args: Vec<String>| {
        let o = run(&args.iter().map(String::as_str).collect::<Vec<_>>());
        assert!(o.status.success(), "{}", stderr(&o));
    };
    go(common(p("imu.csv"), "csv.csv"));
    // The folder holding mav0, and mav0 itself: T_BS from sensor.yaml.
    go(common(p("asl"), "asl.csv"));
    go(common(p("asl/mav0"), "mav0.csv"));
    // No sensor.yaml: the rotation given.
    let mut given = common(p("asl_no_yaml"), "given.csv");
    given.extend(["--imu-to-body".into(), "0,-1,0,1,0,0,0,0,1".into()]);
    go(given);
    let csv = std::fs::read(dir.join("csv.csv")).unwrap();
    for out in ["asl.csv", "mav0.csv", "given.csv"] {
        assert!(
            std::fs::read(dir.join(out)).unwrap() == csv,
            "{out} differs from the CSV log's solution"
        );
    }
    // The rotation matters: the identity (the axes as logged) gives another solution.
    let mut wrong = common(p("asl_no_yaml"), "identity.csv");
    wrong.extend(["--imu-to-body".into(), "1,0,0,0,1,0,0,0,1".into()]);
    go(wrong);
    assert!(std::fs::read(dir.join("identity.csv")).unwrap() != csv);
}

#[test]
fn ins_tum_and_asl_references_replay_to_the_csv_references_solution() {
    let dir = scratch("tum");
    let p = |n: &str| dir.join(n).display().to_string();
    write_imu(&dir.join("imu.csv"));
    write_reference(&dir.join("truth.csv"), 0.0, 0.0);
    let (s, lm) = write_sightings(&dir);
    // The same reference (at rest at 40° N, −105°, 1600 m, body FRD = NED) as a TUM file in
    // ENU axes (body → ENU: 180° about (1, 1, 0)/√2) and as an ASL ground truth in NED axes
    // (q_RS = C_R^B·C_B^S = the 90° turn about z of T_BS).
    let h = std::f64::consts::FRAC_1_SQRT_2;
    let mut tum = String::from("# timestamp tx ty tz qx qy qz qw\n");
    let mut gt = String::from(
        "#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], q_RS_y [], q_RS_z [], v_RS_R_x [m s^-1], v_RS_R_y [m s^-1], v_RS_R_z [m s^-1], b_w_RS_S_x [rad s^-1], b_w_RS_S_y [rad s^-1], b_w_RS_S_z [rad s^-1], b_a_RS_S_x [m s^-2], b_a_RS_S_y [m s^-2], b_a_RS_S_z [m s^-2]\n",
    );
    for k in 0..=200u64 {
        writeln!(tum, "{:.1} 0 0 0 {h} {h} 0 0", k as f64 * 0.1).unwrap();
        writeln!(
            gt,
            "{},0,0,0,{h},0,0,{h},0,0,0,0,0,0,0,0,0",
            k * 100_000_000
        )
        .unwrap();
    }
    std::fs::write(dir.join("truth.tum"), tum).unwrap();
    let gt_dir = dir.join("asl/mav0/state_groundtruth_estimate0");
    std::fs::create_dir_all(&gt_dir).unwrap();
    std::fs::write(gt_dir.join("data.csv"), gt).unwrap();
    write_asl_imu(&dir.join("imu.csv"), &dir.join("asl"), true);
    let go = |imu: &str, truth: &str, out: &str, frame: Option<&str>| {
        let mut args = vec![
            "--imu".to_string(),
            p(imu),
            "--truth".into(),
            p(truth),
            "--sightings".into(),
            s.clone(),
            "--landmarks".into(),
            lm.clone(),
            "--out".into(),
            p(out),
        ];
        if let Some(f) = frame {
            args.extend([
                "--tum-origin".into(),
                "40,-105,1600".into(),
                "--tum-frame".into(),
                f.into(),
            ]);
        }
        let o = run(&args.iter().map(String::as_str).collect::<Vec<_>>());
        assert!(o.status.success(), "{}", stderr(&o));
    };
    go("imu.csv", "truth.csv", "csv.csv", None);
    go("imu.csv", "truth.tum", "tum.csv", Some("enu"));
    go("asl", "asl", "asl.csv", Some("ned"));
    let want = solution(&dir.join("csv.csv"));
    for out in ["tum.csv", "asl.csv"] {
        let got = solution(&dir.join(out));
        assert_eq!(got.len(), want.len(), "{out}");
        // Through ECEF and back the origin moves by round-off: lat/lon to 1e-13 rad (< 1 µm),
        // the rest to 1e-7 (m, m/s, quaternion, σ, NIS).
        for (g, w) in got.iter().zip(&want) {
            // q and −q are one attitude: compare with the same sign.
            let mut g = g.clone();
            if (7..11).map(|c| g[c] * w[c]).sum::<f64>() < 0.0 {
                (7..11).for_each(|c| g[c] = -g[c]);
            }
            for (c, (a, b)) in g.iter().zip(w).enumerate() {
                let tol = if c == 1 || c == 2 { 1e-13 } else { 1e-7 };
                assert!(
                    (a - b).abs() <= tol || (a.is_nan() && b.is_nan()),
                    "{out}, t = {}, column {c}: {a} vs {b}",
                    w[0]
                );
            }
        }
    }
}

#[test]
fn ins_bad_dataset_layouts_are_errors_naming_the_file_and_line() {
    let dir = scratch("layout-errors");
    let p = |n: &str| dir.join(n).display().to_string();
    write_imu(&dir.join("imu.csv"));
    write_reference(&dir.join("truth.csv"), 0.0, 0.0);
    let fails = |args: &[&str], want: &str| {
        let mut all = args.to_vec();
        all.extend(["--filter", "none", "--out", "/dev/null"]);
        let o = run(&all);
        let e = stderr(&o);
        assert_eq!(o.status.code(), Some(1), "{e}");
        assert!(e.contains(want), "`{want}` in {e}");
        assert!(!e.contains("panicked"), "{e}");
    };
    // A missing column.
    write_asl_imu(&dir.join("imu.csv"), &dir.join("short"), true);
    let data = dir.join("short/mav0/imu0/data.csv");
    let text = std::fs::read_to_string(&data).unwrap();
    let cut: String = text
        .lines()
        .map(|l| l.rsplit_once(',').unwrap().0.to_owned() + "\n")
        .collect();
    std::fs::write(&data, cut).unwrap();
    fails(
        &["--imu", &p("short"), "--truth", &p("truth.csv")],
        &format!("{}:1:", data.display()),
    );
    fails(
        &["--imu", &p("short"), "--truth", &p("truth.csv")],
        "header ends before `a_RS_S_z`",
    );
    // Stamps that go back.
    write_asl_imu(&dir.join("imu.csv"), &dir.join("back"), true);
    let data = dir.join("back/mav0/imu0/data.csv");
    let mut lines: Vec<String> = std::fs::read_to_string(&data)
        .unwrap()
        .lines()
        .map(String::from)
        .collect();
    lines.swap(4, 5);
    std::fs::write(&data, lines.join("\n") + "\n").unwrap();
    fails(
        &["--imu", &p("back"), "--truth", &p("truth.csv")],
        &format!(
            "{}:6:1: timestamp 40000000 ns is not after the previous row's (50000000 ns)",
            data.display()
        ),
    );
    // No sensor.yaml and no --imu-to-body.
    write_asl_imu(&dir.join("imu.csv"), &dir.join("noyaml"), false);
    fails(
        &["--imu", &p("noyaml"), "--truth", &p("truth.csv")],
        "sensor.yaml:1:1: missing: the IMU-to-body rotation",
    );
    // Not a rotation.
    fails(
        &[
            "--imu",
            &p("noyaml"),
            "--truth",
            &p("truth.csv"),
            "--imu-to-body",
            "1,0,0,0,2,0,0,0,1",
        ],
        "--imu-to-body: must be a rotation matrix",
    );
    // A TUM reference without its origin, and one with a short line.
    std::fs::write(
        dir.join("t.tum"),
        "# t x y z qx qy qz qw\n0 0 0 0 0 0 0 1\n0.1 0 0 0 0 0 0 1\n",
    )
    .unwrap();
    fails(
        &["--imu", &p("imu.csv"), "--truth", &p("t.tum")],
        &format!(
            "{}:2:1: a TUM trajectory holds positions in a local frame: give its geodetic origin and axes with --tum-origin LAT,LON,ALT --tum-frame enu|ned",
            p("t.tum")
        ),
    );
    std::fs::write(dir.join("s.tum"), "0 0 0 0 0 0 0 1\n0.1 0 0 0 0 0 1\n").unwrap();
    fails(
        &[
            "--imu",
            &p("imu.csv"),
            "--truth",
            &p("s.tum"),
            "--tum-origin",
            "40,-105,1600",
            "--tum-frame",
            "enu",
        ],
        &format!("{}:2:", p("s.tum")),
    );
    fails(
        &[
            "--imu",
            &p("imu.csv"),
            "--truth",
            &p("s.tum"),
            "--tum-origin",
            "40,-105,1600",
            "--tum-frame",
            "enu",
        ],
        "expected the 8 fields of a TUM pose `t x y z qx qy qz qw`, found 7",
    );
}
