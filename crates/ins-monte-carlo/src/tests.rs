//! Tests of the Monte Carlo driver, statistics and reports. Real closed-loop runs use the paper
//! scenario cut to a few seconds and a handful of runs; the failure test uses a tiny local
//! stand-in generator (never shipped as the real thing).

use std::path::PathBuf;

use super::driver::{Plan, simulate as drive};
use super::report::{self, NEES_DOF, NIS_DOF};
use super::stats::{self, ModeStats, Moments, Stats, qi};
use super::*;
use ins_sim::stats::ShardInfo;
use ins_sim::{Mode, Sample, Scenario, SimError, SimRunOutcome};

/// `e` and its causes as the binary prints them, `e: cause: …` (each error shows only its own
/// message and keeps its cause as its source).
pub(crate) fn shown(e: &dyn std::error::Error) -> String {
    std::iter::successors(Some(e), |c| c.source())
        .map(ToString::to_string)
        .collect::<Vec<_>>()
        .join(": ")
}

fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("nav-app-mc-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn paper_toml() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../configs/paper.toml")
}

fn args(runs: u64, duration: f64, threads: usize, shard: Option<&str>) -> RunOptions {
    RunOptions {
        runs: Some(runs),
        duration_s: Some(duration),
        threads: Some(threads),
        shard: shard.map(|s| parse_shard(s).unwrap()),
        seed: Some(77),
        ..RunOptions::new(paper_toml(), temp_dir("default-out"))
    }
}

fn stats_of(a: &RunOptions) -> Stats {
    simulate_stats(&resolve(a).unwrap(), &Silent).unwrap()
}

/// What `nav-app monte-carlo` does with the options: simulate and write (a shard writes only
/// stats.json).
fn simulate(a: &RunOptions) -> Result<(), McError> {
    let r = resolve(a)?;
    let st = simulate_stats(&r, &Silent)?;
    write_outputs(&r.out, &st, !r.sharded)
}

/// What `nav-app monte-carlo merge` does.
fn merge(dirs: Vec<PathBuf>, out: PathBuf, allow_partial: bool) -> Result<(), McError> {
    let merged = merge_dirs(&dirs, allow_partial)?;
    write_outputs(&out, &merged, true)
}

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs()).max(1e-300)
}

/// Same counts exactly, sums to relative round-off `rel`.
fn assert_bins_close(a: &ModeStats, b: &ModeStats, rel: f64) {
    assert_eq!(a.mode, b.mode);
    assert_eq!(a.runs_used, b.runs_used, "{}", a.mode);
    assert_eq!(a.steps, b.steps, "{}", a.mode);
    assert_eq!(a.bins.len(), b.bins.len());
    for (t, (x, y)) in a.bins.iter().zip(&b.bins).enumerate() {
        for q in 0..stats::Q {
            assert_eq!(x[q].n, y[q].n, "{} t={t} q={q}", a.mode);
            assert!(
                close(x[q].sum, y[q].sum, rel) && close(x[q].sum_sq, y[q].sum_sq, rel),
                "{} t={t} q={q}: {:?} vs {:?}",
                a.mode,
                x[q],
                y[q]
            );
        }
    }
}

#[test]
fn merge_of_two_shards_equals_one_run() {
    let single = stats_of(&args(5, 12.0, 2, None));
    assert_eq!(single.modes().len(), 3);
    assert!(single.modes().iter().all(|m| m.runs_used == 5));
    // Two shards written to disk as stats.json and merged by the CLI path (JSON round trip).
    let dirs: Vec<PathBuf> = (1..=2)
        .map(|i| {
            let d = temp_dir(&format!("shard{i}"));
            let mut a = args(5, 12.0, 1, Some(&format!("{i}/2")));
            a.out = Some(d.clone());
            simulate(&a).unwrap();
            assert!(d.join("stats.json").exists());
            assert!(
                !d.join("summary.md").exists(),
                "a shard alone must not present a summary"
            );
            d
        })
        .collect();
    let out = temp_dir("merged");
    merge(dirs.iter().rev().cloned().collect(), out.clone(), false).unwrap();
    let merged: Stats =
        serde_json::from_str(&std::fs::read_to_string(out.join("stats.json")).unwrap()).unwrap();
    assert_eq!(merged.run_ranges(), vec![(0, 2), (2, 5)]);
    assert_eq!(merged.shards().len(), 2);
    assert_eq!(stats::missing_ranges(&merged), vec![]);
    for (a, b) in merged.modes().iter().zip(single.modes()) {
        assert_bins_close(a, b, 1e-12);
    }
    // The per-run briefs are the same runs with the same numbers.
    assert_eq!(merged.runs().len(), single.runs().len());
    for (a, b) in merged.runs().iter().zip(single.runs()) {
        assert_eq!((&a.mode, a.run_index), (&b.mode, b.run_index));
        assert!(close(a.final_pos_3d_m, b.final_pos_3d_m, 1e-12));
    }
    // The headline numbers of the merged summary equal those of the single run.
    let js: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let kf_single = single.mode(Mode::Kf).unwrap().bins.last().unwrap()[qi::POS_3D].rms();
    let kf_merged = js["kf"]["final_position_error_m"].as_f64().unwrap();
    assert!(
        close(kf_single, kf_merged, 1e-12),
        "{kf_single} vs {kf_merged}"
    );
    assert!(out.join("summary.md").exists());
    for d in dirs.iter().chain([&out]) {
        let _ = std::fs::remove_dir_all(d);
    }
}

