//! Probes of a declared ModelStructure against the real behaviour of a model, by finite
//! differences through its C ABI (Co-Simulation).
//!
//! - [`outputs`]: after initialisation and some steps, each input is perturbed and the
//!   outputs are read again without a step: an output that changes must declare the
//!   input in its `dependencies` (direct feedthrough).
//! - [`initial_unknowns`]: for each known of Initialization Mode (input or parameter),
//!   a fresh instance has it perturbed before fmi2ExitInitializationMode: an initial
//!   unknown that changes must declare it.
//!
//! A probe also counts the declared dependencies it saw to be real, so a test can ask
//! that a declaration is not empty talk. Integer outputs are compared too; Real,
//! Integer and Boolean knowns are perturbed (Real by 10 % of max(|x|, 1) inside
//! [min, max], Integer by 1, Boolean flipped); a perturbation the model refuses (set
//! or initialisation fails) is recorded as skipped.

use crate::ffi;
use crate::fmi_sys::fmi2::{fmi2Boolean, fmi2Component, fmi2Status_fmi2OK as OK};
use crate::test_host::Host;
use crate::{Causality, FmuModel, ValueType, VariableSpec, VariableStore};
use std::collections::BTreeSet;

/// What a probe saw.
#[derive(Debug, Default, Clone)]
pub struct Probe {
    /// (unknown, known, before, after): the unknown changed with the known, which it
    /// does not declare.
    pub undeclared: Vec<(String, String, f64, f64)>,
    /// Declared (unknown, known) pairs whose known was probed.
    pub declared: usize,
    /// Declared (unknown, known) pairs seen to be real.
    pub confirmed: Vec<(String, String)>,
    /// Knowns perturbed.
    pub probed: Vec<String>,
    /// Knowns whose perturbation the model refused.
    pub skipped: Vec<String>,
}

impl Probe {
    /// Panics when an unknown changed with a known it does not declare, or when no
    /// declared dependency on a probed known is real (while some are declared).
    pub fn assert_holds(&self, what: &str) {
        assert!(
            self.undeclared.is_empty(),
            "{what}: undeclared dependencies (unknown, known, before, after): {:#?}",
            self.undeclared
        );
        assert!(
            self.declared == 0 || !self.confirmed.is_empty(),
            "{what}: none of the {} declared dependencies is real",
            self.declared
        );
    }

    /// The knowns among `names` that some unknown was seen to depend on.
    pub fn confirmed_knowns(&self) -> BTreeSet<&str> {
        self.confirmed.iter().map(|(_, k)| k.as_str()).collect()
    }
}

fn spec<M: FmuModel>(vr: u32) -> &'static VariableSpec {
    let i = <M::Vars as VariableStore>::index_of(vr).unwrap_or_else(|| panic!("no variable with vr {vr}"));
    &M::Vars::VARIABLES[i]
}

/// The value of `vr` as f64 (Real, Integer or Boolean).
///
/// # Safety
/// `c` is a live instance of `M`.
unsafe fn get<M: FmuModel>(c: fmi2Component, vr: u32) -> f64 {
    // SAFETY: one value read into a local of the right type; `c` live (caller's contract).
    unsafe {
        match spec::<M>(vr).value_type {
            ValueType::Real => {
                let mut x = 0.0;
                assert_eq!(ffi::get_real::<M>(c, &vr, 1, &mut x), OK);
                x
            }
            ValueType::Integer => {
                let mut x = 0;
                assert_eq!(ffi::get_integer::<M>(c, &vr, 1, &mut x), OK);
                f64::from(x)
            }
            ValueType::Boolean => {
                let mut x: fmi2Boolean = 0;
                assert_eq!(ffi::get_boolean::<M>(c, &vr, 1, &mut x), OK);
                f64::from(x)
            }
            ValueType::String => f64::NAN,
        }
    }
}

/// Set `vr` to `x`; whether the model accepted it.
///
/// # Safety
/// `c` is a live instance of `M`.
unsafe fn set<M: FmuModel>(c: fmi2Component, vr: u32, x: f64) -> bool {
    // SAFETY: one value from a local of the right type; `c` live (caller's contract).
    unsafe {
        match spec::<M>(vr).value_type {
            ValueType::Real => ffi::set_real::<M>(c, &vr, 1, &x) == OK,
            ValueType::Integer => ffi::set_integer::<M>(c, &vr, 1, &(x as i32)) == OK,
            ValueType::Boolean => ffi::set_boolean::<M>(c, &vr, 1, &(x as fmi2Boolean)) == OK,
            ValueType::String => false,
        }
    }
}

/// Set every (value reference, value) of `setup`; panics if one is refused.
///
/// # Safety
/// `c` is a live instance of `M` in Initialization Mode.
unsafe fn configure<M: FmuModel>(c: fmi2Component, setup: &[(u32, f64)]) {
    for &(vr, x) in setup {
        // SAFETY: `c` live (caller's contract).
        assert!(unsafe { set::<M>(c, vr, x) }, "setting {} = {x}", spec::<M>(vr).name);
    }
}

/// The perturbed value of a known whose value is `x`.
fn perturbed(s: &VariableSpec, x: f64) -> f64 {
    match s.value_type {
        ValueType::Boolean => 1.0 - x,
        ValueType::Integer => {
            if x + 1.0 <= s.max {
                x + 1.0
            } else {
                x - 1.0
            }
        }
        _ => {
            let d = 0.1 * x.abs().max(1.0);
            if x + d <= s.max {
                x + d
            } else {
                x - d
            }
        }
    }
}

