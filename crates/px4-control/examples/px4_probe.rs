//! The PX4 controller on the declared missions with the nonlinear plant (the reference
//! master of `closed-loop`): the default and fast missions, take-off → landing, the 5 m
//! position steps, under Gauss-Seidel and Jacobi, and the default mission in steady wind;
//! or one run sample by sample.
//!
//! `cargo run --release -p px4-control --example px4_probe -- [table | wind | profile <preset> | trace <preset> [jacobi]]`
//!
//! Environment: `TECS_PIT`, `TECS_THR`, `ALT_TC`, `SPDW`, `ARSP_TRANS` override
//! FW_T_I_GAIN_PIT, FW_T_I_GAIN_THR, FW_T_ALT_TC, FW_T_SPDWEIGHT, VT_ARSP_TRANS; for
//! `trace`, `EVERY` (samples between lines), `STEP="t,n,e,d"` and `STOP` (a reference step
//! and the end time), `WIND="speed,from_bearing_deg"` (steady wind).

use closed_loop::{fly, MissionCheck, Ordering, Scenario, Trace};
use flight_mission::{MissionParams, Phase, SampledUnit};
use guidance::GroundPhases;
use nalgebra::Vector3;
use px4_control::Px4Controller;
use tailsitter_physics::{AeroModel, Airframe, Ground, Plant, StateVector};

/// The take-off → landing mission of the report (the thesis's timings, a 460 m north target).
fn takeoff_landing() -> (MissionParams, Plant, StateVector, f64) {
    let mission = MissionParams {
        takeoff_spinup_time: 2.0,
        takeoff_time: 2.0,
        landing_descent_rate: 2.0,
        landing_target_n: 460.0,
        landing_approach_speed: 3.0,
        ..MissionParams::default()
    };
    let mut plant = Plant::new(Airframe::default());
    plant.aero.model = AeroModel::Global;
    plant.ground = Ground::default();
    let x0 = plant.resting_on_ground(0.0, 0.0, 0.0);
    let g = GroundPhases::new(mission, 1.0);
    let stop = g.mission_start() + mission.end_time() + 1.5 * 510.0 / 3.0 + 200.0 + 20.0;
    (mission, plant, x0, stop)
}

/// PX4's parameters, with `TECS_PIT=<FW_T_I_GAIN_PIT>`, `TECS_THR=<FW_T_I_GAIN_THR>` from the environment.
fn params() -> px4_control::Px4Params {
    let mut p = px4_control::Px4Params::default();
    let env = |k: &str| std::env::var(k).ok().and_then(|v| v.parse::<f64>().ok());
    if let Some(v) = env("TECS_PIT") {
        p.FW_T_I_GAIN_PIT = v;
    }
    if let Some(v) = env("TECS_THR") {
        p.FW_T_I_GAIN_THR = v;
    }
    if let Some(v) = env("ALT_TC") {
        p.FW_T_ALT_TC = v;
    }
    if let Some(v) = env("ARSP_TRANS") {
        p.VT_ARSP_TRANS = v;
    }
    if let Some(v) = env("SPDW") {
        p.FW_T_SPDWEIGHT = v;
    }
    p
}

fn controller(mission: MissionParams) -> Px4Controller {
    Px4Controller::new(Airframe::default(), mission, params()).unwrap()
}

fn run(plant: &Plant, x0: StateVector, mission: MissionParams, s: &Scenario) -> (Trace, MissionCheck) {
    let mut ctl = controller(mission);
    let trace = fly(plant, x0, &mut ctl, s);
    let theta = Plant::new(Airframe::default())
        .trim_level(mission.v_level)
        .unwrap()
        .theta;
    let check = MissionCheck::of(&trace, &mission, theta);
    (trace, check)
}

