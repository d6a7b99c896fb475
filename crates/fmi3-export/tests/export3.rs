//! The toy model of the FMI 2.0 layer's tests exported with `export_fmu3!` and driven
//! through the real `extern "C"` FMI 3.0 functions, as a host would: the state table,
//! error statuses with their log messages, panic safety, FMU state.

#[path = "../../fmi2-export/tests/common/mod.rs"]
#[allow(unused_imports)]
mod common;

use common::{cstring, vr, Toy, TOY_GUID};
use fmi3_abi::*;
use fmi3_export::fmi_sys::fmi3::*;
use std::ffi::{c_void, CStr};
use std::ptr::{null, null_mut};
use std::sync::Mutex;

fmi3_export::export_fmu3!(Toy);

const OK: fmi3Status = fmi3Status_fmi3OK;
const ERROR: fmi3Status = fmi3Status_fmi3Error;
/// `time`: one above the toy's largest value reference (9).
const TIME: u32 = 10;

/// The messages an instance sent to its host: (status, category, message).
#[derive(Default)]
struct Log(Mutex<Vec<(fmi3Status, String, String)>>);

impl Log {
    fn messages(&self) -> Vec<(fmi3Status, String, String)> {
        self.0.lock().unwrap().clone()
    }
    /// The last message, which must have status Error.
    fn last_error(&self) -> String {
        let m = self.messages();
        let (status, category, text) = m.last().expect("a message was logged").clone();
        assert_eq!((status, category.as_str()), (ERROR, "logStatusError"), "{text}");
        text
    }
}

unsafe extern "C" fn record(
    env: fmi3InstanceEnvironment,
    status: fmi3Status,
    category: fmi3String,
    message: fmi3String,
) {
    let log = unsafe { &*env.cast::<Log>() };
    let text = |p: fmi3String| unsafe { CStr::from_ptr(p) }.to_string_lossy().into_owned();
    log.0.lock().unwrap().push((status, text(category), text(message)));
}

fn env(log: &Log) -> fmi3InstanceEnvironment {
    std::ptr::from_ref(log).cast_mut().cast::<c_void>()
}

fn instantiate_cs(log: &Log, name: &str, token: &str, event_mode_used: bool) -> fmi3Instance {
    instantiate_with(name, token, event_mode_used, env(log), Some(record))
}

fn instantiate_with(
    name: &str,
    token: &str,
    event_mode_used: bool,
    env: fmi3InstanceEnvironment,
    logger: fmi3LogMessageCallback,
) -> fmi3Instance {
    let (name, token) = (cstring(name), cstring(token));
    unsafe {
        fmi3InstantiateCoSimulation(
            name.as_ptr(),
            token.as_ptr(),
            null(),
            false,
            logger.is_none(),
            event_mode_used,
            false,
            null(),
            0,
            env,
            logger,
            None,
        )
    }
}

/// StepMode at t = 0, stop time 10.
fn ready(log: &Log) -> fmi3Instance {
    let c = instantiate_cs(log, "toy3", TOY_GUID, false);
    assert!(!c.is_null(), "{:?}", log.messages());
    unsafe {
        assert_eq!(fmi3EnterInitializationMode(c, false, 0.0, 0.0, true, 10.0), OK);
        assert_eq!(fmi3ExitInitializationMode(c), OK);
    }
    c
}

fn get(c: fmi3Instance, r: u32) -> f64 {
    let mut x = f64::NAN;
    assert_eq!(unsafe { fmi3GetFloat64(c, &r, 1, &mut x, 1) }, OK);
    x
}

fn set(c: fmi3Instance, r: u32, x: f64) -> fmi3Status {
    unsafe { fmi3SetFloat64(c, &r, 1, &x, 1) }
}

/// fmi3DoStep with its out-arguments: (status, lastSuccessfulTime).
fn step(c: fmi3Instance, t: f64, h: f64) -> (fmi3Status, f64) {
    let (mut event, mut terminate, mut early, mut last) = (true, true, true, f64::NAN);
    let status = unsafe { fmi3DoStep(c, t, h, true, &mut event, &mut terminate, &mut early, &mut last) };
    if status == OK {
        assert!(
            !event && !terminate && !early,
            "no events, no termination, no early return"
        );
    }
    (status, last)
}

