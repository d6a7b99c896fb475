//! The Monte-Carlo campaign's runs flown natively (issue 15, performance): the same jobs
//! as the Dask/fmpy campaign (`python -m tailsim.campaign --native`), one JSON object per
//! line in, one row per line out, so that the two engines can be compared row by row.
//!
//! A job carries everything the fmpy runner sets: the plant parameters by name (values as
//! IEEE-754 bit patterns, so that no decimal round trip changes a sampled value), the
//! plant's `aero_model`, the controller and its `configuration`, the mission parameters by
//! name, the sample's wind (steady horizontal + 1 − cos gust) and the run's limits. The
//! plant is built as the plant FMU builds it (`fmu-plant`: validated airframe, global-model
//! and ground defaults, 2 ms RK4 substeps, trimmed in a vertical climb at `initial_speed`
//! and re-oriented with the 3-2-1 Euler angles), the controller as the controller FMUs
//! build it (design model = the nominal airframe), and the loop is
//! [`closed_loop::fly`] (Gauss-Seidel, the master the fmpy runner mirrors call for call).
//! The metrics mirror `tailsim.campaign_runner.run_metrics` line by line.

use std::time::Instant;

use closed_loop::{fly, plant_inputs, MeasuredWind, Sample, Scenario, Trace, Wind};
use flight_mission::{FlightController, MissionParams};
use lqr_control::{LqrController, LqrParams};
use nalgebra::Vector3;
use px4_control::{Px4Controller, Px4Params};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use tailsitter_physics::{AeroModel, Airframe, GlobalAero, Ground, Plant, StateVector};
use tsd_control::{TsdController, TsdParams};

/// The plant FMU's default `initial_speed` (m/s): the vertical-climb trim it starts from.
pub const INITIAL_SPEED: f64 = 3.0;
/// Command limits of the saturation metric (thrust 0 / 150 N, surfaces ±25°), as the fmpy runner.
pub const THRUST_LIMITS: (f64, f64) = (0.0, 150.0);
/// |δ| at which a surface command counts as saturated (rad) (25°).
pub const DEFLECTION_LIMIT: f64 = 25.0 * std::f64::consts::PI / 180.0;

/// The sample's wind (m/s), NED, each value as `f64::to_bits`: steady horizontal
/// `steady_n/e` plus the 1 − cos gust `gust · (1 − cos(2π (t − gust_start)/gust_duration)) / 2`
/// inside the gust (s for the times).
#[derive(Debug, Clone, Copy, Deserialize)]
pub struct JobWind {
    pub steady_n: u64,
    pub steady_e: u64,
    pub gust_n: u64,
    pub gust_e: u64,
    pub gust_d: u64,
    pub gust_start: u64,
    pub gust_duration: u64,
    /// Dryden turbulence intensity (the atmosphere's `turbulence_intensity`, 0 none) and its
    /// seed: with turbulence the wind is the atmosphere's ([`wind_of`]).
    #[serde(default)]
    pub turbulence_intensity: i32,
    #[serde(default)]
    pub turbulence_seed: i32,
}

/// One run (see the module documentation).
#[derive(Debug, Clone, Deserialize)]
pub struct Job {
    pub key: String,
    /// "lqr", "tsd" or "px4".
    pub controller: String,
    /// The controllers' `configuration`: 0 tuned, 1 thesis (PX4 has none: 0 only).
    pub configuration: i32,
    /// Only "perfect" (the avionics chain is flown by the fmpy campaign only).
    pub state_source: String,
    /// Plant parameters by name, each as `f64::to_bits`.
    pub plant_bits: BTreeMap<String, u64>,
    /// The plant's `aero_model` (0 thesis, 1 global).
    pub aero_model: i32,
    /// Mission parameters by name (controller parameters), each as `f64::to_bits`.
    pub mission_bits: BTreeMap<String, u64>,
    pub wind: JobWind,
    /// Stop time (s) and communication step (s).
    pub stop_time: f64,
    pub step_size: f64,
    /// The run is a divergence once the controller's `pos_error` exceeds this (m).
    pub divergence_m: f64,
    /// A run flown to the stop time is completed only if its largest `pos_error` stays within
    /// this (m); beyond it the failure is `error` (infinite if absent).
    #[serde(default = "no_error_limit")]
    pub error_limit_m: f64,
}

fn no_error_limit() -> f64 {
    f64::INFINITY
}

