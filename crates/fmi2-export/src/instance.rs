//! One FMU instance: the FMI 2.0 Co-Simulation state machine, argument checks
//! and generic value access around a [`FmuModel`]. Everything here is safe
//! Rust; [`crate::ffi`] converts C arguments and guards against panics.

use crate::logger::{Level, LogSink, Logger};
use crate::model::FmuModel;
use crate::state::{self, StateError, StateReader, StateWriter};
use crate::variables::{Causality, ValueType, Variability, VariableSpec, VariableStore};
use std::ffi::CString;
use std::fmt;

/// FMI 2.0 states of both interfaces (StartAndEnd is "no instance"): Co-Simulation
/// (StepComplete …) and Model Exchange (EventMode, ContinuousTimeMode).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u8)]
pub enum FmiState {
    Instantiated = 1,
    InitializationMode = 2,
    StepComplete = 3,
    StepInProgress = 4,
    StepFailed = 5,
    StepCanceled = 6,
    Terminated = 7,
    /// Model Exchange: event iteration (after initialization or fmi2EnterEventMode).
    EventMode = 8,
    /// Model Exchange: the importer's integrator sets time and states, reads derivatives.
    ContinuousTimeMode = 9,
}

impl FmiState {
    const fn bit(self) -> u16 {
        1 << (self as u8)
    }

    fn from_u8(v: u8) -> Option<Self> {
        Some(match v {
            1 => Self::Instantiated,
            2 => Self::InitializationMode,
            3 => Self::StepComplete,
            4 => Self::StepInProgress,
            5 => Self::StepFailed,
            6 => Self::StepCanceled,
            7 => Self::Terminated,
            8 => Self::EventMode,
            9 => Self::ContinuousTimeMode,
            _ => return None,
        })
    }
}

impl fmt::Display for FmiState {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Debug::fmt(self, f)
    }
}

/// A set of states in which a call is legal.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StateMask(u16);

impl StateMask {
    pub const fn of(states: &[FmiState]) -> Self {
        let mut bits = 0;
        let mut i = 0;
        while i < states.len() {
            bits |= states[i].bit();
            i += 1;
        }
        Self(bits)
    }
    pub const fn contains(self, s: FmiState) -> bool {
        self.0 & s.bit() != 0
    }
}

use FmiState::*;

/// Legal states per call (as the Reference FMUs enforce them).
pub mod mask {
    use super::*;
    pub const ANY: StateMask = StateMask::of(&[
        Instantiated,
        InitializationMode,
        StepComplete,
        StepInProgress,
        StepFailed,
        StepCanceled,
        Terminated,
        EventMode,
        ContinuousTimeMode,
    ]);
    pub const INSTANTIATED: StateMask = StateMask::of(&[Instantiated]);
    pub const INITIALIZATION_MODE: StateMask = StateMask::of(&[InitializationMode]);
    pub const SET: StateMask = StateMask::of(&[
        Instantiated,
        InitializationMode,
        StepComplete,
        EventMode,
        ContinuousTimeMode,
    ]);
    pub const GET: StateMask = StateMask::of(&[
        InitializationMode,
        StepComplete,
        StepFailed,
        StepCanceled,
        Terminated,
        EventMode,
        ContinuousTimeMode,
    ]);
    pub const DO_STEP: StateMask = StateMask::of(&[StepComplete]);
    pub const CANCEL_STEP: StateMask = StateMask::of(&[StepInProgress]);
    pub const TERMINATE: StateMask = StateMask::of(&[StepComplete, StepFailed, EventMode, ContinuousTimeMode]);
    // Model Exchange (FMI 2.0 §3.2.3 state table).
    pub const ENTER_EVENT_MODE: StateMask = StateMask::of(&[EventMode, ContinuousTimeMode]);
    pub const NEW_DISCRETE_STATES: StateMask = StateMask::of(&[EventMode]);
    pub const ENTER_CONTINUOUS_TIME_MODE: StateMask = StateMask::of(&[EventMode]);
    pub const COMPLETED_INTEGRATOR_STEP: StateMask = StateMask::of(&[ContinuousTimeMode]);
    pub const SET_TIME: StateMask = StateMask::of(&[EventMode, ContinuousTimeMode]);
    pub const SET_CONTINUOUS_STATES: StateMask = StateMask::of(&[ContinuousTimeMode]);
    pub const GET_DERIVATIVES: StateMask = StateMask::of(&[EventMode, ContinuousTimeMode, Terminated]);
    pub const GET_EVENT_INDICATORS: StateMask =
        StateMask::of(&[InitializationMode, EventMode, ContinuousTimeMode, Terminated]);
    pub const GET_CONTINUOUS_STATES: StateMask =
        StateMask::of(&[InitializationMode, EventMode, ContinuousTimeMode, Terminated]);
    pub const GET_NOMINALS: StateMask = StateMask::of(&[Instantiated, EventMode, ContinuousTimeMode, Terminated]);
    pub const STATUS: StateMask = StateMask::of(&[StepComplete, StepInProgress, StepFailed, StepCanceled, Terminated]);
}

