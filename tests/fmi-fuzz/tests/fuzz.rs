//! The short deterministic fuzz run of the test suite: a fixed seed and a fixed
//! number of random FMI call sequences over every FMU library (target/x86_64-unknown-linux-gnu/release,
//! built by `cargo xtask dist`). `FMI_FUZZ_SEQUENCES` / `FMI_FUZZ_LQR_SEQUENCES` /
//! `FMI_FUZZ_SEED` override;
//! the long run is `cargo run --release -p fmi-fuzz -- fuzz --seconds N`.

use fmi_fuzz::fuzz::{Config, Fuzzer};
use fmi_fuzz::{load_required, required_models, STEP_CAN_FAIL};
use std::time::Instant;

fn env<T: std::str::FromStr>(name: &str, default: T) -> T {
    std::env::var(name).ok().and_then(|v| v.parse().ok()).unwrap_or(default)
}

#[test]
fn random_call_sequences_keep_every_invariant() {
    let fmus = load_required();
    let seed = env("FMI_FUZZ_SEED", 20_240_607u64);
    let cfg = Config {
        seed,
        sequences: env("FMI_FUZZ_SEQUENCES", 2700),
        deadline: None,
        max_calls: 40,
        // ~0.1 s per LQR sequence (its initialisation builds the trajectory and gains, ~40 ms).
        per_fmu_cap: [("tailsitter_lqr".to_string(), env("FMI_FUZZ_LQR_SEQUENCES", 120))].into(),
        ..Default::default()
    };
    let t0 = Instant::now();
    let report = Fuzzer::new(&fmus, seed).run(&cfg);
    println!("{:.1} s", t0.elapsed().as_secs_f64());
    report.print();
    let (pairs, _) = report.coverage_summary();
    report.assert_sound();
    assert!(pairs > 150, "only {pairs} (function, state) pairs covered");
    let mut must = vec!["fmi2DoStep @ StepComplete", "fmi2DeSerializeFMUstate @ Terminated"];
    // StepFailed only where a model under test can fail a step (per model, not forced).
    if required_models().iter().any(|m| STEP_CAN_FAIL.contains(&m.as_str())) {
        must.push("fmi2SetFMUstate @ StepFailed");
    }
    report.assert_covers(&must);
    // Model Exchange instances of the plant (the only ME model): the ME calls ran legally
    // (some OK) in the ME states, and illegally elsewhere.
    if !required_models().iter().any(|m| m == "tailsitter_plant") {
        return;
    }
    // A run over the plant alone: with five FMUs sharing the sequences, the few plant
    // sequences that instantiate Model Exchange rarely reach ContinuousTimeMode.
    let plant: Vec<_> = fmus.into_iter().filter(|f| f.id == "tailsitter_plant").collect();
    let me_cfg = Config {
        seed,
        sequences: env("FMI_FUZZ_ME_SEQUENCES", 3000),
        ..Default::default()
    };
    let report = Fuzzer::new(&plant, seed).run(&me_cfg);
    report.print();
    assert_eq!(
        report.violations, 0,
        "invariant violations in the plant-only run (see output)"
    );
    for must in [
        "fmi2SetContinuousStates @ ME ContinuousTimeMode",
        "fmi2GetDerivatives @ ME ContinuousTimeMode",
        "fmi2EnterContinuousTimeMode @ ME EventMode",
        "fmi2NewDiscreteStates @ ME EventMode",
        "fmi2GetNominalsOfContinuousStates @ ME Instantiated",
    ] {
        let ok = report.coverage.get(must).map_or(0, |c| c[0]);
        assert!(ok > 0, "{must}: never returned fmi2OK");
    }
    assert!(report.coverage.contains_key("fmi2SetContinuousStates @ ME EventMode"));
}
