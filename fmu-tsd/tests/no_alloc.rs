//! The controller's step path (`FmuModel::do_step`: held samples, controller
//! updates, outputs) does not
//! allocate; the export layer's own path is proven in crates/fmi2-export.

use fmi2_export::testing::{allocations, CountingAllocator};
use fmi2_export::{FmuModel, Logger, VariableStore};
use tailsitter_tsd::{TsdModel, Variables};

#[global_allocator]
static GLOBAL: CountingAllocator = CountingAllocator;

#[test]
fn do_step_does_not_allocate() {
    let mut vars = Variables::with_start_values();
    let mut model = TsdModel::new(&vars);
    let mut log = Logger::null();
    model.initialize(&mut vars, 0.0, &mut log).unwrap();
    // A 5 m offset makes every sample compute a non-trivial command.
    vars.ref_offset_e = 5.0;
    let before = allocations();
    // 10 s at 10 ms: samples every second step, holds in between.
    for k in 0..1000 {
        model.do_step(&mut vars, k as f64 * 0.01, 0.01, &mut log).unwrap();
    }
    assert_eq!(allocations() - before, 0, "allocations on the controller's step path");
    // The samples ran: the reference now includes the offset (it was 0 at initialisation).
    assert!((vars.ref_pos_e - 5.0).abs() < 1e-9, "{}", vars.ref_pos_e);
}
