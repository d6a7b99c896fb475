//! PX4's closed-loop poles at level and vertical flight of the default mission: the largest
//! |z| and the six s-plane poles of largest real part (upper half plane).
//! `cargo run --release -p analysis --example px4_poles`
use analysis::closed::{poles_at, Condition};
use analysis::controllers::Kind;
use flight_mission::MissionParams;
use tailsitter_physics::{Airframe, Plant};

fn main() {
    let mission = MissionParams::default();
    let plant = Plant::new(Airframe::default());
    for cond in Condition::ALL {
        match poles_at(&plant, Kind::Px4.make(&mission), &mission, cond) {
            Ok(p) => {
                let mut s: Vec<_> = p.poles.iter().copied().filter(|s| s.im >= 0.0).collect();
                s.sort_by(|a, b| b.re.total_cmp(&a.re));
                let t: Vec<String> = s.iter().take(6).map(|s| format!("{:.3}{:+.2}i", s.re, s.im)).collect();
                let z = p.discrete.iter().map(|e| e.value.norm()).fold(0.0, f64::max);
                println!("{}: max |z| = {z:.5}; {}", cond.name(), t.join(", "));
            }
            Err(e) => println!("{}: {e:?}", cond.name()),
        }
    }
}
