//! The wing-borne part of the mission flown in the air mass (tuned configuration, README
//! "Mission in wind"): in a steady wind the transitions, the level leg and the last vertical
//! phase keep the still-air trajectory **relative to the air** and the reference position
//! drifts with the estimated wind, p_ref = origin + p_t + D, Ḋ = r ŵ_d (ŵ_d: the horizontal
//! wind estimate less a headwind along the track, which the wind trim carries in the pitch
//! plane). With r = 1 the reference air velocity is the table's own, v_g − ŵ_d = v_t: the
//! still-air trim (V_t, α_t, β = 0, attitude, thrust, surfaces) is then an exact trim in the
//! steady wind, and the gains linearised about it are the still-air ones. r rises
//! (smoothstep) over [`AIR_MASS_RAMP`] s ending [`AIR_MASS_RAMP_END`] s into the first
//! transition: the hover lets go of the ground position and drifts, upright, while it
//! pitches over. The take-off and landing phases hold the ground (r = 0); the approach
//! starts from the drifted reference with its drift velocity.

use flight_mission::Phase;
use nalgebra::Vector3;

use crate::LqrController;

/// Time over which the air-mass weight r rises (smoothstep) from 0 to 1 (s).
pub const AIR_MASS_RAMP: f64 = 7.0;
/// Time into the first transition at which r reaches 1 (s): the ramp starts
/// [`AIR_MASS_RAMP`] − this before the transition.
pub const AIR_MASS_RAMP_END: f64 = 2.5;

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
        let end = self.mission.t_vertical_1 + AIR_MASS_RAMP_END;
        match self.mission.phase_at(t).0 {
            Phase::Vertical1 | Phase::TransitionToLevel => smoothstep(1.0 - (end - t) / AIR_MASS_RAMP),
            Phase::Level | Phase::TransitionToVertical | Phase::Vertical2 => 1.0,
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
