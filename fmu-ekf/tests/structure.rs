//! The ModelStructure declared in modelDescription.xml (Outputs and InitialUnknowns with
//! their dependencies, generated from the declaration) holds for the real model: probed
//! by finite differences through the C ABI (fmi2_export::structure_probe).

use std::path::Path;
use tailsitter_ekf::EkfModel;

#[test]
fn declared_dependencies_hold() {
    let id = tailsitter_ekf::MODEL_IDENTIFIER;
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../modelDescription");
    let model = model_description::load(&dir, id, "0").unwrap();
    let (out_decl, init_decl) = model.structure_refs();
    let (outputs, initial) = fmi2_export::structure_probe::check::<EkfModel>(&out_decl, &init_decl, &[], 25, 0.02);

    // A sampled unit: its outputs after initialisation hold the value computed from the
    // inputs set in Initialization Mode, as declared (initialDependsOnInputs).
    let read = initial.confirmed_knowns();
    assert!(
        model.initial_inputs.iter().any(|i| read.contains(i.as_str())),
        "no input of {id} declared in initialDependsOnInputs changes its initial outputs"
    );
    // No direct feedthrough after initialisation: no output declares an input.
    assert_eq!(outputs.declared, 0);
    // The initial outputs depend on no command (the actuators start at their parameters):
    // none is declared, every command was perturbed and changed none (else `check` fails
    // on an undeclared dependency), so an importer sees no initialisation loop through the
    // controller.
    let commands: Vec<_> = model
        .variables
        .iter()
        .filter(|v| {
            v.decl.causality == model_description::Causality::Input && v.decl.group.as_deref() == Some("commands")
        })
        .map(|v| v.decl.name.as_str())
        .collect();
    assert_eq!(commands.len(), 7);
    for c in &commands {
        assert!(!model.initial_inputs.iter().any(|i| i == c), "{c} declared");
        assert!(initial.probed.iter().any(|p| p == c), "{c} not probed");
        assert!(!read.contains(c), "{c} confirmed");
    }
    let vr = |n: &str| {
        model
            .variables
            .iter()
            .find(|v| v.decl.name == n)
            .unwrap()
            .value_reference
    };
    assert!(init_decl
        .iter()
        .all(|(_, deps)| commands.iter().all(|c| !deps.contains(&vr(c)))));
    // The actuators' start parameters are real dependencies of the initial thrust and elevator.
    for p in ["init_thrust", "init_elevator"] {
        assert!(read.contains(p), "{p} changes no initial output");
    }
}
