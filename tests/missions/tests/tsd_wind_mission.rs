//! The tuned TSD's heading through the first vertical phase and the front transition in wind
//! (tsd-control README, "Missions in wind"): cells of the wind envelope
//! (`analysis::wind_envelope`: global aerodynamics, Gauss-Seidel, perfect state, a steady
//! wind stepping in at 2 s).
//!
//! With the heading steered by the low-passed (measured − reference) specific force and the
//! weathervane's nearer face, the 8 m/s crosswind of the default mission went into the
//! transition span-on (lost 9.7 s from the east, 24.7 m from the west), the handover's
//! transition turned the belly away from the track (24.6 m), and the take-off → landing
//! flight in 10 m/s from 45° was lost in the transition (13.5 s).
//!
//! `cargo test --release -p missions --test tsd_wind_mission -- --nocapture` prints the numbers.

use analysis::controllers::Kind;
use analysis::wind_envelope::{fly_job, Cell, Job, MissionKind, WindForm, BEARINGS_DEG};

/// One cell with a steady wind stepping in at 2 s.
fn cell(mission: MissionKind, speed: f64, bearing_index: usize) -> Cell {
    cell_in(WindForm::Step, mission, speed, bearing_index)
}

/// One cell: completed, and its largest distance to the own reference (m).
fn cell_in(form: WindForm, mission: MissionKind, speed: f64, bearing_index: usize) -> Cell {
    let (c, phases) = fly_job(&Job::new(Kind::Tsd, mission, form, speed, bearing_index), None);
    println!(
        "{form:?} {mission:?} {speed} m/s from {}°: completed {}, max error {:.2} m, per phase {phases:.2?}, {:?}",
        BEARINGS_DEG[bearing_index], c.completed, c.max_error, c.failure
    );
    c
}

/// The default mission, 8 m/s across the track stepping in 3 s before the transition: held
/// from both sides (measured 2.01 m from the east and from the west, in the transition).
#[test]
fn default_mission_holds_an_8_m_s_crosswind_stepping_in_before_the_transition() {
    for b in [2, 6] {
        let c = cell(MissionKind::Default, 8.0, b);
        assert!(c.completed && c.max_error < 3.0, "{c:?}");
    }
}

/// The handover (20 s first vertical phase), 8 m/s from the east: the belly into the wind
/// on the track's side through the transition (measured 1.33 m, in the transition).
#[test]
fn handover_transition_keeps_the_belly_on_the_tracks_side_in_a_crosswind() {
    let c = cell(MissionKind::Handover, 8.0, 2);
    assert!(c.completed && c.max_error < 3.0, "{c:?}");
}

/// Take-off → landing in 10 m/s from 45°: no longer lost in the front transition (measured
/// 3.68 m largest error, in the first vertical phase after the take-off; landed 1.15 m from the target).
#[test]
fn takeoff_landing_flies_the_front_transition_in_a_10_m_s_quartering_headwind() {
    let c = cell(MissionKind::TakeoffLanding, 10.0, 1);
    assert!(c.completed && c.max_error < 4.5, "{c:?}");
}

/// Take-off → landing in 10 m/s from the west: the take-off climbs out with the belly into
/// the wind, the front transition's face (from the back into the wind the first vertical
/// phase turned 180° into the transition: 36.5 m in the back transition). Measured 6.53 m
/// in the first vertical phase, as from the east; not held (that hover, and the landing
/// 3.7 m from the target).
#[test]
fn takeoff_climbs_out_on_the_transitions_face_in_a_10_m_s_crosswind() {
    let c = cell(MissionKind::TakeoffLanding, 10.0, 6);
    assert!(c.max_error < 7.0, "{c:?}");
}

/// Moderate Dryden turbulence: a gust along the nose of the climbing hover leaves ≈ 1 m/s of
/// airspeed at α ≈ ±80°; designed at that α the loops went bang-bang and the aircraft
/// tumbled (the handover with no mean wind lost at 18.7 s, the default mission in 3 m/s from
/// the north 48 m). Designed at α = 0 below 2 m/s of airspeed: measured 1.49 m and 0.94 m.
#[test]
fn turbulent_hover_at_near_zero_airspeed_is_held() {
    let c = cell_in(WindForm::Turbulent, MissionKind::Handover, 0.0, 0);
    assert!(c.completed && c.max_error < 2.5, "{c:?}");
    let c = cell_in(WindForm::Turbulent, MissionKind::Default, 3.0, 0);
    assert!(c.completed && c.max_error < 2.0, "{c:?}");
}
