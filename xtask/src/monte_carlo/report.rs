//! From [`Stats`] to the reports: `summary.md`, `summary.json` and the 1 Hz CSV time series.

use std::fmt::Write as _;

use anyhow::Result;
use serde_json::{Value, json};

use super::stats::{ModeStats, Moments, Stats, missing_ranges, qi};

/// Degrees of freedom of the NEES (error-state dimension).
pub const NEES_DOF: usize = 15;
/// Degrees of freedom of the NIS (three landmarks × (w, h)).
pub const NIS_DOF: usize = 6;
/// Confidence of the χ² bands.
pub const CONFIDENCE: f64 = 0.95;

/// The paper's reported results at 900 s (Lustosa, Chagas & Waldmann, §6).
pub struct PaperFigure {
    /// Mode name.
    pub mode: &'static str,
    /// Position error at 900 s, m (None: not given).
    pub error_m: Option<f64>,
    /// Error as % of distance flown.
    pub percent: Option<f64>,
    /// The paper's words.
    pub text: &'static str,
}

/// What the paper reports, per mode.
pub const PAPER: [PaperFigure; 3] = [
    PaperFigure {
        mode: "standalone",
        error_m: None,
        percent: None,
        text: "diverges, the vertical channel most (Figs. 1, 4)",
    },
    PaperFigure {
        mode: "kf",
        error_m: Some(100.0),
        percent: Some(0.34),
        text: "≈ 0.1 km at 900 s, 0.34 % of distance (Figs. 3, 6)",
    },
    PaperFigure {
        mode: "akf",
        error_m: Some(140.0),
        percent: Some(0.47),
        text: "≈ 0.14 km at 900 s, 0.47 % of distance (Figs. 2, 5)",
    },
];

/// Two-sided 95 % band for the average of `runs` χ²(`dof`) values (exact quantiles, `akf`).
pub fn band(dof: usize, runs: u64) -> Option<(f64, f64)> {
    akf::average_band(dof, runs as usize, CONFIDENCE).ok()
}

/// Time bins (whole seconds) reported in the tables: 195, 600, 900 s where the flight lasts that
/// long, and always the final time.
pub fn report_times(duration_s: f64) -> Vec<usize> {
    let end = duration_s.round() as usize;
    let mut t: Vec<usize> = [195, 600, 900].into_iter().filter(|&t| t < end).collect();
    t.push(end);
    t
}

/// Consistency of a run-averaged χ² statistic over all epochs that have it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Consistency {
    /// Mean over all runs and epochs.
    pub mean: f64,
    /// Epochs with a value.
    pub epochs: usize,
    /// Fraction of epochs whose run average lies inside its 95 % band.
    pub inside: f64,
    /// … above the band (filter over-confident: P or S too small).
    pub above: f64,
    /// … below the band (filter under-confident: P or S too large).
    pub below: f64,
    /// First and last epoch (s) above the band.
    pub above_span: Option<(f64, f64)>,
    /// First and last epoch (s) below the band.
    pub below_span: Option<(f64, f64)>,
}

/// NEES or NIS consistency of one mode (None for a mode without a filter).
pub fn consistency(m: &ModeStats, q: usize, dof: usize) -> Option<Consistency> {
    let mut total = Moments::default();
    let (mut epochs, mut inside, mut above, mut below) = (0usize, 0usize, 0usize, 0usize);
    let (mut above_span, mut below_span) = (None, None);
    let widen = |span: &mut Option<(f64, f64)>, t: f64| {
        *span = Some(span.map_or((t, t), |(a, _)| (a, t)));
    };
    for (t, bin) in m.bins.iter().enumerate() {
        let t = t as f64;
        let b = bin[q];
        if b.n == 0 {
            continue;
        }
        total.merge(&b);
        epochs += 1;
        let avg = b.mean();
        match band(dof, b.n) {
            Some((lo, _)) if avg < lo => {
                below += 1;
                widen(&mut below_span, t);
            }
            Some((_, hi)) if avg > hi => {
                above += 1;
                widen(&mut above_span, t);
            }
            _ => inside += 1,
        }
    }
    (epochs > 0).then(|| {
        let e = epochs as f64;
        Consistency {
            mean: total.mean(),
            epochs,
            inside: inside as f64 / e,
            above: above as f64 / e,
            below: below as f64 / e,
            above_span,
            below_span,
        }
    })
}

