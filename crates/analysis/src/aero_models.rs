//! Beyond the thesis (issue 13): the thesis's linear aerodynamics (`aero_model` = 0) and the
//! global model (`aero_model` = 1, the FMU's default) side by side. Both controllers, untuned,
//! fly the same cases on a plant with each model (and the FMU's default ground, 10 m below
//! the start): the default and the fast mission, hover wind steps, the analysis's gust
//! sweep; plus the force and moment coefficients of both models over α = 0…180°. (The
//! parameter sweep of Table 5.1 is flown on both models by the robustness sweep itself,
//! [`crate::sweep`].) Data only: `aero_models.json` and three CSV files;
//! `python -m tailsim.analysis_report` renders them (`tailsim.aero_report`).

use std::fmt::Write as _;
use std::path::Path;

use closed_loop::{fly, plant_inputs, MissionCheck, Scenario, Wind};
use flight_mission::MissionParams;
use nalgebra::Vector3;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use serde_json::json;
use tailsitter_physics::{AeroModel, Airframe, GlobalAero, Ground, Plant, Surfaces};

use crate::controllers::Kind;
use crate::robust::{gust_scenario, largest_survived, GustPhase, AXES, GUST_DURATION};

/// Airspeed of the coefficient curves (m/s) (any: both models are quasi-steady, and the
/// thrust-free curves do not depend on it).
pub const CURVE_AIRSPEED: f64 = 20.0;

/// One flight case.
#[derive(Debug, Clone)]
pub struct Case {
    /// Short id (CSV, JSON).
    pub id: &'static str,
    /// What is flown.
    pub description: String,
    /// Mission, wind, stop time.
    pub scenario: Scenario,
}

/// The cases: default mission, fast mission (T1 = 3 s, T2 = 4 s), and hovering (first
/// vertical phase held for 40 s, 30 s flown) in a wind stepping at 5 s to 5 or 7 m/s from
/// the north (head-on to the wing: α → 90° of the free stream) or the east (side wind).
pub fn cases(mission: &MissionParams) -> Vec<Case> {
    let preset = MissionParams::fast();
    let fast = MissionParams {
        t_transition_1: preset.t_transition_1,
        t_transition_2: preset.t_transition_2,
        ..*mission
    };
    let hover = MissionParams {
        t_vertical_1: 40.0,
        ..*mission
    };
    let mut out = vec![
        Case {
            id: "default",
            description: "default mission".into(),
            scenario: Scenario::mission(*mission),
        },
        Case {
            id: "fast",
            description: format!(
                "fast mission (T1 {} s, T2 {} s)",
                fast.t_transition_1, fast.t_transition_2
            ),
            scenario: Scenario::mission(fast),
        },
    ];
    for (id, speed, axis, dir) in [
        ("hover_n5", 5.0, 0, "north"),
        ("hover_e5", 5.0, 1, "east (side)"),
        ("hover_n7", 7.0, 0, "north"),
        ("hover_e7", 7.0, 1, "east (side)"),
    ] {
        let mut s = Scenario::mission(hover);
        s.stop_time = 30.0;
        let mut w = Vector3::zeros();
        w[axis] = speed;
        s.wind = Wind::Step { t_start: 5.0, wind: w };
        out.push(Case {
            id,
            description: format!("hover, {speed} m/s wind from the {dir} stepping in at 5 s"),
            scenario: s,
        });
    }
    out
}

