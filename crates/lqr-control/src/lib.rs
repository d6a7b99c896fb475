//! Gain-scheduled LQR flight controller of S.C. Kriel's tail-sitter thesis (chapter 3),
//! pure Rust, independent of FMI.
//!
//! * [`model`]: the full-state Euler model for control (§2.4, candidate 2 of §3.2.3) on the
//!   physics crate's force model, linearised analytically (3.2.7–3.2.9).
//! * [`linalg`]: zero-order-hold discretisation (the tuned alternative to (3.2.10–3.2.11)), the steady-state
//!   DARE by structured doubling, the thesis's N-step backward iteration (3.1.3–3.1.5).
//! * [`trajectory`]: the reference trajectory of §3.3.
//! * [`weights`]: Table 3.4 weights per phase (3.4.1–3.4.3), blended between phases.
//! * [`LqrController`]: implements [`flight_mission::FlightController`]:
//!   every `relinearisation_period` it relinearises about the current estimated state and
//!   the trajectory's inputs, discretises, adds the airspeed integrator (3.2.12–3.2.14) and
//!   solves for K; every sample it applies `u = u_t − K [∫ΔV; x − x_t]`.
//!
//! See README.md for the equations and the design choices.

mod command;
mod error_state;
mod gain;
pub mod linalg;
pub mod model;
mod reference;
pub mod trajectory;
pub mod weights;

pub use gain::{
    GainSolution, NR, WARM_MAX_NEWTON_STEPS, WARM_MAX_RESIDUAL, WARM_MAX_START_RESIDUAL, WARM_MAX_STEP_RESIDUAL,
};

use std::ops::ControlFlow;

use flight_mission::{
    Command, ControlError, ControllerInput, ControllerOutput, MissionParams, ParamError, SampledUnit,
};
use guidance::{GroundPhases, Weathervane, WeathervaneParams};
use nalgebra::{SMatrix, Vector3};
use tailsitter_physics::Airframe;

use command::IntegratorSwitches;
use error_state::{euler_set, ErrorStateSwitches};
use gain::GainScheduleSwitches;
use model::{EulerRep, NA, NU};
use reference::ReferenceSwitches;
use trajectory::{Trajectory, TrajectoryMode, TrajectoryOptions};
use weights::{load_set, WeightSchedule, DEFAULT_WEIGHTS_JSON};

/// Smallest reference airspeed the (V, α, β) model for control supports (m/s).
pub const MIN_AIRSPEED: f64 = 0.5;

/// Bound on the magnitude of the wind estimate (m/s).
pub const MAX_WIND_ESTIMATE: f64 = 20.0;

/// |α| or |β| beyond which vertical flight counts as flight in wind (rad): the gains are then
/// computed about the reference instead of the measured state (README, "Hover in wind").
pub const HOVER_WIND_AIR_ANGLE: f64 = 0.5235987755982988; // 30°

/// Largest pitch rotation of the wind trim (rad) (README, "Gusts").
pub const WIND_TRIM_MAX_PITCH: f64 = 0.3490658503988659; // 20°
/// Largest pitch rotation of the wind trims on the global model (rad) (45°): the level leg's
/// and back transition's (`reference::level_trim`: 23.0° in a 10 m/s tailwind) and the front
/// transition's (README, "Mission in wind").
pub const LEVEL_TRIM_MAX_PITCH: f64 = core::f64::consts::FRAC_PI_4;

/// Largest wind step of the level leg's continuation on the global model (m/s).
pub const LEVEL_TRIM_STEP: f64 = 1.0;

/// Most solves of the level leg's continuation on the global model.
pub const LEVEL_TRIM_STEPS: usize = 12;
/// Largest rotation about the body z axis (the crab in level flight) of the trim along the
/// still-air ground path (rad) (README, "Mission in wind").
pub const GROUND_TRIM_MAX_YAW: f64 = 1.0471975511965976; // 60°
/// Time from the start of the front transition over which its trim along the still-air
/// ground path reaches full weight (s) (README, "Mission in wind").
pub const FRONT_TRIM_RAMP_TIME: f64 = 0.5;
/// The wind trim is phased in (smoothstep) as the estimated wind rises between these
/// speeds (m/s): below the first the reference is untrimmed (still air bit-identical, and
/// the air-data wind an estimator makes of still air not flown).
pub const WIND_TRIM_RAMP: (f64, f64) = (0.5, 1.5);

/// Horizontal speed of the weathervane's wind estimate (4 s filter) (m/s) from which the position integrators ∫ΔN,
/// ∫ΔE, ∫Δh join the mission's gains for the rest of the flight (README, "Mission in
/// wind"); in still air they stay inert (the still-air flights bit-identical).
pub const WIND_INTEGRAL_SPEED: f64 = 1.5;
/// Air-data wind (m/s) over which the take-off and landing phases' velocity feedback passes
/// from the measured air velocity to the inertial velocity less the wind estimate
/// (smoothstep; README, "Take-off and landing").
pub const GROUND_AIR_DATA_RAMP: (f64, f64) = (0.5, 1.5);

