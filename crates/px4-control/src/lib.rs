//! PX4-Autopilot's tail-sitter VTOL control path, re-implemented in Rust as a
//! [`flight_mission::SampledUnit`] (read from PX4's sources for facts; every stage cites
//! the PX4 file and function it follows; no code is copied).
//!
//! Stages, one module each, in the order [`Px4Controller::sample`] runs them:
//!
//! * reference: the mission's flight-path profile (`guidance::Profile`, the same reference
//!   the tuned LQR and TSD controllers fly, so position errors compare), the take-off and
//!   landing phases (`guidance::ground`); in PX4 terms, the navigator's setpoints;
//! * the VTOL mode logic of PX4's tail-sitter (`tailsitter`: multicopter, front
//!   transition, fixed wing, back transition; PX4
//!   `src/modules/vtol_att_control/tailsitter.cpp`);
//! * multicopter: `position` (PX4 `PositionControl`) → thrust vector → attitude
//!   (`attitude::body_z_to_attitude`) → `attitude` (PX4 `AttitudeControl`) → `rate`
//!   (PX4 `RateControl`), in the multicopter frame of a tail-sitter (README, "Frames");
//! * transitions: PX4's timed pitch ramp of the attitude setpoint, flown by the multicopter
//!   attitude and rate loops, the thrust from the multicopter height loop;
//! * fixed wing: `fixed_wing` (TECS, L1, attitude loops, airspeed-scaled rate loop);
//! * `allocation`: the normalised torques onto the six surfaces (pseudo-inverse of the
//!   effectiveness, clipping, saturation fed back to the rate loops' anti-windup).
//!
//! Frames: earth NED; body x nose, y right wing, z belly. Units SI, angles rad.

pub mod allocation;
pub mod attitude;
pub mod fixed_wing;
pub mod params;
pub mod position;
pub mod rate;
mod tailsitter;

pub use params::Px4Params;
pub use tailsitter::VtolMode;

use allocation::Effectiveness;
use attitude::AttitudeGains;
use fixed_wing::{Tecs, TecsParams};
use flight_mission::{
    Command, ControlError, ControllerInput, ControllerOutput, Diagnostics, Measurement, MissionParams, Notice,
    ParamError, Phase, SampledUnit,
};
use guidance::{GroundMode, GroundPhases};
use nalgebra::{Quaternion, UnitQuaternion, Vector2, Vector3, Vector6};
use position::{PositionControl, PositionGains, PositionSetpoint};
use rate::{RateControl, RateGains};
use tailsitter_physics::{Airframe, Plant};

/// Everything a [`Px4Controller`] is built from: the FMU's parameters.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Px4Config {
    /// The controller's own model of the airframe (effectiveness, trims, hover thrust).
    pub airframe: Airframe,
    pub mission: MissionParams,
    pub params: Px4Params,
}

impl Px4Config {
    /// The nominal airframe, the given mission and PX4's parameters.
    pub fn with_mission(mission: MissionParams) -> Self {
        Self {
            mission,
            ..Self::default()
        }
    }
}

/// The values derived from the airframe and the mission where a parameter asks for it
/// (README, "Derived parameters"), and the effectiveness of the two regimes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Derived {
    /// MPC_THR_HOVER: the climb trim's thrust at v_vertical over T_max.
    pub thr_hover: f64,
    /// FW_THR_TRIM: the level trim's thrust at v_level over T_max.
    pub thr_trim: f64,
    /// FW_AIRSPD_TRIM (m/s).
    pub airspeed_trim: f64,
    /// FW_PSP_OFF: the level trim's pitch (rad).
    pub pitch_offset: f64,
    /// TRIM_PITCH: normalised pitch torque of the level trim's surfaces.
    pub trim_pitch: f64,
    /// FW_AIRSPD_MIN, VT_ARSP_TRANS (m/s) (the latter FW_AIRSPD_TRIM when derived).
    pub airspeed_min: f64,
    pub transition_airspeed: f64,
    /// FW_T_CLMB_MAX, FW_T_SINK_MIN (m/s).
    pub climb_max: f64,
    pub sink_min: f64,
    /// MPC_Z_VEL_MAX_UP (m/s).
    pub climb_rate_max: f64,
    /// VT_F_TRANS_DUR, VT_B_TRANS_DUR (s).
    pub front_duration: f64,
    pub back_duration: f64,
    /// Effectiveness at the climb trim (multicopter and transitions) and at the level trim.
    pub mc: Effectiveness,
    pub fw: Effectiveness,
}

