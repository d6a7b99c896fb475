//! Hover in a steady wind *step* (issue 16), the cases of `analysis::envelope_hover`: global
//! aerodynamics, the FMU's default ground 10 m below the start, 3 m/s vertical climb, the
//! wind switched on at 5 s, 40 s; **held** = completes, no ground contact, position error
//! below 10 m throughout and below 1 m over the last 5 s.
//!
//! Before the hover-in-wind design condition (README, "Hover in a wind step") the tuned TSD
//! held 1 of the 8 bearings at 5 m/s under the Jacobi master and no 8 m/s step under either
//! master: the loops designed at the measured α (±60° after the step) went into a bang-bang
//! pitch limit cycle. The wind along the belly (from the north) or the back (south) is the
//! case the weathervane turns every other wind into.
//!
//! Along the span (and half-way to it) the tuned TSD held 7 and 8 m/s from none of the six
//! bearings with a span-wise component under either master before the span-wise measures
//! (README, "Hover in a span-wise wind": path frame kept, weathercock feed-forward, slower roll
//! and strong-crossflow normal poles): 8 m/s from the east drifted 23 m (Gauss-Seidel) and 41 m
//! (Jacobi) before the heading had turned, from the west under Jacobi it tumbled (101 m).
//!
//! `cargo test --release -p missions --test hover_wind_step -- --nocapture` prints the numbers.

use closed_loop::{fly, plant_inputs, Ordering, Scenario, Wind};
use flight_mission::MissionParams;
use tailsitter_physics::{AeroModel, Airframe, Ground, Plant};
use tsd_control::TsdController;

/// Time the step is switched on (s) and length of a run (s).
const STEP_TIME: f64 = 5.0;
const STOP: f64 = 40.0;

/// (held, max error (m), max error over the last 5 s (m)) of one step from `from_deg`.
fn step(speed: f64, from_deg: f64, ordering: Ordering) -> (bool, f64, f64) {
    let mut plant = Plant::new(Airframe::default());
    plant.aero.model = AeroModel::Global;
    plant.ground = Ground::default();
    let mission = MissionParams {
        t_vertical_1: 60.0,
        ..Default::default()
    };
    let x0 = plant.trim_vertical_climb(mission.v_vertical).unwrap().state;
    let mut ctl = TsdController::with_mission(mission).unwrap();
    let mut s = Scenario::mission(mission);
    s.stop_time = STOP;
    s.ordering = ordering;
    s.wind = Wind::step_from(STEP_TIME, from_deg.to_radians(), speed);
    let trace = fly(&plant, x0, &mut ctl, &s);
    let ground = trace
        .samples
        .iter()
        .any(|x| plant.outputs(&x.x, &plant_inputs(&x.command), &x.wind).ground.points > 0);
    let max = trace.samples.iter().map(|x| x.pos_error()).fold(0.0, f64::max);
    let end = trace.samples.last().map_or(0.0, |x| x.t);
    let fin = trace
        .window(end - 5.0, f64::INFINITY)
        .map(|x| x.pos_error())
        .fold(0.0, f64::max);
    println!("{speed} m/s from {from_deg:>3}°, {ordering:?}: max {max:.2} m, last 5 s {fin:.3} m");
    (trace.completed() && !ground && max < 10.0 && fin < 1.0, max, fin)
}

/// 8 m/s along the belly and the back, both masters (tumbled before: 89–137 m).
#[test]
fn holds_an_8_m_s_step_along_the_belly_and_the_back_under_both_masters() {
    for ordering in [Ordering::GaussSeidel, Ordering::Jacobi] {
        for from_deg in [0.0, 180.0] {
            let (held, max, fin) = step(8.0, from_deg, ordering);
            assert!(held, "8 m/s from {from_deg}°, {ordering:?}: max {max} m, final {fin} m");
        }
    }
}

/// 5 m/s from every 45° under the Jacobi master (one communication step of delay between
/// plant and controller): 1 of 8 held before.
#[test]
fn holds_5_m_s_steps_from_every_bearing_under_the_jacobi_master() {
    for k in 0..8 {
        let from_deg = 45.0 * k as f64;
        let (held, max, fin) = step(5.0, from_deg, Ordering::Jacobi);
        assert!(held, "5 m/s from {from_deg}°: max {max} m, final {fin} m");
    }
}

/// 8 m/s along the span (east, west) and half-way to it (45°, 135°), both masters: none held
/// before the span-wise measures (15–101 m), the goal of any direction up to 8 m/s.
#[test]
fn holds_an_8_m_s_step_along_the_span_under_both_masters() {
    for ordering in [Ordering::GaussSeidel, Ordering::Jacobi] {
        for from_deg in [45.0, 90.0, 135.0, 270.0] {
            let (held, max, fin) = step(8.0, from_deg, ordering);
            assert!(held, "8 m/s from {from_deg}°, {ordering:?}: max {max} m, final {fin} m");
        }
    }
}
