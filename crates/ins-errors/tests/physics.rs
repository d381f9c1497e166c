//! Stand-alone INS physics: Schuler period and vertical-channel divergence at the paper's
//! start point (−23°12′, 6000 m).
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use ins_errors::earth::{self, Geodetic};
use ins_errors::error_model::{error_state, inject_errors, system_matrix};
use ins_errors::strapdown::{LinearizationPoint, NavState, Strapdown};
use nalgebra::{Matrix3, SMatrix, UnitQuaternion, Vector3};

fn start() -> Geodetic {
    Geodetic::from_deg(-23.2, -(45.0 + 52.0 / 60.0), 6000.0)
}

/// Truth at rest (hovering) and its ideal IMU output: f_b = −g, ω_ib = Ω (body = NED).
fn at_rest() -> (NavState, Vector3<f64>, Vector3<f64>) {
    let p = start();
    let truth = NavState {
        pos: p,
        vel_ned_mps: Vector3::zeros(),
        att_b_to_n: UnitQuaternion::identity(),
    };
    (
        truth,
        -earth::gravity_ned_mps2(p.lat_rad, p.alt_m),
        earth::earth_rate_ned_radps(p.lat_rad),
    )
}

/// Eigenvalues of A's navigation block (δp, δv, ψ) at rest: a pair ±i(ω_s ± Ω sinL)
/// (Schuler, Foucault-split) with mean period 84.6 min, and one real unstable root 1/τ with
/// τ ≈ 571 s.
#[test]
fn eigenvalues_at_rest_give_schuler_and_vertical_time_constant() {
    let p = start();
    let lp = LinearizationPoint {
        pos: p,
        vel_ned_mps: Vector3::zeros(),
        specific_force_ned_mps2: -earth::gravity_ned_mps2(p.lat_rad, p.alt_m),
        c_b_to_n: Matrix3::identity(),
    };
    let a = system_matrix(&lp);
    let a9: SMatrix<f64, 9, 9> = a.fixed_view::<9, 9>(0, 0).into_owned();
    let ev = a9.complex_eigenvalues();
    let mut schuler: Vec<f64> = ev.iter().filter(|z| z.im > 1.0e-3).map(|z| z.im).collect();
    schuler.sort_by(f64::total_cmp);
    assert_eq!(schuler.len(), 2, "{ev:?}");
    let mean = 0.5 * (schuler[0] + schuler[1]);
    let period_min = 2.0 * std::f64::consts::PI / mean / 60.0;
    println!(
        "Schuler period {period_min:.2} min, Foucault split {:.3e} rad/s",
        schuler[1] - schuler[0]
    );
    assert!(
        (period_min - 84.6).abs() < 0.3,
        "Schuler period {period_min} min"
    );
    // Independent prediction 2π√(R/g), R = √(R_N R_E) + h (≈ 84.55 min here).
    let (r_n, r_e) = earth::radii_of_curvature_m(p.lat_rad);
    let r = (r_n * r_e).sqrt() + p.alt_m;
    let predicted_min =
        2.0 * std::f64::consts::PI * (r / earth::normal_gravity_mps2(p.lat_rad, p.alt_m)).sqrt()
            / 60.0;
    assert!(
        (period_min / predicted_min - 1.0).abs() < 2e-3,
        "{period_min} vs {predicted_min}"
    );
    let split = schuler[1] - schuler[0];
    let foucault = 2.0 * earth::EARTH_RATE_RADPS * p.lat_rad.sin().abs();
    assert!(
        (split / foucault - 1.0).abs() < 0.02,
        "split {split} vs 2Ω sinL {foucault}"
    );
    let lambda = ev.iter().map(|z| z.re).fold(f64::MIN, f64::max);
    let tau = 1.0 / lambda;
    println!("vertical time constant {tau:.1} s");
    assert!((tau - 571.0).abs() < 3.0, "tau {tau}");
}

/// Nonlinear stationary INS with an initial north velocity error of 0.1 m/s: δv_N oscillates
/// with the Schuler period (zero crossings T/2 apart).
#[test]
fn nonlinear_stationary_ins_oscillates_with_schuler_period() {
    let (truth, f_b, w_b) = at_rest();
    let ts = 0.01;
    let init = inject_errors(
        &truth,
        &Vector3::zeros(),
        &Vector3::new(0.1, 0.0, 0.0),
        &Vector3::zeros(),
    );
    let mut ins = Strapdown::new(init, ts).unwrap();
    let mut crossings = Vec::new();
    let mut prev = 0.1;
    let n = (6000.0 / ts) as usize;
    for _ in 0..n {
        ins.step(&f_b, &w_b);
        let dvn = error_state(&truth, ins.state())[3];
        if prev > 0.0 && dvn <= 0.0 || prev < 0.0 && dvn >= 0.0 {
            // Linear interpolation of the crossing time.
            let t = ins.time_s() - ts * dvn / (dvn - prev);
            crossings.push(t);
        }
        prev = dvn;
    }
    assert!(crossings.len() >= 2, "{crossings:?}");
    let period_min = 2.0 * (crossings[1] - crossings[0]) / 60.0;
    println!("crossings {crossings:?}: Schuler period {period_min:.2} min");
    assert!((period_min - 84.6).abs() < 0.5, "period {period_min} min");
}

/// Nonlinear stationary INS with +1 m altitude error: δh(t) = cosh(t/τ) for the unstable
/// vertical channel, τ = 1/√(−∂γ/∂h) ≈ 571 s; after 900 s the error is ≈ 2.5 m.
#[test]
fn nonlinear_vertical_channel_diverges_with_571_s_time_constant() {
    let (truth, f_b, w_b) = at_rest();
    let ts = 0.01;
    let init = inject_errors(
        &truth,
        &Vector3::new(0.0, 0.0, -1.0),
        &Vector3::zeros(),
        &Vector3::zeros(),
    );
    let mut ins = Strapdown::new(init, ts).unwrap();
    for _ in 0..90_000 {
        ins.step(&f_b, &w_b);
    }
    let dh = -error_state(&truth, ins.state())[2];
    let tau_fit = 900.0 / dh.acosh();
    let (_, dg_dh) = earth::normal_gravity_partials(truth.pos.lat_rad, truth.pos.alt_m);
    let tau_model = 1.0 / (-dg_dh).sqrt();
    println!("dh(900 s) = {dh:.4} m, fitted tau {tau_fit:.1} s, model tau {tau_model:.1} s");
    assert!(
        (dh - (900.0 / tau_model).cosh()).abs() < 0.01 * dh,
        "dh {dh}"
    );
    assert!((tau_fit - 571.0).abs() < 3.0, "tau {tau_fit}");
}