/// A failed call: becomes the returned status plus a logged message.
#[derive(Debug, Clone, PartialEq)]
pub struct Fmi2Error {
    pub level: Level,
    pub message: String,
}

impl Fmi2Error {
    /// → fmi2Error.
    pub fn error(message: impl Into<String>) -> Self {
        Self {
            level: Level::Error,
            message: message.into(),
        }
    }
    /// → fmi2Discard.
    pub fn discard(message: impl Into<String>) -> Self {
        Self {
            level: Level::Discard,
            message: message.into(),
        }
    }
}

impl fmt::Display for Fmi2Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

impl From<StateError> for Fmi2Error {
    fn from(e: StateError) -> Self {
        Self::error(e.to_string())
    }
}

pub type Fmi2Result<T = ()> = Result<T, Fmi2Error>;

/// Everything of the state machine that an FMU state captures.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Machine {
    pub state: FmiState,
    pub start_time: f64,
    pub time: f64,
    pub stop_time: Option<f64>,
    pub tolerance: Option<f64>,
    /// `FmuModel::initialize` ran in fmi2ExitInitializationMode.
    pub initialized: bool,
    /// A value was set since outputs were last computed.
    pub dirty: bool,
    /// Instantiated as Model Exchange (fmi2ModelExchange) rather than Co-Simulation.
    pub model_exchange: bool,
}

impl Machine {
    fn fresh() -> Self {
        Self {
            state: Instantiated,
            start_time: 0.0,
            time: 0.0,
            stop_time: None,
            tolerance: None,
            initialized: false,
            dirty: true,
            model_exchange: false,
        }
    }

    fn write(&self, w: &mut StateWriter) {
        w.u8(self.state as u8);
        w.f64(self.start_time);
        w.f64(self.time);
        w.bool(self.stop_time.is_some());
        w.f64(self.stop_time.unwrap_or(0.0));
        w.bool(self.tolerance.is_some());
        w.f64(self.tolerance.unwrap_or(0.0));
        w.bool(self.initialized);
        w.bool(self.dirty);
        w.bool(self.model_exchange);
    }

    fn read(r: &mut StateReader<'_>) -> Result<Self, StateError> {
        let code = r.u8()?;
        let state = match FmiState::from_u8(code) {
            Some(StepInProgress) | None => {
                return Err(StateError::invalid(format!(
                    "state code {code} is not a restorable FMI state"
                )))
            }
            Some(s) => s,
        };
        let start_time = r.f64()?;
        let time = r.f64()?;
        let has_stop = r.bool()?;
        let stop = r.f64()?;
        let has_tol = r.bool()?;
        let tol = r.f64()?;
        let m = Self {
            state,
            start_time,
            time,
            stop_time: has_stop.then_some(stop),
            tolerance: has_tol.then_some(tol),
            initialized: r.bool()?,
            dirty: r.bool()?,
            model_exchange: r.bool()?,
        };
        if !(start_time.is_finite() && time.is_finite() && stop.is_finite() && tol.is_finite()) {
            return Err(StateError::invalid("non-finite time in FMU state"));
        }
        // What fmi2SetupExperiment refuses, a restored state may not bring either.
        if let Some(stop) = m.stop_time {
            if stop < start_time {
                return Err(StateError::invalid(format!(
                    "stopTime = {stop} before startTime = {start_time} in FMU state"
                )));
            }
        }
        if let Some(tol) = m.tolerance {
            if tol <= 0.0 {
                return Err(StateError::invalid(format!(
                    "tolerance = {tol} in FMU state must be > 0"
                )));
            }
        }
        let me_state = matches!(m.state, EventMode | ContinuousTimeMode);
        let cs_state = matches!(m.state, StepComplete | StepFailed | StepCanceled);
        if (me_state && !m.model_exchange) || (cs_state && m.model_exchange) {
            return Err(StateError::invalid(format!(
                "state {} does not belong to a {} instance",
                m.state,
                if m.model_exchange {
                    "Model Exchange"
                } else {
                    "Co-Simulation"
                }
            )));
        }
        Ok(m)
    }
}