#[test]
fn version_and_full_lifecycle() {
    assert_eq!(unsafe { CStr::from_ptr(fmi3GetVersion()) }.to_str(), Ok("3.0"));
    let log = Log::default();
    let c = ready(&log);
    // y = gain x0 at the start; the first-order lag then follows u exactly.
    assert_eq!(get(c, vr::Y), 2.0 * 0.5);
    assert_eq!(set(c, vr::U, 1.0), OK);
    let (status, last) = step(c, 0.0, 0.5);
    assert_eq!((status, last), (OK, 0.5));
    let x = 0.5 + (1.0 - (-0.5f64).exp()) * (1.0 - 0.5);
    assert!((get(c, vr::Y) - 2.0 * x).abs() < 1e-15);
    assert_eq!(get(c, TIME), 0.5);
    let mut steps = 0;
    assert_eq!(unsafe { fmi3GetInt32(c, &vr::STEPS, 1, &mut steps, 1) }, OK);
    assert_eq!(steps, 1);
    let mut enabled = false;
    assert_eq!(unsafe { fmi3GetBoolean(c, &vr::ENABLED, 1, &mut enabled, 1) }, OK);
    assert!(enabled);
    let mut label = null();
    assert_eq!(unsafe { fmi3GetString(c, &vr::LABEL, 1, &mut label, 1) }, OK);
    assert_eq!(unsafe { CStr::from_ptr(label) }.to_str(), Ok("toy"));
    unsafe {
        assert_eq!(fmi3Terminate(c), OK);
        fmi3FreeInstance(c);
    }
}

#[test]
fn illegal_calls_name_the_fmi3_state() {
    let log = Log::default();
    let c = instantiate_cs(&log, "toy3", TOY_GUID, false);
    let mut x = 0.0;
    unsafe {
        assert_eq!(fmi3GetFloat64(c, &vr::Y, 1, &mut x, 1), ERROR);
        assert_eq!(log.last_error(), "fmi3GetFloat64: illegal call in state Instantiated");
        assert_eq!(step(c, 0.0, 0.1).0, ERROR);
        assert_eq!(log.last_error(), "fmi3DoStep: illegal call in state Instantiated");
        assert_eq!(fmi3EnterInitializationMode(c, false, 0.0, 0.0, false, 0.0), OK);
        assert_eq!(fmi3EnterInitializationMode(c, false, 0.0, 0.0, false, 0.0), ERROR);
        assert_eq!(
            log.last_error(),
            "fmi3EnterInitializationMode: illegal call in state InitializationMode"
        );
        assert_eq!(fmi3ExitInitializationMode(c), OK);
        // Co-Simulation without event mode: no Model Exchange call is legal.
        assert_eq!(fmi3EnterContinuousTimeMode(c), ERROR);
        assert_eq!(
            log.last_error(),
            "fmi3EnterContinuousTimeMode: illegal call in state StepMode"
        );
        assert_eq!(fmi3EnterEventMode(c), ERROR);
        assert_eq!(fmi3EnterStepMode(c), ERROR);
        assert_eq!(fmi3Terminate(c), OK);
        assert_eq!(step(c, 0.0, 0.1).0, ERROR);
        assert_eq!(log.last_error(), "fmi3DoStep: illegal call in state Terminated");
        assert_eq!(set(c, vr::U, 1.0), ERROR);
        // Reset: back to Instantiated with the start values.
        assert_eq!(fmi3Reset(c), OK);
        assert_eq!(fmi3ExitInitializationMode(c), ERROR);
        assert_eq!(
            log.last_error(),
            "fmi3ExitInitializationMode: illegal call in state Instantiated"
        );
        fmi3FreeInstance(c);
        // No instance at all.
        assert_eq!(fmi3Terminate(null_mut()), ERROR);
    }
}

