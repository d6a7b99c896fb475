//! Time-scale-decoupled (TSD) flight controller of the tail-sitter (S.C. Kriel's thesis,
//! chapter 4 and appendix B), as a plain Rust struct implementing
//! [`flight_mission::FlightController`].
//!
//! Structure (figures 4.1, 4.2):
//!
//! * **Outer loop** (§4.3), slow: the kinematic [`trajectory`] (§4.3.3) gives reference
//!   position, velocity and specific acceleration; the guidance controller (4.3.24)
//!   commands an earth-axis specific acceleration Σ, decomposed (4.3.27–4.3.30) into an
//!   axial command A_Wc, a normal command C_Wc and a commanded normal vector k^Wc; the
//!   normal-vector-direction (NVD) controller (4.3.1–4.3.6) turns the roll error into a
//!   roll-rate reference. In vertical flight and the transitions the normal vector is
//!   prescribed by the trajectory (§4.3.2.1) and the lateral part of Σ goes to the
//!   directional loop; the switch to the computed normal vector in level flight is a
//!   linear blend over `normal_vector_blend_time`, so commands stay continuous.
//! * **Inner loop** (§4.2), fast, gain-scheduled at every sample from the airspeed, the
//!   thrust and the dynamic pressures q̄ = ½ρV̄² (free stream: wing, ailerons) and
//!   q̄_s = ½ρ(V̄ + 2w)² (slip-stream: elevator, flaps, rudder):
//!   axial specific acceleration with thrust (4.2.1–4.2.8, anti-windup §4.2.1);
//!   normal specific acceleration with the mixed elevator/collective-flap actuator δm
//!   (4.2.9–4.2.17, Table 4.1) and gravity cancellation δmg (App. B);
//!   combined roll-rate / NVD loop (4.2.21–4.2.26, 4.3.7–4.3.11) with ailerons and
//!   differential flaps; directional loop regulating the lateral specific acceleration with
//!   the mixed rudder/vertical-flap actuator (4.2.27–4.2.31, Table 4.2) and feedback
//!   linearisation δR_f (the printed (4.2.29) is garbled; derived in the README).
//!
//! Every inner loop has integral action. Integrators are stored as their contribution
//! to the command (u_I = −K_E ∫e), so gain changes between samples cause no bumps;
//! they are initialised at the first sample so the first command equals the measured
//! actuator state (bumpless start from the plant's trim), wound back by back-calculation
//! with the tracking gain (§4.2.1) when a command saturates, and only finite values are
//! committed. `sample` does not allocate (static nalgebra types only).
//!
//! Stages, one module each, in the order `sample` runs them: `reference` (trajectory or
//! take-off / landing phases, weathervane heading) → `axes` (loop frame, measured specific
//! accelerations) → `design` (gain schedule of every loop) → `guidance` (4.3.24) → `nvd`
//! (decomposition 4.3.27–4.3.30, NVD error 4.3.5) → `inner_loops` (axial, normal, roll,
//! directional laws) → `integrators` (bumpless start, anti-windup) → `mixing` (surface
//! allocation, saturation); `deviations` holds the thesis-vs-tuned switches, one parameter
//! per deviation of docs/THESIS.md (−1 follow `configuration`, 0 printed, 1 deviation).
//!
//! Frames: earth NED, body (x nose, y right wing, z belly), wind axes (x along the air
//! velocity, z in the plane of symmetry). Units SI, angles rad.

mod axes;
mod design;
mod deviations;
pub mod gains;
mod guidance_law;
mod inner_loops;
mod integrators;
mod mixing;
mod nvd;
pub mod params;
mod reference;
pub mod trajectory;
pub mod wind_mission;

