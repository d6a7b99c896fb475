//! The wind [`crate::fly`] hands the plant at each communication point: a function of time
//! ([`Wind::at`]) or the running atmosphere of [`Wind::Atmosphere`] (the `atmosphere` crate,
//! the model of the `tailsitter_atmosphere` FMU), stepped as a co-simulation master steps
//! the FMU.
//!
//! Atmosphere timing (as `tailsim.masters.ClosedLoop(..., atmosphere=...)` and the FMU's
//! documentation): the atmosphere starts at t = 0 on the plant outputs of the initial state
//! with the plant's wind inputs at their start value 0; at each communication point t it
//! reads the plant outputs at t — position and the airspeed computed with the wind the plant
//! holds at its inputs, the one it flew its last step with — and steps (t, h), its output
//! the wind for [t, t + h). Gauss-Seidel: the plant flies that output over [t, t + h);
//! Jacobi: the plant flies the output of the previous point (one step of delay, the output
//! after start at t = 0). The atmosphere's internal sample clock does not depend on the
//! communication step. The controller measures, by [`MeasuredWind`], the wind flown from t
//! (`Current`) or the one the plant holds at its inputs (`HeldInput`, what an FMU master
//! delivers).

use atmosphere::{Atmosphere, Inputs};
use nalgebra::Vector3;
use tailsitter_physics::{idx, InputVector, Plant, StateVector};

use crate::{MeasuredWind, Ordering, Scenario, Wind};

/// The wind of one communication point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointWind {
    /// The wind the plant flies over [t, t + h) (m/s), NED.
    pub flown: Vector3<f64>,
    /// The wind of the plant outputs the controller samples (m/s), NED.
    pub measured: Vector3<f64>,
}

/// The scenario's wind as the loop runs: [`Wind::at`] or a running [`Atmosphere`].
#[derive(Debug, Clone)]
pub struct WindSource {
    wind: Wind,
    measured: MeasuredWind,
    ordering: Ordering,
    atmosphere: Option<Atmosphere>,
    /// The wind the plant holds at its inputs (flown over the last step).
    held: Vector3<f64>,
    /// The atmosphere's last output.
    output: Vector3<f64>,
}

fn vector(w: [f64; 3]) -> Vector3<f64> {
    Vector3::new(w[0], w[1], w[2])
}

/// The atmosphere's inputs: the plant outputs of those names at `x` with the wind `held`.
fn inputs(plant: &Plant, x: &StateVector, u: &InputVector, held: &Vector3<f64>) -> Inputs {
    Inputs {
        pos_ned: [x[idx::POS_N], x[idx::POS_E], x[idx::POS_D]],
        airspeed: plant.outputs(x, u, held).airspeed,
    }
}

impl WindSource {
    /// The source of `scenario` for a flight from `x0` (an atmosphere starts here, at t = 0).
    pub fn new(scenario: &Scenario, plant: &Plant, x0: &StateVector) -> Result<Self, String> {
        let mut source = Self {
            wind: scenario.wind,
            measured: scenario.measured_wind,
            ordering: scenario.ordering,
            atmosphere: None,
            held: Vector3::zeros(),
            output: Vector3::zeros(),
        };
        if let Wind::Atmosphere(params) = scenario.wind {
            let mut a = Atmosphere::new(params).map_err(|e| format!("atmosphere: {e}"))?;
            let start = a
                .start(&inputs(plant, x0, &InputVector::zeros(), &Vector3::zeros()), 0.0)
                .map_err(|e| format!("atmosphere at t = 0: {e}"))?;
            source.output = vector(start);
            source.atmosphere = Some(a);
        }
        Ok(source)
    }

    /// The wind of communication point `k` at `t` (step `h`), the plant in state `x` with
    /// inputs `u`. Call once per point, in order.
    pub fn at(
        &mut self,
        k: usize,
        t: f64,
        h: f64,
        plant: &Plant,
        x: &StateVector,
        u: &InputVector,
    ) -> Result<PointWind, String> {
        let point = match self.atmosphere.as_mut() {
            None => {
                let flown = self.wind.at(t);
                let measured = match self.measured {
                    MeasuredWind::Current => flown,
                    MeasuredWind::HeldInput if k > 0 => self.held,
                    MeasuredWind::HeldInput => flown,
                };
                PointWind { flown, measured }
            }
            Some(a) => {
                let before = self.output;
                let out = a
                    .step(&inputs(plant, x, u, &self.held), t, h)
                    .map_err(|e| format!("atmosphere failed at t = {t}: {e}"))?;
                self.output = vector(out);
                let flown = match self.ordering {
                    Ordering::GaussSeidel => self.output,
                    Ordering::Jacobi => before,
                };
                let measured = match self.measured {
                    MeasuredWind::Current => flown,
                    MeasuredWind::HeldInput => self.held,
                };
                PointWind { flown, measured }
            }
        };
        self.held = point.flown;
        Ok(point)
    }
}
