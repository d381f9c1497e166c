//! The INS/SD epoch loop does not allocate: a run of 200 s makes exactly as many allocations
//! as a run of 20 s with the same segment table (only the per-run setup allocates: trajectory table, boxed filter).
//! Counted with a global allocator that counts the measuring thread's allocations while a
//! flag is set.
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::sync::atomic::{AtomicUsize, Ordering};

use nav_app::ins_sd::{Mode, Sample, Scenario, run};

struct Counting;
static ALLOCS: AtomicUsize = AtomicUsize::new(0);
thread_local! {
    static COUNTING: Cell<bool> = const { Cell::new(false) };
}

// SAFETY: forwards every call to the system allocator unchanged; only counts.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if COUNTING.with(Cell::get) {
            ALLOCS.fetch_add(1, Ordering::Relaxed);
        }
        // SAFETY: same contract as the caller's.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: same contract as the caller's.
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        if COUNTING.with(Cell::get) {
            ALLOCS.fetch_add(1, Ordering::Relaxed);
        }
        // SAFETY: same contract as the caller's.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

fn count_run(sc: &Scenario, mode: Mode) -> usize {
    let mut out = vec![Sample::default(); sc.samples_per_run()];
    ALLOCS.store(0, Ordering::Relaxed);
    COUNTING.with(|c| c.set(true));
    let r = run(sc, mode, 5, &mut out);
    COUNTING.with(|c| c.set(false));
    r.unwrap();
    ALLOCS.load(Ordering::Relaxed)
}

#[test]
fn epoch_loop_does_not_allocate() {
    // Same segment table (one 20 s manoeuvre, then straight flight), 20 s and 200 s long; both
    // include the feedback phase (switch moved to 10 s).
    let mut short = Scenario::paper_default().truncated(20.0).unwrap();
    short.trajectory.segments[0].turn_rate_degps = 1.0;
    short.filter.open_loop_until_s = 10.0;
    let mut long = short.clone();
    long.trajectory.end_time_s = 200.0;
    long.validate().unwrap();
    for mode in Mode::ALL {
        let a = count_run(&short, mode);
        let b = count_run(&long, mode);
        println!("{}: {a} allocations for 20 s, {b} for 200 s", mode.name());
        assert_eq!(
            a,
            b,
            "{}: allocations grow with the run length",
            mode.name()
        );
    }
}
