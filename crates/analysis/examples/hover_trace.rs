//! Time history of one hover-wind case: `hover_trace lqr|tsd speed from_deg [jacobi] [cfg]`.
use analysis::envelope_hover::{hover_mission, plant, STEP_STOP, STEP_TIME};
use closed_loop::{fly, Ordering, Scenario, Trace, Wind};
use flight_mission::FlightController;
use tailsitter_physics::Airframe;

fn run<C: FlightController>(c: &mut C, s: &Scenario) -> Trace {
    let p = plant();
    let x0 = p.trim_vertical_climb(s.mission.v_vertical).unwrap().state;
    fly(&p, x0, c, s)
}

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let speed: f64 = a[2].parse().unwrap();
    let from: f64 = a[3].parse().unwrap();
    let jacobi = a.get(4).is_some_and(|s| s == "jacobi");
    let cfg: i32 = a.get(5).map_or(0, |s| s.parse().unwrap());
    let m = hover_mission();
    let mut s = Scenario::mission(m);
    s.stop_time = STEP_STOP;
    s.ordering = if jacobi {
        Ordering::Jacobi
    } else {
        Ordering::GaussSeidel
    };
    s.wind = Wind::step_from(STEP_TIME, from.to_radians(), speed);
    if let Ok(g) = std::env::var("GUST") {
        // GUST=axis,phase: the envelope's gust case (`speed`, `from_deg` unused).
        let v: Vec<usize> = g.split(',').map(|x| x.parse().unwrap()).collect();
        let mission = flight_mission::MissionParams::default();
        let starts = mission.phase_starts();
        let mid = 0.5 * (starts[v[1]] + starts[v[1] + 1]);
        s = Scenario::mission(mission);
        s.stop_time = mission.end_time() + 5.0;
        s.ordering = if jacobi {
            Ordering::Jacobi
        } else {
            Ordering::GaussSeidel
        };
        s.wind = Wind::gust_along(v[0], analysis::envelope_hover::GUST_AMPLITUDE, mid - 1.0, 2.0);
        eprintln!("gust from {} s", mid - 1.0);
    }
    let trace = if a[1] == "lqr" {
        let mut c = lqr_control::LqrController::new(
            Airframe::default(),
            s.mission,
            lqr_control::LqrParams {
                configuration: cfg,
                ..Default::default()
            },
        )
        .unwrap();
        run(&mut c, &s)
    } else {
        let mut c = tsd_control::TsdController::new(
            Airframe::default(),
            s.mission,
            tsd_control::TsdParams {
                configuration: cfg,
                ..Default::default()
            },
        )
        .unwrap();
        run(&mut c, &s)
    };
    println!("t err dN dE dD V alpha beta tilt_deg nose_az belly_az p q r T_cmd de da dr dfc dfd dv");
    let every: usize = std::env::var("EVERY").ok().and_then(|s| s.parse().ok()).unwrap_or(10);
    for smp in trace.samples.iter().step_by(every) {
        let q = smp.measurement.quat;
        let r = nalgebra::UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(q[3], q[0], q[1], q[2]));
        let x = r * nalgebra::Vector3::x();
        let z = r * nalgebra::Vector3::z();
        let e = smp.measurement.pos_ned - smp.diagnostics.ref_pos_ned;
        let c = smp.command;
        println!(
            "{:5.1} {:6.2} {:6.2} {:6.2} {:6.2} {:5.1} {:6.1} {:6.1} {:6.1} {:6.0} {:6.0} {:6.2} {:6.2} {:6.2} {:6.1} {:6.1} {:6.1} {:6.1} {:6.1} {:6.1} {:6.1}",
            smp.t,
            smp.pos_error(),
            e.x, e.y, e.z,
            smp.measurement.airspeed,
            smp.measurement.alpha.to_degrees(),
            smp.measurement.beta.to_degrees(),
            (-x.z).clamp(-1.0, 1.0).acos().to_degrees(),
            x.y.atan2(x.x).to_degrees(),
            z.y.atan2(z.x).to_degrees(),
            smp.measurement.rates.x, smp.measurement.rates.y, smp.measurement.rates.z,
            c.thrust, c.elevator.to_degrees(), c.aileron.to_degrees(), c.rudder.to_degrees(),
            c.flap_collective.to_degrees(), c.flap_differential.to_degrees(), c.vertical_flap.to_degrees()
        );
    }
    println!("{:?}", trace.failure);
}