pub use design::{FlightCondition, LoopDesign};
pub use params::{
    TsdParams, GUIDANCE_FEEDBACK_LIMIT, HOVER_GUST_NORMAL_POLE_FACTOR, HOVER_LOW_AIRSPEED_ALPHA,
    HOVER_WEATHERCOCK_CROSSFLOW, HOVER_WIND_CROSSFLOW, HOVER_WIND_DESIGN_SPEED_FACTOR, HOVER_WIND_NORMAL_CROSSFLOW,
    HOVER_WIND_NORMAL_POLE_FACTOR, HOVER_WIND_ROLL_POLE_FACTOR, NORMAL_FEEDFORWARD_RAMP, PATH_AIR_WIND_BAND,
    TABLE_4_3_GUIDANCE_LEVEL,
};
pub use trajectory::{Reference, Trajectory};

use axes::{Airflow, LoopAxes};
use deviations::Deviations;
use integrators::{Integrators, VirtualCommands};
use nvd::AccelCommands;
use reference::{ReferenceSignals, ReferenceStage};

use flight_mission::{
    ControlError, ControllerInput, ControllerOutput, Diagnostics, Measurement, MissionParams, ParamError, SampledUnit,
};
use guidance::{GroundPhases, Weathervane, WeathervaneParams};
use nalgebra::Vector3;
use tailsitter_physics::Airframe;

/// Number of f64 values written by [`TsdController::save`]: the loops' six, the
/// weathervane's, the take-off / landing phases' and the mission logic in wind's.
pub const STATE_LEN: usize =
    6 + guidance::weathervane::WEATHERVANE_STATE_LEN + GroundPhases::SAVED_LEN + wind_mission::WIND_MISSION_STATE_LEN;

/// Internal signals of the last sample, for tests, plots and tuning.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Internals {
    /// Guidance command Σ, NED (m/s²) (4.3.24).
    pub sigma_cmd: Vector3<f64>,
    /// Axial, lateral, normal specific-acceleration commands A_Wc, B_Wc, C_Wc (m/s²).
    pub accel_cmd: Vector3<f64>,
    /// Measured A_W, B_W, C_W (m/s²).
    pub accel: Vector3<f64>,
    /// Commanded normal vector k^Wc, NED.
    pub normal_cmd: Vector3<f64>,
    /// NVD error angle φ (4.3.5) (rad).
    pub roll_error: f64,
    /// Weight of the computed (vs prescribed) normal vector, 0..1.
    pub normal_weight: f64,
    /// Schedule variable: 0 at v_vertical, 1 at v_level.
    pub schedule: f64,
    /// Weight κ of the wind axes (vs the reference-path frame), 0..1.
    pub frame_weight: f64,
    /// Mixing ratios (δfc/δe, δv/δr) (4.2.12, Table 4.2).
    pub mixing: (f64, f64),
    /// Unsaturated virtual commands (T_c, δm, δA, δR).
    pub virtual_cmd: [f64; 4],
}

impl Internals {
    /// The internals of a sample with guidance command `sigma`, loop commands `cmd` and
    /// virtual commands `u`.
    fn of(s: &SampleSignals, sigma: &Vector3<f64>, cmd: &AccelCommands, u: &VirtualCommands) -> Self {
        Self {
            sigma_cmd: *sigma,
            accel_cmd: Vector3::new(cmd.a_cmd, cmd.b_cmd, cmd.c_cmd),
            accel: Vector3::new(s.axes.a_w, s.axes.b_w, s.axes.c_w),
            normal_cmd: cmd.k_cmd,
            roll_error: cmd.roll_error,
            normal_weight: cmd.normal_weight,
            schedule: s.d.schedule,
            frame_weight: s.d.kappa,
            mixing: s.d.mixing,
            virtual_cmd: [u.thrust, u.dm, u.da, u.dr],
        }
    }
}

/// The signals every stage after the gain schedule reads: the measurement, the reference,
/// the air flow, the loop frame and the loops' design at this sample.
pub(crate) struct SampleSignals<'a> {
    meas: &'a Measurement,
    r: ReferenceSignals,
    air: Airflow,
    axes: LoopAxes,
    d: LoopDesign,
}

