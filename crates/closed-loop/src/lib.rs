//! The closed loop of the tail-sitter plant ([`tailsitter_physics::Plant`]) and
//! any [`FlightController`], without FMI: the same wiring and timing a
//! co-simulation master uses (docs/DESIGN.md §2 Timing), for tests, analysis
//! campaigns and benchmarks of the controller libraries.
//!
//! Frames: NED earth axes for positions, velocities and wind; SI units.

pub use flight_mission::{measure, measurement, plant_inputs};
use flight_mission::{Command, ControllerInput, Diagnostics, FlightController, Measurement, MissionParams, Notice};
use std::sync::OnceLock;

use nalgebra::Vector3;
use tailsitter_physics::{idx, InputVector, Plant, StateVector};

pub mod avionics;
pub mod wind_source;
pub use wind_source::{PointWind, WindSource};

/// The acceptance criteria of a flown mission, read from
/// `modelDescription/fragments/mission_criteria.json` (compiled in): the one source the
/// Python metrics and reports (`tailsim.metrics.CRITERIA`) read too.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Criteria {
    /// The level-flight checks cover the last this-many seconds of level flight (s).
    pub level_window: f64,
    /// Largest |airspeed − v_level| over the level window (m/s).
    pub level_airspeed_error_max: f64,
    /// Largest |θ − θ_trim| over the level window (rad).
    pub level_pitch_error_max: f64,
    /// Largest |θ − 90°| at the end (rad).
    pub final_pitch_error_max: f64,
    /// Time-edge tolerance (s): see [`EDGE_TOLERANCE`].
    pub edge_tolerance: f64,
}

/// The criteria file's text.
pub const CRITERIA_JSON: &str = include_str!("../../../modelDescription/fragments/mission_criteria.json");

impl Criteria {
    /// Parse the criteria file (values in its declared units: s, m/s, deg).
    pub fn parse(text: &str) -> Result<Self, String> {
        let v: serde_json::Value = serde_json::from_str(text).map_err(|e| format!("mission criteria: {e}"))?;
        let get = |key: &str, unit: &str| -> Result<f64, String> {
            let entry = &v[key];
            if entry["unit"].as_str() != Some(unit) {
                return Err(format!("mission criteria: {key} must be given in {unit}"));
            }
            entry["value"]
                .as_f64()
                .ok_or_else(|| format!("mission criteria: {key} has no numeric value"))
        };
        Ok(Self {
            level_window: get("level_window", "s")?,
            level_airspeed_error_max: get("level_airspeed_error_max", "m/s")?,
            level_pitch_error_max: get("level_pitch_error_max", "deg")?.to_radians(),
            final_pitch_error_max: get("final_pitch_error_max", "deg")?.to_radians(),
            edge_tolerance: get("edge_tolerance", "s")?,
        })
    }

    /// The compiled-in criteria.
    pub fn get() -> &'static Self {
        static CRITERIA: OnceLock<Criteria> = OnceLock::new();
        CRITERIA.get_or_init(|| match Self::parse(CRITERIA_JSON) {
            Ok(c) => c,
            // The file is part of the source: a broken one is a build defect, caught by the tests.
            Err(e) => panic!("{e}"),
        })
    }
}

/// Time edges (s), the mission's ([`flight_mission::EDGE_TOLERANCE`]): used by
/// [`Wind::Step`], [`Scenario::ref_offset`] and [`Trace::window`], and identically by the
/// Python master; equal to `edge_tolerance` of the criteria file (tested).
pub use flight_mission::EDGE_TOLERANCE;

/// How the master orders the two units within a communication step.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Ordering {
    /// Controller samples the plant outputs at t, then the plant steps with
    /// that command (the reference master).
    #[default]
    GaussSeidel,
    /// Both step on values from t: the plant flies the command of the
    /// previous sample (one sample of extra delay).
    Jacobi,
}

