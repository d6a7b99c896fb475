//! The generic bodies of every FMI 2.0 function, called by the thin
//! `extern "C"` wrappers that [`export_fmu!`](crate::export_fmu) generates.
//!
//! # Safety
//!
//! Every function here takes the raw arguments of the C function of the same
//! name and has that function's contract: pointers are either NULL (rejected
//! with fmi2Error, except where `n == 0`) or valid for the declared number of
//! elements; `c` is NULL or a component returned by [`instantiate`] for the
//! same model and not yet freed. Every body runs inside
//! [`std::panic::catch_unwind`]; a panic becomes fmi2Error plus a log message.
#![allow(clippy::missing_safety_doc)]

use crate::instance::{mask, Fmi2Error, Fmi2Result, FmiState, Instance, Snapshot, StateMask};
use crate::logger::{Level, LogSink};
use crate::model::FmuModel;
use crate::variables::{ValueType, VariableStore};
use fmi_sys::fmi2::*;
use std::any::Any;
use std::ffi::{c_char, CStr};
use std::panic::{catch_unwind, AssertUnwindSafe};

pub const OK: fmi2Status = fmi2Status_fmi2OK;
pub const WARNING: fmi2Status = fmi2Status_fmi2Warning;
pub const DISCARD: fmi2Status = fmi2Status_fmi2Discard;
pub const ERROR: fmi2Status = fmi2Status_fmi2Error;

fn status_of(level: Level) -> fmi2Status {
    match level {
        Level::Discard => DISCARD,
        Level::Warning => WARNING,
        Level::Info | Level::Debug => OK,
        Level::Error => ERROR,
    }
}

/// Text of a panic payload.
pub fn panic_message(payload: &(dyn Any + Send)) -> &str {
    if let Some(s) = payload.downcast_ref::<&str>() {
        s
    } else if let Some(s) = payload.downcast_ref::<String>() {
        s
    } else {
        "(non-string panic payload)"
    }
}

/// Run `f`, turning any panic into `fallback`.
pub fn guard<T>(fallback: T, f: impl FnOnce() -> T) -> T {
    catch_unwind(AssertUnwindSafe(f)).unwrap_or(fallback)
}

/// The instance behind `c`, if `c` is a live component of model `M`.
unsafe fn instance<'a, M: FmuModel>(c: fmi2Component) -> Option<&'a mut Instance<M>> {
    if c.is_null() || !c.cast::<u64>().is_aligned() {
        return None;
    }
    // SAFETY: per the contract `c` points to an Instance (repr(C), tag first) of some model.
    let tag = unsafe { c.cast::<u64>().read() };
    if tag != Instance::<M>::tag() {
        return None;
    }
    // SAFETY: the tag identifies an Instance<M>.
    Some(unsafe { &mut *c.cast::<Instance<M>>() })
}

/// The common frame of every instance call: instance lookup, state check,
/// panic guard, error logging.
unsafe fn call<M: FmuModel>(
    c: fmi2Component,
    function: &str,
    allowed: StateMask,
    f: impl FnOnce(&mut Instance<M>) -> Fmi2Result,
) -> fmi2Status {
    // SAFETY: contract of the caller.
    let Some(inst) = (unsafe { instance::<M>(c) }) else {
        return ERROR;
    };
    guard(ERROR, || {
        let result = catch_unwind(AssertUnwindSafe(|| {
            inst.check_state(allowed)?;
            f(inst)
        }));
        match result {
            Ok(Ok(())) => OK,
            Ok(Err(e)) => {
                inst.log(e.level, &format_args!("{function}: {}", e.message));
                status_of(e.level)
            }
            Err(payload) => {
                if inst.machine.state == FmiState::StepInProgress {
                    inst.machine.state = FmiState::StepFailed;
                }
                inst.log(
                    Level::Error,
                    &format_args!("{function}: internal error (panic): {}", panic_message(&*payload)),
                );
                ERROR
            }
        }
    })
}

/// The C array `p[..n]` (empty for `n == 0`); an error for NULL or a misaligned or
/// oversized array.
pub unsafe fn slice<'a, T>(p: *const T, n: usize, what: &str) -> Fmi2Result<&'a [T]> {
    if n == 0 {
        return Ok(&[]);
    }
    if p.is_null() {
        return Err(Fmi2Error::error(format!("{what} is NULL (n = {n})")));
    }
    if n > isize::MAX as usize / std::mem::size_of::<T>().max(1) || !p.is_aligned() {
        return Err(Fmi2Error::error(format!("{what}: invalid array (n = {n})")));
    }
    // SAFETY: non-NULL, aligned, and valid for n elements per the C contract.
    Ok(unsafe { std::slice::from_raw_parts(p, n) })
}

