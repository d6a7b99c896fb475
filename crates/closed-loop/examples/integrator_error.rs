//! Integration error of the plant's fixed-step integrators (issue 17): every flight flown with
//! a candidate integrator / internal step and compared, at every 20 ms communication point,
//! with a converged reference (RK4 at 0.1 ms, checked against RK4 at 0.05 ms and against the
//! fifth-order method at 0.1 ms).
//!
//! `cargo run --release -p closed-loop --example integrator_error [-- global|thesis|both]`
//!
//! Flights (each with the thesis's and the global aerodynamic model):
//! * LQR and TSD, default mission (closed loop, 35 s);
//! * LQR, violent manoeuvre ([`Scenario::violent_manoeuvre`], 27 s);
//! * open loop, hover trim held in a 5 m/s wind from the north (3 s);
//! * open loop, post-stall: level trim at 20 m/s, elevator −0.3 rad held (the nose rises
//!   past α = 25°) (3 s);
//! * open loop, dropped 3 cm onto the gear, tilted 2°, with the FMU's ground (3 s).
//!
//! Printed per flight: the largest position difference (m) and attitude difference (rad,
//! the angle of q_ref⁻¹ q) over the flight, and the right-hand-side evaluations per 20 ms
//! step (mean over the flight). `CANDIDATES="step,tolerance,max_halvings;…"` replaces the
//! candidate list by checked DP5 variants.

use closed_loop::{fly, plant_inputs, Scenario};
use flight_mission::{FlightController, MissionParams};
use lqr_control::{LqrController, LqrParams};
use nalgebra::{Vector3, Vector4};
use tailsitter_physics::idx::*;
use tailsitter_physics::{
    quat_from_euler_321, AeroModel, Airframe, Ground, InputVector, Integrator, Plant, StateVector,
};
use tsd_control::TsdController;

const H: f64 = 0.02;

#[derive(Clone, Copy)]
enum Flight {
    LqrDefault,
    TsdDefault,
    LqrViolent,
    HoverWind,
    PostStall,
    GroundDrop,
}

impl Flight {
    const ALL: [Flight; 6] = [
        Flight::LqrDefault,
        Flight::TsdDefault,
        Flight::LqrViolent,
        Flight::HoverWind,
        Flight::PostStall,
        Flight::GroundDrop,
    ];
    fn name(self) -> &'static str {
        match self {
            Flight::LqrDefault => "LQR default",
            Flight::TsdDefault => "TSD default",
            Flight::LqrViolent => "LQR violent",
            Flight::HoverWind => "hover 5 m/s wind",
            Flight::PostStall => "post-stall",
            Flight::GroundDrop => "ground drop",
        }
    }
}

fn plant(model: AeroModel, integrator: Integrator, step: f64) -> Plant {
    let mut p = Plant::new(Airframe::default());
    p.aero.model = model;
    p.integrator = integrator;
    p.integration_step = step;
    p
}

/// The states at the communication points and the right-hand-side evaluations per step.
type Flown = (Vec<StateVector>, f64);

fn closed_loop<C: FlightController>(p: &Plant, s: &Scenario, c: &mut C) -> Result<Flown, String> {
    let x0 = p.trim_vertical_climb(s.mission.v_vertical).expect("trim").state;
    let trace = fly(p, x0, c, s);
    if let Some(f) = trace.failure {
        return Err(f);
    }
    // Replay each step to count the evaluations (deterministic: the same result).
    let mut evals = 0;
    for w in trace.samples.windows(2) {
        let mut x = w[0].x;
        p.advance_counting(&mut x, &plant_inputs(&w[0].command), &w[0].wind, H, &mut evals)
            .unwrap();
        assert_eq!(x, w[1].x, "replay");
    }
    let steps = trace.samples.len() as f64 - 1.0;
    Ok((trace.samples.iter().map(|s| s.x).collect(), evals as f64 / steps))
}

fn open_loop(p: &Plant, mut x: StateVector, u: &InputVector, wind: &Vector3<f64>, t: f64) -> Result<Flown, String> {
    let n = (t / H).round() as usize;
    let mut out = vec![x];
    let mut evals = 0;
    for _ in 0..n {
        p.advance_counting(&mut x, u, wind, H, &mut evals)
            .map_err(|e| e.to_string())?;
        out.push(x);
    }
    Ok((out, evals as f64 / n as f64))
}

fn fly_flight(f: Flight, model: AeroModel, integrator: Integrator, step: f64) -> Result<Flown, String> {
    let p = plant(model, integrator, step);
    match f {
        Flight::LqrDefault | Flight::LqrViolent => {
            let s = if matches!(f, Flight::LqrDefault) {
                Scenario::mission(MissionParams::default())
            } else {
                Scenario::violent_manoeuvre()
            };
            let mut c = LqrController::new(Airframe::default(), s.mission, LqrParams::default()).unwrap();
            closed_loop(&p, &s, &mut c)
        }
        Flight::TsdDefault => {
            let s = Scenario::mission(MissionParams::default());
            let mut c = TsdController::with_mission(s.mission).unwrap();
            closed_loop(&p, &s, &mut c)
        }
        Flight::HoverWind => {
            let trim = p.trim_vertical_climb(0.0).unwrap();
            open_loop(&p, trim.state, &trim.inputs, &Vector3::new(-5.0, 0.0, 0.0), 3.0)
        }
        Flight::PostStall => {
            let trim = p.trim_level(20.0).unwrap();
            let mut u = trim.inputs;
            u[ELEVATOR_CMD] = -0.3;
            open_loop(&p, trim.state, &u, &Vector3::zeros(), 3.0)
        }
        Flight::GroundDrop => {
            let mut p = p;
            p.ground = Ground::default();
            let mut x = p.resting_on_ground(0.0, 0.0, 0.0);
            x[POS_D] -= 0.03;
            x.fixed_rows_mut::<4>(Q1)
                .copy_from(&quat_from_euler_321(0.0, 88f64.to_radians(), 0.0));
            open_loop(&p, x, &InputVector::zeros(), &Vector3::zeros(), 3.0)
        }
    }
}

