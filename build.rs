//! Shared build script of the `fmu-*` crates (`build = "../build.rs"` in each).
//!
//! Reads the crate's variable declaration `modelDescription/tailsitter_<name>.json`
//! (for crate `fmu-<name>`) and writes into `OUT_DIR`
//! - `variables.rs`: the Rust accessors (`include!`d by the crate),
//! - `modelDescription.xml`: the model description (embedded via `include_str!`).
//!
//! The packager (`cargo xtask dist`) writes the same XML into the `.fmu`, and a
//! test compares both with the reviewed copy in `modelDescription/generated/`.

use std::path::PathBuf;

fn main() {
    let manifest = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").expect("set by cargo"));
    let package = std::env::var("CARGO_PKG_NAME").expect("set by cargo");
    let version = std::env::var("CARGO_PKG_VERSION").expect("set by cargo");
    let out = PathBuf::from(std::env::var("OUT_DIR").expect("set by cargo"));
    let short = package
        .strip_prefix("fmu-")
        .expect("build.rs serves the fmu-* crates only");
    let model_identifier = format!("tailsitter_{short}");
    let declarations = manifest
        .parent()
        .expect("crate inside the workspace")
        .join("modelDescription");

    let model = match model_description::load(&declarations, &model_identifier, &version) {
        Ok(m) => m,
        Err(e) => panic!("variable declaration of {model_identifier}: {e}"),
    };
    let xml_path = out.join("modelDescription.xml");
    std::fs::write(&xml_path, model_description::xml::model_description(&model)).expect("write XML");
    let rust = model_description::rust::variables_module(&model, &xml_path.to_string_lossy());
    std::fs::write(out.join("variables.rs"), rust).expect("write variables.rs");

    println!("cargo:rerun-if-changed=../build.rs");
    for source in &model.sources {
        println!("cargo:rerun-if-changed={}", source.display());
    }
}
