//! The KF with the three measurement matrices of `[filter] measurement_jacobian` on the same
//! seeded runs (common random numbers): RMS over runs of the position error per NED axis at
//! 195 / 600 / 900 s, mean NEES and NIS over the runs still alive, and how many runs failed
//! (and when). Runs that fail (e.g. a landmark ends up behind the camera) count up to their
//! failure time only.
//!
//! `cargo run --release -p ins-sim --example paper_h -- [runs] [open-loop]` (default 30; paper
//! scenario of `configs/paper.toml`, master seed 2009, run seeds as `xtask monte-carlo`;
//! `open-loop` sets `filter.open_loop_until_s` beyond the run: no feedback at all, the filter
//! is linearised at the free INS throughout).
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use ins_sim::{MeasurementJacobian, Mode, Sample, Scenario, run, run_seed};

fn main() {
    let runs: u64 = std::env::args()
        .nth(1)
        .map(|a| a.parse().expect("runs"))
        .unwrap_or(30);
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../configs/paper.toml"
    ))
    .unwrap();
    let mut base = Scenario::from_toml_str(&text).unwrap();
    let open_loop = std::env::args().any(|a| a == "open-loop");
    if open_loop {
        base.filter.open_loop_until_s = 1e9;
    }
    let times = [195usize, 600, 900];
    for jac in [
        MeasurementJacobian::Verified,
        MeasurementJacobian::PaperPrintedElevation,
        MeasurementJacobian::PaperPrinted,
    ] {
        let mut sc = base.clone();
        sc.filter.measurement_jacobian = jac;
        let n = sc.samples_per_run();
        let mut out = vec![Sample::default(); n];
        // Per time: Σ e², alive count, Σ NEES, Σ NIS.
        let mut sum_sq = [[0.0f64; 3]; 3];
        let mut alive = [0usize; 3];
        let mut nees = [0.0f64; 3];
        let mut nis = [0.0f64; 3];
        let mut failures = Vec::new();
        for i in 0..runs {
            out.fill(Sample::default());
            let seed = run_seed(sc.monte_carlo.seed, i);
            let valid_until = match run(&sc, Mode::Kf, seed, &mut out) {
                Ok(o) => o.samples_written,
                Err(e) => {
                    // Samples before the failure are written; find the last one.
                    let last = out.iter().rposition(|s| s.t_s > 0.0).unwrap_or(0);
                    // The run's error and its causes (each error shows only its own message).
                    let why: Vec<String> =
                        std::iter::successors(Some(&e as &dyn std::error::Error), |c| c.source())
                            .map(ToString::to_string)
                            .collect();
                    failures.push(format!("run {i}: {}", why.join(": ")));
                    last // exclude the failing second itself
                }
            };
            for (k, &t) in times.iter().enumerate() {
                if t < valid_until {
                    let s = &out[t];
                    for (acc, e) in sum_sq[k].iter_mut().zip(s.pos_err_ned_m) {
                        *acc += e * e;
                    }
                    alive[k] += 1;
                    nees[k] += s.nees.unwrap_or(f64::NAN);
                    nis[k] += s.nis.unwrap_or(f64::NAN);
                }
            }
        }
        println!(
            "\n== measurement_jacobian = {jac:?}, KF, {runs} runs{} ==",
            if open_loop {
                ", open loop throughout"
            } else {
                ""
            }
        );
        println!("t (s) | runs alive | RMS δp N / E / D (m) | mean NEES (n=15) | mean NIS (n=6)");
        for (k, &t) in times.iter().enumerate() {
            let m = alive[k].max(1) as f64;
            let rms: Vec<String> = (0..3)
                .map(|a| format!("{:.2}", (sum_sq[k][a] / m).sqrt()))
                .collect();
            println!(
                "{t} | {} | {} | {:.3e} | {:.3e}",
                alive[k],
                rms.join(" / "),
                nees[k] / m,
                nis[k] / m
            );
        }
        println!("failed runs: {}", failures.len());
        for f in failures.iter().take(40) {
            println!("  {f}");
        }
    }
}
