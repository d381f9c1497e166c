//! The Monte Carlo through the product binary, as a cluster would run it: shards written by
//! separate `nav-app monte-carlo --shard i/n` processes and merged by `nav-app monte-carlo
//! merge` equal one run over all indices; a missing scenario file is an error, not a fall-back.
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use ins_sim::stats::{self, Stats};

fn nav_app(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_nav-app"))
        .arg("monte-carlo")
        .args(args)
        .output()
        .unwrap()
}

fn paper() -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../configs/paper.toml")
        .display()
        .to_string()
}

fn temp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("nav-app-mc-cli-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn read_stats(dir: &Path) -> Stats {
    serde_json::from_str(&std::fs::read_to_string(dir.join("stats.json")).unwrap()).unwrap()
}

fn ok(o: &Output) {
    assert!(
        o.status.success(),
        "{}\n{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-12 * a.abs().max(b.abs()).max(1e-300)
}

#[test]
fn three_shard_processes_merged_equal_one_run() {
    let common = [
        "--runs",
        "5",
        "--duration",
        "12",
        "--seed",
        "31",
        "--threads",
        "1",
    ];
    let cfg = paper();
    let one = temp("one");
    let mut a: Vec<&str> = vec!["--config", &cfg];
    a.extend(common);
    let one_s = one.display().to_string();
    ok(&nav_app(&[a.as_slice(), &["--out", &one_s]].concat()));

    let shard_dirs: Vec<String> = (1..=3)
        .map(|i| temp(&format!("shard{i}")).display().to_string())
        .collect();
    for (i, d) in shard_dirs.iter().enumerate() {
        let shard = format!("{}/3", i + 1);
        let o = nav_app(&[a.as_slice(), &["--shard", &shard, "--out", d]].concat());
        ok(&o);
        assert!(
            !Path::new(d).join("summary.md").exists(),
            "a shard alone must not present a summary"
        );
    }
    let merged = temp("merged");
    let merged_s = merged.display().to_string();
    // Any order of the shard directories.
    let o = nav_app(&[
        "merge",
        &shard_dirs[2],
        &shard_dirs[0],
        &shard_dirs[1],
        "--out",
        &merged_s,
    ]);
    ok(&o);

    let (single, all) = (read_stats(&one), read_stats(&merged));
    assert_eq!(all.shards().len(), 3);
    assert!(stats::missing_ranges(&all).is_empty());
    assert_eq!(all.runs_total(), single.runs_total());
    for (m, s) in all.modes().iter().zip(single.modes()) {
        assert_eq!(
            (m.mode, m.runs_used, m.steps),
            (s.mode, s.runs_used, s.steps)
        );
        for (bm, bs) in m.bins.iter().zip(&s.bins) {
            for (x, y) in bm.iter().zip(bs) {
                assert_eq!(x.n, y.n);
                assert!(
                    close(x.sum, y.sum) && close(x.sum_sq, y.sum_sq),
                    "{x:?} vs {y:?}"
                );
            }
        }
    }
    // The summaries agree on every headline number and carry the schema.
    let js = |d: &Path| -> serde_json::Value {
        serde_json::from_str(&std::fs::read_to_string(d.join("summary.json")).unwrap()).unwrap()
    };
    let (j1, j2) = (js(&one), js(&merged));
    assert_eq!(j1["schema"], 1);
    assert_eq!(j2["schema"], 1);
    for mode in ["standalone", "kf", "akf"] {
        for key in [
            "final_position_error_m",
            "final_horizontal_error_m",
            "final_position_error_median_m",
        ] {
            let (x, y) = (
                j1[mode][key].as_f64().unwrap(),
                j2[mode][key].as_f64().unwrap(),
            );
            assert!(close(x, y), "{mode}.{key}: {x} vs {y}");
        }
    }
    for d in shard_dirs.iter().map(PathBuf::from).chain([one, merged]) {
        let _ = std::fs::remove_dir_all(d);
    }
}

#[test]
fn a_missing_scenario_file_is_an_error_that_names_it() {
    let missing = temp("absent").join("paper.toml");
    let o = nav_app(&["--config", &missing.display().to_string(), "--runs", "1"]);
    assert_eq!(o.status.code(), Some(1));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("absent") && err.contains("paper.toml"),
        "{err}"
    );
    // A bad option value names the option; clap's errors exit with 2.
    let o = nav_app(&["--config", &paper(), "--shard", "4/3"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("between 1 and 3"));
    let o = nav_app(&["merge"]);
    assert_eq!(o.status.code(), Some(2));
}

#[test]
fn a_bad_scenario_names_the_file_line_column_and_field_once() {
    let text = std::fs::read_to_string(paper()).unwrap();
    let bad = text.replace("r_var_m2 = 40.0", "r_var_m2 = -40.0");
    let line = 1 + bad[..bad.find("r_var_m2 = -40.0").unwrap()]
        .matches('\n')
        .count();
    let dir = temp("badcfg");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("bad.toml");
    std::fs::write(&path, bad).unwrap();
    let p = path.display().to_string();
    let o = nav_app(&[
        "--config",
        &p,
        "--runs",
        "1",
        "--out-root",
        &dir.display().to_string(),
    ]);
    assert_eq!(o.status.code(), Some(1));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains(&format!("{p}:{line}:1: ")), "{err}");
    assert!(err.contains("filter.r_var_m2"), "{err}");
    assert_eq!(err.matches(&p).count(), 1, "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn help_states_the_default_input_and_the_exit_codes() {
    let o = nav_app(&["--help"]);
    ok(&o);
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.contains("configs/paper.toml"), "{text}");
    assert!(text.contains("Exit codes"), "{text}");
}

#[test]
fn filters_choose_the_configurations_simulated_and_an_unknown_one_is_refused() {
    // (clap panicked on every --filters until its value became one list.)
    let out = temp("filters");
    let o = nav_app(&[
        "--config",
        &paper(),
        "--runs",
        "2",
        "--duration",
        "12",
        "--filters",
        "akf,kf",
        "--threads",
        "1",
        "--out",
        out.to_str().unwrap(),
    ]);
    ok(&o);
    let stats = read_stats(&out);
    let modes: Vec<ins_sim::Mode> = stats.modes().iter().map(|m| m.mode).collect();
    assert_eq!(modes, [ins_sim::Mode::Kf, ins_sim::Mode::Akf]);
    let o = nav_app(&["--config", &paper(), "--filters", "kf,bogus", "--runs", "1"]);
    assert_eq!(o.status.code(), Some(2), "a bad command line");
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("`bogus` is not one of"), "{err}");
    let _ = std::fs::remove_dir_all(&out);
}
