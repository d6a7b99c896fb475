//! The generic bodies of every FMI 3.0 function, called by the thin `extern "C"`
//! wrappers that [`export_fmu3!`](crate::export_fmu3) generates.
//!
//! # Safety
//!
//! Every function here takes the raw arguments of the C function of the same name and
//! has that function's contract: pointers are NULL (rejected with fmi3Error, except where
//! the count is 0) or valid for the declared number of elements; `c` is NULL or an
//! instance returned by an instantiate function of the same model and not yet freed.
//! Every body runs inside [`std::panic::catch_unwind`]; a panic becomes fmi3Error plus a
//! log message.
#![allow(clippy::missing_safety_doc)]

use crate::instance::{mask, Instance3, State3};
use fmi2_export::ffi::{c_str, guard, out_ptr, panic_message, slice, slice_mut};
use fmi2_export::instance::{FmiState, StateMask};
use fmi2_export::{Fmi2Error, FmuModel, Instance, Level, LogSink, ValueType, VariableStore};
use fmi_sys::fmi3::*;
use std::ffi::c_char;
use std::panic::{catch_unwind, AssertUnwindSafe};

pub const OK: fmi3Status = fmi3Status_fmi3OK;
pub const WARNING: fmi3Status = fmi3Status_fmi3Warning;
pub const DISCARD: fmi3Status = fmi3Status_fmi3Discard;
pub const ERROR: fmi3Status = fmi3Status_fmi3Error;

type Result3<T = ()> = Result<T, Fmi2Error>;

fn err<T>(message: impl Into<String>) -> Result3<T> {
    Err(Fmi2Error::error(message))
}

fn status_of(level: Level) -> fmi3Status {
    match level {
        Level::Discard => DISCARD,
        Level::Warning => WARNING,
        Level::Info | Level::Debug => OK,
        Level::Error => ERROR,
    }
}

/// The instance behind `c`, if `c` is a live FMI 3.0 instance of model `M`.
unsafe fn instance<'a, M: FmuModel>(c: fmi3Instance) -> Option<&'a mut Instance3<M>> {
    if c.is_null() || !c.cast::<u64>().is_aligned() {
        return None;
    }
    // SAFETY: per the contract `c` points to an Instance3 (repr(C), tag first).
    if unsafe { c.cast::<u64>().read() } != Instance3::<M>::tag() {
        return None;
    }
    // SAFETY: the tag identifies an Instance3<M>.
    Some(unsafe { &mut *c.cast::<Instance3<M>>() })
}

/// The frame of every instance call: lookup, state check, panic guard, error logging.
unsafe fn call<M: FmuModel>(
    c: fmi3Instance,
    function: &str,
    allowed: StateMask,
    f: impl FnOnce(&mut Instance3<M>) -> Result3,
) -> fmi3Status {
    // SAFETY: contract of the caller.
    let Some(inst) = (unsafe { instance::<M>(c) }) else {
        return ERROR;
    };
    guard(ERROR, || {
        let result = catch_unwind(AssertUnwindSafe(|| {
            inst.check_state(allowed).map_err(Fmi2Error::error)?;
            f(inst)
        }));
        match result {
            Ok(Ok(())) => OK,
            Ok(Err(e)) => {
                inst.inner.log(e.level, &format_args!("{function}: {}", e.message));
                status_of(e.level)
            }
            Err(payload) => {
                if inst.state() == FmiState::StepInProgress {
                    inst.inner.machine.state = FmiState::StepFailed;
                }
                inst.inner.log(
                    Level::Error,
                    &format_args!("{function}: internal error (panic): {}", panic_message(&*payload)),
                );
                ERROR
            }
        }
    })
}

/// The value-reference array of a get/set: every variable of this layer is a scalar,
/// so `nValues` must equal `nValueReferences`.
unsafe fn value_refs<'a>(vr: *const fmi3ValueReference, nvr: usize, n_values: usize) -> Result3<&'a [u32]> {
    if n_values != nvr {
        return err(format!(
            "nValues = {n_values}, but nValueReferences = {nvr} and every variable is a scalar"
        ));
    }
    // SAFETY: contract of the caller.
    unsafe { slice(vr, nvr, "valueReferences") }
}

// ---------------------------------------------------------------- common

pub fn get_version() -> *const c_char {
    c"3.0".as_ptr()
}

