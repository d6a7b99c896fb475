//! The toy model exported with `export_fmu!` and driven through the real
//! `extern "C"` functions, as a host would.

mod common;

use common::{cstring, vr, Host, Other, Toy, TOY_GUID};
use fmi2_export::fmi_sys::fmi2::*;
use std::ffi::{c_char, CStr};
use std::ptr::{null, null_mut};

fmi2_export::export_fmu!(Toy);

const OK: fmi2Status = fmi2Status_fmi2OK;
const ERROR: fmi2Status = fmi2Status_fmi2Error;
const DISCARD: fmi2Status = fmi2Status_fmi2Discard;

fn instantiate(host: &Host, name: &str) -> fmi2Component {
    let name = cstring(name);
    let guid = cstring(TOY_GUID);
    let c = unsafe {
        fmi2Instantiate(
            name.as_ptr(),
            fmi2Type_fmi2CoSimulation,
            guid.as_ptr(),
            null(),
            &*host.callbacks,
            0,
            0,
        )
    };
    assert!(!c.is_null(), "{:?}", host.messages());
    c
}

/// Instantiated → StepComplete at t = 0, stop time 10.
fn ready(host: &Host) -> fmi2Component {
    let c = instantiate(host, "toy1");
    unsafe {
        assert_eq!(fmi2SetupExperiment(c, 0, 0.0, 0.0, 1, 10.0), OK);
        assert_eq!(fmi2EnterInitializationMode(c), OK);
        assert_eq!(fmi2ExitInitializationMode(c), OK);
    }
    c
}

fn get_real(c: fmi2Component, r: u32) -> f64 {
    let mut v = f64::NAN;
    assert_eq!(unsafe { fmi2GetReal(c, &r, 1, &mut v) }, OK);
    v
}

fn set_real(c: fmi2Component, r: u32, v: f64) -> fmi2Status {
    unsafe { fmi2SetReal(c, &r, 1, &v) }
}

fn get_int(c: fmi2Component, r: u32) -> i32 {
    let mut v = -1;
    assert_eq!(unsafe { fmi2GetInteger(c, &r, 1, &mut v) }, OK);
    v
}

fn get_string(c: fmi2Component, r: u32) -> String {
    let mut p: fmi2String = null();
    assert_eq!(unsafe { fmi2GetString(c, &r, 1, &mut p) }, OK);
    unsafe { CStr::from_ptr(p) }.to_str().unwrap().to_string()
}

#[test]
fn platform_and_version() {
    unsafe {
        assert_eq!(CStr::from_ptr(fmi2GetTypesPlatform()).to_str().unwrap(), "default");
        assert_eq!(CStr::from_ptr(fmi2GetVersion()).to_str().unwrap(), "2.0");
    }
}

#[test]
fn full_legal_lifecycle() {
    let host = Host::new();
    let c = instantiate(&host, "toy1");
    unsafe {
        assert_eq!(fmi2SetupExperiment(c, 1, 1e-6, 0.0, 1, 10.0), OK);
        assert_eq!(set_real(c, vr::TAU, 0.5), OK);
        assert_eq!(set_real(c, vr::X0, 1.0), OK);
        let mode = [1];
        assert_eq!(fmi2SetInteger(c, &vr::MODE, 1, mode.as_ptr()), OK);
        assert_eq!(fmi2EnterInitializationMode(c), OK);
        // Lazy initialisation: outputs at the start time, before ExitInitializationMode.
        assert_eq!(get_real(c, vr::Y), 2.0);
        assert_eq!(get_real(c, vr::Y0), 2.0);
        assert_eq!(set_real(c, vr::GAIN, 3.0), OK);
        assert_eq!(get_real(c, vr::Y), 3.0);
        assert_eq!(fmi2ExitInitializationMode(c), OK);
        assert_eq!(set_real(c, vr::U, 4.0), OK);
        let h = 0.1;
        let mut x = 1.0f64;
        for k in 0..20 {
            assert_eq!(fmi2DoStep(c, k as f64 * h, h, 1), OK, "{:?}", host.messages());
            x += (1.0 - (-h / 0.5f64).exp()) * (4.0 - x);
            assert_eq!(get_real(c, vr::Y), 3.0 * x);
        }
        assert_eq!(get_int(c, vr::STEPS), 20);
        assert_eq!(get_int(c, vr::MODE), 1);
        let mut b = 0;
        assert_eq!(fmi2GetBoolean(c, &vr::ENABLED, 1, &mut b), OK);
        assert_eq!(b, 1);
        assert_eq!(get_string(c, vr::LABEL), "toy");
        let mut t = 0.0;
        assert_eq!(fmi2GetRealStatus(c, fmi2StatusKind_fmi2LastSuccessfulTime, &mut t), OK);
        assert!((t - 2.0).abs() < 1e-12);
        let mut st = 99;
        assert_eq!(fmi2GetStatus(c, fmi2StatusKind_fmi2DoStepStatus, &mut st), OK);
        assert_eq!(st, OK);
        assert_eq!(fmi2Terminate(c), OK);
        // Values stay readable after Terminate.
        assert_eq!(get_real(c, vr::Y), 3.0 * x);
        let mut term = 0;
        assert_eq!(fmi2GetBooleanStatus(c, fmi2StatusKind_fmi2Terminated, &mut term), OK);
        assert_eq!(term, 1);
        fmi2FreeInstance(c);
    }
    assert!(host.records().iter().all(|r| r.status != ERROR), "{:?}", host.records());
}

