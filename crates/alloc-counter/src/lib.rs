//! Test support: count the heap allocations a piece of code makes on the current thread.
//!
//! The workspace rule "no allocation per frame or per epoch" is checked by tests that install
//! [`CountingAllocator`] as the global allocator of their test binary and wrap the hot path in
//! [`allocations_in`]. This crate is a dev-dependency only; nothing in a shipped binary uses it.
//!
//! # What is counted
//!
//! [`CountingAllocator`] forwards every call unchanged to [`std::alloc::System`] and, for each
//! `alloc`, `alloc_zeroed` and `realloc` call, adds one to a counter owned by the thread that made
//! the call. `dealloc` is not counted: freeing memory is not an allocation. A `realloc` counts as
//! one allocation whether or not the system allocator could resize in place (growing a `Vec`
//! past its capacity is exactly the kind of hidden allocation these tests look for).
//!
//! [`allocations_in`]`(f)` reads the calling thread's counter before and after running `f`:
//!
//! ```text
//! n = count_this_thread(after f) − count_this_thread(before f)
//! ```
//!
//! so `n` is the number of allocation calls made **by the calling thread while `f` ran**:
//!
//! - allocations of other threads (the test harness's own threads, a thread pool, other tests
//!   running in parallel) are never counted, so results do not depend on `--test-threads`;
//! - allocations made by threads that `f` spawns are not counted either (the spawn itself, which
//!   allocates on the calling thread, is);
//! - calls nest: an inner `allocations_in` does not reset anything, and the outer count includes
//!   the inner one;
//! - dropping the value `f` returns happens after the count, in the caller.
//!
//! The counter is a `const`-initialised thread-local [`Cell`] of a type without a
//! destructor, so touching it from inside the allocator neither allocates nor re-enters the
//! allocator, and it stays usable while a thread is being torn down. (This relies on the target
//! having native thread-local storage, as Linux, macOS and Windows do.)
//!
//! # The guard every test keeps
//!
//! If [`CountingAllocator`] is *not* the global allocator of the binary, every count is zero and a
//! "does not allocate" assertion would pass vacuously. Each test therefore also checks that a
//! deliberate allocation is seen, e.g.
//! `assert_eq!(allocations_in(|| std::hint::black_box(Box::new(1u8))).1, 1)`.
//!
//! # Example
//!
//! ```
//! use alloc_counter::{CountingAllocator, allocations_in};
//!
//! #[global_allocator]
//! static ALLOC: CountingAllocator = CountingAllocator::new();
//!
//! fn main() {
//!     let mut buffer = Vec::with_capacity(8);
//!     // Writing into a caller-owned buffer within its capacity does not allocate …
//!     let ((), n) = allocations_in(|| buffer.extend_from_slice(&[1.0_f64, 2.0, 3.0]));
//!     assert_eq!(n, 0);
//!     // … growing it past its capacity does (one `realloc`).
//!     let ((), n) = allocations_in(|| buffer.extend_from_slice(&[0.0; 16]));
//!     assert_eq!(n, 1);
//!     // The guard: a deliberate allocation is seen, so the zero above is not vacuous.
//!     let (boxed, n) = allocations_in(|| std::hint::black_box(Box::new(7_u32)));
//!     assert_eq!((*boxed, n), (7, 1));
//! }
//! ```

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

thread_local! {
    /// Allocation calls made by this thread through [`CountingAllocator`] since it started.
    /// `const`-initialised and without a destructor: no lazy initialisation, no registration,
    /// no allocation on access.
    static THREAD_ALLOCATIONS: Cell<u64> = const { Cell::new(0) };
}

/// Adds one to the current thread's allocation count.
#[inline]
fn count_one() {
    // `try_with` cannot fail for a const-initialised key without destructor; should it ever, the
    // allocation is left uncounted rather than panicking inside the allocator.
    let _ = THREAD_ALLOCATIONS.try_with(|n| n.set(n.get().wrapping_add(1)));
}

/// The current thread's allocation count (0 where the key is unavailable).
#[inline]
fn thread_count() -> u64 {
    THREAD_ALLOCATIONS.try_with(Cell::get).unwrap_or(0)
}

/// A global allocator that forwards to [`System`] and counts, per thread, the `alloc`,
/// `alloc_zeroed` and `realloc` calls (see the crate docs for the exact semantics).
///
/// Install it in a test binary with
/// `#[global_allocator] static ALLOC: CountingAllocator = CountingAllocator::new();`
/// and measure with [`allocations_in`].
#[derive(Debug, Default, Clone, Copy)]
pub struct CountingAllocator {
    _private: (),
}

impl CountingAllocator {
    /// A counting allocator over [`System`]; `const` so it can initialise a `static`.
    #[must_use]
    pub const fn new() -> Self {
        Self { _private: () }
    }
}

// SAFETY: every method forwards its arguments unchanged to `System`, which upholds the
// `GlobalAlloc` contract, and returns `System`'s result unchanged. The only extra work is an
// increment of a const-initialised thread-local `Cell<u64>`, which neither allocates, unwinds
// nor touches the memory being managed.
unsafe impl GlobalAlloc for CountingAllocator {
    #[inline]
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        count_one();
        // SAFETY: the caller upholds `GlobalAlloc::alloc`'s contract (non-zero-size `layout`),
        // which is exactly `System.alloc`'s.
        unsafe { System.alloc(layout) }
    }

    #[inline]
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        count_one();
        // SAFETY: the caller upholds `GlobalAlloc::alloc_zeroed`'s contract, which is exactly
        // `System.alloc_zeroed`'s.
        unsafe { System.alloc_zeroed(layout) }
    }

    #[inline]
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: `ptr` was returned by this allocator, i.e. by `System`, with this `layout`
        // (every allocating method forwards to `System`); the caller upholds the rest.
        unsafe { System.dealloc(ptr, layout) }
    }

    #[inline]
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        count_one();
        // SAFETY: `ptr` was allocated by `System` with `layout` (see `dealloc`); the caller
        // upholds the size requirements of `GlobalAlloc::realloc`, which are `System.realloc`'s.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

/// Runs `f` and returns its result together with the number of allocation calls (`alloc`,
/// `alloc_zeroed`, `realloc`) the **current thread** made through [`CountingAllocator`] while
/// `f` ran.
///
/// Allocations of other threads are not counted; nested calls are included in the outer count;
/// dropping the returned value happens afterwards and is not counted. If `f` panics, the panic
/// propagates and nothing is returned.
///
/// Returns a count of 0 whenever [`CountingAllocator`] is not the global allocator, so tests
/// must also check that a deliberate allocation is counted (see the crate docs).
pub fn allocations_in<R>(f: impl FnOnce() -> R) -> (R, u64) {
    let before = thread_count();
    let result = f();
    let after = thread_count();
    (result, after.wrapping_sub(before))
}
