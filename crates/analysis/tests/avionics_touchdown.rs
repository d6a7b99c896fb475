//! Take-off to landing in still air with the avionics chain (sensors + tuned estimator,
//! Gauss-Seidel): the landing is declared on the gear, not in the air. The estimate's height
//! relative to the start is off by about a metre at the landing (GPS only, σ 4 m per fix);
//! with the touchdown declared on the measured height against the target, the TSD's thrust
//! was cut 0.76 m above the ground in the sensor-noise seed of bearing index 0 (touchdown
//! at 3.5 m/s; index 7: 2.3 m/s).
use analysis::controllers::Kind;
use analysis::takeoff_landing;
use analysis::wind_envelope::{fly_on, plant, seed, StateKind};
use closed_loop::{Ordering, Scenario, Wind};
use flight_mission::Phase;
use tailsitter_physics::{idx, InputVector};

#[test]
fn tsd_with_avionics_lands_on_its_gear() {
    for bearing_index in [0, 7] {
        let plant = plant();
        let mission = takeoff_landing::mission();
        let x0 = plant.resting_on_ground(0.0, 0.0, 0.0);
        let mut scenario = Scenario::mission(mission);
        scenario.stop_time = takeoff_landing::stop_time(&mission);
        scenario.wind = Wind::Calm;
        scenario.ordering = Ordering::GaussSeidel;
        let mut c = Kind::Tsd.make_configured(&mission, 0).unwrap();
        let stop = takeoff_landing::after_landing();
        let trace = fly_on(
            &plant,
            x0,
            &InputVector::zeros(),
            &mut c,
            &scenario,
            StateKind::Avionics,
            seed(bearing_index),
            stop,
        );
        let f = takeoff_landing::evaluate(&plant, Kind::Tsd, Ordering::GaussSeidel, &mission, &trace);
        // At the latch the gear carries the aircraft: the true CG within 15 cm of its height
        // at rest on the gear.
        let latch = trace
            .samples
            .iter()
            .find(|s| s.diagnostics.phase == Phase::Landed)
            .unwrap_or_else(|| panic!("index {bearing_index}: no landing: {:?}", f.failure));
        let above = x0[idx::POS_D] - latch.x[idx::POS_D];
        assert!(
            above.abs() < 0.15,
            "index {bearing_index}: landed {above:.2} m above the ground"
        );
        // (Upright is not asserted: in index 7 the aircraft meets the ground drifting at
        // 1.3 m/s sideways and tips over, the controller's horizontal hold on the estimate.)
        assert!(
            f.touchdown_speed < 0.5,
            "index {bearing_index}: touchdown at {:.2} m/s",
            f.touchdown_speed
        );
    }
}