/// [`slice`] for an output array.
pub unsafe fn slice_mut<'a, T>(p: *mut T, n: usize, what: &str) -> Fmi2Result<&'a mut [T]> {
    // SAFETY: as `slice`; the caller's output array is exclusively ours during the call.
    let s = unsafe { slice(p.cast_const(), n, what)? };
    Ok(unsafe { std::slice::from_raw_parts_mut(s.as_ptr().cast_mut(), s.len()) })
}

/// A non-NULL output argument.
pub unsafe fn out_ptr<'a, T>(p: *mut T, what: &str) -> Fmi2Result<&'a mut T> {
    if p.is_null() || !p.is_aligned() {
        return Err(Fmi2Error::error(format!("{what} is NULL")));
    }
    // SAFETY: non-NULL output argument per the C contract.
    Ok(unsafe { &mut *p })
}

/// A C string argument, `None` for NULL.
pub unsafe fn c_str<'a>(p: *const c_char) -> Option<&'a CStr> {
    // SAFETY: non-NULL strings are NUL-terminated per the C contract.
    (!p.is_null()).then(|| unsafe { CStr::from_ptr(p) })
}

// ---------------------------------------------------------------- common

pub fn get_types_platform() -> *const c_char {
    c"default".as_ptr()
}

pub fn get_version() -> *const c_char {
    c"2.0".as_ptr()
}

pub unsafe fn set_debug_logging<M: FmuModel>(
    c: fmi2Component,
    logging_on: fmi2Boolean,
    n_categories: usize,
    categories: *const fmi2String,
) -> fmi2Status {
    unsafe {
        call::<M>(c, "fmi2SetDebugLogging", mask::ANY, |inst| {
            let on = logging_on != 0;
            let cats = slice(categories, n_categories, "categories")?;
            // Grown while reading, never sized from the host's count alone.
            let mut names = Vec::new();
            for &p in cats {
                let name = c_str(p).ok_or_else(|| Fmi2Error::error("a category name is NULL"))?;
                let name = name
                    .to_str()
                    .map_err(|_| Fmi2Error::error("a category name is not UTF-8"))?;
                if !crate::LOG_CATEGORIES.iter().any(|(n, _)| *n == name) {
                    let known: Vec<&str> = crate::LOG_CATEGORIES.iter().map(|(n, _)| *n).collect();
                    return Err(Fmi2Error::error(format!(
                        "unknown log category {name:?} (known: {known:?})"
                    )));
                }
                names.push(name);
            }
            if names.is_empty() {
                inst.sink.set_all(on);
            }
            for name in names {
                inst.sink.set_category(name, on);
            }
            Ok(())
        })
    }
}

