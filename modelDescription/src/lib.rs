//! Variable declarations of the tail-sitter FMUs — the single source of truth —
//! and the generators built on them.
//!
//! Each FMU's variables (name, causality, variability, type, unit, start,
//! min/max, description) are declared once, in `modelDescription/<modelIdentifier>.json`
//! (with shared fragments pulled in through `"include"`). From that one
//! declaration this crate produces
//! - `modelDescription.xml` ([`xml::model_description`]), written with quick-xml;
//! - the Rust accessors of the FMU ([`rust::variables_module`]): a struct with one
//!   named field per variable implementing `fmi2_export::VariableStore`, value
//!   reference constants, and conversions into the physics/controller parameter
//!   structs ("groups");
//! - the HTML variable tables of `documentation/index.html` ([`html::variable_tables`]).
//!
//! The top-level `build.rs` runs the first two for every `fmu-*` crate; the
//! packager runs the first and the last. A reviewable copy of each XML is kept in
//! `modelDescription/generated/` and a test fails when it drifts.

pub mod defaults;
pub mod html;
pub mod python;
pub mod rust;
pub mod units;
pub mod xml;

use serde::Deserialize;
use std::collections::{BTreeMap, BTreeSet};
use std::fmt;
use std::path::{Path, PathBuf};

/// Error while loading or checking a declaration.
#[derive(Debug, Clone, PartialEq)]
pub struct DeclError(pub String);

impl fmt::Display for DeclError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for DeclError {}

fn err<T>(msg: impl Into<String>) -> Result<T, DeclError> {
    Err(DeclError(msg.into()))
}

/// FMI 2.0 base type.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Default)]
pub enum VarType {
    #[default]
    Real,
    Integer,
    Boolean,
    String,
}

/// FMI 2.0 causality, spelled as in modelDescription.xml.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "camelCase")]
pub enum Causality {
    Parameter,
    CalculatedParameter,
    Input,
    Output,
    Local,
}

impl Causality {
    /// The attribute value in modelDescription.xml.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Parameter => "parameter",
            Self::CalculatedParameter => "calculatedParameter",
            Self::Input => "input",
            Self::Output => "output",
            Self::Local => "local",
        }
    }

    /// The enum variant name in `fmi2_export::Causality`.
    pub fn rust_variant(self) -> &'static str {
        match self {
            Self::Parameter => "Parameter",
            Self::CalculatedParameter => "CalculatedParameter",
            Self::Input => "Input",
            Self::Output => "Output",
            Self::Local => "Local",
        }
    }
}

/// FMI 2.0 variability, spelled as in modelDescription.xml.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "camelCase")]
pub enum Variability {
    Constant,
    Fixed,
    Tunable,
    Discrete,
    Continuous,
}

impl Variability {
    /// The attribute value in modelDescription.xml.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Constant => "constant",
            Self::Fixed => "fixed",
            Self::Tunable => "tunable",
            Self::Discrete => "discrete",
            Self::Continuous => "continuous",
        }
    }

    /// The enum variant name in `fmi2_export::Variability`.
    pub fn rust_variant(self) -> &'static str {
        match self {
            Self::Constant => "Constant",
            Self::Fixed => "Fixed",
            Self::Tunable => "Tunable",
            Self::Discrete => "Discrete",
            Self::Continuous => "Continuous",
        }
    }
}

/// A start value, typed by [`VarType`].
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(untagged)]
pub enum Start {
    Bool(bool),
    Number(f64),
    Text(String),
}

