//! The plant's step path (`FmuModel::do_step`: the integrator's internal steps; the outputs after it) does
//! not allocate; the export layer's own path is proven in crates/fmi2-export.

use fmi2_export::testing::{allocations, CountingAllocator};
use fmi2_export::{FmuModel, Logger, VariableStore};
use tailsitter_plant::{PlantModel, Variables};

#[global_allocator]
static GLOBAL: CountingAllocator = CountingAllocator;

#[test]
fn do_step_does_not_allocate() {
    let mut vars = Variables::with_start_values();
    let mut model = PlantModel::new(&vars);
    let mut log = Logger::null();
    model.initialize(&mut vars, 0.0, &mut log).unwrap();
    vars.elevator_cmd = 0.05;
    vars.wind_e = 2.0;
    let before = allocations();
    for k in 0..500 {
        model.do_step(&mut vars, k as f64 * 0.02, 0.02, &mut log).unwrap();
        // Outputs are lazy (computed on a get): that path must not allocate either.
        model.update_outputs(&mut vars).unwrap();
    }
    assert_eq!(allocations() - before, 0, "allocations on the plant's step path");
    assert!(vars.q.abs() > 1e-6, "the step path really ran");
}
