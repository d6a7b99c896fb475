//! LQR weights (thesis §3.4): per flight phase (Vertical, Tran1, Level, Tran2) the maximum
//! deviations of Table 3.4 in the units of Table 3.1, turned into
//! `Q₁ = diag(1/dev²)` (3.4.1, 3.4.3) and `Q₂ = R · diag(1/dev²)` (3.4.2), in SI units
//! (deg → rad). Tables are JSON ([`DEFAULT_WEIGHTS_JSON`] is embedded); between phases the
//! weights are blended geometrically over a short interval so the gains have no steps.

use flight_mission::{MissionParams, Phase};
use nalgebra::SVector;
use serde::Deserialize;

use crate::model::{NA, NU};

/// The embedded weight tables (`resources/weights.json`).
pub const DEFAULT_WEIGHTS_JSON: &str = include_str!("../resources/weights.json");

/// Maximum deviations of one phase, units of Table 3.1 (angles deg, rates deg/s).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
pub struct MaxDeviations {
    pub v_int: f64,
    pub v: f64,
    pub alpha: f64,
    pub beta: f64,
    pub p: f64,
    pub q: f64,
    pub r: f64,
    pub phi: f64,
    pub theta: f64,
    pub psi: f64,
    pub n: f64,
    pub e: f64,
    pub h: f64,
    pub thrust: f64,
    /// Position integrators ∫ΔN, ∫ΔE, ∫Δh (m·s) (extension; absent = the default below).
    #[serde(default = "default_pos_int")]
    pub n_int: f64,
    #[serde(default = "default_pos_int")]
    pub e_int: f64,
    #[serde(default = "default_pos_int")]
    pub h_int: f64,
    pub thrust_cmd: f64,
    pub elevator: f64,
    pub aileron: f64,
    pub rudder: f64,
    pub flap_collective: f64,
    pub flap_differential: f64,
    pub vertical_flap: f64,
    /// R of (3.4.2).
    pub r_scale: f64,
}

/// Maximum deviation of a position integrator when a table does not give one (m·s).
pub const DEFAULT_POSITION_INTEGRAL_DEVIATION: f64 = 0.3;

fn default_pos_int() -> f64 {
    DEFAULT_POSITION_INTEGRAL_DEVIATION
}

/// One named set of four phase tables.
#[derive(Debug, Clone, PartialEq, Deserialize)]
pub struct WeightSet {
    pub name: String,
    #[serde(default)]
    pub description: String,
    pub vertical: MaxDeviations,
    pub transition_1: MaxDeviations,
    pub level: MaxDeviations,
    pub transition_2: MaxDeviations,
}

#[derive(Debug, Clone, Deserialize)]
struct WeightFile {
    sets: Vec<WeightSet>,
}

/// Diagonal weights in SI units: state (integrator first, then the model states) and input.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Weights {
    /// diag Q₁ over [∫ΔV, V, α, β, p, q, r, φ, θ, ψ, N, E, h, T, ∫ΔN, ∫ΔE, ∫Δh].
    pub q: SVector<f64, NA>,
    /// diag Q₂ over [T_c, δe, δa, δr, δfc, δfd, δv], R included.
    pub r: SVector<f64, NU>,
}

impl MaxDeviations {
    /// (3.4.3) in SI units; `r_scale` multiplies R of the table.
    pub fn weights(&self, r_scale: f64) -> Result<Weights, String> {
        let d = 1f64.to_radians();
        let states = [
            self.v_int,
            self.v,
            self.alpha * d,
            self.beta * d,
            self.p * d,
            self.q * d,
            self.r * d,
            self.phi * d,
            self.theta * d,
            self.psi * d,
            self.n,
            self.e,
            self.h,
            self.thrust,
            self.n_int,
            self.e_int,
            self.h_int,
        ];
        let inputs = [
            self.thrust_cmd,
            self.elevator * d,
            self.aileron * d,
            self.rudder * d,
            self.flap_collective * d,
            self.flap_differential * d,
            self.vertical_flap * d,
        ];
        if states.iter().chain(inputs.iter()).any(|x| !(x.is_finite() && *x > 0.0)) {
            return Err("every maximum deviation must be finite and > 0 (no zero weights, §3.4)".into());
        }
        let rr = self.r_scale * r_scale;
        if !(rr.is_finite() && rr > 0.0) {
            return Err(format!("control weight scale R = {rr} must be > 0"));
        }
        Ok(Weights {
            q: SVector::from_iterator(states.iter().map(|x| 1.0 / (x * x))),
            r: SVector::from_iterator(inputs.iter().map(|x| rr / (x * x))),
        })
    }
}

