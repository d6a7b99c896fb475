//! One FMU adapter for every sampled unit ([`flight_mission::SampledUnit`]): the
//! controllers `fmu-lqr` and `fmu-tsd` today, the sensor model and the estimator
//! tomorrow. Knows no unit: a crate binds its unit to its generated `Variables`
//! by implementing [`Binding`] (four functions; controllers use
//! [`flight_controller_binding!`]) and exports `SampledFmu<ItsBinding>`.
//!
//! What the adapter does for every unit (docs/DESIGN.md §2 timing, §7 units):
//! - builds the unit from its parameters in `fmi2ExitInitializationMode`; an
//!   invalid parameter is an FMI error whose message names it;
//! - samples at the multiples of the unit's sample time ([`SampleClock`]),
//!   the first at the start time, and holds the output in between;
//! - rejects a non-finite Real input with an error naming it;
//! - reports the output's notices as warnings on the FMI logger (a lasting
//!   saturation once);
//! - saves and restores FMU states in one layout: `u64` next sample index, the
//!   held output ([`write_held`]), `u32` count and the unit's values
//!   ([`SampledUnit::save`]).

use std::marker::PhantomData;

use flight_mission::{HeldOutput, Notice, SampleClock};
use fmi2_export::{
    Causality, FmuModel, Logger, ModelError, StateError, StateReader, StateWriter, ValueType, VariableStore,
};

/// Upper bound on the unit values an FMU state may claim (the LQR saves a few hundred).
pub const MAX_SAVED_VALUES: usize = 4096;

type Config<B> = <<B as Binding>::Unit as SampledUnit>::Config;
type Input<B> = <<B as Binding>::Unit as SampledUnit>::Input;
type Output<B> = <<B as Binding>::Unit as SampledUnit>::Output;

/// How a sampled unit maps to the generated variables of its FMU.
pub trait Binding: 'static {
    /// The pure-Rust unit.
    type Unit: SampledUnit;
    /// The generated variable store of the FMU.
    type Vars: VariableStore;
    /// `modelIdentifier` of the FMU.
    const MODEL_IDENTIFIER: &'static str;
    /// GUID of the FMU.
    const GUID: &'static str;
    /// Name of the unit in messages, e.g. "LQR".
    const NAME: &'static str;
    /// The unit's configuration from the parameters.
    fn config(vars: &Self::Vars) -> Config<Self>;
    /// The unit's input at time `t` from the input variables (all finite: checked before).
    fn input(vars: &Self::Vars, t: f64) -> Input<Self>;
    /// Write an output to the output variables.
    fn write_output(vars: &mut Self::Vars, output: &Output<Self>);
}

/// The binding of a [`flight_mission::FlightController`] to the generated
/// `Variables` of a crate that includes `modelDescription/fragments/controller_interface.json`
/// (groups `measurement`, `ref_offset`, `command`, `diagnostics`):
/// `flight_controller_binding!(Lqr, LqrController, "LQR", |vars| config)` defines
/// `pub struct Lqr` implementing [`Binding`] with `Variables`, `MODEL_IDENTIFIER`
/// and `GUID` of the calling module.
#[macro_export]
macro_rules! flight_controller_binding {
    ($binding:ident, $unit:ty, $name:literal, |$vars:ident| $config:expr) => {
        /// The controller bound to this FMU's variables.
        pub struct $binding;

        impl $crate::Binding for $binding {
            type Unit = $unit;
            type Vars = Variables;
            const MODEL_IDENTIFIER: &'static str = MODEL_IDENTIFIER;
            const GUID: &'static str = GUID;
            const NAME: &'static str = $name;

            fn config($vars: &Variables) -> <$unit as $crate::SampledUnit>::Config {
                $config
            }

            fn input(vars: &Variables, t: f64) -> $crate::flight_mission::ControllerInput {
                $crate::flight_mission::ControllerInput {
                    t,
                    measurement: vars.measurement(),
                    ref_offset_ned: vars.ref_offset(),
                }
            }

            fn write_output(vars: &mut Variables, output: &$crate::flight_mission::ControllerOutput) {
                vars.set_command(&output.command);
                vars.set_diagnostics(&output.diagnostics);
            }
        }
    };
}

#[doc(hidden)]
pub use flight_mission;
pub use flight_mission::SampledUnit;

/// The FMU model of the unit of binding `B`.
pub struct SampledFmu<B: Binding> {
    /// The unit as freshly built, with the configuration it was built from
    /// (rebuilt only when a parameter changed).
    pristine: Option<(Config<B>, B::Unit)>,
    unit: Option<B::Unit>,
    clock: SampleClock,
    held: Option<Output<B>>,
    /// Unit state read from an FMU state before the unit existed.
    pending: Option<Vec<f64>>,
    /// The clock's period must be re-read from the parameters (after a state restore).
    reclock: bool,
    /// The previous sample reported a saturation: warn only when one starts.
    saturated: bool,
    binding: PhantomData<fn() -> B>,
}

