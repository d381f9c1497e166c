//! Accuracy of the interval discretisation (A averaged on sub-intervals) against the paper's
//! way: Φ of every 0.01 s INS step multiplied over the 1 s SD interval, and Q_d of every step
//! (Simpson, `discretize_fast`) accumulated through the same products.
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use ins_errors::error_model::{self, Mat15, Transition};
use ins_errors::imu::{ImuErrorParams, ImuErrors};
use ins_errors::strapdown::{LinearizationPoint, Strapdown};
use ins_errors::trajectory::Trajectory;
use ins_sd_filter::interval::IntervalModel;
use ins_sim::Scenario;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

/// Linearisation points of an INS (with sensor errors) at every 0.01 s step of the interval
/// [t0, t0 + 1 s].
fn points(t0_s: f64) -> (Vec<LinearizationPoint>, f64) {
    let sc = Scenario::paper_default()
        .truncated((t0_s + 2.0).ceil())
        .unwrap();
    let tr = Trajectory::new(&sc.trajectory).unwrap();
    let params = ImuErrorParams::from_config(&sc.imu).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let imu = ImuErrors::draw(&params, &mut rng);
    let mut it = tr.samples();
    let s0 = it.next().unwrap();
    let mut ins = Strapdown::new(s0.nav_state(), tr.step_s()).unwrap();
    let mut ideal = s0;
    let mut out = Vec::new();
    let k0 = (t0_s / tr.step_s()).round() as usize;
    for (k, s) in it.enumerate().take(k0 + 100) {
        let (f, w) = imu.measure(
            &ideal.specific_force_body_mps2,
            &ideal.ang_rate_ib_body_radps,
            &mut rng,
        );
        ins.step(&f, &w);
        ideal = s;
        if k + 1 > k0 {
            out.push(ins.linearization_point());
        }
    }
    (out, tr.step_s())
}

/// The 100 Hz reference: Φ_T = Π Φ(A_k, T_s), Q_T accumulated with per-step Simpson Q_d.
fn reference(lps: &[LinearizationPoint], step_s: f64, w: &Mat15) -> (Mat15, Mat15) {
    let mut phi = Mat15::identity();
    let mut q = Mat15::zeros();
    for lp in lps {
        let a = error_model::system_matrix(lp);
        let (phi_k, q_k) = error_model::discretize_fast(&a, w, step_s);
        phi = phi_k.to_dense() * phi;
        error_model::propagate_covariance(&mut q, &phi_k, &q_k);
    }
    (phi, q)
}

/// Max over the diagonal of |P_a − P_b| / P_b for P = Φ P0 Φᵀ + Q with the paper's P0: the
/// error of the variances the filter would predict with.
fn variance_error(pa: (&Mat15, &Mat15), pb: (&Mat15, &Mat15), p0: &Mat15) -> f64 {
    let va = pa.0 * p0 * pa.0.transpose() + pa.1;
    let vb = pb.0 * p0 * pb.0.transpose() + pb.1;
    (0..15)
        .map(|i| ((va[(i, i)] - vb[(i, i)]) / vb[(i, i)]).abs())
        .fold(0.0, f64::max)
}

#[test]
fn averaged_subintervals_match_the_100hz_product() {
    let sc = Scenario::paper_default();
    // P0 large enough that Φ matters: the open-loop covariance after ~100 s.
    let mut p0 = Mat15::zeros();
    let sig = [30.0, 0.5, 1e-3, 0.03, 1e-5];
    for b in 0..5 {
        for i in 0..3 {
            p0[(3 * b + i, 3 * b + i)] = sig[b] * sig[b];
        }
    }
    let psd = [
        sc.imu.accel_noise_var_per_sample_mg2 * 9.806_65e-3f64.powi(2) * 0.01,
        sc.imu.gyro_noise_var_per_sample_degph2
            * (std::f64::consts::PI / 180.0 / 3600.0).powi(2)
            * 0.01,
        1e-9,
        1e-16,
    ];
    // Intervals inside a turn (t = 60 s), across a segment boundary (t = 79.5 s → 80 s) and
    // in a climb (t = 170 s).
    for t0 in [60.0, 79.5, 170.0] {
        let (lps, step_s) = points(t0);
        assert_eq!(lps.len(), 100);
        let mut errs = Vec::new();
        for m in [1usize, 2, 5, 10] {
            let mut model = IntervalModel::new(100, m, step_s, psd);
            let (phi_r, q_r) = reference(&lps, step_s, model.noise_density());
            for lp in &lps {
                model.push(lp);
            }
            assert_eq!(model.steps_done(), 100);
            let (phi, q) = model.take();
            let phi_err = (phi - phi_r).abs().max() / phi_r.abs().max();
            let q_err = (0..15)
                .map(|i| ((q[(i, i)] - q_r[(i, i)]) / q_r[(i, i)]).abs())
                .fold(0.0, f64::max);
            let var_err = variance_error((&phi, &q), (&phi_r, &q_r), &p0);
            // Φ error in units of the states' σ: |ΔΦ_ij| σ_j / σ_i (what one prediction of
            // x̂ = Φ x̂ gets wrong, relative to the states' spread).
            let mut phi_scaled = 0.0f64;
            for i in 0..15 {
                for j in 0..15 {
                    let d = (phi - phi_r)[(i, j)].abs() * sig[j / 3] / sig[i / 3];
                    phi_scaled = phi_scaled.max(d);
                }
            }
            println!(
                "t0 = {t0} s, m = {m:2}: max|ΔΦ|/max|Φ| = {phi_err:.2e}, scaled ΔΦ = {phi_scaled:.2e}, max rel ΔQ_ii = {q_err:.2e}, max rel Δvar = {var_err:.2e}"
            );
            errs.push(phi_scaled);
            // Every m: the filter-relevant errors are far below anything that matters (the
            // default in configs/paper.toml is m = 2).
            assert!(
                phi_scaled < 1e-5,
                "m = {m} at t0 = {t0}: scaled Φ {phi_scaled:e}"
            );
            assert!(var_err < 1e-6, "m = {m} at t0 = {t0}: variance {var_err:e}");
            assert!(q_err < 1e-4, "m = {m} at t0 = {t0}: Q {q_err:e}");
            // The model restarts cleanly after take().
            assert_eq!(model.steps_done(), 0);
        }
        // Refining the sub-intervals improves Φ (m = 10 against m = 1).
        assert!(errs[3] < errs[0], "{errs:?}");
    }
}

