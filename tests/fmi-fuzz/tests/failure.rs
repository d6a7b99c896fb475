//! Failure behaviour in flight, through the real C ABI:
//! - the plant driven out of its envelope (absurd parameters) reports fmi2Error
//!   with a message naming the state that left the envelope, and stays usable
//!   (status, outputs, terminate, reset);
//! - a single enormous communication step returns promptly;
//! - the controllers never emit non-finite commands on garbage-but-finite inputs.

use fmi_fuzz::model_description_types::{Causality, VarType};
use fmi_fuzz::{load_required, Fmu, Rng, ERROR, OK};
use std::time::{Duration, Instant};

/// Envelope quantities the plant names besides its states (`tailsitter_physics::idx::STATE_NAMES`).
const ENVELOPE_QUANTITIES: [&str; 3] = ["speed", "airspeed", "quaternion norm"];

fn plant(fmus: &[Fmu]) -> &Fmu {
    fmus.iter()
        .find(|f| f.id == "tailsitter_plant")
        .expect("tailsitter_plant is required")
}

/// Fly with `params` (set in Instantiated) and `inputs` (after init) until a step fails.
fn diverge(fmu: &Fmu, params: &[(&str, f64)], inputs: &[(&str, f64)]) -> (f64, String) {
    let mut inst = fmu.instance("diverge", true);
    assert_eq!(inst.setup(0.0, None), OK);
    for (name, x) in params {
        assert_eq!(
            inst.set_reals(&[fmu.var(name).vr], &[*x]),
            OK,
            "set {name}: {:?}",
            inst.host.records()
        );
    }
    assert_eq!(inst.enter_init(), OK);
    assert_eq!(inst.exit_init(), OK, "{:?}", inst.host.records());
    for (name, x) in inputs {
        assert_eq!(inst.set_reals(&[fmu.var(name).vr], &[*x]), OK, "set {name}");
    }
    let h = fmu.default_step;
    for k in 0..5000 {
        let t = k as f64 * h;
        let from = inst.host.len();
        match inst.step(t, h) {
            OK => continue,
            ERROR => {
                let msgs: Vec<String> = inst
                    .host
                    .since(from)
                    .into_iter()
                    .filter(|r| r.status == ERROR)
                    .map(|r| r.message)
                    .collect();
                assert!(!msgs.is_empty(), "fmi2Error without a logged message");
                // Still a well-behaved instance: StepFailed, outputs readable, terminate, reset.
                let mut status = 0;
                // SAFETY: live instance, valid out pointer.
                let s = unsafe {
                    fmi_fuzz::ffi!(
                        fmu.api,
                        get_status(inst.c, fmi_fuzz::fmi2::fmi2StatusKind_fmi2DoStepStatus, &mut status)
                    )
                };
                assert_eq!(
                    (s, status),
                    (OK, ERROR),
                    "fmi2GetStatus(DoStepStatus) after the failure"
                );
                assert_eq!(inst.step(t + h, h), ERROR, "DoStep after a failed step must be refused");
                let (s, _) = inst.get_reals(&inst.all_real_vrs());
                assert_eq!(s, OK, "outputs readable in StepFailed");
                assert_eq!(inst.terminate(), OK);
                assert_eq!(inst.reset(), OK);
                inst.initialize();
                assert_eq!(inst.step(0.0, h), OK, "a reset instance flies again");
                return (t, msgs.join(" | "));
            }
            s => panic!("unexpected status {s}"),
        }
    }
    panic!("{}: no divergence with {params:?} {inputs:?}", fmu.id);
}

fn assert_names_a_state(msg: &str) {
    assert!(
        msg.contains("envelope"),
        "message does not say the plant left its envelope: {msg}"
    );
    assert!(
        tailsitter_physics::idx::STATE_NAMES
            .iter()
            .chain(ENVELOPE_QUANTITIES.iter())
            .any(|s| msg.contains(&format!("{s} ")) || msg.contains(&format!("state {s}"))),
        "message names no state: {msg}"
    );
}

#[test]
fn plant_reports_the_state_leaving_the_envelope_on_huge_thrust() {
    let fmus = load_required();
    let fmu = plant(&fmus);
    let (t, msg) = diverge(
        fmu,
        &[("mass", 0.1), ("thrust_max", 10_000.0)],
        &[("thrust_cmd", 10_000.0)],
    );
    println!("huge thrust, 0.1 kg: fmi2Error at t = {t:.2} s: {msg}");
    assert_names_a_state(&msg);
}