impl Derived {
    fn of(airframe: &Airframe, mission: &MissionParams, p: &Px4Params) -> Result<Self, ParamError> {
        let plant = Plant::new(*airframe);
        let err = |what: &str, e: &dyn std::fmt::Display| ParamError(format!("controller airframe: {what}: {e}"));
        let climb = plant
            .trim_vertical_climb(mission.v_vertical)
            .map_err(|e| err("no climb trim at v_vertical", &e))?;
        let level = plant
            .trim_level(mission.v_level)
            .map_err(|e| err("no level trim at v_level", &e))?;
        let limit = airframe.deflection_limit;
        let mc = Effectiveness::at(&plant, &climb.state, limit)
            .ok_or_else(|| ParamError("controller airframe: singular surface effectiveness in the hover".into()))?;
        let fw = Effectiveness::at(&plant, &level.state, limit)
            .ok_or_else(|| ParamError("controller airframe: singular surface effectiveness in level flight".into()))?;
        let or = |value: f64, derived: f64| if value > 0.0 { value } else { derived };
        let trim_u = Vector6::from_iterator(allocation::SURFACES.iter().map(|&k| level.state[k]));
        let trim_pitch = if p.TRIM_PITCH >= -1.0 {
            p.TRIM_PITCH
        } else {
            fw.torque_of(&trim_u).y
        };
        // Energy rates at the throttle limits at the level trim: the excess power of full
        // throttle, and the drag power at idle (thrust 0), per unit weight.
        let v_trim = or(p.FW_AIRSPD_TRIM, mission.v_level);
        let weight = airframe.mass * airframe.gravity;
        let climb_max = or(
            p.FW_T_CLMB_MAX,
            (p.FW_THR_MAX * airframe.thrust_max - level.thrust) * v_trim / weight,
        );
        let sink_min = or(p.FW_T_SINK_MIN, level.thrust * v_trim / weight);
        // Level flight at the profile's α limit with the trimmed lift slope.
        let pm = guidance::PointMass::from_level_trim(airframe, mission.v_level)?;
        let stall_like = (2.0 * weight
            / (airframe.air_density * airframe.wing_area * pm.c_l_alpha * mission.transition_alpha_max))
            .sqrt();
        let airspeed_min = or(p.FW_AIRSPD_MIN, stall_like);
        // The profile's largest climb rate v sin γ (its pull-up into the second vertical
        // phase), at least twice v_vertical (the landings' and steps' margin).
        let profile = guidance::Profile::new(mission, &pm, &guidance::ProfileLimits::of(mission))?;
        let profile_climb = profile
            .points()
            .iter()
            .map(|q| q.v * q.gamma.sin())
            .fold(2.0 * mission.v_vertical, f64::max);
        Ok(Self {
            airspeed_min,
            transition_airspeed: or(p.VT_ARSP_TRANS, v_trim),
            climb_max,
            sink_min,
            climb_rate_max: or(p.MPC_Z_VEL_MAX_UP, profile_climb),
            thr_hover: or(p.MPC_THR_HOVER, climb.thrust / airframe.thrust_max),
            thr_trim: or(p.FW_THR_TRIM, level.thrust / airframe.thrust_max),
            airspeed_trim: v_trim,
            pitch_offset: if p.FW_PSP_OFF >= 0.0 { p.FW_PSP_OFF } else { level.theta },
            trim_pitch,
            front_duration: or(p.VT_F_TRANS_DUR, mission.t_transition_1),
            back_duration: or(p.VT_B_TRANS_DUR, mission.t_transition_2),
            mc,
            fw,
        })
    }
}

/// Signals of the last sample, for tests and plots.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Internals {
    pub mode: Option<VtolMode>,
    /// Attitude setpoint, multicopter frame (in fixed-wing flight: the fixed-wing setpoint
    /// turned into it).
    pub attitude_sp: Option<UnitQuaternion<f64>>,
    /// Rate setpoint of the active rate loop (its own axes).
    pub rate_sp: Vector3<f64>,
    /// Normalised torque, body axes.
    pub torque: Vector3<f64>,
    /// TECS throttle and pitch setpoint (fixed wing).
    pub tecs: (f64, f64),
    /// TECS airspeed setpoint (fixed wing) (m/s).
    pub airspeed_sp: f64,
}