fn at(m: &ModeStats, t: usize) -> &[Moments; super::stats::Q] {
    &m.bins[t.min(m.bins.len() - 1)]
}

fn paper(mode: &str) -> Option<&'static PaperFigure> {
    PAPER.iter().find(|p| p.mode == mode)
}

/// Final 3-D RMS position error, m.
fn final_rms(m: &ModeStats) -> f64 {
    m.bins.last().map_or(f64::NAN, |b| b[qi::POS_3D].rms())
}

/// Epochs per second per core (Σ epochs / Σ per-run thread CPU time, or Σ per-run wall time
/// where no CPU clock was available), and aggregate epochs per second of wall time.
pub fn throughput(stats: &Stats) -> (u64, f64, f64) {
    let epochs: u64 = stats.modes.iter().map(|m| m.epochs).sum();
    let cpu: f64 = stats.modes.iter().map(|m| m.run_cpu_s).sum();
    let run_time: f64 = stats.modes.iter().map(|m| m.run_time_s).sum();
    let per_core = epochs as f64 / if cpu > 0.0 { cpu } else { run_time.max(1e-12) };
    let per_wall = epochs as f64 / stats.wall_s.max(1e-12);
    (epochs, per_core, per_wall)
}

fn f(x: f64, digits: usize) -> String {
    if x.is_finite() {
        format!("{x:.digits$}")
    } else {
        "—".to_string()
    }
}

fn json_num(x: f64) -> Value {
    if x.is_finite() { json!(x) } else { Value::Null }
}

/// `summary.json`.
pub fn summary_json(stats: &Stats) -> Result<String> {
    let mut modes = serde_json::Map::new();
    for m in &stats.modes {
        let last = m.bins.last().copied().unwrap_or_default();
        let dist = last[qi::DIST].mean();
        let mut o = serde_json::Map::new();
        o.insert("runs_used".into(), json!(m.runs_used));
        o.insert(
            "runs_excluded".into(),
            json!(stats.exclusions.iter().filter(|e| e.mode == m.mode).count()),
        );
        o.insert(
            "final_position_error_m".into(),
            json_num(last[qi::POS_3D].rms()),
        );
        o.insert(
            "final_horizontal_error_m".into(),
            json_num(last[qi::POS_H].rms()),
        );
        o.insert(
            "final_vertical_error_m".into(),
            json_num(last[qi::POS_D].rms()),
        );
        o.insert("distance_m".into(), json_num(dist));
        o.insert(
            "final_position_error_median_m".into(),
            json_num(median_final(stats, &m.mode)),
        );
        o.insert(
            "worst_runs".into(),
            serde_json::to_value(worst_runs(stats, &m.mode, 5))?,
        );
        o.insert(
            "final_error_percent_of_distance".into(),
            json_num(100.0 * last[qi::POS_3D].rms() / dist),
        );
        let mut times = serde_json::Map::new();
        for t in report_times(stats.duration_s) {
            let b = at(m, t);
            times.insert(
                t.to_string(),
                json!({
                    "horizontal_error_mean_m": json_num(b[qi::POS_H].mean()),
                    "horizontal_error_sd_m": json_num(b[qi::POS_H].std_dev()),
                    "vertical_down_error_mean_m": json_num(b[qi::POS_D].mean()),
                    "vertical_down_error_sd_m": json_num(b[qi::POS_D].std_dev()),
                    "position_error_rms_m": json_num(b[qi::POS_3D].rms()),
                    "misalignment_mean_rad": [json_num(b[qi::PSI_N].mean()), json_num(b[qi::PSI_E].mean()), json_num(b[qi::PSI_D].mean())],
                    "misalignment_sd_rad": [json_num(b[qi::PSI_N].std_dev()), json_num(b[qi::PSI_E].std_dev()), json_num(b[qi::PSI_D].std_dev())],
                    "distance_m": json_num(b[qi::DIST].mean()),
                    "nees_mean": json_num(b[qi::NEES].mean()),
                    "nis_mean": json_num(b[qi::NIS].mean()),
                }),
            );
        }
        o.insert("at_time_s".into(), Value::Object(times));
        for (name, q, dof) in [("nees", qi::NEES, NEES_DOF), ("nis", qi::NIS, NIS_DOF)] {
            if let Some(c) = consistency(m, q, dof) {
                o.insert(format!("{name}_mean"), json_num(c.mean));
                if let Some((lo, hi)) = band(dof, m.runs_used) {
                    o.insert(format!("{name}_band_95"), json!([lo, hi]));
                }
                o.insert(format!("{name}_fraction_inside_band"), json_num(c.inside));
                o.insert(format!("{name}_fraction_above_band"), json_num(c.above));
                o.insert(format!("{name}_fraction_below_band"), json_num(c.below));
            }
        }
        if let Some(p) = paper(&m.mode) {
            o.insert(
                "paper".into(),
                json!({"error_m": p.error_m, "percent_of_distance": p.percent, "text": p.text}),
            );
        }
        modes.insert(m.mode.clone(), Value::Object(o));
    }
    let (epochs, per_core, per_wall) = throughput(stats);
    let doc = json!({
        "runs_total": stats.runs_total,
        "runs_covered": stats.runs_covered(),
        "seed": stats.seed,
        "duration_s": stats.duration_s,
        "scenario_source": stats.scenario_source,
        "scenario_fingerprint": stats.scenario_fingerprint,
        "shards": stats.shards.len(),
        "excluded_runs": stats.exclusions,
        "epochs": epochs,
        "epochs_per_s_per_core": per_core,
        "epochs_per_s_wall": per_wall,
        "wall_s": stats.wall_s,
    });
    // Each mode at the top level: `summary["kf"]["final_position_error_m"]`.
    let mut top = match doc {
        Value::Object(o) => o,
        _ => serde_json::Map::new(),
    };
    for (k, v) in modes {
        top.insert(k, v);
    }
    Ok(serde_json::to_string_pretty(&Value::Object(top))? + "\n")
}