#[test]
fn merge_refuses_overlap_and_reports_missing_runs() {
    let d1 = temp_dir("ov1");
    let mut a = args(4, 5.0, 1, Some("1/2"));
    a.out = Some(d1.clone());
    simulate(&a).unwrap();
    let e = merge(vec![d1.clone(), d1.clone()], temp_dir("ov-out"), false).unwrap_err();
    assert!(format!("{e:#}").contains("overlap"), "{e:#}");
    let e = merge(vec![d1.clone()], temp_dir("ov-out"), false).unwrap_err();
    assert!(
        format!("{e:#}").contains("missing run indices 2..4"),
        "{e:#}"
    );
    let out = temp_dir("ov-partial");
    merge(vec![d1.clone()], out.clone(), true).unwrap();
    let md = std::fs::read_to_string(out.join("summary.md")).unwrap();
    assert!(md.contains("**Partial:** 2 of 4 runs"), "{md}");
    // A shard of another seed is refused.
    let d2 = temp_dir("ov2");
    let mut b = args(4, 5.0, 1, Some("2/2"));
    b.seed = Some(78);
    b.out = Some(d2.clone());
    simulate(&b).unwrap();
    let e = merge(vec![d1.clone(), d2.clone()], temp_dir("ov-out"), false).unwrap_err();
    assert!(format!("{e:#}").contains("seed"), "{e:#}");
    for d in [d1, d2, out, temp_dir("ov-out")] {
        let _ = std::fs::remove_dir_all(d);
    }
}

#[test]
fn statistics_do_not_depend_on_thread_count() {
    let one = stats_of(&args(6, 10.0, 1, None));
    let two = stats_of(&args(6, 10.0, 2, None));
    for (a, b) in one.modes().iter().zip(two.modes()) {
        // Bit-identical: the records are folded in run-index order.
        assert_eq!(a.bins, b.bins, "{}", a.mode);
        assert_eq!(a.runs_used, b.runs_used);
        assert_eq!(a.steps, b.steps);
    }
    // And the runs differ from each other (the seeds are per run, not one shared draw).
    let kf = one.mode(Mode::Kf).unwrap();
    assert!(kf.bins[10][qi::POS_N].std_dev() > 0.0);
}

#[test]
fn chi_square_bands_match_the_docs_table() {
    // docs/ins-sd.md § Consistency (two decimals).
    let table = [
        (NEES_DOF, 50, 13.52, 16.56),
        (NEES_DOF, 100, 13.95, 16.09),
        (NIS_DOF, 50, 5.08, 7.00),
        (NIS_DOF, 100, 5.34, 6.70),
    ];
    for (dof, runs, lo, hi) in table {
        let (l, h) = report::band(dof, runs).unwrap();
        assert!(
            (l - lo).abs() < 0.006,
            "n={dof} M={runs}: lower {l} vs {lo}"
        );
        assert!(
            (h - hi).abs() < 0.006,
            "n={dof} M={runs}: upper {h} vs {hi}"
        );
    }
}

/// A mode whose every epoch has NEES values with the given run average.
fn nees_mode(avg: f64, runs: u64) -> ModeStats {
    let mut m = ModeStats::new(Mode::Kf, 50);
    for bin in &mut m.bins {
        // Values avg ± 1 alternately: mean exactly avg.
        for r in 0..runs {
            bin[qi::NEES].push(avg + if r % 2 == 0 { 1.0 } else { -1.0 });
        }
    }
    m.runs_used = runs;
    m
}

