//! Static description of an FMU's variables, as emitted by the code generator
//! (`build.rs` + `modelDescription/`) for every model. The export layer uses it
//! to validate every get/set call generically (causality, variability, type,
//! range, finiteness) before the model ever sees a value.

/// FMI 2.0 causality (fmi2ModelDescription, §2.2.7).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Causality {
    Parameter,
    CalculatedParameter,
    Input,
    Output,
    Local,
    Independent,
}

/// FMI 2.0 variability.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Variability {
    Constant,
    Fixed,
    Tunable,
    Discrete,
    Continuous,
}

/// FMI 2.0 base type of a variable.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ValueType {
    Real,
    Integer,
    Boolean,
    String,
}

/// One declared variable. Value references are unique across all types
/// within one model (checked by the generator).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VariableSpec {
    pub name: &'static str,
    pub value_reference: u32,
    pub value_type: ValueType,
    pub causality: Causality,
    pub variability: Variability,
    /// Lower bound for Real/Integer (`f64::NEG_INFINITY` when unbounded).
    pub min: f64,
    /// Upper bound for Real/Integer (`f64::INFINITY` when unbounded).
    pub max: f64,
    /// SI unit name, `""` when dimensionless / not applicable.
    pub unit: &'static str,
    pub description: &'static str,
}

/// The generated per-model value store: one named field per variable, holding
/// the current value. Implemented by generated code only.
/// One continuous state of a Model Exchange FMU: the value references of the state
/// and of its derivative, and the state's nominal value (`nominal` attribute).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContinuousState {
    pub state: u32,
    pub derivative: u32,
    pub nominal: f64,
}

pub trait VariableStore: Clone + Send + 'static {
    /// Every declared variable, in declaration order.
    const VARIABLES: &'static [VariableSpec];
    /// `modelIdentifier` of the FMU the variables are generated for.
    const MODEL_IDENTIFIER: &'static str;
    /// GUID of that FMU's interface.
    const GUID: &'static str;

    /// A store holding every variable's start value.
    fn with_start_values() -> Self;

    /// Index into [`Self::VARIABLES`] of the variable with this value reference.
    fn index_of(value_reference: u32) -> Option<usize>;

    /// `None` if `value_reference` is not a Real of this model.
    fn get_real(&self, value_reference: u32) -> Option<f64>;
    /// Returns `false` (and changes nothing) if `value_reference` is not a Real.
    fn set_real(&mut self, value_reference: u32, value: f64) -> bool;
    fn get_integer(&self, value_reference: u32) -> Option<i32>;
    fn set_integer(&mut self, value_reference: u32, value: i32) -> bool;
    fn get_boolean(&self, value_reference: u32) -> Option<bool>;
    fn set_boolean(&mut self, value_reference: u32, value: bool) -> bool;
    fn get_string(&self, value_reference: u32) -> Option<&str>;
    fn set_string(&mut self, value_reference: u32, value: &str) -> bool;

    /// Append every value, in declaration order, to an FMU-state buffer.
    fn write_state(&self, w: &mut crate::state::StateWriter);
    /// Read back what [`Self::write_state`] wrote.
    fn read_state(&mut self, r: &mut crate::state::StateReader<'_>) -> Result<(), crate::state::StateError>;

    /// The spec of a value reference, if declared.
    /// Model Exchange: the continuous states, in the order of the continuous-state
    /// vector (fmi2GetContinuousStates, fmi2GetDerivatives). Empty: Co-Simulation only.
    const CONTINUOUS_STATES: &'static [ContinuousState] = &[];

    fn spec(value_reference: u32) -> Option<&'static VariableSpec> {
        Self::index_of(value_reference).map(|i| &Self::VARIABLES[i])
    }
}
