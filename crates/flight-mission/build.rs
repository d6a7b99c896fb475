//! Generates `impl Default for MissionParams` and `MissionParams::named_values`
//! into `OUT_DIR/mission_generated.rs` from the `mission` group of
//! `modelDescription/fragments/controller_interface.json`, the single source of
//! the mission parameters' names and defaults.

use std::path::PathBuf;

fn main() {
    let manifest = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").expect("set by cargo"));
    let out = PathBuf::from(std::env::var("OUT_DIR").expect("set by cargo"));
    let dir = manifest.join("../../modelDescription");
    let file = "fragments/controller_interface.json";
    let (decls, sources) =
        model_description::load_declarations(&dir, file).unwrap_or_else(|e| panic!("declaration {file}: {e}"));
    let text = model_description::rust::group_defaults(
        &decls,
        "mission",
        "MissionParams",
        &format!("modelDescription/{file}"),
    );
    std::fs::write(out.join("mission_generated.rs"), text).expect("write mission_generated.rs");
    for s in sources {
        println!("cargo:rerun-if-changed={}", s.display());
    }
    println!("cargo:rerun-if-changed=build.rs");
}
