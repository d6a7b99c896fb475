//! Take-off-to-landing mission (issue 16): both controllers start at rest on the gear
//! (plant `initial_condition = 2`), spin up, take off, fly the thesis's mission (both
//! transitions) and land on a target point ([`guidance::ground`]), on the global
//! aerodynamic model (the plant FMU's default) with the ground plane, Gauss-Seidel and
//! Jacobi. Writes the key `takeoff_landing` of `report.json` (rendered by
//! `python/tailsim/report_takeoff.py`).
//!
//! Touchdown figures, from the plant's contact model ([`tailsitter_physics::ContactState`]):
//! * touchdown speed: the larger of the largest downward speed of a gear point in contact
//!   at the first communication point with contact after the flight (as the plant FMU's
//!   `touchdown_speed` output) and the CG's sink rate at the point before;
//! * miss distance: horizontal distance of the CG from the target at touchdown and at rest;
//! * attitude: tilt of the body x axis from the vertical at touchdown and at the end;
//! * bounce: any communication point without contact after the touchdown, and the largest
//!   rise of the CG above its touchdown height.

use closed_loop::{fly, Ordering, Scenario, Trace, N_PHASES};
use flight_mission::{MissionParams, Phase, SampledUnit};
use guidance::GroundPhases;
use nalgebra::Vector3;
use serde::Serialize;
use tailsitter_physics::{dcm_earth_to_body, idx, AeroModel, Airframe, Ground, Plant, StateVector};

use crate::controllers::{AnyController, Kind};

/// Touchdown criteria of issue 16.
pub const MAX_TOUCHDOWN_SPEED: f64 = 0.5;
/// Largest miss distance from the target (m).
pub const MAX_MISS_DISTANCE: f64 = 0.5;
/// Largest tilt from the vertical to count as upright (deg).
pub const MAX_TILT_DEG: f64 = 10.0;
/// Time flown after the touchdown is declared (s): the aircraft must stay down and upright.
pub const AFTER_LANDING: f64 = 5.0;

/// The report's take-off-to-landing mission: the thesis's timings (5 s vertical,
/// T1 = 5 s, 10 s level, T2 = 10 s, 5 s vertical), a 2 s spin-up and a 2 s take-off climb,
/// the landing target 460 m north of the take-off point (12 m beyond where the α-limited
/// flight path of both controllers ends, 448 m north and 221 m up: both reposition forwards
/// along the belly axis; moving back by 8–48 m — targets at 440 and 400 m — lost the TSD
/// under Jacobi, α −40…−90° in the backward translation), a 2 m/s
/// descent tail first, a flare from 1.5 m to 0.3 m/s.
pub fn mission() -> MissionParams {
    MissionParams {
        takeoff_spinup_time: 2.0,
        takeoff_time: 2.0,
        landing_descent_rate: 2.0,
        landing_target_n: 460.0,
        landing_target_e: 0.0,
        landing_target_d: 0.0,
        landing_approach_speed: 3.0,
        ..MissionParams::default()
    }
}

/// The plant: nominal airframe, global aerodynamics, the FMU's default ground (10 m below
/// the origin), at rest on the gear at (0, 0) heading north.
pub fn plant() -> (Plant, StateVector) {
    let mut plant = Plant::new(Airframe::default());
    plant.aero.model = AeroModel::Global;
    plant.ground = Ground::default();
    let x0 = plant.resting_on_ground(0.0, 0.0, 0.0);
    (plant, x0)
}

/// Upper bound of the flight time of `mission` from `x0` (s): take-off, the mission, an
/// approach over the longest plausible distance, the descent from the mission's peak and the
/// touchdown reference's search below the target (a touchdown not where the height estimate
/// puts the ground).
pub fn stop_time(mission: &MissionParams) -> f64 {
    let g = GroundPhases::new(*mission, 1.0);
    let climb = 400.0;
    let approach =
        1.5 * (mission.landing_target_n.hypot(mission.landing_target_e) + 50.0) / mission.landing_approach_speed;
    use guidance::ground::{TOUCHDOWN_HOLD_TIME, TOUCHDOWN_SEARCH_DEPTH, TOUCHDOWN_SEARCH_RATE};
    let search =
        TOUCHDOWN_HOLD_TIME + TOUCHDOWN_SEARCH_DEPTH / (TOUCHDOWN_SEARCH_RATE * mission.landing_touchdown_rate);
    g.mission_start() + mission.end_time() + approach + climb / mission.landing_descent_rate + search + 20.0
}