#[test]
fn lazy_update_after_input_set_in_step_complete() {
    let host = Host::new();
    let c = ready(&host);
    unsafe {
        assert_eq!(fmi2DoStep(c, 0.0, 0.1, 1), OK);
        assert!(get_real(c, vr::Y) != 0.0);
        let f = [0];
        assert_eq!(fmi2SetBoolean(c, &vr::ENABLED, 1, f.as_ptr()), OK);
        assert_eq!(get_real(c, vr::Y), 0.0, "update_outputs must run before the get");
        let t = [1];
        assert_eq!(fmi2SetBoolean(c, &vr::ENABLED, 1, t.as_ptr()), OK);
        assert!(get_real(c, vr::Y) != 0.0);
        fmi2FreeInstance(c);
    }
}

#[test]
fn illegal_calls_are_rejected_and_logged() {
    let host = Host::new();
    let c = instantiate(&host, "toy1");
    let mut v = 0.0;
    let mut st = 0;
    let check = |status: fmi2Status, function: &str, state: &str| {
        assert_eq!(status, ERROR, "{function} in {state}");
        let expected = format!("{function}: illegal call in state {state}");
        assert!(
            host.messages().contains(&expected),
            "missing {expected:?} in {:?}",
            host.messages()
        );
        let rec = host.records().into_iter().find(|r| r.message == expected).unwrap();
        assert_eq!(rec.status, ERROR);
        assert_eq!(rec.category, "logStatusError");
        assert_eq!(rec.instance, "toy1");
    };
    unsafe {
        // Instantiated
        check(fmi2DoStep(c, 0.0, 0.1, 1), "fmi2DoStep", "Instantiated");
        check(
            fmi2ExitInitializationMode(c),
            "fmi2ExitInitializationMode",
            "Instantiated",
        );
        check(fmi2Terminate(c), "fmi2Terminate", "Instantiated");
        check(fmi2GetReal(c, &vr::Y, 1, &mut v), "fmi2GetReal", "Instantiated");
        check(fmi2CancelStep(c), "fmi2CancelStep", "Instantiated");
        check(
            fmi2GetStatus(c, fmi2StatusKind_fmi2DoStepStatus, &mut st),
            "fmi2GetStatus",
            "Instantiated",
        );
        // InitializationMode
        assert_eq!(fmi2EnterInitializationMode(c), OK);
        check(
            fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0),
            "fmi2SetupExperiment",
            "InitializationMode",
        );
        check(
            fmi2EnterInitializationMode(c),
            "fmi2EnterInitializationMode",
            "InitializationMode",
        );
        check(fmi2DoStep(c, 0.0, 0.1, 1), "fmi2DoStep", "InitializationMode");
        check(fmi2Terminate(c), "fmi2Terminate", "InitializationMode");
        // StepComplete
        assert_eq!(fmi2ExitInitializationMode(c), OK);
        check(
            fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0),
            "fmi2SetupExperiment",
            "StepComplete",
        );
        check(
            fmi2EnterInitializationMode(c),
            "fmi2EnterInitializationMode",
            "StepComplete",
        );
        check(
            fmi2ExitInitializationMode(c),
            "fmi2ExitInitializationMode",
            "StepComplete",
        );
        check(fmi2CancelStep(c), "fmi2CancelStep", "StepComplete");
        // Terminated
        assert_eq!(fmi2Terminate(c), OK);
        check(set_real(c, vr::U, 1.0), "fmi2SetReal", "Terminated");
        check(fmi2DoStep(c, 0.0, 0.1, 1), "fmi2DoStep", "Terminated");
        check(fmi2Terminate(c), "fmi2Terminate", "Terminated");
        // Reset is legal everywhere.
        assert_eq!(fmi2Reset(c), OK);
        fmi2FreeInstance(c);
    }
}

#[test]
fn model_exchange_functions_are_illegal_in_co_simulation_states() {
    let host = Host::new();
    let c = ready(&host);
    let mut x = [0.0; 2];
    let mut b = 0;
    let mut info = fmi2EventInfo::default();
    unsafe {
        assert_eq!(fmi2EnterEventMode(c), ERROR);
        assert_eq!(fmi2NewDiscreteStates(c, &mut info), ERROR);
        assert_eq!(fmi2EnterContinuousTimeMode(c), ERROR);
        assert_eq!(fmi2CompletedIntegratorStep(c, 0, &mut b, &mut b), ERROR);
        assert_eq!(fmi2SetTime(c, 0.0), ERROR);
        assert_eq!(fmi2SetContinuousStates(c, x.as_ptr(), 2), ERROR);
        assert_eq!(fmi2GetDerivatives(c, x.as_mut_ptr(), 2), ERROR);
        assert_eq!(fmi2GetEventIndicators(c, x.as_mut_ptr(), 2), ERROR);
        assert_eq!(fmi2GetContinuousStates(c, x.as_mut_ptr(), 2), ERROR);
        assert_eq!(fmi2GetNominalsOfContinuousStates(c, x.as_mut_ptr(), 2), ERROR);
        assert!(host.logged(&["fmi2SetTime: illegal call in state StepComplete"]));
        assert!(host.logged(&["fmi2GetNominalsOfContinuousStates: illegal call in state StepComplete"]));
        assert_eq!(
            fmi2GetDirectionalDerivative(c, &vr::Y, 1, &vr::U, 1, x.as_ptr(), x.as_mut_ptr()),
            ERROR
        );
        assert!(host.logged(&["fmi2GetDirectionalDerivative: not supported"]));
        let order = [1];
        assert_eq!(
            fmi2SetRealInputDerivatives(c, &vr::U, 1, order.as_ptr(), x.as_ptr()),
            ERROR
        );
        assert_eq!(
            fmi2GetRealOutputDerivatives(c, &vr::Y, 1, order.as_ptr(), x.as_mut_ptr()),
            ERROR
        );
        // None of that disturbed the instance.
        assert_eq!(fmi2DoStep(c, 0.0, 0.1, 1), OK);
        fmi2FreeInstance(c);
    }
}