/// The collective-flap trim of the descent and flare in wind (README, "Take-off and
/// landing"): the shared landing trim's slope and limit (guidance::ground).
pub use guidance::ground::{
    LANDING_FLAP_TRIM_GAIN as LANDING_FLAP_GAIN, LANDING_FLAP_TRIM_LIMIT as LANDING_FLAP_LIMIT,
};
/// Time over which the collective-flap trim of the descent ramps in from zero (s) (README,
/// "Take-off and landing").
pub const LANDING_FLAP_RAMP_TIME: f64 = 12.0;
/// Largest part of the landing's collective-flap command in the point the gains are
/// linearised about (rad); the rest is feed-forward only (README, "Take-off and landing").
pub const LANDING_FLAP_LINEARISED: f64 = 12.0 * core::f64::consts::PI / 180.0;
/// Collective flap per unit sine of the nose's lean towards the belly in the descent and
/// flare in wind (rad) (README, "Take-off and landing").
pub const LANDING_LEAN_GAIN: f64 = 0.7;

/// Time constant τ_s of the integral action on the horizontal position in wind (s).
pub const HOVER_SHIFT_TIME: f64 = 3.0;
/// Bound on that integral's shift of the regulated position (m).
pub const HOVER_SHIFT_LIMIT: f64 = 5.0;

/// The gain matrix K (inputs × [integrator, model states]).
pub type Gain = SMatrix<f64, NU, NA>;

/// Tuning parameters of the LQR (FMU parameter group `lqr`; field names are the FMU
/// parameter names).
#[derive(Debug, Clone, PartialEq)]
pub struct LqrParams {
    /// T_l: period of relinearisation and gain computation (s) (§3.1.3, §3.2.4: 0.2 s).
    pub relinearisation_period: f64,
    /// 0 = exact steady-state DARE (structured doubling), 1 = the thesis's backward
    /// iteration over `riccati_horizon` steps (3.1.3–3.1.5).
    pub riccati_method: i32,
    /// N of the backward iteration (thesis: 200).
    pub riccati_horizon: i32,
    /// Extra factor on every phase's control-weight scale R (3.4.2).
    pub r_scale: f64,
    /// Index of the weight set in the weights JSON (0 = thesis Table 3.4).
    pub weight_set: i32,
    /// Time over which the weights blend from one phase's table to the next (s).
    pub weight_blend_time: f64,
    /// Reference 3-2-1 pitch above which the 2-3-1 Euler set is used (rad).
    pub euler_switch_pitch: f64,
    /// Limit of the airspeed-error integrator |∫ΔV dt| (m), applied with `integrator_clamp`.
    pub integrator_limit: f64,
    /// Leak λ of the airspeed integrator, ẋ_I = V − V_t − λ x_I (1/s). Must be > 0 with the
    /// DARE (`riccati_method` 0): with λ = 0 the integrator minus the along-track position
    /// is an uncontrollable mode at z = 1 (ẋ_I = ΔV = along-track Δṗ in straight flight)
    /// and no stabilising DARE solution exists. λ = 0 is accepted with the finite-horizon
    /// backward iteration (`riccati_method` 1), which returns gains regardless, as the
    /// thesis does (§3.1.3, 3.2.12–3.2.14); the closed loop then keeps that mode at z ≈ 1.
    pub integrator_leak: f64,
    /// 1 (default) = integral action on the earth-frame position error ∫ΔN, ∫ΔE, ∫Δh (zero
    /// steady-state position error in a steady wind or with a model mismatch); 0 = the
    /// thesis's structure, integral action on airspeed only (3.2.12–3.2.14).
    pub position_integral: i32,
    /// Limit of each position-error integrator |∫Δp dt| (m·s).
    pub position_integrator_limit: f64,
    /// Leak of the position integrators (1/s), ẋ_Ip = p − p_t − λ_p x_Ip. Not needed for
    /// stabilisability (see `solve_gain`); > 0 trades the zero steady-state error for less
    /// integrator memory.
    pub position_integrator_leak: f64,
    /// 1 (default) = wind-consistent air-data reference: the reference airspeed, α and β are
    /// those of the reference ground velocity minus the estimated wind, seen from the
    /// reference attitude: the wind counted in full along the reference body x and z axes
    /// (V, α), and across them (β) weighted by max(sin²θ_ref, (V_t/V_L)²) (full in vertical
    /// and level flight, less in the slow part of the transitions) (README, "Gusts"); 0 =
    /// the thesis's no-wind reference (V_t, α_t, β_t = 0).
    pub wind_compensation: i32,
    /// Time constant of the wind estimate ŵ = low-pass(v_inertial − DCMᵀ v_air) (s).
    pub wind_filter_time: f64,
    /// Trajectory: 0 = thesis closed forms (3.3.3–3.3.4, 3.3.13–3.3.17), 1 = force balance.
    pub trajectory_mode: i32,
    /// α_max of (3.3.4) (rad) (trajectory_mode 0 only).
    pub alpha_max: f64,
    /// Banked-turn radius ρ in the level segment (m) (3.3.18–3.3.21); 0 = straight, < 0 left.
    pub turn_radius: f64,
    /// 0 = tuned (these parameters as given), 1 = thesis (§3.2–3.5, see
    /// [`Self::effective`]): backward iteration over `riccati_horizon`, airspeed-integrator
    /// leak 0, Table 3.4 verbatim (weight set 0, switched without blending), the closed-form trajectory (3.3.x), the
    /// no-wind reference, airspeed integral only, and the reference re-anchored at the
    /// measured position at the start of every mission segment (§3.5.1); the switches below
    /// at −1 take the configuration's form (thesis: the printed one).
    pub configuration: i32,
    /// Discretisation of the model for control (docs/THESIS.md D-3.3): 0 = exact zero-order
    /// hold, 1 = the printed first-order form Φ ≈ I + F T_s, Γ ≈ G T_s (3.2.10–3.2.11), with
    /// the integrator augmentation of the corrected (3.2.13); −1 = follow `configuration`
    /// (0 tuned → 0, 1 thesis → 1). Likewise for the switches below: −1 = the configuration's
    /// default, 0 / 1 override it.
    pub discretisation: i32,
    /// Clamp of the airspeed integrator to ±`integrator_limit` (D-3.5): 1 = on, 0 = off (the
    /// printed 3.2.12–3.2.14 have no limit); −1 = follow `configuration` (tuned on, thesis
    /// off).
    pub integrator_clamp: i32,
    /// Freeze of the airspeed integrator while it integrates further into a thrust limit
    /// (D-3.5): 1 = on, 0 = off (printed); −1 = follow `configuration` (tuned on, thesis off).
    pub integrator_freeze: i32,
    /// Thrust command of the trajectory (D-3.15): 1 = T_c = T + τ_T Ṫ (the command leads the
    /// lagged thrust state, 2.3.16), 0 = T_c = T, the printed thrust of (3.3.13–3.3.14); −1 =
    /// follow `configuration` (tuned 1, thesis 0).
    pub thrust_lead: i32,
}

