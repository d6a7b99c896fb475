//! Wind envelope over whole missions: both tuned controllers (perfect state,
//! Gauss-Seidel) fly the default mission and the take-off-to-landing mission
//! ([`crate::takeoff_landing`]) in a steady horizontal wind of [`SPEEDS`] from the
//! [`BEARINGS_DEG`] (the mission heads north: 0° is a headwind in level flight, 90° wind
//! from the right), in two forms:
//!
//! * **step**: the wind steps in at [`STEP_TIME`] ([`Wind::step_from`]);
//! * **turbulent**: the wind is there from t = 0, from the atmosphere of the
//!   `tailsitter_atmosphere` FMU ([`Wind::Atmosphere`]: uniform profile, so the steady
//!   part equals the step's, plus moderate Dryden turbulence, seed 1 + the bearing's
//!   index, the same at every speed).
//!
//! The plant is the plant FMU's default: global aerodynamics and its ground 10 m below the
//! NED origin (the atmosphere's `origin_height`); the default mission starts in the
//! trimmed vertical climb at `v_vertical` at the origin, the take-off-to-landing mission at
//! rest on the gear. Per cell: completed (reached the stop time; for the landing mission:
//! landed, i.e. the controller's `landed` phase, within [`HELD_MAX_ERROR`] of the target),
//! the largest distance to the controller's own reference over the flight (on the gear the
//! reference is the measured position), the landing distance from the target at rest and
//! the touchdown speed. **Held** = completed and the largest distance below
//! [`HELD_MAX_ERROR`]. Writes `wind_envelope.json` and `wind_envelope.csv` into the output
//! folder; `tailsim.reports.wind_envelope` renders them.

use std::path::Path;
use std::time::Instant;

use closed_loop::{fly, wind_from, Ordering, Scenario, Trace, Wind};
use flight_mission::{MissionParams, Phase};
use rayon::prelude::*;
use serde::Serialize;
use tailsitter_physics::{idx, pitch_321, quat_from_euler_321, AeroModel, Airframe, Ground, Plant, StateVector};

use crate::controllers::{AnyController, Kind};
use crate::takeoff_landing;

/// Steady wind speeds (m/s).
pub const SPEEDS: [f64; 5] = [0.0, 3.0, 5.0, 8.0, 10.0];
/// Bearings the wind comes from (deg, clockwise from north, the mission's heading).
pub const BEARINGS_DEG: [f64; 8] = [0.0, 45.0, 90.0, 135.0, 180.0, 225.0, 270.0, 315.0];
/// When the step wind switches on (s).
pub const STEP_TIME: f64 = 2.0;
/// Largest distance to the reference of a held cell (m).
pub const HELD_MAX_ERROR: f64 = 3.0;
/// `turbulence_intensity` of the turbulent cases: moderate (W20 = 30 kt).
pub const TURBULENCE_INTENSITY: i32 = 2;

/// The two missions.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum MissionKind {
    /// The thesis's mission from the trimmed vertical climb.
    Default,
    /// Take-off, the mission, approach and landing ([`takeoff_landing::mission`]).
    TakeoffLanding,
    /// The handover from a long hover in wind to the transition: the default mission with
    /// a [`HANDOVER_VERTICAL`] s first vertical phase (room to weathervane and to turn back).
    Handover,
}

/// First vertical phase of the [`MissionKind::Handover`] mission (s).
pub const HANDOVER_VERTICAL: f64 = 20.0;

impl MissionKind {
    /// The mission flown: the declared defaults, with [`HANDOVER_VERTICAL`] for the
    /// handover, the take-off-to-landing mission for [`MissionKind::TakeoffLanding`].
    pub fn mission(self) -> MissionParams {
        match self {
            MissionKind::Default => MissionParams::default(),
            MissionKind::Handover => MissionParams {
                t_vertical_1: HANDOVER_VERTICAL,
                ..MissionParams::default()
            },
            MissionKind::TakeoffLanding => takeoff_landing::mission(),
        }
    }
}

/// The two wind forms.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum WindForm {
    /// Steady wind stepping in at [`STEP_TIME`].
    Step,
    /// Steady wind from t = 0 plus moderate Dryden turbulence (the atmosphere).
    Turbulent,
}