/// The TSD controller.
#[derive(Debug, Clone, PartialEq)]
pub struct TsdController {
    params: TsdParams,
    mission: MissionParams,
    airframe: Airframe,
    trajectory: Trajectory,
    integrators: Integrators,
    initialized: bool,
    /// Take-off and landing phases around the mission (guidance::ground).
    ground: GroundPhases,
    /// Bit mask of the saturated commands at the last sample (notices on new saturation only).
    saturated: u32,
    internals: Internals,
    /// Heading reference in vertical flight (README, "Weathervaning").
    weathervane: Weathervane,
    /// Heading through the handover, the transitions and level flight in wind (README,
    /// "Missions in wind").
    wind_mission: wind_mission::WindMission,
}

/// Names of the commands, bit order of the saturation mask.
use tailsitter_physics::idx::INPUT_NAMES as COMMAND_NAMES;

#[inline]
fn lerp(a: f64, b: f64, s: f64) -> f64 {
    a + (b - a) * s
}

/// Linear blend weight of `x` across the band `(lo, hi)`: 0 at or below `lo`, 1 at or above
/// `hi` (the schedules and the hover-in-wind bands).
#[inline]
fn band_weight(x: f64, (lo, hi): (f64, f64)) -> f64 {
    ((x - lo) / (hi - lo)).clamp(0.0, 1.0)
}

impl TsdController {
    /// A controller for `mission` with tuning `params`, using `airframe` (its own model of
    /// the aircraft, not necessarily the plant's) for gains and feedback linearisation.
    pub fn new(airframe: Airframe, mission: MissionParams, params: TsdParams) -> Result<Self, ParamError> {
        params.validate()?;
        let params = params.effective()?;
        mission.validate()?;
        airframe
            .validate()
            .map_err(|e| ParamError(format!("controller airframe: {e}")))?;
        // The tuned configuration flies the α- and thrust-limited profile, the thesis
        // configuration the quarter loops of §4.3.3.
        let dev = Deviations::of(&params);
        let trajectory = if dev.limited_profile {
            let pm = guidance::PointMass::from_level_trim(&airframe, mission.v_level)?;
            let profile = guidance::Profile::new(&mission, &pm, &guidance::ProfileLimits::of(&mission))?;
            Trajectory::limited(mission, airframe.gravity, profile)
        } else {
            Trajectory::new(mission, airframe.gravity)
        };
        Ok(Self {
            params,
            mission,
            airframe,
            trajectory,
            integrators: Integrators::default(),
            initialized: false,
            ground: GroundPhases::new(mission, airframe.mass * airframe.gravity).with_thrust_limit(airframe.thrust_max),
            saturated: 0,
            internals: Internals::default(),
            weathervane: Weathervane::new(if dev.weathervane {
                WeathervaneParams::tuned()
            } else {
                WeathervaneParams::disabled()
            })
            .map_err(ParamError)?,
            wind_mission: wind_mission::WindMission::default(),
        })
    }

    /// The switches between the printed thesis and the tuned configuration, per stage.
    fn deviations(&self) -> Deviations {
        Deviations::of(&self.params)
    }

    /// The weathervane of the heading reference (tuned configuration: on; thesis: off).
    pub fn weathervane(&self) -> &Weathervane {
        &self.weathervane
    }

    /// Replace the weathervane's tuning (resets its state).
    pub fn set_weathervane(&mut self, params: WeathervaneParams) -> Result<(), ParamError> {
        self.weathervane = Weathervane::new(params).map_err(ParamError)?;
        Ok(())
    }

    /// The nominal airframe and Table 4.3 poles for `mission`.
    pub fn with_mission(mission: MissionParams) -> Result<Self, ParamError> {
        Self::new(Airframe::default(), mission, TsdParams::default())
    }

    /// Tuning parameters.
    pub fn params(&self) -> &TsdParams {
        &self.params
    }

    /// Mission flown.
    pub fn mission(&self) -> &MissionParams {
        &self.mission
    }

    /// The kinematic trajectory.
    pub fn trajectory(&self) -> &Trajectory {
        &self.trajectory
    }

    /// Internal signals of the last sample.
    pub fn internals(&self) -> &Internals {
        &self.internals
    }

    /// Forget integrators: the next sample starts bumplessly from the measured actuators.
    pub fn reset(&mut self) {
        self.integrators = Integrators::default();
        self.initialized = false;
        self.saturated = 0;
    }