#[test]
fn null_pointers_are_rejected() {
    let host = Host::new();
    let nc: fmi2Component = null_mut();
    let mut v = 0.0;
    let mut st: fmi2FMUstate = null_mut();
    unsafe {
        assert_eq!(fmi2DoStep(nc, 0.0, 0.1, 1), ERROR);
        assert_eq!(fmi2GetReal(nc, &vr::Y, 1, &mut v), ERROR);
        assert_eq!(fmi2SetupExperiment(nc, 0, 0.0, 0.0, 0, 0.0), ERROR);
        assert_eq!(fmi2Reset(nc), ERROR);
        assert_eq!(fmi2GetFMUstate(nc, &mut st), ERROR);
        assert_eq!(fmi2EnterEventMode(nc), ERROR);
        fmi2FreeInstance(nc);

        let c = ready(&host);
        assert_eq!(fmi2GetReal(c, null(), 1, &mut v), ERROR);
        assert!(host.logged(&["fmi2GetReal", "vr is NULL"]));
        assert_eq!(fmi2GetReal(c, &vr::Y, 1, null_mut()), ERROR);
        assert_eq!(fmi2SetReal(c, &vr::U, 1, null()), ERROR);
        assert_eq!(fmi2SetInteger(c, null(), 1, null()), ERROR);
        assert_eq!(fmi2GetString(c, &vr::LABEL, 1, null_mut()), ERROR);
        let nulls: [fmi2String; 1] = [null()];
        assert_eq!(fmi2SetString(c, &vr::LABEL, 1, nulls.as_ptr()), ERROR);
        assert!(host.logged(&["fmi2SetString", "value reference 6", "NULL"]));
        // n == 0 with NULL arrays is fine.
        assert_eq!(fmi2GetReal(c, null(), 0, null_mut()), OK);
        assert_eq!(fmi2SetReal(c, null(), 0, null()), OK);
        assert_eq!(fmi2GetString(c, null(), 0, null_mut()), OK);
        assert_eq!(fmi2SetDebugLogging(c, 1, 0, null()), OK);
        assert_eq!(fmi2SetDebugLogging(c, 1, 1, null()), ERROR);
        // FMU state pointers.
        assert_eq!(fmi2GetFMUstate(c, null_mut()), ERROR);
        assert_eq!(fmi2SetFMUstate(c, null_mut()), ERROR);
        assert_eq!(fmi2FreeFMUstate(c, null_mut()), OK);
        assert_eq!(fmi2FreeFMUstate(c, &mut st), OK);
        let mut size = 0usize;
        assert_eq!(fmi2SerializedFMUstateSize(c, null_mut(), &mut size), ERROR);
        assert_eq!(fmi2GetFMUstate(c, &mut st), OK);
        assert_eq!(fmi2SerializedFMUstateSize(c, st, null_mut()), ERROR);
        assert_eq!(fmi2SerializedFMUstateSize(c, st, &mut size), OK);
        assert_eq!(fmi2SerializeFMUstate(c, st, null_mut(), size), ERROR);
        assert_eq!(fmi2DeSerializeFMUstate(c, null(), 10, &mut st), ERROR);
        let bytes = [0 as c_char; 4];
        assert_eq!(fmi2DeSerializeFMUstate(c, bytes.as_ptr(), 4, null_mut()), ERROR);
        // Status queries.
        assert_eq!(fmi2GetStatus(c, fmi2StatusKind_fmi2DoStepStatus, null_mut()), ERROR);
        assert_eq!(
            fmi2GetRealStatus(c, fmi2StatusKind_fmi2LastSuccessfulTime, null_mut()),
            ERROR
        );
        assert_eq!(fmi2FreeFMUstate(c, &mut st), OK);
        assert!(st.is_null());
        fmi2FreeInstance(c);
    }
}

#[test]
fn instantiate_rejections_return_null() {
    let host = Host::new();
    let name = cstring("toy1");
    let guid = cstring(TOY_GUID);
    let cs = fmi2Type_fmi2CoSimulation;
    unsafe {
        let wrong = cstring("{00000000-0000-0000-0000-000000000000}");
        assert!(fmi2Instantiate(name.as_ptr(), cs, wrong.as_ptr(), null(), &*host.callbacks, 0, 0).is_null());
        assert!(host.logged(&[
            "fmi2Instantiate",
            "GUID mismatch",
            "{00000000-0000-0000-0000-000000000000}",
            TOY_GUID
        ]));
        assert!(fmi2Instantiate(name.as_ptr(), cs, null(), null(), &*host.callbacks, 0, 0).is_null());
        let me = fmi2Type_fmi2ModelExchange;
        assert!(fmi2Instantiate(name.as_ptr(), me, guid.as_ptr(), null(), &*host.callbacks, 0, 0).is_null());
        assert!(host.logged(&["fmi2Instantiate", "Co-Simulation"]));
        assert!(fmi2Instantiate(null(), cs, guid.as_ptr(), null(), &*host.callbacks, 0, 0).is_null());
        let empty = cstring("");
        assert!(fmi2Instantiate(empty.as_ptr(), cs, guid.as_ptr(), null(), &*host.callbacks, 0, 0).is_null());
        assert!(host.logged(&["instanceName is NULL or empty"]));
        assert!(fmi2Instantiate(name.as_ptr(), cs, guid.as_ptr(), null(), null(), 0, 0).is_null());
        let mut no_logger = *host.callbacks;
        no_logger.logger = None;
        assert!(fmi2Instantiate(name.as_ptr(), cs, guid.as_ptr(), null(), &no_logger, 0, 0).is_null());
        // The rejections were logged with the host's environment and name.
        assert!(host
            .records()
            .iter()
            .all(|r| r.status == ERROR && r.category == "logStatusError"));
    }
}

