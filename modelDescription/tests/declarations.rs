//! The declarations load, the generated XML reads back through fmi-schema with
//! every attribute intact, the reviewed copies in `generated/` have not drifted,
//! and malformed declarations are rejected with a message naming the variable.

use fmi_schema::fmi2::{
    Causality as XCausality, Fmi2ModelDescription, ScalarVariableElement, Variability as XVariability,
};
use model_description::{load, xml::model_description, Causality, Start, VarType};
use std::path::{Path, PathBuf};

fn dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).to_path_buf()
}

/// Every model declaration in the folder (files with a modelIdentifier).
fn model_ids() -> Vec<String> {
    let mut ids: Vec<String> = std::fs::read_dir(dir())
        .unwrap()
        .filter_map(|e| {
            let p = e.unwrap().path();
            (p.extension()? == "json").then(|| p.file_stem().unwrap().to_string_lossy().into_owned())
        })
        .collect();
    ids.sort();
    assert!(
        ids.contains(&"tailsitter_plant".to_string()),
        "plant declaration missing: {ids:?}"
    );
    ids
}

#[test]
fn reviewed_xml_matches_generated() {
    for id in model_ids() {
        let model = load(&dir(), &id, env!("CARGO_PKG_VERSION")).unwrap();
        let generated = model_description(&model);
        let path = dir().join("generated").join(format!("{id}.xml"));
        let reviewed = std::fs::read_to_string(&path)
            .unwrap_or_else(|e| panic!("{}: {e} (run `cargo xtask regen`)", path.display()));
        assert!(
            generated == reviewed,
            "{} drifted from its declaration: run `cargo xtask regen` and review the diff",
            path.display()
        );
        let md = model_description::html::variable_reference_markdown(&model);
        let path = dir().join("generated").join(format!("{id}.md"));
        let reviewed = std::fs::read_to_string(&path)
            .unwrap_or_else(|e| panic!("{}: {e} (run `cargo xtask regen`)", path.display()));
        assert!(
            md == reviewed,
            "{} drifted from its declaration: run `cargo xtask regen`",
            path.display()
        );
    }
}

#[test]
fn xml_round_trips_through_fmi_schema() {
    for id in model_ids() {
        let model = load(&dir(), &id, env!("CARGO_PKG_VERSION")).unwrap();
        let xml = model_description(&model);
        let md: Fmi2ModelDescription = fmi_schema::deserialize(&xml).unwrap_or_else(|e| panic!("{id}: {e:?}"));
        assert_eq!(md.fmi_version, "2.0");
        assert_eq!(md.guid, model.guid);
        let cs = md.co_simulation.as_ref().expect("CoSimulation element");
        assert_eq!(cs.model_identifier, id);
        assert_eq!(cs.can_handle_variable_communication_step_size, Some(true));
        let vars: Vec<_> = md.get_model_variables().collect();
        assert_eq!(vars.len(), model.variables.len());
        for (x, v) in vars.iter().zip(&model.variables) {
            let d = &v.decl;
            assert_eq!(x.name, d.name);
            assert_eq!(x.value_reference, v.value_reference);
            assert_eq!(x.description.as_deref(), Some(d.description.as_str()));
            let causality = match d.causality {
                Causality::Parameter => XCausality::Parameter,
                Causality::CalculatedParameter => XCausality::CalculatedParameter,
                Causality::Input => XCausality::Input,
                Causality::Output => XCausality::Output,
                Causality::Local => XCausality::Local,
            };
            assert_eq!(x.causality, causality, "{}", d.name);
            let variability = x.variability.expect("variability written");
            assert_eq!(
                format!("{variability:?}").to_lowercase(),
                v.variability.as_str().to_lowercase(),
                "{}",
                d.name
            );
            let _ = XVariability::Continuous;
            match (&x.elem, d.var_type, &d.start) {
                (ScalarVariableElement::Real(real), VarType::Real, start) => {
                    let want = match start {
                        Some(Start::Number(s)) => Some(*s),
                        _ => None,
                    };
                    assert_eq!(real.start, want, "{}", d.name);
                }
                (ScalarVariableElement::Integer(i), VarType::Integer, start) => {
                    let want = match start {
                        Some(Start::Number(s)) => Some(*s as i32),
                        _ => None,
                    };
                    assert_eq!(i.start, want, "{}", d.name);
                }
                (ScalarVariableElement::Boolean(_), VarType::Boolean, _)
                | (ScalarVariableElement::String, VarType::String, _) => {}
                (elem, t, _) => panic!("{}: element {elem:?} for type {t:?}", d.name),
            }
        }
        let outputs = &md.model_structure.outputs.unknowns;
        let n_out = model
            .variables
            .iter()
            .filter(|v| v.decl.causality == Causality::Output)
            .count();
        assert_eq!(outputs.len(), n_out);
    }
}

