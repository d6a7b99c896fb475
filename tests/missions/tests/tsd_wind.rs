//! Vertical flight (hover/climb at 3 m/s, heading north, nose up) and the default mission in
//! steady wind and gusts, through the reference master of `closed-loop` (Gauss-Seidel) with the
//! nonlinear plant from its trimmed 3 m/s climb in still air (the wind is on from t = 0).
//!
//! Regression of the crosswind divergence: with the low-speed frame blended in the airspeed V̄,
//! a 4 m/s wind along the span (β ≈ 53°, V̄ = 5 m/s) blended in the wind axes and the lateral
//! position diverged after 8 s (380 m at 30 s). The blend now uses the axial airspeed
//! V̄ cos α cos β (README, "Low-speed frame").
//!
//! `cargo test --release -p missions --test tsd_wind -- --nocapture` prints the numbers.

use closed_loop::{fly, MissionCheck, Scenario, Trace, Wind};
use flight_mission::MissionParams;
use nalgebra::Vector3;
use tailsitter_physics::{AeroModel, Airframe, Ground, Plant};
use tsd_control::TsdController;

const HOVER_STOP: f64 = 35.0;

/// 35 s of vertical flight (t_vertical_1 = 40 s) in `wind` (NED air velocity (m/s)).
fn hover(wind: Wind) -> Trace {
    let plant = Plant::new(Airframe::default());
    let mission = MissionParams {
        t_vertical_1: 40.0,
        ..Default::default()
    };
    let x0 = plant.trim_vertical_climb(mission.v_vertical).unwrap().state;
    let mut ctl = TsdController::with_mission(mission).unwrap();
    let mut scenario = Scenario::mission(mission);
    scenario.stop_time = HOVER_STOP;
    scenario.wind = wind;
    fly(&plant, x0, &mut ctl, &scenario)
}

fn max_error(trace: &Trace, t0: f64) -> f64 {
    trace
        .window(t0, HOVER_STOP + 1.0)
        .map(|s| s.pos_error())
        .fold(0.0, f64::max)
}

/// Air velocity of a `speed` wind blowing *from* `bearing` (0 = north, 90° = east).
fn wind_from(bearing_deg: f64, speed: f64) -> Vector3<f64> {
    let b = bearing_deg.to_radians();
    -Vector3::new(b.cos(), b.sin(), 0.0) * speed
}

#[test]
fn hover_holds_position_in_a_steady_5_m_s_wind_from_any_direction() {
    let mut failures = Vec::new();
    for (name, bearing) in [("N", 0.0), ("E", 90.0), ("S", 180.0), ("W", 270.0), ("NE", 45.0)] {
        let trace = hover(Wind::Constant(wind_from(bearing, 5.0)));
        let (max, late) = (max_error(&trace, 0.0), max_error(&trace, 15.0));
        let max_beta = trace
            .samples
            .iter()
            .map(|s| s.measurement.beta.abs())
            .fold(0.0, f64::max);
        let last = trace.samples.last().unwrap();
        println!(
            "5 m/s wind from {name:>2}: max error {max:.3} m, max after 15 s {late:.3} m, final {:.3} m, \
             pitch {:.1}°, |β| max {:.1}°, completed {}",
            last.pos_error(),
            last.theta.to_degrees(),
            max_beta.to_degrees(),
            trace.completed()
        );
        if !(trace.completed() && max < 3.0 && late < 0.5) {
            failures.push(format!(
                "{name}: completed {}, max {max:.2} m, after 15 s {late:.2} m",
                trace.completed()
            ));
        }
    }
    assert!(failures.is_empty(), "{failures:?}");
}

/// The measured case of the defect: 4 m/s along the span, with both signs.
#[test]
fn hover_holds_position_in_a_4_m_s_crosswind() {
    for we in [4.0, -4.0] {
        let trace = hover(Wind::Constant(Vector3::new(0.0, we, 0.0)));
        let (max, late) = (max_error(&trace, 0.0), max_error(&trace, 15.0));
        println!("wind_e = {we:+} m/s: max error {max:.3} m, after 15 s {late:.3} m");
        assert!(trace.completed() && max < 1.0 && late < 0.1, "{max} {late}");
    }
}

/// The analysis campaign's case: a 6 m/s 1 − cos gust along the span in vertical flight.
#[test]
fn hover_rides_out_a_6_m_s_crosswind_gust() {
    for duration in [2.0, 5.0, 10.0] {
        let trace = hover(Wind::OneMinusCosine {
            t_start: 5.0,
            duration,
            amplitude: Vector3::new(0.0, 6.0, 0.0),
        });
        let max = max_error(&trace, 0.0);
        let fin = trace.samples.last().unwrap().pos_error();
        println!("6 m/s 1-cos east gust over {duration} s: max error {max:.3} m, final {fin:.3} m");
        assert!(trace.completed() && max < 5.0 && fin < 0.5, "{max} {fin}");
    }
}

