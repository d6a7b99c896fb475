//! One FMI 3.0 instance: the FMI-independent core of `fmi2-export` ([`Instance`]: model,
//! variables, value checks, FMU state) under the FMI 3.0 state names and state table.
//!
//! FMI 3.0 (§4.2.5 Co-Simulation, §3.2.5 Model Exchange) has the FMI 2.0 states under
//! other names: StepMode is FMI 2.0's StepComplete; a failed step leaves the instance
//! where only getters, Terminate, Reset, FreeInstance and the FMU-state functions are
//! legal (FMI 2.0's StepFailed). The core keeps its FMI 2.0 state enum; this module maps
//! the names and owns the FMI 3.0 legal-state masks.

use fmi2_export::instance::{FmiState, StateMask};
use fmi2_export::{FmuModel, Instance, VariableStore};

use FmiState::*;

/// The FMI 3.0 name of a core state, for log messages.
pub fn state_name(state: FmiState) -> &'static str {
    match state {
        Instantiated => "Instantiated",
        InitializationMode => "InitializationMode",
        StepComplete => "StepMode",
        StepInProgress => "StepMode (step in progress)",
        StepFailed => "StepMode (after a failed step)",
        StepCanceled => "StepMode (step canceled)",
        Terminated => "Terminated",
        EventMode => "EventMode",
        ContinuousTimeMode => "ContinuousTimeMode",
    }
}

/// Legal states per FMI 3.0 call (the FMI 3.0 state tables, restricted to the
/// capabilities the model description declares: no event mode in Co-Simulation, no
/// configuration mode, no clocks).
pub mod mask {
    use super::*;
    use fmi2_export::instance::mask as fmi2;
    /// Every state; Set{…} as in FMI 2.0 (the causality/variability checks of the core
    /// decide per variable).
    pub const ANY: StateMask = fmi2::ANY;
    pub const SET: StateMask = fmi2::SET;
    pub const ENTER_INITIALIZATION_MODE: StateMask = StateMask::of(&[Instantiated]);
    pub const EXIT_INITIALIZATION_MODE: StateMask = StateMask::of(&[InitializationMode]);
    pub const GET: StateMask = StateMask::of(&[
        InitializationMode,
        StepComplete,
        StepFailed,
        Terminated,
        EventMode,
        ContinuousTimeMode,
    ]);
    pub const DO_STEP: StateMask = StateMask::of(&[StepComplete]);
    pub const TERMINATE: StateMask = StateMask::of(&[StepComplete, StepFailed, EventMode, ContinuousTimeMode]);
    // Model Exchange (§3.2.5).
    pub const ENTER_EVENT_MODE: StateMask = StateMask::of(&[ContinuousTimeMode]);
    pub const UPDATE_DISCRETE_STATES: StateMask = StateMask::of(&[EventMode]);
    pub const ENTER_CONTINUOUS_TIME_MODE: StateMask = StateMask::of(&[EventMode]);
    pub const COMPLETED_INTEGRATOR_STEP: StateMask = StateMask::of(&[ContinuousTimeMode]);
    pub const SET_TIME: StateMask = StateMask::of(&[EventMode, ContinuousTimeMode]);
    pub const SET_CONTINUOUS_STATES: StateMask = StateMask::of(&[ContinuousTimeMode]);
    pub const GET_CONTINUOUS: StateMask =
        StateMask::of(&[InitializationMode, EventMode, ContinuousTimeMode, Terminated]);
    pub const GET_NOMINALS: StateMask = StateMask::of(&[
        Instantiated,
        InitializationMode,
        EventMode,
        ContinuousTimeMode,
        Terminated,
    ]);
}

/// The value reference of the independent variable `time`, which FMI 3.0 requires in
/// every model description (exactly one `causality="independent"` variable) and the FMI
/// 2.0 declarations leave implicit: one above the largest declared value reference
/// (`cargo xtask dist` writes the same number into the FMI 3.0 modelDescription.xml).
pub fn time_value_reference<V: VariableStore>() -> u32 {
    V::VARIABLES
        .iter()
        .map(|v| v.value_reference)
        .max()
        .map_or(0, |m| m + 1)
}

/// Tag of a live FMI 3.0 instance (`kind` 1) or FMU state (`kind` 2) of model `M`:
/// FNV-1a of the model's type name and GUID, so that a pointer of another model, of the
/// FMI 2.0 layer, or a freed one is refused.
pub(crate) fn tag_for<M: FmuModel>(kind: u64) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325 ^ kind.wrapping_mul(0x9e37_79b9_7f4a_7c15);
    for b in std::any::type_name::<M>()
        .bytes()
        .chain(M::GUID.bytes())
        .chain(*b"fmi3")
    {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0100_0000_01b3);
    }
    h
}

/// One FMI 3.0 instance (`fmi3Instance` points here).
#[repr(C)]
pub struct Instance3<M: FmuModel> {
    /// First field, checked on every call (wrong model / layer / freed pointer).
    pub(crate) tag: u64,
    /// The model, its variables and the state machine.
    pub inner: Instance<M>,
    /// [`time_value_reference`] of the model.
    pub time_vr: u32,
}

impl<M: FmuModel> Instance3<M> {
    pub(crate) fn tag() -> u64 {
        tag_for::<M>(1)
    }

    pub fn new(inner: Instance<M>) -> Self {
        Self {
            tag: Self::tag(),
            inner,
            time_vr: time_value_reference::<M::Vars>(),
        }
    }

    pub fn state(&self) -> FmiState {
        self.inner.machine.state
    }

    /// `Err(message)` unless the current state is in `mask`.
    pub fn check_state(&self, mask: StateMask) -> Result<(), String> {
        if mask.contains(self.state()) {
            Ok(())
        } else {
            Err(format!("illegal call in state {}", state_name(self.state())))
        }
    }
}

/// An FMU state of the FMI 3.0 layer (`fmi3FMUState` points here).
#[repr(C)]
pub struct State3<M: FmuModel> {
    pub(crate) tag: u64,
    pub snapshot: fmi2_export::Snapshot<M>,
}

impl<M: FmuModel> State3<M> {
    pub(crate) fn tag() -> u64 {
        tag_for::<M>(2)
    }

    pub fn new(snapshot: fmi2_export::Snapshot<M>) -> Self {
        Self {
            tag: Self::tag(),
            snapshot,
        }
    }
}