/// One variable as written in the JSON declaration.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, rename_all = "camelCase")]
pub struct VariableDecl {
    /// Variable name; also the Rust field name, so it must be a Rust identifier.
    pub name: String,
    #[serde(default, rename = "type")]
    pub var_type: VarType,
    pub causality: Causality,
    /// Defaults: parameters `fixed`, Real inputs/outputs `continuous`, other types `discrete`.
    #[serde(default)]
    pub variability: Option<Variability>,
    #[serde(default)]
    pub start: Option<Start>,
    #[serde(default)]
    pub min: Option<f64>,
    #[serde(default)]
    pub max: Option<f64>,
    /// Unit name from [`units::UNITS`] (Real only).
    #[serde(default)]
    pub unit: Option<String>,
    /// Display unit; `rad` defaults to `deg`, `rad/s` to `deg/s`.
    #[serde(default)]
    pub display_unit: Option<String>,
    pub description: String,
    /// Outputs and state derivatives: the knowns this value depends on at a
    /// communication point or in Continuous-Time Mode (ModelStructure `dependencies`):
    /// names of inputs (direct feedthrough) and of continuous states, or [`ALL_STATES`]
    /// for every continuous state. An output that is itself a state depends on that
    /// state without naming it. Empty = depends on no input (nor state).
    #[serde(default)]
    pub depends_on: Vec<String>,
    /// Name of a group (see [`DeclFile::groups`]) this variable is a field of:
    /// parameters and inputs are read into the group's struct, outputs written from it.
    #[serde(default)]
    pub group: Option<String>,
    /// Where the variable sits in its group's struct: `field`, `field[i]` (an
    /// element of a vector or array field) or `[i]` (the group's type is itself a
    /// vector); in a group built on its type's `Default` (see [`DeclFile::groups`])
    /// also a nested field `sub.field` or `sub.field[i]`. Default: the field named
    /// like the variable.
    #[serde(default)]
    pub field: Option<String>,
    /// Model Exchange: this variable is the time derivative of the named continuous
    /// state (`derivative` attribute). The continuous-state vector of
    /// fmi2GetContinuousStates is the states of the derivatives in declaration order.
    #[serde(default)]
    pub derivative_of: Option<String>,
    /// `nominal` attribute (Real only; > 0): the scale of the value, e.g. for the
    /// error control of an ME solver.
    #[serde(default)]
    pub nominal: Option<f64>,
}

impl VariableDecl {
    /// The field path in the group's struct: ([`Self::field`] or the name) split
    /// into the field name (empty for the whole value) and the element index.
    pub fn group_field(&self) -> Result<(&str, Option<usize>), DeclError> {
        let path = self.field.as_deref().unwrap_or(&self.name);
        let field_path = |top: &str| top.split('.').all(is_rust_identifier);
        match path.split_once('[') {
            None if field_path(path) => Ok((path, None)),
            Some((top, rest)) if top.is_empty() || field_path(top) => rest
                .strip_suffix(']')
                .and_then(|i| i.parse().ok())
                .map(|i| (top, Some(i)))
                .ok_or_else(|| DeclError(format!("variable '{}': bad field '{path}'", self.name))),
            _ => err(format!("variable '{}': bad field '{path}'", self.name)),
        }
    }
}

/// The default experiment of the model description.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, rename_all = "camelCase")]
pub struct DefaultExperiment {
    pub start_time: f64,
    pub stop_time: f64,
    pub step_size: f64,
}

/// A JSON declaration file: a model, or a fragment that models include.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, rename_all = "camelCase")]
pub struct DeclFile {
    #[serde(default)]
    pub model_identifier: Option<String>,
    #[serde(default)]
    pub model_name: Option<String>,
    #[serde(default)]
    pub description: Option<String>,
    #[serde(default)]
    pub default_experiment: Option<DefaultExperiment>,
    /// Group name → Rust type path. The generator emits
    /// `Variables::<group>() -> <path>` built field by field from the parameters
    /// or inputs of that group, or `Variables::set_<group>(&<path>)` writing its
    /// outputs, so the struct and the declaration cannot drift without a compile
    /// error (a field missing from the declaration does not compile).
    /// A path followed by [`FROM_DEFAULT`] (`"state_estimator::EstimatorParams { ..Default::default() }"`)
    /// builds the value from the type's `Default` and assigns the declared fields,
    /// which may then be nested (`noise.sigma_gps_vel`): for types with fields
    /// that are not ports or parameters.
    #[serde(default)]
    pub groups: BTreeMap<String, String>,
    /// Other declaration files (relative paths) whose variables are inserted first.
    #[serde(default)]
    pub include: Vec<String>,
    #[serde(default)]
    pub variables: Vec<VariableDecl>,
    /// Parameter groups imported from another declaration (one source for, e.g., the
    /// plant's airframe parameters and a controller's design model of them): appended
    /// after this file's own variables, so their value references follow the others.
    #[serde(default)]
    pub import_groups: Vec<GroupImport>,
    /// Port groups declared once on the other side of a connection: every variable of
    /// this file named like a variable of one of these groups there takes the same
    /// group and field (and the group its type). The plant's outputs read by the
    /// controllers and its command inputs take their mapping from the controller
    /// interface this way, so wiring by name carries each value into the same field.
    #[serde(default)]
    pub connect_groups: Vec<GroupLink>,
    /// The codes of the controllers' `phase` output with their names and, for the five
    /// phases of the mission, the parameter of their duration (read by [`python`]).
    #[serde(default)]
    pub phases: Vec<PhaseDecl>,
    /// Named missions: values of mission parameters over their declared starts (read by
    /// [`python`]).
    #[serde(default)]
    pub presets: BTreeMap<String, Preset>,
    /// The inputs every initial unknown depends on: `true` for all of them, or their
    /// names: a sampled unit whose outputs after fmi2ExitInitializationMode hold the
    /// value computed from the inputs set in Initialization Mode. Besides these an
    /// initial unknown depends on the inputs among its [`VariableDecl::depends_on`].
    /// See [`Model::initial_dependencies`].
    #[serde(default)]
    pub initial_depends_on_inputs: Option<InitialInputs>,
}

