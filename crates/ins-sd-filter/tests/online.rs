//! The online filter driven sample by sample on the paper's flight (first 60 s) with 0, 1, 2 and
//! 5 landmarks in the table, an outlier the χ² gate rejects, the batch update against
//! one-landmark-at-a-time updates (an independent form of the same estimate), the typed errors
//! and the increment/rate forms of the IMU input.
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use akf::{AdaptiveQConfig, QProjection};
use ins_errors::config::{ImuConfig, TrajectoryConfig};
use ins_errors::imu::{ImuErrorParams, ImuErrors};
use ins_errors::strapdown::NavState;
use ins_errors::trajectory::Trajectory;
use ins_sd_filter::{
    ErrorSigmas, ErrorStateEstimator, FilterError, InsSdFilter, InsSdFilterConfig, LandmarkEntry,
    LandmarkTable, LosFrame, MeasurementJacobian, PointedSighting, ProcessNoisePsd, Sighting,
    nav_pose,
};
use nalgebra::Vector3;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

/// Five landmarks around the start of the paper's flight (the first three are the paper's).
const LANDMARKS: [(f64, f64, f64); 5] = [
    (-23.29, -45.80, 20.0),
    (-23.20, -45.85, 10.0),
    (-23.25, -45.89, 30.0),
    (-23.15, -45.95, 50.0),
    (-23.30, -45.95, 0.0),
];

fn table(n: usize) -> LandmarkTable {
    let entries: Vec<LandmarkEntry> = LANDMARKS[..n]
        .iter()
        .enumerate()
        .map(|(i, &(lat_deg, lon_deg, alt_m))| LandmarkEntry {
            id: 10 + i as u32,
            lat_deg,
            lon_deg,
            alt_m,
        })
        .collect();
    LandmarkTable::new(&entries).unwrap()
}

fn config(estimator: ErrorStateEstimator, gate: Option<f64>) -> InsSdFilterConfig {
    let mg = ins_errors::imu::MG_TO_MPS2;
    let degph = ins_errors::imu::DEGPH_TO_RADPS;
    InsSdFilterConfig {
        imu_step_s: 0.01,
        timestamp_tolerance_s: 1e-8,
        update_period_s: 1.0,
        phi_subintervals: 2,
        p0_sigma: ErrorSigmas {
            pos_m: 1.0,
            vel_mps: 0.1,
            psi_rad: 1e-3,
            accel_bias_mps2: 3.0 * mg,
            gyro_drift_radps: 2.0 * degph,
        },
        process_noise: ProcessNoisePsd {
            accel_white_m2ps3: 2.0 * mg * mg * 0.01,
            gyro_white_rad2ps: 2.0 * degph * degph * 0.01,
            accel_bias_rw_m2ps5: 0.0,
            gyro_drift_rw_rad2ps3: 0.0,
        },
        r_var_m2: 40.0,
        open_loop_until_s: 20.0,
        gate_probability: gate,
        estimator,
        jacobian: MeasurementJacobian::Verified,
    }
}

/// Runs `seconds` of the paper's flight through the filter with the first `n` landmarks
/// sighted every second (noise σ = √40 m), `tamper` may change the sightings of an epoch.
/// Returns the filter and the final truth.
fn fly(
    cfg: InsSdFilterConfig,
    n: usize,
    seconds: usize,
    tamper: &dyn Fn(usize, &mut Vec<Sighting>),
) -> (InsSdFilter, NavState) {
    fly_with(cfg, n, seconds, tamper, false)
}

