//! Issue 15, item 5: closed-loop poles of the TSD in the vertical climb at `v_vertical`
//! (3 m/s), tuned (`configuration` 0: reference-path frame below 4 m/s) against the thesis
//! configuration (1: the wind axes at every airspeed), nominal plant and design model.
//! Prints the unstable poles (Re s > 0) and the least damped ones.
//! `cargo run --release -p analysis --example tsd_thesis_vertical_poles`
use analysis::closed::{poles_at, Condition};
use flight_mission::MissionParams;
use tailsitter_physics::{Airframe, Plant};
use tsd_control::{TsdController, TsdParams};

fn main() {
    let mission = MissionParams::default();
    let plant = Plant::new(Airframe::default());
    for (name, p) in [
        ("tuned", TsdParams::default()),
        (
            "thesis",
            TsdParams {
                configuration: 1,
                ..TsdParams::default()
            },
        ),
        (
            "thesis frame, with preview",
            TsdParams {
                wind_frame_speed_low: 0.0,
                wind_frame_speed_high: 1e-6,
                ..TsdParams::default()
            },
        ),
    ] {
        let c = TsdController::new(Airframe::default(), mission, p).expect("parameters");
        let poles = poles_at(&plant, c, &mission, Condition::Vertical).expect("operating point");
        let mut s: Vec<_> = poles.poles.iter().filter(|s| s.im >= 0.0).collect();
        s.sort_by(|a, b| b.re.partial_cmp(&a.re).unwrap());
        let top: Vec<String> = s.iter().take(6).map(|s| format!("{:.3}{:+.3}i", s.re, s.im)).collect();
        println!("{name:>28}: rightmost poles s (1/s): {}", top.join(", "));
    }
}