/// The 1 Hz CSV time series of one mode.
pub fn timeseries_csv(m: &ModeStats) -> String {
    let mut s = String::from("t_s,runs");
    let cols = [
        (qi::POS_N, "pos_n_m"),
        (qi::POS_E, "pos_e_m"),
        (qi::POS_D, "pos_d_m"),
        (qi::POS_H, "pos_horizontal_m"),
        (qi::VEL_N, "vel_n_mps"),
        (qi::VEL_E, "vel_e_mps"),
        (qi::VEL_D, "vel_d_mps"),
        (qi::PSI_N, "psi_n_rad"),
        (qi::PSI_E, "psi_e_rad"),
        (qi::PSI_D, "psi_d_rad"),
    ];
    for (_, name) in cols {
        let _ = write!(s, ",{name}_mean,{name}_sd");
    }
    s.push_str(",pos_3d_rms_m,distance_m,nees_mean,nees_runs,nees_band_lo,nees_band_hi,nis_mean,nis_runs,nis_band_lo,nis_band_hi\n");
    let e = |x: f64| {
        if x.is_finite() {
            format!("{x:.9e}")
        } else {
            String::new()
        }
    };
    for (t, bin) in m.bins.iter().enumerate() {
        let _ = write!(s, "{t},{}", bin[qi::POS_N].n);
        for (q, _) in cols {
            let _ = write!(s, ",{},{}", e(bin[q].mean()), e(bin[q].std_dev()));
        }
        let _ = write!(
            s,
            ",{},{}",
            e(bin[qi::POS_3D].rms()),
            e(bin[qi::DIST].mean())
        );
        for (q, dof) in [(qi::NEES, NEES_DOF), (qi::NIS, NIS_DOF)] {
            let b = bin[q];
            let (lo, hi) = band(dof, b.n).unwrap_or((f64::NAN, f64::NAN));
            let _ = write!(s, ",{},{},{},{}", e(b.mean()), b.n, e(lo), e(hi));
        }
        s.push('\n');
    }
    s
}

