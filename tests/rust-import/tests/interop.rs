//! Interoperability row "Rust `fmi` crate" of the master matrix (the fmpy and
//! libcosim rows are tests/test_interop.py): every packaged FMU in `dist/`
//! loads through rust-fmi's importer, instantiates, initialises, steps over
//! its default experiment, reads every Real, and gets/sets/serializes its FMU
//! state with bit-identical continuation. All five FMUs are required;
//! `TAILSITTER_FMUS=a,b` narrows the set while some are not built yet.

use fmi::fmi2::import::Fmi2Import;
use fmi::fmi2::instance::{CoSimulation, Common, InstanceCS};
use fmi::fmi2::schema::ScalarVariableElement;
use fmi::traits::{FmiImport, FmiStatus};
use std::path::PathBuf;

fn required() -> Vec<String> {
    match std::env::var("TAILSITTER_FMUS") {
        Ok(list) if !list.trim().is_empty() => list.split(',').map(|s| s.trim().to_string()).collect(),
        _ => [
            "tailsitter_plant",
            "tailsitter_lqr",
            "tailsitter_tsd",
            "tailsitter_sensors",
            "tailsitter_ekf",
        ]
        .map(String::from)
        .to_vec(),
    }
}

fn fmu(id: &str) -> PathBuf {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../dist")
        .join(format!("{id}.fmu"));
    assert!(p.exists(), "{} missing: run `cargo xtask dist` first", p.display());
    p
}

fn reals(inst: &mut InstanceCS, vrs: &[u32]) -> Vec<u64> {
    let mut v = vec![0.0; vrs.len()];
    Common::get_real(inst, vrs, &mut v).expect("get_real");
    v.iter().map(|x| x.to_bits()).collect()
}

fn steps(inst: &mut InstanceCS, t0: f64, h: f64, n: usize, vrs: &[u32]) -> Vec<u64> {
    let mut out = Vec::new();
    for k in 0..n {
        inst.do_step(t0 + k as f64 * h, h, true).expect("do_step");
        out.extend(reals(inst, vrs));
    }
    out
}

#[test]
fn every_fmu_runs_under_the_fmi_crate_importer() {
    let mut matrix = Vec::new();
    for id in required() {
        let import: Fmi2Import = fmi::import::from_path(fmu(&id)).expect("load FMU");
        let md = import.model_description();
        assert_eq!(md.fmi_version, "2.0");
        let h = md
            .default_experiment
            .as_ref()
            .and_then(|d| d.step_size())
            .unwrap_or(0.02);
        let real_vrs: Vec<u32> = md
            .model_variables
            .variables
            .iter()
            .filter(|v| matches!(v.elem, ScalarVariableElement::Real(_)))
            .map(|v| v.value_reference)
            .collect();
        let mut inst = import.instantiate_cs(&id, false, false).expect("instantiate");
        assert_eq!(Common::get_version(&inst), "2.0");
        Common::setup_experiment(&mut inst, None, 0.0, None).expect("setup");
        Common::enter_initialization_mode(&mut inst).expect("enter init");
        Common::exit_initialization_mode(&mut inst).expect("exit init");
        let first = steps(&mut inst, 0.0, h, 25, &real_vrs);
        assert!(
            first.iter().all(|b| f64::from_bits(*b).is_finite()),
            "{id}: non-finite value in the default experiment"
        );

        // FMU state: save at t = 25 h, continue 10 steps, restore, repeat; then via serialization.
        let t1 = 25.0 * h;
        let state = inst.get_fmu_state().expect("get state");
        let a = steps(&mut inst, t1, h, 10, &real_vrs);
        assert!(inst.set_fmu_state(&state).ok().is_ok(), "{id}: set state");
        let b = steps(&mut inst, t1, h, 10, &real_vrs);
        let bytes = inst.serialize_fmu_state(&state).expect("serialize");
        let restored = inst.deserialize_fmu_state(&bytes).expect("deserialize");
        assert!(
            inst.set_fmu_state(&restored).ok().is_ok(),
            "{id}: set deserialized state"
        );
        let c = steps(&mut inst, t1, h, 10, &real_vrs);
        assert_eq!(a, b, "{id}: continuation after fmi2SetFMUstate differs");
        assert_eq!(a, c, "{id}: continuation after de-serialization differs");

        // Reset and a second run: identical to the first.
        Common::reset(&mut inst).expect("reset");
        Common::setup_experiment(&mut inst, None, 0.0, None).expect("setup");
        Common::enter_initialization_mode(&mut inst).expect("enter init");
        Common::exit_initialization_mode(&mut inst).expect("exit init");
        assert_eq!(
            steps(&mut inst, 0.0, h, 25, &real_vrs),
            first,
            "{id}: run after reset differs"
        );
        Common::terminate(&mut inst).expect("terminate");
        matrix.push(format!(
            "{id:<18} fmi crate 0.8: instantiate ✓ initialise ✓ step ✓ get/set state ✓ serialize ✓ reset ✓ ({} bytes of state)",
            bytes.len()
        ));
    }
    println!("{}", matrix.join("\n"));
}