#[test]
fn consistency_says_which_way_a_filter_is_inconsistent() {
    let over = report::consistency(&nees_mode(20.0, 100), qi::NEES, NEES_DOF).unwrap();
    assert_eq!((over.above, over.inside, over.below), (1.0, 0.0, 0.0));
    let under = report::consistency(&nees_mode(10.0, 100), qi::NEES, NEES_DOF).unwrap();
    assert_eq!((under.above, under.inside, under.below), (0.0, 0.0, 1.0));
    let ok = report::consistency(&nees_mode(15.0, 100), qi::NEES, NEES_DOF).unwrap();
    assert_eq!(ok.inside, 1.0);
    assert!((ok.mean - 15.0).abs() < 1e-12);
    // No values at all: no verdict (stand-alone has no filter).
    assert!(report::consistency(&ModeStats::new(Mode::Standalone, 5), qi::NEES, 15).is_none());
}

/// Stand-in generator: run `i` has position error N = i·t, E = 1, D = −t; run 2 fails as
/// non-finite at 7 s, run 3 returns a NaN record at 5 s.
fn stand_in(_mode: Mode, index: u64, out: &mut [Sample]) -> Result<SimRunOutcome, SimError> {
    if index == 2 {
        return Err(SimError::NonFinite {
            t_s: 7.0,
            what: "INS velocity",
        });
    }
    for (t, s) in out.iter_mut().enumerate() {
        let tf = t as f64;
        *s = Sample {
            t_s: tf,
            pos_err_ned_m: [index as f64 * tf, 1.0, -tf],
            distance_m: 30.0 * tf,
            nees: (t > 0).then_some(15.0),
            nis: (t > 0).then_some(6.0),
            ..Sample::default()
        };
    }
    if index == 3 {
        out[5].misalignment_rad[1] = f64::NAN;
    }
    Ok(SimRunOutcome {
        samples_written: out.len(),
        steps: 100 * (out.len() as u64 - 1),
        sightings_used: 0,
        sightings_rejected: 0,
    })
}

#[test]
fn non_finite_runs_are_excluded_and_counted() {
    let plan = Plan {
        modes: vec![Mode::Kf],
        samples: 11,
        range: (0, 5),
        threads: 2,
    };
    let sim = drive(&plan, stand_in, &Silent).unwrap();
    let kf = &sim.modes[0];
    assert_eq!(kf.runs_used, 3, "runs 0, 1, 4 kept");
    let ex: Vec<(u64, Option<f64>)> = sim
        .exclusions
        .iter()
        .map(|e| (e.run_index, e.t_s))
        .collect();
    assert_eq!(ex, vec![(2, Some(7.0)), (3, Some(5.0))]);
    assert!(sim.exclusions[1].reason.contains("misalignment"));
    // Means over the kept runs only: N at t = 10 is (0 + 1 + 4)·10 / 3.
    let b = kf.bins[10];
    assert!((b[qi::POS_N].mean() - 50.0 / 3.0).abs() < 1e-12);
    assert_eq!(b[qi::POS_N].n, 3);
    // The reports count and list them.
    let r = Resolved {
        modes: Mode::ALL.to_vec(),
        scenario: Scenario::paper_default().truncated(10.0).unwrap(),
        source: "stand-in".into(),
        runs: 5,
        seed: 1,
        threads: 2,
        shard: stats::ShardInfo { index: 1, count: 1 },
        sharded: false,
        out: PathBuf::new(),
    };
    let st = build_stats(&r, (0, 5), sim).unwrap();
    let kept: Vec<u64> = st.runs().iter().map(|r| r.run_index).collect();
    assert_eq!(kept, vec![0, 1, 4]);
    // Final 3-D error of run i: √((10 i)² + 1 + 100); the median of runs 0, 1, 4 is run 1's.
    assert!((report::median_final(&st, Mode::Kf) - 201f64.sqrt()).abs() < 1e-12);
    let worst = report::worst_runs(&st, Mode::Kf, 1);
    assert_eq!((worst[0].run_index, worst[0].peak_t_s), (4, 10.0));
    let md = summary::summary_md(&st, &summary::summary(&st));
    assert!(md.contains("2 run(s) excluded"), "{md}");
    assert!(md.contains("kf run 2 at t = 7 s"), "{md}");
    assert!(md.contains("kf run 3 at t = 5 s"), "{md}");
    let js: serde_json::Value =
        serde_json::from_str(&summary::summary_json(&summary::summary(&st)).unwrap()).unwrap();
    assert_eq!(js["schema"], summary::SUMMARY_SCHEMA);
    assert_eq!(js["kf"]["runs_excluded"], 2);
    assert_eq!(js["kf"]["runs_used"], 3);
    assert_eq!(js["excluded_runs"].as_array().unwrap().len(), 2);
}

