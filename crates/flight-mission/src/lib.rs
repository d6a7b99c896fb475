//! The mission of the thesis (vertical → level → vertical, §3.3 / §4.3.3) and the
//! interface every tail-sitter controller implements, independent of FMI.
//!
//! Frames: positions and velocities in the NED earth frame unless named `_body`
//! (body axes: x forward through the nose, y right wing, z down). Units SI, angles rad.
//!
//! A controller is a plain struct implementing [`FlightController`]: it is
//! handed a [`ControllerInput`] at every sample and returns a
//! [`ControllerOutput`]. The FMU crates only map FMU variables to these types
//! and use [`SampleClock`] for the zero-order hold.

use nalgebra::{Vector3, Vector4};
use std::fmt;

mod unit;
pub use unit::{HeldOutput, SampledUnit};

/// Mission parameters (DESIGN.md §3), the same names and defaults in both controllers.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MissionParams {
    /// Vertical climb before the first transition [s].
    pub t_vertical_1: f64,
    /// T1, duration of the transition vertical → level [s].
    pub t_transition_1: f64,
    /// Level flight [s].
    pub t_level: f64,
    /// T2, duration of the transition level → vertical [s].
    pub t_transition_2: f64,
    /// Vertical flight after the second transition [s].
    pub t_vertical_2: f64,
    /// V_L, level-flight airspeed [m/s].
    pub v_level: f64,
    /// V_V, vertical climb speed [m/s].
    pub v_vertical: f64,
    /// Controller sample period T_s [s] (§3.2.4).
    pub sample_time: f64,
}

impl Default for MissionParams {
    fn default() -> Self {
        Self {
            t_vertical_1: 5.0,
            t_transition_1: 5.0,
            t_level: 10.0,
            t_transition_2: 10.0,
            t_vertical_2: 5.0,
            v_level: 25.0,
            v_vertical: 3.0,
            sample_time: 0.02,
        }
    }
}

/// A parameter that is not acceptable, with the reason.
#[derive(Debug, Clone, PartialEq)]
pub struct ParamError(pub String);

impl fmt::Display for ParamError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for ParamError {}

impl MissionParams {
    /// Every duration finite and non-negative, transitions and sample time positive,
    /// `v_level > v_vertical ≥ 0`.
    pub fn validate(&self) -> Result<(), ParamError> {
        let named = [
            ("t_vertical_1", self.t_vertical_1),
            ("t_transition_1", self.t_transition_1),
            ("t_level", self.t_level),
            ("t_transition_2", self.t_transition_2),
            ("t_vertical_2", self.t_vertical_2),
            ("v_level", self.v_level),
            ("v_vertical", self.v_vertical),
            ("sample_time", self.sample_time),
        ];
        for (name, value) in named {
            if !value.is_finite() || value < 0.0 {
                return Err(ParamError(format!("{name} = {value}: must be finite and ≥ 0")));
            }
        }
        for (name, value) in [
            ("t_transition_1", self.t_transition_1),
            ("t_transition_2", self.t_transition_2),
        ] {
            if value <= 0.0 {
                return Err(ParamError(format!(
                    "{name} = {value}: a transition needs a positive duration"
                )));
            }
        }
        if self.sample_time <= 0.0 {
            return Err(ParamError(format!("sample_time = {}: must be > 0", self.sample_time)));
        }
        if self.v_level <= self.v_vertical {
            return Err(ParamError(format!(
                "v_level = {} must exceed v_vertical = {}",
                self.v_level, self.v_vertical
            )));
        }
        Ok(())
    }

    /// Start time of each phase, in [`Phase`] order, and the end of the mission.
    pub fn phase_starts(&self) -> [f64; 6] {
        let t1 = self.t_vertical_1;
        let t2 = t1 + self.t_transition_1;
        let t3 = t2 + self.t_level;
        let t4 = t3 + self.t_transition_2;
        let t5 = t4 + self.t_vertical_2;
        [0.0, t1, t2, t3, t4, t5]
    }

    /// Nominal end of the mission [s]; the last phase continues after it.
    pub fn end_time(&self) -> f64 {
        self.phase_starts()[5]
    }

