//! `nav-app monte-carlo --sweep KEY=V1,V2,…`: the same runs (same seeds) at each value of
//! one scenario key — a dotted `section.key` of the scenario file, or several joined with `+`
//! that take the same value (e.g. `sighting.noise_var_m2+filter.r_var_m2=10,40,160` keeps the
//! filter matched). Writes `sweep.md`, `sweep.csv` and `sweep_final_error.{svg,png}` (final
//! 3-D error against the swept value: median and the 10–90 % spread over runs).

use std::fmt::Write as _;
use std::path::Path;

use super::plot::{SweepPoint, sweep_figure};
use super::scenarios::{Row, evaluate};
use super::{McError, Progress};
use ins_sim::{Mode, Scenario};

fn bad(value: &str, reason: String) -> McError {
    McError::Argument {
        flag: "--sweep",
        value: value.to_string(),
        reason,
    }
}

/// A parsed `--sweep` argument.
#[derive(Clone, Debug, PartialEq)]
pub struct Sweep {
    /// The dotted keys set together.
    pub keys: Vec<(String, String)>,
    /// The values, as written.
    pub values: Vec<String>,
}

/// Parses `section.key[+section.key…]=v1,v2,…`.
pub fn parse_sweep(text: &str) -> Result<Sweep, McError> {
    let (k, v) = text
        .split_once('=')
        .ok_or_else(|| bad(text, "expected KEY=V1,V2,…".to_string()))?;
    let mut keys = Vec::new();
    for key in k.split('+') {
        let (sec, name) = key.trim().split_once('.').ok_or_else(|| {
            bad(
                text,
                format!("key `{key}` must be section.key, e.g. filter.akf_window"),
            )
        })?;
        keys.push((sec.to_string(), name.to_string()));
    }
    let values: Vec<String> = v
        .split(',')
        .map(|s| s.trim().to_string())
        .filter(|s| !s.is_empty())
        .collect();
    if values.is_empty() {
        return Err(bad(text, "no values".to_string()));
    }
    Ok(Sweep { keys, values })
}

/// The scenario with every swept key set to `value` (typed like the key's current value).
/// An error in a swept value names the key and the value; one the scenario refuses names its
/// field.
pub fn apply(sc: &Scenario, keys: &[(String, String)], value: &str) -> Result<Scenario, McError> {
    // The scenario's own serialisation cannot fail on a validated scenario; if it ever does, the
    // error says so rather than panicking.
    let internal = |what: &str, e: &dyn std::fmt::Display| {
        bad(value, format!("{what} the scenario failed: {e}"))
    };
    let text = sc
        .to_toml_string()
        .map_err(|e| internal("serialising", &e))?;
    let mut doc: toml::Table = text.parse().map_err(|e| internal("re-reading", &e))?;
    for (sec, key) in keys {
        let table = doc
            .entry(sec.clone())
            .or_insert_with(|| toml::Value::Table(toml::Table::new()));
        let Some(table) = table.as_table_mut() else {
            return Err(bad(value, format!("`{sec}` is not a section")));
        };
        let new = match table.get(key) {
            Some(toml::Value::Integer(_)) => toml::Value::Integer(
                value
                    .parse()
                    .map_err(|_| bad(value, format!("{sec}.{key}: `{value}` is not an integer")))?,
            ),
            Some(toml::Value::Float(_)) | None => toml::Value::Float(
                value
                    .parse()
                    .map_err(|_| bad(value, format!("{sec}.{key}: `{value}` is not a number")))?,
            ),
            Some(toml::Value::String(_)) => toml::Value::String(value.to_string()),
            Some(other) => {
                return Err(bad(
                    value,
                    format!("{sec}.{key}: cannot sweep a {}", other.type_str()),
                ));
            }
        };
        table.insert(key.clone(), new);
    }
    let text = toml::to_string(&doc).map_err(|e| internal("writing", &e))?;
    Ok(Scenario::from_toml_named(
        &format!("--sweep value {value}"),
        &text,
    )?)
}

