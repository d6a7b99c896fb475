//! FMI 3.0 archives `dist/fmi3/<modelIdentifier>.fmu`: the same declarations and the same
//! libraries as the FMI 2.0 archives (every `fmu-*` library also exports the `fmi3*`
//! functions, `crates/fmi3-export`), with an FMI 3.0 modelDescription.xml and the FMI 3.0
//! platform folders `binaries/{x86_64-linux,aarch64-linux,x86_64-windows}/`: unlike
//! FMI 2.0, one archive carries the x86-64 and the ARM Linux library side by side.
//!
//! The model description follows fmi3ModelDescription.xsd (element order ModelExchange,
//! CoSimulation, UnitDefinitions, LogCategories, DefaultExperiment, ModelVariables,
//! ModelStructure): `Float64`/`Int32`/`Boolean`/`String` variables, the
//! independent variable `time` FMI 3.0 requires (value reference one above the largest
//! declared one, as `fmi3_export::time_value_reference`), and the ModelStructure of the
//! FMI 2.0 description with value references in place of indices.

use crate::Platform;
use model_description::xml::{document, element, empty, units_categories_experiment, value_attributes, XmlWriter};
use model_description::{Model, Start, VarType, Variable, AUTHOR, GENERATION_TOOL};
use std::io::{Result, Write};
use std::path::Path;

type W = XmlWriter;

/// Value reference of the independent variable `time` (see the module documentation).
pub fn time_value_reference(model: &Model) -> u32 {
    model
        .variables
        .iter()
        .map(|v| v.value_reference)
        .max()
        .map_or(0, |m| m + 1)
}

impl Platform {
    /// FMI 3.0 platform tuple (folder under `binaries/`, FMI 3.0 §2.5.1.1).
    fn fmi3_folder(self) -> &'static str {
        match self {
            Platform::Linux64 => "x86_64-linux",
            Platform::Aarch64Linux => "aarch64-linux",
            Platform::Win64 => "x86_64-windows",
        }
    }

    /// Path of the library of model `id` in an FMI 3.0 archive.
    fn fmi3_archive_path(self, id: &str) -> String {
        let ext = if self == Platform::Win64 { "dll" } else { "so" };
        format!("binaries/{}/{id}.{ext}", self.fmi3_folder())
    }
}

/// Write `<out>/fmi3/<id>.fmu` for every model of `ids`, with the libraries of every
/// platform in `platforms` (already built).
pub fn write_archives(
    root: &Path,
    out: &Path,
    ids: &[&str],
    platforms: &[Platform],
) -> std::result::Result<(), String> {
    let folder = out.join("fmi3");
    std::fs::create_dir_all(&folder).map_err(|e| format!("{}: {e}", folder.display()))?;
    for id in ids {
        let model = crate::load(id)?;
        let path = folder.join(format!("{id}.fmu"));
        let file = std::fs::File::create(&path).map_err(|e| format!("{}: {e}", path.display()))?;
        let mut zip = zip::ZipWriter::new(file);
        let options = zip::write::SimpleFileOptions::default().compression_method(zip::CompressionMethod::Deflated);
        let mut entries = vec![(
            "modelDescription.xml".to_string(),
            model_description(&model).into_bytes(),
        )];
        for platform in platforms {
            let lib = platform.built_path(root, id);
            let bytes = std::fs::read(&lib).map_err(|e| format!("{}: {e}", lib.display()))?;
            entries.push((platform.fmi3_archive_path(id), bytes));
        }
        for (name, bytes) in &entries {
            zip.start_file(name.as_str(), options)
                .map_err(|e| format!("{name}: {e}"))?;
            zip.write_all(bytes).map_err(|e| format!("{name}: {e}"))?;
        }
        zip.finish().map_err(|e| e.to_string())?;
        println!("wrote {} (FMI 3.0, {} platforms)", path.display(), platforms.len());
    }
    Ok(())
}

/// The FMI 3.0 modelDescription.xml of `model`.
pub fn model_description(model: &Model) -> String {
    document(|w| write_all(w, model)).expect("writing XML into memory cannot fail")
}