#[test]
fn unknown_value_reference_and_wrong_type() {
    let host = Host::new();
    let c = ready(&host);
    let mut v = 0.0;
    let mut i = 0;
    unsafe {
        assert_eq!(fmi2GetReal(c, &999, 1, &mut v), ERROR);
        assert!(host.logged(&["fmi2GetReal", "unknown value reference 999"]));
        assert_eq!(set_real(c, 4242, 1.0), ERROR);
        assert!(host.logged(&["fmi2SetReal", "unknown value reference 4242"]));
        assert_eq!(fmi2GetInteger(c, &vr::Y, 1, &mut i), ERROR);
        assert!(host.logged(&["fmi2GetInteger", "value reference 1 (y)", "Real", "not Integer"]));
        assert_eq!(fmi2GetReal(c, &vr::MODE, 1, &mut v), ERROR);
        assert!(host.logged(&["value reference 4 (mode)"]));
        let s = cstring("x");
        assert_eq!(fmi2SetString(c, &vr::U, 1, &s.as_ptr()), ERROR);
        assert!(host.logged(&["fmi2SetString", "value reference 0 (u)"]));
        fmi2FreeInstance(c);
    }
}

#[test]
fn invalid_values_are_rejected_naming_the_variable() {
    let host = Host::new();
    let c = ready(&host);
    unsafe {
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            assert_eq!(set_real(c, vr::U, bad), ERROR);
        }
        assert!(host.logged(&["fmi2SetReal", "variable u", "not finite"]));
        assert_eq!(set_real(c, vr::GAIN, f64::NAN), ERROR);
        assert!(host.logged(&["variable gain", "NaN", "not finite"]));
        assert_eq!(set_real(c, vr::U, 10.5), ERROR);
        assert!(host.logged(&["variable u", "10.5", "outside [-10, 10]"]));
        assert_eq!(set_real(c, vr::U, 10.0), OK);
        // Outputs, calculated parameters and fixed parameters after initialisation.
        assert_eq!(set_real(c, vr::Y, 1.0), ERROR);
        assert!(host.logged(&["variable y", "cannot be set", "output"]));
        assert_eq!(set_real(c, vr::Y0, 1.0), ERROR);
        assert!(host.logged(&["variable y0", "calculatedParameter"]));
        assert_eq!(set_real(c, vr::TAU, 2.0), ERROR);
        assert!(host.logged(&["variable tau", "fixed parameter", "StepComplete"]));
        assert_eq!(fmi2SetInteger(c, &vr::MODE, 1, &1), ERROR);
        assert_eq!(fmi2SetInteger(c, &vr::STEPS, 1, &1), ERROR);
        // Tunable parameters may change during the simulation.
        assert_eq!(set_real(c, vr::GAIN, 5.0), OK);
        let s = cstring("renamed");
        assert_eq!(fmi2SetString(c, &vr::LABEL, 1, &s.as_ptr()), OK);
        assert_eq!(get_string(c, vr::LABEL), "renamed");
        // An array with one bad element changes nothing.
        let vrs = [vr::U, vr::GAIN, vr::U];
        let vals = [1.0, 7.0, f64::NAN];
        assert_eq!(fmi2SetReal(c, vrs.as_ptr(), 3, vals.as_ptr()), ERROR);
        assert_eq!(get_real(c, vr::U), 10.0);
        assert_eq!(get_real(c, vr::GAIN), 5.0);
        fmi2FreeInstance(c);

        // Integer range, in Instantiated.
        let c = instantiate(&host, "toy2");
        assert_eq!(fmi2SetInteger(c, &vr::MODE, 1, &3), ERROR);
        assert!(host.logged(&["variable mode", "outside [0, 2]"]));
        assert_eq!(fmi2SetInteger(c, &vr::MODE, 1, &-1), ERROR);
        assert_eq!(fmi2SetInteger(c, &vr::MODE, 1, &2), OK);
        assert_eq!(set_real(c, vr::TAU, 0.001), ERROR);
        assert_eq!(set_real(c, vr::TAU, 3.0), OK);
        // mode 2 makes initialisation fail: the get in InitializationMode reports it.
        assert_eq!(fmi2EnterInitializationMode(c), OK);
        let mut v = 0.0;
        assert_eq!(fmi2GetReal(c, &vr::Y, 1, &mut v), ERROR);
        assert!(host.logged(&["fmi2GetReal", "mode 2 cannot be initialised"]));
        assert_eq!(fmi2ExitInitializationMode(c), ERROR);
        // Still in InitializationMode: fix the parameter and retry.
        assert_eq!(fmi2SetInteger(c, &vr::MODE, 1, &0), OK);
        assert_eq!(fmi2ExitInitializationMode(c), OK);
        fmi2FreeInstance(c);
    }
}

