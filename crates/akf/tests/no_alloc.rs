//! The per-epoch paths (predict, update, adaptive push with projection) at the INS size
//! N = 15, M = 6 perform no heap allocation: a counting global allocator counts this thread's
//! allocations (`alloc-counter`).
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used)]

mod common;

use akf::{AdaptiveKalmanFilter, AdaptiveQConfig, QProjection};
use alloc_counter::allocations_in;
use common::*;
use nalgebra::{SMatrix, SVector};

#[global_allocator]
static ALLOC: alloc_counter::CountingAllocator = alloc_counter::CountingAllocator::new();

#[test]
fn predict_update_and_adaptive_push_do_not_allocate() {
    let mut rng = rng(701);
    let p0 = random_spd::<15>(&mut rng, 1.0);
    let phi = SMatrix::<f64, 15, 15>::identity() + uniform_mat::<15, 15>(&mut rng) * 0.001;
    let b: SMatrix<f64, 15, 15> = uniform_mat(&mut rng);
    let q = b * b.transpose() * 1e-6;
    let h: SMatrix<f64, 6, 15> = uniform_mat(&mut rng);
    let r = random_spd::<6>(&mut rng, 0.5);
    let zs: Vec<SVector<f64, 6>> = (0..30).map(|_| normal_vec(&mut rng)).collect();
    for projection in [QProjection::EigenClip, QProjection::Diagonal] {
        let config = AdaptiveQConfig {
            projection,
            ..Default::default()
        };
        let mut f = AdaptiveKalmanFilter::<15>::new(SVector::zeros(), p0, config).unwrap();
        let ((), allocations) = allocations_in(|| {
            for z in &zs {
                for _ in 0..100 {
                    f.predict(&phi, &q).unwrap();
                }
                f.update(z, &h, &r).unwrap();
                f.reset_error_state();
            }
        });
        assert!(f.q_estimate().is_some(), "the window must have filled");
        assert_eq!(allocations, 0, "{projection:?}");
    }
    // The instrument itself works: one watched allocation is counted.
    let (v, allocations) = allocations_in(|| Vec::<u64>::with_capacity(4));
    assert_eq!(allocations, 1);
    drop(v);
}
