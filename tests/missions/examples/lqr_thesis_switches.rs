//! The LQR of `configuration = 1` (the thesis as printed) with each of its configuration-
//! following switches (docs/THESIS.md D-3.3, D-3.5, D-3.15) flipped alone to the tuned form,
//! and the tuned configuration for comparison, on the thesis's own setting: native closed
//! loop (Gauss-Seidel, 20 ms), plant from its 3 m/s climb trim, linear aerodynamics
//! (`aero_model = 0`), true state, calm air, nominal plant, default mission (T1 = 5 s,
//! T2 = 10 s). Then the printed and the tuned configuration on the global aerodynamics
//! (`aero_model = 1`), and the back transition in 5 s instead of 10 s (§3.3.1: "It is
//! possible to complete both trajectories in five seconds"). Prints one markdown table row
//! per run; times are from the start of the mission (T2 starts at 20 s).
//!
//! `cargo run --release -p lqr-control --example thesis_switches`

use closed_loop::{fly, plant_inputs, MissionCheck, Scenario, Trace};
use flight_mission::{MissionParams, Notice};
use lqr_control::{LqrController, LqrParams};
use tailsitter_physics::{AeroModel, Airframe, Plant};

struct Case {
    name: &'static str,
    aero: AeroModel,
    params: LqrParams,
    /// T2 (s); T1 = 5 s.
    t2: f64,
}

fn printed() -> LqrParams {
    LqrParams {
        configuration: 1,
        ..LqrParams::default()
    }
}

fn main() {
    let cases = [
        Case {
            name: "printed (configuration 1)",
            aero: AeroModel::Thesis,
            params: printed(),
            t2: 10.0,
        },
        Case {
            name: "printed, discretisation = 0 (exact ZOH, D-3.3)",
            aero: AeroModel::Thesis,
            params: LqrParams {
                discretisation: 0,
                ..printed()
            },
            t2: 10.0,
        },
        Case {
            name: "printed, integrator_clamp = 1 (±10 m, D-3.5)",
            aero: AeroModel::Thesis,
            params: LqrParams {
                integrator_clamp: 1,
                ..printed()
            },
            t2: 10.0,
        },
        Case {
            name: "printed, integrator_freeze = 1 (D-3.5)",
            aero: AeroModel::Thesis,
            params: LqrParams {
                integrator_freeze: 1,
                ..printed()
            },
            t2: 10.0,
        },
        Case {
            name: "printed, thrust_lead = 1 (D-3.15)",
            aero: AeroModel::Thesis,
            params: LqrParams {
                thrust_lead: 1,
                ..printed()
            },
            t2: 10.0,
        },
        Case {
            name: "tuned (configuration 0)",
            aero: AeroModel::Thesis,
            params: LqrParams::default(),
            t2: 10.0,
        },
        Case {
            name: "printed (configuration 1)",
            aero: AeroModel::Global,
            params: printed(),
            t2: 10.0,
        },
        Case {
            name: "tuned (configuration 0)",
            aero: AeroModel::Global,
            params: LqrParams::default(),
            t2: 10.0,
        },
        Case {
            name: "printed, integrator_clamp = 1 (±10 m, D-3.5)",
            aero: AeroModel::Global,
            params: LqrParams {
                integrator_clamp: 1,
                ..printed()
            },
            t2: 10.0,
        },
        // §3.3.1: "It is possible to complete both trajectories in five seconds".
        Case {
            name: "printed, T2 = 5 s",
            aero: AeroModel::Thesis,
            params: printed(),
            t2: 5.0,
        },
        Case {
            name: "tuned, T2 = 5 s",
            aero: AeroModel::Thesis,
            params: LqrParams::default(),
            t2: 5.0,
        },
        Case {
            name: "printed, T2 = 5 s",
            aero: AeroModel::Global,
            params: printed(),
            t2: 5.0,
        },
    ];
    println!(
        "| LQR | aero_model | completed | criteria | max pos. error (m) | per phase V1/T1/L/T2/V2 (m) | max α T1–T2 \
         (deg) at t (s) | max stall fraction | final θ (deg) | max abs. Σ T_s ΔV (m) | thrust-saturated samples | gain \
         fallbacks | trace = printed's |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    let mut printed_trace: Option<Trace> = None;
    for case in &cases {
        let mission = MissionParams {
            t_transition_2: case.t2,
            ..MissionParams::default()
        };
        let t0 = mission.t_vertical_1;
        let t1 = t0 + mission.t_transition_1 + mission.t_level + mission.t_transition_2;
        let mut plant = Plant::new(Airframe::default());
        plant.aero.model = case.aero;
        let aero = match case.aero {
            AeroModel::Thesis => "0 (linear)",
            AeroModel::Global => "1 (global)",
        };
        let x0 = plant.trim_vertical_climb(mission.v_vertical).expect("climb trim").state;
        let mut c = match LqrController::new(Airframe::default(), mission, case.params.clone()) {
            Ok(c) => c,
            Err(e) => {
                println!("| {} | {aero} | construction failed: {} ||||||||", case.name, e.0);
                continue;
            }
        };
        let trace = fly(&plant, x0, &mut c, &Scenario::mission(mission));
        let theta_trim = plant.trim_level(mission.v_level).expect("level trim").theta;
        let check = MissionCheck::of(&trace, &mission, theta_trim);
        let phases: Vec<String> = check.phase_errors.iter().map(|p| format!("{:.2}", p.max)).collect();
        let saturated = trace
            .notices
            .iter()
            .filter(|(_, n)| matches!(n, Notice::Saturated(name) if *name == "thrust"))
            .count();
        let final_theta = trace.samples.last().map_or(f64::NAN, |s| s.theta.to_degrees());
        let (alpha_max, t_alpha_max) = trace
            .window(t0, t1)
            .map(|s| (s.measurement.alpha, s.t))
            .fold((f64::NEG_INFINITY, f64::NAN), |a, b| if b.0 > a.0 { b } else { a });
        // Share of the wing in post-stall flow (the global model's stall weights, reported for
        // either model).
        let stall = trace
            .samples
            .iter()
            .map(|s| plant.outputs(&s.x, &plant_inputs(&s.command), &s.wind).stall_fraction)
            .fold(0.0, f64::max);
        // The airspeed integrator recomputed from the trace (no clamp, no freeze, leak 0 in
        // every case but the tuned one): Σ T_s (V − V_t).
        let mut x_i: f64 = 0.0;
        let mut x_i_max: f64 = 0.0;
        for s in &trace.samples {
            x_i += mission.sample_time * (s.measurement.airspeed - s.diagnostics.ref_airspeed);
            x_i_max = x_i_max.max(x_i.abs());
        }
        let same = match (&printed_trace, case.aero) {
            (Some(p), AeroModel::Thesis) if case.params != printed() && case.t2 == 10.0 => {
                if p.samples == trace.samples {
                    "yes (bitwise)"
                } else {
                    "no"
                }
            }
            _ => "–",
        };
        if printed_trace.is_none() {
            printed_trace = Some(trace.clone());
        }
        let x_i = if case.params.configuration == 1 {
            format!("{x_i_max:.2}")
        } else {
            "–".to_string()
        };
        println!(
            "| {} | {aero} | {} | {} | {:.2} | {} | {:.1} at {:.2} | {:.2} | {:.1} | {x_i} | {} | {} | {same} |",
            case.name,
            trace.completed_cell(),
            check.verdict(),
            trace.max_pos_error(),
            phases.join(" / "),
            alpha_max.to_degrees(),
            t_alpha_max,
            stall,
            final_theta,
            saturated,
            c.stats().fallbacks,
        );
    }
}
