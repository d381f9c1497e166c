//! The crate's one error, `SimError`: one check per kind (scenario, run, log, statistics) that the
//! variant is the expected one, that it names the place (file, line, column, field, time, shard)
//! and that a wrapped error stays typed as its source.
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use std::error::Error as _;
use std::path::PathBuf;

use ins_sim::logs::{self, TRUTH_HEADER};
use ins_sim::{Mode, Sample, Scenario, SimError, run};

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("ins-sim-error-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn paper_toml() -> String {
    std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../configs/paper.toml"
    ))
    .unwrap()
}

#[test]
fn a_scenario_error_names_the_file_line_column_and_field() {
    let text = paper_toml().replace("r_var_m2 = 40.0", "r_var_m2 = -40.0");
    let line = 1 + text[..text.find("r_var_m2 = -40.0").unwrap()]
        .matches('\n')
        .count();
    let e = Scenario::from_toml_named("bad.toml", &text).unwrap_err();
    let SimError::ScenarioFile { field, error } = &e else {
        panic!("{e:?}")
    };
    assert_eq!(field, "filter.r_var_m2");
    assert_eq!((error.line, error.column), (Some(line), Some(1)));
    assert_eq!(e.scenario_field(), Some("filter.r_var_m2"));
    assert!(e.is_setup());
    let shown = e.to_string();
    assert!(
        shown.starts_with(&format!("bad.toml:{line}:1: ")),
        "{shown}"
    );
    assert!(shown.contains("filter.r_var_m2"), "{shown}");
    // The located error is displayed, not also returned as a source: shown once.
    assert!(e.source().is_none(), "{:?}", e.source());
    assert_eq!(shown, error.to_string());

    // A scenario changed in code: the field is named.
    let e = Scenario::paper_default().truncated(-1.0).unwrap_err();
    assert!(
        matches!(&e, SimError::ScenarioInvalid { field, .. } if e.scenario_field() == Some(field)),
        "{e:?}"
    );
    assert!(
        e.to_string()
            .starts_with(&format!("{}: ", e.scenario_field().unwrap())),
        "{e}"
    );
}

#[test]
fn a_run_error_names_the_time_or_the_buffer() {
    let sc = Scenario::paper_default().truncated(5.0).unwrap();
    let mut out = vec![Sample::default(); 3];
    let e = run(&sc, Mode::Kf, 1, &mut out).unwrap_err();
    assert!(
        matches!(
            e,
            SimError::OutputLength {
                expected: 6,
                got: 3
            }
        ),
        "{e:?}"
    );
    assert!(e.is_setup());
    assert_eq!(
        e.to_string(),
        "output buffer holds 3 samples, the run needs 6 (duration + 1)"
    );
    let e = SimError::NonFinite {
        t_s: 3.0,
        what: "INS position",
    };
    assert!(!e.is_setup());
    assert_eq!(e.run_time_s(), Some(3.0));
    assert_eq!(
        e.to_string(),
        "run became non-finite at t = 3 s: INS position"
    );
    // An export that cannot simulate keeps the run's error as its source.
    let e = SimError::ExportRun {
        source: Box::new(e),
    };
    // The message says what failed; the run's error, its source, when.
    assert_eq!(e.to_string(), "simulating the run to export");
    let inner = e.source().unwrap().downcast_ref::<Box<SimError>>().unwrap();
    assert!(inner.to_string().contains("at t = 3 s"), "{inner}");
    assert!(matches!(**inner, SimError::NonFinite { .. }));
}

#[test]
fn a_log_error_names_the_file_line_and_column() {
    let dir = scratch("logs");
    // A missing file: its path and the OS error.
    let missing = dir.join("absent.csv");
    let e = logs::read_truth(&missing).unwrap_err();
    let SimError::LogIo { path, source } = &e else {
        panic!("{e:?}")
    };
    assert_eq!(path, &missing);
    assert_eq!(source.kind(), std::io::ErrorKind::NotFound);
    assert!(
        e.to_string().starts_with(&missing.display().to_string()),
        "{e}"
    );
    // A malformed CSV field: file, line, column.
    let truth = dir.join("truth.csv");
    std::fs::write(&truth, format!("{TRUTH_HEADER}\n0,0.1,x,0,0,0,0,1,0,0,0\n")).unwrap();
    let e = logs::read_truth(&truth).unwrap_err();
    assert!(
        matches!(&e, SimError::LogParse { path, line: 2, column: 7, .. } if path == &truth),
        "{e:?}"
    );
    assert!(
        e.to_string()
            .starts_with(&format!("{}:2:7: ", truth.display())),
        "{e}"
    );
    // A malformed TOML log: file, line and column through the TOML loader, once.
    let initial = dir.join("initial.toml");
    std::fs::write(&initial, "t_s = 0.0\nlat_rad = \"north\"\n").unwrap();
    let e = logs::read_initial(&initial).unwrap_err();
    let SimError::LogToml { path, error } = &e else {
        panic!("{e:?}")
    };
    assert_eq!(path, &initial);
    assert_eq!(error.line, Some(2));
    let shown = e.to_string();
    assert!(
        shown.starts_with(&format!("{}:2:", initial.display())),
        "{shown}"
    );
    assert_eq!(
        shown.matches(&initial.display().to_string()).count(),
        1,
        "{shown}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_stats_error_names_what_disagrees() {
    let e = ins_sim::stats::merge(Vec::new()).unwrap_err();
    assert!(matches!(e, SimError::StatsEmpty), "{e:?}");
    assert_eq!(e.to_string(), "merge: no statistics to merge");
    let e = ins_sim::stats::shard_range(10, 4, 3).unwrap_err();
    assert!(
        matches!(e, SimError::StatsShard { index: 4, count: 3 }),
        "{e:?}"
    );
    assert!(e.to_string().starts_with("shard 4/3: "), "{e}");
}