    /// The phase flown at mission time `t` and the time since that phase began.
    /// Before 0 it is the first vertical phase; after the end the last one.
    pub fn phase_at(&self, t: f64) -> (Phase, f64) {
        let s = self.phase_starts();
        let phase = if t < s[1] {
            Phase::Vertical1
        } else if t < s[2] {
            Phase::TransitionToLevel
        } else if t < s[3] {
            Phase::Level
        } else if t < s[4] {
            Phase::TransitionToVertical
        } else {
            Phase::Vertical2
        };
        (phase, t - s[phase as usize])
    }
}

/// Flight phase of the mission; the discriminant is the `phase` output of the FMUs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Phase {
    /// Vertical climb at `v_vertical`.
    Vertical1 = 0,
    /// T1: vertical → level.
    TransitionToLevel = 1,
    /// Level flight at `v_level`.
    Level = 2,
    /// T2: level → vertical.
    TransitionToVertical = 3,
    /// Vertical flight after the mission's second transition.
    Vertical2 = 4,
}

impl Phase {
    /// The integer of the `phase` output.
    pub fn code(self) -> i32 {
        self as i32
    }

    /// The phase of a `phase` output value, if valid.
    pub fn from_code(code: i32) -> Option<Self> {
        Some(match code {
            0 => Phase::Vertical1,
            1 => Phase::TransitionToLevel,
            2 => Phase::Level,
            3 => Phase::TransitionToVertical,
            4 => Phase::Vertical2,
            _ => return None,
        })
    }

    /// Whether the aircraft hangs on its propellers in this phase.
    pub fn is_vertical(self) -> bool {
        matches!(self, Phase::Vertical1 | Phase::Vertical2)
    }
}

/// The `phase` output.
impl From<Phase> for i32 {
    fn from(phase: Phase) -> i32 {
        phase.code()
    }
}

/// What a controller measures: the plant outputs of the same names (DESIGN.md §2).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Measurement {
    /// NED position of the CG [m] (`pos_n`, `pos_e`, `pos_d`).
    pub pos_ned: Vector3<f64>,
    /// Inertial velocity, earth axes [m/s] (`vel_n`, `vel_e`, `vel_d`).
    pub vel_ned: Vector3<f64>,
    /// Inertial velocity, body axes [m/s] (`u`, `v`, `w`).
    pub vel_body: Vector3<f64>,
    /// Body rates p, q, r [rad/s].
    pub rates: Vector3<f64>,
    /// Attitude quaternion (A.2.8), scalar part last (`quat_4`).
    pub quat: Vector4<f64>,
    /// Air-relative speed V̄ [m/s].
    pub airspeed: f64,
    /// Angle of attack α [rad] (2.2.12).
    pub alpha: f64,
    /// Sideslip β [rad] (2.2.13).
    pub beta: f64,
    /// Thrust state T [N].
    pub thrust: f64,
    /// Actual deflections δe, δa, δr, δfc, δfd, δv [rad].
    pub surfaces: [f64; 6],
    /// Specific force in body axes [m/s²] (`accel_x`, `accel_y`, `accel_z`).
    pub specific_force_body: Vector3<f64>,
    /// Propeller induced velocity w [m/s] (2.3.21).
    pub induced_velocity: f64,
}