/// Outcome of one flight.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct AeroRow {
    /// Case id.
    pub case: String,
    /// "LQR" / "TSD".
    pub controller: String,
    /// 0 thesis, 1 global.
    pub aero_model: i32,
    /// Reached the stop time without a controller or plant failure and without touching
    /// the ground.
    pub completed: bool,
    /// Completed and (missions only) the mission criteria met.
    pub passed: bool,
    /// Failure message, if it stopped early.
    pub failure: Option<String>,
    /// Largest |α| of the free stream (deg).
    pub max_alpha_deg: f64,
    /// Largest |β| of the free stream (deg) (the side-wind cases).
    pub max_beta_deg: f64,
    /// Largest |position − reference| (m).
    pub max_pos_error_m: f64,
    /// Largest |altitude − reference altitude| (m).
    pub max_alt_dev_m: f64,
    /// Largest `stall_fraction` (the share of the wing in post-stall flow; reported for
    /// either model: for model 0 it says where the thesis's model is used outside its
    /// validity).
    pub max_stall_fraction: f64,
    /// First time the wing left attached flow (s), if it did.
    pub first_stall_s: Option<f64>,
    /// Any contact point touched the ground.
    pub ground_contact: bool,
}

fn plant(airframe: &Airframe, model: AeroModel) -> Plant {
    let mut p = Plant::new(*airframe);
    p.aero.model = model;
    p.ground = Ground::default();
    p
}

/// Fly one case with one controller on one model.
pub fn fly_case(case: &Case, kind: Kind, model: AeroModel) -> AeroRow {
    let is_mission = case.id == "default" || case.id == "fast";
    fly_scenario(case.id, &case.scenario, kind, model, is_mission, &Airframe::default())
}

/// Fly `sc` with one controller (designed on the nominal airframe) on one model of a plant
/// with `airframe`; `is_mission`: also judge the mission criteria.
fn fly_scenario(
    id: &str,
    sc: &Scenario,
    kind: Kind,
    model: AeroModel,
    is_mission: bool,
    airframe: &Airframe,
) -> AeroRow {
    let p = plant(airframe, model);
    let nominal = plant(&Airframe::default(), model);
    let m = &sc.mission;
    let mut row = AeroRow {
        case: id.into(),
        controller: kind.name().into(),
        aero_model: model.index(),
        completed: false,
        passed: false,
        failure: None,
        max_alpha_deg: f64::NAN,
        max_beta_deg: f64::NAN,
        max_pos_error_m: f64::NAN,
        max_alt_dev_m: f64::NAN,
        max_stall_fraction: f64::NAN,
        first_stall_s: None,
        ground_contact: false,
    };
    // A modified plant that cannot trim starts from the nominal trim (as crate::robust).
    let climb = p
        .trim_vertical_climb(m.v_vertical)
        .or_else(|_| nominal.trim_vertical_climb(m.v_vertical));
    let level = p.trim_level(m.v_level).or_else(|_| nominal.trim_level(m.v_level));
    let (x0, theta) = match (climb, level) {
        (Ok(x0), Ok(level)) => (x0.state, level.theta),
        _ => {
            row.failure = Some("no trim".into());
            return row;
        }
    };
    let mut ctl = kind.make(m);
    let trace = fly(&p, x0, &mut ctl, sc);
    let (mut alpha, mut beta, mut alt, mut stall) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for s in &trace.samples {
        let y = p.outputs(&s.x, &plant_inputs(&s.command), &s.wind);
        alpha = alpha.max(s.measurement.alpha.abs());
        beta = beta.max(s.measurement.beta.abs());
        alt = alt.max((s.measurement.pos_ned.z - s.diagnostics.ref_pos_ned.z).abs());
        stall = stall.max(y.stall_fraction);
        if y.stall_fraction > 0.0 && row.first_stall_s.is_none() {
            row.first_stall_s = Some(s.t);
        }
        row.ground_contact |= y.ground.points > 0;
    }
    row.completed = trace.completed() && !row.ground_contact;
    row.passed = row.completed && (!is_mission || MissionCheck::of(&trace, m, theta).passed());
    row.failure = trace.failure.clone().or_else(|| {
        row.ground_contact
            .then(|| "touched the ground (10 m below the start)".to_string())
    });
    row.max_alpha_deg = alpha.to_degrees();
    row.max_beta_deg = beta.to_degrees();
    row.max_pos_error_m = trace.max_pos_error();
    row.max_alt_dev_m = alt;
    row.max_stall_fraction = stall;
    row
}