const INSTANCE_TAG: u64 = 0x4649_4e53_5441_4e43; // "FINSTANC"
const SNAPSHOT_TAG: u64 = 0x4653_4e41_5053_484f; // "FSNAPSHO"

/// Per-model tag distinguishing our pointers from foreign/freed ones.
pub(crate) fn tag_for<M: FmuModel>(kind: u64) -> u64 {
    kind ^ state::fnv1a64(M::GUID.as_bytes()) ^ state::fnv1a64(M::MODEL_IDENTIFIER.as_bytes())
}

/// An FMU state captured by fmi2GetFMUstate / fmi2DeSerializeFMUstate.
#[repr(C)]
pub struct Snapshot<M: FmuModel> {
    /// First field, so a tag can be checked before trusting the type.
    pub(crate) tag: u64,
    pub machine: Machine,
    pub model: M,
    pub vars: M::Vars,
}

impl<M: FmuModel> Snapshot<M> {
    pub(crate) fn tag() -> u64 {
        tag_for::<M>(SNAPSHOT_TAG)
    }

    /// Serialized form: [`state::seal`] around machine + vars + model.
    pub fn serialize(&self) -> Vec<u8> {
        let mut w = StateWriter::new();
        self.machine.write(&mut w);
        self.vars.write_state(&mut w);
        self.model.write_state(&mut w);
        state::seal(M::GUID, w.as_bytes())
    }

    /// The inverse of [`Self::serialize`]. The checksum only proves the bytes are
    /// intact, not that they came from this FMU: every restored variable is checked as
    /// fmi2Set* would check it ([`check_restored_variables`]) before the model sees it.
    pub fn deserialize(bytes: &[u8]) -> Result<Self, StateError> {
        let payload = state::open(M::GUID, bytes)?;
        let mut r = StateReader::new(payload);
        let machine = Machine::read(&mut r)?;
        let mut vars = M::Vars::with_start_values();
        vars.read_state(&mut r)?;
        check_restored_variables(&vars)?;
        let mut model = M::new(&vars);
        model.read_state(&mut r)?;
        r.finish()?;
        Ok(Self {
            tag: Self::tag(),
            machine,
            model,
            vars,
        })
    }
}

