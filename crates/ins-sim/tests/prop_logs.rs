//! Property tests of the INS/SD log readers (`ins_sim::logs`): IMU and sightings CSV,
//! landmark table and initial state TOML, and the data sets' layouts (TUM trajectories, EuRoC/ASL
//! ground truth, IMU and `sensor.yaml`; module `layouts`). Mutated files (flipped bytes, truncation, inserted
//! bytes, NaN/∞/huge or empty fields, duplicated or deleted lines) never panic and either replay
//! or fail with an error naming the file, a line inside it and a column; valid files round-trip.
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use ins_sim::SimError;
use ins_sim::logs::{self, InitialState, ReplayInputs, SolutionRate, names};
use ins_sim::{Mode, Scenario};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngSeed};

fn config() -> Config {
    Config {
        cases: 48,
        failure_persistence: None,
        rng_seed: RngSeed::Fixed(0x6c6f_6773),
        ..Config::default()
    }
}

/// A 6 s flight of the paper's scenario, exported once: the valid logs every case mutates.
fn exported() -> &'static (PathBuf, Scenario) {
    static DIR: OnceLock<(PathBuf, Scenario)> = OnceLock::new();
    DIR.get_or_init(|| {
        let d = std::env::temp_dir().join(format!("ita-nav-prop-logs-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        let sc = Scenario::paper_default().truncated(6.0).unwrap();
        logs::export_run(&sc, Mode::Kf, 11, &d).unwrap();
        (d, sc)
    })
}

#[derive(Debug, Clone)]
enum Mutation {
    FlipByte {
        at: usize,
        bit: u8,
    },
    Truncate {
        at: usize,
    },
    Insert {
        at: usize,
        bytes: Vec<u8>,
    },
    Field {
        line: usize,
        field: usize,
        value: &'static str,
    },
    DuplicateLine {
        line: usize,
    },
    DeleteLine {
        line: usize,
    },
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        (any::<usize>(), 0u8..8).prop_map(|(at, bit)| Mutation::FlipByte { at, bit }),
        any::<usize>().prop_map(|at| Mutation::Truncate { at }),
        (
            any::<usize>(),
            proptest::collection::vec(any::<u8>(), 1..12)
        )
            .prop_map(|(at, bytes)| Mutation::Insert { at, bytes }),
        (
            any::<usize>(),
            0usize..8,
            prop_oneof![
                Just("nan"),
                Just("inf"),
                Just("-inf"),
                Just("1e400"),
                Just(""),
                Just("x"),
                Just("-1"),
                Just("4294967296"),
                Just("1e-320"),
            ]
        )
            .prop_map(|(line, field, value)| Mutation::Field { line, field, value }),
        any::<usize>().prop_map(|line| Mutation::DuplicateLine { line }),
        any::<usize>().prop_map(|line| Mutation::DeleteLine { line }),
    ]
}

fn apply(text: &[u8], m: &Mutation) -> Vec<u8> {
    let mut v = text.to_vec();
    let n = v.len().max(1);
    match m {
        Mutation::FlipByte { at, bit } => {
            let i = at % n;
            if i < v.len() {
                v[i] ^= 1 << bit;
            }
        }
        Mutation::Truncate { at } => v.truncate(at % n),
        Mutation::Insert { at, bytes } => {
            let i = at % n;
            v.splice(i..i, bytes.iter().copied());
        }
        Mutation::Field { line, field, value } => {
            let s = String::from_utf8_lossy(text).into_owned();
            let mut lines: Vec<String> = s.lines().map(str::to_owned).collect();
            let i = line % lines.len().max(1);
            if let Some(l) = lines.get_mut(i) {
                let mut fields: Vec<String> = l.split(',').map(str::to_owned).collect();
                let f = field % fields.len();
                fields[f] = (*value).to_owned();
                *l = fields.join(",");
            }
            v = (lines.join("\n") + "\n").into_bytes();
        }
        Mutation::DuplicateLine { line } | Mutation::DeleteLine { line } => {
            let s = String::from_utf8_lossy(text).into_owned();
            let mut lines: Vec<String> = s.lines().map(str::to_owned).collect();
            let i = line % lines.len().max(1);
            if i < lines.len() {
                if matches!(m, Mutation::DuplicateLine { .. }) {
                    let l = lines[i].clone();
                    lines.insert(i, l);
                } else {
                    lines.remove(i);
                }
            }
            v = (lines.join("\n") + "\n").into_bytes();
        }
    }
    v
}