/// [`DeclFile::initial_depends_on_inputs`]: every input (`true`), none (`false`) or those named.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(untagged)]
pub enum InitialInputs {
    All(bool),
    Named(Vec<String>),
}

/// One code of the `phase` output.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PhaseDecl {
    pub code: i64,
    pub name: String,
    /// The mission parameter of the phase's duration (the five phases of the mission).
    #[serde(default)]
    pub duration: Option<String>,
}

/// A named mission: parameter values over the declared starts.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Preset {
    pub description: String,
    pub values: BTreeMap<String, f64>,
}

/// The groups of another declaration whose ports this file's variables connect to.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, rename_all = "camelCase")]
pub struct GroupLink {
    /// Declaration file (relative path), e.g. `fragments/controller_interface.json`.
    pub file: String,
    /// Its groups whose mapping applies here, e.g. `measurement`.
    pub groups: Vec<String>,
}

/// Import of every parameter of one group of another declaration file, with the
/// same names, types, starts, bounds and units, into a group of this model.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, rename_all = "camelCase")]
pub struct GroupImport {
    /// Declaration file (relative path), e.g. `tailsitter_plant.json`.
    pub file: String,
    /// The group of that file whose parameters are imported, e.g. `airframe`.
    pub group: String,
    /// The group the imported parameters form here (same Rust type), e.g. `design_airframe`.
    #[serde(rename = "as")]
    pub as_group: String,
    /// Text put before each imported description.
    #[serde(default)]
    pub description_prefix: String,
}

/// A fully resolved variable: declaration plus value reference and defaults applied.
#[derive(Debug, Clone, PartialEq)]
pub struct Variable {
    pub decl: VariableDecl,
    pub value_reference: u32,
    pub variability: Variability,
    pub display_unit: Option<String>,
}

impl Variable {
    pub fn name(&self) -> &str {
        &self.decl.name
    }

    /// Whether the XML carries a `start` attribute for this variable.
    pub fn has_start(&self) -> bool {
        self.decl.start.is_some()
    }
}

/// A fully resolved model declaration.
#[derive(Debug, Clone, PartialEq)]
pub struct Model {
    pub model_identifier: String,
    pub model_name: String,
    pub description: String,
    pub version: String,
    pub default_experiment: DefaultExperiment,
    pub groups: BTreeMap<String, String>,
    pub variables: Vec<Variable>,
    /// Every file read, for `cargo:rerun-if-changed`.
    pub sources: Vec<PathBuf>,
    /// Name-based UUID (v5) over the interface: changes whenever any variable,
    /// the identifier or the version changes.
    pub guid: String,
    /// The inputs every initial unknown depends on ([`DeclFile::initial_depends_on_inputs`]).
    pub initial_inputs: Vec<String>,
}

impl Model {
    /// (state, derivative) of every continuous state, in the order of the derivatives'
    /// declarations (= ModelStructure/Derivatives = the continuous-state vector).
    pub fn continuous_states(&self) -> Vec<(&Variable, &Variable)> {
        self.variables
            .iter()
            .filter_map(|d| {
                let state = d.decl.derivative_of.as_deref()?;
                let state = self.variables.iter().find(|v| v.name() == state)?;
                Some((state, d))
            })
            .collect()
    }

    /// Whether the FMU also offers Model Exchange: it declares continuous states.
    pub fn model_exchange(&self) -> bool {
        self.variables.iter().any(|v| v.decl.derivative_of.is_some())
    }