/// Per-phase position errors.
#[derive(Debug, Clone, Serialize)]
pub struct PhaseError {
    pub phase: i32,
    pub name: &'static str,
    /// Max |position − reference| (m).
    pub max: f64,
    /// RMS (m).
    pub rms: f64,
    /// Duration in the phase (s).
    pub duration: f64,
}

/// What one flight measured.
#[derive(Debug, Clone, Serialize)]
pub struct Flight {
    pub controller: &'static str,
    pub ordering: &'static str,
    /// Why the run stopped early, if it did.
    pub failure: Option<String>,
    /// First communication point with the aircraft off the gear (s).
    pub liftoff_time: Option<f64>,
    /// Largest tilt on the gear before lift-off (deg).
    pub ground_tilt_deg: f64,
    /// Touchdown: first contact once the flight was under way ([`flying`]) (s).
    pub touchdown_time: Option<f64>,
    /// Phase-10 (landed, thrust cut) latched at (s).
    pub landed_time: Option<f64>,
    /// Downward speed of the gear at touchdown (m/s).
    pub touchdown_speed: f64,
    /// Vertical speed of the CG at the last communication point before contact (m/s).
    pub touchdown_cg_sink: f64,
    /// Horizontal distance from the target at touchdown (m).
    pub miss_touchdown: f64,
    /// Horizontal distance from the target at the end (m).
    pub miss_final: f64,
    /// Tilt from the vertical at touchdown (deg).
    pub tilt_touchdown_deg: f64,
    /// Tilt from the vertical at the end (deg).
    pub tilt_final_deg: f64,
    /// Horizontal speed of the CG at touchdown (m/s).
    pub horizontal_speed_touchdown: f64,
    /// Left the ground again after the touchdown.
    pub bounced: bool,
    /// Largest rise of the CG above its touchdown height after the touchdown (m).
    pub rebound_height: f64,
    /// Max angle of attack in forward flight (phases 1–3) (deg).
    pub max_alpha_transitions_deg: f64,
    /// Max position error over the flight, up to the touchdown (m).
    pub max_pos_error: f64,
    pub phases: Vec<PhaseError>,
    /// The landing target (NED, m).
    pub target: [f64; 3],
    /// Every criterion met: landed, touchdown speed, miss distance, upright, no bounce.
    pub passed: bool,
    /// Decimated trajectory for the plot: t, N, E, D, ref N, ref E, ref D, phase, tilt (deg), thrust command.
    pub trajectory: Vec<[f64; 10]>,
}

/// Name of a phase code.
pub fn phase_name(code: i32) -> &'static str {
    match Phase::from_code(code) {
        Some(Phase::Vertical1) => "vertical 1",
        Some(Phase::TransitionToLevel) => "transition 1",
        Some(Phase::Level) => "level",
        Some(Phase::TransitionToVertical) => "transition 2",
        Some(Phase::Vertical2) => "vertical 2",
        Some(Phase::OnGround) => "on ground",
        Some(Phase::TakeOff) => "take-off",
        Some(Phase::Approach) => "approach",
        Some(Phase::Descent) => "descent",
        Some(Phase::Flare) => "flare",
        Some(Phase::Landed) => "landed",
        None => "?",
    }
}

/// Tilt of the body x axis from the vertical (rad).
pub fn tilt(x: &StateVector) -> f64 {
    let c = dcm_earth_to_body(&x.fixed_rows::<4>(idx::Q1).into_owned());
    let nose = c.transpose() * Vector3::x();
    (-nose.z).clamp(-1.0, 1.0).acos()
}

