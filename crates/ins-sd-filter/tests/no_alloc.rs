//! Propagation and updates do not allocate: 20 s and 200 s of 100 Hz samples with three
//! sightings a second (and a gate) make the same number of allocations (none).
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use akf::{AdaptiveQConfig, QProjection};
use alloc_counter::allocations_in;
use ins_errors::earth::Geodetic;
use ins_errors::strapdown::NavState;
use ins_sd_filter::{
    ErrorSigmas, ErrorStateEstimator, InsSdFilter, InsSdFilterConfig, LandmarkEntry, LandmarkTable,
    MeasurementJacobian, ProcessNoisePsd, Sighting,
};
use nalgebra::{UnitQuaternion, Vector3};

#[global_allocator]
static ALLOC: alloc_counter::CountingAllocator = alloc_counter::CountingAllocator::new();

fn filter(estimator: ErrorStateEstimator) -> InsSdFilter {
    let cfg = InsSdFilterConfig {
        imu_step_s: 0.01,
        timestamp_tolerance_s: 1e-8,
        update_period_s: 1.0,
        phi_subintervals: 2,
        p0_sigma: ErrorSigmas {
            pos_m: 1.0,
            vel_mps: 0.1,
            psi_rad: 1e-3,
            accel_bias_mps2: 0.03,
            gyro_drift_radps: 1e-5,
        },
        process_noise: ProcessNoisePsd {
            accel_white_m2ps3: 1e-6,
            gyro_white_rad2ps: 1e-12,
            accel_bias_rw_m2ps5: 0.0,
            gyro_drift_rw_rad2ps3: 0.0,
        },
        r_var_m2: 40.0,
        open_loop_until_s: 5.0,
        gate_probability: Some(0.999),
        estimator,
        jacobian: MeasurementJacobian::Verified,
    };
    let table = LandmarkTable::new(&[
        LandmarkEntry {
            id: 0,
            lat_deg: -23.29,
            lon_deg: -45.80,
            alt_m: 20.0,
        },
        LandmarkEntry {
            id: 1,
            lat_deg: -23.20,
            lon_deg: -45.90,
            alt_m: 10.0,
        },
        LandmarkEntry {
            id: 2,
            lat_deg: -23.25,
            lon_deg: -45.89,
            alt_m: 30.0,
        },
    ])
    .unwrap();
    let s = NavState {
        pos: Geodetic::from_deg(-23.2, -45.8667, 6000.0),
        vel_ned_mps: Vector3::new(0.0, 30.0, 0.0),
        att_b_to_n: UnitQuaternion::from_euler_angles(0.0, 0.0, std::f64::consts::FRAC_PI_2),
    };
    InsSdFilter::new(cfg, table, s, 0.0).unwrap()
}

fn run(f: &mut InsSdFilter, seconds: usize) {
    let dv = Vector3::new(0.0, 0.0, -9.79 * 0.01);
    let sightings = [0u32, 1, 2].map(|id| Sighting {
        landmark_id: id,
        w_m: 1.0,
        h_m: -1.0,
    });
    for k in 1..=seconds * 100 {
        let t = k as f64 * 0.01;
        f.propagate(t, &dv, &Vector3::zeros()).unwrap();
        if k % 100 == 0 {
            f.update(t, &sightings).unwrap();
        }
    }
}

#[test]
fn propagate_and_update_do_not_allocate() {
    let ms = ErrorStateEstimator::MohamedSchwarz(AdaptiveQConfig {
        window: 10,
        projection: QProjection::Diagonal,
        min_variance: 0.0,
    });
    for est in [
        ErrorStateEstimator::StandAlone,
        ErrorStateEstimator::Kalman,
        ms,
    ] {
        let mut f = filter(est);
        let (_, n) = allocations_in(|| run(&mut f, 20));
        assert_eq!(n, 0, "{est:?}: {n} allocations in 20 s");
        let mut f = filter(est);
        let (_, n) = allocations_in(|| run(&mut f, 200));
        assert_eq!(n, 0, "{est:?}: {n} allocations in 200 s");
    }
}
