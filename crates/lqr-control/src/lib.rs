//! Gain-scheduled LQR flight controller of S.C. Kriel's tail-sitter thesis (chapter 3),
//! pure Rust, independent of FMI.
//!
//! * [`model`]: the full-state Euler model for control (§2.4, candidate 2 of §3.2.3) on the
//!   physics crate's force model, linearised analytically (3.2.7–3.2.9).
//! * [`linalg`]: zero-order-hold discretisation (replacing (3.2.10–3.2.11)), the steady-state
//!   DARE by structured doubling, the thesis's N-step backward iteration (3.1.3–3.1.5).
//! * [`trajectory`]: the reference trajectory of §3.3.
//! * [`weights`]: Table 3.4 weights per phase (3.4.1–3.4.3), blended between phases.
//! * [`LqrController`]: implements [`flight_mission::FlightController`]:
//!   every `relinearisation_period` it relinearises about the current estimated state and
//!   the trajectory's inputs, discretises, adds the airspeed integrator (3.2.12–3.2.14) and
//!   solves for K; every sample it applies `u = u_t − K [∫ΔV; x − x_t]`.
//!
//! See README.md for the equations and the design choices.

pub mod linalg;
pub mod model;
pub mod trajectory;
pub mod weights;

use flight_mission::{
    Command, ControlError, ControllerInput, ControllerOutput, Diagnostics, MissionParams, Notice, ParamError,
    SampledUnit,
};
use guidance::{GroundMode, GroundPhases, VerticalReference, Weathervane, WeathervaneParams};
use nalgebra::{Matrix3, SMatrix, SVector, Vector3};
use tailsitter_physics::{Airframe, Surfaces};

use linalg::{
    dare_newton_step, dare_residual, dare_sda, discretise_zoh, lqr_gain, riccati_backward, spectral_radius_bound,
    RiccatiError,
};
use model::{ix, linearise, state_of, wrap_pi, EulerRep, I_POS, NA, NU, NX, U, X};
use trajectory::{TrajPoint, Trajectory, TrajectoryMode, TrajectoryOptions};
use weights::{load_set, WeightSchedule, Weights, DEFAULT_WEIGHTS_JSON};

/// Smallest reference airspeed the (V, α, β) model for control supports (m/s).
pub const MIN_AIRSPEED: f64 = 0.5;

/// Bound on the magnitude of the wind estimate (m/s).
pub const MAX_WIND_ESTIMATE: f64 = 20.0;

/// |α| or |β| beyond which vertical flight counts as flight in wind (rad): the gains are then
/// computed about the reference instead of the measured state (README, "Hover in wind").
pub const HOVER_WIND_AIR_ANGLE: f64 = 0.5235987755982988; // 30°

/// Largest pitch rotation of the wind trim (rad) (README, "Gusts").
pub const WIND_TRIM_MAX_PITCH: f64 = 0.3490658503988659; // 20°
/// The wind trim is phased in (smoothstep) as the estimated wind rises between these
/// speeds (m/s): below the first the reference is untrimmed (still air bit-identical, and
/// the air-data wind an estimator makes of still air not flown).
pub const WIND_TRIM_RAMP: (f64, f64) = (0.5, 1.5);

/// Time constant τ_s of the integral action on the horizontal position in wind (s).
pub const HOVER_SHIFT_TIME: f64 = 3.0;
/// Bound on that integral's shift of the regulated position (m).
pub const HOVER_SHIFT_LIMIT: f64 = 5.0;

/// Size of the augmented ZOH exponential: states + integrator + inputs.
const NM: usize = NA + NU;

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
    /// Limit of the airspeed-error integrator |∫ΔV dt| (m).
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
    /// measured position at the start of every mission segment (§3.5.1).
    pub configuration: i32,
}