/// One cell of the envelope.
#[derive(Debug, Clone, Serialize)]
pub struct Cell {
    pub controller: &'static str,
    pub mission: MissionKind,
    pub wind: WindForm,
    /// Steady wind speed (m/s) and the bearing it comes from (deg).
    pub speed: f64,
    pub bearing_deg: f64,
    /// Reached the stop time (the landing mission: landed within [`HELD_MAX_ERROR`] of the target).
    pub completed: bool,
    /// Why the run stopped early, if it did.
    pub failure: Option<String>,
    /// Largest |position − reference| (m) (NaN: not finite).
    pub max_error: f64,
    /// Landing mission: horizontal distance from the target at the end (m), touchdown
    /// speed (m/s), every touchdown criterion of [`takeoff_landing`] met.
    pub landing_distance: Option<f64>,
    pub touchdown_speed: Option<f64>,
    pub landing_passed: Option<bool>,
    /// Completed and `max_error` < [`HELD_MAX_ERROR`].
    pub held: bool,
    /// Wall time of the run (s).
    pub wall_time_s: f64,
}

/// The plant FMU's default plant (global aerodynamics, default ground).
pub fn plant() -> Plant {
    let mut plant = Plant::new(Airframe::default());
    plant.aero.model = AeroModel::Global;
    plant.ground = Ground::default();
    plant
}

/// The plant FMU's start for `initial_condition = 0`: the trimmed vertical climb at
/// `speed`, re-oriented with heading 0 from its 3-2-1 pitch, at the origin.
pub fn trimmed_climb(plant: &Plant, speed: f64) -> Result<StateVector, String> {
    let trim = plant
        .trim_vertical_climb(speed)
        .map_err(|e| format!("vertical-climb trim at {speed} m/s: {e}"))?;
    Ok(at_origin_heading_0(trim.state))
}

/// As fmu-plant starts from a trim: `x` re-oriented with heading 0 from its 3-2-1 pitch
/// (from the DCM), at the origin.
pub fn at_origin_heading_0(mut x: StateVector) -> StateVector {
    let theta = pitch_321(&x.fixed_rows::<4>(idx::Q1).into_owned());
    x.fixed_rows_mut::<4>(idx::Q1)
        .copy_from(&quat_from_euler_321(0.0, theta, 0.0));
    x[idx::POS_N] = 0.0;
    x[idx::POS_E] = 0.0;
    x[idx::POS_D] = 0.0;
    x
}

/// The atmosphere of a turbulent case: uniform steady wind `speed` from `bearing_deg`,
/// moderate Dryden turbulence with `seed`, the ground `origin_height` below the origin.
pub fn atmosphere(speed: f64, bearing_deg: f64, seed: i32, origin_height: f64) -> atmosphere::Params {
    atmosphere::Params {
        wind_speed: speed,
        wind_from: bearing_deg.to_radians(),
        wind_profile: 0,
        origin_height,
        turbulence_model: 1,
        turbulence_intensity: TURBULENCE_INTENSITY,
        seed,
        ..atmosphere::Params::default()
    }
}

/// The wind of a cell.
pub fn wind(form: WindForm, speed: f64, bearing_index: usize, origin_height: f64) -> Wind {
    let bearing = BEARINGS_DEG[bearing_index];
    match form {
        WindForm::Step => Wind::Step {
            t_start: STEP_TIME,
            wind: wind_from(bearing.to_radians(), speed),
        },
        WindForm::Turbulent => Wind::Atmosphere(atmosphere(speed, bearing, 1 + bearing_index as i32, origin_height)),
    }
}

/// Largest |position − reference| of `trace` (m), NaN if any is not finite.
fn max_error(trace: &Trace) -> f64 {
    let mut m: f64 = 0.0;
    for s in &trace.samples {
        let e = s.pos_error();
        if !e.is_finite() {
            return f64::NAN;
        }
        m = m.max(e);
    }
    m
}

/// Fly one cell.
pub fn fly_cell(kind: Kind, mission_kind: MissionKind, form: WindForm, speed: f64, bearing_index: usize) -> Cell {
    fly_cell_phases(kind, mission_kind, form, speed, bearing_index, None).0
}

/// Largest |position − reference| per [`Phase`] code (m) of `trace`.
fn phase_max_errors(trace: &Trace) -> [f64; closed_loop::N_PHASES] {
    let mut out = [0.0; closed_loop::N_PHASES];
    for s in &trace.samples {
        let k = s.diagnostics.phase.code() as usize;
        out[k] = f64::max(out[k], s.pos_error());
    }
    out
}

