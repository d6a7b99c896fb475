//! The sensor model's step path (`FmuModel::do_step`: every sample, filter and
//! output) does not allocate; the export layer's own path is proven in crates/fmi2-export.

use fmi2_export::testing::{step_allocations, CountingAllocator};
use fmi2_export::VariableStore;
use tailsitter_sensors::{SensorsModel, Variables};

#[global_allocator]
static GLOBAL: CountingAllocator = CountingAllocator;

#[test]
fn do_step_does_not_allocate() {
    let mut vars = Variables::with_start_values();
    vars.fault_channel = 2;
    vars.fault_mode = 1;
    vars.fault_start = 1.0;
    vars.fault_duration = 1.0;
    vars.gps_dropout_start = 3.0;
    vars.gps_dropout_duration = 1.0;
    let n = step_allocations::<SensorsModel>(&mut vars, 500, 0.02, |v| v.airspeed = 20.0, |_, _| {});
    assert_eq!(n, 0, "allocations on the sensors' step path");
    assert!(vars.gps_fix_count > 30, "the step path really ran");
}