#[test]
fn bad_arguments_give_clear_errors() {
    let msg = |r: Result<ShardInfo, McError>| r.unwrap_err().to_string();
    assert!(msg(parse_shard("3/2")).contains("between 1 and 2"));
    assert!(msg(parse_shard("0/2")).contains("1-based"));
    assert!(msg(parse_shard("2")).contains("expected i/n"));
    assert!(msg(parse_shard("a/2")).contains("not an integer"));
    assert!(msg(parse_shard("1/0")).contains("at least 1"));
    assert_eq!(
        parse_shard("2/3").unwrap(),
        stats::ShardInfo { index: 2, count: 3 }
    );
    assert_eq!(
        parse_filters("akf, kf,kf").unwrap(),
        vec![Mode::Kf, Mode::Akf],
        "report order, no duplicates"
    );
    assert!(
        parse_filters("kf,ukf")
            .unwrap_err()
            .to_string()
            .contains("`ukf` is not one of")
    );
    let err = |a: RunOptions| shown(&resolve(&a).unwrap_err());
    assert!(err(args(0, 5.0, 1, None)).contains("--runs 0"));
    assert!(err(args(2, 5.0, 0, None)).contains("--threads 0"));
    assert!(err(args(2, 5.0, 1, Some("3/3"))).contains("more shards than runs"));
    assert!(err(args(2, 5000.0, 1, None)).contains("--duration"));
    // The scenario is read from its file: a missing file is an error naming it, never a silent
    // fall-back to a built-in scenario.
    let missing = temp_dir("nofile").join("paper.toml");
    let e = resolve(&RunOptions::new(&missing, temp_dir("x"))).unwrap_err();
    assert!(matches!(e, McError::Io { .. }), "{e:?}");
    assert!(e.to_string().contains("nofile"), "{e}");
    // An invalid config names the field.
    let dir = temp_dir("badcfg");
    std::fs::create_dir_all(&dir).unwrap();
    let text = std::fs::read_to_string(paper_toml()).unwrap();
    let bad = text.replace("r_var_m2 = 40.0", "r_var_m2 = -1.0");
    assert_ne!(bad, text);
    let path = dir.join("bad.toml");
    std::fs::write(&path, bad).unwrap();
    assert!(err(RunOptions::new(&path, &dir)).contains("filter.r_var_m2"));
    // It is the simulation library's typed error, named by its field, file and line.
    let e = resolve(&RunOptions::new(&path, &dir)).unwrap_err();
    let McError::Sim(sim @ SimError::ScenarioFile { field, error }) = &e else {
        panic!("{e:?}")
    };
    assert_eq!(field, "filter.r_var_m2");
    assert_eq!(sim.scenario_field(), Some("filter.r_var_m2"));
    assert!(error.line.is_some());
    // Shown once, file first: the scenario error displays as the located error.
    assert_eq!(shown(&e), error.to_string());
    assert!(
        e.to_string().starts_with(&path.display().to_string()),
        "{e}"
    );
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn a_run_that_cannot_start_names_its_index_and_mode_and_keeps_the_sim_error() {
    let plan = Plan {
        modes: vec![Mode::Akf],
        samples: 11,
        range: (0, 3),
        threads: 1,
    };
    let short = |_: Mode, _: u64, out: &mut [Sample]| -> Result<SimRunOutcome, SimError> {
        Err(SimError::OutputLength {
            expected: 12,
            got: out.len(),
        })
    };
    let e = drive(&plan, short, &Silent).unwrap_err();
    let McError::RunSetup {
        index,
        mode,
        source,
    } = &e
    else {
        panic!("{e:?}")
    };
    assert_eq!((*index, *mode), (0, Mode::Akf));
    assert!(matches!(
        **source,
        SimError::OutputLength {
            expected: 12,
            got: 11
        }
    ));
    assert_eq!(e.to_string(), "run 0 (akf) could not start");
    let chain = shown(&e);
    assert!(
        chain.starts_with("run 0 (akf) could not start: "),
        "{chain}"
    );
    assert_eq!(chain.matches("needs 12").count(), 1, "{chain}");
    // The source is the boxed `SimError` itself.
    let inner = std::error::Error::source(&e).unwrap();
    assert!(inner.downcast_ref::<Box<SimError>>().is_some());
}

#[test]
fn interrupted_output_leaves_no_file_under_its_final_name() {
    let st = stats_of(&args(2, 3.0, 1, None));
    let dir = temp_dir("interrupt");
    std::fs::create_dir_all(&dir).unwrap();
    // A directory where summary.md's temporary file goes makes the last write fail.
    std::fs::create_dir_all(dir.join(".summary.md.partial")).unwrap();
    assert!(write_outputs(&dir, &st, true).is_err());
    let finals: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| !n.starts_with('.'))
        .collect();
    assert!(finals.is_empty(), "{finals:?}");
    // A successful write leaves every output under its final name and no temporary.
    std::fs::remove_dir_all(dir.join(".summary.md.partial")).unwrap();
    write_outputs(&dir, &st, true).unwrap();
    let names: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    assert!(names.iter().all(|n| !n.ends_with(".partial")), "{names:?}");
    for f in [
        "summary.md",
        "summary.json",
        "stats.json",
        "timeseries_kf.csv",
        "fig1_standalone_mean.svg",
        "fig6_kf_sigma.png",
        "fig7_nees_nis.svg",
        "fig8_position_rms.png",
    ] {
        assert!(names.iter().any(|n| n == f), "{f} missing: {names:?}");
    }
    let png = image::open(dir.join("fig2_akf_mean.png")).unwrap();
    assert_eq!((png.width(), png.height()), (1000, 760));
    let svg = std::fs::read_to_string(dir.join("fig3_kf_mean.svg")).unwrap();
    assert!(
        svg.contains("manually tuned KF"),
        "the SVG carries its labels"
    );
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn moments_mean_sd_rms_match_direct_formulas() {
    let xs = [1.5, -2.0, 4.25, 0.5, 3.0];
    let mut m = Moments::default();
    xs.iter().for_each(|&x| m.push(x));
    let n = xs.len() as f64;
    let mean = xs.iter().sum::<f64>() / n;
    let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0);
    let rms = (xs.iter().map(|x| x * x).sum::<f64>() / n).sqrt();
    assert!((m.mean() - mean).abs() < 1e-14);
    assert!((m.std_dev() - var.sqrt()).abs() < 1e-14);
    assert!((m.rms() - rms).abs() < 1e-14);
    let mut a = Moments::default();
    let mut b = Moments::default();
    xs[..2].iter().for_each(|&x| a.push(x));
    xs[2..].iter().for_each(|&x| b.push(x));
    a.merge(&b);
    assert_eq!(a.n, m.n);
    assert!((a.std_dev() - m.std_dev()).abs() < 1e-14);
}