/// As [`fly`]; with `pointed`, each epoch's offsets are sent as body directions
/// (`los_from_offsets` at the filter's pointing pose) through `update_pointed`.
fn fly_with(
    cfg: InsSdFilterConfig,
    n: usize,
    seconds: usize,
    tamper: &dyn Fn(usize, &mut Vec<Sighting>),
    pointed: bool,
) -> (InsSdFilter, NavState) {
    let mut tc = TrajectoryConfig::paper();
    tc.end_time_s = seconds as f64;
    // The first segments (straight, then a right turn), cut at `seconds`.
    let mut left = seconds as f64;
    tc.segments.retain_mut(|seg| {
        if left <= 0.0 {
            return false;
        }
        seg.duration_s = seg.duration_s.min(left);
        left -= seg.duration_s;
        true
    });
    let tr = Trajectory::new(&tc).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(42);
    let imu = ImuErrors::draw(
        &ImuErrorParams::from_config(&ImuConfig::paper()).unwrap(),
        &mut rng,
    );
    let mut rng_sd = ChaCha8Rng::seed_from_u64(43);
    let noise = Normal::new(0.0, 40.0_f64.sqrt()).unwrap();
    let mut it = tr.samples();
    let first = it.next().unwrap();
    let tbl = table(n);
    let lms: Vec<_> = tbl.iter().map(|(id, l)| (id, *l)).collect();
    let mut filter = InsSdFilter::new(cfg, tbl, first.nav_state(), 0.0).unwrap();
    let mut ideal = first;
    let mut truth = first.nav_state();
    let mut sightings = Vec::new();
    for (k, s) in it.enumerate() {
        let k = k + 1;
        let (f, w) = imu.measure(
            &ideal.specific_force_body_mps2,
            &ideal.ang_rate_ib_body_radps,
            &mut rng,
        );
        let t = k as f64 * 0.01;
        filter.propagate(t, &(f * 0.01), &(w * 0.01)).unwrap();
        ideal = s;
        truth = s.nav_state();
        if k % 100 == 0 {
            sightings.clear();
            for (id, lm) in &lms {
                let z = sighting_model::sighting_offset_m(
                    &nav_pose(&truth),
                    &filter.pointing_pose(),
                    lm,
                )
                .unwrap();
                sightings.push(Sighting {
                    landmark_id: *id,
                    w_m: z.x + noise.sample(&mut rng_sd),
                    h_m: z.y + noise.sample(&mut rng_sd),
                });
            }
            tamper(k / 100, &mut sightings);
            let report = if pointed {
                let pose = filter.pointing_pose();
                let directions: Vec<PointedSighting> = sightings
                    .iter()
                    .map(|s| PointedSighting {
                        landmark_id: s.landmark_id,
                        frame: LosFrame::Body,
                        los: sighting_model::los_from_offsets(
                            &pose,
                            filter.landmarks().get(s.landmark_id).unwrap(),
                            &nalgebra::Vector2::new(s.w_m, s.h_m),
                        )
                        .unwrap(),
                    })
                    .collect();
                filter.update_pointed(t, &directions).unwrap()
            } else {
                filter.update(t, &sightings).unwrap()
            };
            assert_eq!(report.used + report.rejected, sightings.len());
        }
    }
    (filter, truth)
}

fn pos_error_m(filter: &InsSdFilter, truth: &NavState) -> f64 {
    let e = ins_errors::error_model::error_state(truth, &filter.navigation_solution());
    e.fixed_rows::<3>(0).norm()
}

#[test]
fn zero_one_two_and_five_landmarks() {
    let mut sigma = Vec::new();
    let mut errors = Vec::new();
    for n in [0, 1, 2, 5] {
        let (filter, truth) = fly(
            config(ErrorStateEstimator::Kalman, Some(0.9999)),
            n,
            60,
            &|_, _| {},
        );
        let st = filter.statistics();
        assert_eq!(st.imu_samples, 6000);
        assert_eq!(st.epochs, if n == 0 { 0 } else { 60 });
        assert_eq!(st.sightings_used, 60 * n as u64, "n = {n}");
        let p = filter.predicted().unwrap().1;
        let s = (p[(0, 0)] + p[(1, 1)] + p[(2, 2)]).sqrt();
        let e = pos_error_m(&filter, &truth);
        println!(
            "{n} landmarks: position σ {s:.2} m, error {e:.2} m, rejected {}",
            st.sightings_rejected
        );
        sigma.push(s);
        errors.push(e);
    }
    // No landmark: free INS (P grows from 1.7 m); each landmark added shrinks the predicted σ.
    assert!(sigma[0] > 10.0, "{sigma:?}");
    assert!(
        sigma[1] < sigma[0] && sigma[2] < sigma[1] && sigma[3] < sigma[2],
        "{sigma:?}"
    );
    // The errors are consistent with the σ (within 4σ) and the free INS drifts far more.
    for (e, s) in errors.iter().zip(&sigma) {
        assert!(*e < 4.0 * s, "error {e} vs σ {s}");
    }
    assert!(errors[0] > 5.0 * errors[3], "{errors:?}");
}

