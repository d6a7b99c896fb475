//! The PX4 controller through a mission, printed every `--every` seconds: VTOL mode,
//! phase, position and reference, airspeed, pitch, α, thrust, position error.
//!
//! `cargo run --release -p missions --example px4_trace -- [default|fast|takeoff_landing|…] [jacobi]`

use closed_loop::{fly, MissionCheck, Ordering, Scenario};
use flight_mission::MissionParams;
use px4_control::Px4Controller;
use tailsitter_physics::{Airframe, Plant};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let preset = args.get(1).map_or("default", String::as_str);
    let jacobi = args.iter().any(|a| a == "jacobi");
    let mission = MissionParams::preset(preset).expect("a declared preset");
    let plant = Plant::new(Airframe::default());
    let x0 = if mission.takeoff_spinup_time > 0.0 {
        plant.trim_vertical_climb(0.0).unwrap().state
    } else {
        plant.trim_vertical_climb(mission.v_vertical).unwrap().state
    };
    let mut ctl = Px4Controller::with_mission(mission).unwrap();
    let mut scenario = Scenario::mission(mission);
    if jacobi {
        scenario.ordering = Ordering::Jacobi;
    }
    let every: usize = std::env::var("EVERY").ok().and_then(|v| v.parse().ok()).unwrap_or(25);
    // Fly sample by sample to record the controller's internals (mode, setpoint pitch).
    let mut internals = Vec::new();
    let mut probe = ctl.clone();
    let trace = fly(&plant, x0, &mut ctl, &scenario);
    for s in &trace.samples {
        let input = flight_mission::ControllerInput {
            t: s.t,
            measurement: s.measurement,
            ref_offset_ned: nalgebra::Vector3::zeros(),
        };
        let _ = flight_mission::SampledUnit::sample(&mut probe, &input);
        let i = *probe.internals();
        let sp_pitch = i
            .attitude_sp
            .map(|q| {
                (q * px4_control::body_from_mc().inverse())
                    .euler_angles()
                    .1
                    .to_degrees()
            })
            .unwrap_or(i.tecs.1.to_degrees());
        internals.push((i.mode.map_or(-1, |m| m as i32), sp_pitch, i.torque));
    }
    for (s, (mode, sp_pitch, torque)) in trace.samples.iter().zip(&internals).step_by(every) {
        print!(
            "m {mode} θsp {sp_pitch:6.1} τ ({:5.2} {:5.2} {:5.2}) ",
            torque.x, torque.y, torque.z
        );
        let m = &s.measurement;
        println!(
            "t {:5.2} ph {:2} pos ({:7.2} {:6.2} {:7.2}) ref ({:7.2} {:6.2} {:7.2}) V {:5.2} θ {:6.1} α {:6.1} T {:6.1} δe {:5.1} err {:6.2}",
            s.t,
            s.diagnostics.phase as i32,
            m.pos_ned.x,
            m.pos_ned.y,
            m.pos_ned.z,
            s.diagnostics.ref_pos_ned.x,
            s.diagnostics.ref_pos_ned.y,
            s.diagnostics.ref_pos_ned.z,
            m.airspeed,
            s.theta.to_degrees(),
            m.alpha.to_degrees(),
            s.command.thrust,
            s.command.elevator.to_degrees(),
            s.pos_error()
        );
    }
    println!("failure: {:?}", trace.failure);
    let check = MissionCheck::of(&trace, &mission, plant.trim_level(mission.v_level).unwrap().theta);
    print!("{check}");
    println!("max pos error {:.2} m", trace.max_pos_error());
    println!("derived: {:?}", ctl.derived());
}