#[test]
fn shard_ranges_partition_the_runs() {
    for runs in [1u64, 7, 100, 10_001] {
        for count in 1..=runs.min(13) {
            let mut next = 0;
            for i in 1..=count {
                let (lo, hi) = stats::shard_range(runs, i, count).unwrap();
                assert_eq!(lo, next);
                assert!(hi - lo >= runs / count && hi - lo <= runs / count + 1);
                next = hi;
            }
            assert_eq!(next, runs);
        }
    }
}

#[test]
fn the_driver_and_the_sequential_loop_fold_bit_identical_statistics() {
    // The driver runs the one run loop per index on its pool; the Python package runs it over
    // the whole range on one thread: same records, same fold, same bits.
    let sc = Scenario::paper_default().truncated(12.0).unwrap();
    let n = sc.samples_per_run();
    let plan = Plan {
        modes: vec![Mode::Kf, Mode::Akf],
        samples: n,
        range: (0, 4),
        threads: 2,
    };
    let runner = ins_sim::runs::closed_loop(&sc, 2009);
    let sim = drive(&plan, &runner, &Silent).unwrap();
    for (slot, &mode) in plan.modes.iter().enumerate() {
        let mut st = ModeStats::new(mode, n);
        let (mut kept, mut excluded) = (Vec::new(), Vec::new());
        let mut out = vec![Sample::default(); n];
        ins_sim::runs::run_range(&runner, mode, 0..4, &mut out, |i, o, v| {
            v.fold(i, o, &mut st, &mut kept, &mut excluded);
        })
        .unwrap();
        let d = &sim.modes[slot];
        assert_eq!((st.runs_used, st.steps), (d.runs_used, d.steps), "{mode}");
        assert_eq!(st.bins, d.bins, "{mode}");
        assert!(excluded.is_empty());
    }
}