#[test]
fn the_gate_rejects_an_outlier_exactly_as_if_it_was_never_sent() {
    let cfg = config(ErrorStateEstimator::Kalman, Some(0.9999));
    // A 300 m gross error on the w offset of landmark 11 at epoch 30 (NIS ≫ 18.4).
    let (gated, _) = fly(cfg, 5, 40, &|epoch, s| {
        if epoch == 30 {
            s[1].w_m += 300.0;
        }
    });
    let (dropped, _) = fly(cfg, 5, 40, &|epoch, s| {
        if epoch == 30 {
            s.remove(1);
        }
    });
    assert_eq!(gated.statistics().sightings_rejected, 1);
    assert_eq!(dropped.statistics().sightings_rejected, 0);
    assert_eq!(gated.error_state(), dropped.error_state());
    assert_eq!(gated.covariance(), dropped.covariance());
    assert_eq!(gated.navigation_solution(), dropped.navigation_solution());
    // Without a gate the outlier goes in and moves the solution.
    let (ungated, _) = fly(
        config(ErrorStateEstimator::Kalman, None),
        5,
        40,
        &|epoch, s| {
            if epoch == 30 {
                s[1].w_m += 300.0;
            }
        },
    );
    let d = ins_errors::error_model::error_state(
        &dropped.navigation_solution(),
        &ungated.navigation_solution(),
    );
    assert!(d.fixed_rows::<3>(0).norm() > 1.0, "{d}");
}

#[test]
fn a_batch_update_equals_one_landmark_at_a_time() {
    // Open loop (no feedback), KF. At 10 s, the same 5 sightings: one update with all five
    // against five updates at the same epoch (each predicts over an empty interval, Φ = I,
    // Q = 0) — the sequential form of the same Bayesian update.
    let mut cfg = config(ErrorStateEstimator::Kalman, None);
    cfg.open_loop_until_s = f64::INFINITY;
    let mut captured = Vec::new();
    let (mut batch, _) = fly(cfg, 5, 10, &|_, _| {});
    let (mut seq, _) = fly(cfg, 5, 10, &|_, _| {});
    assert_eq!(batch.error_state(), seq.error_state());
    // Propagate both one more second with the same perfect IMU sample, then update.
    for k in 1..=100 {
        let t = 10.0 + k as f64 * 0.01;
        let dv = Vector3::new(0.0, 0.0, -9.79 * 0.01);
        for f in [&mut batch, &mut seq] {
            f.propagate(t, &dv, &Vector3::zeros()).unwrap();
        }
    }
    for i in 0..5u32 {
        captured.push(Sighting {
            landmark_id: 10 + i,
            w_m: 3.0 * i as f64 - 4.0,
            h_m: 2.0 - 1.5 * i as f64,
        });
    }
    let rb = batch.update(11.0, &captured).unwrap();
    let mut nis_seq = 0.0;
    for s in &captured {
        nis_seq += seq
            .update(11.0, std::slice::from_ref(s))
            .unwrap()
            .nis
            .unwrap();
    }
    let (xb, xs) = (batch.error_state(), seq.error_state());
    let (pb, ps) = (batch.covariance().unwrap(), seq.covariance().unwrap());
    for i in 0..15 {
        let sd = pb[(i, i)].sqrt();
        assert!(
            (xb[i] - xs[i]).abs() <= 1e-9 * sd,
            "x[{i}]: {} vs {}",
            xb[i],
            xs[i]
        );
        for j in 0..15 {
            let scale = (pb[(i, i)] * pb[(j, j)]).sqrt();
            assert!(
                (pb[(i, j)] - ps[(i, j)]).abs() <= 1e-9 * scale,
                "P[{i},{j}]"
            );
        }
    }
    // The stacked NIS equals the sum of the sequential ones.
    let nb = rb.nis.unwrap();
    assert!((nb - nis_seq).abs() <= 1e-9 * nb, "{nb} vs {nis_seq}");
}