    fn err(msg: impl Into<String>) -> ControlError {
        ControlError(msg.into())
    }
}

/// Everything a [`TsdController`] is built from: the FMU's parameters. The default: the
/// nominal airframe, the default mission and tuning.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct TsdConfig {
    /// The controller's own model of the airframe (may differ from the plant's).
    pub airframe: Airframe,
    pub mission: MissionParams,
    pub params: TsdParams,
}

impl TsdConfig {
    /// The nominal airframe, the given mission and the default tuning (Table 4.3 poles).
    pub fn with_mission(mission: MissionParams) -> Self {
        Self {
            mission,
            ..Self::default()
        }
    }
}

impl SampledUnit for TsdController {
    type Config = TsdConfig;
    type Input = ControllerInput;
    type Output = ControllerOutput;

    fn build(c: &TsdConfig) -> Result<Self, ParamError> {
        Self::new(c.airframe, c.mission, c.params)
    }

    fn sample_time(c: &TsdConfig) -> f64 {
        c.mission.sample_time
    }

    /// Write the complete dynamic state ([`STATE_LEN`] values) for FMU-state serialisation.
    fn save(&self, out: &mut impl FnMut(f64)) {
        out(if self.initialized { 1.0 } else { 0.0 });
        out(self.integrators.thrust);
        out(self.integrators.normal);
        out(self.integrators.roll);
        out(self.integrators.directional);
        out(self.saturated as f64);
        self.weathervane.save(out);
        self.ground.save(out);
        self.wind_mission.save(out);
    }

    /// Restore what [`Self::save`] wrote; a truncated state is an error and leaves `self` unchanged.
    fn restore(&mut self, next: &mut impl FnMut() -> Option<f64>) -> Result<(), ControlError> {
        let mut v = [0.0; STATE_LEN];
        for slot in v.iter_mut() {
            *slot = next().ok_or_else(|| ControlError("truncated TSD controller state".into()))?;
        }
        let mut weathervane = self.weathervane;
        let mut rest = v[6..].iter().copied();
        weathervane.restore(&mut || rest.next()).map_err(ControlError)?;
        self.weathervane = weathervane;
        self.initialized = v[0] != 0.0;
        self.integrators = Integrators {
            thrust: v[1],
            normal: v[2],
            roll: v[3],
            directional: v[4],
        };
        self.saturated = if v[5].is_finite() && v[5] >= 0.0 {
            v[5] as u32
        } else {
            0
        };
        let mut rest = v[6 + guidance::weathervane::WEATHERVANE_STATE_LEN..].iter().copied();
        self.ground
            .restore(&mut || rest.next())
            .ok_or_else(|| ControlError("truncated TSD controller state".into()))?;
        self.wind_mission
            .restore(&v[STATE_LEN - wind_mission::WIND_MISSION_STATE_LEN..]);
        Ok(())
    }

