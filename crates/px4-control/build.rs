//! Generates `impl Default` of this crate's declared parameter structs into `OUT_DIR`
//! from the declarations' start values (table `model_description::defaults::CRATES`).

fn main() {
    model_description::defaults::build();
    println!("cargo:rerun-if-changed=build.rs");
}
