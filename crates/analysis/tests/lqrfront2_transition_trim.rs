//! The tuned LQR's front transition in a steady wind, trimmed along the still-air ground path
//! on the global aerodynamic model with full weight from 0.5 s into the transition and the
//! full sideways wind (lqr-control README, "Mission in wind"): cells of the wind envelope
//! (`analysis::wind_envelope`: global aerodynamics, Gauss-Seidel, perfect state, the steady
//! wind stepping in at 2 s). Phase indices: 0 vertical 1, 1 transition 1, 2 level,
//! 3 transition 2, 4 vertical 2.

use analysis::controllers::Kind;
use analysis::wind_envelope::{fly_job, Cell, Job, MissionKind, WindForm, BEARINGS_DEG};

/// The LQR's envelope cell in a steady `speed` wind from `bearing_deg` and its largest error
/// per phase (m).
fn cell(mission: MissionKind, speed: f64, bearing_deg: f64) -> (Cell, [f64; 11]) {
    let b = BEARINGS_DEG.iter().position(|&d| d == bearing_deg).unwrap();
    fly_job(&Job::new(Kind::Lqr, mission, WindForm::Step, speed, b), None)
}

/// Across the track the front transition stays within 2.5 m at 5 m/s (measured 1.95–2.02 m;
/// 4.03 m with the lift-weighted trim on the model for control) and 1.5 m at 8 m/s (1.12 m;
/// 8.31 m), and both default missions are held on the mission's path.
#[test]
fn crosswind_front_transition_held() {
    for (speed, bound) in [(5.0, 2.5), (8.0, 1.5)] {
        let (c, phases) = cell(MissionKind::Default, speed, 90.0);
        eprintln!(
            "{speed} m/s from 90°: phases {phases:.2?}, largest {:.2} m",
            c.max_error
        );
        assert!(phases[1] < bound, "{speed} m/s: transition 1 {} m", phases[1]);
        assert!(c.held, "{speed} m/s: {:.2} m, path {:?}", c.max_error, c.mission_error);
    }
}

/// Quartering winds: at 5 m/s from 45° the default mission is held (2.13–2.28 m; 4.44 m
/// before), and at 8 m/s from 45° the front transition stays within 6 m (4.12 m; 11.88 m);
/// the handover's 5 m/s wind from 45° is held (1.72 m; 3.96 m).
#[test]
fn quartering_wind_front_transition() {
    let (c, phases) = cell(MissionKind::Default, 5.0, 45.0);
    eprintln!(
        "default 5 m/s from 45°: phases {phases:.2?}, largest {:.2} m",
        c.max_error
    );
    assert!(c.held, "{:.2} m, path {:?}", c.max_error, c.mission_error);
    let (c, phases) = cell(MissionKind::Default, 8.0, 45.0);
    eprintln!(
        "default 8 m/s from 45°: phases {phases:.2?}, largest {:.2} m",
        c.max_error
    );
    assert!(c.completed, "{:?}", c.failure);
    assert!(phases[1] < 6.0, "transition 1 {} m", phases[1]);
    let (c, phases) = cell(MissionKind::Handover, 5.0, 45.0);
    eprintln!(
        "handover 5 m/s from 45°: phases {phases:.2?}, largest {:.2} m",
        c.max_error
    );
    assert!(c.held, "{:.2} m, path {:?}", c.max_error, c.mission_error);
}
