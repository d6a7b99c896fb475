//! The estimator's step path (`FmuModel::do_step`: updates, prediction, outputs) does not
//! allocate; the export layer's own path is proven in crates/fmi2-export.

use fmi2_export::testing::{step_allocations, CountingAllocator};
use fmi2_export::VariableStore;
use tailsitter_ekf::{EkfModel, Variables};

#[global_allocator]
static GLOBAL: CountingAllocator = CountingAllocator;

#[test]
fn do_step_does_not_allocate() {
    let mut vars = Variables::with_start_values();
    let n = step_allocations::<EkfModel>(
        &mut vars,
        500,
        0.02,
        |v| v.elevator_cmd = 0.05,
        |k, v| {
            // A new GPS fix every 12 steps: the GPS, magnetometer, pitot and sideslip updates run.
            if k % 12 == 0 {
                v.gps_fix_count += 1;
            }
            v.imu_gyro_q = 1e-3 * ((k % 7) as f64 - 3.0);
        },
    );
    assert_eq!(n, 0, "allocations on the estimator's step path");
    assert!(vars.elevator.abs() > 0.04, "the step path really ran");
    assert!(vars.est_std_pos.is_finite());
}
