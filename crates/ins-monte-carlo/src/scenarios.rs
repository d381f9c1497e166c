//! `nav-app monte-carlo scenarios`: the matched case (`configs/paper.toml`) and every
//! model-mismatch scenario of `configs/mismatch/`, KF and AKF on the same seeds, in one table:
//! final errors, lost runs, NEES/NIS, the fraction of epochs whose run-average NEES lies in the
//! per-epoch 95 % band, and the sightings used and rejected by the gate.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use rayon::prelude::*;

use super::{McError, Progress, load_scenario};
use ins_sim::runs::{Verdict, run_range};
use ins_sim::{Mode, Sample, Scenario, SimRunOutcome};

/// Options of `scenarios`.
#[derive(Debug, Clone)]
pub struct ScenarioOptions {
    /// Directory of mismatch scenario files (`configs/mismatch`); every `*.toml` in it is a row.
    pub dir: PathBuf,
    /// The matched scenario, the first row (`configs/paper.toml`).
    pub matched: PathBuf,
    /// Runs per scenario and filter.
    pub runs: u64,
    /// Output directory (gets `comparison.md`).
    pub out: PathBuf,
    /// Worker threads [None: all cores].
    pub threads: Option<usize>,
    /// Cut every flight to its first seconds [None: whole flights].
    pub duration_s: Option<f64>,
}

/// One (scenario, filter) row.
#[derive(Clone, Debug)]
pub struct Row {
    /// Scenario name.
    pub scenario: String,
    /// Filter.
    pub mode: Mode,
    /// Runs that reached the end.
    pub kept: u64,
    /// Runs lost (the simulation failed).
    pub lost: u64,
    /// Failure times of the lost runs, s (sorted).
    pub lost_t_s: Vec<f64>,
    /// RMS over kept runs of the final 3-D position error, m.
    pub final_rms_m: f64,
    /// Median of the final 3-D error, m.
    pub final_median_m: f64,
    /// 10th percentile of the final 3-D error, m.
    pub final_p10_m: f64,
    /// 90th percentile of the final 3-D error, m.
    pub final_p90_m: f64,
    /// Mean NEES over kept runs and epochs t ≥ 1 s.
    pub nees_mean: f64,
    /// Fraction of epochs whose run-average NEES is inside the per-epoch 95 % band.
    pub nees_in_band: f64,
    /// Mean NIS per degree of freedom (1 for a consistent filter).
    pub nis_per_dof: f64,
    /// Sightings used per run (mean).
    pub used_per_run: f64,
    /// Sightings rejected per run (mean).
    pub rejected_per_run: f64,
}

struct RunResult {
    final_m: f64,
    nees: Vec<f64>,
    nis_sum: f64,
    dof_sum: f64,
    used: u64,
    rejected: u64,
}

/// Simulates `runs` runs of `sc` in `mode` on the current rayon pool (one call of the one run
/// loop, [`ins_sim::runs::run_range`], per run: the same seeds and the same exclusion rule as
/// the Monte Carlo) and summarises them.
pub fn evaluate(name: &str, sc: &Scenario, mode: Mode, runs: u64) -> Result<Row, McError> {
    let n = sc.samples_per_run();
    let runner = ins_sim::runs::closed_loop(sc, sc.monte_carlo.seed);
    let results: Vec<Result<Result<RunResult, f64>, McError>> = (0..runs)
        .into_par_iter()
        .map(|i| {
            let mut out = vec![Sample::default(); n];
            let mut result = Err(f64::NAN);
            run_range(&runner, mode, i..i + 1, &mut out, |_, out, verdict| {
                result = match verdict {
                    Verdict::Excluded { t_s, .. } => Err(t_s.unwrap_or(f64::NAN)),
                    Verdict::Kept(o) => Ok(RunResult::of(out, &o)),
                }
            })
            .map_err(|e| McError::RunSetup {
                index: i,
                mode,
                source: Box::new(e),
            })?;
            Ok(result)
        })
        .collect();
    let results = results.into_iter().collect::<Result<Vec<_>, McError>>()?;
    let kept: Vec<&RunResult> = results.iter().filter_map(|r| r.as_ref().ok()).collect();
    let mut lost_t_s: Vec<f64> = results
        .iter()
        .filter_map(|r| r.as_ref().err().copied())
        .collect();
    lost_t_s.sort_by(f64::total_cmp);
    let mut row = Row {
        scenario: name.to_string(),
        mode,
        kept: kept.len() as u64,
        lost: runs - kept.len() as u64,
        lost_t_s,
        final_rms_m: f64::NAN,
        final_median_m: f64::NAN,
        final_p10_m: f64::NAN,
        final_p90_m: f64::NAN,
        nees_mean: f64::NAN,
        nees_in_band: f64::NAN,
        nis_per_dof: f64::NAN,
        used_per_run: f64::NAN,
        rejected_per_run: f64::NAN,
    };
    if kept.is_empty() {
        return Ok(row);
    }
    let k = kept.len() as f64;
    row.final_rms_m = (kept.iter().map(|r| r.final_m * r.final_m).sum::<f64>() / k).sqrt();
    let mut finals: Vec<f64> = kept.iter().map(|r| r.final_m).collect();
    finals.sort_by(f64::total_cmp);
    let q = |f: f64| finals[((finals.len() - 1) as f64 * f).round() as usize];
    row.final_median_m = q(0.5);
    row.final_p10_m = q(0.1);
    row.final_p90_m = q(0.9);
    let band = akf::average_band(15, kept.len(), 0.95).unwrap_or((f64::NAN, f64::NAN));
    let (mut inside, mut epochs, mut sum, mut cnt) = (0usize, 0usize, 0.0, 0usize);
    for t in 1..n {
        let vals: Vec<f64> = kept
            .iter()
            .map(|r| r.nees[t])
            .filter(|v| v.is_finite())
            .collect();
        if vals.is_empty() {
            continue;
        }
        let avg = vals.iter().sum::<f64>() / vals.len() as f64;
        sum += vals.iter().sum::<f64>();
        cnt += vals.len();
        epochs += 1;
        if avg >= band.0 && avg <= band.1 {
            inside += 1;
        }
    }
    row.nees_mean = if cnt > 0 { sum / cnt as f64 } else { f64::NAN };
    row.nees_in_band = if epochs > 0 {
        inside as f64 / epochs as f64
    } else {
        f64::NAN
    };
    let (ns, ds) = kept
        .iter()
        .fold((0.0, 0.0), |(a, b), r| (a + r.nis_sum, b + r.dof_sum));
    row.nis_per_dof = if ds > 0.0 { ns / ds } else { f64::NAN };
    row.used_per_run = kept.iter().map(|r| r.used as f64).sum::<f64>() / k;
    row.rejected_per_run = kept.iter().map(|r| r.rejected as f64).sum::<f64>() / k;
    Ok(row)
}

