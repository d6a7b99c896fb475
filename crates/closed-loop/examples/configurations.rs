//! Both configurations of both controllers side by side (issue 15): the tuned defaults and
//! the thesis configurations (`configuration` = 1), on the default mission with the
//! nominal plant and with the plant's C_mα × 1.2 (the controllers' design model stays
//! nominal). Prints one table row per run: completion, the mission criteria, max
//! position error (measured − the controller's own reference), max α, thrust saturation.
//!
//! `cargo run --release -p closed-loop --example configurations`

use closed_loop::{fly, MissionCheck, Scenario, Trace};
use flight_mission::{FlightController, MissionParams};
use lqr_control::{LqrController, LqrParams};
use tailsitter_physics::{Airframe, Plant};
use tsd_control::{TsdController, TsdParams};

fn run<C: FlightController>(plant_af: Airframe, mut c: C, mission: MissionParams) -> (Trace, MissionCheck) {
    let plant = Plant::new(plant_af);
    let x0 = plant.trim_vertical_climb(mission.v_vertical).expect("climb trim").state;
    let scenario = Scenario::mission(mission);
    let trace = fly(&plant, x0, &mut c, &scenario);
    let theta_trim = plant.trim_level(mission.v_level).expect("level trim").theta;
    let check = MissionCheck::of(&trace, &mission, theta_trim);
    (trace, check)
}

fn main() {
    let mission = MissionParams::default();
    let mut perturbed = Airframe::default();
    perturbed.c_m_alpha_a0 *= 1.2;
    perturbed.c_m_alpha_a1 *= 1.2;
    let plants = [("nominal", Airframe::default()), ("C_mα × 1.2", perturbed)];
    println!(
        "| controller | configuration | plant | completed | criteria | max pos. error (m) | per phase V1/T1/L/T2/V2 (m) | max α T1–T2 (deg) | final Δθ (deg) |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    for (plant_name, plant_af) in plants {
        for (conf_name, configuration) in [("tuned", 0), ("thesis", 1)] {
            let lqr_params = LqrParams {
                configuration,
                ..LqrParams::default()
            };
            let tsd_params = TsdParams {
                configuration,
                ..TsdParams::default()
            };
            let runs = [
                (
                    "LQR",
                    LqrController::new(Airframe::default(), mission, lqr_params)
                        .map_err(|e| e.0)
                        .map(|c| run(plant_af, c, mission)),
                ),
                (
                    "TSD",
                    TsdController::new(Airframe::default(), mission, tsd_params)
                        .map_err(|e| e.0)
                        .map(|c| run(plant_af, c, mission)),
                ),
            ];
            for (ctl, result) in runs {
                match result {
                    Err(e) => println!("| {ctl} | {conf_name} | {plant_name} | construction failed: {e} |||||"),
                    Ok((trace, check)) => {
                        // α over the transitions and level flight (at 3 m/s in vertical flight α
                        // is the direction of small sideways velocities, not a lift measure).
                        let t0 = mission.t_vertical_1;
                        let t1 = t0 + mission.t_transition_1 + mission.t_level + mission.t_transition_2;
                        let phases: Vec<String> = check.phase_errors.iter().map(|p| format!("{:.2}", p.max)).collect();
                        println!(
                            "| {ctl} | {conf_name} | {plant_name} | {} | {} | {:.2} | {} | {:.1} | {:.2} |",
                            trace.completed_cell(),
                            check.verdict(),
                            trace.max_pos_error(),
                            phases.join(" / "),
                            trace.max_alpha(t0, t1).to_degrees(),
                            check.final_pitch_error.to_degrees(),
                        );
                    }
                }
            }
        }
    }
}
