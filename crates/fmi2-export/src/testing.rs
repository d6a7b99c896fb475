//! Test support for models built on this layer: a counting global allocator
//! to prove that `fmi2DoStep` does not allocate ([`step_allocations`]). In a test binary:
//!
//! ```ignore
//! #[global_allocator]
//! static GLOBAL: fmi2_export::testing::CountingAllocator = fmi2_export::testing::CountingAllocator;
//! let before = fmi2_export::testing::allocations();
//! // … the code under test …
//! assert_eq!(fmi2_export::testing::allocations() - before, 0);
//! ```

use crate::{FmuModel, Logger};
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

thread_local! {
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

/// The system allocator, counting the allocations of each thread.
pub struct CountingAllocator;

// SAFETY: forwards to the system allocator; the counter never allocates.
unsafe impl GlobalAlloc for CountingAllocator {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let _ = ALLOCATIONS.try_with(|n| n.set(n.get() + 1));
        // SAFETY: the caller's contract, passed on.
        unsafe { System.alloc(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: the caller's contract, passed on.
        unsafe { System.dealloc(ptr, layout) }
    }
}

/// Allocations made so far by this thread (when [`CountingAllocator`] is the global allocator).
pub fn allocations() -> usize {
    ALLOCATIONS.with(Cell::get)
}

/// The allocations of `steps` calls of `M::do_step` (communication step `h` from
/// t = 0) on a model initialised from `vars` at t = 0; `started` changes the inputs
/// after the initialisation, `each(k, vars)` before step `k`. Requires
/// [`CountingAllocator`] as the global allocator of the test binary.
pub fn step_allocations<M: FmuModel>(
    vars: &mut M::Vars,
    steps: usize,
    h: f64,
    started: impl FnOnce(&mut M::Vars),
    mut each: impl FnMut(usize, &mut M::Vars),
) -> usize {
    let mut model = M::new(vars);
    let mut log = Logger::null();
    model.initialize(vars, 0.0, &mut log).expect("initialisation");
    started(vars);
    let before = allocations();
    for k in 0..steps {
        each(k, vars);
        model.do_step(vars, k as f64 * h, h, &mut log).expect("a step");
    }
    allocations() - before
}
