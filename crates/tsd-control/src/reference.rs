//! Reference stage (Fig. 4.2, the trajectory input of the outer loop): the kinematic reference of §4.3.3
//! (position, velocity, specific acceleration Σ^RE (4.3.35–4.3.36), flight-path angle), or
//! the take-off and landing phases around it (`guidance::ground`), and the heading of
//! the weathervane that turns the prescribed normal vector of §4.3.2.1.

use crate::trajectory::Reference;
use crate::TsdController;
use flight_mission::{ControllerInput, ControllerOutput, Measurement, Phase};
use guidance::GroundMode;
use nalgebra::Vector3;

/// Least thrust of the take-off climb while the gear carries weight, in weights (–).
pub const LIFTOFF_THRUST: f64 = 1.15;
/// Height above the take-off point below which the take-off climb counts as on the gear (m):
/// in the air the wing's force along the thrust axis in a wind looks like a gear reaction.
pub const LIFTOFF_HEIGHT: f64 = 0.1;
/// Horizontal wind load on the aircraft standing on its gear per (m/s)² of air-data wind
/// (N s²/m²): the plant's belly-on 42 N at 10 m/s (`tailsitter_physics::ground`), the
/// largest of its faces.
pub const GEAR_WIND_LOAD: f64 = 0.42;
/// Gear's half-spread over the CG's height on the gear, b/h over the fin points (–): the
/// gear tips over a point once the horizontal load exceeds N b/h (`tailsitter_physics::ground`).
pub const GEAR_TIP_RATIO: f64 = 0.56;
/// Margin of the spin-up's normal force over the tip-over bound (–).
pub const GEAR_TIP_MARGIN: f64 = 2.0;

/// The reference signals of one flying sample.
#[derive(Debug, Clone, Copy)]
pub(crate) struct ReferenceSignals {
    /// Mission time of the trajectory (the FMU time shifted by the take-off; NaN in the
    /// take-off and landing phases).
    pub t_mission: f64,
    /// Reference of §4.3.3 (or the ground phases' vertical reference).
    pub reference: Reference,
    /// Reference position with every offset (NED).
    pub ref_pos: Vector3<f64>,
    /// Feed-forward Σ = a − g of the vertical reference of the take-off and landing phases;
    /// `None` on the mission.
    pub sigma_ground: Option<Vector3<f64>>,
    /// Weathervane heading ψ_w about the earth's down axis (rad); 0 in still air and in the
    /// take-off and landing phases.
    pub heading: f64,
}

impl ReferenceSignals {
    /// In the take-off and landing phases (their own vertical reference and loop design).
    pub fn ground_phase(&self) -> bool {
        self.sigma_ground.is_some()
    }
}

/// What the reference stage found: a flying sample, or on the gear (no loop runs).
pub(crate) enum ReferenceStage {
    Flying(ReferenceSignals),
    OnGear { phase: Phase, thrust: f64 },
}

impl TsdController {
    /// Reference (§4.3.3) at the sample, or the take-off / landing phases around it, then
    /// the weathervane's heading (README, "Weathervaning").
    pub(crate) fn reference_stage(&mut self, input: &ControllerInput) -> ReferenceStage {
        let meas = &input.measurement;
        let g = self.airframe.gravity;
        let trajectory = &self.trajectory;
        let origin = self.ground.origin().unwrap_or_else(Vector3::zeros);
        let mission_ref = |tm: f64| {
            let r = trajectory.at(tm);
            (r.pos + input.ref_offset_ned + origin, r.vel)
        };
        // Mission time of the trajectory (the FMU time shifted by the take-off), the
        // reference, its position with every offset, and the feed-forward Σ of a vertical
        // reference of the ground phases.
        let (t_mission, reference, ref_pos, sigma_ground) = match self.ground.step(input.t, meas, mission_ref) {
            GroundMode::Mission { t, offset } => {
                let r = self.trajectory.at(t);
                let shift = offset + origin;
                (t, r, r.pos + input.ref_offset_ned + shift, None)
            }
            GroundMode::Vertical(v) => {
                let r = Reference {
                    phase: v.phase,
                    pos: v.pos,
                    vel: v.vel,
                    specific_accel: v.accel - Vector3::new(0.0, 0.0, g),
                    airspeed: v.vel.norm(),
                    gamma: core::f64::consts::FRAC_PI_2,
                };
                (f64::NAN, r, v.pos + input.ref_offset_ned, Some(r.specific_accel))
            }
            GroundMode::Idle { phase, thrust } => return ReferenceStage::OnGear { phase, thrust },
        };
        // Heading reference (weathervane, README "Weathervaning"): the prescribed normal
        // vector turned about the earth's down axis by ψ_w; zero in still air and in the
        // take-off and landing phases (their own vertical reference).
        let heading = if sigma_ground.is_some() {
            // Take-off and landing phases (README, "Take-off and landing in wind"): the belly
            // or the back into the measured wind.
            // The take-off climb on the front transition's face (README, "Missions in wind").
            let target = if reference.phase == Phase::TakeOff {
                self.wind_mission.takeoff_target(&self.weathervane)
            } else {
                self.wind_mission.ground_target(&self.weathervane, reference.phase)
            };
            self.weathervane.update_towards(&self.mission, input.t, meas, target)
        } else {
            // Mission logic in wind (README, "Missions in wind"): the heading of the
            // handover, the transitions and level flight.
            let target = self.wind_mission.target(
                &self.weathervane,
                &self.mission,
                t_mission,
                meas,
                &reference.specific_accel,
            );
            self.weathervane.update_towards(&self.mission, t_mission, meas, target)
        };
        ReferenceStage::Flying(ReferenceSignals {
            t_mission,
            reference,
            ref_pos,
            sigma_ground,
            heading: heading.heading,
        })
    }