#[test]
fn do_step_argument_checks() {
    let host = Host::new();
    let c = ready(&host);
    unsafe {
        assert_eq!(fmi2DoStep(c, 0.5, 0.1, 1), ERROR);
        assert!(host.logged(&["fmi2DoStep", "currentCommunicationPoint = 0.5"]));
        assert_eq!(fmi2DoStep(c, 0.0, 0.0, 1), ERROR);
        assert_eq!(fmi2DoStep(c, 0.0, -0.1, 1), ERROR);
        assert_eq!(fmi2DoStep(c, 0.0, f64::NAN, 1), ERROR);
        assert_eq!(fmi2DoStep(c, 0.0, f64::INFINITY, 1), ERROR);
        assert_eq!(fmi2DoStep(c, f64::NAN, 0.1, 1), ERROR);
        assert!(host.logged(&["communicationStepSize = NaN"]));
        assert_eq!(fmi2DoStep(c, 0.0, 10.5, 1), ERROR);
        assert!(host.logged(&["stop time 10"]));
        // Rejections leave the instance in StepComplete.
        assert_eq!(fmi2DoStep(c, 0.0, 0.1, 1), OK);
        // Accumulated floating-point time within tolerance is accepted.
        let mut t = 0.1;
        for _ in 0..99 {
            assert_eq!(fmi2DoStep(c, t, 0.1, 1), OK);
            t += 0.1;
        }
        assert!((t - 10.0).abs() < 1e-9);
        assert_eq!(fmi2DoStep(c, t, 0.1, 1), ERROR, "past the stop time");
        fmi2FreeInstance(c);
    }
}

#[test]
fn failing_step_enters_step_failed() {
    let host = Host::new();
    let c = ready(&host);
    unsafe {
        assert_eq!(fmi2DoStep(c, 0.0, 0.1, 1), OK);
        assert_eq!(set_real(c, vr::U, 9.9), OK);
        assert_eq!(fmi2DoStep(c, 0.1, 0.1, 1), ERROR);
        assert!(host.logged(&["fmi2DoStep", "failed", "input u = 9.9 too large"]));
        let mut st = 0;
        assert_eq!(fmi2GetStatus(c, fmi2StatusKind_fmi2DoStepStatus, &mut st), OK);
        assert_eq!(st, ERROR);
        let mut term = 0;
        assert_eq!(fmi2GetBooleanStatus(c, fmi2StatusKind_fmi2Terminated, &mut term), OK);
        assert_eq!(term, 1);
        let mut t = 0.0;
        assert_eq!(fmi2GetRealStatus(c, fmi2StatusKind_fmi2LastSuccessfulTime, &mut t), OK);
        assert_eq!(t, 0.1);
        let mut iv = 0;
        assert_eq!(
            fmi2GetIntegerStatus(c, fmi2StatusKind_fmi2DoStepStatus, &mut iv),
            DISCARD
        );
        assert_eq!(fmi2DoStep(c, 0.1, 0.1, 1), ERROR);
        assert!(host.logged(&["fmi2DoStep: illegal call in state StepFailed"]));
        let _ = get_real(c, vr::Y); // values remain readable
        assert_eq!(fmi2Terminate(c), OK);
        fmi2FreeInstance(c);
    }
}

#[test]
fn panicking_model_becomes_error_not_abort() {
    let host = Host::new();
    let c = ready(&host);
    unsafe {
        assert_eq!(set_real(c, vr::U, -9.75), OK);
        assert_eq!(fmi2DoStep(c, 0.0, 0.1, 1), ERROR);
        assert!(host.logged(&["fmi2DoStep", "panic", "toy model panics at t = 0"]));
        let mut term = 0;
        assert_eq!(fmi2GetBooleanStatus(c, fmi2StatusKind_fmi2Terminated, &mut term), OK);
        assert_eq!(term, 1);
        assert_eq!(fmi2Terminate(c), OK);
        // Reset recovers the instance completely.
        assert_eq!(fmi2Reset(c), OK);
        assert_eq!(fmi2EnterInitializationMode(c), OK);
        assert_eq!(fmi2ExitInitializationMode(c), OK);
        assert_eq!(fmi2DoStep(c, 0.0, 0.1, 1), OK);
        fmi2FreeInstance(c);
    }
}

#[test]
fn reset_behaves_like_a_fresh_instance() {
    let host = Host::new();
    let run = |c: fmi2Component| unsafe {
        assert_eq!(fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0), OK);
        assert_eq!(fmi2EnterInitializationMode(c), OK);
        assert_eq!(fmi2ExitInitializationMode(c), OK);
        assert_eq!(set_real(c, vr::U, 1.0), OK);
        let mut ys = vec![];
        for k in 0..10 {
            assert_eq!(fmi2DoStep(c, k as f64 * 0.1, 0.1, 1), OK);
            ys.push(get_real(c, vr::Y).to_bits());
        }
        (
            ys,
            get_int(c, vr::STEPS),
            get_string(c, vr::LABEL),
            get_real(c, vr::TAU),
        )
    };
    let fresh = run(instantiate(&host, "a"));
    let c = instantiate(&host, "b");
    unsafe {
        assert_eq!(set_real(c, vr::TAU, 7.0), OK);
        let s = cstring("changed");
        assert_eq!(fmi2SetString(c, &vr::LABEL, 1, &s.as_ptr()), OK);
        assert_eq!(fmi2SetupExperiment(c, 0, 0.0, 3.0, 0, 0.0), OK);
        assert_eq!(fmi2EnterInitializationMode(c), OK);
        assert_eq!(fmi2ExitInitializationMode(c), OK);
        assert_eq!(fmi2DoStep(c, 3.0, 0.5, 1), OK);
        assert_eq!(fmi2Reset(c), OK);
        let mut v = 0.0;
        assert_eq!(fmi2GetReal(c, &vr::Y, 1, &mut v), ERROR, "back in Instantiated");
    }
    assert_eq!(run(c), fresh);
}

