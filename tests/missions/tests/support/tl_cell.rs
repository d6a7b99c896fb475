//! One take-off-to-landing cell of the wind envelope (`analysis::takeoff_landing::mission`,
//! `analysis::wind_envelope`: global aerodynamics, the ground 10 m below the origin,
//! Gauss-Seidel, perfect state), flown to 5 s after the landing; its figures printed
//! (`-- --nocapture`).

use analysis::controllers::Kind;
use analysis::takeoff_landing::{self, Flight};
use analysis::wind_envelope::{plant, wind, WindForm, BEARINGS_DEG};
use closed_loop::{fly, Ordering, Scenario};
use flight_mission::Phase;

/// The largest distance to the own reference and the landing's figures of the cell of
/// `kind` in `form` of wind at `speed` (m/s) from the bearing `bearing_index`.
pub fn fly_cell(kind: Kind, form: WindForm, speed: f64, bearing_index: usize) -> (f64, Flight) {
    let plant = plant();
    let mission = takeoff_landing::mission();
    let x0 = plant.resting_on_ground(0.0, 0.0, 0.0);
    let mut scenario = Scenario::mission(mission);
    scenario.stop_time = takeoff_landing::stop_time(&mission);
    scenario.wind = wind(form, speed, bearing_index, plant.ground.height);
    let mut c = kind.make(&mission);
    let mut trace = fly(&plant, x0, &mut c, &scenario);
    if let Some(k) = trace.samples.iter().position(|s| s.diagnostics.phase == Phase::Landed) {
        let t_end = trace.samples[k].t + takeoff_landing::AFTER_LANDING;
        trace.samples.retain(|s| s.t <= t_end + 1e-9);
    }
    let f = takeoff_landing::evaluate(&plant, kind, Ordering::GaussSeidel, &mission, &trace);
    let max = trace.samples.iter().map(|s| s.pos_error()).fold(0.0, f64::max);
    println!(
        "{speed} m/s from {}°: max error {max:.2} m, ground tilt {:.1}°, landed {:?}, miss {:.2} m, touchdown {:.2} m/s, tilt {:.1}° / {:.1}° at the end, every landing criterion {}",
        BEARINGS_DEG[bearing_index],
        f.ground_tilt_deg,
        f.landed_time,
        f.miss_final,
        f.touchdown_speed,
        f.tilt_touchdown_deg,
        f.tilt_final_deg,
        f.passed
    );
    (max, f)
}