/// Earth-frame wind profile (m/s), NED.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum Wind {
    #[default]
    Calm,
    /// The same wind all the time.
    Constant(Vector3<f64>),
    /// Zero before `t_start`, `wind` from then on (from `t ≥ t_start − EDGE_TOLERANCE`).
    Step { t_start: f64, wind: Vector3<f64> },
    /// 1 − cos gust: `amplitude · (1 − cos(2π (t − t_start)/duration)) / 2` inside the gust.
    OneMinusCosine {
        t_start: f64,
        duration: f64,
        amplitude: Vector3<f64>,
    },
    /// A steady wind plus a 1 − cos gust (the Monte-Carlo campaign's samples):
    /// `steady + amplitude · (1 − cos(2π (t − t_start)/duration)) / 2` inside the gust,
    /// `steady` outside (`tailsim.campaign_sampling.wind_function`, same operations).
    SteadyAndGust {
        steady: Vector3<f64>,
        t_start: f64,
        duration: f64,
        amplitude: Vector3<f64>,
    },
    /// The atmosphere of the `tailsitter_atmosphere` FMU (steady wind with a height profile,
    /// Dryden turbulence, 1 − cos gust), run by [`fly`] on the plant's position and airspeed
    /// ([`wind_source`]: the timing of a co-simulation master).
    Atmosphere(atmosphere::Params),
}

/// Air-mass velocity, NED (m/s), of a horizontal wind of `speed` (m/s) blowing *from* the
/// bearing `from_bearing` (rad, 0 = from the north, π/2 = from the east): the meteorological
/// convention, `−speed (cos b, sin b, 0)`. `tailsim.master.wind_from` mirrors it.
pub fn wind_from(from_bearing: f64, speed: f64) -> Vector3<f64> {
    let (s, c) = from_bearing.sin_cos();
    Vector3::new(-speed * c, -speed * s, 0.0)
}

impl Wind {
    /// A steady wind of `speed` (m/s) from `from_bearing` (rad) switched on at `t_start` (s):
    /// [`Wind::Step`] of [`wind_from`].
    pub fn step_from(t_start: f64, from_bearing: f64, speed: f64) -> Self {
        Wind::Step {
            t_start,
            wind: wind_from(from_bearing, speed),
        }
    }

    /// A 1 − cos gust of peak `amplitude` (m/s) along the earth axis `axis` (0 N, 1 E, 2 D;
    /// + = towards north/east/down) from `t_start` over `duration` (s).
    pub fn gust_along(axis: usize, amplitude: f64, t_start: f64, duration: f64) -> Self {
        let mut a = Vector3::zeros();
        a[axis.min(2)] = amplitude;
        Wind::OneMinusCosine {
            t_start,
            duration,
            amplitude: a,
        }
    }

    /// Wind at time `t`.
    pub fn at(&self, t: f64) -> Vector3<f64> {
        match *self {
            Wind::Calm => Vector3::zeros(),
            Wind::Constant(w) => w,
            Wind::Step { t_start, wind } => {
                if t >= t_start - EDGE_TOLERANCE {
                    wind
                } else {
                    Vector3::zeros()
                }
            }
            Wind::OneMinusCosine {
                t_start,
                duration,
                amplitude,
            } => {
                let s = (t - t_start) / duration;
                if (0.0..=1.0).contains(&s) {
                    amplitude * (0.5 * (1.0 - (2.0 * std::f64::consts::PI * s).cos()))
                } else {
                    Vector3::zeros()
                }
            }
            // The 1 − cos gust on top of the steady wind (same operations as the campaign's).
            Wind::SteadyAndGust {
                steady,
                t_start,
                duration,
                amplitude,
            } => {
                steady
                    + Wind::OneMinusCosine {
                        t_start,
                        duration,
                        amplitude,
                    }
                    .at(t)
            }
            // Stateful: [`fly`] runs it ([`WindSource`]); here only its steady wind at the
            // reference height.
            Wind::Atmosphere(p) => wind_from(p.wind_from, p.wind_speed),
        }
    }
}

/// Which wind the plant outputs the controller samples at t were computed with.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum MeasuredWind {
    /// The wind at t (this master's default).
    #[default]
    Current,
    /// The wind the plant flew its last step with, held at its input: the wind at t − h
    /// (at t = 0 the initial wind). What an FMI master that reads the plant's outputs
    /// before it sets the new wind input delivers (`tailsim.master.ClosedLoop`, the
    /// campaign's fmpy runner); the native campaign uses it to fly identical jobs.
    HeldInput,
}