#[allow(clippy::too_many_arguments)]
pub unsafe fn instantiate<M: FmuModel>(
    instance_name: fmi2String,
    fmu_type: fmi2Type,
    guid: fmi2String,
    resource_location: fmi2String,
    functions: *const fmi2CallbackFunctions,
    _visible: fmi2Boolean,
    logging_on: fmi2Boolean,
) -> fmi2Component {
    guard(std::ptr::null_mut(), || {
        if functions.is_null() || !functions.is_aligned() {
            return std::ptr::null_mut();
        }
        // SAFETY: non-NULL callback struct per the C contract; copied.
        let callbacks = unsafe { functions.read() };
        if callbacks.logger.is_none() {
            return std::ptr::null_mut();
        }
        // SAFETY: NUL-terminated if non-NULL.
        let name = unsafe { c_str(instance_name) }
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        let sink = LogSink::new(callbacks.logger, callbacks.componentEnvironment, &name, logging_on != 0);
        let fail = |msg: String| {
            sink.log(Level::Error, &format_args!("fmi2Instantiate: {msg}"));
            std::ptr::null_mut()
        };
        if name.is_empty() {
            return fail("instanceName is NULL or empty".into());
        }
        let has_states = !M::Vars::CONTINUOUS_STATES.is_empty();
        let model_exchange = match fmu_type {
            t if t == fmi2Type_fmi2CoSimulation => false,
            t if t == fmi2Type_fmi2ModelExchange && has_states => true,
            t if t == fmi2Type_fmi2ModelExchange => {
                return fail(format!(
                    "fmuType fmi2ModelExchange not supported: {} is a Co-Simulation FMU only",
                    M::MODEL_IDENTIFIER
                ))
            }
            other => {
                return fail(format!(
                    "fmuType {other} is neither fmi2ModelExchange (0) nor fmi2CoSimulation (1)"
                ))
            }
        };
        // SAFETY: NUL-terminated if non-NULL.
        let Some(guid) = (unsafe { c_str(guid) }) else {
            return fail("fmuGUID is NULL".into());
        };
        if guid.to_bytes() != M::GUID.as_bytes() {
            return fail(format!(
                "GUID mismatch: got {:?}, this binary of {} has {:?}",
                guid.to_string_lossy(),
                M::MODEL_IDENTIFIER,
                M::GUID
            ));
        }
        // SAFETY: NUL-terminated if non-NULL.
        let resources = unsafe { c_str(resource_location) }
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        match catch_unwind(AssertUnwindSafe(|| Instance::<M>::new(sink, resources))) {
            Ok(mut inst) => {
                inst.machine.model_exchange = model_exchange;
                Box::into_raw(Box::new(inst)).cast()
            }
            Err(payload) => {
                // The sink moved into the closure; build a fresh one for the report.
                let sink = LogSink::new(callbacks.logger, callbacks.componentEnvironment, &name, true);
                sink.log(
                    Level::Error,
                    &format_args!("fmi2Instantiate: panic: {}", panic_message(&*payload)),
                );
                std::ptr::null_mut()
            }
        }
    })
}

pub unsafe fn free_instance<M: FmuModel>(c: fmi2Component) {
    // SAFETY: contract of the caller.
    let Some(inst) = (unsafe { instance::<M>(c) }) else {
        return;
    };
    inst.tag = 0;
    // SAFETY: `c` came from Box::into_raw in `instantiate`; the tag was cleared
    // so a second free of the same pointer is (likely) detected.
    let boxed = unsafe { Box::from_raw(c.cast::<Instance<M>>()) };
    guard((), move || drop(boxed));
}

pub unsafe fn setup_experiment<M: FmuModel>(
    c: fmi2Component,
    tolerance_defined: fmi2Boolean,
    tolerance: fmi2Real,
    start_time: fmi2Real,
    stop_time_defined: fmi2Boolean,
    stop_time: fmi2Real,
) -> fmi2Status {
    unsafe {
        call::<M>(c, "fmi2SetupExperiment", mask::INSTANTIATED, |inst| {
            inst.setup_experiment(
                (tolerance_defined != 0).then_some(tolerance),
                start_time,
                (stop_time_defined != 0).then_some(stop_time),
            )
        })
    }
}

pub unsafe fn enter_initialization_mode<M: FmuModel>(c: fmi2Component) -> fmi2Status {
    unsafe {
        call::<M>(c, "fmi2EnterInitializationMode", mask::INSTANTIATED, |i| {
            i.enter_initialization_mode()
        })
    }
}

pub unsafe fn exit_initialization_mode<M: FmuModel>(c: fmi2Component) -> fmi2Status {
    unsafe {
        call::<M>(c, "fmi2ExitInitializationMode", mask::INITIALIZATION_MODE, |i| {
            i.exit_initialization_mode()
        })
    }
}

pub unsafe fn terminate<M: FmuModel>(c: fmi2Component) -> fmi2Status {
    unsafe { call::<M>(c, "fmi2Terminate", mask::TERMINATE, |i| i.terminate()) }
}

pub unsafe fn reset<M: FmuModel>(c: fmi2Component) -> fmi2Status {
    unsafe {
        call::<M>(c, "fmi2Reset", mask::ANY, |i| {
            i.reset();
            Ok(())
        })
    }
}

// ---------------------------------------------------------------- values

pub unsafe fn get_real<M: FmuModel>(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2Real,
) -> fmi2Status {
    unsafe {
        call::<M>(c, "fmi2GetReal", mask::GET, |inst| {
            let vrs = slice(vr, nvr, "vr")?;
            let out = slice_mut(value, nvr, "value")?;
            inst.get_values(vrs, out, ValueType::Real, |v, r| v.get_real(r))
        })
    }
}

