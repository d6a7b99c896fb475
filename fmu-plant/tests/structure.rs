//! The ModelStructure declared in modelDescription.xml (Outputs and InitialUnknowns with
//! their dependencies, generated from the declaration) holds for the real model: probed
//! by finite differences through the C ABI (fmi2_export::structure_probe).

use std::path::Path;
use tailsitter_plant::PlantModel;

#[test]
fn declared_dependencies_hold() {
    let id = tailsitter_plant::MODEL_IDENTIFIER;
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../modelDescription");
    let model = model_description::load(&dir, id, "0").unwrap();
    let (out_decl, init_decl) = model.structure_refs();
    let (outputs, initial) = fmi2_export::structure_probe::check::<PlantModel>(&out_decl, &init_decl, &[], 25, 0.02);

    // The plant: its initial outputs read no command input; the wind feeds through.
    let read = initial.confirmed_knowns();
    assert!(["wind_n", "wind_e", "wind_d"].iter().any(|k| read.contains(k)));
    assert!(outputs
        .confirmed
        .iter()
        .any(|(o, i)| o == "airspeed" && i.starts_with("wind")));
}

/// Derivatives and Outputs against the knowns of Continuous-Time Mode (Model Exchange):
/// each continuous state and each input perturbed in turn, the derivatives and Real
/// outputs read again. A value that changes must declare the state or input.
#[test]
fn declared_derivative_and_output_dependencies_hold_in_model_exchange() {
    use fmi2_export::fmi_sys::fmi2::*;
    use fmi2_export::{ffi, Causality as C, ValueType, VariableStore};
    use std::ffi::CString;
    use tailsitter_plant::Variables;
    const OK: fmi2Status = fmi2Status_fmi2OK;
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../modelDescription");
    let model = model_description::load(&dir, tailsitter_plant::MODEL_IDENTIFIER, "0").unwrap();
    let name = |i: usize| model.variables[i - 1].name().to_string();
    // (unknown vr, unknown name, declared knowns by name)
    let mut unknowns: Vec<(u32, String, Vec<String>)> = Vec::new();
    let derivatives = model.continuous_states().into_iter().map(|(_, d)| d);
    let outputs = model
        .outputs()
        .into_iter()
        .filter(|v| v.decl.var_type == model_description::VarType::Real);
    for v in derivatives.chain(outputs) {
        let deps = model.dependencies(v).into_iter().map(name).collect();
        unknowns.push((v.value_reference, v.name().to_string(), deps));
    }
    let states: Vec<String> = model
        .continuous_states()
        .iter()
        .map(|(s, _)| s.name().to_string())
        .collect();
    let inputs: Vec<(u32, String)> = Variables::VARIABLES
        .iter()
        .filter(|s| s.causality == C::Input && s.value_type == ValueType::Real)
        .map(|s| (s.value_reference, s.name.to_string()))
        .collect();
    let host = fmi2_export::test_host::Host::new();
    let (mut undeclared, mut confirmed, mut declared) = (Vec::new(), 0, 0);
    // SAFETY: one instance, freed at the end; `host` outlives it; buffers of the stated lengths.
    unsafe {
        let iname = CString::new("probe_me").unwrap();
        let guid = CString::new(tailsitter_plant::GUID).unwrap();
        let me = fmi2Type_fmi2ModelExchange;
        let c = ffi::instantiate::<PlantModel>(
            iname.as_ptr(),
            me,
            guid.as_ptr(),
            std::ptr::null(),
            &*host.callbacks,
            0,
            0,
        );
        assert!(!c.is_null());
        assert_eq!(ffi::setup_experiment::<PlantModel>(c, 0, 0.0, 0.0, 0, 0.0), OK);
        assert_eq!(ffi::enter_initialization_mode::<PlantModel>(c), OK);
        assert_eq!(ffi::exit_initialization_mode::<PlantModel>(c), OK);
        let mut info: fmi2EventInfo = std::mem::zeroed();
        assert_eq!(ffi::new_discrete_states::<PlantModel>(c, &mut info), OK);
        assert_eq!(ffi::enter_continuous_time_mode::<PlantModel>(c), OK);
        let n = states.len();
        let mut x0 = vec![0.0; n];
        assert_eq!(ffi::get_continuous_states::<PlantModel>(c, x0.as_mut_ptr(), n), OK);
        let read = |c| -> Vec<f64> {
            let mut dx = vec![0.0; n];
            assert_eq!(ffi::get_derivatives::<PlantModel>(c, dx.as_mut_ptr(), n), OK);
            let mut y = Vec::new();
            for (vr, _, _) in &unknowns[n..] {
                let mut v = 0.0;
                assert_eq!(ffi::get_real::<PlantModel>(c, vr, 1, &mut v), OK);
                y.push(v);
            }
            dx.extend(y);
            dx
        };
        let before = read(c);
        let mut compare = |known: &str, after: &[f64]| {
            for ((_, u, deps), (y0, y1)) in unknowns.iter().zip(before.iter().zip(after)) {
                let is_declared = deps.iter().any(|d| d == known);
                declared += usize::from(is_declared);
                if y0.to_bits() != y1.to_bits() {
                    if is_declared {
                        confirmed += 1;
                    } else {
                        undeclared.push((u.clone(), known.to_string(), *y0, *y1));
                    }
                }
            }
        };
        for (j, s) in states.iter().enumerate() {
            let mut x = x0.clone();
            x[j] += 0.01 * x[j].abs().max(1.0);
            assert_eq!(ffi::set_continuous_states::<PlantModel>(c, x.as_ptr(), n), OK);
            compare(s, &read(c));
        }
        assert_eq!(ffi::set_continuous_states::<PlantModel>(c, x0.as_ptr(), n), OK);
        for (vr, i) in &inputs {
            let mut u = 0.0;
            assert_eq!(ffi::get_real::<PlantModel>(c, vr, 1, &mut u), OK);
            let p = u + 0.01 * u.abs().max(1.0);
            assert_eq!(ffi::set_real::<PlantModel>(c, vr, 1, &p), OK);
            compare(i, &read(c));
            assert_eq!(ffi::set_real::<PlantModel>(c, vr, 1, &u), OK);
        }
        assert_eq!(read(c), before, "restoring the states and inputs restores every value");
        ffi::free_instance::<PlantModel>(c);
    }
    eprintln!(
        "tailsitter_plant Derivatives+Outputs (ME): {} states and {} inputs probed, {declared} declared pairs, {confirmed} seen real, {} undeclared",
        states.len(),
        inputs.len(),
        undeclared.len()
    );
    assert!(
        undeclared.is_empty(),
        "undeclared (unknown, known, before, after): {undeclared:#?}"
    );
    assert!(confirmed > 0);
}
