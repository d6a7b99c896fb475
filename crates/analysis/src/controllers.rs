//! The controllers behind one type, so the sweeps treat them alike: the thesis's two
//! (LQR, TSD) and PX4's tail-sitter control path (`px4-control`), which has no thesis
//! configuration (its parameters are PX4's, with the airframe's derived values).

use flight_mission::{ControlError, ControllerInput, ControllerOutput, MissionParams, ParamError, SampledUnit};
use lqr_control::{LqrConfig, LqrController};
use px4_control::{Px4Config, Px4Controller};
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
    /// PX4-Autopilot's tail-sitter VTOL control path (`px4-control`, PX4's parameters).
    Px4,
}

impl Kind {
    /// Every controller: the thesis's two in its order, then PX4.
    pub const ALL: [Kind; 3] = [Kind::Lqr, Kind::Tsd, Kind::Px4];

    /// The thesis's controllers: the analyses that compare with the thesis's printed
    /// figures or fly its configurations (Table 5.1, the reproduction) apply to these only.
    pub const THESIS: [Kind; 2] = [Kind::Lqr, Kind::Tsd];

    /// "LQR" / "TSD" / "PX4".
    pub fn name(self) -> &'static str {
        match self {
            Kind::Lqr => "LQR",
            Kind::Tsd => "TSD",
            Kind::Px4 => "PX4",
        }
    }

    /// Whether the controller is the thesis's (has its printed figures and its
    /// `configuration` switch, 0 tuned, 1 thesis).
    pub fn in_thesis(self) -> bool {
        self != Kind::Px4
    }

    /// The thesis's Table 5.1 entry (%) of parameter `p` for this controller (none for PX4).
    pub fn thesis_percent(self, p: &crate::sensitivity::Param) -> Option<f64> {
        match self {
            Kind::Lqr => Some(p.thesis.0),
            Kind::Tsd => Some(p.thesis.1),
            Kind::Px4 => None,
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
            Kind::Px4 => AnyController::Px4(Box::new(
                Px4Controller::build(&Px4Config::with_mission(*mission)).expect("default PX4"),
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
    /// PX4.
    Px4(Box<Px4Controller>),
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
            Kind::Px4 => AnyController::Px4(Box::new(SampledUnit::build(&Px4Config::with_mission(*mission))?)),
        })
    }

    fn sample_time((_, mission): &(Kind, MissionParams)) -> f64 {
        mission.sample_time
    }

    fn sample(&mut self, input: &ControllerInput) -> Result<ControllerOutput, ControlError> {
        match self {
            AnyController::Lqr(c) => c.sample(input),
            AnyController::Tsd(c) => c.sample(input),
            AnyController::Px4(c) => c.sample(input),
        }
    }

    fn save(&self, out: &mut impl FnMut(f64)) {
        match self {
            AnyController::Lqr(c) => SampledUnit::save(c.as_ref(), out),
            AnyController::Tsd(c) => SampledUnit::save(c.as_ref(), out),
            AnyController::Px4(c) => SampledUnit::save(c.as_ref(), out),
        }
    }

    fn restore(&mut self, next: &mut impl FnMut() -> Option<f64>) -> Result<(), ControlError> {
        match self {
            AnyController::Lqr(c) => SampledUnit::restore(c.as_mut(), next),
            AnyController::Tsd(c) => SampledUnit::restore(c.as_mut(), next),
            AnyController::Px4(c) => SampledUnit::restore(c.as_mut(), next),
        }
    }
}

impl Analysable for AnyController {
    fn dynamic_states(&self) -> Vec<(usize, &'static str)> {
        match self {
            AnyController::Lqr(c) => c.dynamic_states(),
            AnyController::Tsd(c) => c.dynamic_states(),
            AnyController::Px4(c) => c.dynamic_states(),
        }
    }
}

