//! modelDescription.xml (FMI 2.0 Co-Simulation) written with quick-xml.
//!
//! Element order follows fmi2ModelDescription.xsd: CoSimulation,
//! UnitDefinitions, LogCategories, DefaultExperiment, ModelVariables,
//! ModelStructure. No timestamp is written, so the output is reproducible and
//! can be compared byte for byte with the reviewed copy in the repository.

use crate::{fmt_f64, units, Model, Start, VarType, Variable, AUTHOR, GENERATION_TOOL, LOG_CATEGORIES};
use quick_xml::events::{BytesDecl, Event};
use quick_xml::Writer;
use std::collections::BTreeSet;
use std::io::Result;

/// The quick-xml writer of every XML file the project writes.
pub type XmlWriter = Writer<Vec<u8>>;

/// An XML document as the project writes them (modelDescription.xml, the SSP's
/// SystemStructure.ssd): UTF-8 declaration, elements from `body` indented by two
/// spaces, a final newline; no timestamp, so equal input gives equal bytes.
pub fn document(body: impl FnOnce(&mut XmlWriter) -> Result<()>) -> Result<String> {
    let mut w = Writer::new_with_indent(Vec::new(), b' ', 2);
    w.write_event(Event::Decl(BytesDecl::new("1.0", Some("UTF-8"), None)))?;
    body(&mut w)?;
    let mut text =
        String::from_utf8(w.into_inner()).map_err(|e| std::io::Error::new(std::io::ErrorKind::InvalidData, e))?;
    text.push('\n');
    Ok(text)
}

/// `<name attributes>`, the children `body` writes, `</name>` (`<name ...></name>` when it
/// writes none).
pub fn element<'a>(
    w: &mut XmlWriter,
    name: &str,
    attributes: impl IntoIterator<Item = (&'a str, &'a str)>,
    body: impl FnOnce(&mut XmlWriter) -> Result<()>,
) -> Result<()> {
    w.create_element(name)
        .with_attributes(attributes)
        .write_inner_content(body)?;
    Ok(())
}

/// `<name attributes/>`.
pub fn empty<'a>(
    w: &mut XmlWriter,
    name: &str,
    attributes: impl IntoIterator<Item = (&'a str, &'a str)>,
) -> Result<()> {
    w.create_element(name).with_attributes(attributes).write_empty()?;
    Ok(())
}

/// The complete modelDescription.xml of `model`.
pub fn model_description(model: &Model) -> String {
    document(|w| write_all(w, model)).expect("writing XML into memory cannot fail")
}

type W = XmlWriter;

fn write_all(w: &mut W, model: &Model) -> Result<()> {
    let n_events = "0";
    let attributes = [
        ("fmiVersion", "2.0"),
        ("modelName", model.model_name.as_str()),
        ("guid", model.guid.as_str()),
        ("description", model.description.as_str()),
        ("author", AUTHOR),
        ("version", model.version.as_str()),
        ("generationTool", GENERATION_TOOL),
        ("variableNamingConvention", "flat"),
        ("numberOfEventIndicators", n_events),
    ];
    element(w, "fmiModelDescription", attributes, |w| {
        if model.model_exchange() {
            model_exchange(w, model)?;
        }
        co_simulation(w, model)?;
        units_categories_experiment(w, model)?;
        element(w, "ModelVariables", [], |w| {
            model.variables.iter().try_for_each(|v| scalar_variable(w, model, v))
        })?;
        model_structure(w, model)
    })
}

/// UnitDefinitions, LogCategories and DefaultExperiment, which FMI 2.0 and FMI 3.0 write
/// alike, between the interface elements and ModelVariables.
pub fn units_categories_experiment(w: &mut W, model: &Model) -> Result<()> {
    unit_definitions(w, model)?;
    log_categories(w)?;
    let e = &model.default_experiment;
    let (start, stop, step) = (fmt_f64(e.start_time), fmt_f64(e.stop_time), fmt_f64(e.step_size));
    empty(
        w,
        "DefaultExperiment",
        [
            ("startTime", start.as_str()),
            ("stopTime", stop.as_str()),
            ("stepSize", step.as_str()),
        ],
    )
}

/// `<ModelExchange>`: the same binary (same modelIdentifier) serves both interfaces,
/// as the Reference FMUs do. No event indicators, no time events: the model is smooth
/// between input changes, which the importer handles at its communication points.
fn model_exchange(w: &mut W, model: &Model) -> Result<()> {
    interface(
        w,
        "ModelExchange",
        model,
        &[("completedIntegratorStepNotNeeded", "true")],
    )
}

fn co_simulation(w: &mut W, model: &Model) -> Result<()> {
    interface(
        w,
        "CoSimulation",
        model,
        &[
            ("canHandleVariableCommunicationStepSize", "true"),
            ("canInterpolateInputs", "false"),
            ("maxOutputDerivativeOrder", "0"),
            ("canRunAsynchronuously", "false"),
        ],
    )
}

/// One interface element: the model identifier, `specific` capabilities, then those both
/// interfaces share (many instances, the FMU's own memory management, FMU states).
fn interface(w: &mut W, element: &str, model: &Model, specific: &[(&str, &str)]) -> Result<()> {
    let head = [
        ("modelIdentifier", model.model_identifier.as_str()),
        ("needsExecutionTool", "false"),
    ];
    let shared = [
        ("canBeInstantiatedOnlyOncePerProcess", "false"),
        ("canNotUseMemoryManagementFunctions", "true"),
        ("canGetAndSetFMUstate", "true"),
        ("canSerializeFMUstate", "true"),
        ("providesDirectionalDerivative", "false"),
    ];
    empty(
        w,
        element,
        head.into_iter().chain(specific.iter().copied()).chain(shared),
    )
}