fn write_all(w: &mut W, model: &Model) -> Result<()> {
    let attributes = [
        ("fmiVersion", "3.0"),
        ("modelName", model.model_name.as_str()),
        ("instantiationToken", model.guid.as_str()),
        ("description", model.description.as_str()),
        ("author", AUTHOR),
        ("version", model.version.as_str()),
        ("generationTool", GENERATION_TOOL),
        ("variableNamingConvention", "flat"),
    ];
    element(w, "fmiModelDescription", attributes, |w| {
        let shared = [
            ("modelIdentifier", model.model_identifier.as_str()),
            ("canGetAndSetFMUState", "true"),
            ("canSerializeFMUState", "true"),
        ];
        if model.model_exchange() {
            empty(w, "ModelExchange", shared)?;
        }
        // No event mode, no early return, no intermediate update: a plain fixed- or
        // variable-step slave, as the FMI 2.0 interface.
        empty(
            w,
            "CoSimulation",
            shared
                .into_iter()
                .chain([("canHandleVariableCommunicationStepSize", "true")]),
        )?;
        units_categories_experiment(w, model)?;
        element(w, "ModelVariables", [], |w| {
            let time = time_value_reference(model).to_string();
            empty(
                w,
                "Float64",
                [
                    ("name", "time"),
                    ("valueReference", time.as_str()),
                    ("description", "Simulation time"),
                    ("causality", "independent"),
                    ("variability", "continuous"),
                    ("unit", "s"),
                ],
            )?;
            model.variables.iter().try_for_each(|v| variable(w, model, v))
        })?;
        model_structure(w, model)
    })
}

fn variable(w: &mut W, model: &Model, v: &Variable) -> Result<()> {
    let d = &v.decl;
    let tag = match d.var_type {
        VarType::Real => "Float64",
        VarType::Integer => "Int32",
        VarType::Boolean => "Boolean",
        VarType::String => "String",
    };
    let mut attrs: Vec<(&str, String)> = vec![
        ("name", d.name.clone()),
        ("valueReference", v.value_reference.to_string()),
        ("description", d.description.clone()),
        ("causality", d.causality.as_str().to_string()),
        ("variability", v.variability.as_str().to_string()),
    ];
    attrs.extend(value_attributes(v, false));
    // A String's start value is a child element in FMI 3.0.
    let string_start = match &d.start {
        Some(Start::Text(s)) => Some(s.as_str()),
        _ => None,
    };
    if let Some(state) = &d.derivative_of {
        let vr = model
            .variables
            .iter()
            .find(|s| s.name() == state)
            .map(|s| s.value_reference)
            .expect("checked at load");
        attrs.push(("derivative", vr.to_string()));
    }
    let attrs = attrs.iter().map(|(k, v)| (*k, v.as_str()));
    match string_start {
        Some(s) => element(w, tag, attrs, |w| empty(w, "Start", [("value", s)])),
        None => empty(w, tag, attrs),
    }
}

/// Output, ContinuousStateDerivative and InitialUnknown elements: the FMI 2.0 lists and
/// dependencies ([`Model::dependencies`], [`Model::initial_dependencies`]) by value
/// reference.
fn model_structure(w: &mut W, model: &Model) -> Result<()> {
    let vr = |i: usize| model.variables[i - 1].value_reference.to_string();
    let unknown = |w: &mut W, name: &str, v: &Variable, deps: Vec<usize>| {
        let deps: Vec<String> = deps.into_iter().map(vr).collect();
        let own = v.value_reference.to_string();
        empty(
            w,
            name,
            [
                ("valueReference", own.as_str()),
                ("dependencies", deps.join(" ").as_str()),
            ],
        )
    };
    element(w, "ModelStructure", [], |w| {
        for v in model.outputs() {
            unknown(w, "Output", v, model.dependencies(v))?;
        }
        for (_, d) in model.continuous_states() {
            unknown(w, "ContinuousStateDerivative", d, model.dependencies(d))?;
        }
        for v in model.initial_unknowns() {
            unknown(w, "InitialUnknown", v, model.initial_dependencies(v))?;
        }
        Ok(())
    })
}