    /// 1-based index of the variable `name` in ModelVariables.
    pub fn index_of(&self, name: &str) -> Option<usize> {
        self.variables.iter().position(|v| v.name() == name).map(|i| i + 1)
    }

    /// ModelStructure/Outputs and /Derivatives: the unknowns, in ModelVariables order
    /// (Outputs) and in continuous-state order (Derivatives).
    pub fn outputs(&self) -> Vec<&Variable> {
        self.variables
            .iter()
            .filter(|v| v.decl.causality == Causality::Output)
            .collect()
    }

    /// ModelStructure/InitialUnknowns (FMI 2.0 §2.2.8): outputs and calculated parameters
    /// (none declares `initial`, so they are `calculated`) and the continuous states and
    /// their derivatives (the states here are outputs or locals without start value).
    pub fn initial_unknowns(&self) -> Vec<&Variable> {
        let states: BTreeSet<&str> = self.continuous_states().iter().map(|(s, _)| s.name()).collect();
        self.variables
            .iter()
            .filter(|v| {
                matches!(v.decl.causality, Causality::Output | Causality::CalculatedParameter)
                    || v.decl.derivative_of.is_some()
                    || states.contains(v.name())
            })
            .collect()
    }

    /// The `dependencies` of an output or a state derivative (indices into
    /// ModelVariables, ascending): the inputs and continuous states of its `dependsOn`
    /// ([`ALL_STATES`] expanded), and the output itself when it is a continuous state.
    pub fn dependencies(&self, v: &Variable) -> Vec<usize> {
        let states = self.continuous_states();
        let mut deps = BTreeSet::new();
        for name in &v.decl.depends_on {
            if name == ALL_STATES {
                deps.extend(states.iter().filter_map(|(s, _)| self.index_of(s.name())));
            } else {
                deps.extend(self.index_of(name));
            }
        }
        if states.iter().any(|(s, _)| s.name() == v.name()) {
            deps.extend(self.index_of(v.name()));
        }
        deps.into_iter().collect()
    }

    /// The `dependencies` of an initial unknown (indices, ascending). The knowns of
    /// Initialization Mode are the inputs and the variables with initial = "exact": here
    /// every parameter (all have a start value and no `initial`, so exact). An initial
    /// unknown depends on every parameter (conservative: the initial state is set, and
    /// the calculated parameters trimmed, from them) and on every input when the model
    /// names in `initialDependsOnInputs` ([`Self::initial_inputs`]) and on the inputs among
    /// its [`Self::dependencies`] (the states themselves are not knowns at initialisation).
    pub fn initial_dependencies(&self, v: &Variable) -> Vec<usize> {
        let direct: BTreeSet<usize> = self.dependencies(v).into_iter().collect();
        self.variables
            .iter()
            .enumerate()
            .filter(|(i, k)| match k.decl.causality {
                Causality::Parameter => true,
                Causality::Input => self.initial_inputs.contains(&k.decl.name) || direct.contains(&(i + 1)),
                _ => false,
            })
            .map(|(i, _)| i + 1)
            .collect()
    }

    /// [`Self::outputs`] and [`Self::initial_unknowns`] with their dependencies as value
    /// references: (unknown, knowns) pairs, for probes that check the declared structure
    /// against the real feedthrough of an FMU.
    pub fn structure_refs(&self) -> (Vec<UnknownRefs>, Vec<UnknownRefs>) {
        let vr = |i: usize| self.variables[i - 1].value_reference;
        let refs = |list: Vec<&Variable>, deps: &dyn Fn(&Variable) -> Vec<usize>| {
            list.into_iter()
                .map(|v| (v.value_reference, deps(v).into_iter().map(vr).collect()))
                .collect()
        };
        (
            refs(self.outputs(), &|v| self.dependencies(v)),
            refs(self.initial_unknowns(), &|v| self.initial_dependencies(v)),
        )
    }
}

/// An unknown of ModelStructure and the knowns it depends on, by value reference.
pub type UnknownRefs = (u32, Vec<u32>);

/// In a `dependsOn` list: every continuous state.
pub const ALL_STATES: &str = "@states";

/// Suffix of a group's type path in [`DeclFile::groups`]: the value starts from the
/// type's `Default` and only the declared fields are assigned.
pub const FROM_DEFAULT: &str = " { ..Default::default() }";

/// A group's Rust type and whether it is built on the type's `Default` ([`FROM_DEFAULT`]).
pub fn group_type(path: &str) -> (&str, bool) {
    match path.strip_suffix(FROM_DEFAULT) {
        Some(ty) => (ty, true),
        None => (path, false),
    }
}

