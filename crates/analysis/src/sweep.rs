//! Sweep runner: jobs in parallel on all cores (rayon), deterministic (each job is a
//! pure function of its inputs; results are collected in job order), progress bars
//! (indicatif), cached ([`crate::cache`]), and the report's data: CSV and JSON into the
//! output folder. Rust writes data only; `python -m tailsim.analysis_report <out>` renders
//! every table (Markdown, HTML) and plot from it.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use flight_mission::MissionParams;
use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use serde_json::json;
use tailsitter_physics::{AeroModel, Airframe, Plant};

use crate::cache::{self, Cache};
use crate::closed::{poles_at, Condition};
use crate::controllers::Kind;
use crate::linalg::{damping, match_poles, natural_frequency, upper_half, C64};
use crate::modes::{self, ModeSet};
use crate::robust::{self, FlightOutcome, GustPhase};
use crate::sensitivity::{self, Param, SensitivityRow};

/// What to run.
#[derive(Debug, Clone)]
pub struct Config {
    /// Output folder (created).
    pub out: PathBuf,
    /// N of (5.1.1) (thesis: 50).
    pub n: usize,
    /// Controllers.
    pub controllers: Vec<Kind>,
    /// Conditions of the linear sensitivity study.
    pub conditions: Vec<Condition>,
    /// Parameter ids to sweep (empty = all 25 of Table 5.1).
    pub params: Vec<String>,
    /// Gust amplitudes (m/s), ascending.
    pub gust_amplitudes: Vec<f64>,
    /// Run the nonlinear robustness sweep.
    pub robustness: bool,
    /// Aerodynamic models the robustness sweeps fly (issue 13: the thesis's linear model
    /// and the global one, side by side).
    pub aero_models: Vec<AeroModel>,
    /// Also sweep the nonlinear robustness over τ^this (≤ 1: no wide sweep), to find
    /// where the missions start failing.
    pub wide_tau_power: f64,
    /// Run the gust sweep.
    pub gusts: bool,
    /// Show progress bars.
    pub progress: bool,
    /// Fly the hover-in-wind sweep ([`crate::envelope_hover`]).
    pub envelope_hover: bool,
    /// The mission.
    pub mission: MissionParams,
}

impl Config {
    /// The full analysis into `out`.
    pub fn full(out: impl Into<PathBuf>) -> Self {
        Self {
            out: out.into(),
            n: 50,
            controllers: Kind::ALL.to_vec(),
            conditions: Condition::ALL.to_vec(),
            params: Vec::new(),
            gust_amplitudes: (1..=20).map(f64::from).collect(),
            robustness: true,
            aero_models: vec![AeroModel::Thesis, AeroModel::Global],
            wide_tau_power: 3.0,
            gusts: true,
            progress: true,
            envelope_hover: true,
            mission: MissionParams::default(),
        }
    }

    fn selected_params(&self) -> Vec<Param> {
        sensitivity::params()
            .into_iter()
            .filter(|p| self.params.is_empty() || self.params.iter().any(|s| s == p.id))
            .collect()
    }
}

/// Closed-loop poles of one job (s-plane), or why there are none.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct PoleJob {
    /// Poles (re, im) (rad/s).
    pub poles: Vec<(f64, f64)>,
    /// Dominant coordinates of each pole's eigenvector.
    pub dominant: Vec<String>,
    /// Failure (trim or flight to the operating point).
    pub error: Option<String>,
}

impl PoleJob {
    fn complex(&self) -> Option<Vec<C64>> {
        if self.error.is_some() {
            None
        } else {
            Some(self.poles.iter().map(|p| C64::new(p.0, p.1)).collect())
        }
    }
}

/// Scales of the map coordinates for naming dominant states (m, m/s, rad, rad/s, N, rad).
const COORD_SCALE: [f64; 19] = [
    1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 0.1, 0.1, 0.1, 0.5, 0.5, 0.5, 10.0, 0.1, 0.1, 0.1, 0.1, 0.1, 0.1,
];

