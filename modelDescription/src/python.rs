//! The Python declarations module `python/tailsim/declarations.py`: every model's
//! variables (name, type, causality, variability, unit, start, min, max, description)
//! and default experiment, and from the controller interface
//! (`fragments/controller_interface.json`) the commands and their limits (the plant's
//! `thrust_min`, `thrust_max`, `deflection_limit`), the phases, the mission parameters
//! and the mission presets. Written by `cargo xtask regen`; a test in
//! `tests/declarations.rs` fails when the committed copy differs.

use crate::{load, read_decl, Causality, DeclError, DeclFile, Model, Start, VarType};
use std::fmt::Write;
use std::path::Path;

/// Path of the module, relative to the workspace root.
pub const MODULE_PATH: &str = "python/tailsim/declarations.py";
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

/// The module text for the declarations in `dir`.
pub fn declarations_module(dir: &Path, version: &str) -> Result<String, DeclError> {
    let models = model_ids(dir)?
        .iter()
        .map(|id| load(dir, id, version))
        .collect::<Result<Vec<_>, _>>()?;
    let interface = read_decl(&dir.join(INTERFACE), &mut Vec::new())?;
    render(&models, &interface)
}

/// A Python string literal, quoted as `ruff format` quotes it (double quotes unless
/// the text holds more double than single quotes).
fn py_str(s: &str) -> String {
    let quote = if s.matches('"').count() > s.matches('\'').count() {
        '\''
    } else {
        '"'
    };
    let mut out = String::with_capacity(s.len() + 2);
    out.push(quote);
    for c in s.chars() {
        match c {
            '\\' => out.push_str("\\\\"),
            '\n' => out.push_str("\\n"),
            '\t' => out.push_str("\\t"),
            c if c == quote => {
                out.push('\\');
                out.push(c);
            }
            c if (c as u32) < 0x20 => {
                let _ = write!(out, "\\x{:02x}", c as u32);
            }
            c => out.push(c),
        }
    }
    out.push(quote);
    out
}

fn py_float(x: f64) -> String {
    if x.is_finite() {
        format!("{x:?}")
    } else if x.is_nan() {
        "math.nan".into()
    } else if x > 0.0 {
        "math.inf".into()
    } else {
        "-math.inf".into()
    }
}

fn py_opt_float(x: Option<f64>) -> String {
    x.map_or_else(|| "None".into(), py_float)
}