pub unsafe fn get_integer<M: FmuModel>(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2Integer,
) -> fmi2Status {
    unsafe {
        call::<M>(c, "fmi2GetInteger", mask::GET, |inst| {
            let vrs = slice(vr, nvr, "vr")?;
            let out = slice_mut(value, nvr, "value")?;
            inst.get_values(vrs, out, ValueType::Integer, |v, r| v.get_integer(r))
        })
    }
}

pub unsafe fn get_boolean<M: FmuModel>(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2Boolean,
) -> fmi2Status {
    unsafe {
        call::<M>(c, "fmi2GetBoolean", mask::GET, |inst| {
            let vrs = slice(vr, nvr, "vr")?;
            let out = slice_mut(value, nvr, "value")?;
            inst.get_values(vrs, out, ValueType::Boolean, |v, r| {
                v.get_boolean(r).map(fmi2Boolean::from)
            })
        })
    }
}

pub unsafe fn get_string<M: FmuModel>(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2String,
) -> fmi2Status {
    unsafe {
        call::<M>(c, "fmi2GetString", mask::GET, |inst| {
            let vrs = slice(vr, nvr, "vr")?;
            let out = slice_mut(value, nvr, "value")?;
            inst.get_strings(vrs, out)
        })
    }
}

pub unsafe fn set_real<M: FmuModel>(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Real,
) -> fmi2Status {
    unsafe {
        call::<M>(c, "fmi2SetReal", mask::SET, |inst| {
            let vrs = slice(vr, nvr, "vr")?;
            let values = slice(value, nvr, "value")?;
            inst.set_values(vrs, values, ValueType::Real, |x| Some(*x), |v, r, x| v.set_real(r, x))
        })
    }
}

pub unsafe fn set_integer<M: FmuModel>(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Integer,
) -> fmi2Status {
    unsafe {
        call::<M>(c, "fmi2SetInteger", mask::SET, |inst| {
            let vrs = slice(vr, nvr, "vr")?;
            let values = slice(value, nvr, "value")?;
            inst.set_values(
                vrs,
                values,
                ValueType::Integer,
                |x| Some(f64::from(*x)),
                |v, r, x| v.set_integer(r, x),
            )
        })
    }
}

pub unsafe fn set_boolean<M: FmuModel>(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Boolean,
) -> fmi2Status {
    unsafe {
        call::<M>(c, "fmi2SetBoolean", mask::SET, |inst| {
            let vrs = slice(vr, nvr, "vr")?;
            let values = slice(value, nvr, "value")?;
            inst.set_values(
                vrs,
                values,
                ValueType::Boolean,
                |_| None,
                |v, r, x| v.set_boolean(r, x != 0),
            )
        })
    }
}

pub unsafe fn set_string<M: FmuModel>(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2String,
) -> fmi2Status {
    unsafe {
        call::<M>(c, "fmi2SetString", mask::SET, |inst| {
            let vrs = slice(vr, nvr, "vr")?;
            let ptrs = slice(value, nvr, "value")?;
            // Grown while reading, never sized from the host's count alone.
            let mut strs = Vec::new();
            for (r, &p) in vrs.iter().zip(ptrs) {
                let s = c_str(p).ok_or_else(|| Fmi2Error::error(format!("value for value reference {r} is NULL")))?;
                let s = s
                    .to_str()
                    .map_err(|_| Fmi2Error::error(format!("value for value reference {r} is not UTF-8")))?;
                strs.push(s);
            }
            inst.set_strings(vrs, &strs)
        })
    }
}

// ---------------------------------------------------------------- FMU state

unsafe fn snapshot<'a, M: FmuModel>(p: fmi2FMUstate) -> Fmi2Result<&'a mut Snapshot<M>> {
    if p.is_null() {
        return Err(Fmi2Error::error("FMUstate is NULL"));
    }
    // SAFETY: per the contract `p` is an FMU state of this FMU (repr(C), tag first).
    if !p.cast::<u64>().is_aligned() || unsafe { p.cast::<u64>().read() } != Snapshot::<M>::tag() {
        return Err(Fmi2Error::error("FMUstate is not a (live) FMU state of this model"));
    }
    // SAFETY: the tag identifies a Snapshot<M> allocated by Box.
    Ok(unsafe { &mut *p.cast::<Snapshot<M>>() })
}