pub unsafe fn set_debug_logging<M: FmuModel>(
    c: fmi3Instance,
    logging_on: bool,
    n_categories: usize,
    categories: *const fmi3String,
) -> fmi3Status {
    unsafe {
        call::<M>(c, "fmi3SetDebugLogging", mask::ANY, |inst| {
            let cats = slice(categories, n_categories, "categories")?;
            if cats.is_empty() {
                inst.inner.sink.set_all(logging_on);
                return Ok(());
            }
            // Every name checked before any filter changes.
            for &p in cats {
                let name = c_str(p)
                    .and_then(|s| s.to_str().ok())
                    .ok_or_else(|| Fmi2Error::error("a category name is NULL or not UTF-8"))?;
                if !fmi2_export::LOG_CATEGORIES.iter().any(|(n, _)| *n == name) {
                    return err(format!("unknown log category {name:?}"));
                }
            }
            for &p in cats {
                if let Some(name) = c_str(p).and_then(|s| s.to_str().ok()) {
                    inst.inner.sink.set_category(name, logging_on);
                }
            }
            Ok(())
        })
    }
}

/// fmi3InstantiateCoSimulation (`model_exchange == false`) and
/// fmi3InstantiateModelExchange. NULL for an empty name, a wrong instantiation token,
/// Model Exchange of a model without continuous states, or `eventModeUsed`
/// (`hasEventMode="false"`); the reason goes to `log_message` when given.
#[allow(clippy::too_many_arguments)]
pub unsafe fn instantiate<M: FmuModel>(
    instance_name: fmi3String,
    token: fmi3String,
    resource_path: fmi3String,
    logging_on: bool,
    env: fmi3InstanceEnvironment,
    log_message: fmi3LogMessageCallback,
    model_exchange: bool,
    event_mode_used: bool,
) -> fmi3Instance {
    guard(std::ptr::null_mut(), || {
        // SAFETY: NUL-terminated if non-NULL.
        let name = unsafe { c_str(instance_name) }
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        let function = if model_exchange {
            "fmi3InstantiateModelExchange"
        } else {
            "fmi3InstantiateCoSimulation"
        };
        let sink = LogSink::new_fmi3(log_message, env, &name, logging_on);
        let fail = |msg: String| {
            sink.log(Level::Error, &format_args!("{function}: {msg}"));
            std::ptr::null_mut()
        };
        if name.is_empty() {
            return fail("instanceName is NULL or empty".into());
        }
        if model_exchange && M::Vars::CONTINUOUS_STATES.is_empty() {
            return fail(format!(
                "{} has no continuous states: Co-Simulation only",
                M::MODEL_IDENTIFIER
            ));
        }
        if event_mode_used {
            return fail("eventModeUsed = true, but the FMU declares hasEventMode=\"false\"".into());
        }
        // SAFETY: NUL-terminated if non-NULL.
        let Some(token) = (unsafe { c_str(token) }) else {
            return fail("instantiationToken is NULL".into());
        };
        if token.to_bytes() != M::GUID.as_bytes() {
            return fail(format!(
                "instantiationToken mismatch: got {:?}, this binary of {} has {:?}",
                token.to_string_lossy(),
                M::MODEL_IDENTIFIER,
                M::GUID
            ));
        }
        // SAFETY: NUL-terminated if non-NULL.
        let resources = unsafe { c_str(resource_path) }
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        match catch_unwind(AssertUnwindSafe(|| Instance3::new(Instance::<M>::new(sink, resources)))) {
            Ok(mut inst) => {
                inst.inner.machine.model_exchange = model_exchange;
                Box::into_raw(Box::new(inst)).cast()
            }
            Err(payload) => {
                let sink = LogSink::new_fmi3(log_message, env, &name, true);
                sink.log(
                    Level::Error,
                    &format_args!("{function}: panic: {}", panic_message(&*payload)),
                );
                std::ptr::null_mut()
            }
        }
    })
}

/// fmi3InstantiateScheduledExecution: not supported (no ScheduledExecution interface).
pub unsafe fn instantiate_scheduled_execution(
    instance_name: fmi3String,
    env: fmi3InstanceEnvironment,
    log_message: fmi3LogMessageCallback,
) -> fmi3Instance {
    guard(std::ptr::null_mut(), || {
        // SAFETY: NUL-terminated if non-NULL.
        let name = unsafe { c_str(instance_name) }
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        LogSink::new_fmi3(log_message, env, &name, true).log(
            Level::Error,
            &"fmi3InstantiateScheduledExecution: not supported (the FMU has no <ScheduledExecution> interface)",
        );
        std::ptr::null_mut()
    })
}