fn table() {
    let plant = Plant::new(Airframe::default());
    for preset in ["default", "fast"] {
        let mission = MissionParams::preset(preset).unwrap();
        let x0 = plant.trim_vertical_climb(mission.v_vertical).unwrap().state;
        for (master, ordering) in [("GS", Ordering::GaussSeidel), ("Jacobi", Ordering::Jacobi)] {
            let mut s = Scenario::mission(mission);
            s.ordering = ordering;
            let (trace, check) = run(&plant, x0, mission, &s);
            let per: Vec<String> = check.phase_errors.iter().map(|e| format!("{:.2}", e.max)).collect();
            // α where it means something: airspeed of at least 5 m/s.
            let alpha = trace
                .window(mission.phase_starts()[1], mission.end_time())
                .filter(|s| s.measurement.airspeed >= 5.0)
                .map(|s| s.measurement.alpha.abs())
                .fold(0.0, f64::max)
                .to_degrees();
            println!(
                "{preset:8} {master:6} completed {} criteria {} max err {:.2} m (phases {}) level V err {:.2} m/s θ err {:.2}° final {:.2}° max |α| (T1 on, V ≥ 5 m/s) {alpha:.1}°",
                trace.completed(),
                check.verdict(),
                trace.max_pos_error(),
                per.join(" / "),
                check.level_airspeed_error,
                check.level_pitch_error.to_degrees(),
                check.final_pitch_error.to_degrees()
            );
        }
    }
    let (mission, tplant, x0, stop) = takeoff_landing();
    for (master, ordering) in [("GS", Ordering::GaussSeidel), ("Jacobi", Ordering::Jacobi)] {
        let mut s = Scenario::mission(mission);
        s.ordering = ordering;
        s.stop_time = stop;
        let (trace, check) = run(&tplant, x0, mission, &s);
        let last = trace.samples.last().unwrap();
        let miss = (last.measurement.pos_ned.xy() - nalgebra::Vector2::new(460.0, 0.0)).norm();
        let flight = check.phase_errors.iter().map(|e| e.max).fold(0.0, f64::max);
        // Contact lost after the first touchdown (the gear's rebound), and its height.
        let contact: Vec<u32> = trace
            .samples
            .iter()
            .map(|s| tplant.ground.contact_state(&tplant.airframe, &s.x).points)
            .collect();
        let airborne = contact.iter().position(|&c| c == 0).unwrap_or(0);
        let td = (airborne..contact.len()).find(|&k| contact[k] > 0);
        let (bounced, rebound) = td.map_or((false, 0.0), |k| {
            let d0 = trace.samples[k].measurement.pos_ned.z;
            let rise = trace.samples[k..]
                .iter()
                .map(|s| d0 - s.measurement.pos_ned.z)
                .fold(0.0, f64::max);
            (contact[k..].contains(&0), rise)
        });
        println!(
            "TL       {master:6} completed {} landed {} miss {miss:.2} m tilt {:.1}° max err (every phase) {flight:.2} m bounced {bounced} (rise {:.1} mm)",
            trace.completed(),
            last.diagnostics.phase == Phase::Landed,
            90.0 - last.theta.to_degrees(),
            1000.0 * rebound
        );
    }
    let vertical = MissionParams::preset("step_vertical").unwrap();
    let level = MissionParams::preset("step_level").unwrap();
    let cases = [
        ("vertical N", vertical, 5.0, Vector3::new(5.0, 0.0, 0.0), 35.0),
        ("vertical E", vertical, 5.0, Vector3::new(0.0, 5.0, 0.0), 35.0),
        ("level down", level, 15.0, Vector3::new(0.0, 0.0, 5.0), 45.0),
        ("level E", level, 15.0, Vector3::new(0.0, 5.0, 0.0), 45.0),
    ];
    for (case, mission, t_step, offset, t_end) in cases {
        let x0 = plant.trim_vertical_climb(mission.v_vertical).unwrap().state;
        let axis = offset.normalize();
        let mut s = Scenario::mission(mission);
        s.stop_time = t_end;
        s.ref_offset_steps = vec![(t_step, offset)];
        let (trace, _) = run(&plant, x0, mission, &s);
        let mut last_out = t_step;
        let mut final_err = f64::NAN;
        for smp in trace.window(t_step, t_end + 1.0) {
            let e = (smp.measurement.pos_ned - smp.diagnostics.ref_pos_ned).dot(&axis).abs();
            if e > 0.5 {
                last_out = smp.t;
            }
            final_err = e;
        }
        println!(
            "step {case:11} completed {} settling {:.2} s final {final_err:.3} m",
            trace.completed(),
            last_out - t_step
        );
    }
}

fn wind() {
    let plant = Plant::new(Airframe::default());
    let mission = MissionParams::default();
    let x0 = plant.trim_vertical_climb(mission.v_vertical).unwrap().state;
    for speed in [3.0, 6.0, 9.0] {
        for (from, bearing) in [("N", 0.0), ("E", 90.0), ("S", 180.0), ("W", 270.0)] {
            let mut s = Scenario::mission(mission);
            s.wind = closed_loop::Wind::Constant(closed_loop::wind_from(f64::to_radians(bearing), speed));
            let (trace, check) = run(&plant, x0, mission, &s);
            println!(
                "wind {speed} m/s from {from}: completed {} criteria {} max err {:.2} m level V err {:.2} final {:.2}°",
                trace.completed_cell(),
                check.verdict(),
                trace.max_pos_error(),
                check.level_airspeed_error,
                check.final_pitch_error.to_degrees()
            );
        }
    }
}