#[test]
fn default_mission_in_a_3_m_s_crosswind_and_headwind() {
    let plant = Plant::new(Airframe::default());
    let mission = MissionParams::default();
    let theta_trim = plant.trim_level(mission.v_level).unwrap().theta;
    // The plant is mirror-symmetric: a wind from the west gives the same errors as from the
    // east. A wind from the north is a headwind in level flight: the trajectory is earth-fixed,
    // so the airspeed is 28 m/s (MissionCheck's 1 m/s criterion assumes calm air) — only
    // completion and the position errors are checked there. Both end pitched ≈ 10° into the
    // wind in vertical flight: the crosswind too is faced with the belly (tsd-control README,
    // "Missions in wind"), so MissionCheck's calm-air final-pitch criterion (10°) is not
    // applied; the level-flight criteria are, across the wind.
    for (name, bearing, level_check) in [("E", 90.0, true), ("N", 0.0, false)] {
        let x0 = plant.trim_vertical_climb(mission.v_vertical).unwrap().state;
        let mut ctl = TsdController::with_mission(mission).unwrap();
        let mut scenario = Scenario::mission(mission);
        scenario.wind = Wind::Constant(wind_from(bearing, 3.0));
        let trace = fly(&plant, x0, &mut ctl, &scenario);
        let check = MissionCheck::of(&trace, &mission, theta_trim);
        println!(
            "=== default mission, 3 m/s wind from {name} ===\n{check}  max α {:.2}°",
            trace.max_alpha(0.0, mission.end_time() + 1.0).to_degrees()
        );
        assert!(trace.completed(), "{:?}", trace.failure);
        let c = closed_loop::Criteria::get();
        assert!(
            !level_check
                || (check.all_finite
                    && check.level_airspeed_error <= c.level_airspeed_error_max
                    && check.level_pitch_error <= c.level_pitch_error_max),
            "{check}"
        );
        // The final tilt into the 3 m/s wind (measured 10.4° from either bearing).
        assert!(check.final_pitch_error < 12f64.to_radians(), "{check}");
        assert!(trace.max_pos_error() < 3.0, "{}", trace.max_pos_error());
    }
}

/// Regression of the campaign's robustness loss (issue 16): the default mission on the global
/// aerodynamics (the campaign's plant: `aero_model` = 1, ground contact) in a steady 4–5 m/s
/// wind across the path, on from t = 0. With the level-flight guidance pair −2 ± 1i also
/// across the path the directional loop saturated the rudder in the transition and the level
/// flight began with β ≈ 60° (4 m/s from the east: 50 m off at 14.6 s; 5 m/s from the east,
/// north-east and south-east: all lost, two of them tumbling); with Table 4.3's pair across the
/// path and the guidance feedback bounded (README, "Robustness on uncertain plants") every case
/// completes. Bound: the hover-in-wind campaign's 10 m hold criterion
/// (`analysis::envelope_hover::HOLD_MAX_ERROR`), the campaign's divergence limit being 50 m.
#[test]
fn default_mission_on_the_global_model_in_a_4_to_5_m_s_crosswind() {
    let mut plant = Plant::new(Airframe::default());
    plant.aero.model = AeroModel::Global;
    plant.ground = Ground::default();
    let mission = MissionParams::default();
    for (speed, bearing) in [(4.0, 90.0), (5.0, 45.0), (5.0, 90.0), (5.0, 135.0), (5.0, 270.0)] {
        let x0 = plant.trim_vertical_climb(mission.v_vertical).unwrap().state;
        let mut ctl = TsdController::with_mission(mission).unwrap();
        let mut scenario = Scenario::mission(mission);
        scenario.wind = Wind::Constant(wind_from(bearing, speed));
        let trace = fly(&plant, x0, &mut ctl, &scenario);
        let max = trace.max_pos_error();
        println!(
            "default mission, global aero, {speed} m/s from {bearing}°: completed {}, max error {max:.2} m, max α {:.1}°",
            trace.completed(),
            trace.max_alpha(0.0, mission.end_time() + 1.0).to_degrees()
        );
        assert!(trace.completed(), "{speed} m/s from {bearing}°: {:?}", trace.failure);
        assert!(max < 10.0, "{speed} m/s from {bearing}°: max error {max} m");
    }
}
