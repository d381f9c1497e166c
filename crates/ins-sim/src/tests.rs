//! Unit tests that need the loop's internals (feedback invariance).

use super::engine::{Loop, nav_state};
use super::{Mode, Scenario};
use ins_errors::trajectory::Trajectory;

/// Runs `mode` open loop for `seconds` SD intervals and returns the loop and the last truth.
fn open_loop(mode: Mode, seconds: usize) -> (Loop, ins_errors::strapdown::NavState) {
    let mut sc = Scenario::paper_default().truncated(60.0).unwrap();
    sc.filter.open_loop_until_s = 1e9;
    let plan = sc.plan().unwrap();
    let tr = Trajectory::new(&sc.trajectory).unwrap();
    let mut it = tr.samples();
    let first = it.next().unwrap();
    let mut lp = Loop::new(&sc, mode, 11, &first).unwrap();
    let mut ideal = first;
    let mut truth = nav_state(&first);
    for k in 1..=seconds * plan.steps_per_update {
        let s = it.next().unwrap();
        lp.step(&ideal).unwrap();
        ideal = s;
        truth = nav_state(&s);
        if k % plan.steps_per_update == 0 {
            lp.sd_update(k as f64 * plan.step_s, &truth).unwrap();
        }
    }
    (lp, truth)
}

#[test]
fn feedback_reset_keeps_ins_minus_estimate_invariant() {
    for mode in [Mode::Kf, Mode::Akf] {
        let (mut lp, truth) = open_loop(mode, 40);
        let x = lp.filter_state();
        // After 40 s open loop the INS error and the estimate are both far from zero.
        let e_before = lp.true_error(&truth);
        assert!(e_before.fixed_rows::<3>(0).norm() > 1.0, "{e_before}");
        assert!(x.fixed_rows::<3>(0).norm() > 1.0, "{x}");
        let p_before = *lp.filter_covariance().unwrap();
        let net_before = e_before - x;
        lp.feedback();
        let e_after = lp.true_error(&truth);
        let x_after = lp.filter_state();
        assert_eq!(x_after, nalgebra::SVector::<f64, 15>::zeros());
        assert_eq!(*lp.filter_covariance().unwrap(), p_before, "P must be kept");
        let net_after = e_after - x_after;
        let d = net_after - net_before;
        // The reset is exact to first order; the remainder is bounded by second-order
        // products of the errors and the corrections: ψ by |ψ||ψ̂| (composition of two
        // rotations), δv by |δv̂||φ̂| + |δv||ψ̂| (velocity rotated into the corrected frame), δp by
        // |δp|²/R (local-level displacement).
        let n = |v: &nalgebra::SVector<f64, 15>, i: usize| v.fixed_rows::<3>(i).norm();
        let r_m = 6.37e6;
        let psi_bound = 2.0 * n(&e_before, 6) * n(&x, 6) + 1e-12;
        let vel_bound = 2.0 * (n(&e_before, 3) + n(&x, 3)) * (n(&x, 6) + n(&x, 0) / r_m) + 1e-9;
        let pos_bound = 4.0 * (n(&e_before, 0) + n(&x, 0)).powi(2) / r_m + 1e-6;
        println!(
            "{}: |δp| {:.1} m, |x̂_p| {:.1} m, |ψ| {:.2e}, |ψ̂| {:.2e}; change δp {:.2e} (bound {:.1e}), δv {:.2e} (bound {:.1e}), ψ {:.2e} (bound {:.1e})",
            mode.name(),
            n(&e_before, 0),
            n(&x, 0),
            n(&e_before, 6),
            n(&x, 6),
            n(&d, 0),
            pos_bound,
            n(&d, 3),
            vel_bound,
            n(&d, 6),
            psi_bound
        );
        assert!(n(&d, 0) < pos_bound);
        assert!(n(&d, 3) < vel_bound);
        assert!(n(&d, 6) < psi_bound);
        for i in 0..3 {
            // The bias/drift corrections are exactly additive.
            assert!(d[9 + i].abs() < 1e-15, "∇[{i}] changed by {}", d[9 + i]);
            assert!(d[12 + i].abs() < 1e-18, "ε[{i}] changed by {}", d[12 + i]);
        }
        // And the correction did something: the INS error itself changed by x.
        assert!((e_after - e_before).fixed_rows::<3>(0).norm() > 1.0);
    }
}