#[test]
fn two_instances_are_independent() {
    let h1 = Host::new();
    let h2 = Host::new();
    let a = ready(&h1);
    let b = ready(&h2);
    unsafe {
        assert_eq!(set_real(a, vr::U, 5.0), OK);
        assert_eq!(set_real(b, vr::U, -5.0), OK);
        assert_eq!(fmi2DoStep(a, 0.0, 0.2, 1), OK);
        assert_eq!(fmi2DoStep(b, 0.0, 0.1, 1), OK);
        assert!(get_real(a, vr::Y) > 1.0);
        assert!(get_real(b, vr::Y) < 1.0);
        assert_eq!(fmi2DoStep(a, 0.0, 0.1, 1), ERROR);
        assert!(h1.logged(&["currentCommunicationPoint"]));
        assert!(
            h2.messages().is_empty(),
            "instance b logged through a's host: {:?}",
            h2.messages()
        );
        fmi2FreeInstance(a);
        assert_eq!(fmi2DoStep(b, 0.1, 0.1, 1), OK);
        fmi2FreeInstance(b);
    }
}

#[test]
fn get_string_pointers_stay_valid_until_next_call() {
    let host = Host::new();
    let c = ready(&host);
    unsafe {
        let vrs = [vr::LABEL, vr::LABEL];
        let mut ptrs: [fmi2String; 2] = [null(); 2];
        assert_eq!(fmi2GetString(c, vrs.as_ptr(), 2, ptrs.as_mut_ptr()), OK);
        // Other calls in between do not invalidate them.
        assert_eq!(fmi2DoStep(c, 0.0, 0.1, 1), OK);
        let _ = get_real(c, vr::Y);
        assert_eq!(CStr::from_ptr(ptrs[0]).to_str().unwrap(), "toy");
        assert_eq!(CStr::from_ptr(ptrs[1]).to_str().unwrap(), "toy");
        fmi2FreeInstance(c);
    }
}

#[test]
fn debug_logging_filter_and_message_passthrough() {
    let host = Host::new();
    let c = instantiate(&host, "toy1");
    unsafe {
        let bogus = cstring("logEverythingPlease");
        assert_eq!(fmi2SetDebugLogging(c, 1, 1, &bogus.as_ptr()), ERROR);
        assert!(host.logged(&["fmi2SetDebugLogging", "unknown log category", "logEverythingPlease"]));
        assert_eq!(fmi2EnterInitializationMode(c), OK);
        assert_eq!(fmi2ExitInitializationMode(c), OK);
        assert!(!host.logged(&["initialised"]), "info logged with logging off");
        assert_eq!(fmi2Reset(c), OK);
        let all = cstring("logAll");
        assert_eq!(fmi2SetDebugLogging(c, 1, 1, &all.as_ptr()), OK);
        assert_eq!(fmi2EnterInitializationMode(c), OK);
        assert_eq!(fmi2ExitInitializationMode(c), OK);
        // printf directives reach the host verbatim (passed through "%s").
        let rec = host
            .records()
            .into_iter()
            .find(|r| r.message.starts_with("initialised"))
            .unwrap();
        assert_eq!(rec.message, "initialised with x0 = 0.5 %s %n");
        assert_eq!(rec.category, "logAll");
        assert_eq!(rec.status, OK);
        // Warnings: off after disabling everything, on with logStatusWarning.
        assert_eq!(fmi2SetDebugLogging(c, 0, 0, null()), OK);
        assert_eq!(set_real(c, vr::U, 9.2), OK);
        assert_eq!(fmi2DoStep(c, 0.0, 0.1, 1), OK);
        assert!(!host.logged(&["close to its limit"]));
        let warn = cstring("logStatusWarning");
        assert_eq!(fmi2SetDebugLogging(c, 1, 1, &warn.as_ptr()), OK);
        assert_eq!(fmi2DoStep(c, 0.1, 0.1, 1), OK);
        let rec = host
            .records()
            .into_iter()
            .find(|r| r.message.contains("close to its limit"))
            .unwrap();
        assert_eq!(
            (rec.status, rec.category.as_str()),
            (fmi2Status_fmi2Warning, "logStatusWarning")
        );
        fmi2FreeInstance(c);
    }
}

fn run_steps(c: fmi2Component, from: usize, n: usize, u: impl Fn(usize) -> f64) -> Vec<u64> {
    let mut ys = vec![];
    for k in from..from + n {
        assert_eq!(set_real(c, vr::U, u(k)), OK);
        assert_eq!(unsafe { fmi2DoStep(c, k as f64 * 0.05, 0.05, 1) }, OK);
        ys.push(get_real(c, vr::Y).to_bits());
        ys.push(get_int(c, vr::STEPS) as u64);
    }
    ys
}

fn input(k: usize) -> f64 {
    (k as f64 * 0.37).sin() * 8.0
}