fn pole_job(airframe: &Airframe, kind: Kind, mission: &MissionParams, cond: Condition) -> PoleJob {
    let plant = Plant::new(*airframe);
    match poles_at(&plant, kind.make(mission), mission, cond) {
        Ok(p) if p.poles.is_empty() => PoleJob {
            poles: Vec::new(),
            dominant: Vec::new(),
            error: Some("no eigenvalues (non-finite Jacobian or no QR convergence)".into()),
        },
        Ok(p) => {
            let mut poles = Vec::new();
            let mut dominant = Vec::new();
            for (s, e) in p.poles.iter().zip(&p.discrete) {
                let s = if s.re.is_finite() && s.im.is_finite() {
                    *s
                } else {
                    C64::new(-1e9, 0.0)
                };
                poles.push((s.re, s.im));
                let mut w: Vec<(f64, usize)> = e
                    .vector
                    .iter()
                    .enumerate()
                    .map(|(i, c)| (c.norm() / COORD_SCALE.get(i).copied().unwrap_or(1.0), i))
                    .collect();
                w.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
                dominant.push(
                    w.iter()
                        .take(2)
                        .map(|(_, i)| p.coords[*i].clone())
                        .collect::<Vec<_>>()
                        .join("+"),
                );
            }
            PoleJob {
                poles,
                dominant,
                error: None,
            }
        }
        Err(e) => PoleJob {
            poles: Vec::new(),
            dominant: Vec::new(),
            error: Some(e),
        },
    }
}

/// Inputs-describing prefix of a controller (hash of its Debug form at construction:
/// tuning, trajectory, nominal model).
fn controller_id(kind: Kind, mission: &MissionParams) -> String {
    format!("{}:{}", kind.name(), cache::key(&format!("{:?}", kind.make(mission))))
}

fn bar(cfg: &Config, len: usize, msg: &str) -> ProgressBar {
    if !cfg.progress {
        return ProgressBar::hidden();
    }
    let pb = ProgressBar::new(len as u64);
    pb.set_style(
        ProgressStyle::with_template("{msg:>22} [{bar:40}] {pos}/{len} {elapsed_precise} eta {eta}")
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> "),
    );
    pb.set_message(msg.to_string());
    pb
}

/// Results of the linear sensitivity study.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct SensitivityResult {
    /// Parameter id.
    pub param: String,
    /// Parameter symbol.
    pub name: String,
    /// Controller.
    pub controller: Kind,
    /// Condition.
    pub condition: Condition,
    /// Scale factors of the sweep.
    pub factors: Vec<f64>,
    /// Thesis value (%), level flight.
    pub thesis_percent: f64,
    /// The measure and loci (None if the nominal point failed).
    pub row: Option<SensitivityRow>,
}

/// Results of the nonlinear parameter sweep.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct RobustnessResult {
    /// Parameter id.
    pub param: String,
    /// Parameter symbol.
    pub name: String,
    /// Controller.
    pub controller: Kind,
    /// The plant's aerodynamic model (0 thesis, 1 global).
    pub aero_model: i32,
    /// Factors.
    pub factors: Vec<f64>,
    /// Outcome per factor.
    pub outcomes: Vec<FlightOutcome>,
    /// Contiguous passing range of factors around 1.
    pub range: Option<(f64, f64)>,
    /// Worst position error (m) over the passing range.
    pub worst_pos_error: f64,
}

/// Position-error bound (m) of the stricter gust survival column.
pub const POS_BOUND: f64 = 10.0;

/// Results of the gust sweep.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct GustResult {
    /// Controller.
    pub controller: Kind,
    /// Where.
    pub phase: GustPhase,
    /// Axis index (0 n, 1 e, 2 d).
    pub axis: usize,
    /// Amplitudes (m/s).
    pub amplitudes: Vec<f64>,
    /// Outcomes.
    pub outcomes: Vec<FlightOutcome>,
    /// Largest amplitude with every smaller one passing.
    pub largest_survived: f64,
    /// The same with the position error also below [`POS_BOUND`].
    pub largest_bounded: f64,
}

/// Everything the sweeps produced.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Summary {
    /// Open-loop modes (level, vertical).
    pub open_loop: Vec<ModeSet>,
    /// Nominal closed-loop poles per (controller, condition).
    pub closed_loop: Vec<(Kind, Condition, PoleJob)>,
    /// Sensitivity.
    pub sensitivity: Vec<SensitivityResult>,
    /// Nonlinear parameter robustness over the thesis's sweep.
    pub robustness: Vec<RobustnessResult>,
    /// The same over the wider sweep τ^`wide_tau_power`.
    pub robustness_wide: Vec<RobustnessResult>,
    /// Gusts.
    pub gusts: Vec<GustResult>,
    /// Wall time of the run (s).
    pub wall_time_s: f64,
    /// Jobs answered from the cache.
    pub cache_hits: usize,
    /// Jobs computed.
    pub jobs: usize,
}

