//! The GUID identifies the interface: it changes when a variable's name, type,
//! causality, variability, unit or range changes (and stays the same for an
//! identical declaration), and the built library refuses any other GUID.

use fmi_fuzz::{load_required, workspace_root};
use std::path::Path;

fn copy_declarations(to: &Path) {
    let from = workspace_root().join("modelDescription");
    for sub in ["", "fragments"] {
        let dir = from.join(sub);
        let Ok(entries) = std::fs::read_dir(&dir) else { continue };
        std::fs::create_dir_all(to.join(sub)).expect("mkdir");
        for e in entries.flatten() {
            let p = e.path();
            if p.extension().is_some_and(|x| x == "json") {
                std::fs::copy(&p, to.join(sub).join(e.file_name())).expect("copy");
            }
        }
    }
}

fn guid(dir: &Path, id: &str) -> String {
    model_description::load(dir, id, env!("CARGO_PKG_VERSION"))
        .expect("declaration loads")
        .guid
}

#[test]
fn the_guid_follows_the_interface() {
    for fmu in load_required() {
        let id = &fmu.id;
        let tmp = std::env::temp_dir().join(format!("fmi-fuzz-guid-{}-{id}", std::process::id()));
        let _ = std::fs::remove_dir_all(&tmp);
        copy_declarations(&tmp);
        assert_eq!(guid(&tmp, id), fmu.guid, "{id}: same declaration, same GUID");
        let path = tmp.join(format!("{id}.json"));
        let original = std::fs::read_to_string(&path).expect("read");
        // A variable declared in this file (not in an included fragment) that no other
        // declaration names (a `dependsOn` would dangle after the rename).
        let first = fmu
            .vars
            .iter()
            .map(|v| v.name.clone())
            .find(|n| original.matches(&format!("\"{n}\"")).count() == 1)
            .expect("a variable declared in the model's own file");
        let edits: Vec<(&str, String)> = vec![
            ("rename a variable", original.replacen(&format!("\"{first}\""), &format!("\"{first}_renamed\""), 1)),
            (
                "add a variable",
                original.replacen(
                    "\"variables\": [",
                    "\"variables\": [\n    {\"name\": \"guid_probe\", \"causality\": \"input\", \"start\": 0.0, \"description\": \"probe\"},",
                    1,
                ),
            ),
        ];
        for (what, text) in edits {
            assert_ne!(text, original, "{id}: edit '{what}' did not apply");
            std::fs::write(&path, &text).expect("write");
            assert_ne!(guid(&tmp, id), fmu.guid, "{id}: GUID unchanged after '{what}'");
        }
        std::fs::remove_dir_all(&tmp).expect("cleanup");
        // And the built library checks it.
        assert!(fmu.instantiate("right", false).is_some(), "{id}: declared GUID refused");
    }
}