fn trace(args: &[String]) {
    let preset = args.first().map_or("default", String::as_str);
    let jacobi = args.iter().any(|a| a == "jacobi");
    let (mission, plant, x0, stop) = if preset == "takeoff_landing" {
        takeoff_landing()
    } else {
        let m = MissionParams::preset(preset).expect("a declared preset");
        let p = Plant::new(Airframe::default());
        let x0 = p.trim_vertical_climb(m.v_vertical).unwrap().state;
        (m, p, x0, m.end_time())
    };
    let mut s = Scenario::mission(mission);
    s.stop_time = stop;
    if jacobi {
        s.ordering = Ordering::Jacobi;
    }
    if let Ok(step) = std::env::var("STEP") {
        // STEP="t,n,e,d"
        let v: Vec<f64> = step.split(',').map(|x| x.parse().unwrap()).collect();
        s.ref_offset_steps = vec![(v[0], Vector3::new(v[1], v[2], v[3]))];
        s.stop_time = std::env::var("STOP").ok().and_then(|x| x.parse().ok()).unwrap_or(stop);
    }
    if let Ok(w) = std::env::var("WIND") {
        // WIND="speed,from_bearing_deg"
        let v: Vec<f64> = w.split(',').map(|x| x.parse().unwrap()).collect();
        s.wind = closed_loop::Wind::Constant(closed_loop::wind_from(v[1].to_radians(), v[0]));
    }
    let every: usize = std::env::var("EVERY").ok().and_then(|v| v.parse().ok()).unwrap_or(25);
    let mut ctl = controller(mission);
    let mut probe = ctl.clone();
    let trace = fly(&plant, x0, &mut ctl, &s);
    for (k, smp) in trace.samples.iter().enumerate() {
        let input = flight_mission::ControllerInput {
            t: smp.t,
            measurement: smp.measurement,
            ref_offset_ned: s.ref_offset(smp.t),
        };
        let _ = probe.sample(&input);
        if k % every != 0 {
            continue;
        }
        let i = *probe.internals();
        let m = &smp.measurement;
        println!(
            "Vsp {:5.2} t {:6.2} ph {:2} m {} pos ({:7.2} {:6.2} {:7.2}) ref ({:7.2} {:6.2} {:7.2}) V {:5.2} Vref {:5.2} θ {:6.1} α {:6.1} T {:6.1} thr/θsp ({:.2} {:5.1}) err {:6.2}",
            i.airspeed_sp,
            smp.t,
            smp.diagnostics.phase as i32,
            i.mode.map_or(-1, |m| m as i32),
            m.pos_ned.x,
            m.pos_ned.y,
            m.pos_ned.z,
            smp.diagnostics.ref_pos_ned.x,
            smp.diagnostics.ref_pos_ned.y,
            smp.diagnostics.ref_pos_ned.z,
            m.airspeed,
            smp.diagnostics.ref_airspeed,
            smp.theta.to_degrees(),
            m.alpha.to_degrees(),
            smp.command.thrust,
            i.tecs.0,
            i.tecs.1.to_degrees(),
            smp.pos_error()
        );
    }
    println!("failure: {:?}", trace.failure);
    let theta = Plant::new(Airframe::default())
        .trim_level(mission.v_level)
        .unwrap()
        .theta;
    print!("{}", MissionCheck::of(&trace, &mission, theta));
    println!("max pos error {:.2} m", trace.max_pos_error());
}

/// The mission's flight-path profile every 0.25 s: speed, γ, α, pitch, position.
fn profile(preset: &str) {
    let mission = MissionParams::preset(preset).unwrap();
    let pm = guidance::PointMass::from_level_trim(&Airframe::default(), mission.v_level).unwrap();
    let p = guidance::Profile::new(&mission, &pm, &guidance::ProfileLimits::of(&mission)).unwrap();
    let mut t = 0.0;
    while t <= mission.end_time() {
        let q = p.at(t);
        println!(
            "t {t:6.2} V {:5.2} V̇ {:5.2} γ {:6.1} α {:5.1} θ {:6.1} n {:7.2} h {:7.2} T {:6.1}",
            q.v,
            q.v_dot,
            q.gamma.to_degrees(),
            q.alpha.to_degrees(),
            (q.gamma + q.alpha).to_degrees(),
            q.north,
            q.height,
            q.thrust
        );
        t += 0.25;
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match args.first().map(String::as_str) {
        Some("wind") => wind(),
        Some("trace") => trace(&args[1..]),
        Some("profile") => profile(args.get(1).map_or("default", String::as_str)),
        _ => table(),
    }
}