#[test]
fn bad_values_and_references_are_errors_naming_the_variable() {
    let log = Log::default();
    let c = ready(&log);
    assert_eq!(set(c, vr::U, f64::NAN), ERROR);
    assert_eq!(
        log.last_error(),
        "fmi3SetFloat64: variable u (value reference 0): value NaN is not finite"
    );
    assert_eq!(set(c, vr::U, 11.0), ERROR);
    assert!(log.last_error().contains("outside [-10, 10]"));
    assert_eq!(set(c, 4711, 1.0), ERROR);
    assert_eq!(log.last_error(), "fmi3SetFloat64: unknown value reference 4711");
    assert_eq!(set(c, TIME, 1.0), ERROR);
    assert!(log.last_error().contains("is the independent variable"));
    // A fixed parameter after initialisation, an Int32 read as Float64.
    assert_eq!(set(c, vr::TAU, 2.0), ERROR);
    assert!(log.last_error().contains("tau"));
    let mut x = 0.0;
    assert_eq!(unsafe { fmi3GetFloat64(c, &vr::STEPS, 1, &mut x, 1) }, ERROR);
    assert!(log.last_error().contains("is of type Integer"));
    // Scalars only: nValues must equal nValueReferences.
    let vrs = [vr::U, vr::Y];
    let mut xs = [0.0; 2];
    assert_eq!(unsafe { fmi3GetFloat64(c, vrs.as_ptr(), 2, xs.as_mut_ptr(), 3) }, ERROR);
    assert!(log.last_error().contains("nValues = 3"));
    // NULL arrays.
    assert_eq!(unsafe { fmi3GetFloat64(c, null(), 2, xs.as_mut_ptr(), 2) }, ERROR);
    assert_eq!(log.last_error(), "fmi3GetFloat64: valueReferences is NULL (n = 2)");
    // A type the FMU has no variable of.
    let mut f = 0.0f32;
    assert_eq!(unsafe { fmi3GetFloat32(c, &vr::U, 1, &mut f, 1) }, ERROR);
    assert_eq!(
        log.last_error(),
        "fmi3GetFloat32: value reference 0 is not a Float32 variable (the FMU has none)"
    );
    assert_eq!(unsafe { fmi3GetFloat32(c, null(), 0, null_mut(), 0) }, OK);
    // Nothing changed: the lag still starts from x0.
    assert_eq!(get(c, vr::Y), 1.0);
    // DoStep arguments.
    assert_eq!(step(c, 0.3, 0.1).0, ERROR);
    assert!(log.last_error().contains("does not match the FMU time 0 s"));
    assert_eq!(step(c, 0.0, f64::NAN).0, ERROR);
    assert_eq!(step(c, 0.0, 11.0).0, ERROR);
    assert!(log.last_error().contains("after the stop time"));
    let mut b = false;
    let status = unsafe { fmi3DoStep(c, 0.0, 0.1, true, null_mut(), &mut b, &mut b, &mut 0.0) };
    assert_eq!(status, ERROR);
    assert_eq!(log.last_error(), "fmi3DoStep: eventHandlingNeeded is NULL");
    assert_eq!(get(c, TIME), 0.0);
    unsafe { fmi3FreeInstance(c) };
}

#[test]
fn instantiation_is_refused_with_a_message() {
    let log = Log::default();
    assert!(instantiate_cs(&log, "toy3", "{wrong}", false).is_null());
    assert!(log
        .last_error()
        .starts_with("fmi3InstantiateCoSimulation: instantiationToken mismatch"));
    assert!(instantiate_cs(&log, "", TOY_GUID, false).is_null());
    assert!(log.last_error().contains("instanceName is NULL or empty"));
    assert!(instantiate_cs(&log, "toy3", TOY_GUID, true).is_null());
    assert!(log.last_error().contains("hasEventMode"));
    let (name, token) = (cstring("toy3"), cstring(TOY_GUID));
    let me = unsafe {
        fmi3InstantiateModelExchange(
            name.as_ptr(),
            token.as_ptr(),
            null(),
            false,
            false,
            env(&log),
            Some(record),
        )
    };
    assert!(me.is_null());
    assert!(log.last_error().contains("no continuous states: Co-Simulation only"));
    let se = unsafe {
        fmi3InstantiateScheduledExecution(
            name.as_ptr(),
            token.as_ptr(),
            null(),
            false,
            false,
            env(&log),
            Some(record),
            None,
            None,
            None,
        )
    };
    assert!(se.is_null());
    // A host without a logger is legal in FMI 3.0.
    let quiet = instantiate_with("toy3", TOY_GUID, false, null_mut(), None);
    assert!(!quiet.is_null());
    unsafe {
        assert_eq!(fmi3ExitInitializationMode(quiet), ERROR);
        fmi3FreeInstance(quiet);
    }
}

#[test]
fn failed_step_and_panic_are_errors_not_aborts() {
    let log = Log::default();
    let c = ready(&log);
    assert_eq!(set(c, vr::U, 9.75), OK);
    assert_eq!(step(c, 0.0, 0.1), (ERROR, 0.0));
    assert!(log.last_error().contains("input u = 9.75 too large"));
    assert_eq!(step(c, 0.0, 0.1).0, ERROR);
    assert_eq!(
        log.last_error(),
        "fmi3DoStep: illegal call in state StepMode (after a failed step)"
    );
    // Values stay readable; Terminate is legal.
    assert_eq!(get(c, TIME), 0.0);
    unsafe { assert_eq!(fmi3Terminate(c), OK) };
    unsafe { fmi3FreeInstance(c) };

    let c = ready(&log);
    assert_eq!(set(c, vr::U, -9.75), OK);
    assert_eq!(step(c, 0.0, 0.1).0, ERROR);
    assert!(log
        .last_error()
        .starts_with("fmi3DoStep: internal error (panic): toy model panics"));
    unsafe { fmi3FreeInstance(c) };
}