#[test]
fn plant_reports_the_state_leaving_the_envelope_on_tiny_inertia() {
    let fmus = load_required();
    let fmu = plant(&fmus);
    let (t, msg) = diverge(
        fmu,
        &[("i_xx", 1e-4), ("i_zz", 1e-4)],
        &[("aileron_cmd", 0.4), ("rudder_cmd", -0.4)],
    );
    println!("tiny inertia: fmi2Error at t = {t:.2} s: {msg}");
    assert_names_a_state(&msg);
}

#[test]
fn plant_initialises_at_the_smallest_declared_inertia() {
    // i_yy = 1e-4 lies inside its declared range [1e-4, 1e4]; the trim's Newton
    // iteration must accept a residual at round-off level (it scales with 1/i_yy).
    let fmus = load_required();
    let fmu = plant(&fmus);
    let mut inst = fmu.instance("tiny_iyy", false);
    assert_eq!(inst.setup(0.0, None), OK);
    assert_eq!(inst.set_reals(&[fmu.var("i_yy").vr], &[1e-4]), OK);
    assert_eq!(inst.enter_init(), OK);
    assert_eq!(inst.exit_init(), OK, "{:?}", inst.host.records());
}

#[test]
fn an_enormous_communication_step_returns_promptly() {
    // h = 1e6 s (1e9 substeps at a 1 ms integration step): a single fmi2DoStep must
    // fail (or finish) in bounded time instead of blocking the host for hours.
    let mut hung = Vec::new();
    for id in fmi_fuzz::required_models() {
        let (tx, rx) = std::sync::mpsc::channel();
        let fmu: &'static Fmu = Box::leak(Box::new(Fmu::load(&id).expect("load")));
        std::thread::spawn(move || {
            let mut inst = fmu.instance("huge", false);
            inst.initialize();
            let t0 = Instant::now();
            let s = inst.step(0.0, 1e6);
            let _ = tx.send((s, t0.elapsed()));
        });
        match rx.recv_timeout(Duration::from_secs(10)) {
            Ok((s, dt)) => println!("{id}: fmi2DoStep(h = 1e6 s) → status {s} in {:.3} s", dt.as_secs_f64()),
            Err(_) => {
                println!("{id}: fmi2DoStep(h = 1e6 s) still running after 10 s");
                hung.push(id);
            }
        }
    }
    assert!(hung.is_empty(), "fmi2DoStep(h = 1e6 s) blocks: {hung:?}");
}

/// Outputs that went non-finite (name → count) over 20 runs of 100 steps with
/// garbage-but-finite inputs (within the declared ranges; the interface declares
/// none for the measurements, so ±1e300 is legal).
fn garbage_runs(fmu: &Fmu) -> std::collections::BTreeMap<String, usize> {
    let inputs: Vec<_> = fmu
        .vars_of(VarType::Real)
        .filter(|v| v.causality == Causality::Input)
        .cloned()
        .collect();
    let outputs: Vec<_> = fmu
        .vars_of(VarType::Real)
        .filter(|v| v.causality == Causality::Output)
        .cloned()
        .collect();
    let vrs: Vec<u32> = outputs.iter().map(|v| v.vr).collect();
    let mut rng = Rng::new(7);
    let (mut steps_ok, mut steps_err, mut logged) = (0, 0, 0);
    let mut bad = std::collections::BTreeMap::new();
    for run in 0..20 {
        let mut inst = fmu.instance(&format!("garbage{run}"), true);
        inst.initialize();
        let h = fmu.default_step;
        let mut t = 0.0;
        for _ in 0..100 {
            for v in &inputs {
                let x = loop {
                    let x = match rng.below(4) {
                        0 => rng.wild_f64(),
                        1 => *rng.pick(&[1e300, -1e300, 1e30, -1e30, 5e-324, 0.0, 1e6, -1e6]),
                        _ => (rng.unit() - 0.5) * 10f64.powi(rng.below(8) as i32),
                    };
                    if x.is_finite() && x >= v.min && x <= v.max {
                        break x;
                    }
                };
                assert_eq!(inst.set_reals(&[v.vr], &[x]), OK, "{}: set {} = {x}", fmu.id, v.name);
            }
            let from = inst.host.len();
            let s = inst.step(t, h);
            logged += inst.host.since(from).iter().filter(|r| r.status != OK).count();
            if s != OK {
                steps_err += 1;
                assert!(
                    !inst.host.since(from).is_empty(),
                    "{}: step status {s} without a message",
                    fmu.id
                );
                break;
            }
            steps_ok += 1;
            t += h;
            let (s, y) = inst.get_reals(&vrs);
            assert_eq!(s, OK, "{}: get outputs", fmu.id);
            for (v, value) in outputs.iter().zip(&y) {
                if !value.is_finite() {
                    *bad.entry(v.name.clone()).or_insert(0) += 1;
                }
            }
        }
    }
    println!(
        "{}: garbage inputs: {steps_ok} steps, {steps_err} refused steps, {logged} warnings/errors logged, \
         non-finite outputs: {bad:?}",
        fmu.id
    );
    bad
}