/// Runs the sweep and writes its outputs into `out`; returns the rows.
pub fn run_sweep(
    base: &Scenario,
    sweep: &Sweep,
    modes: &[Mode],
    runs: u64,
    threads: usize,
    out: &Path,
    progress: &dyn Progress,
) -> Result<Vec<(String, Row)>, McError> {
    let label = sweep
        .keys
        .iter()
        .map(|(s, k)| format!("{s}.{k}"))
        .collect::<Vec<_>>()
        .join("+");
    let pool = super::pool(Some(threads))?;
    let mut rows = Vec::new();
    for v in &sweep.values {
        let sc = apply(base, &sweep.keys, v)?;
        for &mode in modes {
            let row = pool.install(|| evaluate(v, &sc, mode, runs))?;
            progress.note(&format!(
                "sweep: {label} = {v:<8} {:<14} median {:.1} m (10–90 %: {:.1}–{:.1} m), RMS {:.1} m, lost {}",
                row.mode,
                row.final_median_m,
                row.final_p10_m,
                row.final_p90_m,
                row.final_rms_m,
                row.lost
            ));
            rows.push((v.clone(), row));
        }
    }
    std::fs::create_dir_all(out).map_err(|source| McError::Io {
        path: out.to_path_buf(),
        source,
    })?;
    let mut md = format!(
        "# Sweep of {label} ({runs} runs per point, {} s, same seeds at every point)\n\n| {label} | filter | final 3-D median (m) | 10 % (m) | 90 % (m) | RMS (m) | lost runs | NEES mean (15) | epochs with NEES in 95 % band | NIS per dof |\n|---|---|---|---|---|---|---|---|---|---|\n",
        base.duration_s()
    );
    let mut csv = String::from(
        "value,filter,median_m,p10_m,p90_m,rms_m,lost,runs,nees_mean,nees_in_band,nis_per_dof\n",
    );
    let mut pts = Vec::new();
    for (v, r) in &rows {
        let _ = writeln!(
            md,
            "| {v} | {} | {:.2} | {:.2} | {:.2} | {:.2} | {} | {:.1} | {:.0} % | {:.2} |",
            r.mode,
            r.final_median_m,
            r.final_p10_m,
            r.final_p90_m,
            r.final_rms_m,
            super::scenarios::lost_text(r),
            r.nees_mean,
            100.0 * r.nees_in_band,
            r.nis_per_dof
        );
        let _ = writeln!(
            csv,
            "{v},{},{:e},{:e},{:e},{:e},{},{},{:e},{:e},{:e}",
            r.mode,
            r.final_median_m,
            r.final_p10_m,
            r.final_p90_m,
            r.final_rms_m,
            r.lost,
            r.lost + r.kept,
            r.nees_mean,
            r.nees_in_band,
            r.nis_per_dof
        );
        if let Ok(x) = v.parse::<f64>() {
            pts.push(SweepPoint {
                mode: r.mode,
                value: x,
                median_m: r.final_median_m,
                p10_m: r.final_p10_m,
                p90_m: r.final_p90_m,
            });
        }
    }
    let write = |name: &str, bytes: &[u8]| -> Result<(), McError> {
        let path = out.join(name);
        std::fs::write(&path, bytes).map_err(|source| McError::Io { path, source })
    };
    write("sweep.md", md.as_bytes())?;
    write("sweep.csv", csv.as_bytes())?;
    if !pts.is_empty() {
        let (svg, png) = sweep_figure(&label, runs, &pts)?;
        write("sweep_final_error.svg", svg.as_bytes())?;
        write("sweep_final_error.png", &png)?;
    }
    Ok(rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_are_parsed_applied_with_their_type_and_errors_name_them() {
        let sw = parse_sweep("sighting.noise_var_m2+filter.r_var_m2=10,40").unwrap();
        assert_eq!(sw.keys.len(), 2);
        assert_eq!(sw.values, vec!["10", "40"]);
        let base = Scenario::paper_default();
        let sc = apply(&base, &sw.keys, "10").unwrap();
        assert_eq!(sc.sighting.noise_var_m2, 10.0);
        assert_eq!(sc.filter.r_var_m2, 10.0);
        assert_eq!(sc.filter.akf_window, base.filter.akf_window);
        let n = parse_sweep("filter.akf_window=5").unwrap();
        assert_eq!(apply(&base, &n.keys, "5").unwrap().filter.akf_window, 5);
        let e = apply(&base, &n.keys, "5.5").unwrap_err().to_string();
        assert!(e.contains("filter.akf_window"), "{e}");
        let bad = parse_sweep("filter.no_such_key=1").unwrap();
        let e = crate::tests::shown(&apply(&base, &bad.keys, "1").unwrap_err());
        assert!(e.contains("no_such_key"), "{e}");
        assert!(parse_sweep("akf_window=5").is_err());
        assert!(parse_sweep("filter.akf_window=").is_err());
    }

    #[test]
    fn a_short_sweep_writes_its_table_csv_and_figure() {
        let base = Scenario::paper_default().truncated(15.0).unwrap();
        let sw = parse_sweep("filter.akf_window=5,10").unwrap();
        let out = std::env::temp_dir().join(format!("ita-nav-sweep-{}", std::process::id()));
        let rows = run_sweep(
            &base,
            &sw,
            &[Mode::Kf, Mode::Akf],
            2,
            1,
            &out,
            &crate::Silent,
        )
        .unwrap();
        assert_eq!(rows.len(), 4);
        // The KF does not depend on the AKF window: same seeds, same result at both values.
        assert_eq!(rows[0].1.final_median_m, rows[2].1.final_median_m);
        for f in [
            "sweep.md",
            "sweep.csv",
            "sweep_final_error.svg",
            "sweep_final_error.png",
        ] {
            assert!(out.join(f).metadata().unwrap().len() > 100, "{f}");
        }
        let csv = std::fs::read_to_string(out.join("sweep.csv")).unwrap();
        assert_eq!(csv.lines().count(), 5);
        let _ = std::fs::remove_dir_all(&out);
    }
}