/// The configuration-following switches of [`LqrParams`]: (name, value, default with
/// `configuration` 0 (tuned), default with 1 (thesis)).
fn following_switches(p: &mut LqrParams) -> [(&'static str, &mut i32, i32, i32); 4] {
    [
        ("discretisation", &mut p.discretisation, 0, 1),
        ("integrator_clamp", &mut p.integrator_clamp, 1, 0),
        ("integrator_freeze", &mut p.integrator_freeze, 1, 0),
        ("thrust_lead", &mut p.thrust_lead, 1, 0),
    ]
}

impl LqrParams {
    /// The parameters the controller flies with: `self` for `configuration` 0 (tuned);
    /// for 1 (thesis) the structure and tuning as printed: the 200-step (`riccati_horizon`)
    /// backward Riccati iteration (3.1.3–3.1.5), airspeed-integrator leak 0 (3.2.12–3.2.14),
    /// weight set 0 (Table 3.4 verbatim) switched at the phase boundaries without blending
    /// (§3.4), trajectory mode 0 (closed forms 3.3.3–3.3.17),
    /// no wind compensation and no position integrators (the thesis has neither).
    ///
    /// The switches `discretisation`, `integrator_clamp`, `integrator_freeze` and
    /// `thrust_lead` follow the configuration when −1 (thesis: the printed forms, 0 / 1 as
    /// documented on each) and keep an explicit 0 or 1 in either configuration.
    pub fn effective(&self) -> Result<Self, ControlError> {
        let mut p = match self.configuration {
            0 => self.clone(),
            1 => Self {
                riccati_method: 1,
                integrator_leak: 0.0,
                weight_set: 0,
                weight_blend_time: 0.0,
                trajectory_mode: 0,
                wind_compensation: 0,
                position_integral: 0,
                ..self.clone()
            },
            c => {
                return Err(ControlError(format!(
                    "configuration = {c}: expected 0 (tuned) or 1 (thesis)"
                )))
            }
        };
        let thesis = p.configuration == 1;
        for (name, v, tuned, printed) in following_switches(&mut p) {
            *v = match *v {
                -1 if thesis => printed,
                -1 => tuned,
                0 | 1 => *v,
                x => {
                    return Err(ControlError(format!(
                        "{name} = {x}: expected -1 (follow configuration), 0 or 1"
                    )))
                }
            };
        }
        Ok(p)
    }

    /// Whether the reference is re-anchored at the measured position at the start of every
    /// mission segment (§3.5.1: "the current aircraft position is used as a starting point"
    /// of each new trajectory) — the thesis configuration; otherwise anchored once.
    pub fn reanchors(&self) -> bool {
        self.configuration == 1
    }
}

// `impl Default for LqrParams`: the start values of group `lqr` of
// modelDescription/tailsitter_lqr.json, generated by build.rs.
include!(concat!(env!("OUT_DIR"), "/lqr_params_generated.rs"));

/// Counters of the gain computations (for reports and benchmarks).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct GainStats {
    pub solves: u64,
    pub fallbacks: u64,
    /// Spectral-radius bound of the last accepted closed loop Φ − ΓK.
    pub last_spectral_radius: f64,
    /// Solves whose warm start (one Newton step from the previous P) was accepted.
    pub warm_solves: u64,
    /// With [`LqrController::verify_warm_start`]: the largest relative difference
    /// max|K_warm − K_cold| / max|K_cold| over the accepted warm solves.
    pub warm_max_gain_error: f64,
}