/// Largest survived gust of one phase, axis, controller and model.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct GustRow {
    /// "vertical" / "transition" / "level".
    pub phase: String,
    /// "n" / "e" / "d".
    pub axis: String,
    /// "LQR" / "TSD".
    pub controller: String,
    /// 0 thesis, 1 global.
    pub aero_model: i32,
    /// Largest amplitude A such that every amplitude ≤ A passes the mission criteria, no
    /// ground contact (m/s) (0: the smallest fails).
    pub largest_survived: f64,
    /// Largest stall fraction over the flights up to and including the first failure.
    pub max_stall_fraction: f64,
}

/// The analysis's gust sweep ([`crate::robust`]: 1−cos gusts along each NED axis in the
/// vertical phase, the first transition and level flight, default mission) flown on both
/// models.
pub fn gust_rows(mission: &MissionParams, amplitudes: &[f64]) -> Vec<GustRow> {
    let mut jobs = Vec::new();
    for phase in GustPhase::ALL {
        for axis in 0..3 {
            for kind in Kind::ALL {
                for model in [AeroModel::Thesis, AeroModel::Global] {
                    jobs.push((phase, axis, kind, model));
                }
            }
        }
    }
    jobs.par_iter()
        .map(|&(phase, axis, kind, model)| {
            let mut passed = Vec::new();
            let mut stall = 0.0f64;
            for &amp in amplitudes {
                let sc = gust_scenario(mission, phase, axis, amp);
                let r = fly_scenario("gust", &sc, kind, model, true, &Airframe::default());
                stall = stall.max(r.max_stall_fraction);
                passed.push(r.passed);
                if !r.passed {
                    break;
                }
            }
            GustRow {
                phase: phase.name().into(),
                axis: AXES[axis].into(),
                controller: kind.name().into(),
                aero_model: model.index(),
                largest_survived: largest_survived(&amplitudes[..passed.len()], &passed),
                max_stall_fraction: stall,
            }
        })
        .collect()
}

/// Lift, drag and pitching-moment coefficients (wind axes, about the CG, no thrust, no
/// rotation, surfaces neutral, β = 0) of one model at α (rad).
pub fn coefficients(a: &Airframe, g: &GlobalAero, model: AeroModel, alpha: f64) -> [f64; 3] {
    let v = CURVE_AIRSPEED;
    let va = Vector3::new(v * alpha.cos(), 0.0, v * alpha.sin());
    let (w, s0) = (Vector3::zeros(), Surfaces::default());
    let fm = match model {
        AeroModel::Thesis => a.forces_moments(&va, &w, 0.0, &s0),
        AeroModel::Global => g.forces_moments(a, &va, &w, 0.0, &s0).0,
    };
    let qs = 0.5 * a.air_density * v * v * a.wing_area;
    let xw = va / v;
    let zw = Vector3::new(-alpha.sin(), 0.0, alpha.cos());
    [
        -fm.force_body.dot(&zw) / qs,
        -fm.force_body.dot(&xw) / qs,
        fm.moment_body.y / (qs * a.mean_chord),
    ]
}