/// The error names a file the replay reads (the mutated one, or — when damage in one file
/// surfaces where another is applied — that one) and a line inside it (and, for a parse error,
/// a column), once, at the start of its message.
fn check_located(e: &SimError, inputs: &[PathBuf]) -> Result<(), TestCaseError> {
    let shown = e.to_string();
    let (p, line, column) = match e {
        SimError::LogParse {
            path, line, column, ..
        } => (path, Some(*line), Some(*column)),
        SimError::LogToml { path, error } => {
            prop_assert_eq!(error.path.as_str(), path.display().to_string());
            (path, error.line, error.column)
        }
        SimError::LogFilter { path, line, .. } => (path, Some(*line), None),
        SimError::LogIo { path, .. } => (path, None, None),
        other => {
            return Err(TestCaseError::fail(format!(
                "unexpected error kind: {other}"
            )));
        }
    };
    prop_assert!(inputs.contains(p), "{shown}");
    prop_assert!(shown.starts_with(&p.display().to_string()), "{shown}");
    if let Some(line) = line {
        let text = std::fs::read(p).unwrap();
        let lines = text.split(|&b| b == b'\n').count() + 1;
        prop_assert!(
            line >= 1 && line <= lines,
            "line {} of {}: {}",
            line,
            lines,
            shown
        );
    }
    if let Some(column) = column {
        prop_assert!(column >= 1, "{shown}");
    }
    Ok(())
}

/// Replay with one of the files replaced by `bytes`; returns the files it read and the result.
fn replay_with(which: &str, bytes: &[u8], case_dir: &Path) -> (Vec<PathBuf>, Result<(), SimError>) {
    let (dir, sc) = exported();
    std::fs::create_dir_all(case_dir).unwrap();
    let mut files = [
        dir.join(names::IMU),
        dir.join(names::SIGHTINGS),
        dir.join(names::LANDMARKS),
        dir.join(names::INITIAL),
    ];
    let path = case_dir.join(which);
    std::fs::write(&path, bytes).unwrap();
    match which {
        names::IMU => files[0] = path,
        names::SIGHTINGS => files[1] = path,
        names::LANDMARKS => files[2] = path,
        _ => files[3] = path,
    }
    let out = case_dir.join("solution.csv");
    let mut w = std::io::BufWriter::new(std::fs::File::create(&out).unwrap());
    let read = files.to_vec();
    let initial = match logs::read_initial(&files[3]) {
        Ok(i) => i,
        Err(e) => return (read, Err(e)),
    };
    let inputs = ReplayInputs {
        imu: logs::ImuLog::new(files[0].clone(), None),
        sightings: Some((files[1].clone(), files[2].clone())),
        initial,
        config: sc.online_filter_config(Mode::Kf),
        max_gap_s: 1.0,
        rate: SolutionRate::Epochs,
        reference: None,
        align_s: 0.0,
        align_limits: logs::AlignLimits::default(),
        allow_unaided: false,
        level: false,
        mcap_out: None,
    };
    (read, logs::replay(inputs, &mut w, &out).map(|_| ()))
}

fn case_dir(tag: &str) -> PathBuf {
    exported().0.join(format!("case-{tag}"))
}

proptest! {
    #![proptest_config(config())]

    #[test]
    fn mutated_imu_logs_replay_or_name_file_line_and_column(m in mutation()) {
        let text = std::fs::read(exported().0.join(names::IMU)).unwrap();
        let bad = apply(&text, &m);
        let (read, r) = replay_with(names::IMU, &bad, &case_dir("imu"));
        if let Err(e) = r {
            check_located(&e, &read)?;
        }
    }

    #[test]
    fn mutated_sighting_logs_replay_or_name_file_line_and_column(m in mutation()) {
        let text = std::fs::read(exported().0.join(names::SIGHTINGS)).unwrap();
        let bad = apply(&text, &m);
        let (read, r) = replay_with(names::SIGHTINGS, &bad, &case_dir("sightings"));
        if let Err(e) = r {
            check_located(&e, &read)?;
        }
    }

    #[test]
    fn mutated_landmark_tables_load_or_name_file_line_and_column(m in mutation()) {
        let text = std::fs::read(exported().0.join(names::LANDMARKS)).unwrap();
        let bad = apply(&text, &m);
        let dir = case_dir("landmarks");
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join(names::LANDMARKS);
        std::fs::write(&path, &bad).unwrap();
        if let Err(e) = logs::read_landmarks(&path) {
            check_located(&e, std::slice::from_ref(&path))?;
        }
    }

    #[test]
    fn mutated_initial_states_load_or_name_file_line_and_column(m in mutation()) {
        let text = std::fs::read(exported().0.join(names::INITIAL)).unwrap();
        let bad = apply(&text, &m);
        let dir = case_dir("initial");
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join(names::INITIAL);
        std::fs::write(&path, &bad).unwrap();
        if let Err(e) = logs::read_initial(&path) {
            check_located(&e, std::slice::from_ref(&path))?;
        }
    }

    #[test]
    fn mutated_solution_files_read_their_sigma_or_name_file_line_and_column(m in mutation()) {
        let text = std::fs::read(exported().0.join(names::SOLUTION)).unwrap();
        let bad = apply(&text, &m);
        let dir = case_dir("solution");
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join(names::SOLUTION);
        std::fs::write(&path, &bad).unwrap();
        if let Err(e) = logs::read_solution_sigma(&path) {
            check_located(&e, std::slice::from_ref(&path))?;
        }
    }

    #[test]
    fn initial_states_round_trip(
        t in -1e6f64..1e6, lat in -1.5f64..1.5, lon in -3.1f64..3.1, alt in -1e3f64..1e5,
        v in proptest::array::uniform3(-300f64..300.0), q in proptest::array::uniform4(-1f64..1.0),
    ) {
        let s = InitialState { t_s: t, lat_rad: lat, lon_rad: lon, alt_m: alt, vel_ned_mps: v, att_quat_wxyz: q };
        let dir = case_dir("roundtrip");
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join(names::INITIAL);
        std::fs::write(&path, toml::to_string(&s).unwrap()).unwrap();
        prop_assert_eq!(logs::read_initial(&path).unwrap(), s);
    }
}