/// The LQR flight controller.
#[derive(Debug, Clone)]
pub struct LqrController {
    airframe: Airframe,
    mission: MissionParams,
    params: LqrParams,
    trajectory: Trajectory,
    schedule: WeightSchedule,
    // ---- state ----
    origin: Option<Vector3<f64>>,
    /// Mission phase the origin was last anchored in (re-anchoring, thesis configuration).
    anchored_phase: i32,
    integrator: f64,
    /// ∫ΔN, ∫ΔE, ∫Δh (m·s).
    pos_integrator: Vector3<f64>,
    /// Low-pass wind estimate, NED (m/s); NaN before the first sample.
    wind: Vector3<f64>,
    /// Rate of the wind estimate of the last sample, (raw − ŵ)/τ_w (m/s²); recomputed every
    /// sample before it is used (not part of the saved state).
    wind_rate: Vector3<f64>,
    gain: Gain,
    have_gain: bool,
    rep: EulerRep,
    next_relinearisation: f64,
    stats: GainStats,
    /// Heading reference in vertical flight (README, "Weathervaning").
    weathervane: Weathervane,
    /// Integrated horizontal position error in wind (N, E, 0) (m) (README, "Hover in wind").
    wind_shift: Vector3<f64>,
    /// Take-off and landing phases around the mission (guidance::ground).
    ground: GroundPhases,
    /// Whether the last sample flew a take-off / landing reference (position integrators on).
    ground_active: bool,
    /// Whether the weathervane's wind estimate has reached [`WIND_INTEGRAL_SPEED`] (latched): the position
    /// integrators are then on in the mission phases (README, "Mission in wind").
    wind_integral: bool,
    /// Whether the horizontal position integrators are on in the descent and flare in wind
    /// (README, "Take-off and landing"; [`Self::update_landing_integral`]).
    landing_integral: bool,
    /// Fraction (0–1) of the collective-flap trim applied in the descent and flare in wind,
    /// ramping in over [`LANDING_FLAP_RAMP_TIME`] (`reference::landing_flaps`).
    landing_flap_ramp: f64,
    /// The last DARE solution of the 14-state design, in the Euler set `rep` (warm start).
    warm_p: Option<SMatrix<f64, NR, NR>>,
    /// The two solutions before `warm_p` (same Euler set, consecutive), for extrapolation.
    warm_hist: [SMatrix<f64, NR, NR>; 2],
    /// How many of `warm_hist` are valid.
    warm_len: usize,
    /// Recompute every accepted warm solve cold and record the difference (tests).
    verify_warm: bool,
}

/// Names of the commands, for [`Notice::Saturated`].
use tailsitter_physics::idx::INPUT_NAMES as COMMAND_NAMES;

/// The configuration switches of the stages of Fig. 3.2 (README, "Where the blocks of
/// Fig. 3.2 live"), each stage's own, from the effective parameters: where the tuned
/// configuration departs from the printed thesis, per stage.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Stages {
    pub reference: ReferenceSwitches,
    pub error_state: ErrorStateSwitches,
    pub gain: GainScheduleSwitches,
    pub integrator: IntegratorSwitches,
}