impl<B: Binding> Clone for SampledFmu<B> {
    fn clone(&self) -> Self {
        Self {
            pristine: self.pristine.clone(),
            unit: self.unit.clone(),
            clock: self.clock,
            held: self.held,
            pending: self.pending.clone(),
            reclock: self.reclock,
            saturated: self.saturated,
            binding: PhantomData,
        }
    }
}

impl<B: Binding> SampledFmu<B> {
    /// The unit in its initial state for the parameters in `vars`.
    fn fresh(&mut self, config: Config<B>) -> Result<B::Unit, ModelError> {
        if let Some((c, unit)) = &self.pristine {
            if *c == config {
                return Ok(unit.clone());
            }
        }
        let unit =
            B::Unit::build(&config).map_err(|e| ModelError::new(format!("{}: invalid parameter: {e}", B::NAME)))?;
        self.pristine = Some((config, unit.clone()));
        Ok(unit)
    }

    /// After a state restore: the clock's period from the restored parameters,
    /// the unit rebuilt if the state was read before it existed.
    fn ensure_unit(&mut self, vars: &B::Vars) -> Result<(), ModelError> {
        if self.reclock {
            let config = B::config(vars);
            let next = self.clock.next_index();
            self.clock = SampleClock::new(B::Unit::sample_time(&config), 0.0);
            self.clock.set_next_index(next);
            if let Some(saved) = self.pending.take() {
                let mut unit = self.fresh(config)?;
                let mut it = saved.into_iter();
                unit.restore(&mut || it.next())
                    .map_err(|e| ModelError::new(format!("restoring the FMU state: {e}")))?;
                self.unit = Some(unit);
            }
            self.reclock = false;
        }
        Ok(())
    }

    /// One sample at `t`.
    fn sample(&mut self, vars: &B::Vars, t: f64, log: &mut Logger<'_>) -> Result<(), ModelError> {
        if let Some(name) = first_non_finite_input(vars) {
            return Err(ModelError::new(format!("input '{name}' is not finite at t = {t} s")));
        }
        let unit = self
            .unit
            .as_mut()
            .ok_or_else(|| ModelError::new(format!("{} not initialised", B::NAME)))?;
        let out = unit
            .sample(&B::input(vars, t))
            .map_err(|e| ModelError::new(format!("{} at t = {t} s: {e}", B::NAME)))?;
        self.saturated = log_notice(log, t, out.notice(), self.saturated);
        self.held = Some(out);
        Ok(())
    }

    fn write_outputs(&self, vars: &mut B::Vars) {
        if let Some(out) = &self.held {
            B::write_output(vars, out);
        }
    }
}

/// The name of the first Real input of `vars` that is not finite.
pub fn first_non_finite_input<V: VariableStore>(vars: &V) -> Option<&'static str> {
    V::VARIABLES
        .iter()
        .filter(|s| s.causality == Causality::Input && s.value_type == ValueType::Real)
        .find(|s| !vars.get_real(s.value_reference).is_some_and(f64::is_finite))
        .map(|s| s.name)
}

impl<B: Binding> FmuModel for SampledFmu<B> {
    type Vars = B::Vars;
    const MODEL_IDENTIFIER: &'static str = B::MODEL_IDENTIFIER;
    const GUID: &'static str = B::GUID;

    fn new(_vars: &B::Vars) -> Self {
        Self {
            pristine: None,
            unit: None,
            // Placeholder period: set from the parameters in `initialize` or after a restore.
            clock: SampleClock::new(1.0, 0.0),
            held: None,
            pending: None,
            reclock: true,
            saturated: false,
            binding: PhantomData,
        }
    }

    fn initialize(&mut self, vars: &mut B::Vars, start_time: f64, log: &mut Logger<'_>) -> Result<(), ModelError> {
        // Idempotent: a fresh unit and clock every time, then the sample at the start time.
        let config = B::config(vars);
        let sample_time = B::Unit::sample_time(&config);
        self.unit = Some(self.fresh(config)?);
        self.pending = None;
        self.reclock = false;
        self.clock = SampleClock::new(sample_time, start_time);
        self.held = None;
        self.saturated = false;
        let due = self.clock.take(start_time);
        debug_assert!(due);
        self.sample(vars, start_time, log)?;
        self.write_outputs(vars);
        Ok(())
    }

    fn update_outputs(&mut self, vars: &mut B::Vars) -> Result<(), ModelError> {
        self.ensure_unit(vars)?;
        self.write_outputs(vars);
        Ok(())
    }

    fn do_step(&mut self, vars: &mut B::Vars, t: f64, _h: f64, log: &mut Logger<'_>) -> Result<(), ModelError> {
        self.ensure_unit(vars)?;
        if self.clock.take(t) || self.held.is_none() {
            self.sample(vars, t, log)?;
        }
        self.write_outputs(vars);
        Ok(())
    }