#[test]
fn a_duplicate_landmark_is_located_at_its_entry() {
    let (dir, _) = exported();
    let text = std::fs::read_to_string(dir.join(names::LANDMARKS)).unwrap();
    let first = text.find("[[landmarks]]").unwrap();
    let entry_end = text[first + 1..]
        .find("[[landmarks]]")
        .map_or(text.len(), |i| i + first + 1);
    let doubled = format!("{text}\n{}", &text[first..entry_end]);
    let d = case_dir("duplicate");
    std::fs::create_dir_all(&d).unwrap();
    let path = d.join(names::LANDMARKS);
    std::fs::write(&path, &doubled).unwrap();
    let e = logs::read_landmarks(&path).unwrap_err();
    let SimError::LogToml { path: p, error } = &e else {
        panic!("{e}")
    };
    assert_eq!(p, &path);
    let line = &error.line.expect("a line");
    let appended_at = text.lines().count() + 2;
    assert!(
        *line >= appended_at,
        "located at line {line}, entry appended at {appended_at}: {e}"
    );
    assert!(
        e.to_string().contains("twice") || e.to_string().to_lowercase().contains("duplicate"),
        "{e}"
    );
}

/// The data sets' layouts (issue 54, item 6): a TUM trajectory, an EuRoC/ASL ground truth and
/// IMU, and `sensor.yaml`, valid before mutation.
mod layouts {
    use std::fmt::Write as _;
    use std::path::PathBuf;

    use ins_sim::logs::{self, LocalAxes, LocalFrame};
    use proptest::prelude::*;

    use super::{apply, case_dir, check_located, config, mutation};

    fn frame() -> LocalFrame {
        LocalFrame::from_text("47.3667,8.55,400", LocalAxes::Enu).unwrap()
    }

    fn tum_text() -> String {
        let mut t = String::from("# t x y z qx qy qz qw\n");
        for k in 0..20 {
            let s = k as f64 * 0.05;
            writeln!(t, "{s} {} {} {} 0.1 -0.2 0.3 0.927", 2.0 * s, -s, 0.1 * s).unwrap();
        }
        t
    }

    fn gt_text() -> String {
        let mut t = String::from(
            "#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], q_RS_y [], q_RS_z [], v_RS_R_x [m s^-1], v_RS_R_y [m s^-1], v_RS_R_z [m s^-1], b_w_RS_S_x [rad s^-1], b_w_RS_S_y [rad s^-1], b_w_RS_S_z [rad s^-1], b_a_RS_S_x [m s^-2], b_a_RS_S_y [m s^-2], b_a_RS_S_z [m s^-2]\n",
        );
        for k in 0..20u64 {
            let s = k as f64 * 0.005;
            writeln!(
                t,
                "{},{},{},0.5,0.8,0.1,-0.2,0.55,2,-1,0,0,0,0,0,0,0",
                1_403_636_579_758_555_392 + k * 5_000_000,
                2.0 * s,
                -s
            )
            .unwrap();
        }
        t
    }

