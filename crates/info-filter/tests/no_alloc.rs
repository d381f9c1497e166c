//! The per-frame hot path (predict + power-sum update) does not allocate.
#![allow(clippy::unwrap_used, clippy::expect_used)]
#![allow(missing_docs)]

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::sync::atomic::{AtomicUsize, Ordering};

use info_filter::{ParabolaKif, RowNorm, ThetaCov};
use nalgebra::{Matrix3, Vector3};

/// Counts allocations made on threads that switched counting on.
struct CountingAlloc;

static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

thread_local! {
    static COUNTING: Cell<bool> = const { Cell::new(false) };
}

// SAFETY: forwards every call unchanged to the system allocator; the bookkeeping touches only an
// atomic counter and a const-initialised thread-local `Cell`, neither of which allocates.
unsafe impl GlobalAlloc for CountingAlloc {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if COUNTING.with(Cell::get) {
            ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        }
        // SAFETY: same contract as our caller's.
        unsafe { System.alloc(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: `ptr` came from `System.alloc` with this `layout`.
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static GLOBAL: CountingAlloc = CountingAlloc;

#[test]
fn predict_and_update_do_not_allocate() {
    let points: Vec<(f32, f32)> = (0..150)
        .map(|i| {
            let y = 90.0 + f64::from(i);
            ((1e-3 * y * y - 0.5 * y + 200.0) as f32, y as f32)
        })
        .collect();
    let mut kif = ParabolaKif::new(
        &Vector3::new(0.0, 0.0, 160.0),
        &ThetaCov::Normalised(Matrix3::identity() * 100.0),
        RowNorm::default(),
    )
    .unwrap();
    let q = kif
        .process_noise(&ThetaCov::Normalised(Matrix3::identity() * 0.25))
        .unwrap();
    COUNTING.with(|c| c.set(true));
    for _ in 0..100 {
        kif.predict(&q).unwrap();
        kif.update(&points, 1.0).unwrap();
    }
    COUNTING.with(|c| c.set(false));
    assert_eq!(ALLOCATIONS.load(Ordering::Relaxed), 0);
    // The counter works: a Vec allocation on a counting thread is seen.
    COUNTING.with(|c| c.set(true));
    let v = std::hint::black_box(vec![1u8; 16]);
    COUNTING.with(|c| c.set(false));
    drop(v);
    assert_eq!(ALLOCATIONS.load(Ordering::Relaxed), 1);
}
