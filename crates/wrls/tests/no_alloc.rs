//! Per-frame WRLS updates do not allocate (paper form: once its buffers are large enough).
#![allow(clippy::unwrap_used, clippy::expect_used)]
#![allow(missing_docs)]

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::sync::atomic::{AtomicUsize, Ordering};

use nalgebra::{Matrix3, Vector3};
use wrls::{PAPER_LAMBDA, RowNorm, ThetaCov, WrlsFast, WrlsPaper};

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
fn updates_do_not_allocate_within_capacity() {
    let points: Vec<(f32, f32)> = (0..150)
        .map(|i| {
            let y = 90.0 + f64::from(i);
            ((1e-3 * y * y - 0.5 * y + 200.0) as f32, y as f32)
        })
        .collect();
    let theta0 = Vector3::new(0.0, 0.0, 160.0);
    let p0 = ThetaCov::Normalised(Matrix3::identity() * 100.0);
    let mut paper = WrlsPaper::new(&theta0, &p0, PAPER_LAMBDA, RowNorm::default(), 150).unwrap();
    let mut fast = WrlsFast::new(&theta0, &p0, PAPER_LAMBDA, RowNorm::default()).unwrap();
    // Warm-up frame: the very first update in the process allocates once (observed; inside
    // faer's factorisation/solve path, lazily initialised state). Later frames must not.
    paper.update(&points).unwrap();
    COUNTING.with(|c| c.set(true));
    for k in 0..50 {
        paper.update(&points[..(k % 3 + 1) * 50]).unwrap();
        fast.update(&points).unwrap();
    }
    COUNTING.with(|c| c.set(false));
    assert_eq!(ALLOCATIONS.load(Ordering::Relaxed), 0);
    // Growing past the capacity allocates (documented), and the counter sees it.
    let more: Vec<(f32, f32)> = points.iter().chain(points.iter()).copied().collect();
    COUNTING.with(|c| c.set(true));
    paper.update(&more).unwrap();
    COUNTING.with(|c| c.set(false));
    assert!(ALLOCATIONS.load(Ordering::Relaxed) > 0);
    assert_eq!(paper.capacity(), 300);
}