#[test]
fn units_and_display_units_are_declared() {
    let model = load(&dir(), "tailsitter_plant", "0").unwrap();
    let xml = model_description(&model);
    for unit in ["\"rad\"", "\"m/s\"", "\"N\"", "\"kg.m2\""] {
        assert!(xml.contains(&format!("<Unit name={unit}>")), "unit {unit} missing");
    }
    assert!(xml.contains("<DisplayUnit name=\"deg\" factor=\"57.29577951308232\"/>"));
    let alpha = model.variables.iter().find(|v| v.name() == "alpha").unwrap();
    assert_eq!(alpha.display_unit.as_deref(), Some("deg"));
}

#[test]
fn guid_changes_with_the_interface() {
    let a = load(&dir(), "tailsitter_plant", "1.0.0").unwrap();
    let b = load(&dir(), "tailsitter_plant", "1.0.1").unwrap();
    assert_ne!(a.guid, b.guid);
    assert_eq!(
        a.guid,
        load(&dir(), "tailsitter_plant", "1.0.0").unwrap().guid,
        "GUID must be deterministic"
    );
}

fn load_text(json: &str) -> Result<model_description::Model, String> {
    let tmp = std::env::temp_dir().join(format!("decl-test-{}-{}", std::process::id(), json.len()));
    std::fs::create_dir_all(&tmp).unwrap();
    std::fs::write(tmp.join("m.json"), json).unwrap();
    let r = load(&tmp, "m", "0").map_err(|e| e.to_string());
    let _ = std::fs::remove_dir_all(&tmp);
    r
}

fn decl(vars: &str) -> String {
    format!(
        r#"{{"modelIdentifier":"m","defaultExperiment":{{"startTime":0,"stopTime":1,"stepSize":0.1}},"variables":[{vars}]}}"#
    )
}

#[test]
fn malformed_declarations_are_rejected() {
    let ok = r#"{"name":"a","causality":"parameter","start":1.0,"description":"d"}"#;
    assert!(load_text(&decl(ok)).is_ok());
    let cases = [
        (format!("{ok},{ok}"), "declared twice"),
        (
            r#"{"name":"a","causality":"parameter","description":"d"}"#.to_string(),
            "needs a start",
        ),
        (
            r#"{"name":"a","causality":"output","start":1,"description":"d"}"#.to_string(),
            "takes no start",
        ),
        (
            r#"{"name":"a","causality":"parameter","start":5,"max":1,"description":"d"}"#.to_string(),
            "outside",
        ),
        (
            r#"{"name":"a","causality":"parameter","start":1,"unit":"furlong","description":"d"}"#.to_string(),
            "unknown unit",
        ),
        (
            r#"{"name":"a b","causality":"parameter","start":1,"description":"d"}"#.to_string(),
            "Rust identifier",
        ),
        (
            r#"{"name":"a","causality":"parameter","start":1,"description":" "}"#.to_string(),
            "empty description",
        ),
        (
            r#"{"name":"a","causality":"input","start":1,"variability":"fixed","description":"d"}"#.to_string(),
            "only parameters",
        ),
        (
            r#"{"name":"a","causality":"output","dependsOn":["x"],"description":"d"}"#.to_string(),
            "neither an input nor a continuous state",
        ),
        (
            r#"{"name":"a","causality":"parameter","start":1,"dependsOn":["@states"],"description":"d"}"#.to_string(),
            "only for outputs and state derivatives",
        ),
        (
            r#"{"name":"a","causality":"parameter","type":"Integer","start":1.5,"description":"d"}"#.to_string(),
            "does not fit",
        ),
        (
            r#"{"name":"a","causality":"parameter","start":1,"group":"g","description":"d"}"#.to_string(),
            "group 'g'",
        ),
        (
            r#"{"name":"a","causality":"parameter","start":1,"field":"x","description":"d"}"#.to_string(),
            "field without group",
        ),
    ];
    for (vars, expected) in cases {
        let e = load_text(&decl(&vars)).expect_err(&vars);
        assert!(
            e.contains(expected) && e.contains('a'),
            "{vars}: got '{e}', expected '{expected}'"
        );
    }
}