impl Kind {
    /// The controller in `configuration` (0 tuned, 1 the thesis as printed, docs/THESIS.md
    /// §1), every deviation switch following it, the nominal airframe as its model. PX4 has
    /// no thesis configuration: 0 is its default tuning, anything else an error.
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
            Kind::Px4 if configuration == 0 => {
                AnyController::Px4(Box::new(SampledUnit::build(&Px4Config::with_mission(*mission))?))
            }
            Kind::Px4 => {
                return Err(ParamError(format!(
                    "configuration = {configuration}: PX4 has no thesis configuration (0 only)"
                )))
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::closed::{poles_at, Analysable, Condition};
    use tailsitter_physics::{Airframe, Plant};

    /// The PX4 states the pole analysis perturbs are where `Px4Controller::save` writes
    /// them: after a flight into the front transition (rates far from zero) the previous
    /// body rates are the rates of the last measurement; the states follow the mode
    /// (multicopter loops in the climb and the transitions, fixed-wing in level flight).
    #[test]
    fn px4_dynamic_states_follow_the_saved_layout_and_the_mode() {
        let mission = MissionParams::default();
        let plant = Plant::new(Airframe::default());
        let x0 = plant.trim_vertical_climb(mission.v_vertical).unwrap().state;
        let starts = mission.phase_starts();
        for (t, first) in [
            (starts[1] - 1.0, "I_vel_n"),
            (starts[1] + 1.0, "I_vel_n"),
            (starts[3] - 1.0, "I_fw_p"),
        ] {
            let mut c = Kind::Px4.make(&mission);
            let mut sc = closed_loop::Scenario::mission(mission);
            sc.stop_time = t;
            let tr = closed_loop::fly(&plant, x0, &mut c, &sc);
            let last = tr.samples.last().unwrap();
            let dyn_states = c.dynamic_states();
            assert_eq!(dyn_states[0].1, first, "t = {t}");
            let s = c.save_state();
            let prev: Vec<f64> = dyn_states[dyn_states.len() - 3..].iter().map(|d| s[d.0]).collect();
            assert_eq!(prev, last.measurement.rates.as_slice(), "t = {t}");
        }
    }

    /// PX4's closed loop in level flight is stable, the along-track position included (the
    /// fixed-wing airspeed setpoint is corrected from the along-track error): every pole
    /// inside the unit circle, the slowest still well away from it.
    #[test]
    fn px4_closed_loop_in_level_flight_is_stable() {
        let mission = MissionParams::default();
        let plant = Plant::new(Airframe::default());
        let p = poles_at(&plant, Kind::Px4.make(&mission), &mission, Condition::Level).unwrap();
        let worst = p.discrete.iter().map(|e| e.value.norm()).fold(0.0, f64::max);
        assert!(worst < 1.0 - 1e-4, "max |z| = {worst}");
    }

    /// In the climb every pole lies in the left half plane with a margin (with PX4's
    /// default MC_ROLL_P = 6.5 the roll-rate loop about the belly axis, no faster than the
    /// attitude loop, gave a growing pair at s = +0.37 ± 7.4j), and the nonlinear flight
    /// agrees: a kick in the body rate r (about the belly axis, PX4's multicopter roll axis
    /// on a tail-sitter) stays below 30 % of the kick over 2 s to 4 s (measured: 22 %).
    #[test]
    fn px4_climb_poles_are_stable_and_a_kicked_flight_decays() {
        let mission = MissionParams::default();
        let plant = Plant::new(Airframe::default());
        let p = poles_at(&plant, Kind::Px4.make(&mission), &mission, Condition::Vertical).unwrap();
        let worst_re = p.poles.iter().map(|s| s.re).fold(f64::MIN, f64::max);
        assert!(worst_re < -0.1, "largest real part {worst_re}");
        let kick = 1e-3;
        let mut x = plant.trim_vertical_climb(mission.v_vertical).unwrap().state;
        x[tailsitter_physics::idx::R] += kick;
        let mut sc = closed_loop::Scenario::mission(mission);
        sc.stop_time = 4.0;
        let tr = closed_loop::fly(&plant, x, &mut Kind::Px4.make(&mission), &sc);
        assert!(tr.failure.is_none(), "{:?}", tr.failure);
        let late = tr
            .samples
            .iter()
            .filter(|s| s.t >= 2.0)
            .map(|s| s.x[tailsitter_physics::idx::R].abs())
            .fold(0.0, f64::max);
        assert!(late < 0.3 * kick, "late |r| = {late}");
    }
}