    fn write_state(&self, w: &mut StateWriter) {
        w.u64(self.clock.next_index());
        write_held(w, &self.held);
        match (&self.unit, &self.pending) {
            (Some(unit), _) => {
                w.u32(unit.saved_len() as u32);
                unit.save(&mut |v| w.f64(v));
            }
            (None, Some(p)) => {
                w.u32(p.len() as u32);
                for v in p {
                    w.f64(*v);
                }
            }
            (None, None) => w.u32(0),
        }
    }

    fn read_state(&mut self, r: &mut StateReader<'_>) -> Result<(), StateError> {
        let next_index = r.u64()?;
        let held = read_held(r)?;
        let n = r.u32()? as usize;
        // The count comes from the buffer: bound it before allocating.
        if n > MAX_SAVED_VALUES {
            return Err(StateError::invalid(format!(
                "{} state claims {n} values (at most {MAX_SAVED_VALUES})",
                B::NAME
            )));
        }
        let mut saved = Vec::with_capacity(n);
        for _ in 0..n {
            saved.push(r.f64()?);
        }
        if n == 0 {
            self.unit = None;
            self.pending = None;
        } else if let Some(unit) = self.unit.as_mut() {
            let expected = unit.saved_len();
            if n != expected {
                return Err(StateError::invalid(format!(
                    "{} state has {n} values, expected {expected}",
                    B::NAME
                )));
            }
            let mut it = saved.into_iter();
            unit.restore(&mut || it.next()).map_err(|e| StateError::invalid(e.0))?;
        } else {
            self.pending = Some(saved);
        }
        self.clock.set_next_index(next_index);
        self.held = held;
        self.reclock = true;
        Ok(())
    }
}

/// Append the held output (or its absence) to an FMU state.
pub fn write_held<O: HeldOutput>(w: &mut StateWriter, held: &Option<O>) {
    w.bool(held.is_some());
    if let Some(out) = held {
        out.save(&mut |x| w.f64(x));
    }
}

/// Read back what [`write_held`] wrote.
pub fn read_held<O: HeldOutput>(r: &mut StateReader<'_>) -> Result<Option<O>, StateError> {
    if !r.bool()? {
        return Ok(None);
    }
    let mut saved = [0.0; 64];
    assert!(O::SAVED_LEN <= saved.len(), "held outputs are small");
    for x in saved[..O::SAVED_LEN].iter_mut() {
        *x = r.f64()?;
    }
    let mut it = saved[..O::SAVED_LEN].iter().copied();
    O::restore(&mut || it.next())
        .map(Some)
        .ok_or_else(|| StateError::invalid("held output: invalid value (e.g. phase out of range)"))
}

/// Log a unit's notice as a warning; `was_saturated` (the previous sample's
/// saturation) keeps a lasting saturation to one message.
/// Returns whether this sample is saturated.
pub fn log_notice(log: &mut Logger<'_>, t: f64, notice: Option<Notice>, was_saturated: bool) -> bool {
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
    use flight_mission::{Command, ControllerOutput, Diagnostics, Phase};

    #[test]
    fn held_output_round_trips_and_rejects_corruption() {
        let out = ControllerOutput {
            command: Command {
                thrust: 12.0,
                rudder: 0.1,
                ..Default::default()
            },
            diagnostics: Diagnostics {
                ref_pos_ned: flight_mission::nalgebra::Vector3::new(1.0, 2.0, 3.0),
                ref_airspeed: 25.0,
                phase: Phase::TransitionToVertical,
                pos_error: 0.3,
            },
            notice: None,
        };
        for held in [None, Some(out)] {
            let mut w = StateWriter::new();
            write_held(&mut w, &held);
            let bytes = w.into_bytes();
            let mut r = StateReader::new(&bytes);
            assert_eq!(read_held::<ControllerOutput>(&mut r).unwrap(), held);
            r.finish().unwrap();
            // Every truncation is an error, never a panic.
            for n in 0..bytes.len() {
                assert!(
                    read_held::<ControllerOutput>(&mut StateReader::new(&bytes[..n])).is_err(),
                    "{n}"
                );
            }
        }
        let mut w = StateWriter::new();
        let mut bad = out;
        bad.diagnostics.phase = Phase::Vertical1;
        write_held(&mut w, &Some(bad));
        let mut bytes = w.into_bytes();
        let phase_at = bytes.len() - 8;
        bytes[phase_at..].copy_from_slice(&11.0f64.to_le_bytes());
        assert!(read_held::<ControllerOutput>(&mut StateReader::new(&bytes)).is_err());
    }

    #[test]
    fn lasting_saturation_is_logged_once() {
        let mut log = Logger::null();
        let s = log_notice(&mut log, 0.0, Some(Notice::Saturated("thrust_cmd")), false);
        assert!(s);
        assert!(log_notice(&mut log, 0.02, Some(Notice::Saturated("thrust_cmd")), s));
        assert!(!log_notice(&mut log, 0.04, None, true));
    }
}
