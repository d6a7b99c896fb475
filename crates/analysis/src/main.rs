use analysis::closed::{poles_at, Condition};
use analysis::linalg::fmt_pole;
use flight_mission::MissionParams;
use tailsitter_physics::{Airframe, Plant};

fn main() {
    let plant = Plant::new(Airframe::default());
    let m = analysis::modes::level_modes(&plant, 25.0).unwrap();
    for md in &m.modes {
        println!("{:20} {:.3} ± {:.3}i  {:?}", md.name, md.re, md.im, md.shape);
    }
    let m = analysis::modes::vertical_modes(&plant, 3.0).unwrap();
    for md in &m.modes {
        println!("{:20} {:.3} ± {:.3}i", md.name, md.re, md.im);
    }
    let mission = MissionParams::default();
    for cond in Condition::ALL {
        let t0 = std::time::Instant::now();
        let c = lqr_control::LqrController::new(Airframe::default(), mission, Default::default()).unwrap();
        let p = poles_at(&plant, c, &mission, cond);
        println!("LQR {cond:?} {:?}", t0.elapsed());
        if let Ok(p) = p { println!("{}", p.poles.iter().map(|s| fmt_pole(*s)).collect::<Vec<_>>().join(", ")); } else { println!("{p:?}"); }
        let t0 = std::time::Instant::now();
        let c = tsd_control::TsdController::new(Default::default(), mission, Airframe::default()).unwrap();
        let p = poles_at(&plant, c, &mission, cond);
        println!("TSD {cond:?} {:?}", t0.elapsed());
        if let Ok(p) = p { println!("{}", p.poles.iter().map(|s| fmt_pole(*s)).collect::<Vec<_>>().join(", ")); } else { println!("{p:?}"); }
    }
    let t0 = std::time::Instant::now();
    let mut c = lqr_control::LqrController::new(Airframe::default(), mission, Default::default()).unwrap();
    let x0 = plant.trim_vertical_climb(3.0).unwrap().state;
    let tr = closed_loop::fly(&plant, x0, &mut c, &closed_loop::Scenario::mission(mission));
    println!("LQR mission {:?} {:?}", t0.elapsed(), tr.failure);
    let t0 = std::time::Instant::now();
    let mut c = tsd_control::TsdController::new(Default::default(), mission, Airframe::default()).unwrap();
    let tr = closed_loop::fly(&plant, x0, &mut c, &closed_loop::Scenario::mission(mission));
    println!("TSD mission {:?} {:?}", t0.elapsed(), tr.failure);
}
