//! The allocation tests, one binary with one counting global allocator: the
//! hot paths (`Tyre::evaluate`/`forces`, `TransientModel::step`, the brush in
//! the transient models, the FMU's set → step → get) make no allocation.
//!
//! The count is per thread: libtest's own threads (output capture, the
//! slow-test watcher) and the other tests of this binary allocate at any
//! moment, so only the measuring thread's allocations say anything about the
//! code under test. Each test reads [`allocations_on_this_thread`] before and
//! after the window it measures, on the thread that runs the model.
//!
//! Why one binary (Cargo.toml, `autotests = false`): a global allocator is
//! per binary, and each test binary costs a full thin-LTO link of the crate.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

thread_local! {
    // const-initialised, no destructor: reading it from inside the allocator
    // never allocates.
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

/// Allocations (alloc and realloc) made so far on the calling thread.
pub fn allocations_on_this_thread() -> usize {
    ALLOCATIONS.with(Cell::get)
}

struct Counting;

fn count() {
    // try_with: the slot may already be gone while a thread shuts down.
    let _ = ALLOCATIONS.try_with(|c| c.set(c.get() + 1));
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        count();
        unsafe { System.alloc(l) }
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        unsafe { System.dealloc(p, l) }
    }
    unsafe fn realloc(&self, p: *mut u8, l: Layout, n: usize) -> *mut u8 {
        count();
        unsafe { System.realloc(p, l, n) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

#[test]
fn the_counter_counts_this_threads_allocations() {
    let n0 = allocations_on_this_thread();
    let probe = std::hint::black_box(vec![0u8; 64]);
    assert!(
        allocations_on_this_thread() > n0,
        "the counting allocator is not counting"
    );
    // Growing in place goes through realloc, which is counted too.
    let mut grown = std::hint::black_box(probe);
    let n1 = allocations_on_this_thread();
    grown.reserve(1 << 16);
    assert!(
        allocations_on_this_thread() > n1,
        "a reallocation was not counted"
    );
    drop(std::hint::black_box(grown));
}

#[path = "brush_transient.rs"]
mod brush_transient;
#[path = "fmu_alloc.rs"]
mod fmu_alloc;
#[path = "mf_alloc.rs"]
mod mf_alloc;
#[path = "transient_alloc.rs"]
mod transient_alloc;