/// One word for a consistency result.
fn state(c: &Consistency) -> &'static str {
    if c.inside >= 0.9 {
        "consistent"
    } else if c.above >= 0.05 && c.below >= 0.05 {
        "inconsistent both ways"
    } else if c.above >= c.below {
        "over-confident"
    } else {
        "under-confident"
    }
}

/// How a χ² statistic sits against its band, in words.
fn verdict(c: &Consistency) -> String {
    let span =
        |x: Option<(f64, f64)>| x.map_or(String::new(), |(a, b)| format!(" (t = {a:.0}…{b:.0} s)"));
    let word = match state(c) {
        "consistent" => "consistent".to_string(),
        "over-confident" => {
            "**over-confident** (its covariance is smaller than its actual errors)".to_string()
        }
        "under-confident" => {
            "**under-confident** (its covariance is larger than its actual errors)".to_string()
        }
        other => format!(
            "**{other}**: under-confident at some epochs, over-confident (covariance too small) at others"
        ),
    };
    format!(
        "run average inside its 95 % band at {:.0} % of the epochs, above at {:.0} %{}, below at {:.0} %{} → {word}",
        100.0 * c.inside,
        100.0 * c.above,
        span(c.above_span),
        100.0 * c.below,
        span(c.below_span)
    )
}

