//! The two controllers of the thesis behind one type, so the sweeps treat them alike.

use flight_mission::{ControlError, ControllerInput, ControllerOutput, MissionParams, ParamError, SampledUnit};
use lqr_control::{LqrConfig, LqrController};
use serde::{Deserialize, Serialize};
use tsd_control::{TsdConfig, TsdController};

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
                LqrController::build(&LqrConfig::with_mission(*mission)).expect("default LQR"),
            )),
            Kind::Tsd => AnyController::Tsd(Box::new(
                TsdController::build(&TsdConfig::with_mission(*mission)).expect("default TSD"),
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

impl SampledUnit for AnyController {
    /// Which controller, flying which mission (default tuning, nominal airframe).
    type Config = (Kind, MissionParams);
    type Input = ControllerInput;
    type Output = ControllerOutput;

    fn build((kind, mission): &(Kind, MissionParams)) -> Result<Self, ParamError> {
        Ok(match kind {
            Kind::Lqr => AnyController::Lqr(Box::new(SampledUnit::build(&LqrConfig::with_mission(*mission))?)),
            Kind::Tsd => AnyController::Tsd(Box::new(SampledUnit::build(&TsdConfig::with_mission(*mission))?)),
        })
    }

    fn sample_time((_, mission): &(Kind, MissionParams)) -> f64 {
        mission.sample_time
    }

    fn sample(&mut self, input: &ControllerInput) -> Result<ControllerOutput, ControlError> {
        match self {
            AnyController::Lqr(c) => c.sample(input),
            AnyController::Tsd(c) => c.sample(input),
        }
    }

    fn save(&self, out: &mut impl FnMut(f64)) {
        match self {
            AnyController::Lqr(c) => SampledUnit::save(c.as_ref(), out),
            AnyController::Tsd(c) => SampledUnit::save(c.as_ref(), out),
        }
    }

    fn restore(&mut self, next: &mut impl FnMut() -> Option<f64>) -> Result<(), ControlError> {
        match self {
            AnyController::Lqr(c) => SampledUnit::restore(c.as_mut(), next),
            AnyController::Tsd(c) => SampledUnit::restore(c.as_mut(), next),
        }
    }
}

impl Analysable for AnyController {
    fn dynamic_states(&self) -> Vec<(usize, &'static str)> {
        match self {
            AnyController::Lqr(c) => c.dynamic_states(),
            AnyController::Tsd(c) => c.dynamic_states(),
        }
    }
}

impl Kind {
    /// The controller in `configuration` (0 tuned, 1 the thesis as printed, docs/THESIS.md
    /// §1), every deviation switch following it, the nominal airframe as its model.
    pub fn make_configured(self, mission: &MissionParams, configuration: i32) -> Result<AnyController, ParamError> {
        Ok(match self {
            Kind::Lqr => {
                let mut c = LqrConfig::with_mission(*mission);
                c.params.configuration = configuration;
                AnyController::Lqr(Box::new(SampledUnit::build(&c)?))
            }
            Kind::Tsd => {
                let mut c = TsdConfig::with_mission(*mission);
                c.params.configuration = configuration;
                AnyController::Tsd(Box::new(SampledUnit::build(&c)?))
            }
        })
    }
}
