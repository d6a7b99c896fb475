//! The tuned LQR's front transition in a weak tailwind (lqr-control README, "Mission in
//! wind"): cells of the wind envelope (`analysis::wind_envelope`: global aerodynamics,
//! Gauss-Seidel, perfect state, the steady wind stepping in at 2 s), the handover being the
//! default mission with a 20 s first vertical phase.

use analysis::controllers::Kind;
use analysis::wind_envelope::{fly_job, Job, MissionKind, WindForm, BEARINGS_DEG};

/// The envelope cell of the LQR in a 5 m/s wind from `bearing_deg`: completed, largest
/// error to its own reference and to the still-air mission path (m).
fn cell(mission: MissionKind, bearing_deg: f64) -> (bool, f64, Option<f64>) {
    let b = BEARINGS_DEG.iter().position(|&d| d == bearing_deg).unwrap();
    let (c, _) = fly_job(&Job::new(Kind::Lqr, mission, WindForm::Step, 5.0, b), None);
    (c.completed, c.max_error, c.mission_error)
}

/// In a 5 m/s tailwind the handover completes within 3 m of its reference and of the
/// mission's path (measured 2.95 m; 3.05 m with the transition linearised about the
/// measured state), and in a 5 m/s quartering tailwind within 8 m (measured 6.98 m; 19.5 m
/// before).
#[test]
fn weak_tailwind_transition_about_the_reference() {
    for (bearing, bound) in [(180.0, 3.0), (135.0, 8.0)] {
        let (completed, worst, path) = cell(MissionKind::Handover, bearing);
        eprintln!("5 m/s from {bearing}°: largest error {worst:.2} m, from the path {path:?}");
        assert!(completed, "from {bearing}°");
        assert!(worst < bound, "5 m/s from {bearing}°: {worst} m");
        assert!(
            path.is_some_and(|p| p < bound),
            "5 m/s from {bearing}°: {path:?} m from the path"
        );
    }
}