    fn imu_text() -> String {
        let mut t = String::from(
            "#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],a_RS_S_x [m s^-2],a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]\n",
        );
        for k in 0..50u64 {
            writeln!(
                t,
                "{},-0.0027,0.0209,0.0795,9.1,0.2,-2.9",
                1_403_636_579_758_555_392 + k * 5_000_000
            )
            .unwrap();
        }
        t
    }

    const YAML: &str = "sensor_type: imu\nT_BS:\n  cols: 4\n  rows: 4\n  data: [0.0, 0.0, 1.0, 0.0,\n         0.0, 1.0, 0.0, 0.0,\n        -1.0, 0.0, 0.0, 0.0,\n         0.0, 0.0, 0.0, 1.0]\nrate_hz: 200\n";

    /// Writes `mav0/<sub>` under a fresh case directory; returns (the folder, the file).
    fn asl(tag: &str, sub: &str, bytes: &[u8], yaml: &[u8]) -> (PathBuf, PathBuf) {
        let root = case_dir(tag);
        let file = root.join("mav0").join(sub);
        std::fs::create_dir_all(file.parent().unwrap()).unwrap();
        std::fs::write(&file, bytes).unwrap();
        std::fs::write(root.join("mav0/imu0/sensor.yaml"), yaml).ok();
        (root, file)
    }

    fn located<T>(r: Result<T, ins_sim::SimError>, files: &[PathBuf]) -> Result<(), TestCaseError> {
        match r {
            Ok(_) => Ok(()),
            Err(e) => check_located(&e, files),
        }
    }

    fn write(tag: &str, name: &str, bytes: &[u8]) -> PathBuf {
        let dir = case_dir(tag);
        std::fs::create_dir_all(&dir).unwrap();
        let p: PathBuf = dir.join(name);
        std::fs::write(&p, bytes).unwrap();
        p
    }

    #[test]
    fn the_valid_layouts_read() {
        let p = write("tum-valid", "t.tum", tum_text().as_bytes());
        assert_eq!(
            logs::read_reference_in(&p, Some(&frame()), None)
                .unwrap()
                .len(),
            20
        );
        let (root, _) = asl(
            "gt-valid",
            "state_groundtruth_estimate0/data.csv",
            gt_text().as_bytes(),
            YAML.as_bytes(),
        );
        assert_eq!(
            logs::read_reference_in(&root, Some(&frame()), None)
                .unwrap()
                .len(),
            20
        );
        let (root, _) = asl(
            "imu-valid",
            "imu0/data.csv",
            imu_text().as_bytes(),
            YAML.as_bytes(),
        );
        let step = logs::imu_nominal_step_s(&root, None).unwrap();
        // EuRoC's stamps (1.4e9 s) resolve to 0.24 µs as f64 seconds (module `asl`).
        assert!((step - 0.005).abs() < 5e-7, "{step}");
        let yaml = write("yaml-valid", "sensor.yaml", YAML.as_bytes());
        assert_eq!(logs::read_sensor_yaml(&yaml).unwrap()[(0, 2)], 1.0);
    }

    proptest! {
        #![proptest_config(config())]

        #[test]
        fn mutated_tum_trajectories_read_or_name_file_line_and_column(m in mutation()) {
            let p = write("tum", "t.tum", &apply(tum_text().as_bytes(), &m));
            located(logs::read_reference_in(&p, Some(&frame()), None), std::slice::from_ref(&p))?;
            located(logs::read_reference_in(&p, None, None), &[p])?;
        }

        #[test]
        fn mutated_asl_ground_truths_read_or_name_file_line_and_column(m in mutation()) {
            let (root, file) = asl("gt", "state_groundtruth_estimate0/data.csv", &apply(gt_text().as_bytes(), &m), YAML.as_bytes());
            located(logs::read_reference_in(&root, Some(&frame()), None), &[file])?;
        }

        #[test]
        fn mutated_asl_imu_logs_read_or_name_file_line_and_column(m in mutation()) {
            let (root, file) = asl("imu", "imu0/data.csv", &apply(imu_text().as_bytes(), &m), YAML.as_bytes());
            located(logs::imu_nominal_step_s(&root, None), &[file])?;
        }

        #[test]
        fn mutated_sensor_yamls_read_or_name_file_and_line(m in mutation()) {
            let p = write("yaml", "sensor.yaml", &apply(YAML.as_bytes(), &m));
            located(logs::read_sensor_yaml(&p), std::slice::from_ref(&p))?;
            let (root, data) = asl("imu-yaml", "imu0/data.csv", imu_text().as_bytes(), &apply(YAML.as_bytes(), &m));
            located(logs::imu_nominal_step_s(&root, None), &[data, root.join("mav0/imu0/sensor.yaml")])?;
        }
    }
}