impl LqrParams {
    /// The parameters the controller flies with: `self` for `configuration` 0 (tuned);
    /// for 1 (thesis) the structure and tuning as printed: the 200-step (`riccati_horizon`)
    /// backward Riccati iteration (3.1.3–3.1.5), airspeed-integrator leak 0 (3.2.12–3.2.14),
    /// weight set 0 (Table 3.4 verbatim) switched at the phase boundaries without blending
    /// (§3.4), trajectory mode 0 (closed forms 3.3.3–3.3.17),
    /// no wind compensation and no position integrators (the thesis has neither).
    pub fn effective(&self) -> Result<Self, ControlError> {
        match self.configuration {
            0 => Ok(self.clone()),
            1 => Ok(Self {
                riccati_method: 1,
                integrator_leak: 0.0,
                weight_set: 0,
                weight_blend_time: 0.0,
                trajectory_mode: 0,
                wind_compensation: 0,
                position_integral: 0,
                ..self.clone()
            }),
            c => Err(ControlError(format!(
                "configuration = {c}: expected 0 (tuned) or 1 (thesis)"
            ))),
        }
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
    /// Take-off and landing phases around the mission (flight_mission::ground).
    ground: GroundPhases,
    /// Whether the last sample flew a take-off / landing reference (position integrators on).
    ground_active: bool,
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

/// The result of one gain computation.
#[derive(Debug, Clone, Copy)]
pub struct GainSolution {
    pub gain: Gain,
    pub phi: SMatrix<f64, NA, NA>,
    pub gamma: SMatrix<f64, NA, NU>,
    pub spectral_radius: f64,
    /// The DARE solution of the design on the [∫ΔV; x] block (inert position integrators,
    /// `riccati_method` 0): the warm start of the next solve. `None` otherwise.
    pub p: Option<SMatrix<f64, NR, NR>>,
    /// Whether the warm start was accepted (else the DARE was solved cold).
    pub warm: bool,
}

/// Size of the design when the position integrators are inert: integrator + model states.
pub const NR: usize = 1 + NX;
/// Size of the augmented ZOH exponential of that design.
const NRM: usize = NR + NU;

/// Warm start of the DARE (README, "Riccati"): a Newton step from the extrapolated previous
/// P is tried only when that start's relative DARE residual on the new model is at most this
/// (close enough for one quadratic step to reach rounding; a farther start goes cold at
/// once, having cost only the residual).
pub const WARM_MAX_START_RESIDUAL: f64 = 1e-7;
/// Newton steps of the warm start before it gives up and solves cold. One: a step (Smith's
/// doubling of the Stein equation, ≈ 13 doublings like the cold SDA's: the slow closed-loop
/// poles set both counts) costs ≈ 0.55 of the cold solve, so a second step loses.
pub const WARM_MAX_NEWTON_STEPS: usize = 1;
/// A further Newton step is taken only from a residual at most this.
pub const WARM_MAX_STEP_RESIDUAL: f64 = 1e-7;
/// The warm solution is accepted when its relative DARE residual is at most this (the cold
/// doubling reaches ≈ 1e-16); otherwise the cold doubling solves again.
pub const WARM_MAX_RESIDUAL: f64 = 1e-13;

/// Discretised model, gain and closed-loop spectral-radius bound of one design.
struct Design<const N: usize> {
    k: SMatrix<f64, NU, N>,
    phi: SMatrix<f64, N, N>,
    gamma: SMatrix<f64, N, NU>,
    rho: f64,
    /// The DARE solution (`riccati_method` 0).
    p: Option<SMatrix<f64, N, N>>,
    /// Whether the warm start was accepted.
    warm: bool,
}

/// ZOH discretisation of (A, B) over `ts` (`M` = N + NU), gain by the DARE (`riccati_method`
/// 0, residual checked; warm-started by one Newton step from `warm` when given and close
/// enough, else the cold doubling) or the backward iteration (1), and the stability check of
/// Φ − ΓK against `limit`.
#[allow(clippy::too_many_arguments)]
fn design<const N: usize, const M: usize>(
    a: &SMatrix<f64, N, N>,
    b: &SMatrix<f64, N, NU>,
    q_diag: &SVector<f64, N>,
    r: &SVector<f64, NU>,
    ts: f64,
    params: &LqrParams,
    limit: f64,
    warm: Option<&SMatrix<f64, N, N>>,
) -> Result<Design<N>, RiccatiError> {
    let (phi, gamma) = discretise_zoh::<N, NU, M>(a, b, ts);
    let q = SMatrix::<f64, N, N>::from_diagonal(q_diag);
    let (k, p, warm) = if params.riccati_method == 0 {
        // Warm: Newton steps from the previous P, accepted on the residual.
        let warm_solution = warm.and_then(|p0| {
            let mut p = *p0;
            let mut max_start = WARM_MAX_START_RESIDUAL;
            for _ in 0..WARM_MAX_NEWTON_STEPS {
                // A start already converged (the model has not changed: steady flight) is
                // returned as it is and accepted on the residual below.
                p = dare_newton_step(&phi, &gamma, &q, r, &p, max_start, WARM_MAX_RESIDUAL)
                    .ok()?
                    .0;
                let k = lqr_gain(&phi, &gamma, &p, r).ok()?;
                let res = dare_residual(&phi, &gamma, &q, &p, &k);
                if res <= WARM_MAX_RESIDUAL {
                    return Some((k, p));
                }
                // The next step starts from here: it must converge at once.
                max_start = WARM_MAX_STEP_RESIDUAL;
            }
            None
        });
        match warm_solution {
            Some((k, p)) => (k, Some(p), true),
            None => {
                let p = dare_sda(&phi, &gamma, &q, r)?;
                let k = lqr_gain(&phi, &gamma, &p, r)?;
                let res = dare_residual(&phi, &gamma, &q, &p, &k);
                if res.is_nan() || res >= 1e-6 {
                    return Err(RiccatiError::Residual(res));
                }
                (k, Some(p), false)
            }
        }
    } else {
        let k = riccati_backward(&phi, &gamma, &q, r, params.riccati_horizon as usize, None)?.0;
        (k, None, false)
    };
    let rho = spectral_radius_bound(&(phi - gamma * k));
    if rho.is_nan() || rho >= limit {
        return Err(RiccatiError::Unstable(rho));
    }
    Ok(Design {
        k,
        phi,
        gamma,
        rho,
        p,
        warm,
    })
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
        let mode = match params.trajectory_mode {
            0 => TrajectoryMode::Thesis,
            1 => TrajectoryMode::ForceBalance,
            m => {
                return Err(ControlError(format!(
                    "trajectory_mode = {m}: expected 0 (thesis) or 1 (force balance)"
                )))
            }
        };
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
            warm_p: None,
            warm_hist: [SMatrix::zeros(); 2],
            warm_len: 0,
            verify_warm: false,
        };
        // Initial gains on the trajectory's start point, so a failure shows at construction.
        let p0 = c.trajectory.at(0.0);
        let rep = c.rep_for(&p0);
        let sol = c.solve_gain(rep, &p0.state(rep), &p0.u, 0.0).map_err(|e| {
            ControlError(format!(
                "gain computation at the start of the trajectory failed: {}",
                e.describe()
            ))
        })?;
        c.gain = sol.gain;
        c.rep = rep;
        c.have_gain = true;
        Ok(c)
    }