impl LqrParams {
    /// The switches of each stage of `sample` (call on [`Self::effective`] parameters).
    pub(crate) fn stages(&self) -> Stages {
        let tuned = self.configuration == 0;
        Stages {
            reference: ReferenceSwitches {
                reanchor: self.reanchors(),
                hover_in_wind: tuned,
                wind_compensation: self.wind_compensation != 0,
                position_integral: self.position_integral != 0,
            },
            error_state: ErrorStateSwitches {
                euler_switch_pitch: self.euler_switch_pitch,
            },
            gain: GainScheduleSwitches {
                relinearisation_period: self.relinearisation_period,
                reference_after_back_transition: tuned,
                reference_in_transition_wind: tuned,
                reference_in_hover_wind: tuned,
            },
            integrator: IntegratorSwitches {
                integrator_limit: self.integrator_limit,
                integrator_clamp: self.integrator_clamp != 0,
                integrator_freeze: self.integrator_freeze != 0,
                integrator_leak: self.integrator_leak,
                position_integrator_limit: self.position_integrator_limit,
                position_integrator_leak: self.position_integrator_leak,
            },
        }
    }
}

impl LqrController {
    /// A controller with the controller's own airframe `airframe` (may differ from the
    /// plant's), the mission and the tuning. Builds the trajectory table and the weight
    /// schedule (the only allocations).
    pub fn new(airframe: Airframe, mission: MissionParams, params: LqrParams) -> Result<Self, ControlError> {
        Self::with_weights_json(airframe, mission, params, DEFAULT_WEIGHTS_JSON)
    }

    /// As [`Self::new`] with the weight tables of a JSON document (format of
    /// `resources/weights.json`); `params.weight_set` picks the set.
    pub fn with_weights_json(
        airframe: Airframe,
        mission: MissionParams,
        params: LqrParams,
        weights_json: &str,
    ) -> Result<Self, ControlError> {
        airframe
            .validate()
            .map_err(|e| ControlError(format!("controller airframe: {e}")))?;
        mission.validate().map_err(|e| ControlError(e.0))?;
        let params = params.effective()?;
        if mission.v_vertical < MIN_AIRSPEED {
            return Err(ControlError(format!(
                "v_vertical = {} m/s: the LQR's model uses airspeed, α and β as states (§2.4), undefined in \
                 hover; use v_vertical >= {MIN_AIRSPEED} m/s",
                mission.v_vertical
            )));
        }
        check_tuning(&params)?;
        let mode = check_switches(&params)?;
        let json = weights_json;
        let index = usize::try_from(params.weight_set).map_err(|_| ControlError("weight_set must be >= 0".into()))?;
        let set = load_set(json, index).map_err(ControlError)?;
        let schedule = WeightSchedule::new(&set, params.r_scale, params.weight_blend_time).map_err(ControlError)?;
        let trajectory = Trajectory::new(
            &airframe,
            &mission,
            &TrajectoryOptions {
                mode,
                alpha_max: params.alpha_max,
                turn_radius: params.turn_radius,
                // The thesis configuration flies the thesis's cosine blends (3.3.1–3.3.6).
                limited_path: params.configuration == 0,
                thrust_lead: params.thrust_lead != 0,
            },
        )
        .map_err(ControlError)?;
        let weathervane = Weathervane::new(if params.configuration == 0 {
            WeathervaneParams::tuned()
        } else {
            WeathervaneParams::disabled()
        })
        .map_err(ControlError)?;
        let mut c = Self {
            airframe,
            mission,
            params,
            trajectory,
            schedule,
            origin: None,
            anchored_phase: 0,
            integrator: 0.0,
            pos_integrator: Vector3::zeros(),
            wind: Vector3::new(f64::NAN, f64::NAN, f64::NAN),
            wind_rate: Vector3::zeros(),
            gain: Gain::zeros(),
            have_gain: false,
            rep: EulerRep::E231,
            next_relinearisation: 0.0,
            stats: GainStats::default(),
            weathervane,
            wind_shift: Vector3::zeros(),
            ground: GroundPhases::new(mission, airframe.mass * airframe.gravity),
            ground_active: false,
            wind_integral: false,
            landing_integral: false,
            landing_flap_ramp: 0.0,
            warm_p: None,
            warm_hist: [SMatrix::zeros(); 2],
            warm_len: 0,
            verify_warm: false,
        };
        c.initial_gains()?;
        Ok(c)
    }

    /// Initial gains on the trajectory's start point, so a failure shows at construction.
    fn initial_gains(&mut self) -> Result<(), ControlError> {
        let (p0, rep) = self.reference_and_euler_set(0.0);
        let sol = self.solve_gain(rep, &p0.state(rep), &p0.u, 0.0).map_err(|e| {
            ControlError(format!(
                "gain computation at the start of the trajectory failed: {}",
                e.describe()
            ))
        })?;
        self.gain = sol.gain;
        self.rep = rep;
        self.have_gain = true;
        Ok(())
    }

    /// The reference trajectory.
    pub fn trajectory(&self) -> &Trajectory {
        &self.trajectory
    }

    /// The trajectory's point at `t` and the Euler set the gain is computed in there
    /// (2-3-1 above `euler_switch_pitch`, §3.2.3.2).
    pub fn reference_and_euler_set(&self, t: f64) -> (trajectory::TrajPoint, EulerRep) {
        let p = self.trajectory.at(t);
        let rep = euler_set(p.euler_321.y, &self.params.stages().error_state);
        (p, rep)
    }

