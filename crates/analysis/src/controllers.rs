//! The two controllers of the thesis behind one type, so campaigns treat them alike.

use flight_mission::{ControlError, ControllerInput, ControllerOutput, FlightController, MissionParams};
use lqr_control::{LqrController, LqrParams};
use serde::{Deserialize, Serialize};
use tailsitter_physics::Airframe;
use tsd_control::{TsdController, TsdParams};

use crate::closed::Analysable;

/// Which controller.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Kind {
    /// Gain-scheduled LQR (thesis ch. 3).
    Lqr,
    /// Time-scale decoupling (thesis ch. 4).
    Tsd,
}

impl Kind {
    /// Both, in the thesis's order.
    pub const ALL: [Kind; 2] = [Kind::Lqr, Kind::Tsd];

    /// "LQR" / "TSD".
    pub fn name(self) -> &'static str {
        match self {
            Kind::Lqr => "LQR",
            Kind::Tsd => "TSD",
        }
    }

    /// The controller with its default tuning and the **nominal** airframe as its model
    /// (gains designed on the perfect model, §5.1), flying `mission`.
    pub fn make(self, mission: &MissionParams) -> AnyController {
        match self {
            Kind::Lqr => AnyController::Lqr(Box::new(
                LqrController::new(Airframe::default(), *mission, LqrParams::default()).expect("default LQR"),
            )),
            Kind::Tsd => AnyController::Tsd(Box::new(
                TsdController::new(TsdParams::default(), *mission, Airframe::default()).expect("default TSD"),
            )),
        }
    }
}

/// Either controller.
#[derive(Debug, Clone)]
pub enum AnyController {
    /// LQR.
    Lqr(Box<LqrController>),
    /// TSD.
    Tsd(Box<TsdController>),
}

impl FlightController for AnyController {
    fn update(&mut self, input: &ControllerInput) -> Result<ControllerOutput, ControlError> {
        match self {
            AnyController::Lqr(c) => c.update(input),
            AnyController::Tsd(c) => c.update(input),
        }
    }
}

impl Analysable for AnyController {
    fn save_state(&self) -> Vec<f64> {
        match self {
            AnyController::Lqr(c) => c.save_state(),
            AnyController::Tsd(c) => c.save_state(),
        }
    }
    fn load_state(&mut self, s: &[f64]) {
        match self {
            AnyController::Lqr(c) => c.load_state(s),
            AnyController::Tsd(c) => c.load_state(s),
        }
    }
    fn dynamic_states(&self) -> Vec<(usize, &'static str)> {
        match self {
            AnyController::Lqr(c) => c.dynamic_states(),
            AnyController::Tsd(c) => c.dynamic_states(),
        }
    }
}
