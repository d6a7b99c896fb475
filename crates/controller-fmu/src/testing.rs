//! Checks every controller FMU's tests share (not used by the FMUs themselves).

use fmi2_export::fmi_sys::fmi2::{fmi2Status_fmi2Error as ERROR, fmi2Status_fmi2OK as OK};
use fmi2_export::test_host::restore_forged;
use fmi2_export::{FmuModel, Logger, StateReader, StateWriter};

/// A serialized FMU state of the controller `M` is checked like values set by the host:
/// a forged mission parameter (a state re-sealed with a valid checksum after its payload
/// was altered, or a state altered in memory) is refused with fmi2Error and a message
/// naming it, before the controller is rebuilt from it (a t_level of 2e10 s once asked
/// the reference profile for 2e12 points: an allocation failure aborts the host); a value
/// the host could have set is restored.
pub fn assert_forged_mission_parameter_is_refused<M: FmuModel>() {
    for (forged, why) in [
        (2e10, "outside [0, 10000]"),
        (f64::NAN, "NaN is not finite"),
        (f64::INFINITY, "inf is not finite"),
        (-1.0, "outside [0, 10000]"),
        (10_000.5, "outside [0, 10000]"),
    ] {
        let r = restore_forged::<M>("t_level", 12.345_678_9, forged);
        for (call, (status, messages)) in [
            ("fmi2DeSerializeFMUstate", &r.deserialize),
            ("fmi2SetFMUstate", &r.set_state),
        ] {
            assert_eq!(*status, ERROR, "{call} of t_level = {forged}: {messages:?}");
            assert!(
                messages
                    .iter()
                    .any(|m| m.starts_with(call) && m.contains("t_level") && m.contains(why)),
                "{call} of t_level = {forged}: {messages:?}"
            );
        }
        assert!(r.unchanged, "t_level = {forged}: the instance changed");
    }
    let r = restore_forged::<M>("t_level", 12.345_678_9, 20.0);
    assert_eq!(r.deserialize.0, OK, "{:?}", r.deserialize.1);
    assert_eq!(r.set_state.0, OK, "{:?}", r.set_state.1);
}

/// Initialising `M` from `vars` (one parameter set out of range by the caller) fails with an
/// error naming `parameter`.
pub fn assert_initialize_refuses<M: FmuModel>(mut vars: M::Vars, parameter: &str) {
    let mut model = M::new(&vars);
    let e = model
        .initialize(&mut vars, 0.0, &mut Logger::null())
        .expect_err("initialize accepted an invalid parameter");
    assert!(format!("{e:?}").contains(parameter), "{parameter}: {e:?}");
}

/// The state written after one sample (`perturb` changes an input first) and read into a
/// fresh instance steps on exactly as the original: the values `outputs` reads agree bit for bit.
pub fn assert_state_round_trip<M: FmuModel>(
    mut vars: M::Vars,
    perturb: impl Fn(&mut M::Vars),
    outputs: impl Fn(&M::Vars) -> Vec<f64>,
) where
    M::Vars: Clone,
{
    let mut model = M::new(&vars);
    let mut log = Logger::null();
    model.initialize(&mut vars, 0.0, &mut log).unwrap();
    perturb(&mut vars);
    model.do_step(&mut vars, 0.02, 0.02, &mut log).unwrap();
    let mut w = StateWriter::new();
    model.write_state(&mut w);
    let bytes = w.into_bytes();
    let mut other = M::new(&vars);
    other.read_state(&mut StateReader::new(&bytes)).unwrap();
    let (mut a, mut b) = (vars.clone(), vars);
    model.do_step(&mut a, 0.04, 0.02, &mut log).unwrap();
    other.do_step(&mut b, 0.04, 0.02, &mut log).unwrap();
    assert_eq!(outputs(&a), outputs(&b));
}

/// Sampling through the FMU (sample time 0.02 s, state after `initialize` checked by
/// `initial`): steps of 5 ms hold the command `command` reads although `perturb` changed an
/// input; the step that reaches the next sample acts on it; an input made non-finite by
/// `poison` is then an error naming `poisoned`.
pub fn assert_sampled_between_steps<M: FmuModel>(
    mut vars: M::Vars,
    initial: impl Fn(&M::Vars),
    perturb: impl Fn(&mut M::Vars),
    command: impl Fn(&M::Vars) -> f64,
    (poison, poisoned): (impl Fn(&mut M::Vars), &str),
) {
    let mut model = M::new(&vars);
    let mut log = Logger::null();
    model.initialize(&mut vars, 0.0, &mut log).unwrap();
    initial(&vars);
    let first = command(&vars);
    perturb(&mut vars);
    for t in [0.0, 0.005] {
        model.do_step(&mut vars, t, 0.005, &mut log).unwrap();
        assert_eq!(command(&vars), first, "changed between samples at {t} s");
    }
    model.do_step(&mut vars, 0.02, 0.005, &mut log).unwrap();
    assert_ne!(command(&vars), first, "the sample at 0.02 s ignored the changed input");
    poison(&mut vars);
    let e = model.do_step(&mut vars, 0.04, 0.02, &mut log).unwrap_err();
    assert!(format!("{e:?}").contains(&format!("'{poisoned}'")), "{e:?}");
}
