//! Campaign runner: jobs in parallel on all cores (rayon), deterministic (each job is a
//! pure function of its inputs; results are collected in job order), progress bars
//! (indicatif), cached ([`crate::cache`]), and the report: Markdown tables, CSV and JSON
//! into the output folder (plots by `plot.py` from the CSVs).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use flight_mission::MissionParams;
use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use tailsitter_physics::{Airframe, Plant};

use crate::cache::{self, Cache};
use crate::closed::{poles_at, Condition};
use crate::controllers::Kind;
use crate::linalg::{damping, fmt_pole, match_poles, natural_frequency, upper_half, C64};
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
    /// Also sweep the nonlinear robustness over τ^this (≤ 1: no wide sweep), to find
    /// where the missions start failing.
    pub wide_tau_power: f64,
    /// Run the gust sweep.
    pub gusts: bool,
    /// Show progress bars.
    pub progress: bool,
    /// The mission.
    pub mission: MissionParams,
}

impl Config {
    /// The full campaign of the issue into `out`.
    pub fn full(out: impl Into<PathBuf>) -> Self {
        Self {
            out: out.into(),
            n: 50,
            controllers: Kind::ALL.to_vec(),
            conditions: Condition::ALL.to_vec(),
            params: Vec::new(),
            gust_amplitudes: (1..=20).map(f64::from).collect(),
            robustness: true,
            wide_tau_power: 3.0,
            gusts: true,
            progress: true,
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

/// Everything the campaign produced.
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

/// Run the campaign and write the report into `cfg.out`.
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
        for &kind in &cfg.controllers {
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
                thesis_percent: if *kind == Kind::Lqr { p.thesis.0 } else { p.thesis.1 },
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
            let mut jobs: Vec<(usize, Kind, f64)> = Vec::new();
            for (pi, tau) in taus.iter().enumerate() {
                for &kind in &cfg.controllers {
                    for fk in sensitivity::factors(*tau, cfg.n) {
                        jobs.push((pi, kind, fk));
                    }
                }
            }
            let pb = bar(cfg, jobs.len(), msg);
            let out: Vec<FlightOutcome> = jobs
                .par_iter()
                .map(|(pi, kind, fk)| {
                    let af = params[*pi].scaled(&nominal, *fk);
                    let sc = closed_loop::Scenario::mission(mission);
                    let key = cache::key(&format!("mission|{}|{:?}|{:?}", id_of(*kind), sc, af));
                    let r = flights_cache.get_or(&key, || robust::fly_mission(&af, kind.make(&mission), &sc));
                    pb.inc(1);
                    r
                })
                .collect();
            pb.finish();
            let mut res = Vec::new();
            let mut at = 0;
            for (p, tau) in params.iter().zip(&taus) {
                let f = sensitivity::factors(*tau, cfg.n);
                for &kind in &cfg.controllers {
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
                let key = cache::key(&format!("mission|{}|{:?}|{:?}", id_of(*kind), sc, nominal));
                let r = flights_cache.get_or(&key, || robust::fly_mission(&nominal, kind.make(&mission), &sc));
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

fn nan_str(v: f64, prec: usize) -> String {
    if v.is_finite() && v < 1e300 {
        format!("{v:.prec$}")
    } else {
        "—".into()
    }
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
    let p = tsd_control::TsdParams::default();
    let c = |re: f64, im: f64| C64::new(re, im);
    match cond {
        Condition::Level => vec![
            ("Axial", c(p.axial_pole_1_level, 0.0)),
            ("Axial", c(p.axial_pole_2_level, 0.0)),
            ("Roll rate", c(p.roll_pole_re_level, p.roll_pole_im_level)),
            ("Normal", c(p.normal_pole_real_level, 0.0)),
            ("Normal", c(p.normal_pole_re_level, p.normal_pole_im_level)),
            ("Directional", c(p.directional_pole_real_level, 0.0)),
            (
                "Directional",
                c(p.directional_pole_re_level, p.directional_pole_im_level),
            ),
            ("Normal vector", c(p.nvd_pole_level, 0.0)),
            ("Guidance", c(p.guidance_pole_re_level, p.guidance_pole_im_level)),
        ],
        Condition::Vertical => vec![
            ("Axial", c(p.axial_pole_1_vertical, 0.0)),
            ("Axial", c(p.axial_pole_2_vertical, 0.0)),
            ("Roll rate", c(p.roll_pole_re_vertical, p.roll_pole_im_vertical)),
            ("Normal", c(p.normal_pole_real_vertical, 0.0)),
            ("Normal", c(p.normal_pole_re_vertical, p.normal_pole_im_vertical)),
            ("Directional", c(p.directional_pole_real_vertical, 0.0)),
            (
                "Directional",
                c(p.directional_pole_re_vertical, p.directional_pole_im_vertical),
            ),
            ("Normal vector", c(p.nvd_pole_vertical, 0.0)),
            ("Guidance", c(p.guidance_pole_re_vertical, p.guidance_pole_im_vertical)),
        ],
    }
}

fn write(out: &Path, name: &str, text: &str) -> std::io::Result<()> {
    std::fs::write(out.join(name), text)
}

/// Markdown, CSV and JSON of a summary.
pub fn write_report(out: &Path, s: &Summary, cfg: &Config) -> std::io::Result<()> {
    let mut md = String::new();
    let _ = writeln!(md, "# Tail-sitter analysis report\n");
    let _ = writeln!(
        md,
        "Generated by `cargo run --release -p analysis -- all --out {}` (N = {}, wall time {:.1} s, {} jobs, {} from the cache).\n",
        cfg.out.display(),
        cfg.n,
        s.wall_time_s,
        s.jobs,
        s.cache_hits
    );

    // ---- open loop
    let mut ol = String::new();
    let _ = writeln!(ol, "## Open-loop modes (thesis §3.4.2, Tables 3.2 and 3.3)\n");
    let lvl = &s.open_loop[0];
    let _ = writeln!(
        ol,
        "{}: trim α = {:.2}°, δe = {:.2}°, T = {:.2} N. Coordinates (V̄, α, β, p, q, r, φ, θ, ψ), 3-2-1 Euler angles; \
         mode shapes normalised to the largest displayed component (V in m/s, angles in rad, rates in rad/s).\n",
        lvl.condition, lvl.trim.0, lvl.trim.1, lvl.trim.2
    );
    let _ = writeln!(
        ol,
        "| mode | ours | ζ | ω_n (rad/s) | thesis | shape (ours) | shape (thesis) |"
    );
    let _ = writeln!(ol, "|---|---|---|---|---|---|---|");
    let mut csv = String::from("condition,mode,re,im,damping,omega_n\n");
    for (name, ev, rows) in modes::thesis_open_loop() {
        let Some(m) = lvl.modes.iter().find(|m| m.name == name) else {
            continue;
        };
        let ours: Vec<String> = rows
            .iter()
            .map(|(c, _, _)| {
                let i = modes::COORDS.iter().position(|x| x == c).unwrap_or(0);
                format!("{} {:.3}∠{:.0}°", c, m.shape[i].0, m.shape[i].1)
            })
            .collect();
        let th: Vec<String> = rows.iter().map(|(c, a, p)| format!("{c} {a:.3}∠{p:.0}°")).collect();
        let _ = writeln!(
            ol,
            "| {} | {} | {:.3} | {:.3} | {} | {} | {} |",
            name,
            fmt_pole(C64::new(m.re, m.im)),
            m.damping,
            m.omega_n,
            fmt_pole(ev),
            ours.join(", "),
            th.join(", ")
        );
    }
    for ms in &s.open_loop {
        for m in &ms.modes {
            let _ = writeln!(
                csv,
                "\"{}\",\"{}\",{},{},{},{}",
                ms.condition, m.name, m.re, m.im, m.damping, m.omega_n
            );
        }
    }
    let vert = &s.open_loop[1];
    let _ = writeln!(
        ol,
        "\n{}: trim T = {:.2} N. The conventional names do not apply; modes named by their dominant coordinate.\n",
        vert.condition, vert.trim.2
    );
    let _ = writeln!(ol, "| mode | eigenvalue | ζ | ω_n (rad/s) |\n|---|---|---|---|");
    for m in &vert.modes {
        let _ = writeln!(
            ol,
            "| {} | {} | {:.3} | {:.3} |",
            m.name,
            fmt_pole(C64::new(m.re, m.im)),
            m.damping,
            m.omega_n
        );
    }
    let _ = writeln!(ol, "\n{}", OPEN_LOOP_NOTES);
    write(out, "open_loop_modes.csv", &csv)?;
    write(out, "open_loop_modes.md", &ol)?;
    md.push_str(&ol);

    // ---- closed loop
    let mut cl = String::new();
    let _ = writeln!(
        cl,
        "\n## Closed-loop poles (Jacobian of the closed-loop sampled map, s = ln z / T)\n\n\
         One method for both controllers: plant over one sample time + controller update, perturbed in the plant's \
         19 minimal coordinates and the controller's integrators (through its save/restore state), at the operating \
         point the nominal mission reaches (level: t = {:.1} s, vertical 3 m/s climb: t = {:.1} s). Upper half plane \
         only; servo (−20) and thrust-lag (−10) poles included.\n",
        Condition::Level.time(&cfg.mission),
        Condition::Vertical.time(&cfg.mission)
    );
    let mut csv = String::from("controller,condition,re,im,damping,omega_n,dominant\n");
    for (kind, cond, job) in &s.closed_loop {
        let _ = writeln!(cl, "### {} — {} flight\n", kind.name(), cond.name());
        if let Some(e) = &job.error {
            let _ = writeln!(cl, "failed: {e}\n");
            continue;
        }
        let _ = writeln!(
            cl,
            "| pole | ζ | ω_n (rad/s) | dominant coordinates |\n|---|---|---|---|"
        );
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
            if p.1 < -1e-9 {
                continue;
            }
            let _ = writeln!(
                cl,
                "| {} | {:.3} | {:.3} | {} |",
                fmt_pole(z),
                damping(z),
                natural_frequency(z),
                d
            );
        }
        let _ = writeln!(cl);
        if *kind == Kind::Tsd {
            let placed = tsd_placed(*cond);
            let achieved = upper_half(&job.complex().unwrap_or_default());
            let pl: Vec<C64> = placed.iter().map(|p| p.1).collect();
            let m = match_poles(&pl, &achieved);
            let _ = writeln!(
                cl,
                "TSD placed (Table 4.3, our parameters) against achieved (nearest closed-loop pole, one-to-one, \
                 closest pairs first; where loops couple and poles crowd, the assignment is ambiguous — the dominant \
                 coordinates in the list above identify the loops):\n\n\
                 | loop | placed | achieved (ours) | thesis Table 4.4 |\n|---|---|---|---|"
            );
            for ((name, p), j) in placed.iter().zip(&m) {
                let th = THESIS_TABLE_4_4
                    .iter()
                    .find(|t| t.0 == *name)
                    .map(|t| if *cond == Condition::Level { t.2 } else { t.1 })
                    .unwrap_or("—");
                let a = j.map(|j| fmt_pole(achieved[j])).unwrap_or_else(|| "—".into());
                let _ = writeln!(cl, "| {} | {} | {} | {} |", name, fmt_pole(*p), a, th);
            }
            let _ = writeln!(cl);
        }
    }
    write(out, "closed_loop_poles.csv", &csv)?;
    write(out, "closed_loop_poles.md", &cl)?;
    md.push_str(&cl);

    // ---- Table 5.1
    let mut t5 = String::new();
    let _ = writeln!(
        t5,
        "\n## Sensitivity (thesis §5.1, Table 5.1)\n\n\
         Each parameter scaled in the plant alone by C₀·τ^(−1+2k/N), k = 0…N−1, N = {}, τ = 1.5 (aerodynamic) / 1.1 \
         (m, I); controllers keep their nominal design model. Entry: RMS over the closed-loop poles of each pole's \
         largest excursion from nominal, in % of its nominal natural frequency (poles with ω_n < {} rad/s left out). \
         `!` marks sweeps with an unstable closed-loop pole somewhere, `✗n` sweeps where n points failed to reach the \
         operating point, `sn` sweeps where at n points an actuator saturated at the operating point (a pole at z = 0, \
         left out of that pole's excursion). The thesis's column is level flight.\n",
        cfg.n,
        sensitivity::MIN_OMEGA
    );
    let mut header = String::from("| parameter |");
    let mut rule = String::from("|---|");
    for &k in &cfg.controllers {
        let _ = write!(header, " {} thesis |", k.name());
        rule.push_str("---|");
        for c in &cfg.conditions {
            let _ = write!(header, " {} ours ({}) |", k.name(), c.name());
            rule.push_str("---|");
        }
    }
    let _ = writeln!(t5, "{header}\n{rule}");
    let mut csv = String::from(
        "param,controller,condition,thesis_percent,rms_percent,rms_span_percent,failed_points,unstable_points\n",
    );
    let mut loci = String::from("param,controller,condition,pole,k,factor,re,im\n");
    for p in cfg.selected_params() {
        let mut line = format!("| {} |", p.name);
        for &k in &cfg.controllers {
            let th = if k == Kind::Lqr { p.thesis.0 } else { p.thesis.1 };
            let _ = write!(line, " {th:.1}% |");
            for &c in &cfg.conditions {
                let r = s
                    .sensitivity
                    .iter()
                    .find(|r| r.param == p.id && r.controller == k && r.condition == c);
                let cell = match r.and_then(|r| r.row.as_ref()) {
                    Some(row) => {
                        let mut t = format!("{:.1}%", row.rms_percent);
                        if row.unstable_points > 0 {
                            t.push_str(" !");
                        }
                        if row.degenerate_points > 0 {
                            let _ = write!(t, " s{}", row.degenerate_points);
                        }
                        if row.failed_points > 0 {
                            let _ = write!(t, " ✗{}", row.failed_points);
                        }
                        t
                    }
                    None => "failed".into(),
                };
                let _ = write!(line, " {cell} |");
                if let Some(r) = r {
                    if let Some(row) = &r.row {
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
        }
        let _ = writeln!(t5, "{line}");
    }
    let _ = writeln!(t5, "\n{}", SENSITIVITY_NOTES);
    write(out, "table_5_1.csv", &csv)?;
    write(out, "loci.csv", &loci)?;
    write(out, "table_5_1.md", &t5)?;
    md.push_str(&t5);

    // ---- robustness
    if !s.robustness.is_empty() {
        let intro = "\n## Nonlinear robustness (beyond the thesis)\n\n\
             The whole default mission flown in the nonlinear closed loop with the parameter scaled over the same \
             sweep as Table 5.1 (τ = 1.5 / 1.1); range = contiguous range of factors around 1 over which the mission \
             passes the controller issues' criteria (`MissionCheck::passed`); worst = largest position error over \
             that range; passes = passing points of N. The mission is symmetric and flown in calm air, so the lateral \
             derivatives are hardly excited (identical position errors): their robustness shows in the gust sweep.\n";
        let rb = robustness_section(intro, &s.robustness, cfg);
        write(out, "robustness.csv", &rb.1)?;
        let mut text = rb.0;
        if !s.robustness_wide.is_empty() {
            let intro = format!(
                "\n### Wider sweep: τ^{} ({:.2} … {:.2} aerodynamic, {:.3} … {:.3} m and I)\n\n\
                 The same flights over a wider range, to find where the missions start failing.\n",
                cfg.wide_tau_power,
                1.5f64.powf(-cfg.wide_tau_power),
                1.5f64.powf(cfg.wide_tau_power * (1.0 - 2.0 / cfg.n as f64)),
                1.1f64.powf(-cfg.wide_tau_power),
                1.1f64.powf(cfg.wide_tau_power * (1.0 - 2.0 / cfg.n as f64)),
            );
            let w = robustness_section(&intro, &s.robustness_wide, cfg);
            write(out, "robustness_wide.csv", &w.1)?;
            text.push_str(&w.0);
        }
        write(out, "robustness.md", &text)?;
        md.push_str(&text);
    }

    // ---- gusts
    if !s.gusts.is_empty() {
        let mut gu = String::new();
        let _ = writeln!(
            gu,
            "\n## Gust sweep (beyond the thesis)\n\n\
             1−cos gusts of {} s along one earth axis (NED; + = towards north/east/down), amplitudes {}…{} m/s: in the \
             first vertical phase (3 m/s climb, from t = 1.5 s), centred on the middle of the first transition, and in \
             level flight (from 2 s after its start). Largest amplitude A such that every amplitude ≤ A still passes the \
             mission criteria (0 = the smallest fails); the criteria do not bound the position error, so the last \
             column also requires a position error ≤ 10 m.\n",
            robust::GUST_DURATION,
            cfg.gust_amplitudes.first().copied().unwrap_or(0.0),
            cfg.gust_amplitudes.last().copied().unwrap_or(0.0)
        );
        let mut header = String::from("| phase | axis |");
        let mut rule = String::from("|---|---|");
        for &k in &cfg.controllers {
            let _ = write!(
                header,
                " {0} largest survived (m/s) | {0} max pos. err at it (m) | {0} largest with pos. err ≤ {1} m |",
                k.name(),
                POS_BOUND
            );
            rule.push_str("---|---|---|");
        }
        let _ = writeln!(gu, "{header}\n{rule}");
        let mut csv = String::from("controller,phase,axis,amplitude,passed,completed,max_pos_error\n");
        for ph in GustPhase::ALL {
            for axis in 0..3 {
                let mut line = format!("| {} | {} |", ph.name(), robust::AXES[axis]);
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
                    let _ = write!(
                        line,
                        " {:.0} | {} | {:.0} |",
                        g.largest_survived,
                        nan_str(err, 2),
                        g.largest_bounded
                    );
                    for (a, o) in g.amplitudes.iter().zip(&g.outcomes) {
                        let _ = writeln!(
                            csv,
                            "{},{},{},{},{},{},{}",
                            k.name(),
                            ph.name(),
                            robust::AXES[axis],
                            a,
                            o.passed,
                            o.completed,
                            o.max_pos_error
                        );
                    }
                }
                let _ = writeln!(gu, "{line}");
            }
        }
        write(out, "gusts.csv", &csv)?;
        write(out, "gusts.md", &gu)?;
        md.push_str(&gu);
    }
    write(out, "report.md", &md)?;
    let json = serde_json::to_string(s).map_err(std::io::Error::other)?;
    write(out, "summary.json", &json)?;
    Ok(())
}

/// Markdown table and CSV of a robustness sweep.
fn robustness_section(intro: &str, results: &[RobustnessResult], cfg: &Config) -> (String, String) {
    let mut rb = String::from(intro);
    let _ = writeln!(rb);
    let mut header = String::from("| parameter |");
    let mut rule = String::from("|---|");
    for &k in &cfg.controllers {
        let _ = write!(header, " {0} range | {0} passes | {0} worst pos. err (m) |", k.name());
        rule.push_str("---|---|---|");
    }
    let _ = writeln!(rb, "{header}\n{rule}");
    let mut csv = String::from(
        "param,controller,factor,passed,completed,max_pos_error,level_airspeed_error,level_pitch_error_deg,failure\n",
    );
    for p in cfg.selected_params() {
        let mut line = format!("| {} |", p.name);
        for &k in &cfg.controllers {
            let Some(r) = results.iter().find(|r| r.param == p.id && r.controller == k) else {
                line.push_str(" — | — | — |");
                continue;
            };
            let n_pass = r.outcomes.iter().filter(|o| o.passed).count();
            let range = match r.range {
                Some((lo, hi)) => format!("{lo:.3} … {hi:.3}"),
                None => "nominal fails".into(),
            };
            let _ = write!(
                line,
                " {} | {}/{} | {} |",
                range,
                n_pass,
                r.outcomes.len(),
                nan_str(r.worst_pos_error, 2)
            );
            for (f, o) in r.factors.iter().zip(&r.outcomes) {
                let _ = writeln!(
                    csv,
                    "{},{},{},{},{},{},{},{},\"{}\"",
                    p.id,
                    k.name(),
                    f,
                    o.passed,
                    o.completed,
                    o.max_pos_error,
                    o.level_airspeed_error,
                    o.level_pitch_error_deg,
                    o.failure.clone().unwrap_or_default().replace('"', "'")
                );
            }
        }
        let _ = writeln!(rb, "{line}");
    }
    (rb, csv)
}

/// Why our open-loop modes differ from Tables 3.2/3.3 (docs/DESIGN.md §4, §6).
pub const OPEN_LOOP_NOTES: &str = "Differences from the thesis (docs/DESIGN.md §4/§6): the thesis's modes were computed \
from its AVL-based model with numbers it does not publish (span, inertia cross-terms, the trim it linearised at: α = 5.9° \
in AVL against our α ≈ 7.5°, δe ≈ −6° once the elevator's own lift counts). Its short period −10.44 ± 24.2i does not follow from its own published derivatives: with C_mα = −1.65, C_mq = −7.64, C_Lα = 4.25, I_y = 0.42 kg m², m = 9 kg, S = 0.574 m², c̄ = 0.366 m at 25 m/s (q̄Sc̄ ≈ 80 N m), M_α ≈ q̄Sc̄C_mα/I_y ≈ −315 s⁻², M_q ≈ q̄Sc̄²C_mq/(2V I_y) ≈ −10.7 s⁻¹ and Z_α/V ≈ q̄SC_Lα/(mV) ≈ 4.2 s⁻¹, so ζω ≈ (10.7 + 4.2)/2 ≈ 7.4 s⁻¹ and ω ≈ √(315 + 10.7·4.2) ≈ 19 rad/s — our −7.4 ± 16.5i (ω_n 18.1), not the thesis's ω_n 26.4 rad/s, which would need about twice the pitch stiffness C_mα/I_y. Lateral modes depend on the span b = 1.569 m (S/c̄) we assume, which sets the \
roll damping L_p ∝ b² and hence the roll pole (ours ≈ −8 against −10.3) and the Dutch roll. The spiral mode is unstable in \
both (no dihedral, §3.4.2), slower in ours. The phugoid matches in frequency (≈ √2·g/V).";

/// Notes on the sensitivity measure.
pub const SENSITIVITY_NOTES: &str = "Our closed loops differ from the thesis's (controllers retuned for this airframe, \
our full sampled-data loop with servo and thrust lags and integrators against the thesis's linear model), so the \
percentages are compared in ranking, not value. The measure is the largest excursion over the sweep; the end-to-end span \
|p(k=N−1) − p(k=0)| is in `table_5_1.csv` (rms_span_percent).";