    /// The current gain matrix and the Euler set it belongs to.
    pub fn gain(&self) -> (&Gain, EulerRep) {
        (&self.gain, self.rep)
    }

    /// Gain computation counters.
    pub fn stats(&self) -> GainStats {
        self.stats
    }

    /// The tuning parameters.
    pub fn params(&self) -> &LqrParams {
        &self.params
    }

    /// Whether the position-error integrators are active (`position_integral = 1`, the
    /// take-off and landing phases, or the mission in wind).
    pub fn has_position_integral(&self) -> bool {
        self.params.position_integral != 0 || self.ground_active || self.wind_integral
    }

    /// Whether the integrator of position axis `j` (N, E, h) is active: all three with
    /// `position_integral = 1`; the height's alone in the take-off and landing phases, where
    /// the touchdown needs the height without a steady error (the descent's thrust differs
    /// from the vertical trim's; the horizontal integrators destabilise the hover
    /// translation of the approach); all three in the mission phases once the wind estimate
    /// has latched [`WIND_INTEGRAL_SPEED`].
    fn position_integral_on(&self, j: usize) -> bool {
        self.params.position_integral != 0
            || self.ground_active && j == 2
            || self.wind_integral && !self.ground_active
            || self.landing_integral
    }

    /// With `on`, every accepted warm-started gain is recomputed cold and the largest relative
    /// difference kept in [`GainStats::warm_max_gain_error`] (a check for tests; doubles the
    /// cost of those solves).
    pub fn verify_warm_start(&mut self, on: bool) {
        self.verify_warm = on;
    }

    /// The position integrators ∫ΔN, ∫ΔE, ∫Δh (m·s) and the wind estimate (NED, m/s).
    pub fn integrator_states(&self) -> (f64, Vector3<f64>, Vector3<f64>) {
        (self.integrator, self.pos_integrator, self.wind)
    }

    /// The weathervane of the heading reference (tuned configuration: on; thesis: off).
    pub fn weathervane(&self) -> &Weathervane {
        &self.weathervane
    }

    /// Replace the weathervane's tuning (resets its state).
    pub fn set_weathervane(&mut self, params: WeathervaneParams) -> Result<(), ControlError> {
        self.weathervane = Weathervane::new(params).map_err(ControlError)?;
        Ok(())
    }

    /// The weight schedule.
    pub fn schedule(&self) -> &WeightSchedule {
        &self.schedule
    }

    /// Positions in the [`Self::save`] layout of the controller's continuous states, with
    /// names: index 4 = the airspeed integrator; after the gains ∫ΔN, ∫ΔE, ∫Δh (with
    /// `position_integral = 1`) and the wind estimate (with `wind_compensation = 1`).
    pub fn dynamic_state_layout(&self) -> Vec<(usize, &'static str)> {
        let mut v = vec![(4, "∫ΔV")];
        let n = 11 + NU * NA;
        if self.has_position_integral() {
            v.extend([(n, "∫ΔN"), (n + 1, "∫ΔE"), (n + 2, "∫Δh")]);
        }
        if self.params.wind_compensation != 0 {
            v.extend([(n + 3, "ŵ_N"), (n + 4, "ŵ_E"), (n + 5, "ŵ_D")]);
        }
        v
    }
}

/// The numeric tuning of `params` (effective): periods, limits, scales finite and > 0, the
/// leaks finite and ≥ 0 (the airspeed integrator's > 0 with the DARE, see [`LqrParams`]).
fn check_tuning(params: &LqrParams) -> Result<(), ControlError> {
    let positive = [
        ("relinearisation_period", params.relinearisation_period),
        ("r_scale", params.r_scale),
        ("integrator_limit", params.integrator_limit),
        ("position_integrator_limit", params.position_integrator_limit),
        ("wind_filter_time", params.wind_filter_time),
    ];
    for (name, v) in positive {
        if !(v.is_finite() && v > 0.0) {
            return Err(ControlError(format!("{name} = {v}: must be finite and > 0")));
        }
    }
    let leak = params.integrator_leak;
    if !(leak.is_finite() && (leak > 0.0 || leak == 0.0 && params.riccati_method == 1)) {
        return Err(ControlError(format!(
            "integrator_leak = {leak}: must be finite and > 0 (= 0 only with riccati_method = 1, the \
             backward iteration: with the DARE the undamped integrator is an uncontrollable mode at z = 1)"
        )));
    }
    if !(params.position_integrator_leak.is_finite() && params.position_integrator_leak >= 0.0) {
        return Err(ControlError(format!(
            "position_integrator_leak = {}: must be finite and >= 0",
            params.position_integrator_leak
        )));
    }
    Ok(())
}