/// Fly every case and the gust sweep (`gust_amplitudes`, ascending; empty = none) with both
/// controllers on both models (in parallel), and write `aero_models.json`,
/// `aero_models.csv`, `aero_gusts.csv` and `aero_coefficients.csv` into `out`.
pub fn run(out: &Path, mission: &MissionParams, gust_amplitudes: &[f64]) -> std::io::Result<Vec<AeroRow>> {
    std::fs::create_dir_all(out)?;
    let cases = cases(mission);
    let mut jobs = Vec::new();
    for (ci, _) in cases.iter().enumerate() {
        for kind in Kind::ALL {
            for model in [AeroModel::Thesis, AeroModel::Global] {
                jobs.push((ci, kind, model));
            }
        }
    }
    let rows: Vec<AeroRow> = jobs
        .par_iter()
        .map(|&(ci, kind, model)| fly_case(&cases[ci], kind, model))
        .collect();

    let mut csv = String::from(
        "case,controller,aero_model,completed,passed,max_alpha_deg,max_beta_deg,max_pos_error_m,max_alt_dev_m,\
         max_stall_fraction,first_stall_s,ground_contact,failure\n",
    );
    for r in &rows {
        let _ = writeln!(
            csv,
            "{},{},{},{},{},{},{},{},{},{},{},{},\"{}\"",
            r.case,
            r.controller,
            r.aero_model,
            r.completed,
            r.passed,
            r.max_alpha_deg,
            r.max_beta_deg,
            r.max_pos_error_m,
            r.max_alt_dev_m,
            r.max_stall_fraction,
            r.first_stall_s.map(|t| t.to_string()).unwrap_or_default(),
            r.ground_contact,
            r.failure.clone().unwrap_or_default().replace('"', "'")
        );
    }
    std::fs::write(out.join("aero_models.csv"), csv)?;

    let a = Airframe::default();
    let g = GlobalAero::default();
    let alphas: Vec<f64> = (0..=180).map(f64::from).collect();
    let mut curves = String::from("alpha_deg,thesis_c_L,thesis_c_D,thesis_c_m,global_c_L,global_c_D,global_c_m\n");
    let mut thesis = [Vec::new(), Vec::new(), Vec::new()];
    let mut global = [Vec::new(), Vec::new(), Vec::new()];
    for &deg in &alphas {
        let t = coefficients(&a, &g, AeroModel::Thesis, deg.to_radians());
        let gl = coefficients(&a, &g, AeroModel::Global, deg.to_radians());
        let _ = writeln!(curves, "{deg},{},{},{},{},{},{}", t[0], t[1], t[2], gl[0], gl[1], gl[2]);
        for k in 0..3 {
            thesis[k].push(t[k]);
            global[k].push(gl[k]);
        }
    }
    std::fs::write(out.join("aero_coefficients.csv"), curves)?;

    let gusts = gust_rows(mission, gust_amplitudes);
    let mut gcsv = String::from("phase,axis,controller,aero_model,largest_survived,max_stall_fraction\n");
    for g in &gusts {
        let _ = writeln!(
            gcsv,
            "{},{},{},{},{},{}",
            g.phase, g.axis, g.controller, g.aero_model, g.largest_survived, g.max_stall_fraction
        );
    }
    std::fs::write(out.join("aero_gusts.csv"), gcsv)?;

    let report = json!({
        "ground_height_m": Ground::default().height,
        "gusts": {"duration_s": GUST_DURATION, "amplitudes": gust_amplitudes, "rows": gusts},
        "coefficients": {
            "airspeed_m_s": CURVE_AIRSPEED,
            "alpha_deg": alphas,
            "thesis": {"c_L": thesis[0], "c_D": thesis[1], "c_m": thesis[2]},
            "global": {"c_L": global[0], "c_D": global[1], "c_m": global[2]},
            "alpha_attached_deg": g.alpha_attached.to_degrees(),
            "alpha_stalled_deg": g.alpha_stalled.to_degrees(),
            "alpha_reverse_attached_deg": g.alpha_reverse_attached.to_degrees(),
            "alpha_reverse_stalled_deg": g.alpha_reverse_stalled.to_degrees(),
            "c_D_90": g.c_D_90,
        },
        "cases": cases.iter().map(|c| json!({"id": c.id, "description": c.description})).collect::<Vec<_>>(),
        "rows": rows,
    });
    let text = serde_json::to_string_pretty(&report).map_err(std::io::Error::other)?;
    std::fs::write(out.join("aero_models.json"), text)?;
    Ok(rows)
}
