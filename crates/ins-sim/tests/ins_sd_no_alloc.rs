//! The INS/SD epoch loop does not allocate: a run of 200 s makes exactly as many allocations
//! as a run of 20 s with the same segment table (only the per-run setup allocates: trajectory table, boxed filter).
//! Counted with the `alloc-counter` global allocator, which counts the measuring thread's
//! allocations only.
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use alloc_counter::allocations_in;
use ins_sim::{Mode, Sample, Scenario, run};

#[global_allocator]
static ALLOC: alloc_counter::CountingAllocator = alloc_counter::CountingAllocator::new();

fn count_run(sc: &Scenario, mode: Mode) -> u64 {
    let mut out = vec![Sample::default(); sc.samples_per_run()];
    let (r, allocations) = allocations_in(|| run(sc, mode, 5, &mut out));
    r.unwrap();
    allocations
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

#[test]
fn the_counter_sees_an_allocation() {
    // Guards the guard: equal counts above must not come from a counter that never counts.
    let (v, allocations) = allocations_in(|| Vec::<u8>::with_capacity(17));
    drop(v);
    assert_eq!(allocations, 1);
}