/// Run the sweeps and write the report into `cfg.out`.
pub fn run(cfg: &Config) -> std::io::Result<Summary> {
    let start = Instant::now();
    std::fs::create_dir_all(&cfg.out)?;
    let cache_dir = cfg.out.join("cache");
    let mission = cfg.mission;
    let nominal = Airframe::default();
    let plant = Plant::new(nominal);
    let params = cfg.selected_params();

    // 1. open-loop modes
    let open_loop = vec![
        modes::level_modes(&plant, mission.v_level).map_err(|e| std::io::Error::other(e.to_string()))?,
        modes::vertical_modes(&plant, mission.v_vertical).map_err(|e| std::io::Error::other(e.to_string()))?,
    ];

    let ids: Vec<(Kind, String)> = cfg
        .controllers
        .iter()
        .map(|k| (*k, controller_id(*k, &mission)))
        .collect();
    let id_of = |k: Kind| ids.iter().find(|x| x.0 == k).map(|x| x.1.clone()).unwrap_or_default();

    // 2 + 3. closed-loop poles: nominal and sensitivity sweeps, one job list.
    let poles_cache = Cache::open(Some(&cache_dir), "poles")?;
    #[derive(Clone)]
    struct PJ {
        airframe: Airframe,
        kind: Kind,
        cond: Condition,
    }
    let mut pjobs: Vec<PJ> = Vec::new();
    for &kind in &cfg.controllers {
        for cond in Condition::ALL {
            pjobs.push(PJ {
                airframe: nominal,
                kind,
                cond,
            });
        }
    }
    let mut sens_index: Vec<(usize, Kind, Condition, Vec<f64>, usize)> = Vec::new();
    for (pi, p) in params.iter().enumerate() {
        let f = sensitivity::factors(p.tau(), cfg.n);
        // Table 5.1 is the thesis's study of its two controllers (the report says so for PX4).
        for &kind in cfg.controllers.iter().filter(|k| k.in_thesis()) {
            for &cond in &cfg.conditions {
                sens_index.push((pi, kind, cond, f.clone(), pjobs.len()));
                for &fk in &f {
                    pjobs.push(PJ {
                        airframe: p.scaled(&nominal, fk),
                        kind,
                        cond,
                    });
                }
            }
        }
    }
    let pb = bar(cfg, pjobs.len(), "closed-loop poles");
    let presults: Vec<PoleJob> = pjobs
        .par_iter()
        .map(|j| {
            let key = cache::key(&format!(
                "poles|{}|{:?}|{:?}|{:?}",
                id_of(j.kind),
                j.cond,
                mission,
                j.airframe
            ));
            let r = poles_cache.get_or(&key, || pole_job(&j.airframe, j.kind, &mission, j.cond));
            pb.inc(1);
            r
        })
        .collect();
    pb.finish();
    let mut closed_loop = Vec::new();
    for (j, r) in pjobs.iter().zip(&presults).take(cfg.controllers.len() * 2) {
        closed_loop.push((j.kind, j.cond, r.clone()));
    }
    let sens: Vec<SensitivityResult> = sens_index
        .iter()
        .map(|(pi, kind, cond, f, first)| {
            let p = &params[*pi];
            let points: Vec<Option<Vec<C64>>> = (0..f.len()).map(|k| presults[first + k].complex()).collect();
            SensitivityResult {
                param: p.id.into(),
                name: p.name.into(),
                controller: *kind,
                condition: *cond,
                factors: f.clone(),
                thesis_percent: kind.thesis_percent(p).unwrap_or(f64::NAN),
                row: sensitivity::track(&points, sensitivity::nominal_index(f)),
            }
        })
        .collect();

    // 4a. nonlinear robustness over the same sweeps (and a wider one).
    let flights_cache = Cache::open(Some(&cache_dir), "flights")?;
    let (mut robustness, mut robustness_wide) = (Vec::new(), Vec::new());
    if cfg.robustness {
        let sweep = |tau_power: f64, msg: &str| -> Vec<RobustnessResult> {
            let taus: Vec<f64> = params.iter().map(|p| p.tau().powf(tau_power)).collect();
            let mut jobs: Vec<(usize, Kind, AeroModel, f64)> = Vec::new();
            for (pi, tau) in taus.iter().enumerate() {
                for &kind in &cfg.controllers {
                    for &model in &cfg.aero_models {
                        for fk in sensitivity::factors(*tau, cfg.n) {
                            jobs.push((pi, kind, model, fk));
                        }
                    }
                }
            }
            let pb = bar(cfg, jobs.len(), msg);
            let out: Vec<FlightOutcome> = jobs
                .par_iter()
                .map(|(pi, kind, model, fk)| {
                    let af = params[*pi].scaled(&nominal, *fk);
                    let sc = closed_loop::Scenario::mission(mission);
                    let key = cache::key(&format!(
                        "mission|{}|{:?}|{:?}|aero_model {}",
                        id_of(*kind),
                        sc,
                        af,
                        model.index()
                    ));
                    let r = flights_cache.get_or(&key, || robust::fly_mission(&af, *model, kind.make(&mission), &sc));
                    pb.inc(1);
                    r
                })
                .collect();
            pb.finish();
            let mut res = Vec::new();
            let mut at = 0;
            for (p, tau) in params.iter().zip(&taus) {
                let f = sensitivity::factors(*tau, cfg.n);
                for (&kind, &model) in cfg
                    .controllers
                    .iter()
                    .flat_map(|k| cfg.aero_models.iter().map(move |m| (k, m)))
                {
                    let outcomes: Vec<FlightOutcome> = out[at..at + f.len()].to_vec();
                    at += f.len();
                    let passed: Vec<bool> = outcomes.iter().map(|o| o.passed).collect();
                    let nom = sensitivity::nominal_index(&f);
                    let range = robust::passing_range(&f, &passed, nom);
                    let worst = match range {
                        Some((lo, hi)) => f
                            .iter()
                            .zip(&outcomes)
                            .filter(|(x, _)| **x >= lo && **x <= hi)
                            .map(|(_, o)| o.max_pos_error)
                            .fold(0.0, f64::max),
                        None => f64::NAN,
                    };
                    res.push(RobustnessResult {
                        param: p.id.into(),
                        name: p.name.into(),
                        controller: kind,
                        aero_model: model.index(),
                        factors: f.clone(),
                        outcomes,
                        range,
                        worst_pos_error: worst,
                    });
                }
            }
            res
        };
        robustness = sweep(1.0, "nonlinear robustness");
        if cfg.wide_tau_power > 1.0 {
            robustness_wide = sweep(cfg.wide_tau_power, "wide robustness");
        }
    }

    // 4b. gusts.
    let mut gusts = Vec::new();
    if cfg.gusts {
        let mut jobs: Vec<(Kind, GustPhase, usize, f64)> = Vec::new();
        for &kind in &cfg.controllers {
            for ph in GustPhase::ALL {
                for axis in 0..3 {
                    for &a in &cfg.gust_amplitudes {
                        jobs.push((kind, ph, axis, a));
                    }
                }
            }
        }
        let pb = bar(cfg, jobs.len(), "gust sweep");
        let out: Vec<FlightOutcome> = jobs
            .par_iter()
            .map(|(kind, ph, axis, a)| {
                let sc = robust::gust_scenario(&mission, *ph, *axis, *a);
                let key = cache::key(&format!("mission|{}|{:?}|{:?}|aero_model 0", id_of(*kind), sc, nominal));
                let r = flights_cache.get_or(&key, || {
                    robust::fly_mission(&nominal, AeroModel::Thesis, kind.make(&mission), &sc)
                });
                pb.inc(1);
                r
            })
            .collect();
        pb.finish();
        let na = cfg.gust_amplitudes.len();
        for (c, chunk) in out.chunks(na.max(1)).enumerate() {
            let (kind, ph, axis, _) = jobs[c * na];
            let passed: Vec<bool> = chunk.iter().map(|o| o.passed).collect();
            gusts.push(GustResult {
                controller: kind,
                phase: ph,
                axis,
                amplitudes: cfg.gust_amplitudes.clone(),
                outcomes: chunk.to_vec(),
                largest_survived: robust::largest_survived(&cfg.gust_amplitudes, &passed),
                largest_bounded: robust::largest_survived(
                    &cfg.gust_amplitudes,
                    &chunk
                        .iter()
                        .map(|o| o.passed && o.max_pos_error <= POS_BOUND)
                        .collect::<Vec<_>>(),
                ),
            });
        }
    }

    let total_jobs =
        presults.len() + (robustness.len() + robustness_wide.len()) * cfg.n + gusts.len() * cfg.gust_amplitudes.len();
    let summary = Summary {
        open_loop,
        closed_loop,
        sensitivity: sens,
        robustness,
        robustness_wide,
        gusts,
        wall_time_s: start.elapsed().as_secs_f64(),
        cache_hits: poles_cache.hits() + flights_cache.hits(),
        jobs: total_jobs,
    };
    write_report(&cfg.out, &summary, cfg)?;
    Ok(summary)
}