/// Generation tool recorded in the XML.
pub const GENERATION_TOOL: &str = "tailsitter-fmus model-description generator";
/// Author recorded in the XML.
pub const AUTHOR: &str = "Tail-sitter FMU developers";
/// Log categories the export layer understands (kept equal to
/// `fmi2_export::LOG_CATEGORIES` by a test in each FMU crate).
pub const LOG_CATEGORIES: &[(&str, &str)] = &[
    (
        "logStatusWarning",
        "Warnings: saturation, fallbacks, recoverable problems",
    ),
    ("logStatusError", "Errors: illegal calls, bad arguments, failed steps"),
    ("logAll", "Everything, including debug messages"),
];

/// Load `<dir>/<model_identifier>.json`, resolve includes, assign value
/// references in declaration order, apply defaults and check everything.
pub fn load(dir: &Path, model_identifier: &str, version: &str) -> Result<Model, DeclError> {
    let path = dir.join(format!("{model_identifier}.json"));
    let mut sources = Vec::new();
    let root = read_decl(&path, &mut sources)?;
    let mut groups = BTreeMap::new();
    let mut decls = Vec::new();
    collect(dir, &root, &mut sources, &mut groups, &mut decls, 0)?;
    let id = root
        .model_identifier
        .clone()
        .ok_or_else(|| DeclError(format!("{}: missing modelIdentifier", path.display())))?;
    if id != model_identifier {
        return err(format!(
            "{}: modelIdentifier '{id}' does not match the file name",
            path.display()
        ));
    }
    let variables = decls
        .into_iter()
        .enumerate()
        .map(|(i, decl)| resolve(decl, i as u32))
        .collect::<Result<Vec<_>, _>>()?;
    let mut model = Model {
        model_identifier: id,
        model_name: root.model_name.clone().unwrap_or_else(|| model_identifier.to_string()),
        description: root.description.clone().unwrap_or_default(),
        version: version.to_string(),
        default_experiment: root
            .default_experiment
            .clone()
            .ok_or_else(|| DeclError(format!("{}: missing defaultExperiment", path.display())))?,
        groups,
        variables,
        sources,
        guid: String::new(),
        initial_inputs: Vec::new(),
    };
    model.initial_inputs = match root.initial_depends_on_inputs.clone() {
        None | Some(InitialInputs::All(false)) => Vec::new(),
        Some(InitialInputs::All(true)) => model
            .variables
            .iter()
            .filter(|v| v.decl.causality == Causality::Input)
            .map(|v| v.name().to_string())
            .collect(),
        Some(InitialInputs::Named(names)) => names,
    };
    check(&model)?;
    model.guid = guid_of(&model);
    Ok(model)
}

/// The variables of one declaration file (`<dir>/<file>`, a model or a fragment)
/// with its includes resolved, without the checks of a complete model: for the
/// build scripts that generate the defaults of a parameter group. Also returns
/// every file read, for `cargo:rerun-if-changed`.
pub fn load_declarations(dir: &Path, file: &str) -> Result<(Vec<VariableDecl>, Vec<PathBuf>), DeclError> {
    let mut sources = Vec::new();
    let root = read_decl(&dir.join(file), &mut sources)?;
    let mut groups = BTreeMap::new();
    let mut decls = Vec::new();
    collect(dir, &root, &mut sources, &mut groups, &mut decls, 0)?;
    Ok((decls, sources))
}

/// The named missions of the controller interface (`presets` of
/// `fragments/controller_interface.json`): name, description and the mission parameters
/// it sets over their declared starts, each checked to be a declared `mission` parameter.
pub fn load_presets(dir: &Path) -> Result<Vec<(String, Preset)>, DeclError> {
    let file = "fragments/controller_interface.json";
    let root = read_decl(&dir.join(file), &mut Vec::new())?;
    let (decls, _) = load_declarations(dir, file)?;
    for (name, preset) in &root.presets {
        for key in preset.values.keys() {
            if !decls
                .iter()
                .any(|d| &d.name == key && d.group.as_deref() == Some("mission"))
            {
                return err(format!("{file}: preset '{name}' sets '{key}', not a mission parameter"));
            }
        }
    }
    Ok(root.presets.into_iter().collect())
}