#[test]
fn more_landmarks_than_one_batch_equal_one_at_a_time() {
    // 10 sightings (two of each landmark) go in two batches of ≤ 8; compare with 10 sequential
    // updates.
    let mut cfg = config(ErrorStateEstimator::Kalman, None);
    cfg.open_loop_until_s = f64::INFINITY;
    let (mut batch, _) = fly(cfg, 5, 5, &|_, _| {});
    let mut seq = batch.clone();
    let s: Vec<Sighting> = (0..10u32)
        .map(|i| Sighting {
            landmark_id: 10 + i % 5,
            w_m: i as f64 - 5.0,
            h_m: 0.5 * i as f64,
        })
        .collect();
    let rb = batch.update(5.0, &s).unwrap();
    assert_eq!(rb.used, 10);
    for one in &s {
        seq.update(5.0, std::slice::from_ref(one)).unwrap();
    }
    let p = batch.covariance().unwrap();
    for i in 0..15 {
        assert!(
            (batch.error_state()[i] - seq.error_state()[i]).abs() <= 1e-9 * p[(i, i)].sqrt(),
            "x[{i}]"
        );
    }
}

#[test]
fn bad_input_is_a_typed_error_and_changes_nothing() {
    let cfg = config(ErrorStateEstimator::Kalman, None);
    let (mut f, _) = fly(cfg, 2, 3, &|_, _| {});
    let before = f.clone();
    let same = |a: &InsSdFilter, b: &InsSdFilter| {
        assert_eq!(a.time_s(), b.time_s());
        assert_eq!(a.error_state(), b.error_state());
        assert_eq!(a.covariance(), b.covariance());
        assert_eq!(a.ins().state(), b.ins().state());
        assert_eq!(a.statistics(), b.statistics());
    };
    let z = Vector3::zeros();
    assert!(matches!(
        f.propagate(3.0, &z, &z),
        Err(FilterError::OutOfOrder { .. })
    ));
    assert!(matches!(
        f.propagate(2.5, &z, &z),
        Err(FilterError::OutOfOrder { .. })
    ));
    assert!(matches!(
        f.propagate(3.01, &Vector3::new(f64::NAN, 0.0, 0.0), &z),
        Err(FilterError::NonFiniteInput { .. })
    ));
    assert!(matches!(
        f.propagate(f64::INFINITY, &z, &z),
        Err(FilterError::NonFiniteInput { .. })
    ));
    let ok = Sighting {
        landmark_id: 10,
        w_m: 0.0,
        h_m: 0.0,
    };
    assert!(matches!(
        f.update(
            3.0,
            &[
                ok,
                Sighting {
                    landmark_id: 99,
                    ..ok
                }
            ]
        ),
        Err(FilterError::UnknownLandmark { id: 99, .. })
    ));
    assert!(matches!(
        f.update(
            3.0,
            &[Sighting {
                w_m: f64::NAN,
                ..ok
            }]
        ),
        Err(FilterError::NonFiniteInput { .. })
    ));
    assert!(matches!(
        f.update(3.5, &[ok]),
        Err(FilterError::NotAtInsTime { .. })
    ));
    assert!(matches!(
        f.update(2.0, &[ok]),
        Err(FilterError::OutOfOrder { .. })
    ));
    same(&f, &before);
    // Configuration and table errors name the field / the id.
    let mut bad = cfg;
    bad.r_var_m2 = -1.0;
    match InsSdFilter::new(bad, table(1), *before.ins().state(), 0.0) {
        Err(FilterError::InvalidConfig { field, .. }) => assert_eq!(field, "r_var_m2"),
        other => panic!("{other:?}"),
    }
    let mut bad = cfg;
    bad.gate_probability = Some(1.0);
    assert!(matches!(
        InsSdFilter::new(bad, table(1), *before.ins().state(), 0.0),
        Err(FilterError::InvalidConfig {
            field: "gate_probability",
            ..
        })
    ));
    let e = LandmarkEntry {
        id: 3,
        lat_deg: 0.0,
        lon_deg: 0.0,
        alt_m: 0.0,
    };
    assert_eq!(
        LandmarkTable::new(&[e, e]),
        Err(FilterError::DuplicateLandmark { id: 3 })
    );
    assert!(LandmarkTable::new(&[LandmarkEntry { lat_deg: 91.0, ..e }]).is_err());
}

