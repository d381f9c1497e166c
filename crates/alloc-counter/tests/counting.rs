//! The counting allocator counts exactly the calling thread's allocation calls inside the closure.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used)]

use std::hint::black_box;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};

use alloc_counter::{CountingAllocator, allocations_in};

#[global_allocator]
static ALLOC: CountingAllocator = CountingAllocator::new();

#[test]
fn each_allocation_in_the_closure_is_counted_once() {
    let ((a, b, c), n) = allocations_in(|| {
        let a = black_box(Box::new(1_u64));
        let b = black_box(vec![0_u8; 32]); // alloc_zeroed
        let c = black_box(String::from("lane"));
        (a, b, c)
    });
    assert_eq!(n, 3);
    assert_eq!((*a, b.len(), c.as_str()), (1, 32, "lane"));
}

#[test]
fn a_closure_that_does_not_allocate_counts_zero_and_returns_its_value() {
    let xs = [1.0_f64, 2.0, 3.0, 4.0];
    let (sum, n) = allocations_in(|| black_box(&xs).iter().sum::<f64>());
    assert_eq!((sum, n), (10.0, 0));
}

#[test]
fn growing_past_capacity_counts_a_realloc_and_freeing_counts_nothing() {
    let mut v: Vec<u64> = Vec::with_capacity(4);
    v.push(1);
    let ((), n) = allocations_in(|| v.reserve_exact(100));
    assert_eq!(n, 1, "one realloc");
    assert!(v.capacity() >= 101);
    let ((), n) = allocations_in(|| drop(black_box(v)));
    assert_eq!(n, 0, "dealloc is not an allocation");
}

#[test]
fn nested_counts_are_included_in_the_outer_count() {
    let ((inner, _kept), outer) = allocations_in(|| {
        let (_b, inner) = allocations_in(|| black_box(Box::new(2_u32)));
        let kept = black_box(Box::new(3_u32));
        (inner, kept)
    });
    assert_eq!((inner, outer), (1, 2));
}

#[test]
fn other_threads_allocations_are_not_counted() {
    const WANTED: u64 = 1000;
    let done = Arc::new(AtomicU64::new(0));
    let stop = Arc::new(AtomicBool::new(false));
    let worker = {
        let (done, stop) = (Arc::clone(&done), Arc::clone(&stop));
        std::thread::spawn(move || {
            // The worker counts its own allocations: per-thread counting works on any thread.
            let ((), own) = allocations_in(|| {
                while !stop.load(Ordering::Acquire) {
                    drop(black_box(vec![1_u8; 64]));
                    done.fetch_add(1, Ordering::Release);
                }
            });
            own
        })
    };
    // While this thread only spins on atomics, the worker allocates at least WANTED times.
    let ((), n) = allocations_in(|| {
        while done.load(Ordering::Acquire) < WANTED {
            std::hint::spin_loop();
        }
    });
    stop.store(true, Ordering::Release);
    let worker_count = worker.join().unwrap();
    assert_eq!(
        n, 0,
        "the worker's allocations leaked into this thread's count"
    );
    assert!(
        worker_count >= WANTED,
        "the worker counted {worker_count} of its own allocations"
    );
}
