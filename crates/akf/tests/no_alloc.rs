//! The per-epoch paths (predict, update, adaptive push with projection) at the INS size
//! N = 15, M = 6 perform no heap allocation: a counting global allocator watches this thread.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used)]

mod common;

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::sync::atomic::{AtomicUsize, Ordering};

use akf::{AdaptiveKalmanFilter, AdaptiveQConfig, QProjection};
use common::*;
use nalgebra::{SMatrix, SVector};

struct Counting;

static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

thread_local! {
    static WATCHING: Cell<bool> = const { Cell::new(false) };
}

// SAFETY: every call is forwarded unchanged to the system allocator; the counter has no effect
// on the returned memory.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if WATCHING.with(Cell::get) {
            ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        }
        // SAFETY: same contract as the caller's (non-zero-size layout), forwarded to System.
        unsafe { System.alloc(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: `ptr` was returned by `System.alloc` with this layout (see `alloc`).
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

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
        WATCHING.with(|w| w.set(true));
        for z in &zs {
            for _ in 0..100 {
                f.predict(&phi, &q).unwrap();
            }
            f.update(z, &h, &r).unwrap();
            f.reset_error_state();
        }
        WATCHING.with(|w| w.set(false));
        assert!(f.q_estimate().is_some(), "the window must have filled");
        assert_eq!(ALLOCATIONS.load(Ordering::Relaxed), 0, "{projection:?}");
    }
    // The instrument itself works: one watched allocation is counted.
    WATCHING.with(|w| w.set(true));
    let v: Vec<u64> = Vec::with_capacity(4);
    WATCHING.with(|w| w.set(false));
    assert_eq!(ALLOCATIONS.load(Ordering::Relaxed), 1);
    drop(v);
}