/// The switches of `params` (effective) in range; the trajectory mode they select.
fn check_switches(params: &LqrParams) -> Result<TrajectoryMode, ControlError> {
    if !(0..=1).contains(&params.wind_compensation) {
        return Err(ControlError(format!(
            "wind_compensation = {}: expected 0 (no-wind reference) or 1",
            params.wind_compensation
        )));
    }
    if !(0..=1).contains(&params.position_integral) {
        return Err(ControlError(format!(
            "position_integral = {}: expected 0 (thesis: airspeed integrator only) or 1 (position integrators)",
            params.position_integral
        )));
    }
    if !(params.euler_switch_pitch > 0.1 && params.euler_switch_pitch < 1.47) {
        return Err(ControlError(format!(
            "euler_switch_pitch = {}: must lie in (0.1, 1.47) rad, away from both Euler singularities",
            params.euler_switch_pitch
        )));
    }
    if !(0..=1).contains(&params.riccati_method) {
        return Err(ControlError(format!(
            "riccati_method = {}: expected 0 (DARE) or 1 (backward)",
            params.riccati_method
        )));
    }
    if params.riccati_horizon < 1 {
        return Err(ControlError(format!(
            "riccati_horizon = {}: must be >= 1",
            params.riccati_horizon
        )));
    }
    match params.trajectory_mode {
        0 => Ok(TrajectoryMode::Thesis),
        1 => Ok(TrajectoryMode::ForceBalance),
        m => Err(ControlError(format!(
            "trajectory_mode = {m}: expected 0 (thesis) or 1 (force balance)"
        ))),
    }
}

/// Everything an [`LqrController`] is built from: the FMU's parameters. The default: the
/// nominal airframe, the default mission, tuning and the built-in weights.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct LqrConfig {
    /// The controller's own model of the airframe (may differ from the plant's).
    pub airframe: Airframe,
    pub mission: MissionParams,
    pub params: LqrParams,
    /// Weight tables in a JSON file (`weights_file`); empty: the built-in tables.
    pub weights_file: String,
}

impl LqrConfig {
    /// The nominal airframe, the given mission, default tuning and weights.
    pub fn with_mission(mission: MissionParams) -> Self {
        Self {
            mission,
            ..Self::default()
        }
    }
}

impl SampledUnit for LqrController {
    type Config = LqrConfig;
    type Input = ControllerInput;
    type Output = ControllerOutput;

    fn build(c: &LqrConfig) -> Result<Self, ParamError> {
        if c.weights_file.is_empty() {
            Self::new(c.airframe, c.mission, c.params.clone())
        } else {
            let json = std::fs::read_to_string(&c.weights_file)
                .map_err(|e| ParamError(format!("weights_file {:?}: {e}", c.weights_file)))?;
            Self::with_weights_json(c.airframe, c.mission, c.params.clone(), &json)
        }
        .map_err(|e| ParamError(e.0))
    }

    fn sample_time(c: &LqrConfig) -> f64 {
        c.mission.sample_time
    }

    /// Append the controller's state (everything `sample` depends on besides its
    /// construction parameters) as f64s.
    fn save(&self, out: &mut impl FnMut(f64)) {
        let origin = self
            .origin
            .unwrap_or_else(|| Vector3::new(f64::NAN, f64::NAN, f64::NAN));
        out(if self.origin.is_some() { 1.0 } else { 0.0 });
        for v in origin.iter() {
            out(*v);
        }
        out(self.integrator);
        out(if self.have_gain { 1.0 } else { 0.0 });
        out(self.rep as i32 as f64);
        out(self.next_relinearisation);
        out(self.stats.solves as f64);
        out(self.stats.fallbacks as f64);
        out(self.stats.last_spectral_radius);
        for v in self.gain.iter() {
            out(*v);
        }
        for v in self.pos_integrator.iter() {
            out(*v);
        }
        for v in self.wind.iter() {
            out(*v);
        }
        out(f64::from(self.anchored_phase));
        self.weathervane.save(out);
        for v in self.wind_shift.iter() {
            out(*v);
        }
        self.ground.save(out);
        out(f64::from(u8::from(self.ground_active)));
        out(self.stats.warm_solves as f64);
        out(f64::from(u8::from(self.warm_p.is_some())));
        for v in self.warm_p.unwrap_or_else(SMatrix::zeros).iter() {
            out(*v);
        }
        out(self.warm_len as f64);
        for v in self.warm_hist.iter().flat_map(|m| m.iter()) {
            out(*v);
        }
        out(f64::from(u8::from(self.wind_integral)));
        out(f64::from(u8::from(self.landing_integral)));
        out(self.landing_flap_ramp);
    }

