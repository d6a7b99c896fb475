//! One FMU adapter for every co-simulation unit ([`flight_mission::SteppedUnit`]):
//! the controllers `fmu-lqr` and `fmu-tsd` (a [`flight_mission::SampledUnit`] through
//! [`flight_mission::Sampled`]), the sensor model `fmu-sensors` and the estimator
//! `fmu-ekf`. Knows no unit: a crate binds its unit to its generated `Variables` by
//! implementing [`Binding`] (the unit's configuration from a parameter group, its
//! input from input groups, its output into output groups; controllers use
//! [`flight_controller_binding!`]) and exports `UnitFmu<ItsBinding>`.
//!
//! What the adapter does for every unit (docs/DESIGN.md §2 timing, §7 units):
//! - builds the unit from its parameters in `fmi2ExitInitializationMode` (again only
//!   when a parameter changed); an invalid parameter is an FMI error whose message
//!   names it: `<unit>: invalid parameter: …`;
//! - starts it at the start time and steps it with the inputs set for t; a unit's
//!   error becomes an FMI error `<unit>: …`;
//! - rejects a non-finite Real input with an error naming it;
//! - forwards the unit's warnings and errors to the FMI logger;
//! - saves and restores FMU states in one layout: `u32` count and the unit's words
//!   ([`SteppedUnit::save`]); a restored state is put into a unit built from the
//!   restored parameters.

use std::marker::PhantomData;

use flight_mission::{ParamError, UnitLog};
use fmi2_export::{
    Causality, FmuModel, Logger, ModelError, StateError, StateReader, StateWriter, ValueType, VariableStore,
};

/// Upper bound on the unit words an FMU state may claim (the LQR saves a few hundred).
pub const MAX_SAVED_VALUES: usize = 4096;

type Config<B> = <<B as Binding>::Unit as SteppedUnit>::Config;
type Input<B> = <<B as Binding>::Unit as SteppedUnit>::Input;
type Output<B> = <<B as Binding>::Unit as SteppedUnit>::Output;

/// How a unit maps to the generated variables of its FMU: in each binding crate,
/// through the group accessors generated from its declaration.
pub trait Binding: 'static {
    /// The pure-Rust unit.
    type Unit: SteppedUnit;
    /// The generated variable store of the FMU.
    type Vars: VariableStore;
    /// `modelIdentifier` of the FMU: its generated variables'.
    const MODEL_IDENTIFIER: &'static str = <Self::Vars as VariableStore>::MODEL_IDENTIFIER;
    /// GUID of the FMU: its generated variables'.
    const GUID: &'static str = <Self::Vars as VariableStore>::GUID;
    /// Name of the unit in messages, e.g. "LQR".
    const NAME: &'static str;
    /// The unit's configuration from the parameters; a parameter that has no
    /// meaning (e.g. an enumeration code out of range) is an error naming it.
    fn config(vars: &Self::Vars) -> Result<Config<Self>, ParamError>;
    /// The unit's input at time `t` from the input variables (all finite: checked before).
    fn input(vars: &Self::Vars, t: f64) -> Input<Self>;
    /// Write an output to the output variables.
    fn write_output(vars: &mut Self::Vars, output: &Output<Self>);
}