/// The plant takes the port ↔ struct-field mapping of its measurement outputs and
/// command inputs from the controller interface (`connectGroups`), so both sides
/// of a connection share one declaration. Every controller port of those groups
/// must then be a plant port of the opposite causality: wiring by name connects
/// them all (30 measurements read, 7 commands driven) plus phi, theta, psi.
#[test]
fn controller_ports_connect_to_plant_ports() {
    let plant = load(&dir(), "tailsitter_plant", "0").unwrap();
    for id in ["tailsitter_lqr", "tailsitter_tsd"] {
        let controller = load(&dir(), id, "0").unwrap();
        let mut connected = 0;
        for c in controller
            .variables
            .iter()
            .filter(|v| matches!(v.decl.causality, Causality::Input | Causality::Output))
        {
            let p = plant.variables.iter().find(|p| p.name() == c.name());
            if matches!(c.decl.group.as_deref(), Some("measurement" | "command")) {
                let p = p.unwrap_or_else(|| panic!("{id}.{} has no plant port", c.name()));
                assert_eq!(
                    (&p.decl.group, &p.decl.field),
                    (&c.decl.group, &c.decl.field),
                    "{id}.{}",
                    c.name()
                );
            }
            if let Some(p) = p {
                assert_ne!(p.decl.causality, c.decl.causality, "{id}.{}", c.name());
                connected += 1;
            }
        }
        assert_eq!(connected, 40, "{id}");
    }
    // A variable that declares its own group where the mapping is connected is an error.
    let dir = std::env::temp_dir().join(format!("decl-connect-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let port = |g: &str| format!(r#"{{"name":"a","causality":"input","start":0.0,{g}"description":"d"}}"#);
    std::fs::write(
        dir.join("other.json"),
        format!(
            r#"{{"groups":{{"g":"T"}},"variables":[{}]}}"#,
            port(r#""group":"g","field":"x","#)
        ),
    )
    .unwrap();
    let model = |g: &str| {
        format!(
            r#"{{"modelIdentifier":"m","defaultExperiment":{{"startTime":0,"stopTime":1,"stepSize":0.1}},"connectGroups":[{{"file":"other.json","groups":["g"]}}],"groups":{{"g":"T"}},"variables":[{}]}}"#,
            port(g)
        )
    };
    std::fs::write(dir.join("m.json"), model("")).unwrap();
    let m = load(&dir, "m", "0").unwrap();
    assert_eq!(
        (
            m.variables[0].decl.group.as_deref(),
            m.variables[0].decl.field.as_deref()
        ),
        (Some("g"), Some("x"))
    );
    std::fs::write(dir.join("m.json"), model(r#""group":"g","#)).unwrap();
    let e = load(&dir, "m", "0").unwrap_err().to_string();
    let _ = std::fs::remove_dir_all(&dir);
    assert!(e.contains("connectGroups"), "{e}");
}

/// A nested field (`sub.field`) is only possible in a group built on its type's
/// `Default`; such a group's constructor assigns the declared fields into it.
#[test]
fn nested_fields_need_a_group_built_on_default() {
    let with = |ty: &str, field: &str| {
        format!(
            r#"{{"modelIdentifier":"m","defaultExperiment":{{"startTime":0,"stopTime":1,"stepSize":0.1}},"groups":{{"g":"{ty}"}},"variables":[{{"name":"a","causality":"parameter","start":1.0,"group":"g","field":"{field}","description":"d"}}]}}"#
        )
    };
    let e = load_text(&with("T", "x.y")).unwrap_err();
    assert!(e.contains("nested field"), "{e}");
    let m = load_text(&with("T { ..Default::default() }", "x.y[2]")).unwrap();
    let rust = model_description::rust::variables_module(&m, "m.xml");
    assert!(rust.contains("let mut value = <T>::default();"), "{rust}");
    assert!(rust.contains("value.x.y[2] = self.a;"), "{rust}");
}

/// The data that `python/tailsim/declarations.py` loads is the generator's.
#[test]
fn python_declarations_data_matches_generated() {
    let generated = model_description::python::declarations_module(&dir(), env!("CARGO_PKG_VERSION")).unwrap();
    let path = dir().join("..").join(model_description::python::MODULE_PATH);
    let committed =
        std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e} (run `cargo xtask regen`)", path.display()));
    assert!(
        generated == committed,
        "{} drifted from the declarations: run `cargo xtask regen` and commit it",
        path.display()
    );
}
