//! The interface of every sampled unit of the co-simulation: the controllers
//! today, the sensor model and the estimator tomorrow (docs/DESIGN.md §2, §7).
//!
//! A sampled unit is plain Rust: built from its parameters ([`SampledUnit::build`],
//! an invalid one is a [`ParamError`] naming it), sampled every
//! [`SampledUnit::sample_time`] ([`SampledUnit::sample`]), and its internal state
//! saved to and restored from a sequence of f64s ([`SampledUnit::save`],
//! [`SampledUnit::restore`]). Its output is held between samples
//! ([`HeldOutput`]). `controller-fmu` turns any such unit into an FMU with one
//! generic adapter; `closed-loop` and `analysis` fly and linearise any
//! [`crate::FlightController`] through the same trait.

use crate::{ControlError, Notice, ParamError, SampleClock};
use std::fmt;

/// The value a sampled unit returns at a sample and a master holds until the
/// next one: saved in FMU states with the unit.
pub trait HeldOutput: Copy + Send + 'static {
    /// Number of values [`Self::save`] writes.
    const SAVED_LEN: usize;
    /// Write the output as f64s (a transient notice is not saved).
    fn save(&self, out: &mut impl FnMut(f64));
    /// Read back what [`Self::save`] wrote; `None` if values are missing or invalid.
    fn restore(next: &mut impl FnMut() -> Option<f64>) -> Option<Self>;
    /// A condition to report as a warning for this sample, if any.
    fn notice(&self) -> Option<Notice>;
}

/// A discrete-time unit: built from its parameters, sampled at the multiples of
/// its sample time, with an internal state that can be saved and restored.
pub trait SampledUnit: Clone + Send + 'static {
    /// Everything the unit is built from (its FMU parameters, the model it uses).
    type Config: Clone + PartialEq + Send + 'static;
    /// What the unit is handed at a sample.
    type Input;
    /// What it returns at a sample.
    type Output: HeldOutput;

    /// A unit in its initial state; an invalid parameter is an error naming it.
    fn build(config: &Self::Config) -> Result<Self, ParamError>;

    /// Sample period of a unit built from `config` (s).
    fn sample_time(config: &Self::Config) -> f64;

    /// The output for the sample at the input's time, updating the internal state
    /// as if one sample period passed since the previous call. Must return
    /// finite values or an error; must not allocate on success.
    fn sample(&mut self, input: &Self::Input) -> Result<Self::Output, ControlError>;

    /// Append the internal state (everything [`Self::sample`] depends on besides
    /// the configuration) as f64s.
    fn save(&self, out: &mut impl FnMut(f64));

    /// Restore what [`Self::save`] wrote into a unit built from the same
    /// configuration; `None` from `next` means a truncated state.
    fn restore(&mut self, next: &mut impl FnMut() -> Option<f64>) -> Result<(), ControlError>;

    /// Number of values [`Self::save`] writes.
    fn saved_len(&self) -> usize {
        let mut n = 0;
        self.save(&mut |_| n += 1);
        n
    }
}

/// Where a unit reports conditions while it starts or steps: the FMU adapter
/// forwards them to the FMI logger (categories `logStatusWarning`, `logStatusError`).
pub trait UnitLog {
    /// A condition the master should know of; the step still succeeds.
    fn warning(&mut self, message: fmt::Arguments<'_>);
    /// A failure the unit recovered from; the step still succeeds.
    fn error(&mut self, message: fmt::Arguments<'_>);
}

/// A co-simulation unit as the master sees it (docs/DESIGN.md §2, §7): built from
/// its parameters, started at the start time, advanced over communication steps
/// [t, t + h) with the inputs set for t, its outputs readable at any time, its
/// internal state saved as 64-bit words. `controller-fmu` turns any such unit into
/// an FMU with one adapter; a [`SampledUnit`] is one through [`Sampled`]; the
/// sensor model and the estimator implement it directly.
pub trait SteppedUnit: Clone + Send + 'static {
    /// Everything the unit is built from (its FMU parameters).
    type Config: Clone + PartialEq + Send + 'static;
    /// What the unit is handed at the start and at every step.
    type Input;
    /// What its output ports show.
    type Output;

    /// A unit in its initial state; an invalid parameter is an error naming it.
    fn build(config: &Self::Config) -> Result<Self, ParamError>;

    /// Start at `t0` from the inputs at `t0` (fmi2ExitInitializationMode); called on
    /// a freshly built unit. An error names what is wrong.
    fn start(&mut self, input: &Self::Input, t0: f64, log: &mut dyn UnitLog) -> Result<(), ControlError>;

    /// Advance over [t, t + h) with the inputs set for t. Must not allocate on success.
    fn step(&mut self, input: &Self::Input, t: f64, h: f64, log: &mut dyn UnitLog) -> Result<(), ControlError>;

    /// The outputs now; `None` before the start.
    fn output(&self) -> Option<Self::Output>;

    /// Append the internal state (everything [`Self::step`] depends on besides the
    /// configuration) as words; an f64 as its IEEE bits (bit-exact).
    fn save(&self, out: &mut impl FnMut(u64));

    /// Restore what [`Self::save`] wrote into a unit built from the same
    /// configuration; `None` from `next` means a truncated state.
    fn restore(&mut self, next: &mut impl FnMut() -> Option<u64>) -> Result<(), ControlError>;

    /// Number of words [`Self::save`] writes.
    fn saved_len(&self) -> usize {
        let mut n = 0;
        self.save(&mut |_| n += 1);
        n
    }
}

/// A [`SampledUnit`] as a [`SteppedUnit`]: samples at the multiples of its sample
/// time ([`SampleClock`]), the first at the start time, one sample per step at
/// most (the inputs exist only at t), and holds the output in between. Reports the
/// output's notices as warnings (a lasting saturation once).
///
/// Saved state: next sample index, held flag, the held output
/// ([`HeldOutput::SAVED_LEN`] values, zeros when none), saturation flag, the unit's values.
#[derive(Debug, Clone)]
pub struct Sampled<U: SampledUnit> {
    unit: U,
    clock: SampleClock,
    held: Option<U::Output>,
    /// The previous sample reported a saturation: warn only when one starts.
    saturated: bool,
}

impl<U: SampledUnit> Sampled<U> {
    /// The sampled unit.
    pub fn unit(&self) -> &U {
        &self.unit
    }

