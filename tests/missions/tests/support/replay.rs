//! The controller inputs of a recorded closed-loop run, replayed by the no-allocation
//! tests and the controller bench (`#[path]`-included).

use closed_loop::{Scenario, Trace};
use flight_mission::ControllerInput;

/// What the controller was given at each sample of `trace`, a run of `scenario`.
pub fn recorded_inputs(trace: &Trace, scenario: &Scenario) -> Vec<ControllerInput> {
    trace
        .samples
        .iter()
        .map(|x| ControllerInput {
            t: x.t,
            measurement: x.measurement,
            ref_offset_ned: scenario.ref_offset(x.t),
        })
        .collect()
}