impl RunResult {
    /// The summary of one kept run (records `out`, all finite).
    fn of(out: &[Sample], o: &SimRunOutcome) -> RunResult {
        let p = out.last().map_or([f64::NAN; 3], |s| s.pos_err_ned_m);
        let mut r = RunResult {
            final_m: (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt(),
            nees: out.iter().map(|s| s.nees.unwrap_or(f64::NAN)).collect(),
            nis_sum: 0.0,
            dof_sum: 0.0,
            used: o.sightings_used,
            rejected: o.sightings_rejected,
        };
        for s in out {
            if let Some(v) = s.nis
                && s.nis_dof > 0
            {
                r.nis_sum += v;
                r.dof_sum += s.nis_dof as f64;
            }
        }
        r
    }
}

/// "k of n (t = a…b s)" for the lost-runs column.
pub fn lost_text(r: &Row) -> String {
    match (r.lost_t_s.first(), r.lost_t_s.last()) {
        (Some(a), Some(b)) => format!("{} of {} (t = {a:.0}…{b:.0} s)", r.lost, r.lost + r.kept),
        _ => format!("{} of {}", r.lost, r.lost + r.kept),
    }
}

/// The comparison table as Markdown.
pub fn table(rows: &[Row], runs: u64, duration_s: f64) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "# Model-mismatch scenarios ({runs} runs per row, {duration_s} s, same seeds in every row)\n"
    );
    let _ = writeln!(
        s,
        "| scenario | filter | final 3-D RMS (m) | median (m) | lost runs | NEES mean (15) | epochs with NEES in 95 % band | NIS per dof (1) | sightings used / run | rejected / run |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|---|---|---|---|---|");
    for r in rows {
        let _ = writeln!(
            s,
            "| {} | {} | {:.1} | {:.1} | {} | {:.1} | {:.0} % | {:.2} | {:.0} | {:.1} |",
            r.scenario,
            r.mode,
            r.final_rms_m,
            r.final_median_m,
            lost_text(r),
            r.nees_mean,
            100.0 * r.nees_in_band,
            r.nis_per_dof,
            r.used_per_run,
            r.rejected_per_run
        );
    }
    let _ = writeln!(
        s,
        "\nLost runs (the simulation failed: a landmark behind the camera or a non-finite state) are counted, not hidden; the statistics are over the kept runs. NEES in band: the fraction of 1 Hz epochs at which the run-average NEES lies inside the 95 % band for that number of runs (akf::average_band), the per-epoch test."
    );
    s
}

/// Runs the matched case and every scenario in `opts.dir`, writes `comparison.md` into
/// `opts.out`; returns the rows and the path written. Each row is also given to
/// `progress.note` as it is done.
pub fn run(
    opts: &ScenarioOptions,
    progress: &dyn Progress,
) -> Result<(Vec<Row>, PathBuf), McError> {
    let io = |path: &Path| {
        let path = path.to_path_buf();
        move |source| McError::Io { path, source }
    };
    let mut files: Vec<PathBuf> = std::fs::read_dir(&opts.dir)
        .map_err(io(&opts.dir))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    files.sort();
    let mut list = vec![("matched".to_string(), opts.matched.clone())];
    for f in files {
        let name = f
            .file_stem()
            .map_or_else(String::new, |s| s.to_string_lossy().into_owned());
        list.push((name, f));
    }
    let pool = super::pool(opts.threads)?;
    let mut rows = Vec::new();
    let mut duration_s = 0.0;
    for (name, path) in &list {
        let sc = load_scenario(path, opts.duration_s)?;
        duration_s = sc.duration_s();
        for mode in [Mode::Kf, Mode::Akf] {
            let row = pool.install(|| evaluate(name, &sc, mode, opts.runs))?;
            progress.note(&format!(
                "scenarios: {name:<20} {:<4} final 3-D RMS {:.1} m, lost {}, NEES {:.1}, rejected/run {:.1}",
                row.mode, row.final_rms_m, row.lost, row.nees_mean, row.rejected_per_run
            ));
            rows.push(row);
        }
    }
    std::fs::create_dir_all(&opts.out).map_err(io(&opts.out))?;
    let path = opts.out.join("comparison.md");
    std::fs::write(&path, table(&rows, opts.runs, duration_s)).map_err(io(&path))?;
    Ok((rows, path))
}