/// One closed-loop run.
#[derive(Debug, Clone, PartialEq)]
pub struct Scenario {
    /// The mission the controller flies (used here for phases and the stop time).
    pub mission: MissionParams,
    /// End of the run (s).
    pub stop_time: f64,
    /// Communication step of the master (s).
    pub comm_step: f64,
    pub ordering: Ordering,
    pub wind: Wind,
    /// `(t, offset)`: from `t` on the reference offset is `offset` (NED, m).
    pub ref_offset_steps: Vec<(f64, Vector3<f64>)>,
    /// The wind of the plant outputs the controller samples (default: the current wind).
    pub measured_wind: MeasuredWind,
}

impl Scenario {
    /// The default mission flown by the reference master at `sample_time`.
    pub fn mission(mission: MissionParams) -> Self {
        Self {
            mission,
            stop_time: mission.end_time(),
            comm_step: mission.sample_time,
            ordering: Ordering::GaussSeidel,
            wind: Wind::Calm,
            ref_offset_steps: Vec::new(),
            measured_wind: MeasuredWind::Current,
        }
    }

    /// A violent manoeuvre for accuracy and speed checks: the fast mission (preset `fast`,
    /// T1 = 3 s, T2 = 4 s, α up to ≈ 44° on the LQR) with a 1 − cos
    /// gust of 6 m/s (north, up) over 2 s at t = 12 s and 5 m reference steps at 20 s and 23 s.
    pub fn violent_manoeuvre() -> Self {
        let mut s = Self::mission(MissionParams::fast());
        s.wind = Wind::OneMinusCosine {
            t_start: 12.0,
            duration: 2.0,
            amplitude: Vector3::new(6.0, 0.0, -6.0),
        };
        s.ref_offset_steps = vec![
            (20.0, Vector3::new(0.0, 5.0, 0.0)),
            (23.0, Vector3::new(5.0, 5.0, -5.0)),
        ];
        s
    }

    /// Reference offset at time `t`.
    pub fn ref_offset(&self, t: f64) -> Vector3<f64> {
        let mut offset = Vector3::zeros();
        for (t_step, value) in &self.ref_offset_steps {
            if t >= *t_step - EDGE_TOLERANCE {
                offset = *value;
            }
        }
        offset
    }
}

/// The closed loop at one communication point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    /// Time (s).
    pub t: f64,
    /// Plant state at `t`.
    pub x: StateVector,
    /// The plant's outputs at `t` (what the controller measured with perfect state).
    pub measurement: Measurement,
    /// Command the plant flies over [t, t + h).
    pub command: Command,
    /// Controller diagnostics of its sample at `t`.
    pub diagnostics: Diagnostics,
    /// Wind at `t` (m/s), NED.
    pub wind: Vector3<f64>,
    /// Pitch θ of the 3-2-1 Euler angles (rad) (well defined near 90°: from the DCM).
    pub theta: f64,
}

impl Sample {
    /// |position − reference position| (m).
    pub fn pos_error(&self) -> f64 {
        (self.measurement.pos_ned - self.diagnostics.ref_pos_ned).norm()
    }
}

/// The record of a run.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Trace {
    pub samples: Vec<Sample>,
    /// Why the run stopped before `stop_time`, if it did.
    pub failure: Option<String>,
    /// Warnings the controller raised (time, notice).
    pub notices: Vec<(f64, Notice)>,
}

/// Number of phase codes ([`flight_mission::Phase`]: the mission's five, take-off and landing).
pub const N_PHASES: usize = 11;

/// Position error statistics of one phase.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PhaseErrors {
    pub samples: usize,
    /// Maximum position error (m).
    pub max: f64,
    /// RMS position error (m).
    pub rms: f64,
}

impl Trace {
    /// Whether the run reached its stop time.
    pub fn completed(&self) -> bool {
        self.failure.is_none()
    }

    /// Position-error statistics per phase, indexed by the phase code (0…4 the thesis's
    /// mission, 5…10 take-off and landing, [`flight_mission::Phase`]).
    pub fn phase_errors(&self) -> [PhaseErrors; N_PHASES] {
        let mut out = [PhaseErrors::default(); N_PHASES];
        let mut sums = [0.0; N_PHASES];
        for s in &self.samples {
            let k = s.diagnostics.phase as usize;
            let e = s.pos_error();
            out[k].samples += 1;
            out[k].max = out[k].max.max(e);
            sums[k] += e * e;
        }
        for (o, sum) in out.iter_mut().zip(sums) {
            if o.samples > 0 {
                o.rms = (sum / o.samples as f64).sqrt();
            }
        }
        out
    }