/// Time history of a flight as CSV: t, phase, error, position and reference (NED), θ, wind.
fn trace_history(trace: &Trace) -> String {
    let mut out = String::from("t,phase,error,n,e,d,ref_n,ref_e,ref_d,theta,wind_n,wind_e,thrust,phi321,psi321,airspeed,alpha,beta,ref_airspeed,elevator,aileron,rudder,flap_c,flap_d,vflap\n");
    for s in &trace.samples {
        let (p, r) = (s.measurement.pos_ned, s.diagnostics.ref_pos_ned);
        out.push_str(&format!(
            "{:.2},{},{:.3},{:.3},{:.3},{:.3},{:.3},{:.3},{:.3},{:.4},{:.3},{:.3},{:.3}\n",
            s.t,
            s.diagnostics.phase.code(),
            s.pos_error(),
            p.x,
            p.y,
            p.z,
            r.x,
            r.y,
            r.z,
            s.theta,
            s.wind.x,
            s.wind.y,
            s.command.thrust
        ));
        let eul = tailsitter_physics::euler_321_from_quat(&s.measurement.quat);
        let m = &s.measurement;
        let c = &s.command;
        out.pop();
        out.push_str(&format!(
            ",{:.3},{:.3},{:.3},{:.3},{:.3},{:.3},{:.3},{:.3},{:.3},{:.3},{:.3},{:.3}\n",
            eul.x,
            eul.z,
            m.airspeed,
            m.alpha,
            m.beta,
            s.diagnostics.ref_airspeed,
            c.elevator,
            c.aileron,
            c.rudder,
            c.flap_collective,
            c.flap_differential,
            c.vertical_flap
        ));
    }
    out
}

/// Fly one cell; also the largest error per phase code, and with `history` the time
/// history written there ([`trace_history`]).
pub fn fly_cell_phases(
    kind: Kind,
    mission_kind: MissionKind,
    form: WindForm,
    speed: f64,
    bearing_index: usize,
    history: Option<&str>,
) -> (Cell, [f64; closed_loop::N_PHASES]) {
    let mut phases = [0.0; closed_loop::N_PHASES];
    let mut record = |trace: &Trace| {
        phases = phase_max_errors(trace);
        if let Some(path) = history {
            let _ = std::fs::write(path, trace_history(trace));
        }
    };
    let start = Instant::now();
    let plant = plant();
    let w = wind(form, speed, bearing_index, plant.ground.height);
    let mut cell = Cell {
        controller: kind.name(),
        mission: mission_kind,
        wind: form,
        speed,
        bearing_deg: BEARINGS_DEG[bearing_index],
        completed: false,
        failure: None,
        max_error: f64::NAN,
        landing_distance: None,
        touchdown_speed: None,
        landing_passed: None,
        held: false,
        wall_time_s: 0.0,
    };
    match mission_kind {
        MissionKind::Default | MissionKind::Handover => {
            let mission = mission_kind.mission();
            match trimmed_climb(&plant, mission.v_vertical) {
                Err(e) => cell.failure = Some(e),
                Ok(x0) => {
                    let mut scenario = Scenario::mission(mission);
                    scenario.wind = w;
                    let mut c = kind.make(&mission);
                    let trace = fly(&plant, x0, &mut c, &scenario);
                    record(&trace);
                    cell.completed = trace.completed();
                    cell.failure = trace.failure.clone();
                    cell.max_error = max_error(&trace);
                }
            }
        }
        MissionKind::TakeoffLanding => {
            let mission = takeoff_landing::mission();
            let x0 = plant.resting_on_ground(0.0, 0.0, 0.0);
            let mut scenario = Scenario::mission(mission);
            scenario.stop_time = takeoff_landing::stop_time(&mission);
            scenario.wind = w;
            let mut c: AnyController = kind.make(&mission);
            let mut trace = fly(&plant, x0, &mut c, &scenario);
            if let Some(k) = trace.samples.iter().position(|s| s.diagnostics.phase == Phase::Landed) {
                let t_end = trace.samples[k].t + takeoff_landing::AFTER_LANDING;
                trace.samples.retain(|s| s.t <= t_end + 1e-9);
            }
            record(&trace);
            let flight = takeoff_landing::evaluate(&plant, kind, Ordering::GaussSeidel, &mission, &trace);
            let at_target = flight.miss_final < HELD_MAX_ERROR;
            cell.completed = trace.completed() && flight.landed_time.is_some() && at_target;
            cell.failure = trace.failure.clone().or_else(|| {
                if flight.landed_time.is_none() {
                    Some("did not land by the stop time".to_string())
                } else {
                    (!at_target).then(|| format!("landed {:.1} m from the target", flight.miss_final))
                }
            });
            cell.max_error = max_error(&trace);
            cell.landing_distance = Some(flight.miss_final);
            cell.touchdown_speed = Some(flight.touchdown_speed);
            cell.landing_passed = Some(flight.passed);
        }
    }
    cell.held = cell.completed && cell.max_error < HELD_MAX_ERROR;
    cell.wall_time_s = start.elapsed().as_secs_f64();
    (cell, phases)
}

