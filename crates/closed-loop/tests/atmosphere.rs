//! `Wind::Atmosphere`: the atmosphere crate as the loop's wind source.

use closed_loop::{fly, wind_from, MeasuredWind, Ordering, Scenario, Trace, Wind};
use flight_mission::MissionParams;
use nalgebra::Vector3;
use tailsitter_physics::{Airframe, Plant};
use tsd_control::{TsdController, TsdParams};

fn run(wind: Wind, ordering: Ordering, measured: MeasuredWind, stop: f64) -> Trace {
    let mission = MissionParams::default();
    let plant = Plant::new(Airframe::default());
    let x0 = plant.trim_vertical_climb(mission.v_vertical).unwrap().state;
    let mut s = Scenario::mission(mission);
    s.stop_time = stop;
    s.wind = wind;
    s.ordering = ordering;
    s.measured_wind = measured;
    let mut c = TsdController::new(Airframe::default(), mission, TsdParams::default()).unwrap();
    fly(&plant, x0, &mut c, &s)
}

fn same(a: &Trace, b: &Trace) {
    assert_eq!(a.samples.len(), b.samples.len());
    for (x, y) in a.samples.iter().zip(&b.samples) {
        assert_eq!(x.x, y.x, "t = {}", x.t);
        assert_eq!(x.wind, y.wind, "t = {}", x.t);
        assert_eq!(x.command, y.command, "t = {}", x.t);
    }
}

#[test]
fn calm_atmosphere_is_calm_air() {
    for ordering in [Ordering::GaussSeidel, Ordering::Jacobi] {
        for measured in [MeasuredWind::Current, MeasuredWind::HeldInput] {
            let a = run(Wind::Atmosphere(atmosphere::Params::default()), ordering, measured, 4.0);
            same(&a, &run(Wind::Calm, ordering, measured, 4.0));
        }
    }
}

#[test]
fn uniform_steady_atmosphere_is_the_constant_wind() {
    // Gauss-Seidel, the controller measuring the wind flown from t: the atmosphere's uniform
    // steady wind from t = 0 is `Wind::Constant`, bit for bit.
    let p = atmosphere::Params {
        wind_speed: 4.0,
        wind_from: 1.0,
        wind_profile: 0,
        ..atmosphere::Params::default()
    };
    let a = run(Wind::Atmosphere(p), Ordering::GaussSeidel, MeasuredWind::Current, 4.0);
    let w = Wind::Constant(wind_from(1.0, 4.0));
    same(&a, &run(w, Ordering::GaussSeidel, MeasuredWind::Current, 4.0));
    assert_eq!(Wind::Atmosphere(p).at(0.0), wind_from(1.0, 4.0));
}

#[test]
fn turbulence_is_seeded_and_jacobi_flies_it_one_step_late() {
    let p = atmosphere::Params {
        wind_speed: 5.0,
        turbulence_intensity: 2,
        origin_height: 10.0,
        seed: 11,
        ..atmosphere::Params::default()
    };
    let gs = run(Wind::Atmosphere(p), Ordering::GaussSeidel, MeasuredWind::HeldInput, 3.0);
    same(
        &gs,
        &run(Wind::Atmosphere(p), Ordering::GaussSeidel, MeasuredWind::HeldInput, 3.0),
    );
    let other = run(
        Wind::Atmosphere(atmosphere::Params { seed: 12, ..p }),
        Ordering::GaussSeidel,
        MeasuredWind::HeldInput,
        3.0,
    );
    assert!(gs.samples.iter().zip(&other.samples).all(|(a, b)| a.wind != b.wind));
    let spread = gs
        .samples
        .iter()
        .map(|s| (s.wind - gs.samples[0].wind).norm())
        .fold(0.0, f64::max);
    assert!(spread > 0.1, "{spread}");
    // Jacobi: the wind flown from t is the atmosphere's output of the previous point.
    let j = run(Wind::Atmosphere(p), Ordering::Jacobi, MeasuredWind::HeldInput, 3.0);
    assert_eq!(j.samples[0].wind, j.samples[1].wind);
    assert_ne!(j.samples[0].wind, Vector3::zeros());
}
