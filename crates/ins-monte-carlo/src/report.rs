//! What the reports are made of, computed from [`Stats`]: the χ² bands, the consistency of a
//! run-averaged NEES/NIS against them, the paper's figures, robust statistics over runs,
//! throughput, and the 1 Hz CSV time series. The two summaries built from these are in
//! [`super::summary`].

use std::fmt::Write as _;

use super::stats::{ModeStats, Moments, Stats, qi};
use super::summary::ChiSquare;
use ins_sim::Mode;

/// Degrees of freedom of the NEES (error-state dimension).
pub const NEES_DOF: usize = 15;
/// Degrees of freedom of the NIS (three landmarks × (w, h)).
pub const NIS_DOF: usize = 6;
/// Confidence of the χ² bands.
pub const CONFIDENCE: f64 = 0.95;

/// The paper's reported results at 900 s (Lustosa, Chagas & Waldmann, §6).
pub struct PaperFigure {
    /// The mode.
    pub mode: Mode,
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
        mode: Mode::Standalone,
        error_m: None,
        percent: None,
        text: "diverges, the vertical channel most (Figs. 1, 4)",
    },
    PaperFigure {
        mode: Mode::Kf,
        error_m: Some(100.0),
        percent: Some(0.34),
        text: "≈ 0.1 km at 900 s, 0.34 % of distance (Figs. 3, 6)",
    },
    PaperFigure {
        mode: Mode::Akf,
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

/// The time bin of `t` seconds, the last one past the end ([`Stats`](ins_sim::stats::Stats) holds at
/// least one a mode: checked on load).
pub(super) fn at(m: &ModeStats, t: usize) -> &[Moments; super::stats::Q] {
    &m.bins[t.min(m.bins.len() - 1)]
}

pub(super) fn paper(mode: Mode) -> Option<&'static PaperFigure> {
    PAPER.iter().find(|p| p.mode == mode)
}

/// Σ 100 Hz INS steps, steps per second per core (Σ steps / Σ per-run thread CPU time, or Σ
/// per-run wall time where no CPU clock was available), and aggregate steps per second of wall
/// time.
pub fn throughput(stats: &Stats) -> (u64, f64, f64) {
    let steps: u64 = stats.modes().iter().map(|m| m.steps).sum();
    let cpu: f64 = stats.modes().iter().map(|m| m.run_cpu_s).sum();
    let run_time: f64 = stats.modes().iter().map(|m| m.run_time_s).sum();
    let per_core = steps as f64 / if cpu > 0.0 { cpu } else { run_time.max(1e-12) };
    let per_wall = steps as f64 / stats.wall_s().max(1e-12);
    (steps, per_core, per_wall)
}

pub(super) fn f(x: f64, digits: usize) -> String {
    if x.is_finite() {
        format!("{x:.digits$}")
    } else {
        "—".to_string()
    }
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
pub(super) fn state(c: &ChiSquare) -> &'static str {
    let (inside, above, below) = (
        c.fraction_inside_band,
        c.fraction_above_band,
        c.fraction_below_band,
    );
    if inside >= 0.9 {
        "consistent"
    } else if above >= 0.05 && below >= 0.05 {
        "inconsistent both ways"
    } else if above >= below {
        "over-confident"
    } else {
        "under-confident"
    }
}

/// How a χ² statistic sits against its band, in words.
pub(super) fn verdict(c: &ChiSquare) -> String {
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
        100.0 * c.fraction_inside_band,
        100.0 * c.fraction_above_band,
        span(c.above_span_s),
        100.0 * c.fraction_below_band,
        span(c.below_span_s)
    )
}

/// Median of the final 3-D errors of the kept runs of `mode`.
pub fn median_final(stats: &Stats, mode: Mode) -> f64 {
    let mut v: Vec<f64> = stats
        .runs()
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
pub fn worst_runs(stats: &Stats, mode: Mode, k: usize) -> Vec<super::stats::RunSummary> {
    let mut v: Vec<_> = stats
        .runs()
        .iter()
        .filter(|r| r.mode == mode)
        .cloned()
        .collect();
    v.sort_by(|a, b| b.peak_pos_3d_m.total_cmp(&a.peak_pos_3d_m));
    v.truncate(k);
    v
}