impl Measurement {
    /// The name of the first non-finite value, if any.
    pub fn first_non_finite(&self) -> Option<&'static str> {
        const V3: [[&str; 3]; 5] = [
            ["pos_n", "pos_e", "pos_d"],
            ["vel_n", "vel_e", "vel_d"],
            ["u", "v", "w"],
            ["p", "q", "r"],
            ["accel_x", "accel_y", "accel_z"],
        ];
        let vectors = [
            &self.pos_ned,
            &self.vel_ned,
            &self.vel_body,
            &self.rates,
            &self.specific_force_body,
        ];
        for (vector, names) in vectors.iter().zip(V3.iter()) {
            for (value, name) in vector.iter().zip(names.iter()) {
                if !value.is_finite() {
                    return Some(name);
                }
            }
        }
        const QUAT: [&str; 4] = ["quat_1", "quat_2", "quat_3", "quat_4"];
        for (value, name) in self.quat.iter().zip(QUAT.iter()) {
            if !value.is_finite() {
                return Some(name);
            }
        }
        const SURFACES: [&str; 6] = [
            "elevator",
            "aileron",
            "rudder",
            "flap_collective",
            "flap_differential",
            "vertical_flap",
        ];
        for (value, name) in self.surfaces.iter().zip(SURFACES.iter()) {
            if !value.is_finite() {
                return Some(name);
            }
        }
        for (value, name) in [
            (self.airspeed, "airspeed"),
            (self.alpha, "alpha"),
            (self.beta, "beta"),
            (self.thrust, "thrust"),
            (self.induced_velocity, "induced_velocity"),
        ] {
            if !value.is_finite() {
                return Some(name);
            }
        }
        None
    }
}

/// Commands to the plant inputs of the same names (`thrust_cmd`, `elevator_cmd`, …).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Command {
    /// Total commanded thrust T_c [N] (2.3.16).
    pub thrust: f64,
    /// δe [rad].
    pub elevator: f64,
    /// δa [rad].
    pub aileron: f64,
    /// δr [rad].
    pub rudder: f64,
    /// δfc [rad].
    pub flap_collective: f64,
    /// δfd [rad].
    pub flap_differential: f64,
    /// δv [rad].
    pub vertical_flap: f64,
}

impl Command {
    /// Whether every command is finite.
    pub fn is_finite(&self) -> bool {
        [
            self.thrust,
            self.elevator,
            self.aileron,
            self.rudder,
            self.flap_collective,
            self.flap_differential,
            self.vertical_flap,
        ]
        .iter()
        .all(|x| x.is_finite())
    }
}

/// Everything a controller is handed at a sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ControllerInput {
    /// Mission time of the sample [s].
    pub t: f64,
    /// The measured plant outputs.
    pub measurement: Measurement,
    /// `ref_offset_n/e/d`: added to the reference position [m], NED.
    pub ref_offset_ned: Vector3<f64>,
}

/// Diagnostic outputs, the same in both controllers (DESIGN.md §2).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Diagnostics {
    /// Reference position including the offset [m], NED.
    pub ref_pos_ned: Vector3<f64>,
    /// Reference airspeed [m/s].
    pub ref_airspeed: f64,
    /// Current mission phase.
    pub phase: Phase,
    /// |measured − reference| position [m].
    pub pos_error: f64,
}

/// A condition a controller reports through the FMI logger as a warning; the
/// command is still valid (finite and within limits).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Notice {
    /// A gain computation failed; the last good gains are used.
    GainFallback(&'static str),
    /// A command reached its limit (name of the command).
    Saturated(&'static str),
}

/// |a − b| without overflow: a scaled Euclidean norm, finite for any finite
/// inputs (|d| up to f64::MAX · √3), so a diagnostic never turns infinite.
pub fn distance(a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    let d = a - b;
    let m = d.amax();
    if m == 0.0 || !m.is_finite() {
        return if m.is_nan() { f64::NAN } else { m };
    }
    let n = m * (d / m).norm();
    if n.is_finite() {
        n
    } else {
        f64::MAX
    }
}

/// What a controller returns at a sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ControllerOutput {
    pub command: Command,
    pub diagnostics: Diagnostics,
    /// At most one notice per sample (no allocation in the sample path).
    pub notice: Option<Notice>,
}

impl HeldOutput for ControllerOutput {
    const SAVED_LEN: usize = 13;

    /// Command and diagnostics (the notice is transient and not saved).
    fn save(&self, out: &mut impl FnMut(f64)) {
        let c = &self.command;
        let d = &self.diagnostics;
        for x in [
            c.thrust,
            c.elevator,
            c.aileron,
            c.rudder,
            c.flap_collective,
            c.flap_differential,
            c.vertical_flap,
            d.ref_pos_ned.x,
            d.ref_pos_ned.y,
            d.ref_pos_ned.z,
            d.ref_airspeed,
            d.pos_error,
            f64::from(d.phase.code()),
        ] {
            out(x);
        }
    }