pub unsafe fn get_fmu_state<M: FmuModel>(c: fmi2Component, state: *mut fmi2FMUstate) -> fmi2Status {
    unsafe {
        call::<M>(c, "fmi2GetFMUstate", mask::ANY, |inst| {
            let slot = out_ptr(state, "FMUstate")?;
            if slot.is_null() {
                *slot = Box::into_raw(Box::new(inst.snapshot())).cast();
            } else {
                inst.snapshot_into(snapshot::<M>(*slot)?);
            }
            Ok(())
        })
    }
}

pub unsafe fn set_fmu_state<M: FmuModel>(c: fmi2Component, state: fmi2FMUstate) -> fmi2Status {
    unsafe {
        call::<M>(c, "fmi2SetFMUstate", mask::ANY, |inst| {
            let snap = snapshot::<M>(state)?;
            if snap.machine.model_exchange != inst.machine.model_exchange {
                return Err(Fmi2Error::error(
                    "the FMU state belongs to an instance of the other interface (Model Exchange vs Co-Simulation)",
                ));
            }
            inst.restore(snap)
        })
    }
}

pub unsafe fn free_fmu_state<M: FmuModel>(c: fmi2Component, state: *mut fmi2FMUstate) -> fmi2Status {
    unsafe {
        call::<M>(c, "fmi2FreeFMUstate", mask::ANY, |_| {
            if state.is_null() || (*state).is_null() {
                return Ok(());
            }
            let snap = snapshot::<M>(*state)?;
            snap.tag = 0;
            drop(Box::from_raw(std::ptr::from_mut(snap)));
            *state = std::ptr::null_mut();
            Ok(())
        })
    }
}

pub unsafe fn serialized_fmu_state_size<M: FmuModel>(
    c: fmi2Component,
    state: fmi2FMUstate,
    size: *mut usize,
) -> fmi2Status {
    unsafe {
        call::<M>(c, "fmi2SerializedFMUstateSize", mask::ANY, |_| {
            let out = out_ptr(size, "size")?;
            *out = snapshot::<M>(state)?.serialize().len();
            Ok(())
        })
    }
}

pub unsafe fn serialize_fmu_state<M: FmuModel>(
    c: fmi2Component,
    state: fmi2FMUstate,
    serialized: *mut fmi2Byte,
    size: usize,
) -> fmi2Status {
    unsafe {
        call::<M>(c, "fmi2SerializeFMUstate", mask::ANY, |_| {
            let bytes = snapshot::<M>(state)?.serialize();
            if size < bytes.len() {
                return Err(Fmi2Error::error(format!(
                    "buffer of {size} bytes too small for {} bytes",
                    bytes.len()
                )));
            }
            let out = slice_mut(serialized.cast::<u8>(), bytes.len(), "serializedState")?;
            out.copy_from_slice(&bytes);
            Ok(())
        })
    }
}

pub unsafe fn deserialize_fmu_state<M: FmuModel>(
    c: fmi2Component,
    serialized: *const fmi2Byte,
    size: usize,
    state: *mut fmi2FMUstate,
) -> fmi2Status {
    unsafe {
        call::<M>(c, "fmi2DeSerializeFMUstate", mask::ANY, |_| {
            let slot = out_ptr(state, "FMUstate")?;
            let bytes = slice(serialized.cast::<u8>(), size, "serializedState")?;
            let snap = Snapshot::<M>::deserialize(bytes)?;
            *slot = Box::into_raw(Box::new(snap)).cast();
            Ok(())
        })
    }
}

// ---------------------------------------------------------------- Co-Simulation

pub unsafe fn do_step<M: FmuModel>(
    c: fmi2Component,
    current_communication_point: fmi2Real,
    communication_step_size: fmi2Real,
    _no_set_fmu_state_prior_to_current_point: fmi2Boolean,
) -> fmi2Status {
    unsafe {
        call::<M>(c, "fmi2DoStep", mask::DO_STEP, |inst| {
            inst.do_step(current_communication_point, communication_step_size)
        })
    }
}

pub unsafe fn cancel_step<M: FmuModel>(c: fmi2Component) -> fmi2Status {
    unsafe {
        call::<M>(c, "fmi2CancelStep", mask::CANCEL_STEP, |inst| {
            inst.machine.state = FmiState::StepCanceled;
            Ok(())
        })
    }
}

