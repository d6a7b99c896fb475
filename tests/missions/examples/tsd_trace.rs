//! Print a closed-loop time series of the TSD controller (debugging and tuning aid).
//!
//! `cargo run --release -p missions --example tsd_trace -- <case> [every_s]`
//! with case one of `default`, `fast` (3/4 s), `fast2` / `fast2j` (2/3 s, Gauss-Seidel / Jacobi), `jacobi`, `vstep-n`, `vstep-e`, `lstep-d`, `lstep-e`, `hover`
//! (40 s of vertical flight); a constant wind with `TSD_WIND=n,e,d` (m/s, NED).

use closed_loop::{measure, pitch, plant_inputs, Ordering, Scenario};
use flight_mission::{ControllerInput, MissionParams, SampledUnit};
use nalgebra::Vector3;
use tailsitter_physics::{Airframe, InputVector, Plant};
use tsd_control::TsdController;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let case = args.get(1).map(String::as_str).unwrap_or("default");
    let every: f64 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(0.5);
    let from: f64 = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(0.0);
    let until: f64 = args.get(4).and_then(|s| s.parse().ok()).unwrap_or(1e9);
    let mut mission = MissionParams::default();
    let mut ordering = Ordering::GaussSeidel;
    let mut steps: Vec<(f64, Vector3<f64>)> = Vec::new();
    let mut stop = None;
    match case {
        "fast" => {
            mission.t_transition_1 = 3.0;
            mission.t_transition_2 = 4.0;
        }
        "fast2" | "fast2j" => {
            mission.t_transition_1 = 2.0;
            mission.t_transition_2 = 3.0;
            if case == "fast2j" {
                ordering = Ordering::Jacobi;
            }
        }
        "jacobi" => ordering = Ordering::Jacobi,
        "vstep-n" | "vstep-e" => {
            mission.t_vertical_1 = 40.0;
            let off = if case == "vstep-n" {
                Vector3::new(5.0, 0.0, 0.0)
            } else {
                Vector3::new(0.0, 5.0, 0.0)
            };
            steps.push((5.0, off));
            stop = Some(35.0);
        }
        "lstep-d" | "lstep-e" => {
            mission.t_level = 40.0;
            let off = if case == "lstep-d" {
                Vector3::new(0.0, 0.0, 5.0)
            } else {
                Vector3::new(0.0, 5.0, 0.0)
            };
            steps.push((15.0, off));
            stop = Some(45.0);
        }
        "hover" => {
            mission.t_vertical_1 = 40.0;
            stop = Some(35.0);
        }
        _ => {}
    }
    // Constant wind (NED, m/s) from the environment: `TSD_WIND=n,e,d`.
    let wind = std::env::var("TSD_WIND")
        .ok()
        .map(|s| {
            let v: Vec<f64> = s
                .split(',')
                .map(|x| x.trim().parse().expect("TSD_WIND=n,e,d"))
                .collect();
            Vector3::new(v[0], v[1], v[2])
        })
        .unwrap_or_else(Vector3::zeros);
    let plant = Plant::new(Airframe::default());
    let mut x = plant.trim_vertical_climb(mission.v_vertical).unwrap().state;
    let mut ctl = TsdController::with_mission(mission).unwrap();
    let mut scenario = Scenario::mission(mission);
    scenario.ordering = ordering;
    scenario.ref_offset_steps = steps;
    let stop = stop.unwrap_or(mission.end_time());
    let h = mission.sample_time;
    let n = (stop / h).round() as usize;
    let mut prev = None;
    let mut u = InputVector::zeros();
    println!("     t ph   err_n   err_e   err_d  theta  alpha   beta    V     T     de     da     dr   Ac     Bc     Cc    Aw    Bw    Cw   phiE   w     p     q     r   vcmd");
    for k in 0..=n {
        let t = k as f64 * h;
        let meas = measure(&plant, &x, &u, &wind);
        let out = ctl
            .sample(&ControllerInput {
                t,
                measurement: meas,
                ref_offset_ned: scenario.ref_offset(t),
            })
            .unwrap_or_else(|e| panic!("{e}"));
        let cmd = match ordering {
            Ordering::GaussSeidel => out.command,
            Ordering::Jacobi => prev.unwrap_or(out.command),
        };
        prev = Some(out.command);
        let i = ctl.internals();
        if t >= from - 1e-9 && t <= until && (t / every - (t / every).round()).abs() < 1e-6 {
            let e = meas.pos_ned - out.diagnostics.ref_pos_ned;
            println!(
                "{t:6.2} {} {:7.2} {:7.2} {:7.2} {:6.1} {:6.1} {:6.1} {:5.1} {:5.1} {:6.1} {:6.1} {:6.1} {:6.2} {:6.2} {:6.2} {:5.2} {:5.2} {:5.2} {:6.1} {:4.2} {:5.2} {:5.2} {:5.2} {:?}",
                out.diagnostics.phase as i32,
                e.x, e.y, e.z,
                pitch(&x).to_degrees(), meas.alpha.to_degrees(), meas.beta.to_degrees(), meas.airspeed, cmd.thrust,
                cmd.elevator.to_degrees(), cmd.aileron.to_degrees(), cmd.rudder.to_degrees(),
                i.accel_cmd.x, i.accel_cmd.y, i.accel_cmd.z, i.accel.x, i.accel.y, i.accel.z,
                i.roll_error.to_degrees(), i.normal_weight, meas.rates.x, meas.rates.y, meas.rates.z, i.virtual_cmd.map(|v| (v * 1000.0).round() / 1000.0),
            );
        }
        u = plant_inputs(&cmd);
        if k == n {
            break;
        }
        if let Err(e) = plant.advance(&mut x, &u, &wind, h) {
            println!("plant failed at {t}: {e}");
            break;
        }
    }
}