/// The controller.
#[derive(Debug, Clone, PartialEq)]
pub struct Px4Controller {
    params: Px4Params,
    mission: MissionParams,
    airframe: Airframe,
    derived: Derived,
    profile: guidance::Profile,
    ground: GroundPhases,
    pub(crate) vtol: tailsitter::Vtol,
    position: PositionControl,
    mc_rate: RateControl,
    fw_rate: RateControl,
    tecs: Tecs,
    /// Body rates of the previous sample (angular acceleration of the D terms); NaN: none.
    last_rates: Vector3<f64>,
    /// Bit mask of the clipped surfaces at the last sample (notices on new saturation only).
    saturated: u32,
    internals: Internals,
}

/// Number of f64 values written by [`Px4Controller::save`].
pub const STATE_LEN: usize = tailsitter::Vtol::SAVED_LEN + 3 + 3 * 2 + 3 * 2 + 2 + 3 + 1 + GroundPhases::SAVED_LEN;

/// The quaternion that turns multicopter axes into body axes: −90° about the body's y axis
/// (x_mc = z_b, the belly; z_mc = −x_b, against the thrust), PX4's
/// `Quatf(Eulerf(0, −π/2, 0))` of `Tailsitter::update_transition_state`.
pub fn body_from_mc() -> UnitQuaternion<f64> {
    UnitQuaternion::from_axis_angle(&Vector3::y_axis(), -core::f64::consts::FRAC_PI_2)
}

/// The attitude of the measurement (thesis quaternion, scalar last) as a rotation body → earth.
pub fn body_attitude(m: &Measurement) -> UnitQuaternion<f64> {
    let q = m.quat;
    UnitQuaternion::from_quaternion(Quaternion::new(q[3], q[0], q[1], q[2]))
}

/// Body rates (p, q, r) in multicopter axes: (r, q, −p).
pub fn mc_rates(body: &Vector3<f64>) -> Vector3<f64> {
    Vector3::new(body.z, body.y, -body.x)
}

/// A multicopter-axes vector in body axes (inverse of [`mc_rates`]).
pub fn body_of_mc(v: &Vector3<f64>) -> Vector3<f64> {
    Vector3::new(-v.z, v.y, v.x)
}

/// The mission reference at a sample: position with every offset, velocity, acceleration,
/// airspeed and phase.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Reference {
    pub pos: Vector3<f64>,
    pub vel: Vector3<f64>,
    pub acc: Vector3<f64>,
    pub airspeed: f64,
    pub phase: Phase,
    /// Whether the mission asks for fixed-wing flight (the transition to level and level).
    pub fixed_wing: bool,
}

impl Px4Controller {
    /// A controller for `mission` with PX4 parameters `params`, using `airframe` (its own
    /// model of the aircraft) for the derived parameters and the effectiveness.
    pub fn new(airframe: Airframe, mission: MissionParams, params: Px4Params) -> Result<Self, ParamError> {
        params.validate()?;
        mission.validate()?;
        airframe
            .validate()
            .map_err(|e| ParamError(format!("controller airframe: {e}")))?;
        let derived = Derived::of(&airframe, &mission, &params)?;
        let pm = guidance::PointMass::from_level_trim(&airframe, mission.v_level)?;
        let profile = guidance::Profile::new(&mission, &pm, &guidance::ProfileLimits::of(&mission))?;
        Ok(Self {
            params,
            mission,
            airframe,
            derived,
            profile,
            ground: GroundPhases::new(mission, airframe.mass * airframe.gravity),
            vtol: tailsitter::Vtol::default(),
            position: PositionControl::default(),
            mc_rate: RateControl::default(),
            fw_rate: RateControl::default(),
            tecs: Tecs::default(),
            last_rates: Vector3::repeat(f64::NAN),
            saturated: 0,
            internals: Internals::default(),
        })
    }

    /// The nominal airframe and PX4's parameters for `mission`.
    pub fn with_mission(mission: MissionParams) -> Result<Self, ParamError> {
        Self::new(Airframe::default(), mission, Px4Params::default())
    }