/// Check every variable of a restored FMU state as fmi2SetReal / fmi2SetInteger would
/// check a value set by the host, so that a state can bring no value the host could not
/// have set:
/// - parameters and inputs (the values the model is configured and driven by): a Real
///   finite, a Real or Integer within its declared `[min, max]`;
/// - constants: their start value (they cannot be set at all);
/// - calculated parameters, outputs, locals and the independent variable: anything (the
///   model computes them; a state captured after a failed or diverging step legitimately
///   holds non-finite outputs). Booleans and Strings have no range.
///
/// The error names the variable, its value and the range.
pub fn check_restored_variables<V: VariableStore>(vars: &V) -> Result<(), StateError> {
    let start = V::with_start_values();
    for spec in V::VARIABLES {
        let vr = spec.value_reference;
        let value = match spec.value_type {
            ValueType::Real => vars.get_real(vr),
            ValueType::Integer => vars.get_integer(vr).map(f64::from),
            ValueType::Boolean | ValueType::String => None,
        };
        if spec.variability == Variability::Constant {
            let same = match spec.value_type {
                ValueType::Real => vars.get_real(vr).map(f64::to_bits) == start.get_real(vr).map(f64::to_bits),
                ValueType::Integer => vars.get_integer(vr) == start.get_integer(vr),
                ValueType::Boolean => vars.get_boolean(vr) == start.get_boolean(vr),
                ValueType::String => vars.get_string(vr) == start.get_string(vr),
            };
            if !same {
                return Err(StateError::invalid(format!(
                    "restored constant {} (value reference {vr}) differs from its declared value",
                    spec.name
                )));
            }
            continue;
        }
        if !matches!(spec.causality, Causality::Parameter | Causality::Input) {
            continue;
        }
        let Some(value) = value else { continue };
        if !value.is_finite() {
            return Err(StateError::invalid(format!(
                "restored variable {} (value reference {vr}): value {value} is not finite",
                spec.name
            )));
        }
        if value < spec.min || value > spec.max {
            return Err(StateError::invalid(format!(
                "restored variable {} (value reference {vr}): value {value} outside [{}, {}]",
                spec.name, spec.min, spec.max
            )));
        }
    }
    Ok(())
}

/// One FMU instance.
#[repr(C)]
pub struct Instance<M: FmuModel> {
    /// First field, checked on every call (wrong model / freed pointer).
    pub(crate) tag: u64,
    pub sink: LogSink,
    pub machine: Machine,
    pub model: M,
    pub vars: M::Vars,
    pub resource_location: String,
    /// Keeps fmi2GetString results alive until the next fmi2GetString.
    strings: Vec<CString>,
}

impl<M: FmuModel> Instance<M> {
    pub(crate) fn tag() -> u64 {
        tag_for::<M>(INSTANCE_TAG)
    }

    pub fn new(sink: LogSink, resource_location: String) -> Self {
        let vars = M::Vars::with_start_values();
        let model = M::new(&vars);
        Self {
            tag: Self::tag(),
            sink,
            machine: Machine::fresh(),
            model,
            vars,
            resource_location,
            strings: Vec::new(),
        }
    }

    pub fn state(&self) -> FmiState {
        self.machine.state
    }

