//! The atmosphere's step path (`FmuModel::do_step`: turbulence samples, profile, gust,
//! outputs) does not allocate; the export layer's own path is proven in crates/fmi2-export.

use fmi2_export::testing::{step_allocations, CountingAllocator};
use fmi2_export::VariableStore;
use tailsitter_atmosphere::{AtmosphereModel, Variables};

#[global_allocator]
static GLOBAL: CountingAllocator = CountingAllocator;

#[test]
fn do_step_does_not_allocate() {
    let mut vars = Variables::with_start_values();
    vars.wind_speed = 5.0;
    vars.turbulence_intensity = 2;
    vars.gust_amplitude_e = 3.0;
    vars.gust_start = 1.0;
    let n = step_allocations::<AtmosphereModel>(
        &mut vars,
        500,
        0.02,
        |v| v.airspeed = 20.0,
        |k, v| v.pos_d = -0.1 * k as f64,
    );
    assert_eq!(n, 0, "allocations on the atmosphere's step path");
    assert!(vars.wind_d != 0.0, "the step path really ran");
}
