//! `[filter] measurement_jacobian`: the option reaches the filter. Same seeds (common random
//! numbers: identical truth, IMU errors and SD noise), KF, open loop for the first 120 s: the
//! INS is the same in every setting, so the recorded error (INS − x̂) differs only through the
//! filter's H.
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use ins_sim::{MeasurementJacobian, Mode, Sample, Scenario, run, run_seed};

const T_S: usize = 120;
const SEEDS: u64 = 3;

/// Per seed: the 1 Hz records of a 120 s KF run with measurement matrix `jac`.
fn runs(jac: MeasurementJacobian) -> Vec<Vec<Sample>> {
    let mut sc = Scenario::paper_default().truncated(T_S as f64).unwrap();
    sc.filter.measurement_jacobian = jac;
    (0..SEEDS)
        .map(|i| {
            let mut out = vec![Sample::default(); sc.samples_per_run()];
            run(&sc, Mode::Kf, run_seed(sc.monte_carlo.seed, i), &mut out).unwrap();
            out
        })
        .collect()
}

/// RMS over seeds of the 3-D position error at `T_S`.
fn rms_3d_m(r: &[Vec<Sample>]) -> f64 {
    let s: f64 = r
        .iter()
        .map(|o| o[T_S].pos_err_ned_m.iter().map(|e| e * e).sum::<f64>())
        .sum();
    (s / r.len() as f64).sqrt()
}

#[test]
fn printed_h_changes_the_estimate_and_degrades_it_while_h3_alone_is_harmless() {
    let verified = runs(MeasurementJacobian::Verified);
    let printed = runs(MeasurementJacobian::PaperPrinted);
    let elevation = runs(MeasurementJacobian::PaperPrintedElevation);
    let (rv, rp, re) = (
        rms_3d_m(&verified),
        rms_3d_m(&printed),
        rms_3d_m(&elevation),
    );
    println!(
        "RMS 3-D error at {T_S} s: verified {rv:.2} m, printed {rp:.2} m, α₀ repaired {re:.2} m"
    );
    // The estimates differ from the first update on (the INS is identical: open loop).
    for (v, p) in verified.iter().zip(&printed) {
        assert_ne!(v[1].pos_err_ned_m, p[1].pos_err_ned_m);
        assert_ne!(v[T_S].pos_err_ned_m, p[T_S].pos_err_ned_m);
    }
    for (v, e) in verified.iter().zip(&elevation) {
        assert_ne!(v[T_S].pos_err_ned_m, e[T_S].pos_err_ned_m);
    }
    // Verified H: metre level (σ_SD = 6.3 m, six observations per second).
    assert!(rv < 10.0, "verified {rv}");
    // The printed α₀ (h rows × cos 2ε, flipped for the steep landmark) ruins the estimate.
    assert!(rp > 10.0 * rv, "printed {rp} vs verified {rv}");
    // The printed H₃ alone (≈ ρ/R of the δp entries) changes the error by a few per cent at most.
    assert!(
        (re - rv).abs() < 0.1 * rv,
        "α₀ repaired {re} vs verified {rv}"
    );
}