pub unsafe fn free_instance<M: FmuModel>(c: fmi3Instance) {
    // SAFETY: contract of the caller.
    let Some(inst) = (unsafe { instance::<M>(c) }) else {
        return;
    };
    inst.tag = 0;
    // SAFETY: `c` came from Box::into_raw in `instantiate`; the tag was cleared so a
    // second free of the same pointer is (likely) detected.
    let boxed = unsafe { Box::from_raw(c.cast::<Instance3<M>>()) };
    guard((), || drop(boxed));
}

pub unsafe fn enter_initialization_mode<M: FmuModel>(
    c: fmi3Instance,
    tolerance_defined: bool,
    tolerance: fmi3Float64,
    start_time: fmi3Float64,
    stop_time_defined: bool,
    stop_time: fmi3Float64,
) -> fmi3Status {
    unsafe {
        call::<M>(
            c,
            "fmi3EnterInitializationMode",
            mask::ENTER_INITIALIZATION_MODE,
            |inst| {
                inst.inner.setup_experiment(
                    tolerance_defined.then_some(tolerance),
                    start_time,
                    stop_time_defined.then_some(stop_time),
                )?;
                inst.inner.enter_initialization_mode()
            },
        )
    }
}

pub unsafe fn exit_initialization_mode<M: FmuModel>(c: fmi3Instance) -> fmi3Status {
    unsafe {
        call::<M>(
            c,
            "fmi3ExitInitializationMode",
            mask::EXIT_INITIALIZATION_MODE,
            |inst| inst.inner.exit_initialization_mode(),
        )
    }
}

pub unsafe fn terminate<M: FmuModel>(c: fmi3Instance) -> fmi3Status {
    unsafe { call::<M>(c, "fmi3Terminate", mask::TERMINATE, |inst| inst.inner.terminate()) }
}

pub unsafe fn reset<M: FmuModel>(c: fmi3Instance) -> fmi3Status {
    unsafe {
        call::<M>(c, "fmi3Reset", mask::ANY, |inst| {
            inst.inner.reset();
            Ok(())
        })
    }
}

// ---------------------------------------------------------------- values

/// fmi3GetFloat64: the declared Float64 variables, and `time` (the independent variable).
pub unsafe fn get_float64<M: FmuModel>(
    c: fmi3Instance,
    vr: *const fmi3ValueReference,
    nvr: usize,
    values: *mut fmi3Float64,
    n_values: usize,
) -> fmi3Status {
    unsafe {
        call::<M>(c, "fmi3GetFloat64", mask::GET, |inst| {
            let vrs = value_refs(vr, nvr, n_values)?;
            let out = slice_mut(values, nvr, "values")?;
            for (&r, slot) in vrs.iter().zip(out.iter_mut()) {
                if r == inst.time_vr {
                    *slot = inst.inner.machine.time;
                } else {
                    inst.inner
                        .get_values(&[r], std::slice::from_mut(slot), ValueType::Real, |v, r| v.get_real(r))?;
                }
            }
            Ok(())
        })
    }
}

/// `Err` if `vrs` names the independent variable (it cannot be set).
fn refuse_time(vrs: &[u32], time_vr: u32) -> Result3 {
    if vrs.contains(&time_vr) {
        return err(format!(
            "time (value reference {time_vr}) is the independent variable: it cannot be set"
        ));
    }
    Ok(())
}

pub unsafe fn set_float64<M: FmuModel>(
    c: fmi3Instance,
    vr: *const fmi3ValueReference,
    nvr: usize,
    values: *const fmi3Float64,
    n_values: usize,
) -> fmi3Status {
    unsafe {
        call::<M>(c, "fmi3SetFloat64", mask::SET, |inst| {
            let vrs = value_refs(vr, nvr, n_values)?;
            refuse_time(vrs, inst.time_vr)?;
            let xs = slice(values, nvr, "values")?;
            inst.inner
                .set_values(vrs, xs, ValueType::Real, |x| Some(*x), |v, r, x| v.set_real(r, x))
        })
    }
}