    /// One sample of the TSD controller: the stages of Figs. 4.1–4.2 in signal order
    /// (crate README, "Where each block of Figs. 4.1–4.2 lives in the code").
    fn sample(&mut self, input: &ControllerInput) -> Result<ControllerOutput, ControlError> {
        input.check()?;
        let meas = &input.measurement;
        let dev = self.deviations();
        // Reference (§4.3.3), or the take-off / landing phases around it.
        let r = match self.reference_stage(input) {
            ReferenceStage::Flying(r) => r,
            ReferenceStage::OnGear { phase, thrust } => return Ok(self.on_gear(meas, phase, thrust)),
        };
        // Measured signals in the loop frame, and every loop designed at this condition.
        let mut air = self.airflow(meas, r.reference.airspeed, r.ground_phase(), dev);
        air.kappa = self.path_air_frame_weight(meas, &r, air.kappa, dev);
        let axes = LoopAxes::measure(meas, &r.reference.tangent(), air.kappa);
        let d = self.scheduled_design(meas, &r, &air, input.t)?;
        let s = SampleSignals { meas, r, air, axes, d };
        // Outer loop (Fig. 4.2): guidance (4.3.24), decomposition and NVD (4.3.1–4.3.30).
        let (sigma_ff, sigma_ahead) = guidance_law::feedforward(&self.trajectory, &r, self.params.feedforward_lead);
        let pos_error = meas.pos_ned - r.ref_pos;
        let vel_error = meas.vel_ned - r.reference.vel;
        let sigma = guidance_law::command(&s.d, &r.reference, &pos_error, &vel_error, &sigma_ff);
        let cmd = self.decompose(&sigma, &s.axes, &r);
        // Inner loops (Fig. 4.1, §4.2), their integrators, mixing and saturation.
        let laws = self.inner_loops(&s, &sigma_ahead, cmd.roll_error, dev);
        if !self.initialized {
            self.integrators
                .bumpless_start(&s, &laws, dev.integrators_as_accelerations);
            self.initialized = true;
        }
        let mut u = self.integrators.commands(
            &s,
            &laws,
            self.airframe.deflection_limit,
            dev.integrators_as_accelerations,
        );
        self.takeoff_lift(&s, &mut u.thrust, dev);
        let (mut command, u_sat) = mixing::allocate(&u, s.d.mixing, dev.roll_differential_flaps, &self.airframe);
        // Landing in wind (README, "Take-off and landing in wind"): the collective and
        // vertical flaps' direct force.
        if dev.hover_wind_design {
            let lim = self.airframe.deflection_limit;
            let since_end = input.t - self.ground.mission_start() - self.mission.end_time();
            let trim = wind_mission::landing_flap_trim(meas, r.reference.phase, &self.weathervane.wind(), since_end)
                * s.air.hover_wind;
            command.flap_collective = (command.flap_collective + trim).clamp(-lim, lim);
            let side = wind_mission::landing_vertical_flap(meas, r.reference.phase) * s.air.hover_wind;
            command.vertical_flap = (command.vertical_flap + side).clamp(-lim, lim);
        }
        if !command.is_finite() {
            return Err(Self::err(format!("non-finite command at t = {} s", input.t)));
        }
        let e = integrators::loop_errors(&s.axes, &cmd, &laws);
        let (ts, gain) = (self.mission.sample_time, self.params.antiwindup_gain);
        self.integrators.anti_windup_step(&s.d, e, &u, &u_sat, ts, gain, dev);
        // Diagnostics.
        let notice = self.saturation_notice(&u, s.d.mixing);
        self.internals = Internals::of(&s, &sigma, &cmd, &u);
        Ok(ControllerOutput {
            command,
            diagnostics: Diagnostics {
                ref_pos_ned: r.ref_pos,
                ref_airspeed: r.reference.airspeed,
                phase: r.reference.phase,
                pos_error: flight_mission::distance(&meas.pos_ned, &r.ref_pos),
            },
            notice,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn save_restore_round_trip() {
        let mut a = TsdController::with_mission(MissionParams::default()).unwrap();
        a.integrators = Integrators {
            thrust: 1.0,
            normal: 2.0,
            roll: 3.0,
            directional: 4.0,
        };
        a.initialized = true;
        a.saturated = 5;
        let mut buf = Vec::new();
        a.save(&mut |x| buf.push(x));
        assert_eq!(buf.len(), STATE_LEN);
        let mut b = TsdController::with_mission(MissionParams::default()).unwrap();
        let mut it = buf.into_iter();
        b.restore(&mut || it.next()).unwrap();
        assert_eq!(a.integrators, b.integrators);
        assert_eq!((a.initialized, a.saturated), (b.initialized, b.saturated));
        let mut empty = std::iter::empty();
        assert!(b.restore(&mut || empty.next()).is_err());
    }

    #[test]
    fn invalid_parameters_are_named() {
        let p = TsdParams {
            normal_pole_re_level: 1.0,
            ..Default::default()
        };
        let e = TsdController::new(Airframe::default(), MissionParams::default(), p).unwrap_err();
        assert!(e.0.contains("normal_pole_re_level"), "{e}");
    }
}