/// Thesis Table 4.4 (achieved TSD poles): (loop, vertical, level).
const THESIS_TABLE_4_4: [(&str, &str, &str); 5] = [
    ("Axial", "−10.0, −15.0", "−10.0, −15.0"),
    ("Roll rate", "−6.4 ± 1.5i", "−10.6 ± 4.5i"),
    ("Normal", "−12.2, −6.0 ± 3.8i", "−9.6, −17.6 ± 9.1i"),
    ("Directional", "−2.9, −4.0 ± 2.3i", "−5.4, −7.8 ± 5.1i"),
    ("Normal vector", "−0.5", "−3.6"),
];

/// Placed TSD poles (Table 4.3, from the controller's parameters): (loop, poles, upper half).
fn tsd_placed(cond: Condition) -> Vec<(&'static str, C64)> {
    tsd_placed_of(&tsd_control::TsdParams::default(), cond)
}

/// The poles `p` places at `cond` (Table 4.3 form): (loop, pole, upper half).
pub(crate) fn tsd_placed_of(p: &tsd_control::TsdParams, cond: Condition) -> Vec<(&'static str, C64)> {
    // (level, vertical) of one parameter, chosen by the condition.
    let at = |level: f64, vertical: f64| if cond == Condition::Level { level } else { vertical };
    let c = |re: f64, im: f64| C64::new(re, im);
    vec![
        ("Axial", c(at(p.axial_pole_1_level, p.axial_pole_1_vertical), 0.0)),
        ("Axial", c(at(p.axial_pole_2_level, p.axial_pole_2_vertical), 0.0)),
        (
            "Roll rate",
            c(
                at(p.roll_pole_re_level, p.roll_pole_re_vertical),
                at(p.roll_pole_im_level, p.roll_pole_im_vertical),
            ),
        ),
        (
            "Normal",
            c(at(p.normal_pole_real_level, p.normal_pole_real_vertical), 0.0),
        ),
        (
            "Normal",
            c(
                at(p.normal_pole_re_level, p.normal_pole_re_vertical),
                at(p.normal_pole_im_level, p.normal_pole_im_vertical),
            ),
        ),
        (
            "Directional",
            c(at(p.directional_pole_real_level, p.directional_pole_real_vertical), 0.0),
        ),
        (
            "Directional",
            c(
                at(p.directional_pole_re_level, p.directional_pole_re_vertical),
                at(p.directional_pole_im_level, p.directional_pole_im_vertical),
            ),
        ),
        ("Normal vector", c(at(p.nvd_pole_level, p.nvd_pole_vertical), 0.0)),
        (
            "Guidance",
            c(
                at(p.guidance_pole_re_level, p.guidance_pole_re_vertical),
                at(p.guidance_pole_im_level, p.guidance_pole_im_vertical),
            ),
        ),
    ]
}

