//! Whole runs of the INS/SD loop: stand-alone equals `ins-errors`'s stand-alone INS, perfect
//! sensors stay at zero error, the KF bounds the error far below stand-alone, bad runs fail
//! with typed errors, and the KF is consistent (NEES/NIS) within a documented loose band.
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use ins_errors::config::BiasModel;
use ins_errors::error_model;
use ins_errors::imu::{ImuErrorParams, ImuErrors};
use ins_errors::strapdown::Strapdown;
use ins_errors::trajectory::Trajectory;
use ins_sim::{Mode, Sample, Scenario, SimError, run, run_seed};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

fn norm3(v: [f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

fn run_once(sc: &Scenario, mode: Mode, seed: u64) -> Vec<Sample> {
    let mut out = vec![Sample::default(); sc.samples_per_run()];
    let o = run(sc, mode, seed, &mut out).unwrap();
    assert_eq!(o.samples_written, out.len());
    assert_eq!(o.steps as f64, sc.duration_s() / sc.trajectory.step_s);
    out
}

/// The reference stand-alone INS written directly on `ins-errors` (as its own bench does):
/// the errors at every whole second.
fn reference_standalone(sc: &Scenario, seed: u64) -> Vec<[f64; 9]> {
    let tr = Trajectory::new(&sc.trajectory).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let imu = ImuErrors::draw(&ImuErrorParams::from_config(&sc.imu).unwrap(), &mut rng);
    let mut it = tr.samples();
    let s0 = it.next().unwrap();
    let nav = |s: &ins_errors::trajectory::TruthSample| s.nav_state();
    let mut ins = Strapdown::new(nav(&s0), tr.step_s()).unwrap();
    let mut ideal = s0;
    let e0 = error_model::error_state(&nav(&s0), ins.state());
    let mut out = vec![std::array::from_fn(|i| e0[i])];
    for (k, s) in it.enumerate() {
        let (f, w) = imu.measure(
            &ideal.specific_force_body_mps2,
            &ideal.ang_rate_ib_body_radps,
            &mut rng,
        );
        ins.step(&f, &w);
        ideal = s;
        if (k + 1) % 100 == 0 {
            let e = error_model::error_state(&nav(&s), ins.state());
            out.push(std::array::from_fn(|i| e[i]));
        }
    }
    out
}

#[test]
fn standalone_equals_the_ins_errors_standalone_run() {
    let sc = Scenario::paper_default().truncated(120.0).unwrap();
    for index in 0..2 {
        let seed = run_seed(sc.monte_carlo.seed, index);
        let ours = run_once(&sc, Mode::Standalone, seed);
        let reference = reference_standalone(&sc, seed);
        assert_eq!(ours.len(), reference.len());
        for (s, r) in ours.iter().zip(&reference) {
            assert_eq!(s.pos_err_ned_m, [r[0], r[1], r[2]], "t = {}", s.t_s);
            assert_eq!(s.vel_err_ned_mps, [r[3], r[4], r[5]], "t = {}", s.t_s);
            assert_eq!(s.misalignment_rad, [r[6], r[7], r[8]], "t = {}", s.t_s);
            assert!(s.nees.is_none() && s.nis.is_none());
        }
        // The errors are real (sensor errors were drawn): hundreds of metres after 120 s.
        assert!(norm3(ours[120].pos_err_ned_m) > 20.0, "{:?}", ours[120]);
    }
}

#[test]
fn records_time_and_distance() {
    let sc = Scenario::paper_default().truncated(30.0).unwrap();
    let out = run_once(&sc, Mode::Kf, 3);
    for (i, s) in out.iter().enumerate() {
        assert_eq!(s.t_s, i as f64);
    }
    // 30 m/s start speed, first segment straight at constant speed.
    assert!(
        (out[30].distance_m - 900.0).abs() < 1.0,
        "{}",
        out[30].distance_m
    );
    assert!(out[0].nis.is_none());
    assert!(out[1..].iter().all(|s| s.nis.is_some() && s.nees.is_some()));
}

#[test]
fn same_seed_same_run_and_modes_share_the_draw() {
    let sc = Scenario::paper_default().truncated(20.0).unwrap();
    let a = run_once(&sc, Mode::Akf, 77);
    let b = run_once(&sc, Mode::Akf, 77);
    assert_eq!(a, b);
    let c = run_once(&sc, Mode::Akf, 78);
    assert_ne!(a[20], c[20]);
}

fn perfect(mut sc: Scenario) -> Scenario {
    sc.imu.accel_bias_sigma_mg = 0.0;
    sc.imu.gyro_drift_sigma_degph = 0.0;
    sc.imu.accel_noise_var_per_sample_mg2 = 0.0;
    sc.imu.gyro_noise_var_per_sample_degph2 = 0.0;
    sc.imu.bias_model = BiasModel::GaussianRandomConstant;
    sc.sighting.noise_var_m2 = 0.0;
    sc
}

#[test]
fn perfect_sensors_and_noise_free_sd_keep_the_errors_near_zero() {
    // 260 s: open loop, the switch at 195 s, then feedback.
    let sc = perfect(Scenario::paper_default().truncated(260.0).unwrap());
    for mode in [Mode::Kf, Mode::Akf] {
        let out = run_once(&sc, mode, 1);
        for s in &out {
            // Mechanization error of the perfect INS is millimetres; the filter must not add
            // anything beyond the linearisation residual.
            assert!(
                norm3(s.pos_err_ned_m) < 0.05,
                "{} t = {}: {:?}",
                mode.name(),
                s.t_s,
                s.pos_err_ned_m
            );
            assert!(
                norm3(s.vel_err_ned_mps) < 1e-3,
                "{} t = {}: {:?}",
                mode.name(),
                s.t_s,
                s.vel_err_ned_mps
            );
            assert!(
                norm3(s.misalignment_rad) < 1e-6,
                "{} t = {}: {:?}",
                mode.name(),
                s.t_s,
                s.misalignment_rad
            );
        }
    }
}

#[test]
fn kf_bounds_the_position_error_far_below_standalone() {
    let sc = Scenario::paper_default();
    for index in 0..3 {
        let seed = run_seed(sc.monte_carlo.seed, index);
        let alone = run_once(&sc, Mode::Standalone, seed);
        let kf = run_once(&sc, Mode::Kf, seed);
        let e_alone = norm3(alone[900].pos_err_ned_m);
        let e_kf = norm3(kf[900].pos_err_ned_m);
        let worst_kf_after_switch = kf[200..]
            .iter()
            .map(|s| norm3(s.pos_err_ned_m))
            .fold(0.0, f64::max);
        println!(
            "run {index}: |δp(900 s)| stand-alone {e_alone:.0} m, KF {e_kf:.2} m (max after 200 s {worst_kf_after_switch:.2} m)"
        );
        // Stand-alone diverges to kilometres (vertical channel); the KF stays within tens of
        // metres throughout (paper: ≈ 100 m at 900 s).
        assert!(e_alone > 1000.0, "{e_alone}");
        assert!(worst_kf_after_switch < 50.0, "{worst_kf_after_switch}");
        assert!(e_kf < e_alone / 100.0);
        // Azimuth misalignment stays bounded after the manoeuvres stop (600 s).
        assert!(
            kf[900].misalignment_rad[2].abs() < 1e-3,
            "{:?}",
            kf[900].misalignment_rad
        );
    }
}

#[test]
fn kf_nees_and_nis_are_consistent_within_a_loose_band() {
    // 20 runs of 260 s (open loop to 195 s, then feedback). Averages over all runs and over
    // the SD epochs t ≥ 30 s (after the first transients).
    let sc = Scenario::paper_default().truncated(260.0).unwrap();
    let runs = 20;
    let (mut nees, mut nis, mut n) = (0.0, 0.0, 0usize);
    let (mut nees_fb, mut n_fb) = (0.0, 0usize);
    for index in 0..runs {
        let out = run_once(&sc, Mode::Kf, run_seed(sc.monte_carlo.seed, index));
        for s in &out[30..] {
            nees += s.nees.unwrap();
            nis += s.nis.unwrap();
            n += 1;
            if s.t_s >= 200.0 {
                nees_fb += s.nees.unwrap();
                n_fb += 1;
            }
        }
    }
    let (nees, nis, nees_fb) = (nees / n as f64, nis / n as f64, nees_fb / n_fb as f64);
    // Per-epoch 95 % bands of the average over 20 runs would be NEES [12.9, 17.3] and NIS
    // [4.6, 7.6] (akf::average_band); averaging over epochs as well narrows them, but the
    // epochs are strongly correlated. Documented loose band: ±25 % around n and m.
    println!(
        "KF over {runs} runs × {} epochs: mean NEES {nees:.2} (n = 15), after feedback {nees_fb:.2}; mean NIS {nis:.2} (m = 6)",
        n / runs as usize
    );
    let band = akf::average_band(15, runs as usize, 0.95).unwrap();
    println!(
        "  95 % per-epoch band for the 20-run average: NEES {band:?}, NIS {:?}",
        akf::average_band(6, runs as usize, 0.95).unwrap()
    );
    assert!((11.25..=18.75).contains(&nees), "NEES {nees}");
    assert!(
        (11.25..=18.75).contains(&nees_fb),
        "NEES after feedback {nees_fb}"
    );
    assert!((4.5..=7.5).contains(&nis), "NIS {nis}");
}

#[test]
fn akf_nees_and_nis_are_reported() {
    let sc = Scenario::paper_default().truncated(260.0).unwrap();
    let runs = 5;
    let (mut nees, mut nis, mut n) = (0.0, 0.0, 0usize);
    for index in 0..runs {
        let out = run_once(&sc, Mode::Akf, run_seed(sc.monte_carlo.seed, index));
        for s in &out[30..] {
            nees += s.nees.unwrap();
            nis += s.nis.unwrap();
            n += 1;
        }
    }
    let (nees, nis) = (nees / n as f64, nis / n as f64);
    println!("AKF over {runs} runs: mean NEES {nees:.2} (n = 15), mean NIS {nis:.2} (m = 6)");
    // Documented behaviour of the Mohamed–Schwarz AKF here (module doc; default diagonal
    // projection): its Q̂ over-estimates the process noise, so it is under-confident: NEES well
    // below 15 (≈ 6.4 over 100 runs) and NIS at or below 6 (≈ 5.3), yet not collapsed to zero.
    assert!((3.0..12.0).contains(&nees), "AKF NEES {nees}");
    assert!((3.5..6.5).contains(&nis), "AKF NIS {nis}");
}

#[test]
fn wrong_buffer_length_is_an_error() {
    let sc = Scenario::paper_default().truncated(10.0).unwrap();
    let mut out = vec![Sample::default(); 10];
    match run(&sc, Mode::Kf, 1, &mut out) {
        Err(SimError::OutputLength {
            expected: 11,
            got: 10,
        }) => {}
        other => panic!("{other:?}"),
    }
}

#[test]
fn exploding_sensors_give_non_finite_with_time_or_a_sighting_error() {
    let mut sc = Scenario::paper_default().truncated(60.0).unwrap();
    sc.imu.accel_bias_sigma_mg = 1e300; // finite, but the velocity overflows
    sc.imu.bias_model = BiasModel::FixedMagnitudeRandomSign;
    let mut out = vec![Sample::default(); sc.samples_per_run()];
    // Every mode runs the INS through the online filter, which refuses the first implausible
    // IMU sample (an infinite specific force) before mechanising it: detected within the first
    // steps, not at a 1 s record epoch.
    match run(&sc, Mode::Standalone, 1, &mut out) {
        Err(SimError::NonFinite { t_s, what }) => {
            assert!(t_s > 0.0 && t_s < 0.1, "{t_s}");
            assert!(what.contains("INS"));
        }
        Err(SimError::Online {
            source: ins_sd_filter::FilterError::ImplausibleImu { t_s, .. },
            ..
        }) => assert!(t_s > 0.0 && t_s < 0.1, "{t_s}"),
        other => panic!("expected a typed failure at the first steps, got {other:?}"),
    }
    // The filter modes go through the online filter, which refuses the first implausible IMU
    // sample (an infinite specific force) before mechanising it.
    match run(&sc, Mode::Kf, 1, &mut out) {
        Err(SimError::NonFinite { t_s, .. }) => assert!(t_s > 0.0 && t_s < 0.1, "{t_s}"),
        Err(SimError::Online {
            source: ins_sd_filter::FilterError::ImplausibleImu { t_s, .. },
            ..
        }) => assert!(t_s > 0.0 && t_s < 0.1, "{t_s}"),
        other => panic!("expected a typed failure, got {other:?}"),
    }
}

#[test]
fn akf_equals_kf_until_its_window_fills_then_adapts() {
    // Same seed → same truth, IMU and SD noise (common random numbers). The AKF predicts with
    // the KF's a-priori Q until N = 10 updates have filled its window, so both filters are
    // identical up to t = 10 s; from the 11th update on it uses Q̂ and departs.
    let sc = Scenario::paper_default().truncated(30.0).unwrap();
    assert_eq!(sc.filter.akf_window, 10);
    let seed = run_seed(sc.monte_carlo.seed, 4);
    let kf = run_once(&sc, Mode::Kf, seed);
    let akf = run_once(&sc, Mode::Akf, seed);
    for t in 0..=10 {
        assert_eq!(kf[t], akf[t], "t = {t}");
    }
    for t in 11..=30 {
        assert_ne!(kf[t].pos_err_ned_m, akf[t].pos_err_ned_m, "t = {t}");
        assert_ne!(kf[t].nis, akf[t].nis, "t = {t}");
    }
    // The truth is shared: same distance flown.
    assert_eq!(kf[30].distance_m, akf[30].distance_m);
}

/// Peak 3-D position error (m) and peak |azimuth misalignment| (mrad) from 600 s to the end.
fn peaks_after_600_s(out: &[Sample]) -> (f64, f64) {
    out.iter()
        .filter(|s| s.t_s >= 600.0)
        .fold((0.0, 0.0), |(p, a), s| {
            (
                f64::max(p, norm3(s.pos_err_ned_m)),
                f64::max(a, s.misalignment_rad[2].abs() * 1e3),
            )
        })
}

/// The default AKF (diagonal projection of Q̂) stays bounded through the 650–900 s window where
/// the eigenvalue-clipping projection blew up in the 100-run Monte Carlo (seed 2009: runs 96, 31
/// and 74 peaked at 6.8, 6.4 and 6.0 km around 790–810 s). Same runs, both projections: the
/// default stays below 0.5 km and 5 mrad of azimuth; eigen_clip on the same draws goes above
/// 1 km on at least one of them, so this test tells the two apart.
#[test]
fn default_akf_stays_bounded_where_eigen_clip_blows_up() {
    let sc = Scenario::paper_default();
    assert_eq!(sc.filter.akf_projection, akf::QProjection::Diagonal);
    let mut clip = sc.clone();
    clip.filter.akf_projection = akf::QProjection::EigenClip;
    let mut clip_worst = 0.0_f64;
    for index in [96, 31, 74] {
        let seed = run_seed(sc.monte_carlo.seed, index);
        let (pos_m, az_mrad) = peaks_after_600_s(&run_once(&sc, Mode::Akf, seed));
        println!("run {index}: diagonal peak {pos_m:.1} m, azimuth {az_mrad:.3} mrad");
        assert!(
            pos_m < 500.0,
            "run {index}: diagonal AKF peak {pos_m} m after 600 s"
        );
        assert!(
            az_mrad < 5.0,
            "run {index}: diagonal AKF azimuth {az_mrad} mrad after 600 s"
        );
        let (clip_m, clip_az) = peaks_after_600_s(&run_once(&clip, Mode::Akf, seed));
        println!("run {index}: eigen_clip peak {clip_m:.1} m, azimuth {clip_az:.3} mrad");
        clip_worst = clip_worst.max(clip_m);
    }
    assert!(
        clip_worst > 1000.0,
        "eigen_clip worst peak {clip_worst} m: no blow-up to guard against"
    );
}

#[test]
fn adaptive_alternatives_share_the_flight_and_equal_the_kf_until_warm() {
    // Sage–Husa (warm-up = akf_window) and the structured Mohamed–Schwarz use the a-priori Q
    // until their estimate exists (10 updates): identical to the KF to t = 10 s (common random
    // numbers), different afterwards.
    let sc = Scenario::paper_default().truncated(20.0).unwrap();
    let seed = run_seed(sc.monte_carlo.seed, 2);
    let kf = run_once(&sc, Mode::Kf, seed);
    for mode in [Mode::AkfSageHusa, Mode::AkfStructured] {
        let a = run_once(&sc, mode, seed);
        for t in 0..=10 {
            assert_eq!(kf[t], a[t], "{} t = {t}", mode.name());
        }
        assert_ne!(kf[15].pos_err_ned_m, a[15].pos_err_ned_m, "{}", mode.name());
        assert_eq!(kf[20].distance_m, a[20].distance_m);
    }
}
