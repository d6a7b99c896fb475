//! Generates `OUT_DIR/params_generated.rs`: `impl Default for Params` with the start
//! values of group `params` of `modelDescription/tailsitter_atmosphere.json`, the
//! single source of the parameters' defaults.

use std::path::PathBuf;

fn main() {
    let manifest = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").expect("set by cargo"));
    let out = PathBuf::from(std::env::var("OUT_DIR").expect("set by cargo"));
    let dir = manifest.join("../../modelDescription");
    let file = "tailsitter_atmosphere.json";
    let (decls, sources) =
        model_description::load_declarations(&dir, file).unwrap_or_else(|e| panic!("declaration {file}: {e}"));
    let text = model_description::rust::group_defaults(&decls, "params", "Params", &format!("modelDescription/{file}"));
    std::fs::write(out.join("params_generated.rs"), text).expect("write params_generated.rs");
    for s in sources {
        println!("cargo:rerun-if-changed={}", s.display());
    }
    println!("cargo:rerun-if-changed=build.rs");
}
