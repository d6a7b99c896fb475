//! The avionics chain's connections by name, shared by the closed-loop tests and the
//! avionics-loop bench (`#[path]`-included): plant state → sensor truth, sensor outputs →
//! estimator inputs, estimate → controller measurement (the FMU connections of the SSP).

use flight_mission::Measurement;
use nalgebra::Vector3;
use state_estimator::{Estimate, Measurements};
use tailsitter_physics::{idx, InputVector, Plant, StateVector};

/// The estimate as the controller's measurement (the plant outputs of the same names).
pub fn measurement(e: &Estimate) -> Measurement {
    Measurement {
        pos_ned: e.pos_ned,
        vel_ned: e.vel_ned,
        vel_body: e.vel_body,
        rates: e.rates,
        quat: e.quat,
        airspeed: e.airspeed,
        alpha: e.alpha,
        beta: e.beta,
        thrust: e.thrust,
        surfaces: e.surfaces,
        specific_force_body: e.specific_force,
        induced_velocity: e.induced_velocity,
    }
}

/// The true state as the sensor model sees it (the plant outputs of the same names).
pub fn truth(plant: &Plant, x: &StateVector, u: &InputVector, wind: &Vector3<f64>) -> sensor_model::Truth {
    let y = plant.outputs(x, u, wind);
    sensor_model::Truth {
        pos_ned: Vector3::new(x[idx::POS_N], x[idx::POS_E], x[idx::POS_D]),
        vel_ned: y.vel_ned,
        rates: Vector3::new(x[idx::P], x[idx::Q], x[idx::R]),
        quat: x.fixed_rows::<4>(idx::Q1).into_owned(),
        airspeed: y.airspeed,
        alpha: y.alpha,
        beta: y.beta,
        specific_force: y.specific_force_body,
    }
}

/// The sensor model's outputs as the estimator's inputs (the FMU connections by name).
pub fn to_estimator(m: &sensor_model::Measurements) -> Measurements {
    Measurements {
        gps_latitude: m.gps_latitude,
        gps_longitude: m.gps_longitude,
        gps_height: m.gps_height,
        gps_vel: m.gps_vel,
        gps_fix_count: m.gps_fix_count as i32,
        gps_valid: m.gps_valid,
        accel: m.accel(),
        gyro: m.gyro(),
        mag: m.mag(),
        pitot: m.pitot_airspeed(),
    }
}
