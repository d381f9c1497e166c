//! The per-frame tracking path does not allocate (issue 4 §1): counted with a global allocator
//! that counts allocations made by the measuring thread while a flag is set.
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::sync::atomic::{AtomicUsize, Ordering};

use nav_app::synth::{SCENES, SceneRenderer};
use nav_app::{Estimator, GreyFrame, LaneTracker, TrackerConfig};

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

fn allocations_while_tracking(estimator: Estimator, scene: &str) -> (usize, u64) {
    let spec = SCENES.iter().find(|s| s.name == scene).copied().unwrap();
    let cfg = TrackerConfig::load(spec.config).unwrap();
    let mut renderer = SceneRenderer::new(spec, 320, 240);
    let mut tracker = LaneTracker::new(&cfg, estimator, 320, 240).unwrap();
    let mut frame = GreyFrame::default();
    let mut frames = 0;
    ALLOCS.store(0, Ordering::Relaxed);
    for i in 0..spec.frames {
        renderer.render(i, &mut frame); // rendering may allocate (RNG, truth); not counted
        COUNTING.with(|c| c.set(true));
        let report = tracker.track(&frame);
        COUNTING.with(|c| c.set(false));
        report.unwrap();
        frames += 1;
    }
    (ALLOCS.load(Ordering::Relaxed), frames)
}

#[test]
fn kif_tracking_and_reinitialisation_frames_do_not_allocate() {
    // wall_recovery covers tracking, coasting, loss and Hough + LS re-initialisation.
    for scene in ["straight_solid", "wall_recovery", "noise"] {
        let (allocs, frames) = allocations_while_tracking(Estimator::Kif, scene);
        assert!(frames > 20);
        assert_eq!(
            allocs, 0,
            "{scene}: {allocs} allocations in {frames} frames"
        );
    }
}

#[test]
fn wrls_tracking_frames_do_not_allocate() {
    let (allocs, frames) = allocations_while_tracking(Estimator::Wrls, "wall_recovery");
    assert!(frames > 20);
    assert_eq!(allocs, 0, "{allocs} allocations in {frames} frames");
}

#[test]
fn the_counter_sees_an_allocation() {
    // Guards the guard: an allocation on the counting thread is counted.
    ALLOCS.store(0, Ordering::Relaxed);
    COUNTING.with(|c| c.set(true));
    let v: Vec<u8> = Vec::with_capacity(17);
    COUNTING.with(|c| c.set(false));
    drop(v);
    assert!(ALLOCS.load(Ordering::Relaxed) >= 1);
}
