//! The short deterministic fuzz runs over the FMUs with no envelope to leave, the
//! atmosphere (`tailsitter_atmosphere`) and the sensors (`tailsitter_sensors`),
//! target/x86_64-unknown-linux-gnu/release, built by `cargo xtask dist --only <id>`: random FMI call sequences
//! keep every invariant of the other FMUs' run.

use fmi_fuzz::fuzz::{Config, Fuzzer};
use fmi_fuzz::Fmu;

/// 1500 sequences over `id` alone. StepFailed is not required: the atmosphere's finite
/// random inputs never fail a step, the sensors' rarely do (only an impossible
/// quaternion), unlike the plant's.
fn run(id: &str) {
    let fmus = vec![Fmu::load(id).unwrap_or_else(|e| panic!("{e}"))];
    let seed = 20_261_123;
    let cfg = Config {
        seed,
        sequences: 1500,
        ..Default::default()
    };
    let report = Fuzzer::new(&fmus, seed).run(&cfg);
    report.print();
    report.assert_sound();
    report.assert_covers(&[
        "fmi2DoStep @ StepComplete",
        "fmi2SetFMUstate @ StepComplete",
        "fmi2DeSerializeFMUstate @ Terminated",
        "fmi2Reset @ StepComplete",
    ]);
}

#[test]
fn random_call_sequences_on_the_atmosphere_fmu_keep_every_invariant() {
    run("tailsitter_atmosphere");
}

#[test]
fn random_call_sequences_on_the_sensor_fmu_keep_every_invariant() {
    run("tailsitter_sensors");
}