/// One row: the outcome and the metrics (NaN where not reached, as the fmpy rows).
#[derive(Debug, Clone, Serialize)]
pub struct Row {
    pub key: String,
    pub completed: bool,
    pub failure: String,
    pub detail: String,
    /// Metric name → value (`tailsim.campaign_runner.metric_columns`); NaN is written as null.
    pub metrics: BTreeMap<String, Option<f64>>,
    /// CPU time of the run's thread (s) and wall time (s).
    pub cpu_time_s: f64,
    pub wall_time_s: f64,
}

fn set_named(values: &mut [(&'static str, &mut f64)], bits: &BTreeMap<String, u64>, what: &str) -> Result<(), String> {
    for (name, b) in bits {
        match values.iter_mut().find(|(n, _)| n == name) {
            Some((_, v)) => **v = f64::from_bits(*b),
            None => return Err(format!("{what} has no parameter '{name}'")),
        }
    }
    Ok(())
}

/// The plant and its initial state as the plant FMU builds them from these parameters.
pub fn plant_of(job: &Job) -> Result<(Plant, StateVector), String> {
    let mut airframe = Airframe::default();
    set_named(&mut airframe.named_values_mut(), &job.plant_bits, "the plant")?;
    airframe
        .validate()
        .map_err(|e| format!("invalid airframe parameter: {e}"))?;
    let model = AeroModel::from_index(job.aero_model).ok_or_else(|| format!("aero_model = {}", job.aero_model))?;
    let mut plant = Plant::new(airframe);
    plant.aero = GlobalAero {
        model,
        ..GlobalAero::default()
    };
    plant.ground = Ground::default();
    let trim = plant
        .trim_vertical_climb(INITIAL_SPEED)
        .map_err(|e| format!("initial trim at initial_speed = {INITIAL_SPEED} m/s failed: {e}"))?;
    Ok((plant, crate::wind_envelope::at_origin_heading_0(trim.state)))
}

/// The mission of a job (the declared defaults, then the job's values by name).
pub fn mission_of(job: &Job) -> Result<MissionParams, String> {
    let mut m = MissionParams::default();
    set_named(&mut m.named_values_mut(), &job.mission_bits, "the mission")?;
    m.validate().map_err(|e| e.0)?;
    Ok(m)
}

/// The job's wind: with turbulence the atmosphere of the `tailsitter_atmosphere` FMU as the
/// fmpy runner sets it (`tailsim.campaign.sampling.atmosphere_parameters`: the steady wind
/// uniform with height, Dryden turbulence of the job's intensity and seed, the 1 − cos gust,
/// the ground `origin_height` below the origin), else the steady wind plus the gust.
pub fn wind_of(job: &Job, origin_height: f64) -> Wind {
    let w = job.wind;
    let f = f64::from_bits;
    if w.turbulence_intensity > 0 {
        let (n, e) = (f(w.steady_n), f(w.steady_e));
        return Wind::Atmosphere(atmosphere::Params {
            wind_speed: n.hypot(e),
            wind_from: (-e).atan2(-n).rem_euclid(2.0 * std::f64::consts::PI),
            wind_profile: 0,
            origin_height,
            turbulence_model: 1,
            turbulence_intensity: w.turbulence_intensity,
            seed: w.turbulence_seed,
            gust_amplitude_n: f(w.gust_n),
            gust_amplitude_e: f(w.gust_e),
            gust_amplitude_d: f(w.gust_d),
            gust_start: f(w.gust_start),
            gust_duration: f(w.gust_duration),
            ..atmosphere::Params::default()
        });
    }
    Wind::SteadyAndGust {
        steady: Vector3::new(f(w.steady_n), f(w.steady_e), 0.0),
        t_start: f(w.gust_start),
        duration: f(w.gust_duration),
        amplitude: Vector3::new(f(w.gust_n), f(w.gust_e), f(w.gust_d)),
    }
}

fn trace_of<C: FlightController>(plant: &Plant, x0: StateVector, mut c: C, scenario: &Scenario) -> Trace {
    fly(plant, x0, &mut c, scenario)
}

/// Fly one job; a failure of any kind is a row, never a panic or an error.
pub fn run(job: &Job) -> Row {
    let (t0, c0) = (Instant::now(), cpu_time());
    let (mut failure, mut detail, mut samples) = (String::new(), String::new(), Vec::new());
    let mut plant = None;
    match fly_job(job) {
        Err(e) => {
            failure = "fmi_error".into(); // what the FMU would refuse with an error status
            detail = e;
        }
        Ok((p, trace)) => {
            plant = Some(p);
            samples = trace.samples;
            if let Some(f) = trace.failure {
                // A plant failure is its envelope check (the FMU's "left its envelope"), the
                // fmpy runner's `divergence`; a controller failure is an FMI error there.
                failure = if f.starts_with("plant failed") {
                    "divergence".into()
                } else {
                    "fmi_error".into()
                };
                detail = f;
            }
            // The fmpy runner stops after the first point whose pos_error exceeds the limit.
            if let Some(k) = samples
                .iter()
                .position(|s| s.diagnostics.pos_error.is_nan() || s.diagnostics.pos_error > job.divergence_m)
            {
                let s = &samples[k];
                if k + 1 < samples.len() || failure.is_empty() {
                    failure = "divergence".into();
                    detail = format!(
                        "position error {:.1} m > {} m at t = {:.2} s",
                        s.diagnostics.pos_error, job.divergence_m, s.t
                    );
                }
                samples.truncate(k + 1);
            }
        }
    }
    let metrics = plant.map_or_else(metrics_of_nothing, |p| metrics(&p, &samples));
    // The completion criterion of a run flown to the end (`tailsim.campaign.runner.error_failure`).
    if failure.is_empty() {
        let max_err = metrics.get("max_err").copied().flatten().unwrap_or(f64::NAN);
        if max_err.is_nan() || max_err > job.error_limit_m {
            failure = "error".into();
            detail = format!("largest position error {max_err:.2} m > {} m", job.error_limit_m);
        }
    }
    Row {
        key: job.key.clone(),
        completed: failure.is_empty(),
        failure,
        detail,
        metrics,
        cpu_time_s: cpu_time() - c0,
        wall_time_s: t0.elapsed().as_secs_f64(),
    }
}

/// The scenario of a job flown on `plant`: the mission, stop time, step and wind of the job,
/// the wind read as the fmpy master reads it.
pub fn scenario_of(job: &Job, plant: &Plant, mission: MissionParams) -> Scenario {
    let mut scenario = Scenario::mission(mission);
    scenario.stop_time = job.stop_time;
    scenario.comm_step = job.step_size;
    scenario.wind = wind_of(job, plant.ground.height);
    // The fmpy master reads the plant outputs before it sets the new wind (tailsim.master).
    scenario.measured_wind = MeasuredWind::HeldInput;
    scenario
}

fn fly_job(job: &Job) -> Result<(Plant, Trace), String> {
    if job.state_source != "perfect" {
        return Err(format!(
            "state source '{}': the native campaign flies 'perfect' only",
            job.state_source
        ));
    }
    let (plant, x0) = plant_of(job)?;
    let mission = mission_of(job)?;
    let scenario = scenario_of(job, &plant, mission);
    // The controllers' design model: the nominal airframe (their `design_airframe` defaults).
    let design = Airframe::default();
    match job.controller.as_str() {
        "lqr" => {
            let p = LqrParams {
                configuration: job.configuration,
                ..LqrParams::default()
            };
            let c = LqrController::new(design, mission, p).map_err(|e| format!("LQR: {e:?}"))?;
            let trace = trace_of(&plant, x0, c, &scenario);
            Ok((plant, trace))
        }
        "tsd" => {
            let p = TsdParams {
                configuration: job.configuration,
                ..TsdParams::default()
            };
            let c = TsdController::new(design, mission, p).map_err(|e| format!("TSD: {}", e.0))?;
            let trace = trace_of(&plant, x0, c, &scenario);
            Ok((plant, trace))
        }
        // PX4's default parameters (its FMU's defaults); it has no thesis configuration.
        "px4" if job.configuration == 0 => {
            let c = Px4Controller::new(design, mission, Px4Params::default()).map_err(|e| format!("PX4: {}", e.0))?;
            let trace = trace_of(&plant, x0, c, &scenario);
            Ok((plant, trace))
        }
        "px4" => Err(format!(
            "configuration = {}: PX4 has no thesis configuration",
            job.configuration
        )),
        other => Err(format!("unknown controller '{other}'")),
    }
}

/// The metrics of a run that flew nothing (all missing).
fn metrics_of_nothing() -> BTreeMap<String, Option<f64>> {
    metrics(&Plant::new(Airframe::default()), &[])
}

/// The metrics of `tailsim.campaign_runner.run_metrics` on the recorded samples. α is the
/// plant's output at t with the wind at t and the sample's command set, as the fmpy runner
/// records it (the controller itself sampled the outputs before the new wind was set).
pub fn metrics(plant: &Plant, samples: &[Sample]) -> BTreeMap<String, Option<f64>> {
    let mut out = BTreeMap::new();
    let finite = |x: f64| if x.is_nan() { None } else { Some(x) };
    let phase = |s: &Sample| s.diagnostics.phase as usize;
    let max = |it: &mut dyn Iterator<Item = f64>| it.fold(None, |m: Option<f64>, x| Some(m.map_or(x, |m| m.max(x))));
    let rms = |v: &[f64]| (!v.is_empty()).then(|| (v.iter().map(|e| e * e).sum::<f64>() / v.len() as f64).sqrt());
    for k in 0..5 {
        let e: Vec<f64> = samples
            .iter()
            .filter(|s| phase(s) == k)
            .map(|s| s.diagnostics.pos_error)
            .collect();
        out.insert(format!("max_err_p{k}"), max(&mut e.iter().copied()));
        out.insert(format!("rms_err_p{k}"), rms(&e));
    }
    let e: Vec<f64> = samples.iter().map(|s| s.diagnostics.pos_error).collect();
    out.insert("max_err".into(), max(&mut e.iter().copied()));
    out.insert("rms_err".into(), rms(&e));
    for (name, k) in [("alt_loss_t1", 1), ("alt_loss_t2", 3)] {
        let below = max(&mut samples
            .iter()
            .filter(|s| phase(s) == k)
            .map(|s| s.measurement.pos_ned.z - s.diagnostics.ref_pos_ned.z));
        out.insert(name.into(), below.map(|b| b.max(0.0)));
    }
    let alpha = max(&mut samples
        .iter()
        .filter(|s| (1..=3).contains(&phase(s)))
        .map(|s| plant.outputs(&s.x, &plant_inputs(&s.command), &s.wind).alpha));
    out.insert("max_alpha_deg".into(), alpha.map(f64::to_degrees));
    let (mut sat, mut sat_thrust) = (0usize, 0usize);
    for s in samples {
        let c = &s.command;
        let t = c.thrust <= THRUST_LIMITS.0 || c.thrust >= THRUST_LIMITS.1 * (1.0 - 1e-9);
        let surf = c.to_array()[1..]
            .iter()
            .any(|d| d.abs() >= DEFLECTION_LIMIT * (1.0 - 1e-9));
        sat += usize::from(t || surf);
        sat_thrust += usize::from(t);
    }
    let n = samples.len() as f64;
    out.insert("sat_frac".into(), (n > 0.0).then(|| sat as f64 / n));
    out.insert("sat_frac_thrust".into(), (n > 0.0).then(|| sat_thrust as f64 / n));
    out.insert("t_end".into(), samples.last().map(|s| s.t));
    out.insert(
        "last_phase".into(),
        samples.iter().map(|s| phase(s) as f64).reduce(f64::max),
    );
    out.into_iter().map(|(k, v)| (k, v.and_then(finite))).collect()
}

/// CPU time of the calling thread (s) (`CLOCK_THREAD_CPUTIME_ID`, as Python's `time.thread_time`).
fn cpu_time() -> f64 {
    clock_seconds(libc::CLOCK_THREAD_CPUTIME_ID)
}

/// The reading of a POSIX CPU-time clock (s); NaN if the clock cannot be read.
pub(crate) fn clock_seconds(clock: libc::clockid_t) -> f64 {
    let mut ts = libc::timespec { tv_sec: 0, tv_nsec: 0 };
    // SAFETY: clock_gettime writes one timespec into `ts`, which outlives the call.
    let rc = unsafe { libc::clock_gettime(clock, &mut ts) };
    if rc == 0 {
        ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9
    } else {
        f64::NAN
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn job(controller: &str) -> Job {
        Job {
            key: "0/x".into(),
            controller: controller.into(),
            configuration: 0,
            state_source: "perfect".into(),
            plant_bits: BTreeMap::new(),
            aero_model: 0,
            mission_bits: BTreeMap::new(),
            wind: JobWind {
                steady_n: 0,
                steady_e: 0,
                gust_n: 0,
                gust_e: 0,
                gust_d: 0,
                gust_start: 0,
                gust_duration: 1.0f64.to_bits(),
                turbulence_intensity: 0,
                turbulence_seed: 0,
            },
            stop_time: 1.0,
            step_size: 0.02,
            divergence_m: 50.0,
            error_limit_m: 5.0,
        }
    }

    #[test]
    fn parameters_are_set_by_name_and_unknown_names_refused() {
        let mut j = job("lqr");
        j.plant_bits.insert("mass".into(), 10.5f64.to_bits());
        j.mission_bits.insert("t_level".into(), 2.5f64.to_bits());
        assert_eq!(plant_of(&j).unwrap().0.airframe.mass, 10.5);
        assert_eq!(mission_of(&j).unwrap().t_level, 2.5);
        j.plant_bits.insert("mas".into(), 1.0f64.to_bits());
        assert!(plant_of(&j).unwrap_err().contains("'mas'"));
    }

    #[test]
    fn an_invalid_parameter_is_a_failed_row_with_the_reason() {
        let mut j = job("tsd");
        j.plant_bits.insert("mass".into(), (-1.0f64).to_bits());
        let r = run(&j);
        assert!(
            !r.completed && r.failure == "fmi_error" && r.detail.contains("mass"),
            "{r:?}"
        );
        assert_eq!(r.metrics["max_err"], None);
    }

    #[test]
    fn a_divergence_stops_at_the_first_point_beyond_the_limit() {
        let mut j = job("lqr");
        j.stop_time = 2.0;
        // pos_error at t = 0 is 0 m: a limit of −1 m is exceeded by the first point.
        j.divergence_m = -1.0;
        let r = run(&j);
        assert_eq!(r.failure, "divergence");
        assert_eq!(r.metrics["t_end"], Some(0.0));
    }

    /// Completed = flown to the end within the error limit: the same crosswind flight is an
    /// `error` below its largest error and completed above it.
    #[test]
    fn a_flight_beyond_the_error_limit_is_an_error() {
        let mut j = job("tsd");
        j.stop_time = 3.0;
        j.wind.steady_e = 5.0f64.to_bits();
        let r = run(&j);
        let max_err = r.metrics["max_err"].unwrap();
        assert!(r.completed && max_err > 0.05, "{r:?}");
        j.error_limit_m = 0.5 * max_err;
        let r = run(&j);
        assert!(
            !r.completed && r.failure == "error" && r.detail.contains("largest position error"),
            "{r:?}"
        );
        assert_eq!(r.metrics["max_err"], Some(max_err));
    }

    /// With turbulence the wind is the atmosphere's, whose steady part is the job's wind.
    #[test]
    fn turbulent_job_flies_the_atmosphere_with_the_steady_wind() {
        let mut j = job("tsd");
        j.wind.steady_n = (-3.0f64).to_bits();
        j.wind.steady_e = 4.0f64.to_bits();
        assert!(matches!(wind_of(&j, 10.0), Wind::SteadyAndGust { .. }));
        j.wind.turbulence_intensity = 2;
        j.wind.turbulence_seed = 9;
        let Wind::Atmosphere(p) = wind_of(&j, 10.0) else {
            panic!("not the atmosphere")
        };
        assert_eq!((p.turbulence_model, p.turbulence_intensity, p.seed), (1, 2, 9));
        assert_eq!((p.wind_profile, p.origin_height), (0, 10.0));
        assert!((Wind::Atmosphere(p).at(0.0) - Vector3::new(-3.0, 4.0, 0.0)).norm() < 1e-12);
    }

    /// PX4 is an arm like the others: the same short flight completes; it has no thesis
    /// configuration, so configuration 1 is a failed row saying so.
    #[test]
    fn px4_flies_the_same_job_and_refuses_a_thesis_configuration() {
        let r = run(&job("px4"));
        assert!(r.completed, "{r:?}");
        assert_eq!(r.metrics["t_end"], Some(1.0));
        let mut j = job("px4");
        j.configuration = 1;
        let r = run(&j);
        assert!(
            !r.completed && r.failure == "fmi_error" && r.detail.contains("no thesis configuration"),
            "{r:?}"
        );
    }

    #[test]
    fn nominal_short_flight_completes_in_the_vertical_phase() {
        let r = run(&job("tsd"));
        assert!(r.completed, "{r:?}");
        // 1 s of the default mission: the first vertical climb (5 s), 51 points.
        assert_eq!(r.metrics["last_phase"], Some(0.0));
        assert_eq!(r.metrics["t_end"], Some(1.0));
        assert_eq!(r.metrics["max_err_p1"], None);
    }
}