pub unsafe fn get_int32<M: FmuModel>(
    c: fmi3Instance,
    vr: *const fmi3ValueReference,
    nvr: usize,
    values: *mut fmi3Int32,
    n_values: usize,
) -> fmi3Status {
    unsafe {
        call::<M>(c, "fmi3GetInt32", mask::GET, |inst| {
            let vrs = value_refs(vr, nvr, n_values)?;
            let out = slice_mut(values, nvr, "values")?;
            inst.inner
                .get_values(vrs, out, ValueType::Integer, |v, r| v.get_integer(r))
        })
    }
}

pub unsafe fn set_int32<M: FmuModel>(
    c: fmi3Instance,
    vr: *const fmi3ValueReference,
    nvr: usize,
    values: *const fmi3Int32,
    n_values: usize,
) -> fmi3Status {
    unsafe {
        call::<M>(c, "fmi3SetInt32", mask::SET, |inst| {
            let vrs = value_refs(vr, nvr, n_values)?;
            refuse_time(vrs, inst.time_vr)?;
            let xs = slice(values, nvr, "values")?;
            inst.inner.set_values(
                vrs,
                xs,
                ValueType::Integer,
                |x| Some(f64::from(*x)),
                |v, r, x| v.set_integer(r, x),
            )
        })
    }
}

pub unsafe fn get_boolean<M: FmuModel>(
    c: fmi3Instance,
    vr: *const fmi3ValueReference,
    nvr: usize,
    values: *mut fmi3Boolean,
    n_values: usize,
) -> fmi3Status {
    unsafe {
        call::<M>(c, "fmi3GetBoolean", mask::GET, |inst| {
            let vrs = value_refs(vr, nvr, n_values)?;
            let out = slice_mut(values, nvr, "values")?;
            inst.inner
                .get_values(vrs, out, ValueType::Boolean, |v, r| v.get_boolean(r))
        })
    }
}

pub unsafe fn set_boolean<M: FmuModel>(
    c: fmi3Instance,
    vr: *const fmi3ValueReference,
    nvr: usize,
    values: *const fmi3Boolean,
    n_values: usize,
) -> fmi3Status {
    unsafe {
        call::<M>(c, "fmi3SetBoolean", mask::SET, |inst| {
            let vrs = value_refs(vr, nvr, n_values)?;
            refuse_time(vrs, inst.time_vr)?;
            // Read as bytes: a host's byte other than 0/1 must not become an invalid `bool`.
            let xs = slice(values.cast::<u8>(), nvr, "values")?;
            inst.inner.set_values(
                vrs,
                xs,
                ValueType::Boolean,
                |_| None,
                |v, r, x| v.set_boolean(r, x != 0),
            )
        })
    }
}

/// fmi3GetString: the pointers stay valid until the next fmi3GetString on the instance.
pub unsafe fn get_string<M: FmuModel>(
    c: fmi3Instance,
    vr: *const fmi3ValueReference,
    nvr: usize,
    values: *mut fmi3String,
    n_values: usize,
) -> fmi3Status {
    unsafe {
        call::<M>(c, "fmi3GetString", mask::GET, |inst| {
            let vrs = value_refs(vr, nvr, n_values)?;
            let out = slice_mut(values, nvr, "values")?;
            inst.inner.get_strings(vrs, out)
        })
    }
}

pub unsafe fn set_string<M: FmuModel>(
    c: fmi3Instance,
    vr: *const fmi3ValueReference,
    nvr: usize,
    values: *const fmi3String,
    n_values: usize,
) -> fmi3Status {
    unsafe {
        call::<M>(c, "fmi3SetString", mask::SET, |inst| {
            let vrs = value_refs(vr, nvr, n_values)?;
            refuse_time(vrs, inst.time_vr)?;
            let ptrs = slice(values, nvr, "values")?;
            // Grown while reading, never sized from the host's count alone.
            let mut strs = Vec::new();
            for (r, &p) in vrs.iter().zip(ptrs) {
                let s = c_str(p)
                    .and_then(|s| s.to_str().ok())
                    .ok_or_else(|| Fmi2Error::error(format!("value for value reference {r} is NULL or not UTF-8")))?;
                strs.push(s);
            }
            inst.inner.set_strings(vrs, &strs)
        })
    }
}

