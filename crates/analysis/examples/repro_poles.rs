//! All closed-loop poles of the TSD in `configuration` (default 1) at level and vertical
//! flight (the poles behind the reproduction's Table 4.4).
//! `cargo run --release -p analysis --example repro_poles [configuration]`
use analysis::closed::Condition;
use analysis::controllers::Kind;
use analysis::reproduction::poles;
use flight_mission::MissionParams;
use tailsitter_physics::Airframe;

fn main() {
    let conf: i32 = std::env::args().nth(1).and_then(|a| a.parse().ok()).unwrap_or(1);
    for cond in Condition::ALL {
        let mut p = poles(&Airframe::default(), Kind::Tsd, conf, &MissionParams::default(), cond).unwrap_or_default();
        p.retain(|s| s.im >= 0.0);
        p.sort_by(|a, b| b.re.total_cmp(&a.re));
        let s: Vec<String> = p.iter().map(|s| format!("{:.2}{:+.2}i", s.re, s.im)).collect();
        println!("{}: {}", cond.name(), s.join(", "));
    }
}
