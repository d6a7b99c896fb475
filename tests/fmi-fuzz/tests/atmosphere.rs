//! The short deterministic fuzz run over the atmosphere FMU (`tailsitter_atmosphere`,
//! target/release, built by `cargo xtask dist --only tailsitter_atmosphere`): random FMI
//! call sequences keep every invariant of the other FMUs' run.

use fmi_fuzz::fuzz::{Config, Fuzzer};
use fmi_fuzz::Fmu;

#[test]
fn random_call_sequences_on_the_atmosphere_fmu_keep_every_invariant() {
    let fmus = vec![Fmu::load("tailsitter_atmosphere").unwrap_or_else(|e| panic!("{e}"))];
    let seed = 20_261_123;
    let cfg = Config {
        seed,
        sequences: 1500,
        deadline: None,
        max_calls: 40,
        per_fmu_cap: Default::default(),
        ..Default::default()
    };
    let report = Fuzzer::new(&fmus, seed).run(&cfg);
    report.print();
    assert_eq!(report.violations, 0, "invariant violations (see output)");
    assert_eq!(report.reset_checks, report.sequences);
    assert!(
        report.restore_checks > report.sequences / 2,
        "restore checks {}",
        report.restore_checks
    );
    // The atmosphere has no envelope to leave: finite random inputs never fail a step, so
    // StepFailed is not required here.
    for must in [
        "fmi2DoStep @ StepComplete",
        "fmi2SetFMUstate @ StepComplete",
        "fmi2DeSerializeFMUstate @ Terminated",
        "fmi2Reset @ StepComplete",
    ] {
        assert!(report.coverage.contains_key(must), "{must} never exercised");
    }
}