    /// Restore what [`Self::save`] wrote; `None` from `next` = truncated state.
    fn restore(&mut self, next: &mut impl FnMut() -> Option<f64>) -> Result<(), ControlError> {
        let mut take = || next().ok_or_else(|| ControlError("truncated LQR controller state".into()));
        let has_origin = take()? != 0.0;
        let o = Vector3::new(take()?, take()?, take()?);
        self.origin = if has_origin { Some(o) } else { None };
        self.integrator = take()?;
        self.have_gain = take()? != 0.0;
        self.rep = if take()? == 0.0 { EulerRep::E321 } else { EulerRep::E231 };
        self.next_relinearisation = take()?;
        self.stats.solves = take()? as u64;
        self.stats.fallbacks = take()? as u64;
        self.stats.last_spectral_radius = take()?;
        for v in self.gain.iter_mut() {
            *v = take()?;
        }
        for v in self.pos_integrator.iter_mut() {
            *v = take()?;
        }
        for v in self.wind.iter_mut() {
            *v = take()?;
        }
        let phase = take()?;
        if !(0.0..=4.0).contains(&phase) || phase.fract() != 0.0 {
            return Err(ControlError(format!("LQR controller state: anchored phase {phase}")));
        }
        self.anchored_phase = phase as i32;
        self.weathervane.restore(&mut || next()).map_err(ControlError)?;
        let mut take = || next().ok_or_else(|| ControlError("truncated LQR controller state".into()));
        self.wind_shift = Vector3::new(take()?, take()?, take()?);
        self.ground
            .restore(&mut || take().ok())
            .ok_or_else(|| ControlError("truncated LQR controller state".into()))?;
        self.ground_active = take()? != 0.0;
        self.stats.warm_solves = take()? as u64;
        let has_warm = take()? != 0.0;
        let mut p = SMatrix::<f64, NR, NR>::zeros();
        for v in p.iter_mut() {
            *v = take()?;
        }
        self.warm_p = has_warm.then_some(p);
        let len = take()?;
        if !(0.0..=2.0).contains(&len) || len.fract() != 0.0 {
            return Err(ControlError(format!("LQR controller state: warm-start history {len}")));
        }
        self.warm_len = len as usize;
        for m in self.warm_hist.iter_mut() {
            for v in m.iter_mut() {
                *v = take()?;
            }
        }
        self.wind_integral = take()? != 0.0;
        self.landing_integral = take()? != 0.0;
        self.landing_flap_ramp = take()?;
        Ok(())
    }

    /// One sample of Fig. 3.2, stage by stage (README, "Where the blocks of Fig. 3.2 live"):
    /// take-off / landing (`ground_stage`) → reference x_t, u_t (`reference_stage`, §3.3) →
    /// Euler set and error state (`euler_set`, `state_and_reference`, 3.2.1) → gain schedule
    /// (`schedule_gains`, §3.1.3, §3.2.4) → feedback u = u_t − K dx (`command_stage`) →
    /// integrators (`integrator_stage`, 3.2.12–3.2.14) → diagnostics. The switches of each
    /// stage come from `LqrParams::stages`.
    fn sample(&mut self, input: &ControllerInput) -> Result<ControllerOutput, ControlError> {
        let m = &input.measurement;
        if let Some(name) = m.first_non_finite() {
            return Err(ControlError(format!("measurement {name} is not finite")));
        }
        if !input.t.is_finite() {
            return Err(ControlError(format!("sample time t = {} is not finite", input.t)));
        }
        let sw = self.params.stages();
        // The mission time t is the FMU time less the spin-up and take-off climb (the same
        // without take-off).
        let t = input.t - self.ground.mission_start();
        let measured_neh = Vector3::new(m.pos_ned.x, m.pos_ned.y, -m.pos_ned.z);
        let ground = match self.ground_stage(input, measured_neh, &sw.reference) {
            ControlFlow::Continue(ground) => ground,
            ControlFlow::Break(idle) => return Ok(idle),
        };
        let r = self.reference_stage(input, t, measured_neh, ground, &sw.reference);
        let rep = euler_set(r.pitch_321, &sw.error_state);
        let (x, xt) = self.state_and_reference(rep, m, &r);
        let mut notice = self.schedule_gains(t, m, &r, rep, (&x, &xt), &sw.gain);
        // A failed solve at an Euler switch keeps the gains in use, and with them their set.
        let (x, xt) = if self.rep == rep {
            (x, xt)
        } else {
            self.state_and_reference(self.rep, m, &r)
        };
        let dx = self.error_vector(&x, &xt);
        let (u, saturated) = self.command_stage(t, &r.feed_forward(), &dx, &mut notice)?;
        self.integrator_stage(&x, &xt, &saturated, &sw.integrator);
        Ok(ControllerOutput {
            command: Command::from_array(u.into()),
            diagnostics: self.diagnostics(t, &measured_neh, &r),
            notice,
        })
    }
}
