//! The controller's step path (`FmuModel::do_step`: held samples, controller
//! updates, outputs) does not
//! allocate; the export layer's own path is proven in crates/fmi2-export.

use fmi2_export::testing::{step_allocations, CountingAllocator};
use fmi2_export::VariableStore;
use tailsitter_px4::{Px4Model, Variables};

#[global_allocator]
static GLOBAL: CountingAllocator = CountingAllocator;

#[test]
fn do_step_does_not_allocate() {
    let mut vars = Variables::with_start_values();
    // 10 s at 10 ms: samples every second step, holds in between; a 5 m offset makes
    // every sample compute a non-trivial command.
    let n = step_allocations::<Px4Model>(&mut vars, 1000, 0.01, |v| v.ref_offset_e = 5.0, |_, _| {});
    assert_eq!(n, 0, "allocations on the controller's step path");
    // The samples ran: the reference now includes the offset (it was 0 at initialisation).
    assert!((vars.ref_pos_e - 5.0).abs() < 1e-9, "{}", vars.ref_pos_e);
}
