//! Test support for models built on this layer: a counting global allocator
//! to prove that `fmi2DoStep` does not allocate. In a test binary:
//!
//! ```ignore
//! #[global_allocator]
//! static GLOBAL: fmi2_export::testing::CountingAllocator = fmi2_export::testing::CountingAllocator;
//! let before = fmi2_export::testing::allocations();
//! // … the code under test …
//! assert_eq!(fmi2_export::testing::allocations() - before, 0);
//! ```

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
