//! `tailsitter_lqr`: the gain-scheduled LQR controller of thesis chapter 3
//! ([`lqr_control::LqrController`]) bound to the generic FMI 2.0 Co-Simulation export
//! layer through the one adapter of every co-simulation unit ([`controller_fmu::UnitFmu`]).
//! Only the parameters live here; the variables are declared in
//! `modelDescription/tailsitter_lqr.json`, the ports in its controller-interface
//! fragment, and timing, state and messages in `controller-fmu` (docs/DESIGN.md §2).

use lqr_control::{LqrConfig, LqrController};

/// Generated from the declaration: `Variables`, `vr`, `GUID`, `MODEL_IDENTIFIER`, `MODEL_DESCRIPTION_XML`.
#[allow(clippy::all)]
mod generated {
    include!(concat!(env!("OUT_DIR"), "/variables.rs"));
}
pub use generated::{vr, Variables, GUID, MODEL_DESCRIPTION_XML, MODEL_IDENTIFIER};

// The design model (parameter group `design_airframe`, default = the plant's nominal
// airframe) is the controller's model of the aircraft; it may differ from the plant's.
controller_fmu::flight_controller_binding!(Lqr, LqrController, "LQR", |vars| LqrConfig {
    airframe: vars.design_airframe(),
    mission: vars.mission(),
    params: vars.lqr(),
    weights_file: vars.weights_file.clone(),
});

/// One controller instance.
pub type LqrModel = controller_fmu::UnitFmu<Lqr>;

fmi2_export::export_fmu!(LqrModel);
// The same model as an FMI 3.0 FMU (fmi3* symbols; dist/fmi3/<id>.fmu).
fmi3_export::export_fmu3!(LqrModel);