/// The units actually used, in the order of [`units::UNITS`].
pub fn used_units(model: &Model) -> Vec<&'static units::Unit> {
    let used: BTreeSet<&str> = model.variables.iter().filter_map(|v| v.decl.unit.as_deref()).collect();
    units::UNITS.iter().filter(|u| used.contains(u.name)).collect()
}

fn unit_definitions(w: &mut W, model: &Model) -> Result<()> {
    let used = used_units(model);
    if used.is_empty() {
        return Ok(());
    }
    element(w, "UnitDefinitions", [], |w| {
        used.into_iter().try_for_each(|u| {
            element(w, "Unit", [("name", u.name)], |w| {
                let mut base: Vec<(&str, String)> = [("kg", u.kg), ("m", u.m), ("s", u.s), ("A", u.a), ("rad", u.rad)]
                    .into_iter()
                    .filter(|(_, exp)| *exp != 0)
                    .map(|(name, exp)| (name, exp.to_string()))
                    .collect();
                if u.factor != 1.0 {
                    base.push(("factor", fmt_f64(u.factor)));
                }
                empty(w, "BaseUnit", base.iter().map(|(k, v)| (*k, v.as_str())))?;
                u.display_units.iter().try_for_each(|d| {
                    empty(
                        w,
                        "DisplayUnit",
                        [("name", d.name), ("factor", fmt_f64(d.factor).as_str())],
                    )
                })
            })
        })
    })
}

fn log_categories(w: &mut W) -> Result<()> {
    element(w, "LogCategories", [], |w| {
        LOG_CATEGORIES
            .iter()
            .try_for_each(|(name, description)| empty(w, "Category", [("name", *name), ("description", *description)]))
    })
}

fn scalar_variable(w: &mut W, model: &Model, v: &Variable) -> Result<()> {
    let d = &v.decl;
    let vr = v.value_reference.to_string();
    let attributes = [
        ("name", d.name.as_str()),
        ("valueReference", vr.as_str()),
        ("description", d.description.as_str()),
        ("causality", d.causality.as_str()),
        ("variability", v.variability.as_str()),
    ];
    element(w, "ScalarVariable", attributes, |w| {
        let tag = match d.var_type {
            VarType::Real => "Real",
            VarType::Integer => "Integer",
            VarType::Boolean => "Boolean",
            VarType::String => "String",
        };
        let mut attrs = value_attributes(v, true);
        if let Some(state) = &d.derivative_of {
            attrs.push(("derivative", index_of(model, state).to_string()));
        }
        empty(w, tag, attrs.iter().map(|(k, v)| (*k, v.as_str())))
    })
}

/// The attributes of a variable's type element, in schema order: `unit`, `displayUnit`,
/// `min`, `max`, `nominal`, `start` (a String's start only with `string_start`: FMI 3.0
/// writes it as a child element). Shared by the FMI 2.0 and FMI 3.0 writers.
pub fn value_attributes(v: &Variable, string_start: bool) -> Vec<(&'static str, String)> {
    let d = &v.decl;
    let mut attrs: Vec<(&'static str, String)> = Vec::new();
    if let Some(u) = &d.unit {
        attrs.push(("unit", u.clone()));
    }
    if let Some(du) = &v.display_unit {
        attrs.push(("displayUnit", du.clone()));
    }
    let number = |x: f64| match d.var_type {
        VarType::Integer => format!("{}", x as i64),
        _ => fmt_f64(x),
    };
    if let Some(lo) = d.min {
        attrs.push(("min", number(lo)));
    }
    if let Some(hi) = d.max {
        attrs.push(("max", number(hi)));
    }
    if let Some(x) = d.nominal {
        attrs.push(("nominal", fmt_f64(x)));
    }
    match &d.start {
        Some(Start::Number(x)) => attrs.push(("start", number(*x))),
        Some(Start::Bool(b)) => attrs.push(("start", b.to_string())),
        Some(Start::Text(s)) if string_start => attrs.push(("start", s.clone())),
        _ => {}
    }
    attrs
}

/// 1-based index of a variable in ModelVariables.
fn index_of(model: &Model, name: &str) -> usize {
    model
        .variables
        .iter()
        .position(|v| v.name() == name)
        .map(|i| i + 1)
        .expect("checked at load")
}

fn model_structure(w: &mut W, model: &Model) -> Result<()> {
    let derivatives: Vec<&Variable> = model.continuous_states().into_iter().map(|(_, d)| d).collect();
    element(w, "ModelStructure", [], |w| {
        write_unknowns(w, model, "Outputs", &model.outputs(), |v| model.dependencies(v))?;
        write_unknowns(w, model, "Derivatives", &derivatives, |v| model.dependencies(v))?;
        write_unknowns(w, model, "InitialUnknowns", &model.initial_unknowns(), |v| {
            model.initial_dependencies(v)
        })
    })
}

/// One list of ModelStructure (nothing when `list` is empty): an `Unknown` per variable
/// with its `dependencies` (indices of the knowns, ascending; an empty list = none).
fn write_unknowns(
    w: &mut W,
    model: &Model,
    name: &str,
    list: &[&Variable],
    deps: impl Fn(&Variable) -> Vec<usize>,
) -> Result<()> {
    if list.is_empty() {
        return Ok(());
    }
    element(w, name, [], |w| {
        list.iter().try_for_each(|v| {
            let index = index_of(model, v.name()).to_string();
            let deps: Vec<String> = deps(v).iter().map(usize::to_string).collect();
            empty(
                w,
                "Unknown",
                [("index", index.as_str()), ("dependencies", deps.join(" ").as_str())],
            )
        })
    })
}