fn write(out: &Path, name: &str, text: &str) -> std::io::Result<()> {
    std::fs::write(out.join(name), text)
}

/// `(re, im)` of a pole as a JSON pair.
fn pair(z: C64) -> serde_json::Value {
    json!([z.re, z.im])
}

/// The data of the report: the CSV files of every table and figure, `report.json` (every
/// table of the report as structured data, rendered to Markdown, HTML and plots by
/// `python -m tailsim.analysis_report`) and `summary.json` (the raw [`Summary`]).
pub fn write_report(out: &Path, s: &Summary, cfg: &Config) -> std::io::Result<()> {
    let params = cfg.selected_params();
    let controllers: Vec<&str> = cfg.controllers.iter().map(|k| k.name()).collect();
    let conditions: Vec<&str> = cfg.conditions.iter().map(|c| c.name()).collect();

    // ---- open loop
    let mut csv = String::from("condition,mode,re,im,damping,omega_n\n");
    for ms in &s.open_loop {
        for m in &ms.modes {
            let _ = writeln!(
                csv,
                "\"{}\",\"{}\",{},{},{},{}",
                ms.condition, m.name, m.re, m.im, m.damping, m.omega_n
            );
        }
    }
    write(out, "open_loop_modes.csv", &csv)?;
    let open_loop = json!({
        "coords": modes::COORDS,
        "conditions": s.open_loop.iter().map(|ms| json!({
            "condition": ms.condition,
            "trim": {"alpha_deg": ms.trim.0, "elevator_deg": ms.trim.1, "thrust_n": ms.trim.2},
            "modes": ms.modes.iter().map(|m| json!({
                "name": m.name, "re": m.re, "im": m.im, "damping": m.damping, "omega_n": m.omega_n,
                "shape": m.shape,
            })).collect::<Vec<_>>(),
        })).collect::<Vec<_>>(),
        "thesis_level": modes::thesis_open_loop().iter().map(|(name, ev, rows)| json!({
            "name": name, "re": ev.re, "im": ev.im,
            "shape": rows.iter().map(|(c, a, p)| json!([c, a, p])).collect::<Vec<_>>(),
        })).collect::<Vec<_>>(),
    });

    // ---- closed loop
    let mut csv = String::from("controller,condition,re,im,damping,omega_n,dominant\n");
    let mut runs = Vec::new();
    for (kind, cond, job) in &s.closed_loop {
        let mut poles = Vec::new();
        for (p, d) in job.poles.iter().zip(&job.dominant) {
            let z = C64::new(p.0, p.1);
            let _ = writeln!(
                csv,
                "{},{},{},{},{},{},{}",
                kind.name(),
                cond.name(),
                p.0,
                p.1,
                damping(z),
                natural_frequency(z),
                d
            );
            poles.push(json!({
                "re": p.0, "im": p.1, "damping": damping(z), "omega_n": natural_frequency(z), "dominant": d,
            }));
        }
        // TSD: placed poles (Table 4.3) matched one-to-one to the achieved ones (Table 4.4 form).
        let mut placed_vs_achieved = Vec::new();
        if *kind == Kind::Tsd && job.error.is_none() {
            let placed = tsd_placed(*cond);
            let achieved = upper_half(&job.complex().unwrap_or_default());
            let pl: Vec<C64> = placed.iter().map(|p| p.1).collect();
            for ((name, p), j) in placed.iter().zip(match_poles(&pl, &achieved)) {
                let thesis = THESIS_TABLE_4_4.iter().find(|t| t.0 == *name).map(|t| {
                    if *cond == Condition::Level {
                        t.2
                    } else {
                        t.1
                    }
                });
                placed_vs_achieved.push(json!({
                    "loop": name, "placed": pair(*p), "achieved": j.map(|j| pair(achieved[j])), "thesis": thesis,
                }));
            }
        }
        runs.push(json!({
            "controller": kind.name(), "condition": cond.name(), "error": job.error,
            "poles": poles, "tsd_placed": placed_vs_achieved,
        }));
    }
    write(out, "closed_loop_poles.csv", &csv)?;
    let closed_loop = json!({
        "analysis_time_s": {
            "level": Condition::Level.time(&cfg.mission),
            "vertical": Condition::Vertical.time(&cfg.mission),
        },
        "runs": runs,
    });

    // ---- Table 5.1
    let mut csv = String::from(
        "param,controller,condition,thesis_percent,rms_percent,rms_span_percent,failed_points,unstable_points\n",
    );
    let mut loci = String::from("param,controller,condition,pole,k,factor,re,im\n");
    let mut sens_rows = Vec::new();
    for p in &params {
        for &k in cfg.controllers.iter().filter(|k| k.in_thesis()) {
            let th = k.thesis_percent(p).unwrap_or(f64::NAN);
            for &c in &cfg.conditions {
                let r = s
                    .sensitivity
                    .iter()
                    .find(|r| r.param == p.id && r.controller == k && r.condition == c);
                let row = r.and_then(|r| r.row.as_ref());
                sens_rows.push(json!({
                    "param": p.id, "controller": k.name(), "condition": c.name(), "thesis_percent": th,
                    "row": row.map(|row| json!({
                        "rms_percent": row.rms_percent,
                        "rms_span_percent": row.rms_span_percent,
                        "failed_points": row.failed_points,
                        "unstable_points": row.unstable_points,
                        "degenerate_points": row.degenerate_points,
                    })),
                }));
                let (Some(r), Some(row)) = (r, row) else { continue };
                let _ = writeln!(
                    csv,
                    "{},{},{},{},{},{},{},{}",
                    p.id,
                    k.name(),
                    c.name(),
                    th,
                    row.rms_percent,
                    row.rms_span_percent,
                    row.failed_points,
                    row.unstable_points
                );
                for (i, l) in row.loci.iter().enumerate() {
                    for (kk, v) in l.iter().enumerate() {
                        if let Some((re, im)) = v {
                            let _ = writeln!(
                                loci,
                                "{},{},{},{},{},{},{},{}",
                                p.id,
                                k.name(),
                                c.name(),
                                i,
                                kk,
                                r.factors[kk],
                                re,
                                im
                            );
                        }
                    }
                }
            }
        }
    }
    write(out, "table_5_1.csv", &csv)?;
    write(out, "loci.csv", &loci)?;
    let not_in_table: Vec<&str> = cfg
        .controllers
        .iter()
        .filter(|k| !k.in_thesis())
        .map(|k| k.name())
        .collect();
    let sensitivity = json!({
        "min_omega": sensitivity::MIN_OMEGA,
        "rows": sens_rows,
        // Controllers in the run that Table 5.1 does not cover, and why.
        "not_applicable": not_in_table.iter().map(|name| json!({
            "controller": name,
            "reason": "Table 5.1 is the thesis's sensitivity study of its own two controllers; \
                       PX4 is not in the thesis and has no thesis configuration",
        })).collect::<Vec<_>>(),
    });

    // ---- robustness
    let mut robustness = serde_json::Value::Null;
    if !s.robustness.is_empty() {
        let (rows, csv) = robustness_data(&s.robustness, cfg);
        write(out, "robustness.csv", &csv)?;
        let mut wide = serde_json::Value::Null;
        if !s.robustness_wide.is_empty() {
            let (rows, csv) = robustness_data(&s.robustness_wide, cfg);
            write(out, "robustness_wide.csv", &csv)?;
            let power = cfg.wide_tau_power;
            let upper = power * (1.0 - 2.0 / cfg.n as f64);
            wide = json!({
                "tau_power": power,
                // Factor ranges of the wide sweep: (lowest, highest) of τ^(power·(−1+2k/N)).
                "aerodynamic_range": [1.5f64.powf(-power), 1.5f64.powf(upper)],
                "mass_inertia_range": [1.1f64.powf(-power), 1.1f64.powf(upper)],
                "rows": rows,
            });
        }
        robustness = json!({
            "aero_models": cfg.aero_models.iter().map(|m| m.index()).collect::<Vec<_>>(),
            "alpha_attached_deg": tailsitter_physics::GlobalAero::default().alpha_attached.to_degrees(),
            "rows": rows,
            "wide": wide,
        });
    }

    // ---- gusts
    let mut gusts = serde_json::Value::Null;
    if !s.gusts.is_empty() {
        let mut csv = String::from("controller,phase,axis,amplitude,passed,completed,max_pos_error\n");
        let mut rows = Vec::new();
        for ph in GustPhase::ALL {
            for (axis, axis_name) in robust::AXES.iter().enumerate() {
                for &k in &cfg.controllers {
                    let Some(g) = s
                        .gusts
                        .iter()
                        .find(|g| g.controller == k && g.phase == ph && g.axis == axis)
                    else {
                        continue;
                    };
                    let err = g
                        .amplitudes
                        .iter()
                        .position(|a| *a == g.largest_survived)
                        .map(|i| g.outcomes[i].max_pos_error)
                        .unwrap_or(f64::NAN);
                    rows.push(json!({
                        "phase": ph.name(), "axis": axis_name, "controller": k.name(),
                        "largest_survived": g.largest_survived,
                        "max_pos_error_at_largest": err,
                        "largest_bounded": g.largest_bounded,
                    }));
                    for (a, o) in g.amplitudes.iter().zip(&g.outcomes) {
                        let _ = writeln!(
                            csv,
                            "{},{},{},{},{},{},{}",
                            k.name(),
                            ph.name(),
                            axis_name,
                            a,
                            o.passed,
                            o.completed,
                            o.max_pos_error
                        );
                    }
                }
            }
        }
        write(out, "gusts.csv", &csv)?;
        gusts = json!({
            "duration_s": robust::GUST_DURATION,
            "amplitudes": cfg.gust_amplitudes,
            "pos_bound_m": POS_BOUND,
            "rows": rows,
        });
    }

    let report = json!({
        "out": cfg.out.display().to_string(),
        "n": cfg.n,
        "wall_time_s": s.wall_time_s,
        "jobs": s.jobs,
        "cache_hits": s.cache_hits,
        "controllers": controllers,
        "conditions": conditions,
        "params": params.iter().map(|p| json!({
            "id": p.id, "name": p.name,
            "thesis_percent": {(Kind::Lqr.name()): p.thesis.0, (Kind::Tsd.name()): p.thesis.1},
        })).collect::<Vec<_>>(),
        "open_loop": open_loop,
        "closed_loop": closed_loop,
        "sensitivity": sensitivity,
        "robustness": robustness,
        "gusts": gusts,
        "envelope_hover": if cfg.envelope_hover { crate::envelope_hover::report() } else { serde_json::Value::Null },
        "envelope_transitions": crate::envelope_transitions::report(),
        "takeoff_landing": crate::takeoff_landing::report_value(cfg),
    });
    let text = serde_json::to_string_pretty(&report).map_err(std::io::Error::other)?;
    write(out, "report.json", &text)?;
    let json = serde_json::to_string(s).map_err(std::io::Error::other)?;
    write(out, "summary.json", &json)?;
    Ok(())
}

