//! The Python declarations data `python/tailsim/declarations.json`: every model's
//! variables (name, type, causality, variability, unit, start, min, max, description)
//! and default experiment, and from the controller interface
//! (`fragments/controller_interface.json`) the commands and their limits (the plant's
//! `thrust_min`, `thrust_max`, `deflection_limit`), the phases, the mission parameters
//! and the mission presets. Written by `cargo xtask regen`; a test in
//! `tests/declarations.rs` fails when the committed copy differs. The hand-written
//! module `python/tailsim/declarations.py` loads it into the package's public names
//! (`MODELS`, `VARIABLES`, `COMMANDS`, `mission()`, ...): data, not generated code.

use crate::{load, read_decl, Causality, DeclError, DeclFile, Model, Start, VarType};
use std::fmt::Write;
use std::path::Path;

/// Path of the generated data, relative to the workspace root (the entry point's name
/// is kept from when the generator wrote the Python module itself).
pub const MODULE_PATH: &str = "python/tailsim/declarations.json";
/// The controller interface fragment, relative to the declarations folder.
pub const INTERFACE: &str = "fragments/controller_interface.json";
/// The plant model and its parameters that bound the commands.
const PLANT: &str = "tailsitter_plant";
const THRUST_MIN: &str = "thrust_min";
const THRUST_MAX: &str = "thrust_max";
const DEFLECTION_LIMIT: &str = "deflection_limit";

/// Every model declaration of `dir` (the JSON files with a modelIdentifier), sorted.
pub fn model_ids(dir: &Path) -> Result<Vec<String>, DeclError> {
    let mut ids = Vec::new();
    let entries = std::fs::read_dir(dir).map_err(|e| DeclError(format!("{}: {e}", dir.display())))?;
    for entry in entries {
        let path = entry.map_err(|e| DeclError(e.to_string()))?.path();
        if path.extension().is_some_and(|x| x == "json") {
            let decl = read_decl(&path, &mut Vec::new())?;
            if decl.model_identifier.is_some() {
                ids.push(path.file_stem().unwrap_or_default().to_string_lossy().into_owned());
            }
        }
    }
    ids.sort();
    Ok(ids)
}

/// The JSON text of the declarations in `dir` (written to [`MODULE_PATH`]).
pub fn declarations_module(dir: &Path, version: &str) -> Result<String, DeclError> {
    let models = model_ids(dir)?
        .iter()
        .map(|id| load(dir, id, version))
        .collect::<Result<Vec<_>, _>>()?;
    let interface = read_decl(&dir.join(INTERFACE), &mut Vec::new())?;
    render(&models, &interface)
}

/// A JSON string.
fn js(s: &str) -> String {
    serde_json::to_string(s).expect("a string serialises")
}

/// A JSON number; the non-finite ones as Python's `json` reads them.
fn jf(x: f64) -> String {
    if x.is_finite() {
        format!("{x:?}")
    } else if x.is_nan() {
        "NaN".into()
    } else if x > 0.0 {
        "Infinity".into()
    } else {
        "-Infinity".into()
    }
}

fn jf_opt(x: Option<f64>) -> String {
    x.map_or_else(|| "null".into(), jf)
}

fn j_start(ty: VarType, start: &Option<Start>) -> String {
    match (ty, start) {
        (_, None) => "null".into(),
        (VarType::Boolean, Some(Start::Number(x))) => (*x != 0.0).to_string(),
        (VarType::Integer, Some(Start::Number(x))) => format!("{}", *x as i64),
        (_, Some(Start::Number(x))) => jf(*x),
        (_, Some(Start::Bool(b))) => b.to_string(),
        (_, Some(Start::Text(s))) => js(s),
    }
}

fn type_name(ty: VarType) -> &'static str {
    match ty {
        VarType::Real => "Real",
        VarType::Integer => "Integer",
        VarType::Boolean => "Boolean",
        VarType::String => "String",
    }
}

fn start_of(model: &Model, name: &str) -> Result<f64, DeclError> {
    let v = model
        .variables
        .iter()
        .find(|v| v.name() == name)
        .ok_or_else(|| DeclError(format!("{}: no variable '{name}'", model.model_identifier)))?;
    match v.decl.start {
        Some(Start::Number(x)) => Ok(x),
        _ => Err(DeclError(format!(
            "{}: '{name}' has no numeric start",
            model.model_identifier
        ))),
    }
}

/// Writes the `"key": {...}` members of one JSON object, one a line at `indent`, in order.
fn object(out: &mut String, key: &str, indent: &str, members: impl IntoIterator<Item = (String, String)>) {
    let body: Vec<String> = members
        .into_iter()
        .map(|(k, v)| format!("{indent}  {}: {v}", js(&k)))
        .collect();
    if body.is_empty() {
        let _ = write!(out, "{indent}{}: {{}}", js(key));
    } else {
        let _ = write!(out, "{indent}{}: {{\n{}\n{indent}}}", js(key), body.join(",\n"));
    }
}

/// A JSON array of strings, on one line.
fn strings<S: AsRef<str>>(items: &[S]) -> String {
    let items: Vec<String> = items.iter().map(|s| js(s.as_ref())).collect();
    format!("[{}]", items.join(", "))
}