    /// `None` if values are missing or the phase is invalid.
    fn restore(next: &mut impl FnMut() -> Option<f64>) -> Option<Self> {
        let mut v = [0.0; Self::SAVED_LEN];
        for x in v.iter_mut() {
            *x = next()?;
        }
        let phase = if v[12].fract() == 0.0 {
            Phase::from_code(v[12] as i32)?
        } else {
            return None;
        };
        Some(Self {
            command: Command {
                thrust: v[0],
                elevator: v[1],
                aileron: v[2],
                rudder: v[3],
                flap_collective: v[4],
                flap_differential: v[5],
                vertical_flap: v[6],
            },
            diagnostics: Diagnostics {
                ref_pos_ned: Vector3::new(v[7], v[8], v[9]),
                ref_airspeed: v[10],
                phase,
                pos_error: v[11],
            },
            notice: None,
        })
    }

    fn notice(&self) -> Option<Notice> {
        self.notice
    }
}

/// A failure that leaves the controller without a valid command.
#[derive(Debug, Clone, PartialEq)]
pub struct ControlError(pub String);

impl fmt::Display for ControlError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for ControlError {}

/// A tail-sitter flight controller: a [`SampledUnit`] from the measured plant
/// outputs to the commands (plain state, no middleware). Implemented for every
/// sampled unit with these input and output types.
pub trait FlightController: SampledUnit<Input = ControllerInput, Output = ControllerOutput> {}

impl<T: SampledUnit<Input = ControllerInput, Output = ControllerOutput>> FlightController for T {}

#[doc(hidden)]
pub use nalgebra;

/// Zero-order hold of a sampled controller inside a co-simulation step:
/// samples are due at the multiples of `sample_time`.
///
/// A master calling `doStep(t, h)` gives the controller the inputs at `t`; the
/// controller samples when `t` has reached the next multiple of `sample_time`
/// (within a relative tolerance, so `0.1 = 5 × 0.02` counts), and the command
/// is held until the next sample. With `h` larger than `sample_time` one
/// sample is taken per step (the inputs exist only at `t`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SampleClock {
    sample_time: f64,
    next_index: u64,
}

impl SampleClock {
    /// A clock whose first sample is due at `start_time` (rounded up to a multiple).
    pub fn new(sample_time: f64, start_time: f64) -> Self {
        let mut clock = Self {
            sample_time,
            next_index: 0,
        };
        clock.next_index = clock.index_at_or_after(start_time);
        clock
    }

    fn tolerance(&self) -> f64 {
        1e-6 * self.sample_time
    }

    fn index_at_or_after(&self, t: f64) -> u64 {
        let k = ((t - self.tolerance()) / self.sample_time).ceil();
        if k.is_finite() && k > 0.0 {
            k as u64
        } else {
            0
        }
    }

    /// Time of the next due sample.
    pub fn next_sample_time(&self) -> f64 {
        self.next_index as f64 * self.sample_time
    }

    /// Whether a sample is due at `t`; if so the clock moves to the first
    /// multiple of `sample_time` after `t`.
    pub fn take(&mut self, t: f64) -> bool {
        if t + self.tolerance() >= self.next_sample_time() {
            self.next_index = self
                .index_at_or_after(t + 0.5 * self.sample_time)
                .max(self.next_index + 1);
            true
        } else {
            false
        }
    }

    /// Internal state for FMU-state serialisation.
    pub fn next_index(&self) -> u64 {
        self.next_index
    }