/// Table rows (JSON) and CSV of a robustness sweep: one row per parameter, controller and
/// aerodynamic model, with the sweep's largest α and stall fraction (where the thesis's
/// model left its validity) and the nominal flight (factor 1).
fn robustness_data(results: &[RobustnessResult], cfg: &Config) -> (Vec<serde_json::Value>, String) {
    let mut rows = Vec::new();
    let mut csv = String::from(
        "param,controller,aero_model,factor,passed,completed,max_pos_error,level_airspeed_error,\
         level_pitch_error_deg,max_alpha_deg,max_stall_fraction,failure\n",
    );
    for p in cfg.selected_params() {
        for &k in &cfg.controllers {
            for model in &cfg.aero_models {
                let Some(r) = results
                    .iter()
                    .find(|r| r.param == p.id && r.controller == k && r.aero_model == model.index())
                else {
                    continue;
                };
                let fold = |f: fn(&FlightOutcome) -> f64| {
                    r.outcomes.iter().map(f).filter(|v| v.is_finite()).fold(0.0, f64::max)
                };
                let nominal = r.outcomes.get(sensitivity::nominal_index(&r.factors));
                rows.push(json!({
                    "param": p.id, "controller": k.name(), "aero_model": r.aero_model, "range": r.range,
                    "passes": r.outcomes.iter().filter(|o| o.passed).count(),
                    "points": r.outcomes.len(),
                    "worst_pos_error": r.worst_pos_error,
                    "max_alpha_deg": fold(|o| o.max_alpha_deg),
                    "max_stall_fraction": fold(|o| o.max_stall_fraction),
                    "nominal": nominal.map(|o| json!({
                        "passed": o.passed, "max_pos_error": o.max_pos_error,
                        "max_alpha_deg": o.max_alpha_deg, "max_stall_fraction": o.max_stall_fraction,
                    })),
                }));
                for (f, o) in r.factors.iter().zip(&r.outcomes) {
                    let _ = writeln!(
                        csv,
                        "{},{},{},{},{},{},{},{},{},{},{},\"{}\"",
                        p.id,
                        k.name(),
                        r.aero_model,
                        f,
                        o.passed,
                        o.completed,
                        o.max_pos_error,
                        o.level_airspeed_error,
                        o.level_pitch_error_deg,
                        o.max_alpha_deg,
                        o.max_stall_fraction,
                        o.failure.clone().unwrap_or_default().replace('"', "'")
                    );
                }
            }
        }
    }
    (rows, csv)
}
