//! One LQR closed-loop run for the LQR mission tests (`#[path]`-included).

use closed_loop::{fly, MissionCheck, Scenario, Trace};
use lqr_control::{LqrController, LqrParams};
use tailsitter_physics::{Airframe, Plant};

/// The default-airframe LQR flying `scenario` on a plant of airframe `plant_af` from its
/// trimmed vertical climb: the trace, the mission check and the controller after the run.
pub fn run(plant_af: Airframe, params: LqrParams, scenario: &Scenario) -> (Trace, MissionCheck, LqrController) {
    let plant = Plant::new(plant_af);
    let x0 = plant.trim_vertical_climb(scenario.mission.v_vertical).unwrap().state;
    let mut c = LqrController::new(Airframe::default(), scenario.mission, params).unwrap();
    let trace = fly(&plant, x0, &mut c, scenario);
    let theta_trim = plant.trim_level(scenario.mission.v_level).unwrap().theta;
    let check = MissionCheck::of(&trace, &scenario.mission, theta_trim);
    (trace, check, c)
}