fn unavailable(kind: fmi2StatusKind, function: &str) -> Fmi2Error {
    Fmi2Error::discard(format!("status kind {kind} is not available through {function}"))
}

pub unsafe fn get_status<M: FmuModel>(c: fmi2Component, kind: fmi2StatusKind, value: *mut fmi2Status) -> fmi2Status {
    unsafe {
        call::<M>(c, "fmi2GetStatus", mask::STATUS, |inst| {
            let out = out_ptr(value, "value")?;
            match kind {
                k if k == fmi2StatusKind_fmi2DoStepStatus => {
                    *out = match inst.state() {
                        FmiState::StepFailed => ERROR,
                        FmiState::StepCanceled => DISCARD,
                        _ => OK,
                    };
                    Ok(())
                }
                _ => Err(unavailable(kind, "fmi2GetStatus")),
            }
        })
    }
}

pub unsafe fn get_real_status<M: FmuModel>(c: fmi2Component, kind: fmi2StatusKind, value: *mut fmi2Real) -> fmi2Status {
    unsafe {
        call::<M>(c, "fmi2GetRealStatus", mask::STATUS, |inst| {
            let out = out_ptr(value, "value")?;
            match kind {
                k if k == fmi2StatusKind_fmi2LastSuccessfulTime => {
                    *out = inst.machine.time;
                    Ok(())
                }
                _ => Err(unavailable(kind, "fmi2GetRealStatus")),
            }
        })
    }
}

pub unsafe fn get_integer_status<M: FmuModel>(
    c: fmi2Component,
    kind: fmi2StatusKind,
    value: *mut fmi2Integer,
) -> fmi2Status {
    unsafe {
        call::<M>(c, "fmi2GetIntegerStatus", mask::STATUS, |_| {
            out_ptr(value, "value")?;
            Err(unavailable(kind, "fmi2GetIntegerStatus"))
        })
    }
}

pub unsafe fn get_boolean_status<M: FmuModel>(
    c: fmi2Component,
    kind: fmi2StatusKind,
    value: *mut fmi2Boolean,
) -> fmi2Status {
    unsafe {
        call::<M>(c, "fmi2GetBooleanStatus", mask::STATUS, |inst| {
            let out = out_ptr(value, "value")?;
            match kind {
                k if k == fmi2StatusKind_fmi2Terminated => {
                    *out = matches!(inst.state(), FmiState::StepFailed | FmiState::Terminated).into();
                    Ok(())
                }
                _ => Err(unavailable(kind, "fmi2GetBooleanStatus")),
            }
        })
    }
}

pub unsafe fn get_string_status<M: FmuModel>(
    c: fmi2Component,
    kind: fmi2StatusKind,
    value: *mut fmi2String,
) -> fmi2Status {
    unsafe {
        call::<M>(c, "fmi2GetStringStatus", mask::STATUS, |_| {
            out_ptr(value, "value")?;
            Err(unavailable(kind, "fmi2GetStringStatus"))
        })
    }
}

// ---------------------------------------------------------------- not supported

/// Log "`function`: not supported (`why`)" and return fmi2Error.
pub unsafe fn not_supported<M: FmuModel>(c: fmi2Component, function: &str, why: &str) -> fmi2Status {
    unsafe {
        call::<M>(c, function, mask::ANY, |_| {
            Err(Fmi2Error::error(format!("not supported ({why})")))
        })
    }
}

// ---------------------------------------------------------------- Model Exchange
//
// Legal only in the Model Exchange states (EventMode, ContinuousTimeMode, …), which a
// Co-Simulation instance never reaches: there every call below fails with "illegal
// call in state …", and a model without continuous states cannot be instantiated as
// Model Exchange at all.

pub unsafe fn enter_event_mode<M: FmuModel>(c: fmi2Component) -> fmi2Status {
    unsafe {
        call::<M>(c, "fmi2EnterEventMode", mask::ENTER_EVENT_MODE, |inst| {
            inst.machine.state = FmiState::EventMode;
            Ok(())
        })
    }
}

