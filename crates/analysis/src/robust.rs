//! Beyond the thesis: nonlinear robustness. The whole default mission (vertical →
//! transition → level → transition → vertical) is flown in the nonlinear closed loop
//! ([`closed_loop::fly`]) with a modified plant or a gust, and judged by the controller
//! issues' completion criteria ([`closed_loop::MissionCheck::passed`]: airspeed within
//! 1 m/s and pitch within 5° of trim over the last 5 s of level flight, within 10° of
//! vertical at the end, every value finite, no failure). The plant's aerodynamics are
//! chosen per flight (issue 13): the thesis's linear model ([`AeroModel::Thesis`], the
//! controllers' design model and [`Plant::new`]'s choice) or the global model
//! ([`AeroModel::Global`], the plant FMU's default); no ground in either.

use closed_loop::{fly, plant_inputs, MissionCheck, Scenario, Wind};
use flight_mission::MissionParams;
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};
use tailsitter_physics::{AeroModel, Airframe, Plant};

use crate::closed::Analysable;

/// Outcome of one mission flight.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct FlightOutcome {
    /// Mission criteria met.
    pub passed: bool,
    /// Reached the stop time (no controller or plant failure).
    pub completed: bool,
    /// Failure message, if it stopped early.
    pub failure: Option<String>,
    /// Largest position error over the flight (m) (up to a failure).
    pub max_pos_error: f64,
    /// Largest |V − v_level| over the last 5 s of level flight (m/s).
    pub level_airspeed_error: f64,
    /// Largest |θ − θ_trim| over the last 5 s of level flight (deg).
    pub level_pitch_error_deg: f64,
    /// Largest |α| of the free stream over the flight (deg).
    #[serde(default)]
    pub max_alpha_deg: f64,
    /// Largest `stall_fraction` over the flight (share of the wing in post-stall flow; for
    /// the thesis's model: how far outside its validity it was used).
    #[serde(default)]
    pub max_stall_fraction: f64,
}

/// A plant with `airframe` and aerodynamic `model` (no ground).
pub fn plant(airframe: &Airframe, model: AeroModel) -> Plant {
    let mut p = Plant::new(*airframe);
    p.aero.model = model;
    p
}

/// Fly the mission of `scenario` with `controller` on a plant with `airframe` and the
/// aerodynamic `model`, from the plant's own vertical-climb trim (the nominal one if the
/// modified plant cannot trim).
pub fn fly_mission<C: Analysable>(
    airframe: &Airframe,
    model: AeroModel,
    mut controller: C,
    scenario: &Scenario,
) -> FlightOutcome {
    let plant = plant(airframe, model);
    let nominal = plant_nominal(model);
    let m = &scenario.mission;
    let x0 = plant
        .trim_vertical_climb(m.v_vertical)
        .or_else(|_| nominal.trim_vertical_climb(m.v_vertical))
        .map(|t| t.state);
    let theta = plant
        .trim_level(m.v_level)
        .or_else(|_| nominal.trim_level(m.v_level))
        .map(|t| t.theta);
    let (Ok(x0), Ok(theta)) = (x0, theta) else {
        return FlightOutcome {
            passed: false,
            completed: false,
            failure: Some("no trim".into()),
            max_pos_error: f64::MAX,
            level_airspeed_error: f64::MAX,
            level_pitch_error_deg: f64::MAX,
            max_alpha_deg: f64::NAN,
            max_stall_fraction: f64::NAN,
        };
    };
    let trace = fly(&plant, x0, &mut controller, scenario);
    let check = MissionCheck::of(&trace, m, theta);
    let finite = |v: f64| if v.is_finite() { v } else { f64::MAX };
    let (mut alpha, mut stall) = (0.0f64, 0.0f64);
    for s in &trace.samples {
        alpha = alpha.max(s.measurement.alpha.abs());
        let y = plant.outputs(&s.x, &plant_inputs(&s.command), &s.wind);
        stall = stall.max(y.stall_fraction);
    }
    FlightOutcome {
        passed: trace.completed() && check.passed(),
        completed: trace.completed(),
        failure: trace.failure.clone(),
        max_pos_error: finite(trace.max_pos_error()),
        level_airspeed_error: finite(check.level_airspeed_error),
        level_pitch_error_deg: finite(check.level_pitch_error.to_degrees()),
        max_alpha_deg: alpha.to_degrees(),
        max_stall_fraction: stall,
    }
}

