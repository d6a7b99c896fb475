//! The estimator's step path (`FmuModel::do_step`: updates, prediction, outputs) does not
//! allocate; the export layer's own path is proven in crates/fmi2-export.

use fmi2_export::testing::{allocations, CountingAllocator};
use fmi2_export::{FmuModel, Logger, VariableStore};
use tailsitter_ekf::{EkfModel, Variables};

#[global_allocator]
static GLOBAL: CountingAllocator = CountingAllocator;

#[test]
fn do_step_does_not_allocate() {
    let mut vars = Variables::with_start_values();
    let mut model = EkfModel::new(&vars);
    let mut log = Logger::null();
    model.initialize(&mut vars, 0.0, &mut log).unwrap();
    vars.elevator_cmd = 0.05;
    let before = allocations();
    for k in 0..500 {
        // A new GPS fix every 12 steps: the GPS, magnetometer, pitot and sideslip updates run.
        if k % 12 == 0 {
            vars.gps_fix_count += 1;
        }
        vars.imu_gyro_q = 1e-3 * ((k % 7) as f64 - 3.0);
        model.do_step(&mut vars, k as f64 * 0.02, 0.02, &mut log).unwrap();
    }
    assert_eq!(allocations() - before, 0, "allocations on the estimator's step path");
    assert!(vars.elevator.abs() > 0.04, "the step path really ran");
    assert!(vars.est_std_pos.is_finite());
}
