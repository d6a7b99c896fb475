//! The trait a model implements to be exported as an FMI 2.0 Co-Simulation (and,
//! with continuous states, Model Exchange) FMU.
//! The export layer owns the state machine, argument checks, logging, FMU state
//! and panic safety; a model only supplies its equations.

use crate::logger::Logger;
use crate::state::{StateError, StateReader, StateWriter};
use crate::variables::VariableStore;

/// Error raised by a model; becomes `fmi2Error` plus a logged message.
#[derive(Debug, Clone, PartialEq)]
pub struct ModelError {
    pub message: String,
}

impl ModelError {
    pub fn new(message: impl Into<String>) -> Self {
        Self {
            message: message.into(),
        }
    }
}

impl std::fmt::Display for ModelError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for ModelError {}

/// A co-simulation model. One value of `Self` per FMU instance; `Clone` backs
/// fmi2GetFMUstate/fmi2SetFMUstate.
pub trait FmuModel: Clone + Send + 'static {
    /// The generated variable store of this model.
    type Vars: VariableStore;

    /// `modelIdentifier` of modelDescription.xml.
    const MODEL_IDENTIFIER: &'static str;
    /// `guid` of modelDescription.xml; checked in fmi2Instantiate.
    const GUID: &'static str;

    /// A model in its default state, from the start values.
    fn new(vars: &Self::Vars) -> Self;

    /// Derive the initial internal state from parameters and inputs
    /// (e.g. a trim). Called lazily, behind a dirty flag, whenever a
    /// value was set in Instantiated / InitializationMode and a value is
    /// then read, and always in fmi2ExitInitializationMode. Must be
    /// idempotent. Also responsible for the outputs at the start time.
    fn initialize(&mut self, vars: &mut Self::Vars, start_time: f64, log: &mut Logger<'_>) -> Result<(), ModelError>;

    /// Recompute outputs (and calculated parameters) from the internal state
    /// and current inputs into `vars`. Called lazily before a get when a set
    /// happened since the last computation.
    fn update_outputs(&mut self, vars: &mut Self::Vars) -> Result<(), ModelError>;

    /// Outputs are computed lazily after a step: `do_step` need not write them, the export
    /// layer marks them stale and calls [`Self::update_outputs`] before the next get (as the
    /// Reference FMUs do behind their dirty flag). A host that steps without reading every
    /// step then does not pay for outputs it never reads. Default `false`: `do_step` writes
    /// the outputs.
    const LAZY_STEP_OUTPUTS: bool = false;

    /// Advance from `t` to `t + h`. Inputs in `vars` are those set for `t`;
    /// on return, `vars` outputs hold values at `t + h` (unless
    /// [`Self::LAZY_STEP_OUTPUTS`]: then [`Self::update_outputs`] computes them on demand).
    /// Must not allocate on the success path.
    fn do_step(&mut self, vars: &mut Self::Vars, t: f64, h: f64, log: &mut Logger<'_>) -> Result<(), ModelError>;

    /// Model Exchange (only for models whose `Vars::CONTINUOUS_STATES` is not empty):
    /// take the continuous states `x` (finite, in the order of `CONTINUOUS_STATES`) as the
    /// internal state. The export layer then calls [`Self::update_outputs`], which must
    /// also write every derivative variable of `CONTINUOUS_STATES` (ẋ at the current
    /// states and inputs). Default: an error (Co-Simulation-only model).
    fn set_continuous_states(&mut self, _vars: &mut Self::Vars, _x: &[f64]) -> Result<(), ModelError> {
        Err(ModelError::new(
            "this model has no continuous states (Co-Simulation only)",
        ))
    }

    /// Append the complete internal state (everything `do_step` depends on
    /// besides `vars`) to an FMU-state buffer.
    fn write_state(&self, w: &mut StateWriter);
    /// Restore what [`Self::write_state`] wrote.
    fn read_state(&mut self, r: &mut StateReader<'_>) -> Result<(), StateError>;
}