#[test]
fn get_set_fmu_state_continues_bit_identically() {
    let host = Host::new();
    let c = ready(&host);
    unsafe {
        run_steps(c, 0, 10, input);
        let mut st: fmi2FMUstate = null_mut();
        assert_eq!(fmi2GetFMUstate(c, &mut st), OK);
        assert!(!st.is_null());
        let first = run_steps(c, 10, 20, input);
        // Diverge, then roll back.
        run_steps(c, 30, 5, |_| -3.0);
        assert_eq!(fmi2SetFMUstate(c, st), OK);
        assert_eq!(run_steps(c, 10, 20, input), first);
        // Rolling back out of StepFailed works too.
        assert_eq!(set_real(c, vr::U, 9.9), OK);
        assert_eq!(fmi2DoStep(c, 30.0 * 0.05, 0.05, 1), ERROR);
        assert_eq!(fmi2SetFMUstate(c, st), OK);
        assert_eq!(run_steps(c, 10, 20, input), first);
        // Overwriting an existing state in place.
        let st_before = st;
        assert_eq!(fmi2GetFMUstate(c, &mut st), OK);
        assert_eq!(st, st_before);
        assert_eq!(fmi2FreeFMUstate(c, &mut st), OK);
        assert!(st.is_null());
        fmi2FreeInstance(c);
    }
}

fn serialize(c: fmi2Component, st: fmi2FMUstate) -> Vec<u8> {
    let mut size = 0;
    unsafe {
        assert_eq!(fmi2SerializedFMUstateSize(c, st, &mut size), OK);
        let mut buf = vec![0u8; size];
        assert_eq!(fmi2SerializeFMUstate(c, st, buf.as_mut_ptr().cast(), size), OK);
        assert_eq!(fmi2SerializeFMUstate(c, st, buf.as_mut_ptr().cast(), size - 1), ERROR);
        buf
    }
}

fn deserialize(c: fmi2Component, bytes: &[u8]) -> (fmi2Status, fmi2FMUstate) {
    let mut st: fmi2FMUstate = null_mut();
    let status = unsafe { fmi2DeSerializeFMUstate(c, bytes.as_ptr().cast(), bytes.len(), &mut st) };
    (status, st)
}

#[test]
fn serialized_state_round_trip_is_bit_identical() {
    let host = Host::new();
    let a = ready(&host);
    unsafe {
        run_steps(a, 0, 7, input);
        let s = cstring("saved label");
        assert_eq!(fmi2SetString(a, &vr::LABEL, 1, &s.as_ptr()), OK);
        let mut st: fmi2FMUstate = null_mut();
        assert_eq!(fmi2GetFMUstate(a, &mut st), OK);
        let bytes = serialize(a, st);
        assert_eq!(fmi2FreeFMUstate(a, &mut st), OK);
        let expected = run_steps(a, 7, 25, input);

        // Restore into a brand-new instance (still in Instantiated).
        let b = instantiate(&host, "restored");
        let (status, mut st_b) = deserialize(b, &bytes);
        assert_eq!(status, OK, "{:?}", host.messages());
        assert_eq!(fmi2SetFMUstate(b, st_b), OK);
        assert_eq!(get_string(b, vr::LABEL), "saved label");
        assert_eq!(run_steps(b, 7, 25, input), expected);
        // Serializing the deserialized state reproduces the bytes.
        assert_eq!(serialize(b, st_b), bytes);
        assert_eq!(fmi2FreeFMUstate(b, &mut st_b), OK);
        fmi2FreeInstance(a);
        fmi2FreeInstance(b);
    }
}

#[test]
fn corrupt_truncated_and_foreign_buffers_are_rejected() {
    let host = Host::new();
    let c = ready(&host);
    unsafe {
        run_steps(c, 0, 3, input);
        let mut st: fmi2FMUstate = null_mut();
        assert_eq!(fmi2GetFMUstate(c, &mut st), OK);
        let bytes = serialize(c, st);
        assert_eq!(fmi2FreeFMUstate(c, &mut st), OK);

        for n in 0..bytes.len() {
            let (status, st) = deserialize(c, &bytes[..n]);
            assert_eq!(status, ERROR, "truncated to {n} bytes");
            assert!(st.is_null());
        }
        assert!(host.logged(&["fmi2DeSerializeFMUstate", "truncated"]));
        for i in 0..bytes.len() {
            for mask in [0x01u8, 0x80, 0xff] {
                let mut b = bytes.clone();
                b[i] ^= mask;
                let (status, st) = deserialize(c, &b);
                assert_eq!(status, ERROR, "byte {i} ^ {mask:#x} accepted");
                assert!(st.is_null());
            }
        }
        assert!(host.logged(&["checksum"]));
        assert!(host.logged(&["bad magic"]));
        let mut longer = bytes.clone();
        longer.extend_from_slice(&[0, 0, 0]);
        assert_eq!(deserialize(c, &longer).0, ERROR);
        assert_eq!(deserialize(c, b"garbage that is not a state at all").0, ERROR);

        // A state of another model (same layout, other GUID) is refused.
        let host2 = Host::new();
        let name = cstring("other");
        let guid = cstring(<Other as fmi2_export::FmuModel>::GUID);
        let o = fmi2_export::ffi::instantiate::<Other>(
            name.as_ptr(),
            fmi2Type_fmi2CoSimulation,
            guid.as_ptr(),
            null(),
            &*host2.callbacks,
            0,
            0,
        );
        assert!(!o.is_null());
        let mut ost: fmi2FMUstate = null_mut();
        assert_eq!(fmi2_export::ffi::get_fmu_state::<Other>(o, &mut ost), OK);
        let mut size = 0;
        assert_eq!(
            fmi2_export::ffi::serialized_fmu_state_size::<Other>(o, ost, &mut size),
            OK
        );
        let mut foreign = vec![0u8; size];
        assert_eq!(
            fmi2_export::ffi::serialize_fmu_state::<Other>(o, ost, foreign.as_mut_ptr().cast(), size),
            OK
        );
        let (status, st) = deserialize(c, &foreign);
        assert_eq!(status, ERROR);
        assert!(st.is_null());
        assert!(host.logged(&["another model", "{99999999"]));
        // Its in-memory state and its component are refused too (tag check).
        assert_eq!(fmi2SetFMUstate(c, ost), ERROR);
        assert!(host.logged(&["fmi2SetFMUstate", "not a (live) FMU state of this model"]));
        assert_eq!(fmi2DoStep(o, 0.0, 0.1, 1), ERROR);
        assert_eq!(fmi2_export::ffi::free_fmu_state::<Other>(o, &mut ost), OK);
        fmi2_export::ffi::free_instance::<Other>(o);

        // The instance is unharmed and still accepts its own buffer.
        let (status, mut good) = deserialize(c, &bytes);
        assert_eq!(status, OK);
        assert_eq!(fmi2SetFMUstate(c, good), OK);
        assert_eq!(fmi2FreeFMUstate(c, &mut good), OK);
        assert_eq!(fmi2DoStep(c, 3.0 * 0.05, 0.05, 1), OK);
        fmi2FreeInstance(c);
    }
}

