//! The replay refuses what cannot be right (issue 54, items 1 and 2), on small logs written
//! here: inputs on other clocks are errors naming each file and its span, a filter that used no
//! sighting is an error unless allowed, every input row not used is counted, and a static
//! alignment is refused when the vehicle is not at rest (the measured spread or speed and the
//! filter file's limit in the message).
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use ins_sim::filter_file::FilterFile;
use ins_sim::logs::{
    self, FilterSettings, ReplayRequest, ReplaySummary, SightingPlan, SolutionRate,
};
use ins_sim::{Mode, SimError};

const LAT_DEG: f64 = 40.0;
const LON_DEG: f64 = -105.0;
const ALT_M: f64 = 1600.0;

fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("ita-nav-checks-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A 100 Hz rates log from `t0_s` for `duration_s`, level, heading north, at rest plus
/// `motion(t) = (specific force, angular rate)` added in body axes; a small deterministic noise.
fn write_imu(
    path: &Path,
    t0_s: f64,
    duration_s: f64,
    motion: impl Fn(f64) -> ([f64; 3], [f64; 3]),
) {
    let lat = LAT_DEG.to_radians();
    let g = ins_errors::earth::normal_gravity_mps2(lat, ALT_M);
    let w = ins_errors::earth::earth_rate_ned_radps(lat);
    let mut text = String::from(logs::IMU_RATES_HEADER) + "\n";
    let n = (duration_s * 100.0).round() as usize;
    for k in 1..=n {
        let t = t0_s + k as f64 * 0.01;
        // A zero-mean pseudo-noise: 2e-3 m/s², 1e-4 rad/s.
        let e = ((k * 7919) % 1000) as f64 / 1000.0 - 0.4995;
        let (f, r) = motion(t - t0_s);
        writeln!(
            text,
            "{t:.5},{:e},{:e},{:e},{:e},{:e},{:e}",
            w.x + r[0] + 1e-4 * e,
            w.y + r[1] - 1e-4 * e,
            w.z + r[2],
            f[0] + 2e-3 * e,
            f[1] - 2e-3 * e,
            -g + f[2],
        )
        .unwrap();
    }
    std::fs::write(path, text).unwrap();
}

fn at_rest(_: f64) -> ([f64; 3], [f64; 3]) {
    ([0.0; 3], [0.0; 3])
}

/// A reference at 10 Hz from `t0_s` for `duration_s`, level, heading north, moving north at
/// `speed_mps`.
fn write_reference(path: &Path, t0_s: f64, duration_s: f64, speed_mps: f64) {
    let mut text = String::from(logs::REFERENCE_DEG_HEADER) + "\n";
    let n = (duration_s * 10.0).round() as usize;
    let (rn, _) = ins_errors::earth::radii_of_curvature_m(LAT_DEG.to_radians());
    for k in 0..=n {
        let dt = k as f64 * 0.1;
        let lat = LAT_DEG + (speed_mps * dt / (rn + ALT_M)).to_degrees();
        writeln!(
            text,
            "{:.3},{lat:.10},{LON_DEG},{ALT_M},{speed_mps},0,0,1,0,0,0",
            t0_s + dt
        )
        .unwrap();
    }
    std::fs::write(path, text).unwrap();
}

/// Landmarks around the reference and 1 Hz sightings from it, times shifted by `shift_s`.
fn write_sightings(dir: &Path, reference: &Path, shift_s: f64) -> (PathBuf, PathBuf) {
    let rows = logs::read_reference(reference).unwrap();
    let lm = dir.join("landmarks.toml");
    let entries = logs::landmarks_around(&rows, 8, 30.0, 100.0, 3).unwrap();
    logs::write_landmarks(&lm, &entries).unwrap();
    let table = logs::read_landmarks(&lm).unwrap();
    let path = dir.join("sightings.csv");
    let mut buf = Vec::new();
    let plan = SightingPlan {
        max_per_epoch: 4,
        ..SightingPlan::default()
    };
    logs::write_sightings(&rows, &table, &plan, &mut buf, &path).unwrap();
    let text = String::from_utf8(buf).unwrap();
    let mut shifted = String::new();
    for (i, line) in text.lines().enumerate() {
        if i == 0 {
            shifted += line;
        } else {
            let (t, rest) = line.split_once(',').unwrap();
            let t: f64 = t.parse().unwrap();
            write!(shifted, "{:e},{rest}", t + shift_s).unwrap();
        }
        shifted.push('\n');
    }
    std::fs::write(&path, shifted).unwrap();
    (path, lm)
}

fn write_initial(path: &Path, init: &logs::InitialState) {
    std::fs::write(path, toml::to_string(init).unwrap()).unwrap();
}

fn request(dir: &Path, sightings: Option<(PathBuf, PathBuf)>) -> ReplayRequest {
    ReplayRequest {
        imu: dir.join("imu.csv"),
        imu_topic: None,
        mode: if sightings.is_some() {
            Mode::Kf
        } else {
            Mode::Standalone
        },
        sightings,
        initial: None,
        reference: Some(dir.join("truth.csv")),
        start_s: None,
        settings: FilterSettings::File(FilterFile::preset("mems").unwrap()),
        gate: None,
        align_s: 0.0,
        allow_unaided: false,
        max_gap_s: 5.0,
        rate: SolutionRate::Hz(1.0),
        mcap_out: None,
        layouts: Default::default(),
    }
}

fn run(dir: &Path, r: &ReplayRequest) -> Result<ReplaySummary, SimError> {
    let out = dir.join("solution.csv");
    let mut w = std::io::BufWriter::new(std::fs::File::create(&out).unwrap());
    logs::replay(r.inputs()?, &mut w, &out)
}

fn expect_spans(result: Result<ReplaySummary, SimError>, problem: &str) -> String {
    match result {
        Err(e @ SimError::InputSpans { .. }) => {
            let text = e.to_string();
            assert!(text.contains(problem), "{text}");
            text
        }
        Err(e) => panic!("another error: {e}"),
        Ok(s) => panic!(
            "accepted: {} IMU samples, {} epochs, metrics {:?}",
            s.imu_samples,
            s.epochs,
            s.metrics.map(|m| (m.compared, m.position_m.rms))
        ),
    }
}

/// The trap: a reference on the device's boot clock (t ≈ 46 408 s) with an IMU log
/// from 0 gave 0 IMU samples and a perfect-looking 0.000 m RMS.
#[test]
fn a_reference_on_another_clock_is_refused_naming_each_file_and_its_span() {
    let dir = temp_dir("ref-clock");
    write_imu(&dir.join("imu.csv"), 0.0, 20.0, at_rest);
    write_reference(&dir.join("truth.csv"), 0.0, 20.0, 0.0);
    let sightings = write_sightings(&dir, &dir.join("truth.csv"), 0.0);
    write_reference(&dir.join("truth.csv"), 46_408.547, 20.0, 0.0);
    let text = expect_spans(
        run(&dir, &request(&dir, Some(sightings.clone()))),
        "the inputs do not overlap in time: no IMU sample after the start of the replay at t = 46408.547 s",
    );
    let imu = dir.join("imu.csv").display().to_string();
    let truth = dir.join("truth.csv").display().to_string();
    let s = sightings.0.display().to_string();
    assert!(
        text.contains(&format!("IMU log {imu}: t = 0.010–20.000 s (2000 rows)")),
        "{text}"
    );
    assert!(
        text.contains(&format!(
            "reference {truth}: t = 46408.547–46428.547 s (201 rows)"
        )),
        "{text}"
    );
    assert!(
        text.contains(&format!("sightings {s}: t = 1.000–")),
        "{text}"
    );
    // Unaided too: no filter, the same refusal.
    expect_spans(
        run(&dir, &request(&dir, None)),
        "no IMU sample after the start",
    );
    // With an initial state of the IMU's clock, the reference is never compared.
    let rows = logs::read_reference(&dir.join("truth.csv")).unwrap();
    let init = logs::initial_from_reference(&rows, rows[0].t_s, 1.0).unwrap();
    let init_path = dir.join("initial.toml");
    write_initial(&init_path, &logs::InitialState { t_s: 0.0, ..init });
    let mut r = request(&dir, None);
    r.initial = Some(init_path);
    expect_spans(
        run(&dir, &r),
        "no reference row inside the replay, t = 0.000–20.000 s",
    );
}

/// An IMU log that starts long after the start of the replay (the reference's first row).
#[test]
fn an_imu_log_that_starts_long_after_the_start_is_refused_with_the_spans() {
    let dir = temp_dir("imu-late");
    write_imu(&dir.join("imu.csv"), 100.0, 10.0, at_rest);
    write_reference(&dir.join("truth.csv"), 0.0, 20.0, 0.0);
    let sightings = write_sightings(&dir, &dir.join("truth.csv"), 0.0);
    let text = expect_spans(
        run(&dir, &request(&dir, Some(sightings))),
        "the first IMU sample after the start of the replay (t = 0.000 s) comes 100.010 s later",
    );
    assert!(text.contains("t = 100.010–110.000 s (1000 rows)"), "{text}");
    // The sightings' whole span, though the replay stopped before the first.
    assert!(text.contains("t = 1.000–20.000 s (80 rows)"), "{text}");
}

/// The second trap: sightings on another clock made `--filter kf` an unaided run
/// reported as a KF run. Refused unless allowed; allowed, the unused rows are counted.
#[test]
fn a_filter_that_used_no_sighting_is_refused_unless_unaided_is_allowed() {
    let dir = temp_dir("sightings-clock");
    write_imu(&dir.join("imu.csv"), 0.0, 20.0, at_rest);
    write_reference(&dir.join("truth.csv"), 0.0, 20.0, 0.0);
    let sightings = write_sightings(&dir, &dir.join("truth.csv"), 5_000.0);
    let text = expect_spans(
        run(&dir, &request(&dir, Some(sightings.clone()))),
        "the filter used no sighting (0 epochs applied, 0 sightings rejected by the gate; 0 sightings at or before the start at t = 0.000 s, 80 after the IMU's last sample at t = 20.000 s)",
    );
    assert!(text.contains("allow_unaided"), "{text}");
    assert!(text.contains("t = 5001.000–5020.000 s (80 rows)"), "{text}");
    let mut r = request(&dir, Some(sightings));
    r.allow_unaided = true;
    let s = run(&dir, &r).unwrap();
    assert_eq!((s.epochs, s.sightings_used), (0, 0));
    assert_eq!(s.unused.sightings_after_end, 80);
}

/// Every input row not used is counted: IMU and sightings before the start, sightings after
/// the IMU's end, reference rows outside the replay.
#[test]
fn every_input_row_not_used_is_counted() {
    let dir = temp_dir("unused");
    write_imu(&dir.join("imu.csv"), 0.0, 20.0, at_rest);
    // Reference 0–30 s; sightings from it at 1..=30 s; the replay from 5 s to the IMU's 20 s.
    write_reference(&dir.join("truth.csv"), 0.0, 30.0, 0.0);
    let sightings = write_sightings(&dir, &dir.join("truth.csv"), 0.0);
    let mut r = request(&dir, Some(sightings));
    r.start_s = Some(5.0);
    let s = run(&dir, &r).unwrap();
    assert_eq!(s.imu_samples, 1500);
    assert_eq!(s.epochs, 15);
    let u = s.unused;
    assert_eq!(u.imu_before_start, 500);
    // 4 sightings per epoch: epochs 1..=5 s before (5 at the start: skipped), 21..=30 after.
    assert_eq!(u.sightings_before_start, 20);
    assert_eq!(u.sightings_after_end, 40);
    assert_eq!(u.reference_before_start, 50);
    assert_eq!(u.reference_after_end, 100);
    assert_eq!(
        s.epochs * 4 + u.sightings_before_start + u.sightings_after_end,
        120
    );
    assert_eq!(s.spans.len(), 3);
    assert_eq!(s.spans[0].span_s, Some([0.01, 20.0]));
}

fn expect_not_at_rest(result: Result<ReplaySummary, SimError>, needle: &str) -> String {
    match result {
        Err(e @ SimError::NotAtRest { .. }) => {
            let text = e.to_string();
            assert!(text.contains(needle), "{text}");
            assert!(
                text.contains("not at rest over the alignment window"),
                "{text}"
            );
            text
        }
        Err(e) => panic!("another error: {e}"),
        Ok(s) => panic!("aligned: {:?}", s.alignment),
    }
}

/// The trap: `--align-s 5` on a car moving at 8–11 m/s took its turning as gyro bias.
/// With a reference its speed is checked; here the IMU even looks at rest.
#[test]
fn an_alignment_while_the_reference_moves_is_refused_with_its_speed_and_the_limit() {
    let dir = temp_dir("align-speed");
    write_imu(&dir.join("imu.csv"), 0.0, 20.0, at_rest);
    write_reference(&dir.join("truth.csv"), 0.0, 20.0, 9.5);
    let mut r = request(&dir, None);
    r.align_s = 5.0;
    let text = expect_not_at_rest(
        run(&dir, &r),
        "the reference's speed reaches 9.5000 m/s, above the filter file's align.max_speed_mps = 0.3 m/s",
    );
    assert!(text.contains("t = 0.000–5.000 s"), "{text}");
    assert!(text.contains("without --align-s"), "{text}");
}

/// Without a reference, turning (the gyro's 1-s means vary) or accelerating (the
/// accelerometer's) is refused; the limits come from the filter file.
#[test]
fn an_alignment_while_turning_or_accelerating_is_refused_with_the_measured_spread() {
    let dir = temp_dir("align-spread");
    write_reference(&dir.join("truth.csv"), 0.0, 20.0, 0.0);
    let rows = logs::read_reference(&dir.join("truth.csv")).unwrap();
    let init = logs::initial_from_reference(&rows, 0.0, 1.0).unwrap();
    write_initial(&dir.join("initial.toml"), &init);
    let mut r = request(&dir, None);
    r.reference = None;
    r.initial = Some(dir.join("initial.toml"));
    r.align_s = 10.0;
    // Weaving: yaw rate 3 °/s · sin(0.5 t).
    write_imu(&dir.join("imu.csv"), 0.0, 20.0, |t| {
        ([0.0; 3], [0.0, 0.0, 3f64.to_radians() * (0.5 * t).sin()])
    });
    expect_not_at_rest(
        run(&dir, &r),
        "above the filter file's align.max_gyro_spread_deg_per_s = 0.25 °/s",
    );
    // Accelerating and braking: 0.5 m/s² · sin(0.5 t) forward.
    write_imu(&dir.join("imu.csv"), 0.0, 20.0, |t| {
        ([0.5 * (0.5 * t).sin(), 0.0, 0.0], [0.0; 3])
    });
    expect_not_at_rest(
        run(&dir, &r),
        "above the filter file's align.max_accel_spread_mps2 = 0.05 m/s²",
    );
    // The limit is the filter file's: raised there, the same log aligns.
    let file =
        FilterFile::from_toml_str("[align]\nmax_accel_spread_mps2 = 1.0\n", "f.toml").unwrap();
    r.settings = FilterSettings::File(file);
    let a = run(&dir, &r).unwrap().alignment.unwrap();
    assert!(
        a.accel_spread_mps2 > 0.2 && a.accel_spread_mps2 < 1.0,
        "{a:?}"
    );
}

/// At rest (with engine-like vibration faster than 1 s) the alignment passes and reports its
/// spreads; a window shorter than two 1-s blocks cannot be checked and is refused.
#[test]
fn an_alignment_at_rest_passes_and_a_window_under_two_seconds_is_refused() {
    let dir = temp_dir("align-rest");
    // 25 Hz vibration: 0.3 m/s², 2 °/s (the shared car log's engine: 2.4 °/s sample spread).
    write_imu(&dir.join("imu.csv"), 0.0, 20.0, |t| {
        let v = (std::f64::consts::TAU * 25.0 * t).sin();
        ([0.0, 0.0, 0.3 * v], [0.0, 2f64.to_radians() * v, 0.0])
    });
    write_reference(&dir.join("truth.csv"), 0.0, 20.0, 0.0);
    let mut r = request(&dir, None);
    r.align_s = 10.0;
    let a = run(&dir, &r).unwrap().alignment.unwrap();
    assert!(a.samples >= 999, "{a:?}");
    assert!(a.accel_spread_mps2 < 0.01, "{a:?}");
    assert!(a.gyro_spread_radps.to_degrees() < 0.05, "{a:?}");
    assert_eq!(a.reference_max_speed_mps, Some(0.0));
    r.align_s = 1.5;
    match run(&dir, &r) {
        Err(SimError::LogParse { message, .. }) => {
            assert!(message.contains("fewer than two whole"), "{message}");
        }
        other => panic!("{other:?}"),
    }
}

/// The `[align]` limits are validated on load with the other fields: a bad value names the
/// file, the line and the field.
#[test]
fn the_align_limits_of_the_filter_file_are_validated_on_load() {
    let d = FilterFile::preset("mems").unwrap();
    assert_eq!(
        d.align_limits(),
        logs::AlignLimits {
            max_accel_spread_mps2: 0.05,
            max_gyro_spread_deg_per_s: 0.25,
            max_speed_mps: 0.3,
        }
    );
    for (text, key) in [
        ("[align]\nmax_speed_mps = -1.0\n", "align.max_speed_mps"),
        (
            "preset = \"paper\"\n[align]\nmax_gyro_spread_deg_per_s = 0.0\n",
            "align.max_gyro_spread_deg_per_s",
        ),
        ("[align]\nmax_accel_spread = 0.1\n", "max_accel_spread"),
    ] {
        let e = FilterFile::from_toml_str(text, "filter.toml").unwrap_err();
        let shown = e.to_string();
        let line = text.lines().count();
        assert!(
            shown.starts_with(&format!("filter.toml:{line}:")),
            "{shown}"
        );
        assert!(shown.contains(key), "{shown}");
    }
}
