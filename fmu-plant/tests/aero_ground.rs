//! The plant FMU's issue-13 variables: `aero_model`, `stall_fraction`, `aero_regime`, the
//! ground (`initial_condition = 2`, `ground_contact_points`, `touchdown_speed`) and the
//! logger messages when the aircraft first leaves attached flow and when it touches down.

use fmi2_export::fmi_sys::fmi2::*;
use fmi2_export::{FmuModel, LogSink, Logger, VariableStore};
use std::ffi::{c_char, c_void, CStr};
use std::sync::Mutex;
use tailsitter_plant::{PlantModel, Variables};

static MESSAGES: Mutex<Vec<String>> = Mutex::new(Vec::new());

/// Host logger receiving `logger(env, name, status, category, "%s", message)` (see the bench).
unsafe extern "C" fn record(
    _env: fmi2ComponentEnvironment,
    name: fmi2String,
    _status: fmi2Status,
    _category: fmi2String,
    _format: fmi2String,
    message: *const c_char,
) {
    // SAFETY: the export layer passes NUL-terminated instance name and message.
    let text = unsafe {
        format!(
            "{}: {}",
            CStr::from_ptr(name).to_string_lossy(),
            CStr::from_ptr(message).to_string_lossy()
        )
    };
    MESSAGES.lock().unwrap().push(text);
}

fn sink(instance: &str) -> LogSink {
    let logger: fmi2CallbackLogger =
        // SAFETY: `record` takes the six arguments the layer passes (one variadic argument).
        Some(unsafe { std::mem::transmute::<*const c_void, unsafe extern "C" fn(fmi2ComponentEnvironment, fmi2String, fmi2Status, fmi2String, fmi2String, ...)>(record as *const c_void) });
    LogSink::new(logger, std::ptr::null_mut(), instance, true)
}

/// Messages of `instance` containing `needle` (tests run in parallel).
fn messages_containing(instance: &str, needle: &str) -> usize {
    let prefix = format!("{instance}: ");
    MESSAGES
        .lock()
        .unwrap()
        .iter()
        .filter(|m| m.starts_with(&prefix) && m.contains(needle))
        .count()
}

/// One 20 ms step and the outputs after it (computed lazily: `LAZY_STEP_OUTPUTS`).
fn step(model: &mut PlantModel, vars: &mut Variables, t: f64, log: &mut Logger<'_>) {
    model.do_step(vars, t, 0.02, log).unwrap();
    model.update_outputs(vars).unwrap();
}

/// Starts at rest on the ground, stays there, takes off, lands hard: outputs and messages.
#[test]
fn ground_start_take_off_and_hard_landing_are_reported() {
    let sink = sink("ground");
    let mut log = Logger::new(&sink);
    let mut vars = Variables::with_start_values();
    vars.initial_condition = 2;
    vars.thrust_cmd = 0.0;
    let mut model = PlantModel::new(&vars);
    model.initialize(&mut vars, 0.0, &mut log).unwrap();
    assert_eq!(vars.ground_contact_points, 4.0);
    assert_eq!(vars.trim_thrust, 0.0);
    assert!((vars.theta - core::f64::consts::FRAC_PI_2).abs() < 1e-9);
    let d0 = vars.pos_d;
    // The default ground is 10 m below the origin; the CG stands gear_length above it.
    assert!((d0 - (vars.ground_height - vars.gear_length)).abs() < 0.02);
    let mut t = 0.0;
    for _ in 0..250 {
        step(&mut model, &mut vars, t, &mut log);
        t += 0.02;
    }
    assert_eq!(vars.ground_contact_points, 4.0);
    assert!((vars.pos_d - d0).abs() < 1e-6 && vars.touchdown_speed == 0.0);
    // Take off, climb, cut the motors: it falls back and lands hard (tail first).
    vars.thrust_cmd = 130.0;
    for _ in 0..75 {
        step(&mut model, &mut vars, t, &mut log);
        t += 0.02;
    }
    assert_eq!(vars.ground_contact_points, 0.0);
    assert!(messages_containing("ground", "lift-off") >= 1);
    vars.thrust_cmd = 0.0;
    let mut landed = false;
    for _ in 0..300 {
        step(&mut model, &mut vars, t, &mut log);
        t += 0.02;
        landed |= vars.ground_contact_points > 0.0;
        assert!(vars.pos_d.is_finite() && vars.accel_x.is_finite());
    }
    assert!(landed);
    assert!(vars.touchdown_speed > 1.0, "touchdown {}", vars.touchdown_speed);
    assert!(messages_containing("ground", "hard touchdown") >= 1);
}

/// Hovering, a 6 m/s wind step: the regime outputs leave 0 and one warning is logged, once;
/// with `aero_model = 0` the same warning names the thesis model used outside its validity.
#[test]
fn leaving_attached_flow_is_reported_once() {
    for (model_index, expected) in [(1, "global model"), (0, "outside its validity")] {
        let name = format!("hover{model_index}");
        let sink = sink(&name);
        let mut log = Logger::new(&sink);
        let mut vars = Variables::with_start_values();
        vars.initial_speed = 0.0;
        vars.aero_model = model_index;
        let mut model = PlantModel::new(&vars);
        model.initialize(&mut vars, 0.0, &mut log).unwrap();
        vars.thrust_cmd = vars.trim_thrust;
        assert_eq!((vars.stall_fraction, vars.aero_regime), (0.0, 0.0));
        let before = messages_containing(&name, expected);
        vars.wind_n = 6.0;
        let mut t = 0.0;
        for _ in 0..10 {
            step(&mut model, &mut vars, t, &mut log);
            t += 0.02;
        }
        assert!(vars.stall_fraction > 0.0 && vars.aero_regime >= 1.0);
        assert_eq!(messages_containing(&name, expected) - before, 1);
    }
}

#[test]
fn bad_aero_and_ground_parameters_are_refused() {
    let mut log = Logger::null();
    for set in [
        (|v: &mut Variables| v.aero_model = 3) as fn(&mut Variables),
        |v: &mut Variables| v.alpha_stalled = v.alpha_attached,
        |v: &mut Variables| v.ground_stiffness = 0.0,
    ] {
        let mut vars = Variables::with_start_values();
        set(&mut vars);
        let mut model = PlantModel::new(&vars);
        assert!(model.initialize(&mut vars, 0.0, &mut log).is_err());
    }
}