/// The landing's first ground contact (in the flare or landed, so not a take-off bounce).
pub fn first_landing_contact<'a>(plant: &Plant, trace: &'a Trace) -> Option<&'a closed_loop::Sample> {
    trace.samples.iter().find(|s| {
        matches!(s.diagnostics.phase, Phase::Flare | Phase::Landed)
            && plant
                .outputs(&s.x, &closed_loop::plant_inputs(&s.command), &s.wind)
                .ground
                .points
                > 0
    })
}

/// A stop condition for [`closed_loop::fly_with`]: true from [`AFTER_LANDING`] after the
/// first sample in [`Phase::Landed`].
pub fn after_landing() -> impl FnMut(&closed_loop::Sample) -> bool {
    let mut landed: Option<f64> = None;
    move |s| {
        if landed.is_none() && s.diagnostics.phase == Phase::Landed {
            landed = Some(s.t);
        }
        landed.is_some_and(|t| s.t >= t + AFTER_LANDING - 1e-9)
    }
}

/// One take-off-to-landing cell of the wind envelope flown as [`crate::wind_envelope`] flies
/// it (its plant, wind and turbulence seed; `kind` tuned), stopped [`AFTER_LANDING`] after
/// the landing: the plant and the trace.
pub fn fly_wind_cell(
    kind: Kind,
    form: crate::wind_envelope::WindForm,
    state: crate::wind_envelope::StateKind,
    ordering: Ordering,
    speed: f64,
    bearing_index: usize,
) -> (Plant, Trace) {
    use crate::wind_envelope as env;
    let plant = env::plant();
    let m = mission();
    let x0 = plant.resting_on_ground(0.0, 0.0, 0.0);
    let mut scenario = Scenario::mission(m);
    scenario.stop_time = stop_time(&m);
    scenario.wind = env::wind(form, speed, bearing_index, plant.ground.height);
    scenario.ordering = ordering;
    let mut c = kind.make_configured(&m, 0).expect("the tuned controller builds");
    let u0 = tailsitter_physics::InputVector::zeros();
    let seed = env::seed(bearing_index);
    let trace = env::fly_on(&plant, x0, &u0, &mut c, &scenario, state, seed, after_landing());
    (plant, trace)
}

/// Fly `kind` through `mission` with `ordering`, stopping [`AFTER_LANDING`] after the landing.
pub fn fly_one(kind: Kind, ordering: Ordering, mission: &MissionParams) -> (Trace, Flight) {
    let (plant, x0) = plant();
    let mut controller = AnyController::build(&(kind, *mission)).expect("controller builds");
    let mut scenario = Scenario::mission(*mission);
    scenario.ordering = ordering;
    scenario.stop_time = stop_time(mission);
    let trace = fly_until_landed(&plant, x0, &mut controller, &scenario);
    let flight = evaluate(&plant, kind, ordering, mission, &trace);
    (trace, flight)
}

/// [`fly`] in pieces of 10 s until [`AFTER_LANDING`] after the landing or the stop time.
fn fly_until_landed(plant: &Plant, x0: StateVector, controller: &mut AnyController, scenario: &Scenario) -> Trace {
    // One run to the stop time is simplest; the closed loop has no early stop, so fly to
    // the bound and cut the trace after the landing.
    let mut trace = fly(plant, x0, controller, scenario);
    if let Some(k) = trace.samples.iter().position(|s| s.diagnostics.phase == Phase::Landed) {
        let t_end = trace.samples[k].t + AFTER_LANDING;
        trace.samples.retain(|s| s.t <= t_end + 1e-9);
    }
    trace
}

/// Height of the lowest contact point above the ground (m) from which the aircraft counts as
/// flying: a hop on the gear at take-off (lift-off, contact again below it) is not the
/// landing's touchdown.
pub const FLYING_CLEARANCE: f64 = 2.0;