    pub fn params(&self) -> &Px4Params {
        &self.params
    }

    pub fn mission(&self) -> &MissionParams {
        &self.mission
    }

    /// The derived parameters and the effectiveness.
    pub fn derived(&self) -> &Derived {
        &self.derived
    }

    /// Signals of the last sample.
    pub fn internals(&self) -> &Internals {
        &self.internals
    }

    /// The VTOL mode of the last sample.
    pub fn mode(&self) -> VtolMode {
        self.vtol.mode
    }

    fn position_gains(&self) -> PositionGains {
        let p = &self.params;
        PositionGains {
            pos_p: Vector3::new(p.MPC_XY_P, p.MPC_XY_P, p.MPC_Z_P),
            vel_p: Vector3::new(p.MPC_XY_VEL_P_ACC, p.MPC_XY_VEL_P_ACC, p.MPC_Z_VEL_P_ACC),
            vel_i: Vector3::new(p.MPC_XY_VEL_I_ACC, p.MPC_XY_VEL_I_ACC, p.MPC_Z_VEL_I_ACC),
            vel_d: Vector3::new(p.MPC_XY_VEL_D_ACC, p.MPC_XY_VEL_D_ACC, p.MPC_Z_VEL_D_ACC),
            vel_max_xy: p.MPC_XY_VEL_MAX,
            vel_max_up: self.derived.climb_rate_max,
            vel_max_down: p.MPC_Z_VEL_MAX_DN,
            tilt_max: p.MPC_TILTMAX_AIR,
            thr_hover: self.derived.thr_hover,
            thr_min: p.MPC_THR_MIN,
            thr_max: p.MPC_THR_MAX,
            gravity: self.airframe.gravity,
        }
    }

    fn attitude_gains(&self) -> AttitudeGains {
        let p = &self.params;
        AttitudeGains {
            p: Vector3::new(p.MC_ROLL_P, p.MC_PITCH_P, p.MC_YAW_P),
            yaw_weight: p.MC_YAW_WEIGHT,
            rate_limit: Vector3::new(p.MC_ROLLRATE_MAX, p.MC_PITCHRATE_MAX, p.MC_YAWRATE_MAX),
        }
    }

    fn mc_rate_gains(&self) -> RateGains {
        let p = &self.params;
        RateGains {
            p: Vector3::new(p.MC_ROLLRATE_P, p.MC_PITCHRATE_P, p.MC_YAWRATE_P),
            i: Vector3::new(p.MC_ROLLRATE_I, p.MC_PITCHRATE_I, p.MC_YAWRATE_I),
            d: Vector3::new(p.MC_ROLLRATE_D, p.MC_PITCHRATE_D, p.MC_YAWRATE_D),
            ff: Vector3::new(p.MC_ROLLRATE_FF, p.MC_PITCHRATE_FF, p.MC_YAWRATE_FF),
            int_lim: Vector3::new(p.MC_RR_INT_LIM, p.MC_PR_INT_LIM, p.MC_YR_INT_LIM),
        }
    }

    /// Fixed-wing rate gains at airspeed scaling `s` (feed-forward divided by s).
    fn fw_rate_gains(&self, s: f64) -> RateGains {
        let p = &self.params;
        RateGains {
            p: Vector3::new(p.FW_RR_P, p.FW_PR_P, p.FW_YR_P),
            i: Vector3::new(p.FW_RR_I, p.FW_PR_I, p.FW_YR_I),
            d: Vector3::zeros(),
            ff: Vector3::new(p.FW_RR_FF, p.FW_PR_FF, p.FW_YR_FF) / s,
            int_lim: Vector3::new(p.FW_RR_IMAX, p.FW_PR_IMAX, p.FW_YR_IMAX),
        }
    }

    fn tecs_params(&self) -> TecsParams {
        let p = &self.params;
        TecsParams {
            alt_tc: p.FW_T_ALT_TC,
            tas_tc: p.FW_T_TAS_TC,
            thr_damp: p.FW_T_THR_DAMP,
            i_gain_thr: p.FW_T_I_GAIN_THR,
            i_gain_pit: p.FW_T_I_GAIN_PIT,
            ptch_damp: p.FW_T_PTCH_DAMP,
            spd_weight: p.FW_T_SPDWEIGHT,
            clmb_max: self.derived.climb_max,
            sink_min: self.derived.sink_min,
            sink_max: p.FW_T_SINK_MAX,
            thr_trim: self.derived.thr_trim,
            thr_min: p.FW_THR_MIN,
            thr_max: p.FW_THR_MAX,
            pitch_min: p.FW_P_LIM_MIN,
            pitch_max: p.FW_P_LIM_MAX,
            gravity: self.airframe.gravity,
        }
    }