/// No discrete states, no time events: one iteration, nothing changes.
pub unsafe fn new_discrete_states<M: FmuModel>(c: fmi2Component, info: *mut fmi2EventInfo) -> fmi2Status {
    unsafe {
        call::<M>(c, "fmi2NewDiscreteStates", mask::NEW_DISCRETE_STATES, |_| {
            let info = out_ptr(info, "eventInfo")?;
            info.newDiscreteStatesNeeded = fmi2False as fmi2Boolean;
            info.terminateSimulation = fmi2False as fmi2Boolean;
            info.nominalsOfContinuousStatesChanged = fmi2False as fmi2Boolean;
            info.valuesOfContinuousStatesChanged = fmi2False as fmi2Boolean;
            info.nextEventTimeDefined = fmi2False as fmi2Boolean;
            info.nextEventTime = 0.0;
            Ok(())
        })
    }
}

pub unsafe fn enter_continuous_time_mode<M: FmuModel>(c: fmi2Component) -> fmi2Status {
    unsafe {
        call::<M>(
            c,
            "fmi2EnterContinuousTimeMode",
            mask::ENTER_CONTINUOUS_TIME_MODE,
            |inst| {
                inst.machine.state = FmiState::ContinuousTimeMode;
                Ok(())
            },
        )
    }
}

/// No step events: never asks for event mode or termination.
pub unsafe fn completed_integrator_step<M: FmuModel>(
    c: fmi2Component,
    _no_set_fmu_state_prior_to_current_point: fmi2Boolean,
    enter_event_mode: *mut fmi2Boolean,
    terminate_simulation: *mut fmi2Boolean,
) -> fmi2Status {
    unsafe {
        call::<M>(
            c,
            "fmi2CompletedIntegratorStep",
            mask::COMPLETED_INTEGRATOR_STEP,
            |_| {
                let enter = out_ptr(enter_event_mode, "enterEventMode")?;
                let terminate = out_ptr(terminate_simulation, "terminateSimulation")?;
                *enter = fmi2False as fmi2Boolean;
                *terminate = fmi2False as fmi2Boolean;
                Ok(())
            },
        )
    }
}

pub unsafe fn set_time<M: FmuModel>(c: fmi2Component, time: fmi2Real) -> fmi2Status {
    unsafe { call::<M>(c, "fmi2SetTime", mask::SET_TIME, |inst| inst.set_time(time)) }
}

pub unsafe fn set_continuous_states<M: FmuModel>(c: fmi2Component, x: *const fmi2Real, nx: usize) -> fmi2Status {
    unsafe {
        call::<M>(c, "fmi2SetContinuousStates", mask::SET_CONTINUOUS_STATES, |inst| {
            inst.set_continuous_states(slice(x, nx, "x")?)
        })
    }
}

pub unsafe fn get_derivatives<M: FmuModel>(c: fmi2Component, dx: *mut fmi2Real, nx: usize) -> fmi2Status {
    unsafe {
        call::<M>(c, "fmi2GetDerivatives", mask::GET_DERIVATIVES, |inst| {
            inst.get_derivatives(slice_mut(dx, nx, "derivatives")?)
        })
    }
}

/// numberOfEventIndicators = 0: only `ni == 0` is valid.
pub unsafe fn get_event_indicators<M: FmuModel>(c: fmi2Component, z: *mut fmi2Real, ni: usize) -> fmi2Status {
    unsafe {
        call::<M>(c, "fmi2GetEventIndicators", mask::GET_EVENT_INDICATORS, |_| {
            slice_mut(z, ni, "eventIndicators")?;
            if ni != 0 {
                return Err(Fmi2Error::error(format!(
                    "ni = {ni}, but the model has no event indicators"
                )));
            }
            Ok(())
        })
    }
}

pub unsafe fn get_continuous_states<M: FmuModel>(c: fmi2Component, x: *mut fmi2Real, nx: usize) -> fmi2Status {
    unsafe {
        call::<M>(c, "fmi2GetContinuousStates", mask::GET_CONTINUOUS_STATES, |inst| {
            inst.get_continuous_states(slice_mut(x, nx, "x")?)
        })
    }
}

pub unsafe fn get_nominals_of_continuous_states<M: FmuModel>(
    c: fmi2Component,
    x_nominal: *mut fmi2Real,
    nx: usize,
) -> fmi2Status {
    unsafe {
        call::<M>(c, "fmi2GetNominalsOfContinuousStates", mask::GET_NOMINALS, |inst| {
            inst.get_nominals(slice_mut(x_nominal, nx, "x_nominal")?)
        })
    }
}