/// Whether a sample after the lift-off shows the flight under way, so that the next ground
/// contact is the landing's touchdown: the gear at least [`FLYING_CLEARANCE`] clear of the
/// ground, or the controller already in the landing (approach, descent, flare, landed).
pub fn flying(phase: Phase, contact: &tailsitter_physics::ContactState) -> bool {
    contact.clearance >= FLYING_CLEARANCE
        || matches!(phase, Phase::Approach | Phase::Descent | Phase::Flare | Phase::Landed)
}

/// The figures of a flown trace.
pub fn evaluate(plant: &Plant, kind: Kind, ordering: Ordering, mission: &MissionParams, trace: &Trace) -> Flight {
    let origin = trace
        .samples
        .first()
        .map_or(Vector3::zeros(), |s| s.measurement.pos_ned);
    let target = origin
        + Vector3::new(
            mission.landing_target_n,
            mission.landing_target_e,
            mission.landing_target_d,
        );
    let contact = |s: &closed_loop::Sample| {
        plant
            .outputs(&s.x, &closed_loop::plant_inputs(&s.command), &s.wind)
            .ground
    };
    let mut liftoff = None;
    let mut touchdown: Option<usize> = None;
    let mut ground_tilt: f64 = 0.0;
    // A contact counts as the touchdown only once the flight is under way ([`flying`]): a
    // hop on the gear at take-off is not the landing.
    let mut under_way = false;
    for (k, s) in trace.samples.iter().enumerate() {
        let c = contact(s);
        if liftoff.is_none() {
            if c.points == 0 {
                liftoff = Some(k);
            } else {
                ground_tilt = ground_tilt.max(tilt(&s.x));
            }
        }
        if liftoff.is_some() {
            under_way |= flying(s.diagnostics.phase, &c);
            if under_way && c.points > 0 {
                touchdown = Some(k);
                break;
            }
        }
    }
    let end = trace.samples.last();
    let (mut speed, mut cg_sink, mut miss_td, mut tilt_td, mut hspeed) =
        (f64::NAN, f64::NAN, f64::NAN, f64::NAN, f64::NAN);
    let (mut bounced, mut rebound) = (false, 0.0f64);
    if let Some(k) = touchdown {
        let s = &trace.samples[k];
        cg_sink = trace.samples[k - 1].measurement.vel_ned.z;
        // The larger of the gear's sink at the first contact point and the CG's just before.
        speed = contact(s).sink_rate.max(cg_sink);
        miss_td = (s.measurement.pos_ned.xy() - target.xy()).norm();
        tilt_td = tilt(&s.x).to_degrees();
        hspeed = s.measurement.vel_ned.xy().norm();
        let z0 = s.measurement.pos_ned.z;
        for s in &trace.samples[k..] {
            bounced |= contact(s).points == 0;
            rebound = rebound.max(z0 - s.measurement.pos_ned.z);
        }
    }
    let miss_final = end.map_or(f64::NAN, |s| (s.measurement.pos_ned.xy() - target.xy()).norm());
    let tilt_final = end.map_or(f64::NAN, |s| tilt(&s.x).to_degrees());
    let landed_time = trace
        .samples
        .iter()
        .find(|s| s.diagnostics.phase == Phase::Landed)
        .map(|s| s.t);
    let flown = touchdown.map_or(trace.samples.len(), |k| k);
    let mut sums = [(0usize, 0.0f64, 0.0f64); N_PHASES];
    let mut max_alpha: f64 = 0.0;
    for s in &trace.samples[..flown] {
        let p = s.diagnostics.phase as usize;
        let e = s.pos_error();
        sums[p].0 += 1;
        sums[p].1 = sums[p].1.max(e);
        sums[p].2 += e * e;
        if (1..=3).contains(&p) {
            max_alpha = max_alpha.max(s.measurement.alpha.abs());
        }
    }
    let h = trace.samples.get(1).map_or(mission.sample_time, |s| s.t);
    let phases: Vec<PhaseError> = [5, 6, 0, 1, 2, 3, 4, 7, 8, 9]
        .iter()
        .filter(|&&p| sums[p].0 > 0)
        .map(|&p| PhaseError {
            phase: p as i32,
            name: phase_name(p as i32),
            max: sums[p].1,
            rms: (sums[p].2 / sums[p].0 as f64).sqrt(),
            duration: sums[p].0 as f64 * h,
        })
        .collect();
    // Position errors while flying (on the gear the reference is the measured position).
    let max_pos_error = phases.iter().map(|p| p.max).fold(0.0, f64::max);
    let step = (0.1 / h).round().max(1.0) as usize;
    let trajectory = trace
        .samples
        .iter()
        .step_by(step)
        .map(|s| {
            let m = &s.measurement;
            let r = &s.diagnostics.ref_pos_ned;
            [
                s.t,
                m.pos_ned.x,
                m.pos_ned.y,
                m.pos_ned.z,
                r.x,
                r.y,
                r.z,
                f64::from(s.diagnostics.phase.code()),
                tilt(&s.x).to_degrees(),
                s.command.thrust,
            ]
        })
        .collect();
    let passed = trace.completed()
        && landed_time.is_some()
        && speed < MAX_TOUCHDOWN_SPEED
        && miss_td < MAX_MISS_DISTANCE
        && miss_final < MAX_MISS_DISTANCE
        && tilt_td < MAX_TILT_DEG
        && tilt_final < MAX_TILT_DEG
        && !bounced;
    Flight {
        controller: kind.name(),
        ordering: match ordering {
            Ordering::GaussSeidel => "gauss-seidel",
            Ordering::Jacobi => "jacobi",
        },
        failure: trace.failure.clone(),
        liftoff_time: liftoff.map(|k| trace.samples[k].t),
        ground_tilt_deg: ground_tilt.to_degrees(),
        touchdown_time: touchdown.map(|k| trace.samples[k].t),
        landed_time,
        touchdown_speed: speed,
        touchdown_cg_sink: cg_sink,
        miss_touchdown: miss_td,
        miss_final,
        tilt_touchdown_deg: tilt_td,
        tilt_final_deg: tilt_final,
        horizontal_speed_touchdown: hspeed,
        bounced,
        rebound_height: rebound,
        max_alpha_transitions_deg: max_alpha.to_degrees(),
        max_pos_error,
        phases,
        target: [target.x, target.y, target.z],
        passed,
        trajectory,
    }
}

