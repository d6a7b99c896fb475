//! The tuned TSD's take-off-to-landing cells with every landing criterion of
//! `takeoff_landing::evaluate` (a development probe, flown as the wind envelope flies them):
//! `tsdland3_criteria step|turb SPEEDS BEARING_INDICES|all [jacobi] [avionics] [trace FROM]`.
use analysis::controllers::Kind;
use analysis::takeoff_landing::{self, tilt};
use analysis::wind_envelope::{fly_on, plant, seed, wind, StateKind, WindForm, BEARINGS_DEG};
use closed_loop::{Ordering, Sample, Scenario};
use flight_mission::Phase;
use rayon::prelude::*;
use tailsitter_physics::InputVector;

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
    let ordering = if a.iter().any(|s| s == "jacobi") {
        Ordering::Jacobi
    } else {
        Ordering::GaussSeidel
    };
    let state = if a.iter().any(|s| s == "avionics") {
        StateKind::Avionics
    } else {
        StateKind::Perfect
    };
    let from: Option<f64> = a
        .iter()
        .position(|s| s == "trace")
        .and_then(|i| a.get(i + 1))
        .and_then(|x| x.parse().ok());
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
            scenario.ordering = ordering;
            let mut c = Kind::Tsd.make_configured(&mission, 0).unwrap();
            let stop = takeoff_landing::after_landing();
            let trace = fly_on(&plant, x0, &InputVector::zeros(), &mut c, &scenario, state, seed(b), stop);
            let f = takeoff_landing::evaluate(&plant, Kind::Tsd, ordering, &mission, &trace);
            let mut out = String::new();
            if let Some(from) = from {
                for s in trace.samples.iter().filter(|s| s.t >= from).step_by(5) {
                    let g = plant.outputs(&s.x, &closed_loop::plant_inputs(&s.command), &s.wind).ground;
                    out += &format!(
                        "{:7.2} {:2} n {:8.3} e {:7.3} d {:6.3} vz {:5.2} tilt {:5.1} T {:6.1} pts {} \n",
                        s.t,
                        s.diagnostics.phase.code(),
                        s.measurement.pos_ned.x,
                        s.measurement.pos_ned.y,
                        s.measurement.pos_ned.z,
                        s.measurement.vel_ned.z,
                        tilt(&s.x).to_degrees(),
                        s.command.thrust,
                        g.points
                    );
                }
            }
            let landed = trace.samples.iter().any(|s: &Sample| s.diagnostics.phase == Phase::Landed);
            out += &format!(
                "{speed:>4} {:>5} passed {:5} landed {landed:5} lift {:6.2} td@ {:7.2} landed@ {:7.2} td {:5.2} miss td {:6.2} end {:5.2} tilt td {:5.1} end {:5.1} bounced {} rebound {:.3} ground tilt {:.1} {}",
                BEARINGS_DEG[b],
                f.passed,
                f.liftoff_time.unwrap_or(f64::NAN),
                f.touchdown_time.unwrap_or(f64::NAN),
                f.landed_time.unwrap_or(f64::NAN),
                f.touchdown_speed,
                f.miss_touchdown,
                f.miss_final,
                f.tilt_touchdown_deg,
                f.tilt_final_deg,
                f.bounced,
                f.rebound_height,
                f.ground_tilt_deg,
                trace.failure.as_deref().unwrap_or("")
            );
            out
        })
        .collect();
    for r in &rows {
        println!("{r}");
    }
}