/// Median of the final 3-D errors of the kept runs of `mode`.
pub fn median_final(stats: &Stats, mode: &str) -> f64 {
    let mut v: Vec<f64> = stats
        .runs
        .iter()
        .filter(|r| r.mode == mode)
        .map(|r| r.final_pos_3d_m)
        .collect();
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// The `k` kept runs of `mode` with the largest peak 3-D error, largest first.
pub fn worst_runs(stats: &Stats, mode: &str, k: usize) -> Vec<super::stats::RunSummary> {
    let mut v: Vec<_> = stats
        .runs
        .iter()
        .filter(|r| r.mode == mode)
        .cloned()
        .collect();
    v.sort_by(|a, b| b.peak_pos_3d_m.total_cmp(&a.peak_pos_3d_m));
    v.truncate(k);
    v
}

/// `summary.md`.
pub fn summary_md(stats: &Stats) -> String {
    let mut s = String::new();
    let runs = stats.runs_covered();
    let _ = writeln!(s, "# INS/SD Monte Carlo — Lustosa, Chagas & Waldmann, §6\n");
    let missing = missing_ranges(stats);
    if !missing.is_empty() {
        let _ = writeln!(
            s,
            "> **Partial:** {runs} of {} runs; missing run indices {}.\n",
            stats.runs_total,
            missing
                .iter()
                .map(|(a, b)| format!("{a}..{b}"))
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    let _ = writeln!(
        s,
        "{runs} runs per configuration, master seed {}, {} s of flight, scenario {} (fingerprint {}){}.\n",
        stats.seed,
        stats.duration_s,
        stats.scenario_source,
        stats.scenario_fingerprint,
        if stats.shards.len() > 1 {
            format!(", merged from {} shards", stats.shards.len())
        } else {
            String::new()
        }
    );

    // Headline against the paper.
    let _ = writeln!(s, "## At the final time, beside the paper\n");
    let _ = writeln!(
        s,
        "| configuration | runs used | excluded | 3-D error RMS (m) | 3-D error median (m) | horizontal RMS (m) | vertical RMS (m) | distance (km) | 3-D error / distance | paper |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|---|---|---|---|---|");
    for m in &stats.modes {
        let last = m.bins.last().copied().unwrap_or_default();
        let dist = last[qi::DIST].mean();
        let excluded = stats.exclusions.iter().filter(|e| e.mode == m.mode).count();
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} % | {} |",
            m.mode,
            m.runs_used,
            excluded,
            f(last[qi::POS_3D].rms(), 1),
            f(median_final(stats, &m.mode), 1),
            f(last[qi::POS_H].rms(), 1),
            f(last[qi::POS_D].rms(), 1),
            f(dist / 1000.0, 2),
            f(100.0 * last[qi::POS_3D].rms() / dist, 3),
            paper(&m.mode).map_or("", |p| p.text)
        );
    }
    s.push('\n');
    checks(&mut s, stats);

    // Tables per configuration.
    for m in &stats.modes {
        let _ = writeln!(s, "## {}\n", m.mode);
        let _ = writeln!(
            s,
            "Mean ± σ over runs. Vertical = down component of the position error (computed − true). ψ = misalignment (N, E, D = azimuth).\n"
        );
        let _ = writeln!(
            s,
            "| t (s) | horizontal (m) | vertical, down (m) | 3-D RMS (m) | ψ_N (mrad) | ψ_E (mrad) | ψ_D (mrad) | distance (km) | 3-D RMS / distance | NEES avg | NIS avg |"
        );
        let _ = writeln!(s, "|---|---|---|---|---|---|---|---|---|---|---|");
        for t in report_times(stats.duration_s) {
            let b = at(m, t);
            let pm = |q: usize, k: f64, d: usize| {
                format!("{} ± {}", f(k * b[q].mean(), d), f(k * b[q].std_dev(), d))
            };
            let dist = b[qi::DIST].mean();
            let _ = writeln!(
                s,
                "| {t} | {} | {} | {} | {} | {} | {} | {} | {} % | {} | {} |",
                pm(qi::POS_H, 1.0, 1),
                pm(qi::POS_D, 1.0, 1),
                f(b[qi::POS_3D].rms(), 1),
                pm(qi::PSI_N, 1e3, 3),
                pm(qi::PSI_E, 1e3, 3),
                pm(qi::PSI_D, 1e3, 3),
                f(dist / 1000.0, 2),
                f(100.0 * b[qi::POS_3D].rms() / dist, 3),
                f(b[qi::NEES].mean(), 2),
                f(b[qi::NIS].mean(), 2),
            );
        }
        s.push('\n');
        for (name, q, dof) in [("NEES", qi::NEES, NEES_DOF), ("NIS", qi::NIS, NIS_DOF)] {
            if let Some(c) = consistency(m, q, dof) {
                let (lo, hi) = band(dof, m.runs_used).unwrap_or((f64::NAN, f64::NAN));
                let _ = writeln!(
                    s,
                    "- {name} (n = {dof}): average over {} runs and {} epochs {}; 95 % band for the average of {} runs [{}, {}]; {}.",
                    m.runs_used,
                    c.epochs,
                    f(c.mean, 2),
                    m.runs_used,
                    f(lo, 2),
                    f(hi, 2),
                    verdict(&c)
                );
            }
        }
        let worst = worst_runs(stats, &m.mode, 3);
        if !worst.is_empty() {
            let _ = writeln!(
                s,
                "- Worst runs by peak 3-D position error: {}.",
                worst
                    .iter()
                    .map(|r| format!(
                        "run {} peaks at {} m at t = {} s (final {} m{})",
                        r.run_index,
                        f(r.peak_pos_3d_m, 1),
                        r.peak_t_s,
                        f(r.final_pos_3d_m, 1),
                        r.peak_nees
                            .map_or(String::new(), |x| format!(", peak NEES {}", f(x, 0)))
                    ))
                    .collect::<Vec<_>>()
                    .join("; ")
            );
        }
        s.push('\n');
    }

    // Exclusions.
    let _ = writeln!(s, "## Runs excluded as non-finite or failed\n");
    if stats.exclusions.is_empty() {
        let _ = writeln!(s, "None: every run stayed finite.\n");
    } else {
        let _ = writeln!(
            s,
            "{} run(s) excluded from their configuration's statistics (never averaged in):\n",
            stats.exclusions.len()
        );
        for e in &stats.exclusions {
            let _ = writeln!(
                s,
                "- {} run {}{}: {}",
                e.mode,
                e.run_index,
                e.t_s.map_or(String::new(), |t| format!(" at t = {t} s")),
                e.reason
            );
        }
        s.push('\n');
    }

    let _ = writeln!(s, "## Scenario assumptions\n");
    for a in &stats.assumptions {
        let _ = writeln!(s, "- {a}");
    }
    s.push('\n');
    let _ = writeln!(s, "## Why our numbers may differ from the paper's\n");
    let _ = writeln!(
        s,
        "The paper does not give its manoeuvre sequence, initial speed and heading, landmark geometry relative to the flight, initial covariance, the manually tuned Q, nor how many Monte Carlo runs it averaged; all are our choices (listed above, in the config). Position error at 900 s depends mostly on the landmark geometry (range and angles: σ_SD = √40 m at the landmark constrains angles, so position accuracy scales with range) and on the filter's Q (how much it trusts the INS), so only the ordering and the order of magnitude are expected to match.\n"
    );

    differences(&mut s, stats);

    let (epochs, per_core, per_wall) = throughput(stats);
    let _ = writeln!(s, "## Throughput\n");
    let _ = writeln!(
        s,
        "{epochs} filter epochs (100 Hz INS steps, all configurations) in {:.2} s of simulation wall time (summed over shards if merged): **{:.0} epochs/s per core** (Σ epochs / Σ CPU time of the threads that ran them), {:.0} epochs/s aggregate over the wall time (lower than threads × per-core when the machine is shared). A run that fails is not counted. For comparison on this machine (docs/ins-sd.md): KF-GINS (C++, 21 states, text I/O) ≈ 40 000 epochs/s; pyins (Python, 0.01 s covariance step) ≈ 136 epochs/s.",
        stats.wall_s, per_core, per_wall
    );
    s
}

/// The "what it must show" items, checked on the numbers.
fn checks(s: &mut String, stats: &Stats) {
    let get = |name: &str| stats.mode(name);
    let _ = writeln!(s, "Checks against the paper's claims:\n");
    if let (Some(sa), Some(kf), Some(akf)) = (get("standalone"), get("kf"), get("akf")) {
        let (e_sa, e_kf, e_akf) = (final_rms(sa), final_rms(kf), final_rms(akf));
        let ordered = e_kf < e_akf && e_akf < e_sa;
        let _ = writeln!(
            s,
            "- Ordering KF < AKF < stand-alone at the final time (paper): {} ({} m < {} m < {} m).",
            if ordered {
                "**reproduced**"
            } else if e_kf < e_sa && e_akf < e_sa {
                "**partly**: both filters beat stand-alone, but the AKF is not worse than the KF"
            } else {
                "**not reproduced**"
            },
            f(e_kf, 1),
            f(e_akf, 1),
            f(e_sa, 1)
        );
    }
    let at_900 = (stats.duration_s - 900.0).abs() < 0.5;
    if !at_900 {
        let _ = writeln!(
            s,
            "- The paper's position errors are at 900 s; this run ends at {} s, so they are not compared.",
            stats.duration_s
        );
    }
    for m in stats.modes.iter().filter(|_| at_900) {
        if let Some(p) = paper(&m.mode)
            && let Some(paper_m) = p.error_m
        {
            let ratio = final_rms(m) / paper_m;
            let _ = writeln!(
                s,
                "- {}: ours / paper = {} → {}.",
                m.mode,
                f(ratio, 2),
                if (0.316..=3.16).contains(&ratio) {
                    "same order of magnitude"
                } else {
                    "**different order of magnitude**"
                }
            );
        }
    }
    if let Some(sa) = get("standalone")
        && let Some(last) = sa.bins.last()
    {
        let (v, n, e) = (
            last[qi::POS_D].rms(),
            last[qi::POS_N].rms(),
            last[qi::POS_E].rms(),
        );
        let _ = writeln!(
            s,
            "- Stand-alone diverges, vertical channel most: RMS N {} m, E {} m, vertical {} m at the final time → {}.",
            f(n, 1),
            f(e, 1),
            f(v, 1),
            if v > n && v > e {
                "vertical largest"
            } else {
                "**vertical not the largest**"
            }
        );
    }
    let end = stats.duration_s.round() as usize;
    if end > 600 {
        for m in &stats.modes {
            if m.mode == "standalone" {
                continue;
            }
            let s600 = at(m, 600)[qi::PSI_D].std_dev();
            let send = at(m, end)[qi::PSI_D].std_dev();
            let (t_max, s_max) = (600..=end.min(m.bins.len() - 1))
                .map(|t| (t, m.bins[t][qi::PSI_D].std_dev()))
                .fold((600, s600), |a, b| if b.1 > a.1 { b } else { a });
            let _ = writeln!(
                s,
                "- {}: azimuth misalignment σ {} mrad at 600 s (manoeuvres end), largest after it {} mrad at {t_max} s, {} mrad at {end} s → {}.",
                m.mode,
                f(1e3 * s600, 3),
                f(1e3 * s_max, 3),
                f(1e3 * send, 3),
                if s_max <= 2.0 * s600 {
                    "bounded after the manoeuvres end (paper: limited azimuth misalignment after 600 s)"
                } else {
                    "**not bounded: it grows after the manoeuvres end**"
                }
            );
        }
    }
    s.push('\n');
}

/// Data-driven notes on where and why our filters differ from the paper's figures.
fn differences(s: &mut String, stats: &Stats) {
    if (stats.duration_s - 900.0).abs() >= 0.5 {
        return;
    }
    for m in &stats.modes {
        let (Some(p), Some(nees)) = (paper(&m.mode), consistency(m, qi::NEES, NEES_DOF)) else {
            continue;
        };
        let Some(paper_m) = p.error_m else { continue };
        let ratio = final_rms(m) / paper_m;
        let nis = consistency(m, qi::NIS, NIS_DOF).unwrap_or_default();
        let _ = write!(
            s,
            "- **{}**: {} × the paper's error (NEES {}, NIS {}). ",
            m.mode,
            f(ratio, 2),
            state(&nees),
            state(&nis)
        );
        if ratio < 0.316 {
            let _ = writeln!(
                s,
                "Ours is much smaller. Every second the SD gives six image offsets of σ = {} m at the landmark; a filter whose model matches the simulated errors (its NIS says whether it does) averages them down to metres, and with three landmarks always in view the INS errors stay observable. Read this way, the SD noise alone does not account for the paper's figure: its error budget must contain effects its text does not state (landmark geometry and ranges, its tuning of Q and P₀, or a mismatch between its simulation and its filter model). Two of them were tested on 30 seeded runs (`cargo run --release -p nav-app --example paper_h -- 30`, and `-- 30 open-loop`): the paper's printed sighting Jacobian (eqs. 15–18) read literally makes the KF diverge to kilometres, so it is not what the authors ran; the verified H with the INS never corrected (`[filter] open_loop_until_s = 1e9`) gives 96 m, 0.34 % of the distance at 900 s for the KF — the paper's own figure — and 177 m for the AKF (paper 140 m). A filter linearised about an uncorrected, drifting INS (the paper's §7: \"H requires a rather accurate estimate of the UAV position\") is the likely reason for the gap; we keep the feedback the paper describes.",
                f(40f64.sqrt(), 1)
            );
        } else if ratio > 3.16 {
            let _ = writeln!(
                s,
                "Ours is much larger: look at the filter's consistency above (a filter whose covariance does not match its errors weighs the SD wrongly) and at the excluded runs."
            );
        } else {
            let _ = writeln!(s, "Same order of magnitude as the paper.");
        }
        nees_story(s, m);
    }
    s.push('\n');
}

/// Phases of the flight for the NEES story: open loop, just after the switch to feedback
/// (195 s), manoeuvres with feedback, straight flight after the manoeuvres end (600 s).
const PHASES: [(usize, usize, &str); 4] = [
    (1, 194, "open loop"),
    (195, 260, "just after the switch to feedback"),
    (261, 600, "manoeuvres, feedback"),
    (601, usize::MAX, "straight flight after the manoeuvres"),
];

/// Why the NEES of one filter mode sits where it does, phase by phase, from its time series.
fn nees_story(s: &mut String, m: &ModeStats) {
    let Some((lo, hi)) = m
        .bins
        .iter()
        .map(|b| b[qi::NEES].n)
        .find(|&n| n > 0)
        .and_then(|n| band(NEES_DOF, n))
    else {
        return;
    };
    let mut parts = Vec::new();
    for (a, b, name) in PHASES {
        let b = b.min(m.bins.len().saturating_sub(1));
        let mut pooled = Moments::default();
        let mut peak: Option<(usize, f64)> = None;
        for t in a..=b {
            let x = m.bins[t][qi::NEES];
            if x.n == 0 {
                continue;
            }
            pooled.merge(&x);
            if peak.is_none_or(|(_, p)| x.mean() > p) {
                peak = Some((t, x.mean()));
            }
        }
        let Some((t_peak, peak)) = peak else { continue };
        let mean = pooled.mean();
        let word = if mean < lo {
            "below the band: under-confident (P larger than the errors)"
        } else if mean > hi {
            "above the band: over-confident (P smaller than the errors)"
        } else {
            "inside the band"
        };
        let spike = if peak > 10.0 * hi {
            format!(
                "; **the run average peaks at {} at t = {t_peak} s**, a blow-up",
                f(peak, 0)
            )
        } else if peak > hi && mean <= hi {
            format!(
                "; above the band at some epochs, peak {} at t = {t_peak} s",
                f(peak, 1)
            )
        } else {
            String::new()
        };
        parts.push(format!(
            "{a}–{} s ({name}) {}, {word}{spike}",
            b,
            f(mean, 1)
        ));
    }
    let _ = writeln!(
        s,
        "  NEES by phase (band for one epoch's run average [{}, {}]): {}.",
        f(lo, 2),
        f(hi, 2),
        parts.join("; ")
    );
    let reading = if m.mode == "akf_sage_husa" {
        "Reading: Sage–Husa averages the single-update estimates Δx Δxᵀ + P⁺ − Φ P⁺₋ Φᵀ with a forgetting factor (memory ≈ 1/(1 − b) updates) instead of a window of 10; the longer memory smooths the indefinite P⁺ − Φ P⁺₋ Φᵀ term, so less of Q̂ is clipped away by the projection. Where NEES and NIS are below their bands it still over-estimates the process noise (same innovation-based estimate)."
    } else if m.mode == "akf_structured" {
        "Reading: the windowed Mohamed–Schwarz Q̂ projected by non-negative least squares onto the model's four noise inputs (Q = Σ q_k B_k): PSD with the model's correlations, but the raw Q̂ sees the noise only through the innovations (rank ≤ 6 per update), so the fitted densities are not the true ones (a 40 s look: all weight on the gyro white noise and drift random walk)."
    } else if m.mode == "kf" {
        "Reading: below the band, P₀ and the doubled white-noise Q (config comment: tuned so) keep P larger than the errors; above it late in open loop and just after the switch to feedback at 195 s, the linearisation residue of the INS error grown in open loop (the linear error model degrades as the uncorrected error grows) is not in P; feedback removes it within about a minute. The NIS, which sees only the six measurement directions, stays consistent."
    } else {
        "Reading: the Mohamed–Schwarz Q̂ (innovation-based, fed back into the gain that produces the innovations) does not converge to the true Q; where NEES and NIS are both below their bands it over-estimates the process noise. With the eigenvalue-clipping projection (floor 0) the loop runs away (measured: 100 runs, seed 2009, worst runs 6–7 km at 790–810 s, azimuth σ 22 mrad at 792 s, run-average NEES up to 10⁴): with N = 10 < 15 states Q̂ is dominated by the indefinite P⁺ − Φ P⁺ Φᵀ, clipping its large negative eigenvalues adds their magnitude back as positive mass in mixed-unit directions, a larger Q̂ gives a larger P and more clipped mass, and in straight flight after 600 s (level/azimuth weakly observable) this feedback ends in a Q̂ explosion (≈ 1.5 km per interval on position at 800 s, run 96); the diagonal projection (the default) stays bounded."
    };
    let _ = writeln!(s, "  {reading}");
}