#[test]
fn increments_and_rates_are_the_same_sample() {
    let cfg = config(ErrorStateEstimator::Kalman, None);
    let (a, _) = fly(cfg, 3, 2, &|_, _| {});
    let mut b = a.clone();
    let mut a = a;
    let f = Vector3::new(0.3, -0.2, -9.7);
    let w = Vector3::new(1e-3, -2e-3, 5e-3);
    for k in 1..=50 {
        let t = 2.0 + k as f64 * 0.01;
        a.propagate(t, &(f * 0.01), &(w * 0.01)).unwrap();
        b.propagate_rates(t, &f, &w).unwrap();
    }
    let d = ins_errors::error_model::error_state(a.ins().state(), b.ins().state());
    assert!(d.fixed_rows::<3>(0).norm() < 1e-9, "{d}");
    assert!(d.fixed_rows::<3>(6).norm() < 1e-14, "{d}");
    // An irregular step (a dropped sample: 0.02 s) is mechanised with its own length: the
    // position advances by about twice a nominal step.
    let p0 = a.ins().state().pos;
    a.propagate(2.52, &(f * 0.02), &(w * 0.02)).unwrap();
    let moved = ins_errors::earth::pos_err_ned_m(&a.ins().state().pos, &p0).norm();
    let v = a.ins().state().vel_ned_mps.norm();
    assert!(
        (moved / (v * 0.02) - 1.0).abs() < 0.01,
        "{moved} vs {}",
        v * 0.02
    );
}

#[test]
fn the_adaptive_filter_uses_its_estimate_once_the_window_is_full() {
    let cfg = config(
        ErrorStateEstimator::MohamedSchwarz(AdaptiveQConfig {
            window: 10,
            projection: QProjection::Diagonal,
            min_variance: 0.0,
        }),
        None,
    );
    let (f, _) = fly(cfg, 3, 15, &|_, _| {});
    // Updates 11..=15 predict with Q̂ (the window fills at update 10).
    assert_eq!(f.statistics().adaptive_q_used, 5);
    assert!(f.q_estimate().is_some());
}

#[test]
fn the_gate_threshold_is_the_chi_square_quantile() {
    for p in [0.9, 0.99, 0.9999] {
        let mut c = config(ErrorStateEstimator::Kalman, Some(p));
        c.gate_probability = Some(p);
        let exact = c.gate_threshold().unwrap();
        // Cross-check with the Wilson–Hilferty approximation of `akf` (≤ 5 % off at 2 dof here).
        let approx = akf::chi_square_quantile(p, 2.0).unwrap();
        assert!(
            (exact / approx - 1.0).abs() < 0.05,
            "p {p}: {exact} vs {approx}"
        );
        // And the defining property of the 2-dof χ²: P(NIS > x) = exp(−x/2).
        assert!(((-exact / 2.0).exp() - (1.0 - p)).abs() < 1e-12);
    }
}

#[test]
fn the_interval_noise_basis_reproduces_the_model_q() {
    // Q_T is linear in the noise densities: Σ psd_k B_k must equal the Q_T of the same
    // interval computed with the densities directly (the structured projection relies on it).
    use ins_sd_filter::interval::IntervalModel;
    let psd = [9.6e-7, 2.35e-13, 1e-9, 1e-15];
    let mut with = IntervalModel::new(100, 2, 0.01, psd);
    with.enable_noise_basis();
    let (filter, _) = fly(config(ErrorStateEstimator::Kalman, None), 1, 45, &|_, _| {});
    let mut ins = filter.ins().clone();
    for _ in 0..100 {
        ins.step(
            &Vector3::new(0.2, 0.1, -9.78),
            &Vector3::new(1e-4, -2e-4, 3e-3),
        );
        with.push(&ins.linearization_point());
    }
    let (_, q) = with.take();
    let mut sum = ins_errors::error_model::Mat15::zeros();
    for (k, b) in with.noise_basis().iter().enumerate() {
        sum += b * psd[k];
    }
    for i in 0..15 {
        for j in 0..15 {
            let scale = (q[(i, i)] * q[(j, j)]).sqrt();
            assert!(
                (sum[(i, j)] - q[(i, j)]).abs() <= 1e-12 * scale,
                "({i}, {j})"
            );
        }
    }
    assert!(q[(0, 0)] > 0.0 && q[(14, 14)] > 0.0);
}