/// Get/set of a type the FMU declares no variable of (Float32, Int8 … UInt64, Binary,
/// Clock): legal with no value references, an error naming the first one otherwise.
pub unsafe fn no_variables<M: FmuModel>(
    c: fmi3Instance,
    function: &str,
    allowed: StateMask,
    type_name: &str,
    vr: *const fmi3ValueReference,
    nvr: usize,
) -> fmi3Status {
    unsafe {
        call::<M>(c, function, allowed, |_| {
            let vrs = slice(vr, nvr, "valueReferences")?;
            match vrs.first() {
                None => Ok(()),
                Some(r) => err(format!(
                    "value reference {r} is not a {type_name} variable (the FMU has none)"
                )),
            }
        })
    }
}

// ---------------------------------------------------------------- FMU state

unsafe fn state<'a, M: FmuModel>(p: fmi3FMUState) -> Result3<&'a mut State3<M>> {
    if p.is_null() {
        return err("FMUState is NULL");
    }
    // SAFETY: per the contract `p` is an FMU state of this FMU (repr(C), tag first).
    if !p.cast::<u64>().is_aligned() || unsafe { p.cast::<u64>().read() } != State3::<M>::tag() {
        return err("FMUState is not a (live) FMU state of this model");
    }
    // SAFETY: the tag identifies a State3<M> allocated by Box.
    Ok(unsafe { &mut *p.cast::<State3<M>>() })
}

pub unsafe fn get_fmu_state<M: FmuModel>(c: fmi3Instance, fmu_state: *mut fmi3FMUState) -> fmi3Status {
    unsafe {
        call::<M>(c, "fmi3GetFMUState", mask::ANY, |inst| {
            let slot = out_ptr(fmu_state, "FMUState")?;
            if slot.is_null() {
                *slot = Box::into_raw(Box::new(State3::new(inst.inner.snapshot()))).cast();
            } else {
                inst.inner.snapshot_into(&mut state::<M>(*slot)?.snapshot);
            }
            Ok(())
        })
    }
}

pub unsafe fn set_fmu_state<M: FmuModel>(c: fmi3Instance, fmu_state: fmi3FMUState) -> fmi3Status {
    unsafe {
        call::<M>(c, "fmi3SetFMUState", mask::ANY, |inst| {
            let snap = &state::<M>(fmu_state)?.snapshot;
            if snap.machine.model_exchange != inst.inner.machine.model_exchange {
                return err(
                    "the FMU state belongs to an instance of the other interface (Model Exchange vs Co-Simulation)",
                );
            }
            inst.inner.restore(snap)
        })
    }
}

pub unsafe fn free_fmu_state<M: FmuModel>(c: fmi3Instance, fmu_state: *mut fmi3FMUState) -> fmi3Status {
    unsafe {
        call::<M>(c, "fmi3FreeFMUState", mask::ANY, |_| {
            if fmu_state.is_null() || (*fmu_state).is_null() {
                return Ok(());
            }
            let s = state::<M>(*fmu_state)?;
            s.tag = 0;
            drop(Box::from_raw(std::ptr::from_mut(s)));
            *fmu_state = std::ptr::null_mut();
            Ok(())
        })
    }
}

pub unsafe fn serialized_fmu_state_size<M: FmuModel>(
    c: fmi3Instance,
    fmu_state: fmi3FMUState,
    size: *mut usize,
) -> fmi3Status {
    unsafe {
        call::<M>(c, "fmi3SerializedFMUStateSize", mask::ANY, |_| {
            let out = out_ptr(size, "size")?;
            *out = state::<M>(fmu_state)?.snapshot.serialize().len();
            Ok(())
        })
    }
}

pub unsafe fn serialize_fmu_state<M: FmuModel>(
    c: fmi3Instance,
    fmu_state: fmi3FMUState,
    serialized: *mut fmi3Byte,
    size: usize,
) -> fmi3Status {
    unsafe {
        call::<M>(c, "fmi3SerializeFMUState", mask::ANY, |_| {
            let bytes = state::<M>(fmu_state)?.snapshot.serialize();
            if size < bytes.len() {
                return err(format!("buffer of {size} bytes too small for {} bytes", bytes.len()));
            }
            slice_mut(serialized, bytes.len(), "serializedState")?.copy_from_slice(&bytes);
            Ok(())
        })
    }
}