    /// The run's completion as a table cell: `yes`, or `no: ` and the failure.
    pub fn completed_cell(&self) -> String {
        match &self.failure {
            None => "yes".to_string(),
            Some(f) => format!("no: {f}"),
        }
    }

    /// Maximum position error over the whole run (m).
    pub fn max_pos_error(&self) -> f64 {
        self.samples.iter().map(Sample::pos_error).fold(0.0, f64::max)
    }

    /// Samples with `t0 ≤ t < t1`.
    pub fn window(&self, t0: f64, t1: f64) -> impl Iterator<Item = &Sample> {
        self.samples
            .iter()
            .filter(move |s| s.t >= t0 - EDGE_TOLERANCE && s.t < t1 - EDGE_TOLERANCE)
    }

    /// Maximum angle of attack (rad) with `t0 ≤ t < t1`.
    pub fn max_alpha(&self, t0: f64, t1: f64) -> f64 {
        self.window(t0, t1)
            .map(|s| s.measurement.alpha)
            .fold(f64::NEG_INFINITY, f64::max)
    }
}

/// What [`MissionCheck`] needs of one communication point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CheckSample {
    /// Time (s).
    pub t: f64,
    /// Mission phase (0…4).
    pub phase: usize,
    /// |position − reference position| (m).
    pub pos_error: f64,
    /// Airspeed (m/s).
    pub airspeed: f64,
    /// Pitch θ (rad).
    pub theta: f64,
    /// Every value of the sample finite.
    pub finite: bool,
}

impl From<&Sample> for CheckSample {
    fn from(s: &Sample) -> Self {
        Self {
            t: s.t,
            phase: s.diagnostics.phase as usize,
            pos_error: s.pos_error(),
            airspeed: s.measurement.airspeed,
            theta: s.theta,
            finite: s.x.iter().all(|v| v.is_finite()) && s.command.is_finite(),
        }
    }
}

/// The acceptance criteria of the controller issues, evaluated on a trace.
#[derive(Debug, Clone, PartialEq)]
pub struct MissionCheck {
    /// Max |airspeed − v_level| over the last 5 s of level flight (m/s).
    pub level_airspeed_error: f64,
    /// Max |θ − θ_trim| over the last 5 s of level flight (rad).
    pub level_pitch_error: f64,
    /// |θ − 90°| at the end (rad).
    pub final_pitch_error: f64,
    /// Every sampled value finite.
    pub all_finite: bool,
    /// Per-phase position errors.
    pub phase_errors: [PhaseErrors; 5],
}

impl MissionCheck {
    /// Evaluate `trace` of `mission`; `theta_level_trim` is the plant's trimmed
    /// pitch in level flight at `v_level` (rad).
    pub fn of(trace: &Trace, mission: &MissionParams, theta_level_trim: f64) -> Self {
        let samples: Vec<CheckSample> = trace.samples.iter().map(CheckSample::from).collect();
        Self::of_samples(&samples, mission, theta_level_trim)
    }

    /// The same on the recorded values alone (a trajectory from any master; the Python
    /// `tailsim.metrics.mission_check` mirrors this line by line).
    pub fn of_samples(samples: &[CheckSample], mission: &MissionParams, theta_level_trim: f64) -> Self {
        let s = mission.phase_starts();
        let (t0, t1) = ((s[3] - Criteria::get().level_window).max(s[2]), s[3]);
        let mut level_airspeed_error: f64 = 0.0;
        let mut level_pitch_error: f64 = 0.0;
        for sample in samples
            .iter()
            .filter(|x| x.t >= t0 - EDGE_TOLERANCE && x.t < t1 - EDGE_TOLERANCE)
        {
            level_airspeed_error = level_airspeed_error.max((sample.airspeed - mission.v_level).abs());
            level_pitch_error = level_pitch_error.max((sample.theta - theta_level_trim).abs());
        }
        let final_pitch_error = samples
            .last()
            .map_or(f64::INFINITY, |s| (s.theta - std::f64::consts::FRAC_PI_2).abs());
        let mut phase_errors = [PhaseErrors::default(); 5];
        let mut sums = [0.0; 5];
        for x in samples {
            let k = x.phase.min(4);
            phase_errors[k].samples += 1;
            phase_errors[k].max = phase_errors[k].max.max(x.pos_error);
            sums[k] += x.pos_error * x.pos_error;
        }
        for (o, sum) in phase_errors.iter_mut().zip(sums) {
            if o.samples > 0 {
                o.rms = (sum / o.samples as f64).sqrt();
            }
        }
        Self {
            level_airspeed_error,
            level_pitch_error,
            final_pitch_error,
            all_finite: samples.iter().all(|x| x.finite),
            phase_errors,
        }
    }