fn read_decl(path: &Path, sources: &mut Vec<PathBuf>) -> Result<DeclFile, DeclError> {
    let text = std::fs::read_to_string(path).map_err(|e| DeclError(format!("{}: {e}", path.display())))?;
    sources.push(path.to_path_buf());
    serde_json::from_str(&text).map_err(|e| DeclError(format!("{}: {e}", path.display())))
}

fn collect(
    dir: &Path,
    file: &DeclFile,
    sources: &mut Vec<PathBuf>,
    groups: &mut BTreeMap<String, String>,
    out: &mut Vec<VariableDecl>,
    depth: usize,
) -> Result<(), DeclError> {
    if depth > 8 {
        return err("include nesting deeper than 8 (a cycle?)");
    }
    for inc in &file.include {
        let sub = read_decl(&dir.join(inc), sources)?;
        collect(dir, &sub, sources, groups, out, depth + 1)?;
    }
    for (k, v) in &file.groups {
        if let Some(old) = groups.insert(k.clone(), v.clone()) {
            if &old != v {
                return err(format!("group '{k}' declared as both {old} and {v}"));
            }
        }
    }
    let own = out.len();
    out.extend(file.variables.iter().cloned());
    for link in &file.connect_groups {
        let src = read_decl(&dir.join(&link.file), sources)?;
        let mut src_groups = BTreeMap::new();
        let mut src_decls = Vec::new();
        collect(dir, &src, sources, &mut src_groups, &mut src_decls, depth + 1)?;
        for g in &link.groups {
            let ty = src_groups
                .get(g)
                .cloned()
                .ok_or_else(|| DeclError(format!("connectGroups: {} declares no group '{g}'", link.file)))?;
            if let Some(old) = groups.insert(g.clone(), ty.clone()) {
                if old != ty {
                    return err(format!("group '{g}' declared as both {old} and {ty}"));
                }
            }
            let mut linked = 0;
            for port in src_decls.iter().filter(|d| d.group.as_ref() == Some(g)) {
                if let Some(v) = out[own..].iter_mut().find(|v| v.name == port.name) {
                    if v.group.is_some() || v.field.is_some() {
                        return err(format!(
                            "variable '{}': its group comes from {} (connectGroups): declare none",
                            v.name, link.file
                        ));
                    }
                    v.group = Some(g.clone());
                    v.field = port.field.clone();
                    linked += 1;
                }
            }
            if linked == 0 {
                return err(format!(
                    "connectGroups: no variable connects to group '{g}' of {}",
                    link.file
                ));
            }
        }
    }
    for import in &file.import_groups {
        let src = read_decl(&dir.join(&import.file), sources)?;
        let mut src_groups = BTreeMap::new();
        let mut src_decls = Vec::new();
        collect(dir, &src, sources, &mut src_groups, &mut src_decls, depth + 1)?;
        let ty = src_groups
            .get(&import.group)
            .cloned()
            .ok_or_else(|| DeclError(format!("import: {} declares no group '{}'", import.file, import.group)))?;
        if let Some(old) = groups.insert(import.as_group.clone(), ty.clone()) {
            if old != ty {
                return err(format!("group '{}' declared as both {old} and {ty}", import.as_group));
            }
        }
        let before = out.len();
        out.extend(
            src_decls
                .into_iter()
                .filter(|d| d.group.as_deref() == Some(import.group.as_str()) && d.causality == Causality::Parameter)
                .map(|mut d| {
                    d.group = Some(import.as_group.clone());
                    d.description = format!("{}{}", import.description_prefix, d.description);
                    d
                }),
        );
        if out.len() == before {
            return err(format!(
                "import: group '{}' of {} has no parameters",
                import.group, import.file
            ));
        }
    }
    Ok(())
}

fn resolve(decl: VariableDecl, value_reference: u32) -> Result<Variable, DeclError> {
    let variability = decl.variability.unwrap_or(match (decl.causality, decl.var_type) {
        (Causality::Parameter | Causality::CalculatedParameter, _) => Variability::Fixed,
        (_, VarType::Real) => Variability::Continuous,
        _ => Variability::Discrete,
    });
    let display_unit = decl.display_unit.clone().or_else(|| match decl.unit.as_deref() {
        Some("rad") => Some("deg".to_string()),
        Some("rad/s") => Some("deg/s".to_string()),
        _ => None,
    });
    Ok(Variable {
        decl,
        value_reference,
        variability,
        display_unit,
    })
}

