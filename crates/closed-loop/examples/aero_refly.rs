//! Re-fly both controllers (untuned) with the thesis (0) and global (1) aerodynamic models:
//! default and fast missions, hover wind steps of 5 and 7 m/s.
//! `cargo run --release -p closed-loop --example aero_refly [lqr|tsd]` (default: both)

use closed_loop::{fly, MissionCheck, Scenario, Trace, Wind};
use flight_mission::{FlightController, MissionParams};
use nalgebra::Vector3;
use tailsitter_physics::{AeroModel, Airframe, Ground, Plant};

fn plant(model: AeroModel) -> Plant {
    let mut p = Plant::new(Airframe::default());
    p.aero.model = model;
    p.ground = Ground::default(); // the FMU's default ground, 10 m below the start
    p
}

fn summary<C: FlightController>(name: &str, model: AeroModel, scenario: &Scenario, make: &dyn Fn(&MissionParams) -> C) {
    let p = plant(model);
    let x0 = p.trim_vertical_climb(scenario.mission.v_vertical).unwrap().state;
    let mut ctl = make(&scenario.mission);
    let trace: Trace = fly(&p, x0, &mut ctl, scenario);
    let theta = p.trim_level(scenario.mission.v_level).map(|t| t.theta).unwrap_or(0.0);
    let check = MissionCheck::of(&trace, &scenario.mission, theta);
    let max_alpha = trace
        .samples
        .iter()
        .map(|s| s.measurement.alpha.abs())
        .fold(0.0, f64::max);
    let (mut max_stall, mut ground, mut max_d) = (0.0f64, 0u32, f64::NEG_INFINITY);
    for s in &trace.samples {
        let y = p.outputs(&s.x, &closed_loop::plant_inputs(&s.command), &s.wind);
        max_stall = max_stall.max(y.stall_fraction);
        ground = ground.max(y.ground.points);
        max_d = max_d.max(s.x[tailsitter_physics::idx::POS_D]);
    }
    println!(
        "{name:<34} aero_model {}: crashed {:<5} mission check {:<5} max |alpha| {:6.1} deg, max pos error {:7.2} m, \
         max stall fraction {:.2}, lowest pos_d {:6.2} m, ground contact {}{}",
        model.index(),
        !trace.completed() || ground > 0,
        check.passed(),
        max_alpha.to_degrees(),
        trace.max_pos_error(),
        max_stall,
        max_d,
        ground > 0,
        trace.failure.as_ref().map(|f| format!(" — {f}")).unwrap_or_default()
    );
}

fn all<C: FlightController>(make: &dyn Fn(&MissionParams) -> C) {
    let default = MissionParams::default();
    let fast = MissionParams::fast();
    let hover = MissionParams {
        t_vertical_1: 40.0,
        ..Default::default()
    };
    for model in [AeroModel::Thesis, AeroModel::Global] {
        summary("default mission", model, &Scenario::mission(default), make);
        summary("fast mission (T1 3 s, T2 4 s)", model, &Scenario::mission(fast), make);
        for speed in [5.0, 7.0] {
            let mut s = Scenario::mission(hover);
            s.stop_time = 30.0;
            s.wind = Wind::Step {
                t_start: 5.0,
                wind: Vector3::new(speed, 0.0, 0.0),
            };
            summary(&format!("hover, {speed} m/s wind step at 5 s"), model, &s, make);
            let mut s = Scenario::mission(hover);
            s.stop_time = 30.0;
            s.wind = Wind::Step {
                t_start: 5.0,
                wind: Vector3::new(0.0, speed, 0.0),
            };
            summary(&format!("hover, {speed} m/s side wind step"), model, &s, make);
        }
    }
}

fn main() {
    let which = std::env::args().nth(1).unwrap_or_else(|| "both".into());
    if which == "lqr" || which == "both" {
        println!("== LQR");
        all(&|m: &MissionParams| {
            lqr_control::LqrController::new(Airframe::default(), *m, lqr_control::LqrParams::default()).unwrap()
        });
    }
    if which == "tsd" || which == "both" {
        println!("== TSD");
        all(&|m: &MissionParams| tsd_control::TsdController::with_mission(*m).unwrap());
    }
}