/// Render the data from the loaded models and the controller interface: one JSON
/// object whose members the loader `python/tailsim/declarations.py` turns into its
/// public names (`models` into `MODELS`, `DEFAULT_EXPERIMENTS` and `VARIABLES`, the
/// others into the upper-case name of the same words).
pub fn render(models: &[Model], interface: &DeclFile) -> Result<String, DeclError> {
    let mut members: Vec<String> = Vec::new();
    let mut out = String::new();
    let model_json = |m: &Model| {
        let e = &m.default_experiment;
        let mut s = format!(
            "{{\n      \"default_experiment\": [{}, {}, {}],\n      \"variables\": [\n",
            jf(e.start_time),
            jf(e.stop_time),
            jf(e.step_size)
        );
        let vars: Vec<String> = m
            .variables
            .iter()
            .map(|v| {
                let d = &v.decl;
                format!(
                    "        [{}, {}, {}, {}, {}, {}, {}, {}, {}]",
                    js(&d.name),
                    js(type_name(d.var_type)),
                    js(d.causality.as_str()),
                    js(v.variability.as_str()),
                    d.unit.as_deref().map_or_else(|| "null".into(), js),
                    j_start(d.var_type, &d.start),
                    jf_opt(d.min),
                    jf_opt(d.max),
                    js(&d.description),
                )
            })
            .collect();
        s.push_str(&vars.join(",\n"));
        s.push_str("\n      ]\n    }");
        s
    };
    object(
        &mut out,
        "models",
        "  ",
        models.iter().map(|m| (m.model_identifier.clone(), model_json(m))),
    );
    members.push(std::mem::take(&mut out));

    // The controller interface: commands, phases, mission.
    let iface = &interface.variables;
    let commands: Vec<&str> = iface
        .iter()
        .filter(|v| v.group.as_deref() == Some("command"))
        .map(|v| v.name.as_str())
        .collect();
    members.push(format!("  \"commands\": {}", strings(&commands)));
    let plant = models
        .iter()
        .find(|m| m.model_identifier == PLANT)
        .ok_or_else(|| DeclError(format!("no model {PLANT}")))?;
    members.push(format!(
        "  \"thrust_limits\": [{}, {}]",
        jf(start_of(plant, THRUST_MIN)?),
        jf(start_of(plant, THRUST_MAX)?)
    ));
    members.push(format!(
        "  \"deflection_limit\": {}",
        jf(start_of(plant, DEFLECTION_LIMIT)?)
    ));
    object(
        &mut out,
        "phase_names",
        "  ",
        interface.phases.iter().map(|p| (p.code.to_string(), js(&p.name))),
    );
    members.push(std::mem::take(&mut out));

    let mission_phases: Vec<_> = interface.phases.iter().filter(|p| p.duration.is_some()).collect();
    for (i, p) in mission_phases.iter().enumerate() {
        if p.code != i as i64 {
            return Err(DeclError(format!(
                "phase '{}': the mission's phases must be codes 0, 1, ...",
                p.name
            )));
        }
    }
    let mission: Vec<_> = iface
        .iter()
        .filter(|v| v.group.as_deref() == Some("mission") && v.causality == Causality::Parameter)
        .collect();
    let is_mission = |name: &str| mission.iter().any(|v| v.name == name);
    let phases: Vec<&str> = mission_phases.iter().map(|p| p.name.as_str()).collect();
    members.push(format!("  \"phases\": {}", strings(&phases)));
    let durations: Vec<&str> = mission_phases.iter().filter_map(|p| p.duration.as_deref()).collect();
    if let Some(d) = durations.iter().find(|d| !is_mission(d)) {
        return Err(DeclError(format!("phase duration '{d}' is not a mission parameter")));
    }
    members.push(format!("  \"phase_durations\": {}", strings(&durations)));
    let names: Vec<&str> = mission.iter().map(|v| v.name.as_str()).collect();
    members.push(format!("  \"mission\": {}", strings(&names)));
    object(
        &mut out,
        "mission_defaults",
        "  ",
        mission
            .iter()
            .map(|v| (v.name.clone(), j_start(VarType::Real, &v.start))),
    );
    members.push(std::mem::take(&mut out));
    object(
        &mut out,
        "mission_ranges",
        "  ",
        mission
            .iter()
            .map(|v| (v.name.clone(), format!("[{}, {}]", jf_opt(v.min), jf_opt(v.max)))),
    );
    members.push(std::mem::take(&mut out));

    let mut presets = Vec::new();
    for (name, preset) in &interface.presets {
        if let Some(k) = preset.values.keys().find(|k| !is_mission(k)) {
            return Err(DeclError(format!("preset '{name}': '{k}' is not a mission parameter")));
        }
        // In the mission group's order.
        let values: Vec<String> = mission
            .iter()
            .filter_map(|v| Some(format!("{}: {}", js(&v.name), jf(*preset.values.get(&v.name)?))))
            .collect();
        presets.push((name.clone(), format!("{{{}}}", values.join(", "))));
    }
    object(&mut out, "presets", "  ", presets);
    members.push(std::mem::take(&mut out));
    object(
        &mut out,
        "preset_descriptions",
        "  ",
        interface.presets.iter().map(|(n, p)| (n.clone(), js(&p.description))),
    );
    members.push(out);
    Ok(format!("{{\n{}\n}}\n", members.join(",\n")))
}
