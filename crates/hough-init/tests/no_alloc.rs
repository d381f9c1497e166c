//! Initialisation with an existing workspace does not allocate (counting global allocator
//! that counts only allocations of the thread that armed it, so the test harness's own
//! threads cannot disturb the count).
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::sync::atomic::{AtomicUsize, Ordering};

use hough_init::{
    AngleBand, HoughParams, HoughWorkspace, LaneInitParams, Point, fit_parabola, init_lane,
};

struct Counting;
static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

thread_local! {
    // const-initialised, no destructor: usable from inside the allocator.
    static ARMED: Cell<bool> = const { Cell::new(false) };
}

fn count() {
    if ARMED.with(Cell::get) {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
    }
}

// SAFETY: forwards to the system allocator unchanged; only counts calls.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        count();
        // SAFETY: same contract as the caller's.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: same contract as the caller's.
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        count();
        // SAFETY: same contract as the caller's.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

#[test]
fn repeated_initialisations_do_not_allocate() {
    let left: Vec<Point> = (100..240)
        .map(|r| Point::new(200.0 - 0.8 * f64::from(r - 100), f64::from(r)))
        .collect();
    let right: Vec<Point> = (100..240)
        .map(|r| Point::new(170.0 + 0.9 * f64::from(r - 100), f64::from(r)))
        .collect();
    let mut ws = HoughWorkspace::new(320, 240, HoughParams::default()).unwrap();
    let params = LaneInitParams {
        refit_iterations: 1,
        ..LaneInitParams::default()
    };
    let before = ALLOCATIONS.load(Ordering::Relaxed);
    let mut used = 0;
    // Sanity: the counter does see this thread's allocations.
    ARMED.with(|a| a.set(true));
    let probe = std::hint::black_box(vec![1u8; 16]);
    ARMED.with(|a| a.set(false));
    assert_eq!(
        ALLOCATIONS.load(Ordering::Relaxed),
        before + 1,
        "counter is not counting"
    );
    drop(probe);
    let before = before + 1;
    ARMED.with(|a| a.set(true));
    for _ in 0..10 {
        used += init_lane(&left, &AngleBand::LEFT_LANE, &mut ws, &params)
            .unwrap()
            .points_used;
        used += init_lane(&right, &AngleBand::RIGHT_LANE, &mut ws, &params)
            .unwrap()
            .points_used;
        used += fit_parabola(&left).unwrap().points_used;
    }
    ARMED.with(|a| a.set(false));
    let after = ALLOCATIONS.load(Ordering::Relaxed);
    assert!(used > 0);
    assert_eq!(
        after - before,
        0,
        "{} allocations during initialisation",
        after - before
    );
}
