//! Time history of one gust case of issue 16 (`analysis::envelope_hover`): the tuned LQR on the
//! default mission, global aerodynamics, a 5 m/s 2 s 1 − cos gust along AXIS (0 N, 1 E, 2 D;
//! 3 = no gust) centred on the middle of PHASE. `gust_trace AXIS PHASE [jacobi] [every]`.
use closed_loop::{fly, Ordering, Scenario, Wind};
use flight_mission::MissionParams;
use lqr_control::{LqrController, LqrParams};
use tailsitter_physics::{AeroModel, Airframe, Ground, Plant};

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let axis: usize = a[1].parse().unwrap();
    let phase: usize = a[2].parse().unwrap();
    let jacobi = a.get(3).is_some_and(|s| s == "jacobi");
    let every: usize = a.get(4).map_or(10, |s| s.parse().unwrap());
    let mut p = Plant::new(Airframe::default());
    p.aero.model = AeroModel::Global;
    p.ground = Ground::default();
    let m = MissionParams::default();
    let st = m.phase_starts();
    let mid = 0.5 * (st[phase] + st[phase + 1]);
    let mut s = Scenario::mission(m);
    s.stop_time = m.end_time() + 5.0;
    s.ordering = if jacobi {
        Ordering::Jacobi
    } else {
        Ordering::GaussSeidel
    };
    let t0 = mid - 1.0;
    if axis < 3 {
        s.wind = Wind::gust_along(axis, 5.0, t0, 2.0);
    }
    let mut c = LqrController::new(Airframe::default(), m, LqrParams::default()).unwrap();
    let x0 = p.trim_vertical_climb(m.v_vertical).unwrap().state;
    let tr = fly(&p, x0, &mut c, &s);
    println!("t err dN dE dD V alpha beta p q r T de da dr dfc");
    for smp in tr.samples.iter().step_by(every) {
        if smp.t < t0 - 0.5 || smp.t > t0 + 10.0 {
            continue;
        }
        let e = smp.measurement.pos_ned - smp.diagnostics.ref_pos_ned;
        let c = smp.command;
        let me = &smp.measurement;
        println!(
            "{:5.2} {:5.2} {:6.2} {:6.2} {:6.2} {:5.1} {:6.1} {:6.1} {:6.2} {:6.2} {:6.2} {:6.1} {:6.1} {:6.1} {:6.1} {:6.1}",
            smp.t, smp.pos_error(), e.x, e.y, e.z, me.airspeed, me.alpha.to_degrees(), me.beta.to_degrees(),
            me.rates.x, me.rates.y, me.rates.z, c.thrust, c.elevator.to_degrees(), c.aileron.to_degrees(),
            c.rudder.to_degrees(), c.flap_collective.to_degrees()
        );
    }
    println!("{:?}", tr.failure);
}