pub unsafe fn deserialize_fmu_state<M: FmuModel>(
    c: fmi3Instance,
    serialized: *const fmi3Byte,
    size: usize,
    fmu_state: *mut fmi3FMUState,
) -> fmi3Status {
    unsafe {
        call::<M>(c, "fmi3DeserializeFMUState", mask::ANY, |_| {
            let slot = out_ptr(fmu_state, "FMUState")?;
            let bytes = slice(serialized, size, "serializedState")?;
            let snap = fmi2_export::Snapshot::<M>::deserialize(bytes)?;
            *slot = Box::into_raw(Box::new(State3::new(snap))).cast();
            Ok(())
        })
    }
}

// ---------------------------------------------------------------- Co-Simulation

/// fmi3DoStep: the step of the core; never requests event handling or termination,
/// never returns early; `lastSuccessfulTime` is the instance time after the call
/// (`t + h`, or `t` when the step failed).
#[allow(clippy::too_many_arguments)]
pub unsafe fn do_step<M: FmuModel>(
    c: fmi3Instance,
    current_communication_point: fmi3Float64,
    communication_step_size: fmi3Float64,
    _no_set_fmu_state_prior_to_current_point: bool,
    event_handling_needed: *mut fmi3Boolean,
    terminate_simulation: *mut fmi3Boolean,
    early_return: *mut fmi3Boolean,
    last_successful_time: *mut fmi3Float64,
) -> fmi3Status {
    unsafe {
        call::<M>(c, "fmi3DoStep", mask::DO_STEP, |inst| {
            let event = out_ptr(event_handling_needed, "eventHandlingNeeded")?;
            let terminate = out_ptr(terminate_simulation, "terminateSimulation")?;
            let early = out_ptr(early_return, "earlyReturn")?;
            let last = out_ptr(last_successful_time, "lastSuccessfulTime")?;
            let result = inst.inner.do_step(current_communication_point, communication_step_size);
            *event = false;
            *terminate = false;
            *early = false;
            *last = inst.inner.machine.time;
            result
        })
    }
}

// ---------------------------------------------------------------- Model Exchange

pub unsafe fn enter_event_mode<M: FmuModel>(c: fmi3Instance) -> fmi3Status {
    unsafe {
        call::<M>(c, "fmi3EnterEventMode", mask::ENTER_EVENT_MODE, |inst| {
            inst.inner.machine.state = FmiState::EventMode;
            Ok(())
        })
    }
}

/// No discrete states, no time events: one iteration, every flag false.
#[allow(clippy::too_many_arguments)]
pub unsafe fn update_discrete_states<M: FmuModel>(
    c: fmi3Instance,
    discrete_states_need_update: *mut fmi3Boolean,
    terminate_simulation: *mut fmi3Boolean,
    nominals_changed: *mut fmi3Boolean,
    values_changed: *mut fmi3Boolean,
    next_event_time_defined: *mut fmi3Boolean,
    next_event_time: *mut fmi3Float64,
) -> fmi3Status {
    unsafe {
        call::<M>(c, "fmi3UpdateDiscreteStates", mask::UPDATE_DISCRETE_STATES, |_| {
            let flags = [
                (discrete_states_need_update, "discreteStatesNeedUpdate"),
                (terminate_simulation, "terminateSimulation"),
                (nominals_changed, "nominalsOfContinuousStatesChanged"),
                (values_changed, "valuesOfContinuousStatesChanged"),
                (next_event_time_defined, "nextEventTimeDefined"),
            ];
            for (p, what) in flags {
                out_ptr(p, what)?;
            }
            let time = out_ptr(next_event_time, "nextEventTime")?;
            for (p, _) in flags {
                *p = false;
            }
            *time = 0.0;
            Ok(())
        })
    }
}

pub unsafe fn enter_continuous_time_mode<M: FmuModel>(c: fmi3Instance) -> fmi3Status {
    unsafe {
        call::<M>(
            c,
            "fmi3EnterContinuousTimeMode",
            mask::ENTER_CONTINUOUS_TIME_MODE,
            |inst| {
                inst.inner.machine.state = FmiState::ContinuousTimeMode;
                Ok(())
            },
        )
    }
}

