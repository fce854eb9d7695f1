//! A global allocator that counts, per thread, the allocations made
//! while counting is on: the no-allocation tests' one copy.
//!
//! A `#[global_allocator]` must be declared in the test crate itself, so
//! each test declares it in one line and counts through this module:
//!
//! ```
//! #[global_allocator]
//! static GLOBAL: tcb_test_support::CountingAllocator = tcb_test_support::CountingAllocator;
//!
//! fn main() {
//!     let mut row: Vec<f32> = Vec::with_capacity(8);
//!     let ((), none) = tcb_test_support::count_allocations(|| row.push(1.0));
//!     assert_eq!(none.count, 0);
//!     let (_, one) = tcb_test_support::count_allocations(|| vec![0u8; 64]);
//!     assert_eq!((one.count, one.bytes, one.largest), (1, 64, 64));
//! }
//! ```
//!
//! Only the counting thread's allocations count (a test harness's other
//! threads may allocate meanwhile), and starting a count checks that the
//! allocator is installed, so that a test which forgot the declaration
//! fails instead of counting nothing.

// Implementing `GlobalAlloc` is unsafe by nature; every block forwards to
// the system allocator unchanged.
#![allow(unsafe_code)]

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

/// The system allocator, counting each allocation and reallocation (and
/// the bytes it asks for: a reallocation its new size) on a thread while
/// [`start_counting`] is in force there.
pub struct CountingAllocator;

thread_local! {
    /// Whether this thread's allocations are counted (const, no
    /// destructor: reading it allocates nothing).
    static COUNTING: Cell<bool> = const { Cell::new(false) };
    /// This thread's counted allocations and the bytes they asked for:
    /// per thread, so that tests running side by side do not count each
    /// other's.
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
    static BYTES: Cell<usize> = const { Cell::new(0) };
    static LARGEST: Cell<usize> = const { Cell::new(0) };
}

fn count(bytes: usize) {
    if COUNTING.with(Cell::get) {
        ALLOCATIONS.with(|c| c.set(c.get() + 1));
        BYTES.with(|c| c.set(c.get() + bytes));
        LARGEST.with(|c| c.set(c.get().max(bytes)));
    }
}

// SAFETY: every method forwards its arguments unchanged to `System`, which
// upholds `GlobalAlloc`'s contract; counting touches only const thread
// locals, which neither allocate nor unwind.
unsafe impl GlobalAlloc for CountingAllocator {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        count(layout.size());
        // SAFETY: forwarded unchanged to the system allocator.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: forwarded unchanged to the system allocator.
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        count(new_size);
        // SAFETY: forwarded unchanged to the system allocator.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

/// What a count saw on its thread.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Allocations {
    /// Allocations and reallocations.
    pub count: usize,
    /// The bytes they asked for (a reallocation its new size).
    pub bytes: usize,
    /// The most bytes one of them asked for.
    pub largest: usize,
}

/// Counts this thread's allocations from now until [`stop_counting`].
///
/// # Panics
///
/// If [`CountingAllocator`] is not the global allocator (a probe
/// allocation went uncounted): the count would be 0 whatever runs.
///
/// ```should_panic
/// // No `#[global_allocator]` here: refused, rather than counting nothing.
/// tcb_test_support::start_counting();
/// ```
pub fn start_counting() {
    let before = counted();
    COUNTING.with(|c| c.set(true));
    drop(std::hint::black_box(Box::new(0u8)));
    let probe = counted();
    ALLOCATIONS.with(|c| c.set(before.count));
    BYTES.with(|c| c.set(before.bytes));
    LARGEST.with(|c| c.set(before.largest));
    if probe.count == before.count {
        COUNTING.with(|c| c.set(false));
        panic!(
            "CountingAllocator is not the global allocator: declare \
             `#[global_allocator] static GLOBAL: tcb_test_support::CountingAllocator = \
             tcb_test_support::CountingAllocator;` in the test crate"
        );
    }
}

/// Stops counting this thread's allocations.
pub fn stop_counting() {
    COUNTING.with(|c| c.set(false));
}

/// This thread's counted allocations since the last take (or since the
/// thread started), and the count set back to zero.
pub fn take_counted() -> Allocations {
    let taken = counted();
    ALLOCATIONS.with(|c| c.set(0));
    BYTES.with(|c| c.set(0));
    LARGEST.with(|c| c.set(0));
    taken
}

/// This thread's counted allocations so far.
fn counted() -> Allocations {
    Allocations {
        count: ALLOCATIONS.with(Cell::get),
        bytes: BYTES.with(Cell::get),
        largest: LARGEST.with(Cell::get),
    }
}

/// Runs `f`, counting the allocations it makes on this thread.
///
/// # Panics
///
/// As [`start_counting`]: if [`CountingAllocator`] is not the global
/// allocator.
pub fn count_allocations<R>(f: impl FnOnce() -> R) -> (R, Allocations) {
    let before = take_counted();
    start_counting();
    let r = f();
    stop_counting();
    let during = take_counted();
    // What was counted before, kept for a caller's own take.
    ALLOCATIONS.with(|c| c.set(before.count));
    BYTES.with(|c| c.set(before.bytes));
    LARGEST.with(|c| c.set(before.largest));
    (r, during)
}
