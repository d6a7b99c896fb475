use closed_loop::{fly, Ordering, Scenario};
use flight_mission::MissionParams;
use tailsitter_physics::{Airframe, Plant};
use tsd_control::{TsdController, TsdParams};
fn main() {
    let mut p = TsdParams::default();
    let mut verbose = false;
    for a in std::env::args().skip(1) {
        if a == "-v" {
            verbose = true;
            continue;
        }
        let (k, v) = a.split_once('=').unwrap();
        let v: f64 = v.parse().unwrap();
        match k {
            "gre" => p.guidance_pole_re_vertical = v,
            "gim" => p.guidance_pole_im_vertical = v,
            "glre" => p.guidance_pole_re_level = v,
            "glim" => p.guidance_pole_im_level = v,
            "lead" => p.feedforward_lead = v,
            "wlo" => p.wind_frame_speed_low = v,
            "whi" => p.wind_frame_speed_high = v,
            "nr" => p.normal_pole_real_vertical = v,
            "nre" => p.normal_pole_re_vertical = v,
            "nvd" => p.nvd_pole_vertical = v,
            "ax" => {
                p.axial_pole_1_vertical = v;
                p.axial_pole_1_level = v;
            }
            _ => panic!("{k}"),
        }
    }
    for (t1, t2) in [(5.0, 10.0), (3.0, 4.0), (2.0, 3.0)] {
        let m = MissionParams {
            t_transition_1: t1,
            t_transition_2: t2,
            ..Default::default()
        };
        for ord in [Ordering::GaussSeidel, Ordering::Jacobi] {
            let plant = Plant::new(Airframe::default());
            let x0 = plant.trim_vertical_climb(3.0).unwrap().state;
            let mut c = TsdController::new(Airframe::default(), m, p).unwrap();
            let mut sc = Scenario::mission(m);
            sc.ordering = ord;
            let tr = fly(&plant, x0, &mut c, &sc);
            let s = m.phase_starts();
            let amax = tr
                .window(s[1], s[5])
                .map(|x| x.measurement.alpha.abs())
                .fold(0.0, f64::max);
            let dh1 = tr
                .window(s[1], s[2] + 1.0)
                .map(|x| (x.measurement.pos_ned.z - x.diagnostics.ref_pos_ned.z).abs())
                .fold(0.0, f64::max);
            print!(
                "{t1}/{t2} {:?}: err {:.2} α {:.1} dh1 {:.2} {}| ",
                ord,
                tr.max_pos_error(),
                amax.to_degrees(),
                dh1,
                if tr.completed() { "" } else { "FAIL" }
            );
            if verbose && t1 == 3.0 && ord == Ordering::GaussSeidel {
                for s in tr.samples.iter().filter(|s| s.t > 4.9 && s.t < 12.0).step_by(10) {
                    let e = s.measurement.pos_ned - s.diagnostics.ref_pos_ned;
                    println!(
                        "{:5.2} eN {:6.2} eD {:6.2} α {:6.1} θ {:6.1} V {:5.1} Vref {:5.1} Tc {:6.1}",
                        s.t,
                        e.x,
                        e.z,
                        s.measurement.alpha.to_degrees(),
                        s.theta.to_degrees(),
                        s.measurement.airspeed,
                        s.diagnostics.ref_airspeed,
                        s.command.thrust
                    );
                }
            }
        }
    }
    println!();
}
