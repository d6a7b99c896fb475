//! Time history of one wind-envelope cell:
//! `wind_probe lqr|tsd default|tl step|turb speed bearing_index [dt]` prints every `dt` s
//! (default 1): time, phase, position error (N, E, D), airspeed, α, β, heading, pitch,
//! thrust and surfaces, then the cell's verdict.
use analysis::controllers::Kind;
use analysis::takeoff_landing;
use analysis::wind_envelope::{fly_cell, plant, trimmed_climb, wind, MissionKind, WindForm};
use closed_loop::{fly, Scenario};

fn main() {
    let a: Vec<String> = std::env::args().collect();
    if a[1] == "grid" {
        // `wind_probe grid lqr|tsd default|tl step|turb`: the cells' largest errors.
        let kind = if a[2] == "lqr" { Kind::Lqr } else { Kind::Tsd };
        let mk = if a[3] == "tl" {
            MissionKind::TakeoffLanding
        } else {
            MissionKind::Default
        };
        let form = if a[4] == "turb" {
            WindForm::Turbulent
        } else {
            WindForm::Step
        };
        use rayon::prelude::*;
        let jobs: Vec<(f64, usize)> = analysis::wind_envelope::SPEEDS
            .iter()
            .flat_map(|&s| (0..8).map(move |b| (s, b)))
            .collect();
        let cells: Vec<_> = jobs.par_iter().map(|&(s, b)| fly_cell(kind, mk, form, s, b)).collect();
        for s in analysis::wind_envelope::SPEEDS {
            let row: Vec<_> = cells.iter().filter(|c| c.speed == s).collect();
            let held = row.iter().filter(|c| c.held).count();
            let errs: Vec<String> = row
                .iter()
                .map(|c| {
                    let mut t = format!("{:.1}", c.max_error);
                    if let Some(d) = c.landing_distance {
                        t += &format!("/{:.2}/{:.2}", d, c.touchdown_speed.unwrap_or(f64::NAN));
                    }
                    if !c.completed {
                        t += "!";
                    }
                    t
                })
                .collect();
            println!("{s:4} m/s held {held}/8: {}", errs.join(" "));
        }
        return;
    }
    let kind = if a[1] == "lqr" { Kind::Lqr } else { Kind::Tsd };
    let mk = if a[2] == "tl" {
        MissionKind::TakeoffLanding
    } else {
        MissionKind::Default
    };
    let form = if a[3] == "turb" {
        WindForm::Turbulent
    } else {
        WindForm::Step
    };
    let speed: f64 = a[4].parse().unwrap();
    let b: usize = a[5].parse().unwrap();
    let dt: f64 = a.get(6).map_or(1.0, |s| s.parse().unwrap());
    let p = plant();
    let (mission, x0, stop) = match mk {
        MissionKind::Default | MissionKind::Handover => {
            let m = mk.mission();
            (m, trimmed_climb(&p, m.v_vertical).unwrap(), m.end_time() + 5.0)
        }
        MissionKind::TakeoffLanding => {
            let m = takeoff_landing::mission();
            (m, p.resting_on_ground(0.0, 0.0, 0.0), takeoff_landing::stop_time(&m))
        }
    };
    let mut s = Scenario::mission(mission);
    s.stop_time = stop;
    s.wind = wind(form, speed, b, p.ground.height);
    let mut c = kind.make(&mission);
    let trace = fly(&p, x0, &mut c, &s);
    let mut next = 0.0;
    println!("t phase eN eE eD V alpha beta belly nose theta T de da dr dfc dfd dv");
    for smp in &trace.samples {
        if smp.t + 1e-9 < next {
            continue;
        }
        next += dt;
        let m = &smp.measurement;
        let e = m.pos_ned - smp.diagnostics.ref_pos_ned;
        let q = m.quat;
        let (w, x, y, z) = (q[3], q[0], q[1], q[2]);
        // Bearings of the belly (body z) and the nose (body x) in the horizontal plane.
        let r = nalgebra::UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(w, x, y, z));
        let bz = r * nalgebra::Vector3::z();
        let bx = r * nalgebra::Vector3::x();
        let psi = bz.y.atan2(bz.x);
        let nose = bx.y.atan2(bx.x);
        let sf = m.surfaces.map(f64::to_degrees);
        println!(
            "{:6.2} {:2} {:7.2} {:7.2} {:7.2} {:5.1} {:6.1} {:6.1} {:6.1} {:6.1} {:5.1} {:5.1} {:5.1} {:5.1} {:5.1} {:5.1} {:5.1} {:5.1}",
            smp.t,
            smp.diagnostics.phase as i32,
            e.x,
            e.y,
            e.z,
            m.airspeed,
            m.alpha.to_degrees(),
            m.beta.to_degrees(),
            psi.to_degrees(),
            nose.to_degrees(),
            smp.theta.to_degrees(),
            m.thrust,
            sf[0],
            sf[1],
            sf[2],
            sf[3],
            sf[4],
            sf[5]
        );
    }
    println!("failure: {:?}", trace.failure);
    let pe: Vec<String> = trace.phase_errors().iter().map(|e| format!("{:.2}", e.max)).collect();
    println!("max error per phase: {}", pe.join(" "));
    let cell = fly_cell(kind, mk, form, speed, b);
    println!("{cell:?}");
}