    /// Take-off climb on the gear (README, "Take-off and landing in wind"): while the gear
    /// still carries weight ([`guidance::GroundPhases::gear_share`] above
    /// [`guidance::ground::CONTACT_REACTION`]) within [`LIFTOFF_HEIGHT`] of the take-off
    /// point, the virtual thrust command `thrust` (N) is raised to at least [`LIFTOFF_THRUST`]
    /// weights through the thrust integrator, so the aircraft leaves the gear before a wind
    /// tips it over a leg, and the loop takes the raised thrust over in the air (no step
    /// back down when the gear unloads). Tuned configuration only.
    pub(crate) fn takeoff_lift(
        &mut self,
        s: &crate::SampleSignals,
        thrust: &mut f64,
        dev: crate::deviations::Deviations,
    ) {
        if !dev.hover_wind_design || s.r.reference.phase != Phase::TakeOff {
            return;
        }
        let meas = s.meas;
        let height = self.ground.origin().map_or(f64::INFINITY, |o| o.z - meas.pos_ned.z);
        if !(height < LIFTOFF_HEIGHT && self.ground.gear_share(meas) > guidance::ground::CONTACT_REACTION) {
            return;
        }
        let floor = (LIFTOFF_THRUST * self.airframe.mass * self.airframe.gravity).min(self.airframe.thrust_max);
        let raise = floor - *thrust;
        if raise > 0.0 {
            *thrust = floor;
            // The integrator's contribution to T_c is u_I (as accelerations) or −K_E·E.
            self.integrators.thrust += if dev.integrators_as_accelerations {
                raise
            } else {
                raise / -s.d.axial.1
            };
        }
    }

    /// On the gear: no loop runs (no integrator wind-up); the next flight phase starts
    /// bumpless from the measured thrust and surfaces.
    pub(crate) fn on_gear(&mut self, meas: &Measurement, phase: Phase, thrust: f64) -> ControllerOutput {
        let thrust = self.spinup_thrust_in_wind(meas, phase, thrust);
        self.initialized = false;
        self.saturated = 0;
        ControllerOutput::on_gear(meas, phase, thrust, self.airframe.thrust_min, self.airframe.thrust_max)
    }

    /// Spin-up thrust on the gear in wind (README, "Take-off and landing in wind"): the
    /// ramp's `thrust` (N), limited so that the gear keeps the normal force
    /// N = m g − T ≥ [`GEAR_TIP_MARGIN`] F_w / [`GEAR_TIP_RATIO`] against the measured wind's
    /// load F_w = [`GEAR_WIND_LOAD`] |ŵ_h|² (ŵ the instantaneous air-data wind, gusts
    /// included): the thrust takes weight off the gear, and a gust then tips the aircraft
    /// over a gear point (or slides it) before the take-off. The take-off climb lifts off
    /// at once ([`Self::takeoff_lift`]). Tuned configuration only; still air unchanged.
    pub(crate) fn spinup_thrust_in_wind(&self, meas: &Measurement, phase: Phase, thrust: f64) -> f64 {
        if phase != Phase::OnGround || !self.deviations().hover_wind_design {
            return thrust;
        }
        let w = guidance::weathervane::air_data_wind(meas).xy();
        if !(w.x.is_finite() && w.y.is_finite()) {
            return thrust;
        }
        let load = GEAR_WIND_LOAD * w.norm_squared();
        let weight = self.airframe.mass * self.airframe.gravity;
        thrust.min((weight - GEAR_TIP_MARGIN * load / GEAR_TIP_RATIO).max(0.0))
    }
}