fn py_start(ty: VarType, start: &Option<Start>) -> String {
    match (ty, start) {
        (_, None) => "None".into(),
        (VarType::Boolean, Some(Start::Bool(b))) => (if *b { "True" } else { "False" }).into(),
        (VarType::Boolean, Some(Start::Number(x))) => (if *x != 0.0 { "True" } else { "False" }).into(),
        (VarType::Integer, Some(Start::Number(x))) => format!("{}", *x as i64),
        (_, Some(Start::Number(x))) => py_float(*x),
        (_, Some(Start::Bool(b))) => (if *b { "True" } else { "False" }).into(),
        (_, Some(Start::Text(s))) => py_str(s),
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

/// A multi-line tuple of strings (trailing comma: `ruff format` keeps it exploded).
fn tuple_of(out: &mut String, name: &str, doc: &str, items: &[String]) {
    let _ = writeln!(out, "#: {doc}\n{name} = (");
    for item in items {
        let _ = writeln!(out, "    {},", py_str(item));
    }
    out.push_str(")\n\n");
}

/// Render the module from the loaded models and the controller interface.
pub fn render(models: &[Model], interface: &DeclFile) -> Result<String, DeclError> {
    let mut out = String::new();
    out.push_str(
        "\"\"\"The FMUs' declared interfaces (modelDescription/*.json), for the Python masters and reports.\n\
         \n\
         Generated by `cargo xtask regen` (modelDescription/src/python.rs): do not edit.\n\
         \"\"\"\n\
         \n\
         # Generated by cargo xtask regen - do not edit.\n\
         \n\
         from __future__ import annotations\n\
         \n\
         from typing import NamedTuple\n\
         \n\
         \n\
         class Variable(NamedTuple):\n    \"\"\"One declared variable, as in modelDescription.xml.\"\"\"\n\n    \
         name: str\n    type: str\n    causality: str\n    variability: str\n    unit: str | None\n    \
         start: float | int | bool | str | None\n    min: float | None\n    max: float | None\n    \
         description: str\n\n\n\
         class DefaultExperiment(NamedTuple):\n    start_time: float\n    stop_time: float\n    step_size: float\n\n\n",
    );
    let ids: Vec<String> = models.iter().map(|m| m.model_identifier.clone()).collect();
    tuple_of(&mut out, "MODELS", "The model identifiers.", &ids);

    out.push_str("#: Default experiment of each model.\nDEFAULT_EXPERIMENTS: dict[str, DefaultExperiment] = {\n");
    for m in models {
        let e = &m.default_experiment;
        let _ = writeln!(
            out,
            "    {}: DefaultExperiment({}, {}, {}),",
            py_str(&m.model_identifier),
            py_float(e.start_time),
            py_float(e.stop_time),
            py_float(e.step_size)
        );
    }
    out.push_str("}\n\n");

    out.push_str(
        "#: The variables of each model by name, in declaration (value reference) order.\n\
         VARIABLES: dict[str, dict[str, Variable]] = {\n",
    );
    for m in models {
        let _ = writeln!(out, "    {}: {{", py_str(&m.model_identifier));
        for v in &m.variables {
            let d = &v.decl;
            let _ = writeln!(out, "        {}: Variable(", py_str(&d.name));
            for field in [
                py_str(&d.name),
                py_str(type_name(d.var_type)),
                py_str(d.causality.as_str()),
                py_str(v.variability.as_str()),
                d.unit.as_deref().map_or_else(|| "None".into(), py_str),
                py_start(d.var_type, &d.start),
                py_opt_float(d.min),
                py_opt_float(d.max),
                py_str(&d.description),
            ] {
                let _ = writeln!(out, "            {field},");
            }
            out.push_str("        ),\n");
        }
        out.push_str("    },\n");
    }
    out.push_str("}\n\n");

    // The controller interface: commands, phases, mission.
    let iface = &interface.variables;
    let commands: Vec<String> = iface
        .iter()
        .filter(|v| v.group.as_deref() == Some("command"))
        .map(|v| v.name.clone())
        .collect();
    tuple_of(
        &mut out,
        "COMMANDS",
        "The controllers' commands (outputs of the controller interface's `command` group), thrust first.",
        &commands,
    );
    let plant = models
        .iter()
        .find(|m| m.model_identifier == PLANT)
        .ok_or_else(|| DeclError(format!("no model {PLANT}")))?;
    let _ = writeln!(
        out,
        "#: The plant's thrust limits (N): its parameters `{THRUST_MIN}`, `{THRUST_MAX}`.\n\
         THRUST_LIMITS = ({}, {})\n\
         #: The plant's deflection limit of every surface, +/- (rad): its parameter `{DEFLECTION_LIMIT}`.\n\
         DEFLECTION_LIMIT = {}\n",
        py_float(start_of(plant, THRUST_MIN)?),
        py_float(start_of(plant, THRUST_MAX)?),
        py_float(start_of(plant, DEFLECTION_LIMIT)?),
    );

    out.push_str("#: Names of the codes of the controllers' `phase` output.\nPHASE_NAMES: dict[int, str] = {\n");
    for p in &interface.phases {
        let _ = writeln!(out, "    {}: {},", p.code, py_str(&p.name));
    }
    out.push_str("}\n\n");
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
    tuple_of(
        &mut out,
        "PHASES",
        "The phases of the mission (codes 0, 1, ...), in order.",
        &mission_phases.iter().map(|p| p.name.clone()).collect::<Vec<_>>(),
    );
    let durations: Vec<String> = mission_phases.iter().filter_map(|p| p.duration.clone()).collect();
    if let Some(d) = durations.iter().find(|d| !is_mission(d)) {
        return Err(DeclError(format!("phase duration '{d}' is not a mission parameter")));
    }
    tuple_of(
        &mut out,
        "PHASE_DURATIONS",
        "The mission parameters of the phases' durations (s), in phase order.",
        &durations,
    );
    tuple_of(
        &mut out,
        "MISSION",
        "The mission parameters every controller declares (the controller interface's `mission` group).",
        &mission.iter().map(|v| v.name.clone()).collect::<Vec<_>>(),
    );
    out.push_str("#: Their declared defaults.\nMISSION_DEFAULTS: dict[str, float] = {\n");
    for v in &mission {
        let _ = writeln!(out, "    {}: {},", py_str(&v.name), py_start(VarType::Real, &v.start));
    }
    out.push_str(
        "}\n\n#: Their declared ranges (min, max).\nMISSION_RANGES: dict[str, tuple[float | None, float | None]] = {\n",
    );
    for v in &mission {
        let _ = writeln!(
            out,
            "    {}: ({}, {}),",
            py_str(&v.name),
            py_opt_float(v.min),
            py_opt_float(v.max)
        );
    }
    out.push_str("}\n\n");

    out.push_str("#: Named missions: values over `MISSION_DEFAULTS`.\nPRESETS: dict[str, dict[str, float]] = {\n");
    for (name, preset) in &interface.presets {
        if let Some(k) = preset.values.keys().find(|k| !is_mission(k)) {
            return Err(DeclError(format!("preset '{name}': '{k}' is not a mission parameter")));
        }
        if preset.values.is_empty() {
            let _ = writeln!(out, "    {}: {{}},", py_str(name));
            continue;
        }
        let _ = writeln!(out, "    {}: {{", py_str(name));
        // In the mission group's order.
        for v in &mission {
            if let Some(x) = preset.values.get(&v.name) {
                let _ = writeln!(out, "        {}: {},", py_str(&v.name), py_float(*x));
            }
        }
        out.push_str("    },\n");
    }
    out.push_str("}\n\n#: What each preset is.\nPRESET_DESCRIPTIONS: dict[str, str] = {\n");
    for (name, preset) in &interface.presets {
        let _ = writeln!(out, "    {}: {},", py_str(name), py_str(&preset.description));
    }
    out.push_str(
        "}\n\n\n\
         def mission(preset: str = \"default\", **values: float) -> dict[str, float]:\n    \
         \"\"\"Every mission parameter: the declared defaults, the preset's values, then `values`.\"\"\"\n    \
         unknown = [k for k in values if k not in MISSION_DEFAULTS]\n    \
         if unknown:\n        \
         raise KeyError(f\"not mission parameters: {unknown}\")\n    \
         return {**MISSION_DEFAULTS, **PRESETS[preset], **values}\n\n\n\
         def stop_time(params: dict[str, float]) -> float:\n    \
         \"\"\"The end of the mission: the sum of its phases' durations (s).\"\"\"\n    \
         return float(sum(float(params[k]) for k in PHASE_DURATIONS))\n",
    );
    Ok(out)
}