fn controllers(fmus: &[Fmu]) -> Vec<&Fmu> {
    let c: Vec<&Fmu> = fmus.iter().filter(|f| f.id != "tailsitter_plant").collect();
    if c.is_empty() {
        println!("no controller FMU in TAILSITTER_FMUS: nothing to check");
    }
    c
}

#[test]
fn controllers_never_emit_non_finite_commands_on_garbage_inputs() {
    let fmus = load_required();
    for fmu in controllers(&fmus) {
        let bad = garbage_runs(fmu);
        let commands: Vec<_> = bad.keys().filter(|n| n.ends_with("_cmd")).collect();
        assert!(commands.is_empty(), "{}: non-finite commands {commands:?}", fmu.id);
    }
}

#[test]
fn controllers_keep_every_output_finite_on_garbage_inputs() {
    // Diagnostic outputs too (pos_error, references, phase): a host records them.
    let fmus = load_required();
    for fmu in controllers(&fmus) {
        let bad = garbage_runs(fmu);
        assert!(bad.is_empty(), "{}: non-finite outputs {bad:?}", fmu.id);
    }
}

#[test]
fn a_step_whose_end_time_overflows_is_refused() {
    // fmi2SetupExperiment accepts any finite start time; t + h must stay finite too,
    // or the FMU time becomes +inf, every later currentCommunicationPoint "matches"
    // it, and the FMU's own serialized state no longer deserializes.
    let mut accepted = Vec::new();
    for fmu in &load_required() {
        let mut inst = fmu.instance("overflow", false);
        assert_eq!(inst.setup(1e300, None), OK);
        assert_eq!(inst.enter_init(), OK);
        if inst.exit_init() != OK {
            continue; // a model refusing this start time is fine (see the next test)
        }
        if inst.step(1e300, f64::MAX) == OK {
            let mut t = 0.0;
            // SAFETY: live instance, valid out pointer.
            unsafe {
                fmi_fuzz::ffi!(
                    fmu.api,
                    get_real_status(inst.c, fmi_fuzz::fmi2::fmi2StatusKind_fmi2LastSuccessfulTime, &mut t)
                )
            };
            accepted.push(format!("{}: FMU time {t}", fmu.id));
        }
    }
    assert!(
        accepted.is_empty(),
        "fmi2DoStep(t = 1e300, h = f64::MAX) accepted: {accepted:?}"
    );
}

#[test]
fn any_finite_start_time_is_handled_without_panic() {
    // A panic is caught by the export layer (fmi2Error "internal error (panic)"),
    // but it is a model bug: a huge start/mission time must be refused or handled.
    let mut panics = Vec::new();
    for fmu in &load_required() {
        for start in [1e300, 1e20, -1e20] {
            let mut inst = fmu.instance("start", false);
            assert_eq!(inst.setup(start, None), OK);
            assert_eq!(inst.enter_init(), OK);
            if inst.exit_init() == OK {
                inst.step(start, fmu.default_step);
                inst.get_reals(&inst.all_real_vrs());
            }
            panics.extend(
                inst.host
                    .records()
                    .into_iter()
                    .filter(|r| r.message.contains("panic"))
                    .map(|r| format!("{} start {start}: {}", fmu.id, r.message)),
            );
        }
    }
    assert!(panics.is_empty(), "{panics:#?}");
}