    fn sample(&mut self, input: &U::Input, t: f64, log: &mut dyn UnitLog) -> Result<(), ControlError> {
        let out = self
            .unit
            .sample(input)
            .map_err(|e| ControlError(format!("at t = {t} s: {e}")))?;
        self.saturated = log_notice(log, t, out.notice(), self.saturated);
        self.held = Some(out);
        Ok(())
    }
}

impl<U: SampledUnit> SteppedUnit for Sampled<U> {
    type Config = U::Config;
    type Input = U::Input;
    type Output = U::Output;

    fn build(config: &U::Config) -> Result<Self, ParamError> {
        Ok(Self {
            unit: U::build(config)?,
            clock: SampleClock::new(U::sample_time(config), 0.0),
            held: None,
            saturated: false,
        })
    }

    fn start(&mut self, input: &U::Input, t0: f64, log: &mut dyn UnitLog) -> Result<(), ControlError> {
        self.clock = SampleClock::new(self.clock.sample_time(), t0);
        self.held = None;
        self.saturated = false;
        let due = self.clock.take(t0);
        debug_assert!(due);
        self.sample(input, t0, log)
    }

    fn step(&mut self, input: &U::Input, t: f64, _h: f64, log: &mut dyn UnitLog) -> Result<(), ControlError> {
        if self.clock.take(t) || self.held.is_none() {
            self.sample(input, t, log)?;
        }
        Ok(())
    }

    fn output(&self) -> Option<U::Output> {
        self.held
    }

    fn save(&self, out: &mut impl FnMut(u64)) {
        out(self.clock.next_index());
        out(u64::from(self.held.is_some()));
        match &self.held {
            Some(h) => h.save(&mut |x| out(x.to_bits())),
            None => (0..U::Output::SAVED_LEN).for_each(|_| out(0)),
        }
        out(u64::from(self.saturated));
        self.unit.save(&mut |x| out(x.to_bits()));
    }