    /// The mission reference at mission time `t` (profile), shifted by `shift`.
    fn mission_reference(&self, t: f64, shift: &Vector3<f64>) -> Reference {
        let p = self.profile.at(t);
        let (sg, cg) = p.gamma.sin_cos();
        let tangent = Vector3::new(cg, 0.0, -sg);
        let normal = Vector3::new(-sg, 0.0, -cg);
        let phase = self.mission.phase_at(t).0;
        Reference {
            pos: Vector3::new(p.north, 0.0, -p.height) + shift,
            vel: tangent * p.v,
            acc: tangent * p.v_dot + normal * (p.v * p.gamma_dot),
            airspeed: p.v,
            phase,
            fixed_wing: matches!(phase, Phase::TransitionToLevel | Phase::Level),
        }
    }

    /// The reference of this sample, or `Err` with the on-gear phase and thrust.
    fn reference(&mut self, input: &ControllerInput) -> Result<Reference, (Phase, f64)> {
        let origin = self.ground.origin().unwrap_or_else(Vector3::zeros);
        let offset = input.ref_offset_ned;
        let profile = &self.profile;
        let mission_ref = |tm: f64| {
            let p = profile.at(tm);
            let (sg, cg) = p.gamma.sin_cos();
            (
                Vector3::new(p.north, 0.0, -p.height) + offset + origin,
                Vector3::new(cg, 0.0, -sg) * p.v,
            )
        };
        match self.ground.step(input.t, &input.measurement, mission_ref) {
            GroundMode::Mission { t, offset: shift } => Ok(self.mission_reference(t, &(shift + origin + offset))),
            GroundMode::Vertical(v) => Ok(Reference {
                pos: v.pos + offset,
                vel: v.vel,
                acc: v.accel,
                airspeed: v.vel.norm(),
                phase: v.phase,
                fixed_wing: false,
            }),
            GroundMode::Idle { phase, thrust } => Err((phase, thrust)),
        }
    }

    /// On the gear: no loop runs; every integrator and the mode reset.
    fn on_gear(&mut self, meas: &Measurement, phase: Phase, thrust: f64) -> ControllerOutput {
        self.reset_loops();
        ControllerOutput::on_gear(meas, phase, thrust, self.airframe.thrust_min, self.airframe.thrust_max)
    }

    fn reset_loops(&mut self) {
        self.vtol = tailsitter::Vtol::default();
        self.position.reset();
        self.mc_rate.reset();
        self.fw_rate.reset();
        self.tecs = Tecs::default();
        self.last_rates = Vector3::repeat(f64::NAN);
        self.saturated = 0;
    }

    /// Angular acceleration of the D terms: the change of the body rates over a sample.
    fn angular_accel(&self, rates: &Vector3<f64>) -> Vector3<f64> {
        if self.last_rates.iter().all(|v| v.is_finite()) {
            (rates - self.last_rates) / self.mission.sample_time
        } else {
            Vector3::zeros()
        }
    }

    /// Multicopter thrust vector (NED, fraction of T_max) of the reference; with
    /// `height_only` the horizontal axes are free (PX4's transition flight task).
    fn mc_thrust(&mut self, meas: &Measurement, r: &Reference, height_only: bool) -> Vector3<f64> {
        let g = self.position_gains();
        let nan = f64::NAN;
        let sp = if height_only {
            PositionSetpoint {
                pos: Vector3::new(nan, nan, r.pos.z),
                vel: Vector3::new(nan, nan, r.vel.z),
                acc: Vector3::new(nan, nan, r.acc.z),
            }
        } else {
            PositionSetpoint {
                pos: r.pos,
                vel: r.vel,
                acc: r.acc,
            }
        };
        let q_b = body_attitude(meas);
        let vel_dot = q_b * meas.specific_force_body + Vector3::new(0.0, 0.0, self.airframe.gravity);
        self.position.update(
            &g,
            &sp,
            &meas.pos_ned,
            &meas.vel_ned,
            &vel_dot,
            self.mission.sample_time,
        )
    }

