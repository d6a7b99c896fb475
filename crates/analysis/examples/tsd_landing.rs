//! The tuned TSD's take-off-to-landing mission in wind, with every landing criterion (a
//! development probe): `tsd_landing step|turb SPEEDS BEARING_INDICES|all`. Per cell: held
//! (as the wind envelope), largest error to the own reference, landing miss at rest,
//! touchdown speed, tilt at touchdown and at the end, and whether every landing criterion
//! of `takeoff_landing` is met.
use analysis::controllers::{AnyController, Kind};
use analysis::takeoff_landing;
use analysis::wind_envelope::{plant, wind, WindForm, BEARINGS_DEG, HELD_MAX_ERROR};
use closed_loop::{fly, Ordering, Scenario};
use flight_mission::Phase;
use rayon::prelude::*;

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let form = if a[1] == "step" {
        WindForm::Step
    } else {
        WindForm::Turbulent
    };
    let speeds: Vec<f64> = a[2].split(',').map(|s| s.parse().unwrap()).collect();
    let bearings: Vec<usize> = if a[3] == "all" {
        (0..BEARINGS_DEG.len()).collect()
    } else {
        a[3].split(',').map(|s| s.parse().unwrap()).collect()
    };
    let jobs: Vec<(f64, usize)> = speeds
        .iter()
        .flat_map(|&s| bearings.iter().map(move |&b| (s, b)))
        .collect();
    let rows: Vec<String> = jobs
        .par_iter()
        .map(|&(speed, b)| {
            let plant = plant();
            let mission = takeoff_landing::mission();
            let x0 = plant.resting_on_ground(0.0, 0.0, 0.0);
            let mut scenario = Scenario::mission(mission);
            scenario.stop_time = takeoff_landing::stop_time(&mission);
            scenario.wind = wind(form, speed, b, plant.ground.height);
            let mut c: AnyController = Kind::Tsd.make(&mission);
            let mut trace = fly(&plant, x0, &mut c, &scenario);
            if let Some(k) = trace.samples.iter().position(|s| s.diagnostics.phase == Phase::Landed) {
                let t_end = trace.samples[k].t + takeoff_landing::AFTER_LANDING;
                trace.samples.retain(|s| s.t <= t_end + 1e-9);
            }
            let f = takeoff_landing::evaluate(&plant, Kind::Tsd, Ordering::GaussSeidel, &mission, &trace);
            let max_error = trace.samples.iter().map(|s| s.pos_error()).fold(0.0, f64::max);
            let completed = trace.completed() && f.landed_time.is_some() && f.miss_final < HELD_MAX_ERROR;
            format!(
                "{speed:>4} m/s {:>5}°  held {:5}  max {:7.2}  miss {:6.2}  td {:5.2} m/s  tilt td {:5.1}° end {:5.1}°  bounced {:5}  landing passed {}",
                BEARINGS_DEG[b],
                completed && max_error < HELD_MAX_ERROR,
                max_error,
                f.miss_final,
                f.touchdown_speed,
                f.tilt_touchdown_deg,
                f.tilt_final_deg,
                f.bounced,
                f.passed
            )
        })
        .collect();
    for r in rows {
        println!("{r}");
    }
}
