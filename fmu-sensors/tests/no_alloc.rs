//! The sensor model's step path (`FmuModel::do_step`: every sample, filter and
//! output) does not allocate; the export layer's own path is proven in crates/fmi2-export.

use fmi2_export::testing::{allocations, CountingAllocator};
use fmi2_export::{FmuModel, Logger, VariableStore};
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
    let mut model = SensorsModel::new(&vars);
    let mut log = Logger::null();
    model.initialize(&mut vars, 0.0, &mut log).unwrap();
    vars.airspeed = 20.0;
    let before = allocations();
    for k in 0..500 {
        model.do_step(&mut vars, k as f64 * 0.02, 0.02, &mut log).unwrap();
    }
    assert_eq!(allocations() - before, 0, "allocations on the sensors' step path");
    assert!(vars.gps_fix_count > 30, "the step path really ran");
}