    /// [`Self::passed`] as a table cell: `pass` or `fail`.
    pub fn verdict(&self) -> &'static str {
        if self.passed() {
            "pass"
        } else {
            "fail"
        }
    }

    /// The issue's criteria ([`Criteria`]: airspeed within 1 m/s and pitch within 5° over
    /// the last 5 s of level flight, within 10° of vertical at the end), all finite.
    pub fn passed(&self) -> bool {
        let c = Criteria::get();
        self.all_finite
            && self.level_airspeed_error <= c.level_airspeed_error_max
            && self.level_pitch_error <= c.level_pitch_error_max
            && self.final_pitch_error <= c.final_pitch_error_max
    }
}

impl std::fmt::Display for MissionCheck {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        writeln!(
            f,
            "level: airspeed err {:.3} m/s, pitch err {:.2} deg; final pitch err {:.2} deg; finite {}",
            self.level_airspeed_error,
            self.level_pitch_error.to_degrees(),
            self.final_pitch_error.to_degrees(),
            self.all_finite
        )?;
        const NAMES: [&str; 5] = ["vertical 1", "transition 1", "level", "transition 2", "vertical 2"];
        for (name, e) in NAMES.iter().zip(self.phase_errors.iter()) {
            writeln!(
                f,
                "  {name:>12}: max {:.3} m, rms {:.3} m ({} samples)",
                e.max, e.rms, e.samples
            )?;
        }
        Ok(())
    }
}

/// Pitch θ (3-2-1) of a plant state ([`tailsitter_physics::pitch_321`]).
pub fn pitch(x: &StateVector) -> f64 {
    tailsitter_physics::pitch_321(&x.fixed_rows::<4>(idx::Q1).into_owned())
}

/// Fly `controller` with `plant` from state `x0` through `scenario`.
///
/// Timing (docs/DESIGN.md §2): at each communication point t the controller is
/// handed the plant outputs at t; it samples when its own clock is due (here:
/// every multiple of `mission.sample_time`, the first at t = 0) and holds its
/// command otherwise. The plant then advances over [t, t + h) with the
/// command of this sample (Gauss-Seidel) or of the previous communication
/// point (Jacobi). The run stops early, with `failure` set, if the
/// controller fails or the plant leaves its envelope.
pub fn fly<C: FlightController>(plant: &Plant, x0: StateVector, controller: &mut C, scenario: &Scenario) -> Trace {
    fly_with(plant, x0, controller, scenario, &mut Perfect, |_| false)
}

/// What the controller is handed at each communication point: the plant's outputs
/// ([`Perfect`]) or an estimate of them ([`avionics::AvionicsSource`]: sensors and estimator).
pub trait StateSource {
    /// The controller's measurement at `t` (step `h`); `truth` is the plant's outputs at `t`
    /// (state `x`, inputs `u`, the wind of the plant outputs `wind`).
    #[allow(clippy::too_many_arguments)]
    fn measure(
        &mut self,
        t: f64,
        h: f64,
        plant: &Plant,
        x: &StateVector,
        u: &InputVector,
        wind: &Vector3<f64>,
        truth: &Measurement,
    ) -> Result<Measurement, String>;

    /// After the controller's sample at `t`: the command the plant flies over [t, t + h).
    fn flown(&mut self, t: f64, h: f64, command: &Command) -> Result<(), String>;
}

/// The controller measures the plant's outputs (perfect state).
#[derive(Debug, Clone, Copy, Default)]
pub struct Perfect;