/// (max position difference (m), max attitude difference (rad)).
fn diff(a: &[StateVector], b: &[StateVector]) -> (f64, f64) {
    assert_eq!(a.len(), b.len());
    let (mut dp, mut da) = (0.0f64, 0.0f64);
    for (x, y) in a.iter().zip(b) {
        dp = dp.max((x.fixed_rows::<3>(POS_N) - y.fixed_rows::<3>(POS_N)).norm());
        let qa: Vector4<f64> = x.fixed_rows::<4>(Q1).into_owned();
        let qb: Vector4<f64> = y.fixed_rows::<4>(Q1).into_owned();
        // Angle between the attitudes: 2 asin(|q_a − ±q_b| / 2), the sign that is closer.
        let d = (qa - qb).norm().min((qa + qb).norm());
        da = da.max(2.0 * (0.5 * d).min(1.0).asin());
    }
    (dp, da)
}

fn main() {
    let which = std::env::args().nth(1).unwrap_or_else(|| "both".into());
    let models: Vec<AeroModel> = match which.as_str() {
        "global" => vec![AeroModel::Global],
        "thesis" => vec![AeroModel::Thesis],
        _ => vec![AeroModel::Global, AeroModel::Thesis],
    };
    let mut candidates: Vec<(Integrator, f64)> = vec![
        (Integrator::Rk4, 0.002),
        (Integrator::Rk4, 0.004),
        (Integrator::Rk4, 0.005),
        (Integrator::Rk4, 0.01),
        (Integrator::Dp5, 0.004),
        (Integrator::Dp5, 0.005),
        (Integrator::Dp5, H / 3.0),
        (Integrator::Dp5, 0.01),
        (Integrator::Dp5, 0.02),
    ];
    for (step, tolerance) in [
        (0.005, 1e-9),
        (H / 3.0, 4e-9),
        (H / 3.0, 2e-9),
        (H / 3.0, 1e-9),
        (0.01, 1e-9),
        (0.01, 3e-10),
    ] {
        candidates.push((
            Integrator::Dp5Checked {
                tolerance,
                max_halvings: 4,
            },
            step,
        ));
    }
    if let Ok(extra) = std::env::var("CANDIDATES") {
        // "step,tolerance,max_halvings;…"
        candidates.clear();
        candidates.push((Integrator::Rk4, 0.002));
        for c in extra.split(';') {
            let v: Vec<f64> = c.split(',').map(|t| t.parse().unwrap()).collect();
            candidates.push((
                Integrator::Dp5Checked {
                    tolerance: v[1],
                    max_halvings: v[2] as u32,
                },
                v[0],
            ));
        }
    }
    for model in models {
        println!("\n## aero {model:?}: max position difference (m) / attitude difference (rad) against RK4 at 0.1 ms; right-hand sides per 20 ms in brackets\n");
        let mut header = String::from("| integrator, step |");
        for f in Flight::ALL {
            header.push_str(&format!(" {} |", f.name()));
        }
        println!("{header}");
        println!("|---|{}", "---|".repeat(Flight::ALL.len()));
        let refs: Vec<Vec<StateVector>> = Flight::ALL
            .iter()
            .map(|&f| {
                fly_flight(f, model, Integrator::Rk4, 1e-4)
                    .unwrap_or_else(|e| panic!("{}: {e}", f.name()))
                    .0
            })
            .collect();
        let mut rows: Vec<(String, Integrator, f64)> = Vec::new();
        if std::env::var_os("CANDIDATES").is_none() {
            rows.push(("RK4 0.05 ms (reference check)".into(), Integrator::Rk4, 5e-5));
            rows.push(("DP5 0.1 ms (reference check)".into(), Integrator::Dp5, 1e-4));
        }
        for (integrator, step) in &candidates {
            let label = match integrator {
                Integrator::Dp5Checked {
                    tolerance,
                    max_halvings,
                } => format!(
                    "DP5 checked {:.3} ms, tol {tolerance:.0e}, ≤ {max_halvings} halvings",
                    step * 1e3
                ),
                other => format!("{other:?} {:.3} ms", step * 1e3),
            };
            rows.push((label, *integrator, *step));
        }
        for (label, integrator, step) in rows {
            let mut row = format!("| {label} |");
            for (f, r) in Flight::ALL.iter().zip(&refs) {
                match fly_flight(*f, model, integrator, step) {
                    Ok((x, n)) => {
                        let (dp, da) = diff(&x, r);
                        row.push_str(&format!(" {dp:.1e} / {da:.1e} ({n:.1}) |"));
                    }
                    Err(e) => row.push_str(&format!(" failed: {e} |")),
                }
            }
            println!("{row}");
        }
    }
}
