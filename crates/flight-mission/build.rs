//! Generates from `modelDescription/fragments/controller_interface.json`, the
//! single source of the controller ports and the mission parameters:
//! - `OUT_DIR/mission_generated.rs`: `impl Default for MissionParams` and
//!   `MissionParams::named_values` (group `mission`, table
//!   `model_description::defaults::CRATES`);
//! - `OUT_DIR/presets_generated.rs`: `PRESETS`, the named missions (`presets`);
//! - `OUT_DIR/measurement_generated.rs`: `Measurement::named_values` and `first_non_finite`, naming
//!   the port of a non-finite value (group `measurement`).

use std::path::PathBuf;

fn main() {
    let manifest = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").expect("set by cargo"));
    let out = PathBuf::from(std::env::var("OUT_DIR").expect("set by cargo"));
    let dir = manifest.join("../../modelDescription");
    let file = "fragments/controller_interface.json";
    let (decls, sources) =
        model_description::load_declarations(&dir, file).unwrap_or_else(|e| panic!("declaration {file}: {e}"));
    model_description::defaults::build();
    let check = model_description::rust::group_first_non_finite(
        &decls,
        "measurement",
        "Measurement",
        &format!("modelDescription/{file}"),
    );
    std::fs::write(out.join("measurement_generated.rs"), check).expect("write measurement_generated.rs");
    let presets = model_description::load_presets(&dir).unwrap_or_else(|e| panic!("mission presets: {e}"));
    let text = model_description::rust::mission_presets(&presets, &format!("modelDescription/{file}"));
    std::fs::write(out.join("presets_generated.rs"), text).expect("write presets_generated.rs");
    for s in sources {
        println!("cargo:rerun-if-changed={}", s.display());
    }
    println!("cargo:rerun-if-changed=build.rs");
}