impl StateSource for Perfect {
    fn measure(
        &mut self,
        _t: f64,
        _h: f64,
        _plant: &Plant,
        _x: &StateVector,
        _u: &InputVector,
        _wind: &Vector3<f64>,
        truth: &Measurement,
    ) -> Result<Measurement, String> {
        Ok(*truth)
    }

    fn flown(&mut self, _t: f64, _h: f64, _command: &Command) -> Result<(), String> {
        Ok(())
    }
}

/// [`fly`] with the controller measuring through `state_source`, stopping early (completed) after
/// the first recorded sample for which `stop` is true. The trace records the truth (the
/// plant's outputs) as each sample's `measurement`, whatever the controller measured.
pub fn fly_with<C: FlightController, S: StateSource>(
    plant: &Plant,
    x0: StateVector,
    controller: &mut C,
    scenario: &Scenario,
    state_source: &mut S,
    mut stop: impl FnMut(&Sample) -> bool,
) -> Trace {
    let h = scenario.comm_step;
    let n = (scenario.stop_time / h).round() as usize;
    let mut trace = Trace {
        samples: Vec::with_capacity(n + 1),
        failure: None,
        notices: Vec::new(),
    };
    let mut clock = flight_mission::SampleClock::new(scenario.mission.sample_time, 0.0);
    let mut x = x0;
    // The gear's friction memory (stick-slip anchors), flown with the state.
    let mut anchors = tailsitter_physics::ContactAnchors::FREE;
    anchors.update(&plant.ground, &plant.airframe, &x);
    let mut held: Option<flight_mission::ControllerOutput> = None;
    let mut previous_command: Option<Command> = None;
    let mut source = match WindSource::new(scenario, plant, &x0) {
        Ok(s) => s,
        Err(e) => {
            trace.failure = Some(e);
            return trace;
        }
    };
    for k in 0..=n {
        let t = k as f64 * h;
        let u_now = previous_command
            .map(|c| plant_inputs(&c))
            .unwrap_or_else(InputVector::zeros);
        let (wind, measured_wind) = match source.at(k, t, h, plant, &x, &u_now) {
            Ok(w) => (w.flown, w.measured),
            Err(e) => {
                trace.failure = Some(e);
                break;
            }
        };
        // The plant's outputs with the gear's anchors (its specific force on the ground).
        let measurement =
            flight_mission::measurement(&x, &plant.outputs_in_contact(&x, &anchors, &u_now, &measured_wind));
        let measured = match state_source.measure(t, h, plant, &x, &u_now, &measured_wind, &measurement) {
            Ok(m) => m,
            Err(e) => {
                trace.failure = Some(e);
                break;
            }
        };
        if clock.take(t) || held.is_none() {
            let input = ControllerInput {
                t,
                measurement: measured,
                ref_offset_ned: scenario.ref_offset(t),
            };
            match controller.sample(&input) {
                Ok(out) => {
                    if let Some(notice) = out.notice {
                        trace.notices.push((t, notice));
                    }
                    if !out.command.is_finite() {
                        trace.failure = Some(format!("controller returned a non-finite command at t = {t}"));
                        break;
                    }
                    held = Some(out);
                }
                Err(e) => {
                    trace.failure = Some(format!("controller failed at t = {t}: {e}"));
                    break;
                }
            }
        }
        let out = held.expect("set above");
        let flown = match scenario.ordering {
            Ordering::GaussSeidel => out.command,
            Ordering::Jacobi => previous_command.unwrap_or(out.command),
        };
        trace.samples.push(Sample {
            t,
            x,
            measurement,
            command: flown,
            diagnostics: out.diagnostics,
            wind,
            theta: pitch(&x),
        });
        previous_command = Some(out.command);
        if k == n || stop(trace.samples.last().expect("pushed above")) {
            break;
        }
        if let Err(e) = state_source.flown(t, h, &flown) {
            trace.failure = Some(e);
            break;
        }
        if let Err(e) = plant.advance_in_contact(&mut x, &mut anchors, &plant_inputs(&flown), &wind, h) {
            trace.failure = Some(format!("plant failed after t = {t}: {e}"));
            break;
        }
    }
    trace
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gust_shape() {
        let g = Wind::OneMinusCosine {
            t_start: 1.0,
            duration: 2.0,
            amplitude: Vector3::new(4.0, 0.0, 0.0),
        };
        assert_eq!(g.at(0.5), Vector3::zeros());
        assert!((g.at(2.0).x - 4.0).abs() < 1e-12);
        assert!((g.at(1.5).x - 2.0).abs() < 1e-12);
        assert_eq!(g.at(3.5), Vector3::zeros());
    }

    #[test]
    fn steady_and_gust_is_the_sum() {
        let steady = Vector3::new(1.0, -2.0, 0.0);
        let w = Wind::SteadyAndGust {
            steady,
            t_start: 1.0,
            duration: 2.0,
            amplitude: Vector3::new(4.0, 0.0, -1.0),
        };
        assert_eq!(w.at(0.5), steady);
        assert_eq!(w.at(3.5), steady);
        // mid-gust: the full amplitude on top of the steady wind
        assert!((w.at(2.0) - Vector3::new(5.0, -2.0, -1.0)).norm() < 1e-12);
        assert!((w.at(1.5) - Vector3::new(3.0, -2.0, -0.5)).norm() < 1e-12);
    }

    #[test]
    fn wind_from_bearings() {
        // From the east: blows towards the west.
        let e = wind_from(std::f64::consts::FRAC_PI_2, 5.0);
        assert!((e - Vector3::new(0.0, -5.0, 0.0)).norm() < 1e-12);
        let n = wind_from(0.0, 3.0);
        assert_eq!(n, Vector3::new(-3.0, 0.0, 0.0));
        let sw = wind_from(225f64.to_radians(), 2f64.sqrt());
        assert!((sw - Vector3::new(1.0, 1.0, 0.0)).norm() < 1e-12);
        assert_eq!(Wind::step_from(1.0, 0.0, 3.0).at(1.0), n);
        assert_eq!(Wind::step_from(1.0, 0.0, 3.0).at(0.5), Vector3::zeros());
        let g = Wind::gust_along(1, 5.0, 2.0, 2.0);
        assert_eq!(g.at(3.0), Vector3::new(0.0, 5.0, 0.0));
    }

    #[test]
    fn criteria_file_parses_to_the_issue_values() {
        let c = Criteria::get();
        assert_eq!(c.level_window, 5.0);
        assert_eq!(c.level_airspeed_error_max, 1.0);
        assert!((c.level_pitch_error_max - 5.0 * std::f64::consts::PI / 180.0).abs() < 1e-15);
        assert!((c.final_pitch_error_max - 10.0 * std::f64::consts::PI / 180.0).abs() < 1e-15);
        assert_eq!(c.edge_tolerance, EDGE_TOLERANCE);
        assert!(Criteria::parse(&CRITERIA_JSON.replace("\"deg\"", "\"rad\"")).is_err());
    }

    #[test]
    fn step_edges_use_the_shared_tolerance() {
        let h = 0.02;
        let w = Wind::Step {
            t_start: 2.1,
            wind: Vector3::new(1.0, 0.0, 0.0),
        };
        // 105 · 0.02 = 2.1000000000000001 in floating point, 2.1 − 1e-12 just below.
        assert_eq!(w.at(105.0 * h).x, 1.0);
        assert_eq!(w.at(2.1 - 1e-12).x, 1.0);
        assert_eq!(w.at(2.1 - 1e-6).x, 0.0);
        let mut s = Scenario::mission(MissionParams::default());
        s.ref_offset_steps = vec![(2.1, Vector3::new(5.0, 0.0, 0.0))];
        for t in [2.1 - 1e-12, 2.1 - 1e-6, 104.0 * h, 105.0 * h] {
            assert_eq!(s.ref_offset(t).x, 5.0 * w.at(t).x, "t = {t}");
        }
    }

    #[test]
    fn offsets_hold_from_their_time() {
        let mut s = Scenario::mission(MissionParams::default());
        s.ref_offset_steps = vec![(2.0, Vector3::new(5.0, 0.0, 0.0)), (4.0, Vector3::new(0.0, 5.0, 0.0))];
        assert_eq!(s.ref_offset(1.0), Vector3::zeros());
        assert_eq!(s.ref_offset(2.0).x, 5.0);
        assert_eq!(s.ref_offset(5.0), Vector3::new(0.0, 5.0, 0.0));
    }
}