    /// Multicopter attitude and rate loops towards `q_sp` (multicopter frame): the
    /// normalised body torque, and the rate setpoint.
    fn mc_torque(&mut self, meas: &Measurement, q_sp: &UnitQuaternion<f64>) -> (Vector3<f64>, Vector3<f64>) {
        let q_mc = body_attitude(meas) * body_from_mc();
        let rate_sp = attitude::attitude_rate_setpoint(&self.attitude_gains(), &q_mc, q_sp, 0.0);
        let w = mc_rates(&meas.rates);
        let acc = mc_rates(&self.angular_accel(&meas.rates));
        let g = self.mc_rate_gains();
        let nu = self
            .mc_rate
            .update(&g, &w, &rate_sp, &acc, self.mission.sample_time, false);
        (body_of_mc(&nu), rate_sp)
    }

    /// Fixed-wing flight: TECS, L1, attitude and rate loops; the normalised body torque and
    /// the throttle.
    fn fw_control(&mut self, meas: &Measurement, r: &Reference) -> (Vector3<f64>, f64) {
        let d = self.derived;
        let p = self.params;
        let g = self.airframe.gravity;
        let dt = self.mission.sample_time;
        let q_b = body_attitude(meas);
        let (roll, pitch, yaw) = q_b.euler_angles();
        // TECS: the airspeed rate from the specific force along the nose and gravity.
        let tas = meas.airspeed;
        let tas_rate = meas.specific_force_body.x - g * pitch.sin();
        let tp = self.tecs_params();
        let tas_sp = self.fw_airspeed_setpoint(meas, r);
        self.internals.airspeed_sp = tas_sp;
        let out = self.tecs.update(
            &tp,
            -meas.pos_ned.z,
            -meas.vel_ned.z,
            tas,
            tas_rate,
            -r.pos.z,
            tas_sp,
            -r.vel.z,
            dt,
        );
        // L1 along the reference's horizontal direction through the reference position.
        let h = r.vel.xy();
        let dir = if h.norm() > 1.0 {
            h.normalize()
        } else {
            Vector2::new(1.0, 0.0)
        };
        let a_lat = fixed_wing::l1_lateral_accel(
            p.FW_L1_PERIOD,
            p.FW_L1_DAMPING,
            &r.pos.xy(),
            &dir,
            &meas.pos_ned.xy(),
            &meas.vel_ned.xy(),
        );
        let roll_sp = (a_lat / g).atan().clamp(-p.FW_R_LIM, p.FW_R_LIM);
        let pitch_sp = out.pitch + d.pitch_offset;
        self.vtol.fw_pitch_sp = pitch_sp;
        self.vtol.fw_yaw = yaw;
        let rate_sp = fixed_wing::fw_attitude_rates(
            &Vector3::new(roll, pitch, yaw),
            roll_sp,
            pitch_sp,
            p.FW_R_TC,
            p.FW_P_TC,
            tas,
            g,
        );
        // Airspeed scaling s = V_trim / V (V at least FW_AIRSPD_MIN).
        let s = d.airspeed_trim / tas.max(d.airspeed_min);
        let gains = self.fw_rate_gains(s);
        let acc = self.angular_accel(&meas.rates);
        let u = self.fw_rate.update(&gains, &meas.rates, &rate_sp, &acc, dt, false);
        let trim = Vector3::new(0.0, d.trim_pitch, 0.0) * (s * s);
        let torque = (u * (s * s) + trim).map(|v| v.clamp(-1.0, 1.0));
        self.internals.rate_sp = rate_sp;
        self.internals.tecs = (out.throttle, pitch_sp);
        (torque, out.throttle)
    }