#[test]
fn dense_and_block_transitions_agree() {
    // The model's Φ_T keeps the block form: bias rows [0 I], ψ rows free of δp, δv, ∇.
    let (lps, step_s) = points(40.0);
    let mut model = IntervalModel::new(100, 10, step_s, [1e-6, 1e-13, 0.0, 0.0]);
    for lp in &lps {
        model.push(lp);
    }
    let (phi, _) = model.take();
    let back = Transition::from_dense(&phi).to_dense();
    assert_eq!(phi, back);
    for i in 9..15 {
        for j in 0..15 {
            assert_eq!(phi[(i, j)], if i == j { 1.0 } else { 0.0 });
        }
    }
    for i in 6..9 {
        for j in (0..6).chain(9..12) {
            assert_eq!(phi[(i, j)], 0.0);
        }
    }
}

#[test]
fn propagated_covariance_matches_the_standalone_monte_carlo_spread() {
    use ins_sim::{Mode, Sample, run, run_seed};
    // Stand-alone INS, 150 s: the spread of 200 seeded runs against the covariance propagated
    // through the interval model (1 s steps, true sensor statistics, P0 = bias and drift σ only:
    // the INS starts at the truth). Checks the error model, its averaging and the noise
    // conversion together against the nonlinear simulation.
    let t_end = 150usize;
    let sc = Scenario::paper_default().truncated(t_end as f64).unwrap();
    let runs = 200u64;
    let mut sum2 = [0.0f64; 9];
    let mut out = vec![Sample::default(); sc.samples_per_run()];
    for i in 0..runs {
        run(&sc, Mode::Standalone, run_seed(99, i), &mut out).unwrap();
        let s = out[t_end];
        for k in 0..3 {
            sum2[k] += s.pos_err_ned_m[k].powi(2);
            sum2[3 + k] += s.vel_err_ned_mps[k].powi(2);
            sum2[6 + k] += s.misalignment_rad[k].powi(2);
        }
    }
    // Covariance along the error-free INS (its linearisation points are those of any run to
    // first order).
    let tr = Trajectory::new(&sc.trajectory).unwrap();
    let step_s = tr.step_s();
    let params = ImuErrorParams::from_config(&sc.imu).unwrap();
    let psd = {
        let e = ImuErrors::draw(&params, &mut ChaCha8Rng::seed_from_u64(0));
        let (qa, qg) = e.noise_psd(step_s);
        [qa, qg, 0.0, 0.0]
    };
    let mut it = tr.samples();
    let s0 = it.next().unwrap();
    let mut ins = Strapdown::new(s0.nav_state(), step_s).unwrap();
    let mut p = Mat15::zeros();
    for i in 0..3 {
        p[(9 + i, 9 + i)] = params.accel_bias_sigma_mps2.powi(2);
        p[(12 + i, 12 + i)] = params.gyro_drift_sigma_radps.powi(2);
    }
    let mut model = IntervalModel::new(100, 2, step_s, psd);
    let mut ideal = s0;
    for (k, s) in it.enumerate() {
        ins.step(
            &ideal.specific_force_body_mps2,
            &ideal.ang_rate_ib_body_radps,
        );
        ideal = s;
        model.push(&ins.linearization_point());
        if (k + 1) % 100 == 0 {
            let (phi, q) = model.take();
            p = phi * p * phi.transpose() + q;
        }
    }
    let names = [
        "δp_N", "δp_E", "δp_D", "δv_N", "δv_E", "δv_D", "ψ_N", "ψ_E", "ψ_D",
    ];
    for k in 0..9 {
        let sample = sum2[k] / runs as f64;
        let ratio = sample / p[(k, k)];
        println!(
            "t = {t_end} s {}: MC σ = {:.3e}, model σ = {:.3e}, ratio of variances {ratio:.3}",
            names[k],
            sample.sqrt(),
            p[(k, k)].sqrt()
        );
        // 200 runs: the sample variance has ≈ 10 % relative σ; band ±30 %.
        assert!((0.7..1.3).contains(&ratio), "{}: ratio {ratio}", names[k]);
    }
}