    pub fn logger(&self) -> Logger<'_> {
        Logger::new(&self.sink)
    }

    pub fn log(&self, level: Level, message: &dyn fmt::Display) {
        self.sink.log(level, message);
    }

    /// `Err` (logged by the caller) unless the current state is in `mask`.
    pub fn check_state(&self, mask: StateMask) -> Fmi2Result {
        if mask.contains(self.machine.state) {
            Ok(())
        } else {
            Err(Fmi2Error::error(format!(
                "illegal call in state {}",
                self.machine.state
            )))
        }
    }

    pub fn reset(&mut self) {
        self.vars = M::Vars::with_start_values();
        self.model = M::new(&self.vars);
        let model_exchange = self.machine.model_exchange;
        self.machine = Machine::fresh();
        self.machine.model_exchange = model_exchange;
        self.strings.clear();
    }

    pub fn setup_experiment(&mut self, tolerance: Option<f64>, start: f64, stop: Option<f64>) -> Fmi2Result {
        if !start.is_finite() {
            return Err(Fmi2Error::error(format!("startTime = {start} is not finite")));
        }
        if let Some(stop) = stop {
            if !stop.is_finite() || stop < start {
                return Err(Fmi2Error::error(format!(
                    "stopTime = {stop} must be finite and >= startTime = {start}"
                )));
            }
        }
        if let Some(tol) = tolerance {
            if !tol.is_finite() || tol <= 0.0 {
                return Err(Fmi2Error::error(format!("tolerance = {tol} must be finite and > 0")));
            }
        }
        self.machine.start_time = start;
        self.machine.time = start;
        self.machine.stop_time = stop;
        self.machine.tolerance = tolerance;
        Ok(())
    }

    pub fn enter_initialization_mode(&mut self) -> Fmi2Result {
        self.machine.state = InitializationMode;
        Ok(())
    }

    pub fn exit_initialization_mode(&mut self) -> Fmi2Result {
        let mut log = Logger::new(&self.sink);
        self.model
            .initialize(&mut self.vars, self.machine.start_time, &mut log)
            .map_err(|e| Fmi2Error::error(format!("initialization failed: {e}")))?;
        self.machine.initialized = true;
        self.machine.dirty = false;
        self.machine.state = if self.machine.model_exchange {
            EventMode
        } else {
            StepComplete
        };
        Ok(())
    }

    pub fn terminate(&mut self) -> Fmi2Result {
        self.machine.state = Terminated;
        Ok(())
    }

    /// Bring outputs up to date before a get.
    fn refresh(&mut self) -> Fmi2Result {
        if !self.machine.dirty {
            return Ok(());
        }
        if self.machine.initialized {
            self.model
                .update_outputs(&mut self.vars)
                .map_err(|e| Fmi2Error::error(format!("computing outputs failed: {e}")))?;
        } else {
            let mut log = Logger::new(&self.sink);
            self.model
                .initialize(&mut self.vars, self.machine.start_time, &mut log)
                .map_err(|e| Fmi2Error::error(format!("initialization failed: {e}")))?;
        }
        self.machine.dirty = false;
        Ok(())
    }

    fn spec_for(vr: u32, ty: ValueType) -> Fmi2Result<&'static VariableSpec> {
        let spec = M::Vars::spec(vr).ok_or_else(|| Fmi2Error::error(format!("unknown value reference {vr}")))?;
        if spec.value_type != ty {
            return Err(Fmi2Error::error(format!(
                "value reference {vr} ({}) is of type {:?}, not {ty:?}",
                spec.name, spec.value_type
            )));
        }
        Ok(spec)
    }

    /// Read values of type `ty` through `get` into `out` (same length as `vrs`).
    pub fn get_values<T>(
        &mut self,
        vrs: &[u32],
        out: &mut [T],
        ty: ValueType,
        get: impl Fn(&M::Vars, u32) -> Option<T>,
    ) -> Fmi2Result {
        debug_assert_eq!(vrs.len(), out.len());
        if vrs.is_empty() {
            return Ok(());
        }
        self.refresh()?;
        for (vr, slot) in vrs.iter().zip(out.iter_mut()) {
            let spec = Self::spec_for(*vr, ty)?;
            *slot = get(&self.vars, *vr)
                .ok_or_else(|| Fmi2Error::error(format!("value reference {vr} ({}) has no {ty:?} value", spec.name)))?;
        }
        Ok(())
    }

    /// fmi2GetString: pointers stay valid until the next fmi2GetString / Reset / FreeInstance.
    /// Nothing is sized from `nvr` before the value references are read (a host's count
    /// alone must not decide an allocation).
    pub fn get_strings(&mut self, vrs: &[u32], out: &mut [*const std::os::raw::c_char]) -> Fmi2Result {
        debug_assert_eq!(vrs.len(), out.len());
        let mut strings = Vec::new();
        if !vrs.is_empty() {
            self.refresh()?;
            for vr in vrs {
                let spec = Self::spec_for(*vr, ValueType::String)?;
                let s = self.vars.get_string(*vr).ok_or_else(|| {
                    Fmi2Error::error(format!("value reference {vr} ({}) has no String value", spec.name))
                })?;
                strings.push(crate::logger::to_cstring(s));
            }
        }
        for (slot, s) in out.iter_mut().zip(&strings) {
            *slot = s.as_ptr();
        }
        self.strings = strings;
        Ok(())
    }

    /// Whether `spec` may be set in the current state.
    fn check_settable(&self, spec: &VariableSpec) -> Fmi2Result {
        let state = self.machine.state;
        let ok = match (spec.causality, spec.variability) {
            (_, Variability::Constant) => false,
            (Causality::Input, _) => true,
            (Causality::Parameter, Variability::Fixed) => matches!(state, Instantiated | InitializationMode),
            // Model Exchange: tunable parameters change only at events (FMI 2.0 §3.2.3).
            (Causality::Parameter, Variability::Tunable) => state != ContinuousTimeMode,
            (Causality::Parameter, _) => matches!(state, Instantiated | InitializationMode),
            _ => false,
        };
        if ok {
            return Ok(());
        }
        let what = match (spec.causality, spec.variability) {
            (_, Variability::Constant) => "a constant".to_string(),
            (Causality::Parameter, v) => {
                format!(
                    "a {} parameter, not settable in state {state}",
                    format!("{v:?}").to_lowercase()
                )
            }
            (Causality::CalculatedParameter, _) => "a calculatedParameter".to_string(),
            (c, _) => format!("an {}", format!("{c:?}").to_lowercase()),
        };
        Err(Fmi2Error::error(format!(
            "variable {} (value reference {}) cannot be set: it is {what}",
            spec.name, spec.value_reference
        )))
    }

    fn check_range(spec: &VariableSpec, value: f64) -> Fmi2Result {
        if !value.is_finite() {
            return Err(Fmi2Error::error(format!(
                "variable {} (value reference {}): value {value} is not finite",
                spec.name, spec.value_reference
            )));
        }
        if value < spec.min || value > spec.max {
            return Err(Fmi2Error::error(format!(
                "variable {} (value reference {}): value {value} outside [{}, {}]",
                spec.name, spec.value_reference, spec.min, spec.max
            )));
        }
        Ok(())
    }

    /// Validate every value first, then apply them all (nothing changes on error).
    pub fn set_values<T: Copy>(
        &mut self,
        vrs: &[u32],
        values: &[T],
        ty: ValueType,
        numeric: impl Fn(&T) -> Option<f64>,
        mut set: impl FnMut(&mut M::Vars, u32, T) -> bool,
    ) -> Fmi2Result {
        debug_assert_eq!(vrs.len(), values.len());
        for (vr, value) in vrs.iter().zip(values) {
            let spec = Self::spec_for(*vr, ty)?;
            self.check_settable(spec)?;
            if let Some(x) = numeric(value) {
                Self::check_range(spec, x)?;
            }
        }
        for (vr, value) in vrs.iter().zip(values) {
            if !set(&mut self.vars, *vr, *value) {
                return Err(Fmi2Error::error(format!(
                    "value reference {vr} could not be set as {ty:?}"
                )));
            }
        }
        if !vrs.is_empty() {
            self.machine.dirty = true;
        }
        Ok(())
    }

    pub fn set_strings(&mut self, vrs: &[u32], values: &[&str]) -> Fmi2Result {
        self.set_values(vrs, values, ValueType::String, |_| None, |v, vr, s| v.set_string(vr, s))
    }

    pub fn do_step(&mut self, t: f64, h: f64) -> Fmi2Result {
        let expected = self.machine.time;
        if !t.is_finite() || (t - expected).abs() > 1e-9 * expected.abs().max(1.0) {
            return Err(Fmi2Error::error(format!(
                "currentCommunicationPoint = {t} s does not match the FMU time {expected} s"
            )));
        }
        if !(h.is_finite() && h > 0.0) {
            return Err(Fmi2Error::error(format!(
                "communicationStepSize = {h} s must be finite and > 0"
            )));
        }
        if !(t + h).is_finite() {
            return Err(Fmi2Error::error(format!(
                "step from {t} s by {h} s ends at a non-finite time"
            )));
        }
        if let Some(stop) = self.machine.stop_time {
            if t + h > stop + 1e-9 * stop.abs().max(1.0) {
                return Err(Fmi2Error::error(format!(
                    "step from {t} s by {h} s ends after the stop time {stop} s"
                )));
            }
        }
        self.machine.state = StepInProgress;
        let mut log = Logger::new(&self.sink);
        match self.model.do_step(&mut self.vars, t, h, &mut log) {
            Ok(()) => {
                self.machine.time = t + h;
                // Lazy models: outputs computed by the next get (`refresh`).
                self.machine.dirty = M::LAZY_STEP_OUTPUTS;
                self.machine.state = StepComplete;
                Ok(())
            }
            Err(e) => {
                self.machine.state = StepFailed;
                Err(Fmi2Error::error(format!(
                    "step from t = {t} s by h = {h} s failed: {e}"
                )))
            }
        }
    }

    pub fn snapshot(&self) -> Snapshot<M> {
        Snapshot {
            tag: Snapshot::<M>::tag(),
            machine: self.machine,
            model: self.model.clone(),
            vars: self.vars.clone(),
        }
    }

    /// Overwrite `snap` in place (fmi2GetFMUstate with a non-NULL state).
    pub fn snapshot_into(&self, snap: &mut Snapshot<M>) {
        snap.machine = self.machine;
        snap.model.clone_from(&self.model);
        snap.vars.clone_from(&self.vars);
    }

    // ------------------------------------------------------------ Model Exchange

    /// `Err` unless `n` is the number of continuous states.
    fn check_nx(n: usize, what: &str) -> Fmi2Result {
        let nx = M::Vars::CONTINUOUS_STATES.len();
        if n != nx {
            return Err(Fmi2Error::error(format!(
                "{what} = {n}, but the model has {nx} continuous states"
            )));
        }
        Ok(())
    }

    /// fmi2SetTime.
    pub fn set_time(&mut self, t: f64) -> Fmi2Result {
        if !t.is_finite() {
            return Err(Fmi2Error::error(format!("time = {t} is not finite")));
        }
        self.machine.time = t;
        self.machine.dirty = true;
        Ok(())
    }

    /// fmi2SetContinuousStates: every value finite, then handed to the model.
    pub fn set_continuous_states(&mut self, x: &[f64]) -> Fmi2Result {
        Self::check_nx(x.len(), "nx")?;
        for (value, cs) in x.iter().zip(M::Vars::CONTINUOUS_STATES) {
            if !value.is_finite() {
                let name = M::Vars::spec(cs.state).map_or("?", |s| s.name);
                return Err(Fmi2Error::error(format!("state {name} = {value} is not finite")));
            }
        }
        self.model
            .set_continuous_states(&mut self.vars, x)
            .map_err(|e| Fmi2Error::error(format!("setting the continuous states failed: {e}")))?;
        self.machine.dirty = true;
        Ok(())
    }

    /// Read the state (`derivative == false`) or derivative variable of every continuous state.
    fn read_states(&mut self, out: &mut [f64], derivative: bool) -> Fmi2Result {
        Self::check_nx(out.len(), "nx")?;
        self.refresh()?;
        for (slot, cs) in out.iter_mut().zip(M::Vars::CONTINUOUS_STATES) {
            let vr = if derivative { cs.derivative } else { cs.state };
            let value = self
                .vars
                .get_real(vr)
                .ok_or_else(|| Fmi2Error::error(format!("value reference {vr} has no Real value")))?;
            if !value.is_finite() {
                let name = M::Vars::spec(vr).map_or("?", |s| s.name);
                return Err(Fmi2Error::error(format!(
                    "{name} = {value} at t = {} s is not finite",
                    self.machine.time
                )));
            }
            *slot = value;
        }
        Ok(())
    }

    /// fmi2GetContinuousStates.
    pub fn get_continuous_states(&mut self, out: &mut [f64]) -> Fmi2Result {
        self.read_states(out, false)
    }

    /// fmi2GetDerivatives.
    pub fn get_derivatives(&mut self, out: &mut [f64]) -> Fmi2Result {
        self.read_states(out, true)
    }

    /// fmi2GetNominalsOfContinuousStates (the `nominal` attributes; constant).
    pub fn get_nominals(&self, out: &mut [f64]) -> Fmi2Result {
        Self::check_nx(out.len(), "nx")?;
        for (slot, cs) in out.iter_mut().zip(M::Vars::CONTINUOUS_STATES) {
            *slot = cs.nominal;
        }
        Ok(())
    }

    /// fmi2SetFMUstate: the variables are checked again ([`check_restored_variables`]; a
    /// state from fmi2GetFMUstate or fmi2DeSerializeFMUstate passes) before anything is
    /// overwritten, so a refused state leaves the instance as it was.
    pub fn restore(&mut self, snap: &Snapshot<M>) -> Fmi2Result {
        check_restored_variables(&snap.vars)?;
        self.machine = snap.machine;
        self.model.clone_from(&snap.model);
        self.vars.clone_from(&snap.vars);
        Ok(())
    }
}
