//! The wing-borne part of the mission flown in the air mass (tuned configuration, README
//! "Mission in wind"): in a steady wind the transitions and the level leg keep the still-air
//! trajectory **relative to the air** and the reference position drifts with the estimated
//! wind, p_ref = origin + p_t + D, Ḋ = r ŵ. With r = 1 the reference air velocity is the
//! table's own, v_g − ŵ = v_t: the still-air trim (V_t, α_t, β = 0, attitude, thrust,
//! surfaces) is then an exact trim in the steady wind, and the gains scheduled on it are the
//! still-air ones. r ramps from 0 to 1 over the last [`AIR_MASS_RAMP_IN`] s of the first
//! vertical phase (the hover lets go of the ground position and drifts, upright, before the
//! pitch-over) and back to 0 over the first [`AIR_MASS_RAMP_OUT`] s of the last vertical
//! phase (the hover then holds the drifted position against the wind, as in the first).

use flight_mission::Phase;
use nalgebra::Vector3;

use crate::LqrController;

/// Time over which the air-mass weight r rises from 0 to 1 before the first transition (s).
pub const AIR_MASS_RAMP_IN: f64 = 2.0;

/// 3x² − 2x³ on [0, 1].
fn smoothstep(x: f64) -> f64 {
    let x = x.clamp(0.0, 1.0);
    x * x * (3.0 - 2.0 * x)
}

impl LqrController {
    /// The air-mass weight r at mission time `t`: 0 in still air or gusts (the steady-wind
    /// latch [`crate::WIND_INTEGRAL_SPEED`] not reached), in the take-off and landing phases
    /// and in the thesis configuration; otherwise 1 in the transitions and level flight,
    /// ramped (smoothstep) at the end of the first and the start of the last vertical phase.
    pub(crate) fn air_mass_weight(&self, t: f64, tuned: bool) -> f64 {
        if !(tuned && self.wind_integral) || self.ground_active {
            return 0.0;
        }
        let (phase, tau) = self.mission.phase_at(t);
        match phase {
            Phase::Vertical1 => {
                let left = self.mission.t_vertical_1 - tau;
                smoothstep(1.0 - left / AIR_MASS_RAMP_IN)
            }
            Phase::TransitionToLevel | Phase::Level | Phase::TransitionToVertical | Phase::Vertical2 => 1.0,
            _ => 0.0,
        }
    }

    /// Advance the air-mass drift D of the reference position by one sample (Ḋ = r ŵ, the
    /// horizontal wind estimate; (N, E, h)) and keep r for the sample's air-data reference
    /// ([`Self::reference_wind`]). Only finite values are committed.
    pub(crate) fn update_air_mass_drift(&mut self, t: f64, tuned: bool) {
        let r = self.air_mass_weight(t, tuned);
        self.air_mass_r = r;
        if r == 0.0 || !self.wind.iter().all(|v| v.is_finite()) {
            return;
        }
        let d = self.drift + self.mission.sample_time * r * self.drifting_wind(&self.wind);
        if d.iter().all(|v| v.is_finite()) {
            self.drift = d;
        }
    }

    /// The wind the reference's air data and wind trim see: ŵ less r times its horizontal
    /// part (the part the drifting reference moves with).
    pub(crate) fn reference_wind(&self, w: &Vector3<f64>) -> Vector3<f64> {
        if self.air_mass_r == 0.0 {
            *w
        } else {
            w - self.air_mass_r * self.drifting_wind(w)
        }
    }

    /// The part of the wind `w` the reference drifts with (N, E, 0): the horizontal wind less
    /// a headwind along the mission track (a headwind is carried in the pitch plane by the
    /// wind trim and the air-data reference, README "Gusts").
    pub(crate) fn drifting_wind(&self, w: &Vector3<f64>) -> Vector3<f64> {
        let (s, c) = self.trajectory.at(f64::INFINITY).euler_321.z.sin_cos();
        let along = w.x * c + w.y * s;
        let head = along.min(0.0);
        Vector3::new(w.x - head * c, w.y - head * s, 0.0)
    }

    /// The velocity (NED) the reference drifts with at the current sample, r times the
    /// drifting part of the wind estimate.
    pub(crate) fn drift_velocity(&self) -> Vector3<f64> {
        if self.air_mass_r == 0.0 || !self.wind.iter().all(|v| v.is_finite()) {
            return Vector3::zeros();
        }
        self.air_mass_r * self.drifting_wind(&self.wind)
    }

    /// The air-mass drift D of the reference position (N, E, h) (m).
    pub fn air_mass_drift(&self) -> Vector3<f64> {
        self.drift
    }
}