/// `bytes` (a serialized state of the toy) with the first f64 equal to `from` in its
/// payload replaced by `to`, re-sealed with a valid checksum (what a corrupting or
/// malicious host can produce).
fn reseal_replacing(bytes: &[u8], from: f64, to: &[u8]) -> Vec<u8> {
    let mut payload = fmi2_export::state::open(TOY_GUID, bytes).unwrap().to_vec();
    let needle = from.to_le_bytes();
    let at = payload
        .windows(8)
        .position(|w| w == needle)
        .expect("the marker value is in the payload");
    payload[at..at + to.len()].copy_from_slice(to);
    fmi2_export::state::seal(TOY_GUID, &payload)
}

#[test]
fn restored_parameters_and_inputs_are_checked_like_set_values() {
    let host = Host::new();
    let c = instantiate(&host, "toy1");
    unsafe {
        // Marker values, to find the variables in the payload.
        assert_eq!(set_real(c, vr::TAU, 1.234_567), OK);
        assert_eq!(set_real(c, vr::X0, 0.765_432_1), OK);
        assert_eq!(fmi2SetupExperiment(c, 0, 0.0, 0.0, 1, 10.0), OK);
        assert_eq!(fmi2EnterInitializationMode(c), OK);
        assert_eq!(fmi2ExitInitializationMode(c), OK);
        run_steps(c, 0, 3, input);
        assert_eq!(set_real(c, vr::U, 4.321_987), OK);
        let mut st: fmi2FMUstate = null_mut();
        assert_eq!(fmi2GetFMUstate(c, &mut st), OK);
        let bytes = serialize(c, st);
        let expected = run_steps(c, 3, 5, input);

        let cases: [(f64, f64, &[&str]); 5] = [
            (1.234_567, 2e10, &["tau", "20000000000", "outside [0.01, 100]"]),
            (1.234_567, f64::NAN, &["tau", "NaN", "not finite"]),
            (1.234_567, -0.0, &["tau", "outside [0.01, 100]"]),
            (4.321_987, 11.0, &["u (value reference 0)", "outside [-10, 10]"]),
            (4.321_987, f64::NEG_INFINITY, &["variable u", "-inf", "not finite"]),
        ];
        for (from, to, parts) in cases {
            let forged = reseal_replacing(&bytes, from, &to.to_le_bytes());
            let n = host.messages().len();
            let (status, st) = deserialize(c, &forged);
            assert_eq!(status, ERROR, "{parts:?}");
            assert!(st.is_null());
            let new = &host.messages()[n..];
            assert!(
                new.iter()
                    .any(|m| m.starts_with("fmi2DeSerializeFMUstate: ") && parts.iter().all(|p| m.contains(p))),
                "{parts:?} not in {new:?}"
            );
        }
        // An unbounded parameter takes any finite value, but not a non-finite one.
        let forged = reseal_replacing(&bytes, 0.765_432_1, &1e300f64.to_le_bytes());
        let (status, mut ok) = deserialize(c, &forged);
        assert_eq!(status, OK, "{:?}", host.messages());
        assert_eq!(fmi2FreeFMUstate(c, &mut ok), OK);
        let forged = reseal_replacing(&bytes, 0.765_432_1, &f64::INFINITY.to_le_bytes());
        assert_eq!(deserialize(c, &forged).0, ERROR);
        assert!(host.logged(&["x0", "inf", "not finite"]));

        // fmi2SetFMUstate checks the same: a state altered in memory is refused and the
        // instance keeps its state.
        let snap = &mut *st.cast::<fmi2_export::Snapshot<Toy>>();
        snap.vars.mode = 7;
        let before = get_real(c, vr::Y).to_bits();
        assert_eq!(fmi2SetFMUstate(c, st), ERROR);
        assert!(host.logged(&["fmi2SetFMUstate", "mode", "7", "outside [0, 2]"]));
        assert_eq!(get_real(c, vr::Y).to_bits(), before);
        assert_eq!(get_int(c, vr::STEPS), 8);
        // Repaired, it restores and continues bit-identically.
        snap.vars.mode = 0;
        assert_eq!(fmi2SetFMUstate(c, st), OK);
        assert_eq!(run_steps(c, 3, 5, input), expected);
        assert_eq!(fmi2FreeFMUstate(c, &mut st), OK);
        fmi2FreeInstance(c);
    }
}