/// The `takeoff_landing` key of `report.json`: both controllers, both orderings.
#[derive(Debug, Clone, Serialize)]
pub struct Report {
    /// The mission's parameters (name, value).
    pub mission: Vec<(&'static str, f64)>,
    pub criteria: Criteria,
    pub flights: Vec<Flight>,
}

/// The touchdown criteria, stated in the report.
#[derive(Debug, Clone, Serialize)]
pub struct Criteria {
    pub max_touchdown_speed: f64,
    pub max_miss_distance: f64,
    pub max_tilt_deg: f64,
}

/// Fly every controller with both orderings (in parallel).
pub fn report(kinds: &[Kind]) -> Report {
    use rayon::prelude::*;
    let m = mission();
    let jobs: Vec<(Kind, Ordering)> = kinds
        .iter()
        .flat_map(|&k| [(k, Ordering::GaussSeidel), (k, Ordering::Jacobi)])
        .collect();
    let flights = jobs.par_iter().map(|&(k, o)| fly_one(k, o, &m).1).collect();
    Report {
        mission: m.named_values().to_vec(),
        criteria: Criteria {
            max_touchdown_speed: MAX_TOUCHDOWN_SPEED,
            max_miss_distance: MAX_MISS_DISTANCE,
            max_tilt_deg: MAX_TILT_DEG,
        },
        flights,
    }
}

/// The `takeoff_landing` value of `report.json`: the flights of the configured controllers
/// with the nonlinear sweeps (`cfg.robustness`), else null.
pub fn report_value(cfg: &crate::sweep::Config) -> serde_json::Value {
    if !cfg.robustness || cfg.controllers.is_empty() {
        return serde_json::Value::Null;
    }
    serde_json::to_value(report(&cfg.controllers)).unwrap_or(serde_json::Value::Null)
}