    fn restore(&mut self, next: &mut impl FnMut() -> Option<u64>) -> Result<(), ControlError> {
        let truncated = || ControlError("truncated state".into());
        let flag = |w: u64| match w {
            0 => Ok(false),
            1 => Ok(true),
            _ => Err(ControlError(format!("invalid flag {w}"))),
        };
        let next_index = next().ok_or_else(truncated)?;
        let has_held = flag(next().ok_or_else(truncated)?)?;
        let mut words = [0u64; 64];
        let words = &mut words[..U::Output::SAVED_LEN];
        for w in words.iter_mut() {
            *w = next().ok_or_else(truncated)?;
        }
        let mut values = words.iter().map(|w| f64::from_bits(*w));
        let held = match (has_held, U::Output::restore(&mut || values.next())) {
            (false, _) => None,
            (true, Some(h)) => Some(h),
            (true, None) => {
                return Err(ControlError(
                    "held output: invalid value (e.g. phase out of range)".into(),
                ))
            }
        };
        let saturated = flag(next().ok_or_else(truncated)?)?;
        self.unit.restore(&mut || next().map(f64::from_bits))?;
        self.clock.set_next_index(next_index);
        self.held = held;
        self.saturated = saturated;
        Ok(())
    }
}

/// Log a unit's notice as a warning; `was_saturated` (the previous sample's
/// saturation) keeps a lasting saturation to one message.
/// Returns whether this sample is saturated.
fn log_notice(log: &mut dyn UnitLog, t: f64, notice: Option<Notice>, was_saturated: bool) -> bool {
    match notice {
        Some(Notice::GainFallback(why)) => log.warning(format_args!(
            "t = {t} s: gain computation failed ({why}); using the last good gains"
        )),
        Some(Notice::Saturated(name)) if !was_saturated => log.warning(format_args!(
            "t = {t} s: {name} saturated (not logged again until it ends)"
        )),
        _ => {}
    }
    matches!(notice, Some(Notice::Saturated(_)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Command, ControllerOutput, Diagnostics, Phase};

    /// Counts the warnings.
    #[derive(Default)]
    struct Count(usize);
    impl UnitLog for Count {
        fn warning(&mut self, _: fmt::Arguments<'_>) {
            self.0 += 1;
        }
        fn error(&mut self, _: fmt::Arguments<'_>) {
            self.0 += 1;
        }
    }

    #[test]
    fn lasting_saturation_is_logged_once() {
        let mut log = Count::default();
        let s = log_notice(&mut log, 0.0, Some(Notice::Saturated("thrust_cmd")), false);
        assert!(s && log.0 == 1);
        assert!(log_notice(&mut log, 0.02, Some(Notice::Saturated("thrust_cmd")), s));
        assert_eq!(log.0, 1);
        assert!(!log_notice(&mut log, 0.04, None, true));
        log_notice(&mut log, 0.06, Some(Notice::GainFallback("singular")), false);
        assert_eq!(log.0, 2);
    }

    /// Holds its last input as the output's thrust; counts its samples.
    #[derive(Debug, Clone, PartialEq)]
    struct Counter {
        samples: f64,
    }

    impl SampledUnit for Counter {
        type Config = f64;
        type Input = (f64, Phase);
        type Output = ControllerOutput;

        fn build(sample_time: &f64) -> Result<Self, ParamError> {
            if *sample_time > 0.0 {
                Ok(Self { samples: 0.0 })
            } else {
                Err(ParamError(format!("sample_time = {sample_time}")))
            }
        }

        fn sample_time(sample_time: &f64) -> f64 {
            *sample_time
        }

        fn sample(&mut self, input: &(f64, Phase)) -> Result<ControllerOutput, ControlError> {
            self.samples += 1.0;
            Ok(ControllerOutput {
                command: Command {
                    thrust: input.0,
                    ..Default::default()
                },
                diagnostics: Diagnostics {
                    ref_pos_ned: nalgebra::Vector3::new(1.0, 2.0, 3.0),
                    ref_airspeed: 25.0,
                    phase: input.1,
                    pos_error: 0.3,
                },
                notice: None,
            })
        }

        fn save(&self, out: &mut impl FnMut(f64)) {
            out(self.samples);
        }

        fn restore(&mut self, next: &mut impl FnMut() -> Option<f64>) -> Result<(), ControlError> {
            self.samples = next().ok_or_else(|| ControlError("truncated".into()))?;
            Ok(())
        }
    }

    fn words(u: &Sampled<Counter>) -> Vec<u64> {
        let mut w = Vec::new();
        u.save(&mut |x| w.push(x));
        w
    }

    #[test]
    fn samples_hold_and_state_round_trips() {
        let mut log = Count::default();
        let mut u = Sampled::<Counter>::build(&0.02).unwrap();
        assert!(Sampled::<Counter>::build(&0.0).is_err());
        assert!(u.output().is_none());
        let fresh = words(&u);
        assert_eq!(fresh.len(), u.saved_len());
        u.start(&(1.0, Phase::Vertical1), 0.0, &mut log).unwrap();
        // Held at 5 ms steps until the next multiple of the sample time.
        u.step(&(2.0, Phase::Vertical1), 0.0, 0.005, &mut log).unwrap();
        u.step(&(3.0, Phase::Vertical1), 0.01, 0.005, &mut log).unwrap();
        assert_eq!(u.output().unwrap().command.thrust, 1.0);
        u.step(&(4.0, Phase::TransitionToVertical), 0.02, 0.005, &mut log)
            .unwrap();
        assert_eq!(u.output().unwrap().command.thrust, 4.0);
        assert_eq!(u.unit().samples, 2.0);
        // A saved state continues identically in a fresh unit; a fresh state clears the output.
        let saved = words(&u);
        assert_eq!(saved.len(), fresh.len());
        let mut v = Sampled::<Counter>::build(&0.02).unwrap();
        let mut it = saved.iter().copied();
        v.restore(&mut || it.next()).unwrap();
        assert_eq!(v.output(), u.output());
        for (k, t) in [0.025, 0.03, 0.04].iter().enumerate() {
            u.step(&(k as f64, Phase::Level), *t, 0.005, &mut log).unwrap();
            v.step(&(k as f64, Phase::Level), *t, 0.005, &mut log).unwrap();
            assert_eq!(words(&u), words(&v));
        }
        let mut it = fresh.iter().copied();
        v.restore(&mut || it.next()).unwrap();
        assert!(v.output().is_none());
        // Truncated or corrupt states are errors, never panics.
        for n in 0..saved.len() {
            let mut it = saved[..n].iter().copied();
            assert!(v.restore(&mut || it.next()).is_err(), "{n}");
        }
        let mut bad = saved.clone();
        bad[2 + 12] = 11.0f64.to_bits(); // the held phase (codes 0–10 are valid)
        let mut it = bad.iter().copied();
        assert!(v.restore(&mut || it.next()).is_err());
        bad = saved;
        bad[1] = 2; // the held flag
        let mut it = bad.iter().copied();
        assert!(v.restore(&mut || it.next()).is_err());
    }
}