fn is_rust_identifier(s: &str) -> bool {
    let mut chars = s.chars();
    matches!(chars.next(), Some(c) if c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
        && !matches!(
            s,
            "type" | "fn" | "struct" | "impl" | "self" | "Self" | "move" | "ref" | "mod" | "use" | "let"
        )
}

/// Check the rules of FMI 2.0 (start/initial per causality, min ≤ start ≤ max, units known)
/// and our own (names are Rust identifiers, unique; dependencies name inputs or states;
/// groups declared).
fn check(model: &Model) -> Result<(), DeclError> {
    let mut names = BTreeSet::new();
    let inputs: BTreeSet<&str> = model
        .variables
        .iter()
        .filter(|v| v.decl.causality == Causality::Input)
        .map(|v| v.name())
        .collect();
    for i in &model.initial_inputs {
        if !inputs.contains(i.as_str()) {
            return err(format!("initialDependsOnInputs: '{i}' is not an input"));
        }
    }
    for v in &model.variables {
        let d = &v.decl;
        let n = &d.name;
        if !is_rust_identifier(n) {
            return err(format!("variable '{n}': name must be a Rust identifier"));
        }
        if !names.insert(n.as_str()) {
            return err(format!("variable '{n}' declared twice"));
        }
        if d.description.trim().is_empty() {
            return err(format!("variable '{n}': empty description"));
        }
        let needs_start = matches!(d.causality, Causality::Parameter | Causality::Input);
        let forbids_start = matches!(d.causality, Causality::CalculatedParameter | Causality::Output);
        if needs_start && d.start.is_none() {
            return err(format!("variable '{n}': {} needs a start value", d.causality.as_str()));
        }
        if forbids_start && d.start.is_some() {
            return err(format!(
                "variable '{n}': {} is calculated and takes no start value",
                d.causality.as_str()
            ));
        }
        match (d.causality, v.variability) {
            (Causality::Parameter | Causality::CalculatedParameter, Variability::Fixed | Variability::Tunable) => {}
            (Causality::Parameter | Causality::CalculatedParameter, other) => {
                return err(format!("variable '{n}': a parameter cannot be {}", other.as_str()));
            }
            (_, Variability::Fixed | Variability::Tunable) => {
                return err(format!("variable '{n}': only parameters are fixed or tunable"));
            }
            (_, Variability::Continuous) if d.var_type != VarType::Real => {
                return err(format!("variable '{n}': only Real variables can be continuous"));
            }
            _ => {}
        }
        match (&d.start, d.var_type) {
            (None, _) | (Some(Start::Number(_)), VarType::Real) | (Some(Start::Bool(_)), VarType::Boolean) => {}
            (Some(Start::Number(x)), VarType::Integer) if x.fract() == 0.0 && x.abs() <= i32::MAX as f64 => {}
            (Some(Start::Text(_)), VarType::String) => {}
            (Some(s), t) => return err(format!("variable '{n}': start {s:?} does not fit type {t:?}")),
        }
        if let (Some(lo), Some(hi)) = (d.min, d.max) {
            if lo > hi {
                return err(format!("variable '{n}': min {lo} > max {hi}"));
            }
        }
        if let Some(Start::Number(x)) = &d.start {
            if !x.is_finite() || d.min.is_some_and(|lo| *x < lo) || d.max.is_some_and(|hi| *x > hi) {
                return err(format!("variable '{n}': start {x} outside [min, max]"));
            }
        }
        if (d.min.is_some() || d.max.is_some()) && !matches!(d.var_type, VarType::Real | VarType::Integer) {
            return err(format!("variable '{n}': min/max only for Real and Integer"));
        }
        if let Some(u) = &d.unit {
            if d.var_type != VarType::Real {
                return err(format!("variable '{n}': unit only for Real"));
            }
            let unit = units::find(u).ok_or_else(|| DeclError(format!("variable '{n}': unknown unit '{u}'")))?;
            if let Some(du) = &v.display_unit {
                if !unit.display_units.iter().any(|x| x.name == du) {
                    return err(format!("variable '{n}': unit '{u}' has no display unit '{du}'"));
                }
            }
        } else if v.display_unit.is_some() {
            return err(format!("variable '{n}': displayUnit without unit"));
        }
        if !d.depends_on.is_empty() && d.causality != Causality::Output && d.derivative_of.is_none() {
            return err(format!(
                "variable '{n}': dependsOn only for outputs and state derivatives"
            ));
        }
        for dep in &d.depends_on {
            let state = dep == ALL_STATES
                || model
                    .variables
                    .iter()
                    .any(|o| o.decl.derivative_of.as_deref() == Some(dep.as_str()));
            if !inputs.contains(dep.as_str()) && !state {
                return err(format!(
                    "variable '{n}': dependsOn '{dep}' is neither an input nor a continuous state"
                ));
            }
        }
        if let Some(x) = d.nominal {
            if d.var_type != VarType::Real || !(x.is_finite() && x > 0.0) {
                return err(format!("variable '{n}': nominal must be a finite number > 0 on a Real"));
            }
        }
        if let Some(state) = &d.derivative_of {
            let Some(s) = model.variables.iter().find(|v| v.name() == state) else {
                return err(format!("variable '{n}': derivativeOf '{state}' is not declared"));
            };
            let continuous_real =
                |v: &Variable| v.decl.var_type == VarType::Real && v.variability == Variability::Continuous;
            if !continuous_real(v) || !matches!(d.causality, Causality::Local | Causality::Output) {
                return err(format!(
                    "variable '{n}': a derivative must be a continuous Real local or output"
                ));
            }
            if !continuous_real(s) || !matches!(s.decl.causality, Causality::Local | Causality::Output) {
                return err(format!(
                    "variable '{n}': state '{state}' must be a continuous Real local or output"
                ));
            }
            if s.decl.derivative_of.is_some() {
                return err(format!("variable '{n}': state '{state}' is itself a derivative"));
            }
            let twice = model
                .variables
                .iter()
                .filter(|o| o.decl.derivative_of.as_deref() == Some(state.as_str()))
                .count();
            if twice > 1 {
                return err(format!("state '{state}' has {twice} derivatives"));
            }
        }
        if let Some(g) = &d.group {
            if !model.groups.contains_key(g) {
                return err(format!("variable '{n}': group '{g}' not declared in \"groups\""));
            }
            if !matches!(
                d.causality,
                Causality::Parameter | Causality::CalculatedParameter | Causality::Input | Causality::Output
            ) {
                return err(format!(
                    "variable '{n}': a {} cannot belong to a group",
                    d.causality.as_str()
                ));
            }
            let written = |c: Causality| matches!(c, Causality::Output | Causality::CalculatedParameter);
            let writes = written(d.causality);
            let (top, _) = d.group_field()?;
            if top.contains('.') && !group_type(&model.groups[g]).1 && !writes {
                return err(format!(
                    "variable '{n}': a nested field needs a group built on its type's Default (\"{}{FROM_DEFAULT}\")",
                    model.groups[g]
                ));
            }
            if model
                .variables
                .iter()
                .any(|o| o.decl.group.as_ref() == Some(g) && written(o.decl.causality) != writes)
            {
                return err(format!(
                    "group '{g}' mixes outputs or calculated parameters with parameters or inputs (variable '{n}')"
                ));
            }
        } else if d.field.is_some() {
            return err(format!("variable '{n}': field without group"));
        }
    }
    Ok(())
}

/// A canonical text of the interface, hashed into the GUID.
fn guid_of(model: &Model) -> String {
    let mut text = format!("{}\n{}\n", model.model_identifier, model.version);
    for v in &model.variables {
        let d = &v.decl;
        text.push_str(&format!(
            "{}|{}|{:?}|{}|{}|{:?}|{:?}|{:?}|{:?}\n",
            v.value_reference,
            d.name,
            d.var_type,
            d.causality.as_str(),
            v.variability.as_str(),
            d.start,
            d.min,
            d.max,
            d.unit
        ));
        // Only when present, so the GUIDs of models without them do not change.
        if let Some(state) = &d.derivative_of {
            text.push_str(&format!("derivative_of {state}\n"));
        }
        if let Some(x) = d.nominal {
            text.push_str(&format!("nominal {x:?}\n"));
        }
    }
    let namespace = uuid::Uuid::NAMESPACE_URL;
    format!("{{{}}}", uuid::Uuid::new_v5(&namespace, text.as_bytes()))
}

/// Formats a number the way both the XML and the generated Rust need it:
/// the shortest text that parses back to the same `f64`.
pub fn fmt_f64(x: f64) -> String {
    // `{:?}` gives e.g. "1e-5" or "88.376": both valid xs:double and Rust literals.
    format!("{x:?}")
}