/// Every cell of `missions` × both wind forms × `kinds` × [`SPEEDS`] × [`BEARINGS_DEG`],
/// flown in parallel (rayon), in that order.
pub fn run_grid(kinds: &[Kind], missions: &[MissionKind]) -> Vec<Cell> {
    let mut jobs = Vec::new();
    for &m in missions {
        for form in [WindForm::Step, WindForm::Turbulent] {
            for &k in kinds {
                for &s in &SPEEDS {
                    for b in 0..BEARINGS_DEG.len() {
                        jobs.push((k, m, form, s, b));
                    }
                }
            }
        }
    }
    jobs.par_iter()
        .map(|&(k, m, form, s, b)| fly_cell(k, m, form, s, b))
        .collect()
}

/// Held cells per (mission, wind form, controller, speed): "held/8".
pub fn summary(cells: &[Cell]) -> Vec<serde_json::Value> {
    let mut out = Vec::new();
    let mut keys: Vec<(MissionKind, WindForm, &str, u64)> = Vec::new();
    for c in cells {
        let key = (c.mission, c.wind, c.controller, c.speed.to_bits());
        if !keys.contains(&key) {
            keys.push(key);
        }
    }
    for (m, w, k, s) in keys {
        let row: Vec<&Cell> = cells
            .iter()
            .filter(|c| (c.mission, c.wind, c.controller, c.speed.to_bits()) == (m, w, k, s))
            .collect();
        out.push(serde_json::json!({
            "mission": m,
            "wind": w,
            "controller": k,
            "speed": f64::from_bits(s),
            "held": row.iter().filter(|c| c.held).count(),
            "completed": row.iter().filter(|c| c.completed).count(),
            "cells": row.len(),
        }));
    }
    out
}

fn csv_field(x: Option<f64>) -> String {
    x.map_or_else(String::new, |v| format!("{v}"))
}

/// Fly the grid and write `wind_envelope.json` (parameters, cells, summary) and
/// `wind_envelope.csv` (one row per cell) into `out`. Returns the cells.
pub fn run(out: &Path, kinds: &[Kind], missions: &[MissionKind]) -> Result<Vec<Cell>, String> {
    std::fs::create_dir_all(out).map_err(|e| format!("{}: {e}", out.display()))?;
    let start = Instant::now();
    let cells = run_grid(kinds, missions);
    let wall = start.elapsed().as_secs_f64();
    let value = serde_json::json!({
        "speeds": SPEEDS,
        "bearings_deg": BEARINGS_DEG,
        "step_time": STEP_TIME,
        "held_max_error": HELD_MAX_ERROR,
        "turbulence_intensity": TURBULENCE_INTENSITY,
        "ordering": "gauss-seidel",
        "state": "perfect",
        "wall_time_s": wall,
        "threads": rayon::current_num_threads(),
        "summary": summary(&cells),
        "cells": cells,
    });
    let json_path = out.join("wind_envelope.json");
    let text = serde_json::to_string_pretty(&value).map_err(|e| e.to_string())?;
    std::fs::write(&json_path, text).map_err(|e| format!("{}: {e}", json_path.display()))?;
    let mut csv = String::from(
        "controller,mission,wind,speed,bearing_deg,completed,held,max_error,landing_distance,touchdown_speed,landing_passed,failure\n",
    );
    for c in &cells {
        csv.push_str(&format!(
            "{},{},{},{},{},{},{},{},{},{},{},\"{}\"\n",
            c.controller,
            c.mission.name(),
            c.wind.name(),
            c.speed,
            c.bearing_deg,
            c.completed,
            c.held,
            c.max_error,
            csv_field(c.landing_distance),
            csv_field(c.touchdown_speed),
            c.landing_passed.map_or_else(String::new, |p| p.to_string()),
            c.failure.as_deref().unwrap_or("").replace('"', "'"),
        ));
    }
    let csv_path = out.join("wind_envelope.csv");
    std::fs::write(&csv_path, csv).map_err(|e| format!("{}: {e}", csv_path.display()))?;
    Ok(cells)
}

