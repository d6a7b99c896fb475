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

use crate::{ControlError, Notice, ParamError};

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