/// No step events: never asks for event mode or termination.
pub unsafe fn completed_integrator_step<M: FmuModel>(
    c: fmi3Instance,
    _no_set_fmu_state_prior_to_current_point: bool,
    enter_event_mode: *mut fmi3Boolean,
    terminate_simulation: *mut fmi3Boolean,
) -> fmi3Status {
    unsafe {
        call::<M>(
            c,
            "fmi3CompletedIntegratorStep",
            mask::COMPLETED_INTEGRATOR_STEP,
            |_| {
                let enter = out_ptr(enter_event_mode, "enterEventMode")?;
                let terminate = out_ptr(terminate_simulation, "terminateSimulation")?;
                *enter = false;
                *terminate = false;
                Ok(())
            },
        )
    }
}

pub unsafe fn set_time<M: FmuModel>(c: fmi3Instance, time: fmi3Float64) -> fmi3Status {
    unsafe { call::<M>(c, "fmi3SetTime", mask::SET_TIME, |inst| inst.inner.set_time(time)) }
}

pub unsafe fn set_continuous_states<M: FmuModel>(c: fmi3Instance, x: *const fmi3Float64, nx: usize) -> fmi3Status {
    unsafe {
        call::<M>(c, "fmi3SetContinuousStates", mask::SET_CONTINUOUS_STATES, |inst| {
            inst.inner.set_continuous_states(slice(x, nx, "continuousStates")?)
        })
    }
}

pub unsafe fn get_continuous_state_derivatives<M: FmuModel>(
    c: fmi3Instance,
    dx: *mut fmi3Float64,
    nx: usize,
) -> fmi3Status {
    unsafe {
        call::<M>(c, "fmi3GetContinuousStateDerivatives", mask::GET_CONTINUOUS, |inst| {
            inst.inner.get_derivatives(slice_mut(dx, nx, "derivatives")?)
        })
    }
}

pub unsafe fn get_continuous_states<M: FmuModel>(c: fmi3Instance, x: *mut fmi3Float64, nx: usize) -> fmi3Status {
    unsafe {
        call::<M>(c, "fmi3GetContinuousStates", mask::GET_CONTINUOUS, |inst| {
            inst.inner.get_continuous_states(slice_mut(x, nx, "continuousStates")?)
        })
    }
}

pub unsafe fn get_nominals_of_continuous_states<M: FmuModel>(
    c: fmi3Instance,
    nominals: *mut fmi3Float64,
    nx: usize,
) -> fmi3Status {
    unsafe {
        call::<M>(c, "fmi3GetNominalsOfContinuousStates", mask::GET_NOMINALS, |inst| {
            inst.inner.get_nominals(slice_mut(nominals, nx, "nominals")?)
        })
    }
}

/// The model has no event indicators (as its FMI 2.0 Model Exchange): only `ni == 0`.
pub unsafe fn get_event_indicators<M: FmuModel>(c: fmi3Instance, z: *mut fmi3Float64, ni: usize) -> fmi3Status {
    unsafe {
        call::<M>(c, "fmi3GetEventIndicators", mask::GET_CONTINUOUS, |_| {
            slice_mut(z, ni, "eventIndicators")?;
            if ni != 0 {
                return err(format!("nEventIndicators = {ni}, but the model has none"));
            }
            Ok(())
        })
    }
}

pub unsafe fn get_number_of_event_indicators<M: FmuModel>(c: fmi3Instance, n: *mut usize) -> fmi3Status {
    unsafe {
        call::<M>(c, "fmi3GetNumberOfEventIndicators", mask::ANY, |_| {
            *out_ptr(n, "nEventIndicators")? = 0;
            Ok(())
        })
    }
}

pub unsafe fn get_number_of_continuous_states<M: FmuModel>(c: fmi3Instance, n: *mut usize) -> fmi3Status {
    unsafe {
        call::<M>(c, "fmi3GetNumberOfContinuousStates", mask::ANY, |_| {
            *out_ptr(n, "nContinuousStates")? = M::Vars::CONTINUOUS_STATES.len();
            Ok(())
        })
    }
}

// ---------------------------------------------------------------- not supported

/// Log "`function`: not supported (`why`)" and return fmi3Error.
pub unsafe fn not_supported<M: FmuModel>(c: fmi3Instance, function: &str, why: &str) -> fmi3Status {
    unsafe { call::<M>(c, function, mask::ANY, |_| err(format!("not supported ({why})"))) }
}
