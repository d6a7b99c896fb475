//! Transition probe (issue 16): default, fast 3/4 and 2/3 missions, both controllers, both orderings.
//! `cargo run --release -p closed-loop --example envelope_probe`
use closed_loop::{fly, Ordering, Scenario, Trace};
use flight_mission::{FlightController, MissionParams};
use lqr_control::{LqrController, LqrParams};
use tailsitter_physics::{Airframe, Plant};
use tsd_control::{TsdController, TsdParams};

fn stats(trace: &Trace, m: &MissionParams) -> String {
    let s = m.phase_starts();
    let mut out = String::new();
    for (a, b) in [(s[1], s[2]), (s[3], s[4])] {
        let amax = trace
            .window(a, b)
            .map(|x| x.measurement.alpha)
            .fold(f64::NEG_INFINITY, f64::max);
        let amin = trace
            .window(a, b)
            .map(|x| x.measurement.alpha)
            .fold(f64::INFINITY, f64::min);
        let dh = trace
            .window(a, b + 1.0)
            .map(|x| (x.measurement.pos_ned.z - x.diagnostics.ref_pos_ned.z).abs())
            .fold(0.0, f64::max);
        let tmax = trace.window(a, b).map(|x| x.command.thrust).fold(0.0, f64::max);
        out += &format!(
            "α {:6.1}/{:6.1}° dh {:5.2} m Tc≤{:5.1} | ",
            amin.to_degrees(),
            amax.to_degrees(),
            dh,
            tmax
        );
    }
    out += &format!("max err {:6.2} m", trace.max_pos_error());
    if let Some(f) = &trace.failure {
        out += &format!(" FAIL {f}");
    }
    out
}

fn run<C: FlightController>(mut c: C, m: MissionParams, ord: Ordering) -> String {
    let plant = Plant::new(Airframe::default());
    let x0 = plant.trim_vertical_climb(m.v_vertical).unwrap().state;
    let mut sc = Scenario::mission(m);
    sc.ordering = ord;
    sc.stop_time += 3.0;
    stats(&fly(&plant, x0, &mut c, &sc), &m)
}

fn main() {
    let conf: i32 = std::env::args().nth(1).map(|s| s.parse().unwrap()).unwrap_or(0);
    for (t1, t2) in [(5.0, 10.0), (3.0, 4.0), (2.0, 3.0)] {
        let m = MissionParams {
            t_transition_1: t1,
            t_transition_2: t2,
            ..Default::default()
        };
        for ord in [Ordering::GaussSeidel, Ordering::Jacobi] {
            let l = LqrController::new(
                Airframe::default(),
                m,
                LqrParams {
                    configuration: conf,
                    ..Default::default()
                },
            )
            .map(|c| run(c, m, ord))
            .unwrap_or_else(|e| e.0);
            println!("{t1}/{t2} {ord:?} LQR {l}");
            let t = TsdController::new(
                Airframe::default(),
                m,
                TsdParams {
                    configuration: conf,
                    ..Default::default()
                },
            )
            .map(|c| run(c, m, ord))
            .unwrap_or_else(|e| e.0);
            println!("{t1}/{t2} {ord:?} TSD {t}");
        }
    }
}