    /// TECS's airspeed setpoint in fixed-wing flight: the airspeed that gives the ground
    /// velocity t̂ (|v_ref| + e_s / τ_s) along the reference's tangent t̂ in the measured
    /// wind, e_s = t̂ · (p_ref − p) the along-track error (README, "What differs from PX4":
    /// PX4 flies waypoints, not a position over time). τ_s = 2 FW_T_TAS_TC: with TECS's
    /// first-order speed loop of time constant τ_v the along-track error obeys
    /// τ_v ë + ė + e/τ_s = 0, damped at ζ = √(τ_s/(4 τ_v)) = 0.71. The correction is at most
    /// FW_AIRSPD_TRIM − FW_AIRSPD_MIN either way and the setpoint at least FW_AIRSPD_MIN.
    fn fw_airspeed_setpoint(&self, meas: &Measurement, r: &Reference) -> f64 {
        let d = &self.derived;
        let speed = r.vel.norm();
        if speed < 1.0 {
            return r.airspeed.max(d.airspeed_min);
        }
        let tangent = r.vel / speed;
        let e_s = tangent.dot(&(r.pos - meas.pos_ned));
        let tau_s = 2.0 * self.params.FW_T_TAS_TC;
        let span = (d.airspeed_trim - d.airspeed_min).max(0.0);
        let ground_sp = tangent * (speed + (e_s / tau_s).clamp(-span, span));
        // The wind: the ground velocity less the air velocity (body axes turned to earth).
        let q_b = body_attitude(meas);
        let (sa, ca) = meas.alpha.sin_cos();
        let (sb, cb) = meas.beta.sin_cos();
        let air = q_b * (Vector3::new(ca * cb, sb, sa * cb) * meas.airspeed);
        let wind = meas.vel_ned - air;
        (ground_sp - wind).norm().max(d.airspeed_min)
    }

    /// A notice when a surface is newly clipped.
    fn saturation_notice(&mut self, thrust: f64, u: &Vector6<f64>, limit: f64) -> Option<Notice> {
        use tailsitter_physics::idx::INPUT_NAMES;
        let mut mask = 0u32;
        if thrust <= self.airframe.thrust_min || thrust >= self.airframe.thrust_max {
            mask |= 1;
        }
        for (i, d) in u.iter().enumerate() {
            if d.abs() >= limit * (1.0 - 1e-9) {
                mask |= 1 << (i + 1);
            }
        }
        let new = mask & !self.saturated;
        self.saturated = mask;
        (new != 0).then(|| Notice::Saturated(INPUT_NAMES[new.trailing_zeros() as usize]))
    }
}

impl SampledUnit for Px4Controller {
    type Config = Px4Config;
    type Input = ControllerInput;
    type Output = ControllerOutput;

    fn build(c: &Px4Config) -> Result<Self, ParamError> {
        Self::new(c.airframe, c.mission, c.params)
    }

    fn sample_time(c: &Px4Config) -> f64 {
        c.mission.sample_time
    }

    /// Write the complete dynamic state ([`STATE_LEN`] values).
    fn save(&self, out: &mut impl FnMut(f64)) {
        self.vtol.save(out);
        for v in self.position.vel_int.iter() {
            out(*v);
        }
        for rc in [&self.mc_rate, &self.fw_rate] {
            for v in rc.integral.iter() {
                out(*v);
            }
            for i in 0..3 {
                out(f64::from(u8::from(rc.saturated_positive[i])) + 2.0 * f64::from(u8::from(rc.saturated_negative[i])));
            }
        }
        out(self.tecs.thr_int);
        out(self.tecs.pitch_int);
        for v in self.last_rates.iter() {
            out(*v);
        }
        out(f64::from(self.saturated));
        self.ground.save(out);
    }

    /// Restore what [`Self::save`] wrote; a truncated or invalid state is an error and
    /// leaves `self` unchanged.
    fn restore(&mut self, next: &mut impl FnMut() -> Option<f64>) -> Result<(), ControlError> {
        let mut v = [0.0; STATE_LEN];
        for slot in v.iter_mut() {
            *slot = next().ok_or_else(|| ControlError("truncated PX4 controller state".into()))?;
        }
        let mut it = v.iter().copied();
        let mut take = || it.next();
        let mut copy = self.clone();
        copy.vtol
            .restore(&mut take)
            .ok_or_else(|| ControlError("invalid PX4 VTOL state".into()))?;
        let vec3 = |take: &mut dyn FnMut() -> Option<f64>| -> Vector3<f64> {
            Vector3::new(take().unwrap_or(0.0), take().unwrap_or(0.0), take().unwrap_or(0.0))
        };
        copy.position.vel_int = vec3(&mut take);
        for k in 0..2 {
            let integral = vec3(&mut take);
            let flags = vec3(&mut take);
            let rc = if k == 0 { &mut copy.mc_rate } else { &mut copy.fw_rate };
            rc.integral = integral;
            for i in 0..3 {
                let f = flags[i] as u8;
                rc.saturated_positive[i] = f & 1 != 0;
                rc.saturated_negative[i] = f & 2 != 0;
            }
        }
        copy.tecs.thr_int = take().unwrap_or(0.0);
        copy.tecs.pitch_int = take().unwrap_or(0.0);
        copy.last_rates = vec3(&mut take);
        let s = take().unwrap_or(0.0);
        copy.saturated = if s.is_finite() && s >= 0.0 { s as u32 } else { 0 };
        copy.ground
            .restore(&mut take)
            .ok_or_else(|| ControlError("truncated PX4 controller state".into()))?;
        *self = copy;
        Ok(())
    }