fn plant_nominal(model: AeroModel) -> Plant {
    plant(&Airframe::default(), model)
}

/// Where in the mission a gust hits.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum GustPhase {
    /// First vertical phase (3 m/s climb), gust from t = 1.5 s.
    Vertical,
    /// Centred on the middle of the first transition.
    Transition,
    /// Level flight, from 2 s after its start.
    Level,
}

impl GustPhase {
    /// All three.
    pub const ALL: [GustPhase; 3] = [GustPhase::Vertical, GustPhase::Transition, GustPhase::Level];

    /// Lower-case name.
    pub fn name(self) -> &'static str {
        match self {
            GustPhase::Vertical => "vertical",
            GustPhase::Transition => "transition",
            GustPhase::Level => "level",
        }
    }

    /// Start time of a gust of `duration` in `mission`.
    pub fn start(self, mission: &MissionParams, duration: f64) -> f64 {
        let s = mission.phase_starts();
        match self {
            GustPhase::Vertical => (s[1] - duration).clamp(0.0, 1.5),
            GustPhase::Transition => s[1] + 0.5 * mission.t_transition_1 - 0.5 * duration,
            GustPhase::Level => s[2] + 2.0,
        }
    }
}

/// Gust duration (s) of the sweep.
pub const GUST_DURATION: f64 = 2.0;

/// Earth axis names of the gust directions.
pub const AXES: [&str; 3] = ["n", "e", "d"];

/// The default mission with a 1−cos gust of `amplitude` (m/s) along NED `axis`.
pub fn gust_scenario(mission: &MissionParams, phase: GustPhase, axis: usize, amplitude: f64) -> Scenario {
    let mut sc = Scenario::mission(*mission);
    let mut a = Vector3::zeros();
    a[axis] = amplitude;
    sc.wind = Wind::OneMinusCosine {
        t_start: phase.start(mission, GUST_DURATION),
        duration: GUST_DURATION,
        amplitude: a,
    };
    sc
}

/// Largest contiguous passing range of factors around the nominal index:
/// (lowest, highest) factor, or None if the nominal flight itself fails.
pub fn passing_range(factors: &[f64], passed: &[bool], nominal: usize) -> Option<(f64, f64)> {
    if !passed.get(nominal).copied().unwrap_or(false) {
        return None;
    }
    let mut lo = nominal;
    while lo > 0 && passed[lo - 1] {
        lo -= 1;
    }
    let mut hi = nominal;
    while hi + 1 < passed.len() && passed[hi + 1] {
        hi += 1;
    }
    Some((factors[lo], factors[hi]))
}

/// Largest amplitude A of an ascending grid such that every amplitude ≤ A passed
/// (0 if the smallest fails).
pub fn largest_survived(amplitudes: &[f64], passed: &[bool]) -> f64 {
    let mut best = 0.0;
    for (a, p) in amplitudes.iter().zip(passed) {
        if *p {
            best = *a;
        } else {
            break;
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges() {
        let f = [0.5, 0.75, 1.0, 1.25, 1.5];
        assert_eq!(
            passing_range(&f, &[false, true, true, true, false], 2),
            Some((0.75, 1.25))
        );
        assert_eq!(passing_range(&f, &[true, true, false, true, true], 2), None);
        assert_eq!(largest_survived(&[1.0, 2.0, 3.0], &[true, true, false]), 2.0);
        assert_eq!(largest_survived(&[1.0, 2.0, 3.0], &[false, true, true]), 0.0);
    }
}