    /// Restore what [`Self::next_index`] returned.
    pub fn set_next_index(&mut self, next_index: u64) {
        self.next_index = next_index;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_mission_phases() {
        let m = MissionParams::default();
        assert!(m.validate().is_ok());
        assert_eq!(m.end_time(), 35.0);
        assert_eq!(m.phase_at(0.0).0, Phase::Vertical1);
        assert_eq!(m.phase_at(4.999).0, Phase::Vertical1);
        let (p, dt) = m.phase_at(7.0);
        assert_eq!(p, Phase::TransitionToLevel);
        assert!((dt - 2.0).abs() < 1e-12);
        assert_eq!(m.phase_at(12.0).0, Phase::Level);
        assert_eq!(m.phase_at(25.0).0, Phase::TransitionToVertical);
        assert_eq!(m.phase_at(31.0).0, Phase::Vertical2);
        assert_eq!(m.phase_at(100.0).0, Phase::Vertical2);
    }

    #[test]
    fn held_output_round_trips() {
        let output = ControllerOutput {
            command: Command {
                thrust: 50.0,
                vertical_flap: -0.2,
                ..Default::default()
            },
            diagnostics: Diagnostics {
                ref_pos_ned: Vector3::new(1.0, 2.0, 3.0),
                ref_airspeed: 25.0,
                phase: Phase::Level,
                pos_error: 0.5,
            },
            notice: None,
        };
        let mut saved = Vec::new();
        output.save(&mut |x| saved.push(x));
        assert_eq!(saved.len(), ControllerOutput::SAVED_LEN);
        let mut it = saved.clone().into_iter();
        assert_eq!(ControllerOutput::restore(&mut || it.next()), Some(output));
        saved[12] = 7.0;
        let mut it = saved.clone().into_iter();
        assert_eq!(ControllerOutput::restore(&mut || it.next()), None, "invalid phase");
        let mut it = saved[..5].iter().copied();
        assert_eq!(ControllerOutput::restore(&mut || it.next()), None, "truncated");
    }

    /// Regression (fuzzing): huge but finite positions made `pos_error` infinite.
    #[test]
    fn distance_never_overflows() {
        let a = Vector3::new(1e300, -1e300, 1e300);
        let d = distance(&a, &Vector3::zeros());
        assert!(d.is_finite() && (d / 1e300 - 3f64.sqrt()).abs() < 1e-12);
        assert_eq!(distance(&Vector3::new(3.0, 4.0, 0.0), &Vector3::zeros()), 5.0);
        assert_eq!(distance(&a, &a), 0.0);
        assert_eq!(
            distance(&Vector3::new(f64::MAX, -f64::MAX, 0.0), &Vector3::zeros()),
            f64::MAX
        );
    }

    #[test]
    fn invalid_missions_are_named() {
        let m = MissionParams {
            sample_time: 0.0,
            ..Default::default()
        };
        assert!(m.validate().unwrap_err().0.contains("sample_time"));
        let m = MissionParams {
            t_level: f64::NAN,
            ..Default::default()
        };
        assert!(m.validate().unwrap_err().0.contains("t_level"));
        let m = MissionParams {
            v_level: 2.0,
            ..Default::default()
        };
        assert!(m.validate().unwrap_err().0.contains("v_level"));
    }

    fn samples(h: f64, until: f64) -> Vec<f64> {
        let mut clock = SampleClock::new(0.02, 0.0);
        let mut out = Vec::new();
        let n = (until / h).round() as usize;
        for i in 0..n {
            let t = i as f64 * h;
            if clock.take(t) {
                out.push(t);
            }
        }
        out
    }

    #[test]
    fn clock_samples_at_multiples_whatever_the_step() {
        let fine = samples(0.001, 0.2);
        assert_eq!(fine.len(), 10);
        for (k, t) in fine.iter().enumerate() {
            assert!((t - 0.02 * k as f64).abs() < 1e-9, "{t}");
        }
        assert_eq!(samples(0.02, 0.2), fine);
        assert_eq!(samples(0.02, 0.2).len(), 10);
        assert_eq!(samples(0.005, 0.2).len(), 10);
        // Coarser than the sample time: one sample per step.
        assert_eq!(samples(0.05, 0.2).len(), 4);
        // A step not dividing the sample time: samples at the first point at or after each multiple.
        let odd = samples(0.003, 0.06);
        assert_eq!(odd.len(), 3);
        assert!((odd[1] - 0.021).abs() < 1e-9, "{odd:?}");
    }
}