    /// One sample: reference → VTOL mode → the loops of the mode → allocation.
    fn sample(&mut self, input: &ControllerInput) -> Result<ControllerOutput, ControlError> {
        input.check()?;
        let meas = &input.measurement;
        let r = match self.reference(input) {
            Ok(r) => r,
            Err((phase, thrust)) => return Ok(self.on_gear(meas, phase, thrust)),
        };
        let q_mc = body_attitude(meas) * body_from_mc();
        let mode = self.vtol.update(input.t, &r, &q_mc, meas.airspeed, &self.derived);
        let t_max = self.airframe.thrust_max;
        let (torque, thrust_fraction, eff) = match mode {
            VtolMode::Multicopter => {
                let thr = self.mc_thrust(meas, &r, false);
                let body_z = -thr.normalize();
                let q_sp = attitude::body_z_to_attitude(&body_z, 0.0);
                self.vtol.mc_sp = q_sp;
                let (torque, rate_sp) = self.mc_torque(meas, &q_sp);
                self.internals.rate_sp = rate_sp;
                self.internals.attitude_sp = Some(q_sp);
                (torque, thr.norm(), self.derived.mc)
            }
            VtolMode::FrontTransition | VtolMode::BackTransition => {
                let thr = self.mc_thrust(meas, &r, true);
                let q_sp = self.vtol.transition_setpoint(input.t, &self.derived);
                let (torque, rate_sp) = self.mc_torque(meas, &q_sp);
                self.internals.rate_sp = rate_sp;
                self.internals.attitude_sp = Some(q_sp);
                (torque, thr.norm(), self.derived.mc)
            }
            VtolMode::FixedWing => {
                let (torque, throttle) = self.fw_control(meas, &r);
                self.internals.attitude_sp = None;
                (torque, throttle, self.derived.fw)
            }
        };
        let alloc = eff.allocate(&torque, &Vector6::zeros());
        // Saturation feedback to the active rate loop's anti-windup (its own axes).
        match mode {
            VtolMode::FixedWing => {
                self.fw_rate.saturated_positive = alloc.saturated_positive;
                self.fw_rate.saturated_negative = alloc.saturated_negative;
            }
            _ => {
                let (p, n) = (alloc.saturated_positive, alloc.saturated_negative);
                // MC x = body z, MC y = body y, MC z = −body x.
                self.mc_rate.saturated_positive = [p[2], p[1], n[0]];
                self.mc_rate.saturated_negative = [n[2], n[1], p[0]];
            }
        }
        self.last_rates = meas.rates;
        let thrust = (thrust_fraction * t_max).clamp(self.airframe.thrust_min, self.airframe.thrust_max);
        let u = alloc.deflections;
        let command = Command {
            thrust,
            elevator: u[0],
            aileron: u[1],
            rudder: u[2],
            flap_collective: u[3],
            flap_differential: u[4],
            vertical_flap: u[5],
        };
        if !command.is_finite() {
            self.reset_loops();
            return Err(ControlError(format!("non-finite command at t = {} s", input.t)));
        }
        self.internals.mode = Some(mode);
        self.internals.torque = torque;
        let notice = self.saturation_notice(thrust, &u, eff.limit);
        Ok(ControllerOutput {
            command,
            diagnostics: Diagnostics {
                ref_pos_ned: r.pos,
                ref_airspeed: r.airspeed,
                phase: r.phase,
                pos_error: flight_mission::distance(&meas.pos_ned, &r.pos),
            },
            notice,
        })
    }
}