impl MissionKind {
    /// The name the JSON uses.
    pub fn name(self) -> &'static str {
        match self {
            MissionKind::Default => "default",
            MissionKind::TakeoffLanding => "takeoff_landing",
            MissionKind::Handover => "handover",
        }
    }
}

impl WindForm {
    /// The name the JSON uses.
    pub fn name(self) -> &'static str {
        match self {
            WindForm::Step => "step",
            WindForm::Turbulent => "turbulent",
        }
    }
}

/// Columns of [`trace_csv`].
pub const TRACE_COLUMNS: [&str; 9] = [
    "time",
    "pos_n",
    "pos_e",
    "pos_d",
    "wind_n",
    "wind_e",
    "wind_d",
    "thrust_cmd",
    "elevator_cmd",
];

/// One native flight of the default mission through the atmosphere `params`, as the FMU
/// master flies it (`tailsim.masters.ClosedLoop(..., atmosphere=...)`: the plant FMU's
/// default start, the controller measuring the plant outputs with the wind the plant holds)
/// as CSV of [`TRACE_COLUMNS`] (shortest round-trip decimals), one row per communication
/// point up to `stop_time`. For the comparison with the FMU master.
pub fn trace_csv(kind: Kind, ordering: Ordering, params: atmosphere::Params, stop_time: f64) -> Result<String, String> {
    let plant = plant();
    let mission = MissionParams::default();
    let x0 = trimmed_climb(&plant, mission.v_vertical)?;
    let mut scenario = Scenario::mission(mission);
    scenario.stop_time = stop_time;
    scenario.ordering = ordering;
    scenario.wind = Wind::Atmosphere(params);
    scenario.measured_wind = closed_loop::MeasuredWind::HeldInput;
    let mut c = kind.make(&mission);
    let trace = fly(&plant, x0, &mut c, &scenario);
    if let Some(f) = trace.failure {
        return Err(f);
    }
    let mut out = TRACE_COLUMNS.join(",");
    out.push('\n');
    for s in &trace.samples {
        let p = s.measurement.pos_ned;
        let row = [
            s.t,
            p.x,
            p.y,
            p.z,
            s.wind.x,
            s.wind.y,
            s.wind.z,
            s.command.thrust,
            s.command.elevator,
        ];
        out.push_str(&row.map(|v| format!("{v:?}")).join(","));
        out.push('\n');
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn calm_cell_of_the_default_mission_holds() {
        for kind in Kind::ALL {
            let c = fly_cell(kind, MissionKind::Default, WindForm::Step, 0.0, 0);
            assert!(c.completed && c.held, "{c:?}");
        }
    }

    /// The tuned LQR's mission logic in wind (lqr-control README, "Mission in wind"): the
    /// default mission in a steady 3 m/s wind along the span in hover (from the east) and in
    /// a 5 m/s headwind is held (< 3 m from its own reference; 10.5 and 4.1 m before), and
    /// in an 8 m/s headwind stepping in 3 s before the transition it completes within 5 m
    /// (lost before: 419 m).
    #[test]
    fn lqr_holds_the_default_mission_in_moderate_wind() {
        for (speed, bearing, bound) in [(3.0, 2, HELD_MAX_ERROR), (5.0, 0, HELD_MAX_ERROR), (8.0, 0, 5.0)] {
            let c = fly_cell(Kind::Lqr, MissionKind::Default, WindForm::Step, speed, bearing);
            assert!(c.completed && c.max_error < bound, "{c:?}");
        }
    }

    /// The front transition across the wind (lqr-control README, "Mission in wind"): with
    /// the gains computed about the wind-consistent reference in the transition, the
    /// default mission in an 8 m/s wind from the east (across the track) completes, the
    /// transition within 10 m of its reference and the flight within 15 m (measured 9.1 and
    /// 12.2 m; relinearised about the measured state it was lost in the transition, 424 m),
    /// and in a 5 m/s wind from the north-east within 5 m (measured 3.75 m; 12.4 m before).
    #[test]
    fn lqr_completes_the_front_transition_across_the_wind() {
        for (speed, bearing, transition_bound, bound) in [(8.0, 2, 10.0, 15.0), (5.0, 1, 5.0, 5.0)] {
            let (c, phases) = fly_cell_phases(Kind::Lqr, MissionKind::Default, WindForm::Step, speed, bearing, None);
            let transition = phases[Phase::TransitionToLevel.code() as usize];
            assert!(
                c.completed && transition < transition_bound && c.max_error < bound,
                "{c:?}: transition {transition}"
            );
        }
    }

    /// Take-off to landing in a steady 5 m/s headwind and an 8 m/s tailwind (stepping in on
    /// the gear): the tuned LQR flies the approach and the descent within 3 m of its
    /// reference and comes to rest within 0.5 m of the target after a touchdown under
    /// 0.5 m/s (before, the approach and descent in wind were lost from 3 m/s: an undamped
    /// pitch oscillation of the near-hover air data linearised at α = β = 0). Not yet
    /// upright: it touches down leaning 28–40° into the wind and tips over (lqr-control
    /// README, "Mission in wind"), so `landing_passed` is false.
    #[test]
    fn lqr_descends_onto_the_target_in_wind() {
        for (speed, bearing) in [(5.0, 0), (8.0, 4)] {
            let c = fly_cell(Kind::Lqr, MissionKind::TakeoffLanding, WindForm::Step, speed, bearing);
            let (_, phases) = fly_cell_phases(
                Kind::Lqr,
                MissionKind::TakeoffLanding,
                WindForm::Step,
                speed,
                bearing,
                None,
            );
            let descent = phases[Phase::Approach.code() as usize].max(phases[Phase::Descent.code() as usize]);
            assert!(
                c.completed && descent < HELD_MAX_ERROR,
                "{c:?}: approach/descent {descent}"
            );
            assert!(
                c.landing_distance.unwrap() < 0.5 && c.touchdown_speed.unwrap() < 0.5,
                "{c:?}"
            );
        }
    }

    /// Representative held cells of the tuned TSD over the default mission: a 10 m/s head-,
    /// tail- and quartering (45°) wind stepping in, a 3 m/s crosswind, and an 8 m/s headwind
    /// with moderate turbulence, each within the held limit with the largest error measured
    /// (0.6, 0.5, 2.2, 1.8, 1.1 m) plus 0.5 m; an 8 m/s quartering headwind (45°) and a 10 m/s
    /// quartering tailwind (135°) within 2.7 m and the held limit (measured 2.2 and 2.7 m).
    #[test]
    fn tuned_tsd_holds_representative_wind_cells_of_the_default_mission() {
        for (form, speed, bearing, bound) in [
            (WindForm::Step, 10.0, 0, 1.1),
            (WindForm::Step, 10.0, 4, 1.0),
            (WindForm::Step, 10.0, 1, 2.7),
            (WindForm::Step, 3.0, 2, 2.3),
            (WindForm::Turbulent, 8.0, 0, 1.6),
            // Held by the mission logic in wind (without it 12.3 and 456 m, lost).
            (WindForm::Step, 8.0, 1, 2.7),
            (WindForm::Step, 10.0, 3, 3.0),
        ] {
            let c = fly_cell(Kind::Tsd, MissionKind::Default, form, speed, bearing);
            assert!(c.held && c.max_error < bound, "{c:?}");
        }
    }

    #[test]
    fn turbulent_wind_is_the_atmosphere_with_the_steady_part_of_the_step() {
        let Wind::Atmosphere(p) = wind(WindForm::Turbulent, 5.0, 2, 10.0) else {
            panic!("not the atmosphere")
        };
        assert_eq!(
            (p.wind_speed, p.wind_profile, p.seed, p.origin_height),
            (5.0, 0, 3, 10.0)
        );
        assert_eq!(
            Wind::Atmosphere(p).at(0.0),
            wind(WindForm::Step, 5.0, 2, 10.0).at(STEP_TIME)
        );
    }
}
