//! The three controllers (LQR, TSD, PX4) side by side in one run: the default and fast
//! missions under Gauss-Seidel and Jacobi, take-off → landing, and the 5 m position steps;
//! largest position error, completion and the mission criteria.
//!
//! `cargo run --release -p missions --example controller_table`

use closed_loop::{fly, MissionCheck, Ordering, Scenario, Trace};
use flight_mission::{FlightController, MissionParams, Phase, SampledUnit};
use lqr_control::{LqrConfig, LqrController};
use nalgebra::Vector3;
use px4_control::{Px4Config, Px4Controller};
use tailsitter_physics::{Airframe, Plant, StateVector};
use tsd_control::{TsdConfig, TsdController};

fn fly_any(name: &str, mission: MissionParams, plant: &Plant, x0: StateVector, scenario: &Scenario) -> Trace {
    fn go<C: FlightController>(mut c: C, plant: &Plant, x0: StateVector, s: &Scenario) -> Trace {
        fly(plant, x0, &mut c, s)
    }
    match name {
        "LQR" => go(
            LqrController::build(&LqrConfig::with_mission(mission)).unwrap(),
            plant,
            x0,
            scenario,
        ),
        "TSD" => go(
            TsdController::build(&TsdConfig::with_mission(mission)).unwrap(),
            plant,
            x0,
            scenario,
        ),
        _ => go(
            Px4Controller::build(&Px4Config::with_mission(mission)).unwrap(),
            plant,
            x0,
            scenario,
        ),
    }
}

fn main() {
    let names = ["LQR", "TSD", "PX4"];
    let plant = Plant::new(Airframe::default());
    println!("| mission | master | controller | completed | criteria | largest position error (m) | largest error per phase 0-4 (m) | final pitch error (deg) |");
    println!("|---|---|---|---|---|---|---|---|");
    for preset in ["default", "fast"] {
        let mission = MissionParams::preset(preset).unwrap();
        let x0 = plant.trim_vertical_climb(mission.v_vertical).unwrap().state;
        let theta = plant.trim_level(mission.v_level).unwrap().theta;
        for (master, ordering) in [("Gauss-Seidel", Ordering::GaussSeidel), ("Jacobi", Ordering::Jacobi)] {
            for name in names {
                let mut s = Scenario::mission(mission);
                s.ordering = ordering;
                let trace = fly_any(name, mission, &plant, x0, &s);
                let check = MissionCheck::of(&trace, &mission, theta);
                let per: Vec<String> = check.phase_errors.iter().map(|e| format!("{:.1}", e.max)).collect();
                println!(
                    "| {preset} | {master} | {name} | {} | {} | {:.2} | {} | {:.2} |",
                    trace.completed_cell(),
                    check.verdict(),
                    trace.max_pos_error(),
                    per.join(" / "),
                    check.final_pitch_error.to_degrees()
                );
            }
        }
    }
    // Steady wind (m/s, from the four quarters): the default mission, Gauss-Seidel.
    println!();
    println!(
        "| steady wind | controller | completed | criteria | largest position error (m) | final pitch error (deg) |"
    );
    println!("|---|---|---|---|---|---|");
    let mission = MissionParams::default();
    let x0 = plant.trim_vertical_climb(mission.v_vertical).unwrap().state;
    let theta = plant.trim_level(mission.v_level).unwrap().theta;
    for speed in [3.0, 6.0] {
        for (from, bearing) in [("N", 0.0), ("E", 90.0), ("S", 180.0), ("W", 270.0)] {
            for name in names {
                let mut s = Scenario::mission(mission);
                s.wind = closed_loop::Wind::Constant(closed_loop::wind_from(f64::to_radians(bearing), speed));
                let trace = fly_any(name, mission, &plant, x0, &s);
                let check = MissionCheck::of(&trace, &mission, theta);
                println!(
                    "| {speed} m/s from {from} | {name} | {} | {} | {:.2} | {:.2} |",
                    trace.completed_cell(),
                    check.verdict(),
                    trace.max_pos_error(),
                    check.final_pitch_error.to_degrees()
                );
            }
        }
    }
    // Take-off → landing on the global aerodynamics with the ground plane.
    let mission = analysis::takeoff_landing::mission();
    let (tplant, x0) = analysis::takeoff_landing::plant();
    println!();
    println!("| take-off → landing | master | controller | completed | landed | miss distance (m) | largest position error in flight (m) | final tilt (deg) |");
    println!("|---|---|---|---|---|---|---|---|");
    for (master, ordering) in [("Gauss-Seidel", Ordering::GaussSeidel), ("Jacobi", Ordering::Jacobi)] {
        for name in names {
            let mut s = Scenario::mission(mission);
            s.ordering = ordering;
            s.stop_time = analysis::takeoff_landing::stop_time(&mission);
            let trace = fly_any(name, mission, &tplant, x0, &s);
            let last = trace.samples.last().unwrap();
            let landed = last.diagnostics.phase == Phase::Landed;
            let miss = (last.measurement.pos_ned.xy() - Vector3::new(460.0, 0.0, 0.0).xy()).norm();
            let tilt = 90.0 - last.theta.to_degrees();
            println!(
                "| take-off → landing | {master} | {name} | {} | {} | {miss:.2} | {:.2} | {tilt:.1} |",
                trace.completed_cell(),
                if landed { "yes" } else { "no" },
                trace.max_pos_error()
            );
        }
    }
    // 5 m position steps (vertical: a 40 s first vertical phase; level: a 40 s level phase).
    println!();
    println!("| step | controller | completed | settling < 0.5 m on the stepped axis (s) | final error on that axis (m) | largest position error (m) |");
    println!("|---|---|---|---|---|---|");
    let vertical = MissionParams::preset("step_vertical").unwrap();
    let level = MissionParams::preset("step_level").unwrap();
    let cases = [
        ("vertical, north 5 m", vertical, 5.0, Vector3::new(5.0, 0.0, 0.0), 35.0),
        ("vertical, east 5 m", vertical, 5.0, Vector3::new(0.0, 5.0, 0.0), 35.0),
        ("level, down 5 m", level, 15.0, Vector3::new(0.0, 0.0, 5.0), 45.0),
        ("level, east 5 m", level, 15.0, Vector3::new(0.0, 5.0, 0.0), 45.0),
    ];
    for (case, mission, t_step, offset, t_end) in cases {
        let x0 = plant.trim_vertical_climb(mission.v_vertical).unwrap().state;
        let axis = offset.normalize();
        for name in names {
            let mut s = Scenario::mission(mission);
            s.stop_time = t_end;
            s.ref_offset_steps = vec![(t_step, offset)];
            let trace = fly_any(name, mission, &plant, x0, &s);
            let mut last_out = t_step;
            let mut final_err = f64::NAN;
            let mut max_err: f64 = 0.0;
            for smp in trace.window(t_step, t_end + 1.0) {
                let e = (smp.measurement.pos_ned - smp.diagnostics.ref_pos_ned).dot(&axis).abs();
                if e > 0.5 {
                    last_out = smp.t;
                }
                final_err = e;
                max_err = max_err.max(smp.pos_error());
            }
            println!(
                "| {case} | {name} | {} | {:.2} | {final_err:.3} | {max_err:.2} |",
                trace.completed_cell(),
                last_out - t_step
            );
        }
    }
}
