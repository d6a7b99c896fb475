//! The Rust parameter defaults come from the declarations only: the reviewed copies in
//! `generated/` have not drifted, every declared parameter group's type is generated, and
//! no generated type has a hand-written (or derived) `Default` in its crate.

use model_description::defaults::{generate, CrateDefaults, CRATES};
use model_description::{load, Causality};
use std::path::{Path, PathBuf};

fn dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).to_path_buf()
}

#[test]
fn reviewed_defaults_match_generated() {
    for c in CRATES {
        let (text, _) = generate(&dir(), c).unwrap();
        let path = dir().join("generated").join(c.out);
        let reviewed = std::fs::read_to_string(&path)
            .unwrap_or_else(|e| panic!("{}: {e} (run `cargo xtask regen`)", path.display()));
        assert!(reviewed == text, "{} is stale: run `cargo xtask regen`", path.display());
    }
}

#[test]
fn every_declared_parameter_group_type_is_generated() {
    for id in [
        "tailsitter_plant",
        "tailsitter_lqr",
        "tailsitter_tsd",
        "tailsitter_sensors",
        "tailsitter_ekf",
    ] {
        let model = load(&dir(), id, "0").unwrap();
        for (group, path) in &model.groups {
            let parameters = model
                .variables
                .iter()
                .any(|v| v.decl.group.as_deref() == Some(group.as_str()) && v.decl.causality == Causality::Parameter);
            if !parameters {
                continue;
            }
            let (ty, from_default) = model_description::group_type(path);
            let krate = ty.split("::").next().unwrap().replace('_', "-");
            let name = ty.rsplit("::").next().unwrap().trim();
            // A `{ ..Default::default() }` group type may derive its Default from generated parts.
            let generated = CRATES.iter().filter(|c| c.krate == krate).any(|c| {
                c.structs
                    .iter()
                    .any(|s| s.type_name == name || (from_default && s.group == group.as_str()))
            });
            assert!(
                generated,
                "{id}: group '{group}' ({path}) has no generated defaults in defaults::CRATES"
            );
        }
    }
}

/// Every `.rs` file below `dir`.
fn sources(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display())) {
        let path = entry.unwrap().path();
        if path.is_dir() {
            sources(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// Hand-written `impl Default for <type_name>` or `#[derive(.., Default, ..)]` on
/// `struct <type_name>` in `text`: the lines found.
fn hand_written_default(text: &str, type_name: &str) -> Vec<String> {
    let mut found = Vec::new();
    let lines: Vec<&str> = text.lines().collect();
    for (i, line) in lines.iter().enumerate() {
        let code = line.split("//").next().unwrap();
        let words: Vec<&str> = code
            .split(|c: char| !(c.is_alphanumeric() || c == '_'))
            .filter(|w| !w.is_empty())
            .collect();
        let implements = words.windows(4).any(|w| w == ["impl", "Default", "for", type_name]);
        let declares = words.windows(2).any(|w| w == ["struct", type_name]);
        let derived = declares
            && lines[..i]
                .iter()
                .rev()
                .take_while(|l| l.trim_start().starts_with("#[") || l.trim_start().starts_with("///"))
                .any(|l| l.contains("derive(") && l.contains("Default"));
        if implements || derived {
            found.push(format!("{}: {}", i + 1, line.trim()));
        }
    }
    found
}

fn crate_sources(c: &CrateDefaults) -> Vec<PathBuf> {
    let mut files = Vec::new();
    sources(&dir().join("../crates").join(c.krate).join("src"), &mut files);
    assert!(!files.is_empty(), "no sources of {}", c.krate);
    files
}

#[test]
fn no_hand_written_default_for_a_generated_type() {
    let mut offences = Vec::new();
    for c in CRATES {
        for file in crate_sources(c) {
            let text = std::fs::read_to_string(&file).unwrap();
            for s in c.structs {
                for hit in hand_written_default(&text, s.type_name) {
                    offences.push(format!("{}:{hit}", file.display()));
                }
            }
        }
    }
    assert!(
        offences.is_empty(),
        "declared parameter types take their Default from the declarations (build.rs, \
         model_description::defaults::CRATES), not from hand-written code:\n{}",
        offences.join("\n")
    );
}

#[test]
fn the_scan_finds_hand_written_defaults() {
    let text = "/// Doc.\n#[derive(Debug, Clone, Default)]\npub struct LqrParams {\n}\nimpl Default for TsdParams {\n";
    assert_eq!(hand_written_default(text, "LqrParams").len(), 1);
    assert_eq!(hand_written_default(text, "TsdParams").len(), 1);
    assert!(hand_written_default("// impl Default for Earth {\n", "Earth").is_empty());
    assert!(hand_written_default("impl Default for EarthModel {\n", "Earth").is_empty());
}