    /// The reference trajectory.
    pub fn trajectory(&self) -> &Trajectory {
        &self.trajectory
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

    /// Whether the position-error integrators are active (`position_integral = 1`).
    pub fn has_position_integral(&self) -> bool {
        self.params.position_integral != 0 || self.ground_active
    }

    /// Whether the integrator of position axis `j` (N, E, h) is active: all three with
    /// `position_integral = 1`; the height's alone in the take-off and landing phases, where
    /// the touchdown needs the height without a steady error (the descent's thrust differs
    /// from the vertical trim's; the horizontal integrators destabilise the hover
    /// translation of the approach).
    fn position_integral_on(&self, j: usize) -> bool {
        self.params.position_integral != 0 || self.ground_active && j == 2
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

    /// The Euler set for a reference point: 2-3-1 when the reference 3-2-1 pitch exceeds
    /// `euler_switch_pitch` (vertical flight and the nose-high parts of the transitions,
    /// where 3-2-1 is singular), 3-2-1 otherwise (§2.2.1, §3.2.3.2).
    fn rep_for(&self, p: &TrajPoint) -> EulerRep {
        if p.euler_321.y.abs() > self.params.euler_switch_pitch {
            EulerRep::E231
        } else {
            EulerRep::E321
        }
    }

    /// Linearise about (x, u_t), discretise by ZOH with the airspeed integrator, and solve
    /// for the gain with the weights of time t. No allocation.
    ///
    /// Integrator (3.2.12–3.2.14), derived in continuous time and discretised with the
    /// model: `ẋ_I = V − V_t − λ x_I = H_I x_p − λ x_I`, so the augmented system is
    /// `[ẋ_I; ẋ_p] = [−λ H_I; 0 F] [x_I; x_p] + [0; G] u_p`, and ZOH gives
    /// `Φ_I = [e^{−λT_s} ∫H_I e^{Fτ}dτ; 0 Φ]`, `Γ_I = [·; Γ]` — to first order in T_s and
    /// for λ = 0 `Φ_I ≈ [1 T_s H_I; 0 Φ]`; the printed (3.2.13) has T_s in the (1,1)
    /// position and Γ_I's first row is not zero but O(T_s²). The small leak λ
    /// (`integrator_leak`) makes the augmented pair stabilisable (see [`LqrParams`]).
    ///
    /// The DARE is solved cold (structured doubling); [`Self::solve_gain_warm`] starts from a
    /// previous solution.
    pub fn solve_gain(&self, rep: EulerRep, x: &X, u: &U, t: f64) -> Result<GainSolution, RiccatiError> {
        self.solve_gain_warm(rep, x, u, t, None)
    }

    /// [`Self::solve_gain`] with the DARE warm-started from `warm`, the [`GainSolution::p`] of
    /// an earlier solve (README, "Riccati"): one Newton step, accepted when the residual of its
    /// result is ≤ [`WARM_MAX_RESIDUAL`], else the cold doubling. Only the design with inert
    /// position integrators (the default) is warm-started.
    pub fn solve_gain_warm(
        &self,
        rep: EulerRep,
        x: &X,
        u: &U,
        t: f64,
        warm: Option<&SMatrix<f64, NR, NR>>,
    ) -> Result<GainSolution, RiccatiError> {
        let mut xl = *x;
        // Keep the linearisation point inside the model's domain (V > 0, away from the
        // Euler singularity the rep choice avoids anyway).
        xl[ix::V] = xl[ix::V].max(1.0);
        let (f, g) = linearise(&self.airframe, rep, &xl, u);
        let mut a = SMatrix::<f64, NA, NA>::zeros();
        a[(0, 0)] = -self.params.integrator_leak;
        a[(0, 1 + ix::V)] = 1.0;
        a.fixed_view_mut::<NX, NX>(1, 1).copy_from(&f);
        for j in 0..3 {
            if self.position_integral_on(j) {
                // ẋ_Ip = p − p_t − λ_p x_Ip, p ∈ {N, E, h}.
                a[(I_POS + j, 1 + ix::N + j)] = 1.0;
                a[(I_POS + j, I_POS + j)] = -self.params.position_integrator_leak;
            } else {
                // Thesis structure: the position integrators are inert, decoupled, stable
                // states (not driven by the model, not driving it). The DARE solution is then
                // block-diagonal and their gain columns are zero: K on the other states is
                // exactly the thesis's 14-state gain.
                a[(I_POS + j, I_POS + j)] = -1.0;
            }
        }
        let mut b = SMatrix::<f64, NA, NU>::zeros();
        b.fixed_view_mut::<NX, NU>(1, 0).copy_from(&g);
        if !a.iter().chain(b.iter()).all(|v| v.is_finite()) {
            return Err(RiccatiError::NonFinite);
        }
        let w: Weights = self.schedule.at(&self.mission, t);
        let ts = self.mission.sample_time;
        // With the undamped integrator (leak 0, thesis) the integrator-minus-along-track
        // mode sits at z = 1 whatever the gain: accept the marginal bound (a Jordan block at
        // z = 1 raises the 2¹⁶-power bound to at most (2¹⁶)^(1/2¹⁶) ≈ 1 + 1.7e-4).
        let limit = if self.params.integrator_leak == 0.0 {
            1.0 + 1e-3
        } else {
            1.0
        };
        if (0..3).any(|j| self.position_integral_on(j)) {
            let d = design::<NA, NM>(&a, &b, &w.q, &w.r, ts, &self.params, limit, None)?;
            return Ok(GainSolution {
                gain: d.k,
                phi: d.phi,
                gamma: d.gamma,
                spectral_radius: d.rho,
                p: None,
                warm: false,
            });
        }
        // Inert position integrators (the default): they are decoupled (ẋ_Ip = −x_Ip, no
        // input), so Φ, Γ, P are block-diagonal and their gain columns zero. The design runs
        // on the leading [∫ΔV; x] block alone (NR = 14 states: ≈ 0.56× the cubic work of 17)
        // and the result is embedded: the same gains to rounding (an inert state only ever
        // adds exact zeros to the full problem's sums).
        let d = design::<NR, NRM>(
            &a.fixed_view::<NR, NR>(0, 0).into_owned(),
            &b.fixed_view::<NR, NU>(0, 0).into_owned(),
            &w.q.fixed_rows::<NR>(0).into_owned(),
            &w.r,
            ts,
            &self.params,
            limit,
            warm,
        )?;
        let mut k = Gain::zeros();
        k.fixed_view_mut::<NU, NR>(0, 0).copy_from(&d.k);
        let mut phi = SMatrix::<f64, NA, NA>::zeros();
        phi.fixed_view_mut::<NR, NR>(0, 0).copy_from(&d.phi);
        let inert = (-ts).exp();
        for j in NR..NA {
            phi[(j, j)] = inert;
        }
        let mut gamma = SMatrix::<f64, NA, NU>::zeros();
        gamma.fixed_view_mut::<NR, NU>(0, 0).copy_from(&d.gamma);
        // The inert block's eigenvalue e^{−T_s} joins the spectrum of the closed loop.
        let rho = d.rho.max(inert);
        Ok(GainSolution {
            gain: k,
            phi,
            gamma,
            spectral_radius: rho,
            p: d.p,
            warm: d.warm,
        })
    }

    /// Update the wind estimate: ŵ ← ŵ + (1 − e^{−T_s/τ_w}) (v_inertial − DCMᵀ v_air − ŵ),
    /// v_air = V (cα cβ, sβ, sα cβ); initialised with the first measurement, bounded by
    /// [`MAX_WIND_ESTIMATE`], only finite values committed.
    fn estimate_wind(&mut self, m: &flight_mission::Measurement) {
        if self.params.wind_compensation == 0 {
            self.wind = Vector3::zeros();
            return;
        }
        let (sa, ca) = m.alpha.sin_cos();
        let (sb, cb) = m.beta.sin_cos();
        let v_air = m.airspeed * Vector3::new(ca * cb, sb, sa * cb);
        let raw = m.vel_ned - model::dcm_of_quat(&m.quat).transpose() * v_air;
        let mut w = if self.wind.iter().all(|v| v.is_finite()) {
            let k = 1.0 - (-self.mission.sample_time / self.params.wind_filter_time).exp();
            self.wind + k * (raw - self.wind)
        } else {
            raw
        };
        let n = w.norm();
        let bounded = n > MAX_WIND_ESTIMATE;
        if bounded {
            w *= MAX_WIND_ESTIMATE / n;
        }
        if w.iter().all(|v| v.is_finite()) {
            self.wind = w;
            // The filter's own rate, dŵ/dt = (raw − ŵ)/τ_w; none while the bound holds ŵ.
            let rate = (raw - w) / self.params.wind_filter_time;
            self.wind_rate = if !bounded && rate.iter().all(|v| v.is_finite()) {
                rate
            } else {
                Vector3::zeros()
            };
        }
    }

    /// Sideways weight of the wind in the air-data reference, max(sin²θ_ref, (V_t/V_L)²).
    fn lateral_wind_weight(&self, p: &TrajPoint) -> f64 {
        p.euler_321
            .y
            .sin()
            .powi(2)
            .max((p.v / self.mission.v_level).powi(2).min(1.0))
    }

    /// The reference point trimmed for the estimated wind (README, "Gusts"), weighted by the
    /// lift-borne fraction (V_t/V_L)²: pitch θ_t + δ with α_t + δ (the same ground velocity),
    /// the pitch rate δ̇ added to the body rates (through the wind estimate's rate), thrust and
    /// elevator changed. None without wind compensation, in still air or where the trim fails.
    fn trimmed(&self, p: &TrajPoint) -> Option<TrajPoint> {
        let h = self.mission.sample_time;
        let w_next = self.wind + h * self.wind_rate;
        let lift = (p.v / self.mission.v_level).powi(2).min(1.0);
        let (w0, w1) = WIND_TRIM_RAMP;
        let weight = |w: &Vector3<f64>| {
            let x = ((w.norm() - w0) / (w1 - w0)).clamp(0.0, 1.0);
            lift * x * x * (3.0 - 2.0 * x)
        };
        let (k, k_next) = (weight(&self.wind), weight(&w_next));
        if self.params.wind_compensation == 0 || !(k > 0.0 || k_next > 0.0) {
            return None;
        }
        let s_lat = self.lateral_wind_weight(p);
        let z = self.wind_trim(p, &self.wind, s_lat)?;
        let z_next = self.wind_trim(p, &w_next, s_lat)?;
        let rate = (k_next * z_next.x - k * z.x) / h;
        let mut q = *p;
        q.euler_321.y += k * z.x;
        q.alpha += k * z.x;
        let (sphi, cphi) = p.euler_321.x.sin_cos();
        q.rates += rate * Vector3::new(0.0, cphi, -sphi);
        q.thrust += k * z.y;
        q.u[0] += k * z.y;
        q.u[1] += k * z.z;
        Some(q)
    }

    /// Lift-borne wind trim of a reference point (README, "Gusts"): the pitch rotation δ, the
    /// thrust change ΔT and the elevator change Δδe that keep the reference's force and
    /// pitching moment — hence its ground-path acceleration (2.2.19–2.2.21) and q̇
    /// (2.2.22–2.2.24) — in the wind `wind` (NED, m/s): with C(δ) the reference attitude
    /// pitched by δ and v_a = v_g,t − ŵ, solve
    /// C(δ)ᵀ F(C(δ) v_a, T_t + ΔT, δe_t + Δδe) = C_tᵀ F(v_b,t, T_t, δe_t) (in-plane x, z) and
    /// M_y(…) = M_y,t by Newton's method on the model for control. None where it does not
    /// converge or leaves the limits (the untrimmed reference is then used).
    fn wind_trim(&self, p: &TrajPoint, wind: &Vector3<f64>, s_lat: f64) -> Option<Vector3<f64>> {
        let af = &self.airframe;
        let surfaces = |dde: f64| Surfaces::from_array([p.u[1] + dde, p.u[2], p.u[3], p.u[4], p.u[5], p.u[6]]);
        let c_t = model::dcm_of_quat(&p.quat());
        let vb_t = model::body_velocity(p.v, p.alpha, 0.0);
        let fm_t = af.forces_moments(&vb_t, &p.rates, p.thrust, &surfaces(0.0));
        let f_e = c_t.transpose() * fm_t.force_body;
        let v_g = c_t.transpose() * vb_t;
        let (v_a, v_lat) = (v_g - wind, v_g - s_lat * wind);
        let residual = |z: &Vector3<f64>| -> Vector3<f64> {
            let mut q = *p;
            q.euler_321.y += z.x;
            let c = model::dcm_of_quat(&q.quat());
            let mut vb = c * v_a;
            vb.y = (c * v_lat).y;
            let fm = af.forces_moments(&vb, &p.rates, p.thrust + z.y, &surfaces(z.z));
            let df = c_t * (c.transpose() * fm.force_body - f_e);
            Vector3::new(df.x, df.z, fm.moment_body.y - fm_t.moment_body.y)
        };
        let steps = Vector3::new(1e-6, 1e-4, 1e-6);
        let mut z = Vector3::zeros();
        for _ in 0..8 {
            let r = residual(&z);
            if !r.iter().all(|v| v.is_finite()) {
                return None;
            }
            if r.xy().norm() < 1e-6 * af.mass * af.gravity && r.z.abs() < 1e-7 {
                let in_limits = z.x.abs() <= WIND_TRIM_MAX_PITCH
                    && (af.thrust_min..=af.thrust_max).contains(&(p.thrust + z.y))
                    && (p.u[1] + z.z).abs() <= af.deflection_limit;
                return in_limits.then_some(z);
            }
            let mut jac = Matrix3::zeros();
            for j in 0..3 {
                let mut zj = z;
                zj[j] += steps[j];
                jac.set_column(j, &((residual(&zj) - r) / steps[j]));
            }
            z -= jac.lu().solve(&r)?;
        }
        None
    }

    /// Reference (V, α, β): with wind compensation, those of the air velocity
    /// `DCM_t (v_g,t − ŵ)` in the reference body axes, where `v_g,t = DCM_tᵀ V_t (cα_t, 0, sα_t)`
    /// is the reference (no-wind) ground velocity. In vertical flight holding a position in
    /// wind needs large α or β (with the no-wind reference α_t = β_t = 0 the LQR fights the
    /// air angles, yaws about the thrust axis and loses the aircraft beyond ≈ 3 m/s). In
    /// level flight and the transitions the reference ground path is held through gusts:
    /// the airspeed and α follow the wind (README, "Gusts"; with the mission's airspeed
    /// and α the LQR ran 3.5 m ahead in a 5 m/s tailwind gust and sank 3.9 m in a down
    /// gust). The sideways component (β) is weighted by s = max(sin²θ_ref, (V_t/V_L)²):
    /// counted in full, a 5 m/s gust across the path in the slow part of transition 1
    /// (V_t ≈ 10 m/s, β ≈ 27°) left the aircraft 5.8 m off (1.2 m with s = sin²θ_ref).
    fn air_reference(&self, p: &TrajPoint) -> Vector3<f64> {
        let plain = Vector3::new(p.v, p.alpha, 0.0);
        if self.params.wind_compensation == 0 || !self.wind.iter().all(|v| v.is_finite()) {
            return plain;
        }
        let s_lat = self.lateral_wind_weight(p);
        let c = model::dcm_of_quat(&p.quat());
        let (sa, ca) = p.alpha.sin_cos();
        let v_g = c.transpose() * (p.v * Vector3::new(ca, 0.0, sa));
        let full = c * (v_g - self.wind);
        let v_b = Vector3::new(full.x, (c * (v_g - s_lat * self.wind)).y, full.z);
        let v = v_b.norm();
        if !(v.is_finite() && v >= MIN_AIRSPEED) {
            return plain;
        }
        Vector3::new(v, v_b.z.atan2(v_b.x), (v_b.y / v).clamp(-1.0, 1.0).asin())
    }

    /// Position integrators ∫ΔN, ∫ΔE, ∫Δh: x_Ip(k+1) = e^{−λ_p T_s} x_Ip(k) + T_s (p − p_t),
    /// with anti-windup per integrator: the update is skipped when its increment would push a
    /// saturated command further into its limit (conditional integration, through the
    /// integrator's gain column), the result is clamped to `position_integrator_limit`, and
    /// only finite values are committed.
    fn integrate_position(&mut self, x: &X, xt: &X, saturated: &[f64; NU]) {
        let ts = self.mission.sample_time;
        let lim = self.params.position_integrator_limit;
        let decay = (-self.params.position_integrator_leak * ts).exp();
        for j in 0..3 {
            if !self.position_integral_on(j) {
                continue;
            }
            let old = self.pos_integrator[j];
            let next = (decay * old + ts * (x[ix::N + j] - xt[ix::N + j])).clamp(-lim, lim);
            let delta = next - old;
            // Command change caused by this increment: −K[:, I_POS + j] · delta.
            let winds_up =
                (0..NU).any(|i| saturated[i] != 0.0 && -self.gain[(i, I_POS + j)] * delta * saturated[i] > 0.0);
            if next.is_finite() && !winds_up {
                self.pos_integrator[j] = next;
            }
        }
    }

    /// The reference point of a take-off / landing reference (flight_mission::ground): the
    /// mission's vertical attitude (nose up, belly north) and rates, the position relative
    /// to the origin, airspeed |v|, and the vertical trim inputs with the thrust
    /// `T = m (g + a_up) + (T_trim − m g) · climb/V_V` (weight, the reference acceleration and
    /// the trim's drag scaled with the climb rate).
    fn ground_point(&self, v: &VerticalReference) -> TrajPoint {
        let mut p = self.trajectory.at(f64::NEG_INFINITY);
        let af = &self.airframe;
        let w = af.mass * af.gravity;
        let climb = -v.vel.z;
        let thrust = w + af.mass * (-v.accel.z) + (p.u[0] - w) * (climb / self.mission.v_vertical).clamp(-1.0, 1.0);
        let o = self.origin.unwrap_or_else(Vector3::zeros);
        p.v = v.vel.norm();
        p.pos_neh = Vector3::new(v.pos.x, v.pos.y, -v.pos.z) - o;
        p.thrust = thrust;
        p.u[0] = thrust;
        p
    }

    /// Air data in the take-off and landing phases: near hover V, α, β are undefined (α
    /// jumps to π in the tail-first descent), so x and x_t carry the body air velocity
    /// `v_a = V (cα cβ, sβ, sα cβ)` as `(u_a, w_a/V_e, v_a/V_e)` in place of `(V, α, β)`, the
    /// reference's from `DCM_t (v_ref − ŵ)`, with `V_e = max(u_a,t, 1 m/s)`: to first order
    /// the model's (V, α, β) at α = β = 0 and V = V_e, where `solve_gain` linearises (the same
    /// 1 m/s floor), and continuous through V = 0 and reversed flow.
    fn hover_air_data(
        &self,
        m: &flight_mission::Measurement,
        v: &VerticalReference,
        reference: &TrajPoint,
        x: &mut X,
        xt: &mut X,
    ) {
        let (sa, ca) = m.alpha.sin_cos();
        let (sb, cb) = m.beta.sin_cos();
        let va = m.airspeed * Vector3::new(ca * cb, sb, sa * cb);
        let wind = if self.wind.iter().all(|w| w.is_finite()) {
            self.wind
        } else {
            Vector3::zeros()
        };
        let vat = model::dcm_of_quat(&reference.quat()) * (v.vel - wind);
        let ve = vat.x.max(1.0);
        x[ix::V] = va.x;
        x[ix::ALPHA] = va.z / ve;
        x[ix::BETA] = va.y / ve;
        xt[ix::V] = vat.x;
        xt[ix::ALPHA] = vat.z / ve;
        xt[ix::BETA] = vat.y / ve;
    }

    /// Append the controller's state (everything `sample` depends on besides its
    /// construction parameters) as f64s.
    pub fn save(&self, out: &mut impl FnMut(f64)) {
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

    /// Restore what [`Self::save`] wrote; `None` from `next` = truncated state.
    pub fn restore(&mut self, next: &mut impl FnMut() -> Option<f64>) -> Result<(), ControlError> {
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
        Ok(())
    }
}

/// Everything an [`LqrController`] is built from: the FMU's parameters.
#[derive(Debug, Clone, PartialEq)]
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
            airframe: Airframe::default(),
            mission,
            params: LqrParams::default(),
            weights_file: String::new(),
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

    fn save(&self, out: &mut impl FnMut(f64)) {
        Self::save(self, out)
    }

    fn restore(&mut self, next: &mut impl FnMut() -> Option<f64>) -> Result<(), ControlError> {
        Self::restore(self, next)
    }

    fn sample(&mut self, input: &ControllerInput) -> Result<ControllerOutput, ControlError> {
        let m = &input.measurement;
        if let Some(name) = m.first_non_finite() {
            return Err(ControlError(format!("measurement {name} is not finite")));
        }
        if !input.t.is_finite() {
            return Err(ControlError(format!("sample time t = {} is not finite", input.t)));
        }
        // Take-off and landing around the mission (flight_mission::ground): the mission time
        // t is the FMU time less the spin-up and take-off climb (the same without take-off).
        let t = input.t - self.ground.mission_start();
        let measured_neh = Vector3::new(m.pos_ned.x, m.pos_ned.y, -m.pos_ned.z);
        let (trajectory, lqr_origin) = (&self.trajectory, self.origin);
        let mode = self.ground.step(input.t, m, |tm| {
            let p = trajectory.at(tm);
            let o = lqr_origin.unwrap_or(measured_neh);
            let off = &input.ref_offset_ned;
            let (sg, cg) = p.gamma.sin_cos();
            let (sp, cp) = p.euler_321.z.sin_cos();
            let pos = o + p.pos_neh + Vector3::new(off.x, off.y, -off.z);
            (
                Vector3::new(pos.x, pos.y, -pos.z),
                p.v * Vector3::new(cg * cp, cg * sp, -sg),
            )
        });
        let (offset, ground_ref) = match mode {
            GroundMode::Mission { offset, .. } => (offset, None),
            GroundMode::Vertical(v) => (Vector3::zeros(), Some(v)),
            GroundMode::Idle { phase, thrust } => {
                // On the gear: no gain computation, no integration (no wind-up).
                let af = &self.airframe;
                return Ok(ControllerOutput {
                    command: Command {
                        thrust: thrust.clamp(af.thrust_min, af.thrust_max),
                        ..Command::default()
                    },
                    diagnostics: Diagnostics {
                        ref_pos_ned: m.pos_ned,
                        ref_airspeed: 0.0,
                        phase,
                        pos_error: 0.0,
                    },
                    notice: None,
                });
            }
        };
        if self.origin.is_none() && self.ground.takeoff() {
            // Mission origin: the take-off point (measured on the gear); gains relinearised
            // from the first flying sample.
            let o = self.ground.origin().unwrap_or(m.pos_ned);
            self.origin = Some(Vector3::new(o.x, o.y, -o.z));
            self.next_relinearisation = f64::NEG_INFINITY;
        }
        if ground_ref.is_some() != self.ground_active {
            // Into or out of the take-off / landing phases: the gains change structure (the
            // position integrators' columns); relinearise now, integrators from zero.
            self.ground_active = ground_ref.is_some();
            self.next_relinearisation = f64::NEG_INFINITY;
            if self.params.position_integral == 0 {
                self.pos_integrator = Vector3::zeros();
            }
        }
        // Heading reference in vertical flight (README, "Weathervaning"); the take-off and
        // landing phases keep their own vertical reference.
        let heading = self.weathervane.update(&self.mission, t, m);
        let reference = match &ground_ref {
            Some(v) => self.ground_point(v),
            None => self.trajectory.at(t).turned(&heading),
        };
        let off = &(input.ref_offset_ned + offset);
        let phase = self.mission.phase_at(t).0 as i32;
        if ground_ref.is_none() && self.params.reanchors() && self.origin.is_some() && phase != self.anchored_phase {
            // §3.5.1: each new trajectory starts at the current position, so the reference
            // position equals the measured one at the first sample of the segment.
            self.origin = Some(measured_neh - reference.pos_neh - Vector3::new(off.x, off.y, -off.z));
        }
        if ground_ref.is_none() {
            self.anchored_phase = phase;
        }
        let origin = *self.origin.get_or_insert(measured_neh);
        // Reference position: start + trajectory + offset, as (N, E, h); in the take-off and
        // landing phases the vertical reference (NED, origin included) + offset.
        let ref_neh = match &ground_ref {
            Some(v) => Vector3::new(v.pos.x + off.x, v.pos.y + off.y, -(v.pos.z + off.z)),
            None => origin + reference.pos_neh + Vector3::new(off.x, off.y, -off.z),
        };
        let rep = self.rep_for(&reference);
        // Vertical flight in wind: where the weathervane may turn (`Weathervane::free`), it
        // is engaged (a filtered horizontal wind ≥ its engage speed) or, before the filter has caught up with a sudden wind, measured air
        // angles beyond [`HOVER_WIND_AIR_ANGLE`] with an unfiltered air-data wind ≥ the engage
        // speed (in still air the climb's air comes from the nose, α, β ≈ 0, and the air-data
        // wind is zero). Tuned configuration only (the thesis's has no weathervane).
        let in_wind = ground_ref.is_none()
            && self.params.configuration == 0
            && self.weathervane.free(&self.mission, t)
            && (self.weathervane.engaged()
                || (m.alpha.abs() > HOVER_WIND_AIR_ANGLE || m.beta.abs() > HOVER_WIND_AIR_ANGLE)
                    && guidance::weathervane::air_data_wind(m).xy().norm() >= self.weathervane.params().engage_speed);
        // Integral action on the horizontal position in wind (README, "Hover in wind"): the
        // position the gains regulate to is the reference moved against the integrated error,
        // s ← s + T_s/τ_s (p − p_ref), regulated to p_ref − s, so the steady error of a
        // steady wind vanishes; out of wind s decays with τ_s, and in still air it stays 0.
        {
            let ts = self.mission.sample_time;
            let e = Vector3::new(measured_neh.x - ref_neh.x, measured_neh.y - ref_neh.y, 0.0);
            let next = if in_wind {
                let mut s = self.wind_shift + e * (ts / HOVER_SHIFT_TIME);
                let n = s.norm();
                if n > HOVER_SHIFT_LIMIT {
                    s *= HOVER_SHIFT_LIMIT / n;
                }
                s
            } else if self.wind_shift != Vector3::zeros() {
                let s = self.wind_shift * (-ts / HOVER_SHIFT_TIME).exp();
                if s.norm() < 1e-6 {
                    Vector3::zeros()
                } else {
                    s
                }
            } else {
                self.wind_shift
            };
            if next.iter().all(|v| v.is_finite()) {
                self.wind_shift = next;
            }
        }
        let ctrl_neh = ref_neh - self.wind_shift;

        self.estimate_wind(m);
        let reference = match ground_ref {
            None => self.trimmed(&reference).unwrap_or(reference),
            Some(_) => reference,
        };
        let mut x = state_of(
            rep, m.airspeed, m.alpha, m.beta, &m.rates, &m.quat, &m.pos_ned, m.thrust,
        );
        let mut xt = reference.state(rep);
        xt[ix::N] = ctrl_neh.x;
        xt[ix::E] = ctrl_neh.y;
        xt[ix::H] = ctrl_neh.z;
        let air_ref = self.air_reference(&reference);
        xt[ix::V] = air_ref.x;
        xt[ix::ALPHA] = air_ref.y;
        xt[ix::BETA] = air_ref.z;
        if let Some(v) = &ground_ref {
            self.hover_air_data(m, v, &reference, &mut x, &mut xt);
        }

        let mut notice = None;
        let due = t + 1e-9 >= self.next_relinearisation;
        if !self.have_gain || rep != self.rep || due {
            // Relinearise about the current estimated state with the trajectory's inputs
            // (§3.1.3, 3.2.7–3.2.9); positions do not enter the model.
            // Hover in wind (README, "Hover in wind"): relinearise about the reference (the
            // weathervaned vertical attitude with the wind-consistent air data) rather than
            // the measured state, whose tilt into the wind and α, β of 30–90° put the linear
            // model far outside its range (gains that over-tilted and lost the aircraft
            // from 7 m/s). In still air the weathervane is never engaged: unchanged.
            // After the back transition (vertical 2, before the weathervane is free) a wind
            // across the slowing climb shows as air angles of 30–70° too: relinearise about the
            // reference there as well (README, "Gusts"; about the measured β of −66° the gains
            // of a 5 m/s east gust cut the thrust to zero and then saturated it: 2.15 m added
            // under Jacobi, 1.71 m now).
            let lin_ref = in_wind
                || ground_ref.is_none()
                    && self.params.configuration == 0
                    && self.mission.phase_at(t).0 == flight_mission::Phase::Vertical2
                    && (m.alpha.abs() > HOVER_WIND_AIR_ANGLE || m.beta.abs() > HOVER_WIND_AIR_ANGLE)
                    && guidance::weathervane::air_data_wind(m).xy().norm() >= self.weathervane.params().engage_speed;
            let mut x_lin = if lin_ref { xt } else { x };
            // In the take-off and landing phases linearise at α = β = 0: x carries the body
            // air velocity there (`hover_air_data`), exact at α = β = 0 for any w/V_e.
            if ground_ref.is_some() {
                x_lin[ix::ALPHA] = 0.0;
                x_lin[ix::BETA] = 0.0;
            }
            // Warm start: the previous solutions in the same Euler set, extrapolated (quadratic
            // through the last three, linear through two, else the last).
            let warm = if rep == self.rep {
                self.warm_p.map(|p1| match self.warm_len {
                    0 => p1,
                    1 => p1 * 2.0 - self.warm_hist[0],
                    _ => p1 * 3.0 - self.warm_hist[0] * 3.0 + self.warm_hist[1],
                })
            } else {
                // A P of the other Euler set is no start (nor history) for this one.
                self.warm_p = None;
                self.warm_len = 0;
                None
            };
            match self.solve_gain_warm(rep, &x_lin, &reference.u, t, warm.as_ref()) {
                Ok(sol) => {
                    if sol.warm {
                        self.stats.warm_solves += 1;
                        if self.verify_warm {
                            if let Ok(cold) = self.solve_gain(rep, &x_lin, &reference.u, t) {
                                let e = (sol.gain - cold.gain).amax() / cold.gain.amax();
                                self.stats.warm_max_gain_error = self.stats.warm_max_gain_error.max(e);
                            } else {
                                self.stats.warm_max_gain_error = f64::INFINITY;
                            }
                        }
                    }
                    self.gain = sol.gain;
                    self.have_gain = true;
                    self.stats.last_spectral_radius = sol.spectral_radius;
                    if let (Some(_), Some(old)) = (sol.p, self.warm_p) {
                        self.warm_hist[1] = self.warm_hist[0];
                        self.warm_hist[0] = old;
                        self.warm_len = (self.warm_len + 1).min(2);
                    } else {
                        self.warm_len = 0;
                    }
                    self.warm_p = sol.p;
                }
                Err(e) => {
                    self.stats.fallbacks += 1;
                    notice = Some(Notice::GainFallback(e.describe()));
                    if rep != self.rep {
                        // The old gains belong to the other Euler set: they cannot be reused
                        // on this state vector. Keep the old representation until a solve succeeds.
                        x = state_of(
                            self.rep, m.airspeed, m.alpha, m.beta, &m.rates, &m.quat, &m.pos_ned, m.thrust,
                        );
                        xt = reference.state(self.rep);
                        xt[ix::N] = ctrl_neh.x;
                        xt[ix::E] = ctrl_neh.y;
                        xt[ix::H] = ctrl_neh.z;
                        xt[ix::V] = air_ref.x;
                        xt[ix::ALPHA] = air_ref.y;
                        xt[ix::BETA] = air_ref.z;
                        if let Some(v) = &ground_ref {
                            self.hover_air_data(m, v, &reference, &mut x, &mut xt);
                        }
                    }
                }
            }
            if notice.is_none() {
                self.rep = rep;
            }
            self.stats.solves += 1;
            if due {
                self.next_relinearisation = t + self.params.relinearisation_period;
            }
        }

        let mut dx = SVector::<f64, NA>::zeros();
        dx[0] = self.integrator;
        for j in 0..3 {
            dx[I_POS + j] = self.pos_integrator[j];
        }
        for i in 0..NX {
            let d = x[i] - xt[i];
            dx[1 + i] = if (ix::PHI..=ix::PSI).contains(&i) {
                wrap_pi(d)
            } else {
                d
            };
        }
        let mut u = reference.u - self.gain * dx;
        // Limits of the plant: thrust range, deflection limit.
        let af = &self.airframe;
        let mut thrust_saturated = 0.0;
        // Direction (+1 above the upper limit, −1 below the lower, 0 inside) per command.
        let mut saturated = [0.0f64; NU];
        for i in 0..NU {
            let (lo, hi) = if i == 0 {
                (af.thrust_min, af.thrust_max)
            } else {
                (-af.deflection_limit, af.deflection_limit)
            };
            if u[i] < lo || u[i] > hi {
                saturated[i] = if u[i] > hi { 1.0 } else { -1.0 };
                if i == 0 {
                    thrust_saturated = saturated[i];
                }
                u[i] = u[i].clamp(lo, hi);
                if notice.is_none() {
                    notice = Some(Notice::Saturated(COMMAND_NAMES[i]));
                }
            }
        }
        if !u.iter().all(|v| v.is_finite()) {
            return Err(ControlError(format!("non-finite command at t = {t}")));
        }
        // Integrator x_I(k+1) = x_I(k) + T_s (V − V_t) (3.2.12–3.2.14), with anti-windup:
        // not integrated further into a thrust limit, and bounded.
        let dv = x[ix::V] - xt[ix::V];
        // Negative airspeed error asks for more thrust (K row of T_c on x_I is negative).
        let pushes_up = dv < 0.0;
        if !(thrust_saturated > 0.0 && pushes_up || thrust_saturated < 0.0 && !pushes_up) {
            let lim = self.params.integrator_limit;
            let ts = self.mission.sample_time;
            let decay = (-self.params.integrator_leak * ts).exp();
            let next = (decay * self.integrator + ts * dv).clamp(-lim, lim);
            if next.is_finite() {
                self.integrator = next;
            }
        }
        if self.has_position_integral() {
            self.integrate_position(&x, &xt, &saturated);
        }

        let pos = Vector3::new(m.pos_ned.x, m.pos_ned.y, -m.pos_ned.z);
        let diagnostics = Diagnostics {
            ref_pos_ned: Vector3::new(ref_neh.x, ref_neh.y, -ref_neh.z),
            ref_airspeed: reference.v,
            phase: ground_ref.map_or(self.mission.phase_at(t).0, |v| v.phase),
            pos_error: flight_mission::distance(&pos, &ref_neh),
        };
        let command = Command::from_array(u.into());
        Ok(ControllerOutput {
            command,
            diagnostics,
            notice,
        })
    }
}

#[cfg(test)]
mod wind_trim_tests {
    use super::*;

    /// Earth-frame force (N) and pitching moment (N m) of the model for control at reference
    /// point `p` in the wind `w`, its ground velocity being that of (V_t, α_t, attitude).
    fn loads(af: &Airframe, p: &TrajPoint, w: &Vector3<f64>) -> (Vector3<f64>, f64) {
        let c = model::dcm_of_quat(&p.quat());
        let v_g = c.transpose() * model::body_velocity(p.v, p.alpha, 0.0);
        let s = Surfaces::from_array([p.u[1], p.u[2], p.u[3], p.u[4], p.u[5], p.u[6]]);
        let fm = af.forces_moments(&(c * (v_g - w)), &p.rates, p.thrust, &s);
        (c.transpose() * fm.force_body, fm.moment_body.y)
    }

    fn controller() -> LqrController {
        LqrController::new(Airframe::default(), MissionParams::default(), LqrParams::default()).unwrap()
    }

    /// The trimmed level-flight reference in a steady 5 m/s tail- or headwind has the
    /// still-air reference's force and pitching moment (the same ground-path acceleration and
    /// q̇, 2.2.19–2.2.24) at the same ground velocity; a tailwind lowers the dynamic pressure,
    /// so it pitches up to a larger α (lift ∝ V̄² α), a headwind the other way.
    #[test]
    fn level_flight_trim_keeps_force_and_moment() {
        let mut c = controller();
        let af = Airframe::default();
        let p = c.trajectory().at(15.0);
        let (f_still, m_still) = loads(&af, &p, &Vector3::zeros());
        for sign in [1.0, -1.0] {
            let w = Vector3::new(5.0 * sign, 0.0, 0.0);
            c.wind = w;
            c.wind_rate = Vector3::zeros();
            let q = c.trimmed(&p).expect("trim converges");
            let (f, m) = loads(&af, &q, &w);
            assert!(
                (f - f_still).norm() < 1e-5 * af.mass * af.gravity,
                "{sign}: {f} vs {f_still}"
            );
            assert!((m - m_still).abs() < 1e-6, "{sign}: {m} vs {m_still}");
            let dtheta = q.euler_321.y - p.euler_321.y;
            let alpha_air = c.air_reference(&q).y;
            assert!(
                sign * dtheta > 0.0 && sign * (alpha_air - p.alpha) > 0.0,
                "{sign}: δ {dtheta}, α {alpha_air}"
            );
            // Without a wind rate the reference gains no pitch rate.
            assert_eq!(q.rates, p.rates);
        }
    }

    /// In still air, in an estimated wind below the ramp (what an estimator makes of still
    /// air) and without wind compensation the reference is not touched, so the still-air
    /// flights are bit-identical to the untrimmed controller's.
    #[test]
    fn no_trim_in_still_air_or_without_compensation() {
        let mut c = controller();
        let p = c.trajectory().at(15.0);
        c.wind_rate = Vector3::zeros();
        for w in [0.0, 0.99 * WIND_TRIM_RAMP.0] {
            c.wind = Vector3::new(w, 0.0, 0.0);
            assert!(c.trimmed(&p).is_none(), "{w}");
        }
        let mut t = LqrController::new(
            Airframe::default(),
            MissionParams::default(),
            LqrParams {
                configuration: 1,
                ..Default::default()
            },
        )
        .unwrap();
        t.wind = Vector3::new(5.0, 0.0, 0.0);
        assert!(t.trimmed(&p).is_none());
    }
}