/// The weights of the four phases in SI units, ready for blending.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WeightSchedule {
    /// Vertical, Tran1, Level, Tran2.
    pub phases: [Weights; 4],
    /// Blend time after a phase boundary (s).
    pub blend_time: f64,
}

/// Parse a weights JSON document and pick set `index`.
pub fn load_set(json: &str, index: usize) -> Result<WeightSet, String> {
    let file: WeightFile = serde_json::from_str(json).map_err(|e| format!("weights JSON: {e}"))?;
    let n = file.sets.len();
    file.sets
        .into_iter()
        .nth(index)
        .ok_or_else(|| format!("weight_set = {index}: the table has {n} sets"))
}

fn table_index(phase: Phase) -> usize {
    match phase {
        Phase::Vertical1 | Phase::Vertical2 => 0,
        // Take-off and landing (guidance::ground): vertical flight.
        Phase::OnGround | Phase::TakeOff | Phase::Approach | Phase::Descent | Phase::Flare | Phase::Landed => 0,
        Phase::TransitionToLevel => 1,
        Phase::Level => 2,
        Phase::TransitionToVertical => 3,
    }
}

impl WeightSchedule {
    /// From a weight set; `r_scale` multiplies every phase's R.
    pub fn new(set: &WeightSet, r_scale: f64, blend_time: f64) -> Result<Self, String> {
        Ok(Self {
            phases: [
                set.vertical.weights(r_scale)?,
                set.transition_1.weights(r_scale)?,
                set.level.weights(r_scale)?,
                set.transition_2.weights(r_scale)?,
            ],
            blend_time: blend_time.max(0.0),
        })
    }

    /// Weights at mission time t: the phase's table, blended geometrically (log-linear,
    /// with a smoothstep in time) from the previous phase's over `blend_time` after the
    /// boundary, so Q and R — and the gains — change without steps.
    pub fn at(&self, mission: &MissionParams, t: f64) -> Weights {
        let (phase, tau) = mission.phase_at(t);
        let cur = self.phases[table_index(phase)];
        let prev = match phase {
            Phase::Vertical1 => return cur,
            Phase::OnGround | Phase::TakeOff | Phase::Approach | Phase::Descent | Phase::Flare | Phase::Landed => {
                return cur
            }
            Phase::TransitionToLevel => Phase::Vertical1,
            Phase::Level => Phase::TransitionToLevel,
            Phase::TransitionToVertical => Phase::Level,
            Phase::Vertical2 => Phase::TransitionToVertical,
        };
        if self.blend_time <= 0.0 || tau >= self.blend_time {
            return cur;
        }
        let s = tau / self.blend_time;
        let l = s * s * (3.0 - 2.0 * s);
        let p = self.phases[table_index(prev)];
        let mix = |a: f64, b: f64| (a.ln() * (1.0 - l) + b.ln() * l).exp();
        Weights {
            q: p.q.zip_map(&cur.q, mix),
            r: p.r.zip_map(&cur.r, mix),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn embedded_table_is_table_3_4() {
        let set = load_set(DEFAULT_WEIGHTS_JSON, 0).unwrap();
        assert_eq!(set.name, "thesis_table_3_4");
        assert_eq!(set.level.theta, 0.05);
        assert_eq!(set.vertical.r_scale, 100.0);
        let w = set.level.weights(1.0).unwrap();
        // θ: 1/(0.05°)² in rad⁻².
        assert!((w.q[8] - 1.0 / (0.05f64.to_radians().powi(2))).abs() < 1e-6);
        // δe: R · 1/(0.3°)².
        assert!((w.r[1] - 75.0 / (0.3f64.to_radians().powi(2))).abs() < 1e-3);
    }

    #[test]
    fn blending_is_continuous() {
        let set = load_set(DEFAULT_WEIGHTS_JSON, 0).unwrap();
        let s = WeightSchedule::new(&set, 1.0, 1.0).unwrap();
        let m = MissionParams::default();
        for b in &m.phase_starts()[1..5] {
            let a = s.at(&m, b - 1e-9);
            let c = s.at(&m, b + 1e-9);
            for i in 0..NA {
                assert!((a.q[i] / c.q[i] - 1.0).abs() < 1e-6);
            }
        }
    }
}