#[test]
fn fmu_state_and_serialization_continue_bit_identically() {
    let log = Log::default();
    let c = ready(&log);
    let run = |from: usize, n: usize| -> Vec<u64> {
        (from..from + n)
            .map(|k| {
                assert_eq!(set(c, vr::U, (k as f64 * 0.7).sin()), OK);
                assert_eq!(step(c, k as f64 * 0.1, 0.1).0, OK);
                get(c, vr::Y).to_bits()
            })
            .collect()
    };
    run(0, 5);
    let mut state: fmi3FMUState = null_mut();
    let mut size = 0;
    unsafe {
        assert_eq!(fmi3GetFMUState(c, &mut state), OK);
        assert_eq!(fmi3SerializedFMUStateSize(c, state, &mut size), OK);
    }
    let mut bytes = vec![0u8; size];
    unsafe {
        assert_eq!(fmi3SerializeFMUState(c, state, bytes.as_mut_ptr(), size), OK);
        assert_eq!(fmi3SerializeFMUState(c, state, bytes.as_mut_ptr(), size - 1), ERROR);
    }
    let first = run(5, 5);
    unsafe { assert_eq!(fmi3SetFMUState(c, state), OK) };
    assert_eq!(run(5, 5), first);
    let mut restored: fmi3FMUState = null_mut();
    unsafe {
        assert_eq!(fmi3DeserializeFMUState(c, bytes.as_ptr(), size, &mut restored), OK);
        assert_eq!(fmi3SetFMUState(c, restored), OK);
    }
    assert_eq!(run(5, 5), first);
    // A corrupted buffer is refused; the instance keeps its state.
    bytes[size / 2] ^= 0x40;
    let mut bad: fmi3FMUState = null_mut();
    unsafe {
        assert_eq!(fmi3DeserializeFMUState(c, bytes.as_ptr(), size, &mut bad), ERROR);
        assert!(bad.is_null());
        assert_eq!(fmi3FreeFMUState(c, &mut state), OK);
        assert_eq!(fmi3FreeFMUState(c, &mut restored), OK);
        assert!(state.is_null() && restored.is_null());
        fmi3FreeInstance(c);
    }
}

#[test]
fn unsupported_capabilities_log_why() {
    let log = Log::default();
    let c = ready(&log);
    let mut n = 99;
    unsafe {
        assert_eq!(fmi3GetNumberOfContinuousStates(c, &mut n), OK);
        assert_eq!(n, 0);
        assert_eq!(fmi3GetNumberOfEventIndicators(c, &mut n), OK);
        assert_eq!(n, 0);
        assert_eq!(fmi3EnterConfigurationMode(c), ERROR);
        assert_eq!(
            log.last_error(),
            "fmi3EnterConfigurationMode: not supported (no structural parameters)"
        );
        let (mut seed, mut out) = (1.0, 0.0);
        let status = fmi3GetDirectionalDerivative(c, &vr::Y, 1, &vr::U, 1, &seed, 1, &mut out, 1);
        assert_eq!(status, ERROR);
        assert!(log.last_error().contains("providesDirectionalDerivatives"));
        seed += 1.0;
        assert_eq!(seed, 2.0);
        let mut b = false;
        assert_eq!(fmi3GetClock(c, &vr::U, 1, &mut b), ERROR);
        fmi3FreeInstance(c);
    }
}

#[test]
fn debug_logging_filters_categories() {
    let log = Log::default();
    let c = ready(&log);
    let warn = cstring("logStatusWarning");
    let bogus = cstring("logNothing");
    unsafe {
        assert_eq!(fmi3SetDebugLogging(c, true, 1, &warn.as_ptr()), OK);
        assert_eq!(fmi3SetDebugLogging(c, true, 1, &bogus.as_ptr()), ERROR);
        assert_eq!(
            log.last_error(),
            "fmi3SetDebugLogging: unknown log category \"logNothing\""
        );
    }
    // The model's warning (u > 9) reaches the host with status Warning.
    assert_eq!(set(c, vr::U, 9.25), OK);
    assert_eq!(step(c, 0.0, 0.1).0, OK);
    let (status, category, text) = log.messages().last().unwrap().clone();
    assert_eq!(
        (status, category.as_str(), text.as_str()),
        (fmi3Status_fmi3Warning, "logStatusWarning", "input u close to its limit")
    );
    unsafe { fmi3FreeInstance(c) };
}