/// The binding of a [`flight_mission::FlightController`] to the generated
/// `Variables` of a crate that includes `modelDescription/fragments/controller_interface.json`
/// (groups `measurement`, `ref_offset`, `command`, `diagnostics`):
/// `flight_controller_binding!(Lqr, LqrController, "LQR", |vars| config)` defines
/// `pub struct Lqr` implementing [`Binding`] for the controller sampled by
/// [`flight_mission::Sampled`], with `Variables`, `MODEL_IDENTIFIER` and `GUID` of
/// the calling module.
#[macro_export]
macro_rules! flight_controller_binding {
    ($binding:ident, $unit:ty, $name:literal, |$vars:ident| $config:expr) => {
        /// The controller bound to this FMU's variables.
        pub struct $binding;

        impl $crate::Binding for $binding {
            type Unit = $crate::flight_mission::Sampled<$unit>;
            type Vars = Variables;
            const NAME: &'static str = $name;

            fn config(
                $vars: &Variables,
            ) -> Result<<$unit as $crate::flight_mission::SampledUnit>::Config, $crate::flight_mission::ParamError>
            {
                Ok($config)
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
pub use flight_mission::{SampledUnit, SteppedUnit};

pub mod testing;

/// The FMU model of the unit of binding `B`.
pub struct UnitFmu<B: Binding> {
    /// The unit as freshly built, with the configuration it was built from
    /// (rebuilt only when a parameter changed).
    pristine: Option<(Config<B>, B::Unit)>,
    unit: Option<B::Unit>,
    /// Unit state read from an FMU state: put into a unit built from the restored
    /// parameters before the next use.
    pending: Option<Vec<u64>>,
    binding: PhantomData<fn() -> B>,
}

impl<B: Binding> Clone for UnitFmu<B> {
    fn clone(&self) -> Self {
        Self {
            pristine: self.pristine.clone(),
            unit: self.unit.clone(),
            pending: self.pending.clone(),
            binding: PhantomData,
        }
    }
}

/// The FMI logger as the unit's [`UnitLog`].
struct Log<'a, 'b>(&'a mut Logger<'b>);

impl UnitLog for Log<'_, '_> {
    fn warning(&mut self, message: std::fmt::Arguments<'_>) {
        self.0.warning(message);
    }
    fn error(&mut self, message: std::fmt::Arguments<'_>) {
        self.0.error(message);
    }
}

impl<B: Binding> UnitFmu<B> {
    /// The unit, if started or restored (for tests and tools).
    pub fn unit(&self) -> Option<&B::Unit> {
        self.unit.as_ref()
    }

    /// The unit in its initial state for the parameters in `vars`.
    fn fresh(&mut self, vars: &B::Vars) -> Result<B::Unit, ModelError> {
        let invalid = |e: ParamError| ModelError::new(format!("{}: invalid parameter: {e}", B::NAME));
        let config = B::config(vars).map_err(invalid)?;
        if let Some((c, unit)) = &self.pristine {
            if *c == config {
                return Ok(unit.clone());
            }
        }
        let unit = B::Unit::build(&config).map_err(invalid)?;
        self.pristine = Some((config, unit.clone()));
        Ok(unit)
    }

    /// After a state restore: the restored unit state in a unit built from the restored parameters.
    fn ensure_unit(&mut self, vars: &B::Vars) -> Result<&mut B::Unit, ModelError> {
        if let Some(saved) = self.pending.take() {
            let mut unit = self.fresh(vars)?;
            let mut it = saved.into_iter();
            unit.restore(&mut || it.next())
                .map_err(|e| ModelError::new(format!("restoring the FMU state: {e}")))?;
            self.unit = Some(unit);
        }
        self.unit
            .as_mut()
            .ok_or_else(|| ModelError::new(format!("{} not initialised", B::NAME)))
    }

    fn write_outputs(&self, vars: &mut B::Vars) {
        if let Some(out) = self.unit.as_ref().and_then(SteppedUnit::output) {
            B::write_output(vars, &out);
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

fn check_inputs<V: VariableStore>(vars: &V, t: f64) -> Result<(), ModelError> {
    match first_non_finite_input(vars) {
        Some(name) => Err(ModelError::new(format!("input '{name}' is not finite at t = {t} s"))),
        None => Ok(()),
    }
}

impl<B: Binding> FmuModel for UnitFmu<B> {
    type Vars = B::Vars;
    const MODEL_IDENTIFIER: &'static str = B::MODEL_IDENTIFIER;
    const GUID: &'static str = B::GUID;

    fn new(_vars: &B::Vars) -> Self {
        Self {
            pristine: None,
            unit: None,
            pending: None,
            binding: PhantomData,
        }
    }

    fn initialize(&mut self, vars: &mut B::Vars, start_time: f64, log: &mut Logger<'_>) -> Result<(), ModelError> {
        // Idempotent: a fresh unit every time, started from the inputs at the start time.
        self.unit = None;
        self.pending = None;
        let mut unit = self.fresh(vars)?;
        check_inputs(vars, start_time)?;
        unit.start(&B::input(vars, start_time), start_time, &mut Log(log))
            .map_err(|e| ModelError::new(format!("{}: {e}", B::NAME)))?;
        self.unit = Some(unit);
        self.write_outputs(vars);
        Ok(())
    }

    fn update_outputs(&mut self, vars: &mut B::Vars) -> Result<(), ModelError> {
        if self.pending.is_some() {
            self.ensure_unit(vars)?;
        }
        self.write_outputs(vars);
        Ok(())
    }

    fn do_step(&mut self, vars: &mut B::Vars, t: f64, h: f64, log: &mut Logger<'_>) -> Result<(), ModelError> {
        let unit = self.ensure_unit(vars)?;
        check_inputs(vars, t)?;
        unit.step(&B::input(vars, t), t, h, &mut Log(log))
            .map_err(|e| ModelError::new(format!("{}: {e}", B::NAME)))?;
        self.write_outputs(vars);
        Ok(())
    }

    fn write_state(&self, w: &mut StateWriter) {
        match (&self.pending, &self.unit) {
            (Some(p), _) => {
                w.u32(p.len() as u32);
                p.iter().for_each(|x| w.u64(*x));
            }
            (None, Some(unit)) => {
                w.u32(unit.saved_len() as u32);
                unit.save(&mut |x| w.u64(x));
            }
            (None, None) => w.u32(0),
        }
    }

    fn read_state(&mut self, r: &mut StateReader<'_>) -> Result<(), StateError> {
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
            saved.push(r.u64()?);
        }
        if n == 0 {
            self.unit = None;
            self.pending = None;
            return Ok(());
        }
        if let Some(unit) = &self.unit {
            // Check the state now against the unit it came from (same parameters unless
            // the restored variables change them).
            let expected = unit.saved_len();
            if n != expected {
                return Err(StateError::invalid(format!(
                    "{} state has {n} values, expected {expected}",
                    B::NAME
                )));
            }
            let mut check = unit.clone();
            let mut it = saved.iter().copied();
            check.restore(&mut || it.next()).map_err(|e| StateError::invalid(e.0))?;
        }
        // The parameters come back with the variables: the unit is rebuilt from them before use.
        self.unit = None;
        self.pending = Some(saved);
        Ok(())
    }
}