#[test]
fn sage_husa_and_structured_filters_run_and_fit_non_negative_densities() {
    let sh = ErrorStateEstimator::SageHusa(akf::SageHusaConfig {
        forgetting: 0.95,
        warmup: 10,
        projection: QProjection::Diagonal,
        min_variance: 0.0,
    });
    let st = ErrorStateEstimator::MohamedSchwarz(AdaptiveQConfig {
        window: 10,
        projection: QProjection::Structured,
        min_variance: 0.0,
    });
    for est in [sh, st] {
        let (f, truth) = fly(config(est, None), 3, 40, &|_, _| {});
        // The estimate is used from update 11 on (warm-up / window of 10).
        assert_eq!(f.statistics().adaptive_q_used, 30, "{est:?}");
        let e = pos_error_m(&f, &truth);
        assert!(e < 20.0, "{est:?}: {e} m");
    }
    let (f, _) = fly(config(st, None), 3, 40, &|_, _| {});
    let d = f.fitted_noise_densities().expect("fitted");
    assert!(d.iter().all(|v| v.is_finite() && *v >= 0.0), "{d}");
    println!("structured fit after 40 s: densities {d:?}");
}

#[test]
fn an_imu_gap_or_an_implausible_sample_is_refused_and_changes_nothing() {
    let cfg = config(ErrorStateEstimator::Kalman, None);
    let (mut f, _) = fly(cfg, 2, 3, &|_, _| {});
    let (t, before) = (f.time_s(), *f.ins().state());
    let z = Vector3::zeros();
    // Two seconds of missing data (the update interval is 1 s).
    assert!(matches!(
        f.propagate(t + 2.0, &z, &z),
        Err(FilterError::ImuGap { .. })
    ));
    // 4.3e9 m/s gained in 10 ms, or 500 rad/s: no navigation IMU reads that.
    assert!(matches!(
        f.propagate(t + 0.01, &Vector3::new(4.294_967_296e9, 0.0, 0.0), &z),
        Err(FilterError::ImplausibleImu { .. })
    ));
    assert!(matches!(
        f.propagate_rates(t + 0.01, &z, &Vector3::new(0.0, 0.0, 500.0)),
        Err(FilterError::ImplausibleImu { .. })
    ));
    assert_eq!(f.time_s(), t);
    assert_eq!(*f.ins().state(), before);
}

#[test]
fn body_directions_made_from_the_offsets_give_the_same_estimate() {
    let cfg = config(ErrorStateEstimator::Kalman, Some(0.9999));
    let (offsets, _) = fly_with(cfg, 3, 30, &|_, _| {}, false);
    let (pointed, _) = fly_with(cfg, 3, 30, &|_, _| {}, true);
    assert_eq!(offsets.statistics(), pointed.statistics());
    let (a, b) = (offsets.navigation_solution(), pointed.navigation_solution());
    let e = ins_errors::error_model::error_state(&a, &b);
    assert!(e.fixed_rows::<3>(0).norm() < 1e-6, "{e}");
    let (pa, pb) = (offsets.covariance().unwrap(), pointed.covariance().unwrap());
    assert!((pa - pb).norm() < 1e-9 * pa.norm(), "{}", (pa - pb).norm());
}

#[test]
fn a_direction_pointing_away_from_its_landmark_is_rejected_not_used() {
    let cfg = config(ErrorStateEstimator::Kalman, None);
    let (mut filter, _) = fly(cfg, 3, 2, &|_, _| {});
    let pose = filter.pointing_pose();
    let lm = *filter.landmarks().get(10).unwrap();
    let towards = sighting_model::los_from_truth(
        &pose,
        &lm,
        LosFrame::LocalLevel,
        &nalgebra::Vector2::zeros(),
    )
    .unwrap();
    let t = filter.time_s();
    let sightings = [
        PointedSighting {
            landmark_id: 10,
            frame: LosFrame::LocalLevel,
            los: towards,
        },
        // −towards points away from every landmark here.
        PointedSighting {
            landmark_id: 11,
            frame: LosFrame::LocalLevel,
            los: -towards * 5.0,
        },
    ];
    let mut only_first = filter.clone();
    let report = filter.update_pointed(t, &sightings).unwrap();
    assert_eq!((report.used, report.rejected), (1, 1));
    only_first.update_pointed(t, &sightings[..1]).unwrap();
    assert_eq!(filter.covariance(), only_first.covariance());
    // A NaN direction is an error, before anything changes.
    let before = *filter.statistics();
    let nan = [PointedSighting {
        landmark_id: 10,
        frame: LosFrame::Body,
        los: nalgebra::Vector3::new(f64::NAN, 0.0, 1.0),
    }];
    assert!(matches!(
        filter.update_pointed(t, &nan),
        Err(FilterError::NonFiniteInput { .. })
    ));
    assert_eq!(filter.statistics(), &before);
}
