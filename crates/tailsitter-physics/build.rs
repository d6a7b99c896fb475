//! Generates from the plant's declaration (`modelDescription/tailsitter_plant.json`,
//! the single source of every parameter, default and port name) into `OUT_DIR`:
//! - `airframe_generated.rs`: `impl Default for Airframe` (the declared start values)
//!   and `Airframe::named_values` (group `airframe`, table `model_description::defaults::CRATES`),
//!   likewise `Ground`, `GlobalAero` and `Site` (from `fragments/site.json`);
//! - `input_names.rs`: `INPUT_NAMES`, the plant's command inputs (group `command`).

use std::path::PathBuf;

fn main() {
    let manifest = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").expect("set by cargo"));
    let out = PathBuf::from(std::env::var("OUT_DIR").expect("set by cargo"));
    let dir = manifest.join("../../modelDescription");
    let file = "tailsitter_plant.json";
    let (decls, sources) =
        model_description::load_declarations(&dir, file).unwrap_or_else(|e| panic!("declaration {file}: {e}"));
    model_description::defaults::build();
    let names = model_description::rust::group_names(
        &decls,
        "command",
        "INPUT_NAMES",
        "Input names (the plant's command inputs), by index; generated from the declaration.",
    );
    std::fs::write(out.join("input_names.rs"), names).expect("write input_names.rs");
    for s in sources {
        println!("cargo:rerun-if-changed={}", s.display());
    }
    println!("cargo:rerun-if-changed=build.rs");
}