fn knowns<M: FmuModel>(causalities: &[Causality]) -> Vec<&'static VariableSpec> {
    M::Vars::VARIABLES
        .iter()
        .filter(|s| causalities.contains(&s.causality) && s.value_type != ValueType::String)
        .collect()
}

fn same(a: f64, b: f64) -> bool {
    a.to_bits() == b.to_bits() || a == b
}

/// Compare `before`/`after` of every unknown for the known `k`.
fn record<M: FmuModel>(p: &mut Probe, unknowns: &[(u32, Vec<u32>)], k: &VariableSpec, before: &[f64], after: &[f64]) {
    p.probed.push(k.name.to_string());
    for ((u, deps), (&y0, &y1)) in unknowns.iter().zip(before.iter().zip(after)) {
        let declared = deps.contains(&k.value_reference);
        let name = spec::<M>(*u).name.to_string();
        p.declared += usize::from(declared);
        match (declared, same(y0, y1)) {
            (true, false) => p.confirmed.push((name, k.name.to_string())),
            (false, false) => p.undeclared.push((name, k.name.to_string(), y0, y1)),
            _ => {}
        }
    }
}

/// Probe the Outputs of `M`: (output, declared inputs) by value reference. The instance
/// is initialised with its start values overridden by `setup` (value reference, value)
/// and advanced `steps` steps of `h` seconds first.
pub fn outputs<M: FmuModel>(unknowns: &[(u32, Vec<u32>)], setup: &[(u32, f64)], steps: usize, h: f64) -> Probe {
    let host = Host::new();
    let mut p = Probe::default();
    // SAFETY: the instance lives within this block and `host` outlives it.
    unsafe {
        let c = host.initializing::<M>("probe");
        configure::<M>(c, setup);
        assert_eq!(ffi::exit_initialization_mode::<M>(c), OK, "{:?}", host.messages());
        for k in 0..steps {
            assert_eq!(ffi::do_step::<M>(c, k as f64 * h, h, 1), OK, "{:?}", host.messages());
        }
        let read = |c| unknowns.iter().map(|(u, _)| get::<M>(c, *u)).collect::<Vec<_>>();
        for k in knowns::<M>(&[Causality::Input]) {
            let x = get::<M>(c, k.value_reference);
            let before = read(c);
            if !set::<M>(c, k.value_reference, perturbed(k, x)) {
                p.skipped.push(k.name.to_string());
                continue;
            }
            let after = read(c);
            assert!(set::<M>(c, k.value_reference, x));
            record::<M>(&mut p, unknowns, k, &before, &after);
        }
        ffi::free_instance::<M>(c);
    }
    p
}

/// Probe the InitialUnknowns of `M`: (unknown, declared knowns) by value reference; the
/// knowns perturbed are every input and parameter, from their start values overridden by
/// `setup` (value reference, value).
pub fn initial_unknowns<M: FmuModel>(unknowns: &[(u32, Vec<u32>)], setup: &[(u32, f64)]) -> Probe {
    let host = Host::new();
    let mut p = Probe::default();
    // SAFETY: each instance lives within one iteration and `host` outlives it.
    unsafe {
        let run = |k: Option<&VariableSpec>| -> Option<Vec<f64>> {
            let c = host.initializing::<M>("probe");
            configure::<M>(c, setup);
            let ok = match k {
                Some(k) => {
                    let x = get::<M>(c, k.value_reference);
                    set::<M>(c, k.value_reference, perturbed(k, x)) && ffi::exit_initialization_mode::<M>(c) == OK
                }
                None => ffi::exit_initialization_mode::<M>(c) == OK,
            };
            let y = ok.then(|| unknowns.iter().map(|(u, _)| get::<M>(c, *u)).collect());
            ffi::free_instance::<M>(c);
            y
        };
        let before = run(None).expect("initialisation with the start values");
        for k in knowns::<M>(&[Causality::Input, Causality::Parameter]) {
            match run(Some(k)) {
                Some(after) => record::<M>(&mut p, unknowns, k, &before, &after),
                None => p.skipped.push(k.name.to_string()),
            }
        }
    }
    p
}

/// Both probes of `M` from the values `setup` ([`outputs`] after `steps` steps of `h`,
/// [`initial_unknowns`]),
/// each asserted to hold ([`Probe::assert_holds`]); a summary on stderr.
pub fn check<M: FmuModel>(
    outputs_declared: &[(u32, Vec<u32>)],
    initial_declared: &[(u32, Vec<u32>)],
    setup: &[(u32, f64)],
    steps: usize,
    h: f64,
) -> (Probe, Probe) {
    let o = outputs::<M>(outputs_declared, setup, steps, h);
    let i = initial_unknowns::<M>(initial_declared, setup);
    for (what, p) in [("Outputs", &o), ("InitialUnknowns", &i)] {
        eprintln!(
            "{} {what}: {} knowns probed ({} refused), {} declared pairs, {} seen real, {} undeclared",
            M::MODEL_IDENTIFIER,
            p.probed.len(),
            p.skipped.len(),
            p.declared,
            p.confirmed.len(),
            p.undeclared.len()
        );
    }
    o.assert_holds(&format!("{} Outputs", M::MODEL_IDENTIFIER));
    i.assert_holds(&format!("{} InitialUnknowns", M::MODEL_IDENTIFIER));
    (o, i)
}
