//! One take-off-to-landing cell of the wind envelope (a development probe):
//! `gearstic_tl_probe lqr|tsd step|turb SPEED BEARING_INDEX [avionics] [jacobi]`. Prints the
//! evaluated flight and the samples from 3 s before the touchdown to the end (every 0.2 s).
use analysis::controllers::Kind;
use analysis::takeoff_landing::{evaluate, fly_wind_cell, mission, tilt};
use analysis::wind_envelope::{StateKind, WindForm};
use closed_loop::Ordering;

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let kind = if a[1] == "lqr" { Kind::Lqr } else { Kind::Tsd };
    let form = if a[2] == "step" {
        WindForm::Step
    } else {
        WindForm::Turbulent
    };
    let speed: f64 = a[3].parse().unwrap();
    let bearing: usize = a[4].parse().unwrap();
    let state = if a.iter().any(|s| s == "avionics") {
        StateKind::Avionics
    } else {
        StateKind::Perfect
    };
    let ordering = if a.iter().any(|s| s == "jacobi") {
        Ordering::Jacobi
    } else {
        Ordering::GaussSeidel
    };
    let (plant, trace) = fly_wind_cell(kind, form, state, ordering, speed, bearing);
    let mut f = evaluate(&plant, kind, ordering, &mission(), &trace);
    f.trajectory.clear();
    println!("{f:#?}");
    let t0 = f.touchdown_time.unwrap_or(0.0) - 3.0;
    let target = f.target;
    for s in trace.samples.iter().filter(|s| s.t >= t0 - 1e-9) {
        if ((s.t * 50.0).round() as i64) % 10 != 0 {
            continue;
        }
        let y = plant.outputs(&s.x, &closed_loop::plant_inputs(&s.command), &s.wind);
        let m = &s.measurement;
        println!(
            "t {:7.2} {:?} dN {:7.3} dE {:7.3} D {:7.3} v {:6.3} {:6.3} {:6.3} T {:6.2} pts {} tilt {:5.1} wind {:5.1} {:5.1}",
            s.t,
            s.diagnostics.phase,
            m.pos_ned.x - target[0],
            m.pos_ned.y - target[1],
            m.pos_ned.z,
            m.vel_ned.x,
            m.vel_ned.y,
            m.vel_ned.z,
            s.command.thrust,
            y.ground.points,
            tilt(&s.x).to_degrees(),
            s.wind.x,
            s.wind.y
        );
    }
}
