//! The port mapping between the plant and a controller: the plant outputs grouped as
//! a [`Measurement`] and a [`Command`] as the plant's input vector (what the plant FMU
//! writes to and reads from its ports).

use crate::{Command, Measurement};
use nalgebra::Vector3;
use tailsitter_physics::{idx, InputVector, Outputs, Plant, StateVector};

/// What the controller would measure: the plant outputs of the same names.
pub fn measure(plant: &Plant, x: &StateVector, u: &InputVector, wind: &Vector3<f64>) -> Measurement {
    measurement(x, &plant.outputs(x, u, wind))
}

/// The plant outputs grouped as a [`Measurement`], from the state and the
/// computed outputs: what the plant FMU writes to its output ports.
pub fn measurement(x: &StateVector, y: &Outputs) -> Measurement {
    Measurement {
        pos_ned: Vector3::new(x[idx::POS_N], x[idx::POS_E], x[idx::POS_D]),
        vel_ned: y.vel_ned,
        vel_body: Vector3::new(x[idx::U], x[idx::V], x[idx::W]),
        rates: Vector3::new(x[idx::P], x[idx::Q], x[idx::R]),
        quat: x.fixed_rows::<4>(idx::Q1).into_owned(),
        airspeed: y.airspeed,
        alpha: y.alpha,
        beta: y.beta,
        thrust: x[idx::THRUST],
        surfaces: [
            x[idx::ELEVATOR],
            x[idx::AILERON],
            x[idx::RUDDER],
            x[idx::FLAP_COLLECTIVE],
            x[idx::FLAP_DIFFERENTIAL],
            x[idx::VERTICAL_FLAP],
        ],
        specific_force_body: y.specific_force_body,
        induced_velocity: y.induced_velocity,
    }
}

/// The plant input vector of a command.
pub fn plant_inputs(c: &Command) -> InputVector {
    let mut u = InputVector::zeros();
    u[idx::THRUST_CMD] = c.thrust;
    u[idx::ELEVATOR_CMD] = c.elevator;
    u[idx::AILERON_CMD] = c.aileron;
    u[idx::RUDDER_CMD] = c.rudder;
    u[idx::FLAP_COLLECTIVE_CMD] = c.flap_collective;
    u[idx::FLAP_DIFFERENTIAL_CMD] = c.flap_differential;
    u[idx::VERTICAL_FLAP_CMD] = c.vertical_flap;
    u
}
