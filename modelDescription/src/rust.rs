//! Rust accessors generated from a declaration: included by each `fmu-*`
//! crate through `include!(concat!(env!("OUT_DIR"), "/variables.rs"))`.
//!
//! The module defines `Variables` (one public field per variable, named as
//! the variable), `vr::<name>` value-reference constants, the
//! `fmi2_export::VariableStore` implementation, `MODEL_IDENTIFIER`, `GUID`,
//! `MODEL_DESCRIPTION_XML`, and per group one `Variables::<group>()`
//! constructor (parameters, inputs) or `Variables::set_<group>()` (outputs).

use crate::{fmt_f64, Causality, Model, Start, VarType, Variable, VariableDecl};
use std::fmt::Write;

fn rust_type(t: VarType) -> &'static str {
    match t {
        VarType::Real => "f64",
        VarType::Integer => "i32",
        VarType::Boolean => "bool",
        VarType::String => "String",
    }
}

fn start_literal(d: &VariableDecl) -> String {
    match (&d.start, d.var_type) {
        (Some(Start::Number(x)), VarType::Real) => fmt_f64(*x),
        (Some(Start::Number(x)), VarType::Integer) => format!("{}", *x as i64),
        (Some(Start::Bool(b)), _) => b.to_string(),
        (Some(Start::Text(s)), _) => format!("String::from({s:?})"),
        (None, VarType::Real) => "0.0".into(),
        (None, VarType::Integer) => "0".into(),
        (None, VarType::Boolean) => "false".into(),
        (None, VarType::String) => "String::new()".into(),
        (Some(s), t) => unreachable!("checked at load: {s:?} for {t:?}"),
    }
}

/// `impl Variables { fn <group>() }` reading the parameters or inputs of a group
/// into its type, or `fn set_<group>()` writing the outputs of a group from it.
fn group_accessor(model: &Model, group: &str, path: &str) -> String {
    let members: Vec<&Variable> = model
        .variables
        .iter()
        .filter(|v| v.decl.group.as_deref() == Some(group))
        .collect();
    if members.is_empty() {
        return String::new();
    }
    let mut s = String::from("impl Variables {\n");
    let fields: Vec<(&str, Option<usize>, &str)> = members
        .iter()
        .map(|v| {
            let (top, index) = v.decl.group_field().expect("checked at load");
            (top, index, v.name())
        })
        .collect();
    let (ty, from_default) = crate::group_type(path);
    let path = ty;
    let causality = members[0].decl.causality;
    let written = matches!(causality, Causality::Output | Causality::CalculatedParameter);
    if written || causality == Causality::Input {
        let _ = writeln!(
            s,
            "    /// Set the variables of group `{group}` from a `{path}`.\n    #[allow(dead_code)]\n    pub fn set_{group}(&mut self, value: &{path}) {{"
        );
        for (top, index, name) in &fields {
            let sep = if top.is_empty() { "" } else { "." };
            let element = index.map(|i| format!("[{i}]")).unwrap_or_default();
            let _ = writeln!(s, "        self.{name} = value{sep}{top}{element}.into();");
        }
        s.push_str("    }\n");
    }
    if !written {
        let _ = writeln!(
            s,
            "    /// The `{path}` built from the variables of group `{group}`.\n    #[allow(dead_code)]\n    pub fn {group}(&self) -> {path} {{"
        );
        // Fields in order of first appearance; vector elements gathered into one array.
        let mut tops: Vec<&str> = Vec::new();
        for (top, _, _) in &fields {
            if !tops.contains(top) {
                tops.push(top);
            }
        }
        let value_of = |top: &str| -> String {
            let mut elements: Vec<(usize, &str)> = fields
                .iter()
                .filter(|(t, _, _)| *t == top)
                .map(|(_, i, n)| (i.unwrap_or(usize::MAX), *n))
                .collect();
            if elements.len() == 1 && elements[0].0 == usize::MAX {
                return format!("self.{}", elements[0].1);
            }
            elements.sort();
            assert!(
                elements.iter().enumerate().all(|(k, (i, _))| k == *i),
                "group '{group}': elements of '{top}' must be [0], [1], … once each"
            );
            let list: Vec<String> = elements.iter().map(|(_, n)| format!("self.{n}")).collect();
            format!("[{}].into()", list.join(", "))
        };
        if from_default {
            let _ = writeln!(s, "        let mut value = <{path}>::default();");
            for (top, index, name) in &fields {
                let sep = if top.is_empty() { "" } else { "." };
                let element = index.map(|i| format!("[{i}]")).unwrap_or_default();
                let _ = writeln!(s, "        value{sep}{top}{element} = self.{name};");
            }
            let _ = writeln!(s, "        value");
        } else if tops == [""] {
            let _ = writeln!(s, "        let value: {path} = {};\n        value", value_of(""));
        } else {
            let _ = writeln!(s, "        {path} {{");
            for top in &tops {
                let _ = writeln!(s, "            {top}: {},", value_of(top));
            }
            let _ = writeln!(s, "        }}");
        }
        s.push_str("    }\n");
    }
    s.push_str("}\n");
    s
}

fn bound(x: Option<f64>, default: &str) -> String {
    x.map(fmt_f64).unwrap_or_else(|| default.to_string())
}

/// The generated module text. `xml_file` is the path `include_str!` reads the
/// generated modelDescription.xml from.
pub fn variables_module(model: &Model, xml_file: &str) -> String {
    let mut s = String::new();
    let w = &mut s;
    // The header and the value store.
    let _ = writeln!(
        w,
        "// @generated by build.rs from modelDescription/{id}.json: do not edit.\n\
         use fmi2_export::{{Causality, StateError, StateReader, StateWriter, ValueType, Variability, VariableSpec, VariableStore}};\n\n\
         /// `modelIdentifier` of this FMU.\npub const MODEL_IDENTIFIER: &str = {id:?};\n\
         /// GUID of this FMU's interface (UUID v5 over the declaration).\npub const GUID: &str = {guid:?};\n\
         /// The generated modelDescription.xml.\npub const MODEL_DESCRIPTION_XML: &str = include_str!({xml_file:?});\n\n\
         /// Current value of every variable of `{id}`, one field each.\n\
         #[allow(non_snake_case)]\n#[derive(Debug, Clone, PartialEq)]\npub struct Variables {{",
        id = model.model_identifier,
        guid = model.guid,
    );
    for v in &model.variables {
        let d = &v.decl;
        let unit = d.unit.as_deref().map(|u| format!(" ({u})")).unwrap_or_default();
        let _ = writeln!(w, "    /// {} ({}){unit}", d.description, d.causality.as_str());
        let _ = writeln!(w, "    pub {}: {},", d.name, rust_type(d.var_type));
    }
    let _ = writeln!(w, "}}\n");

    // Value references.
    let _ = writeln!(w, "/// Value reference of every variable, named as the variable.\n#[allow(non_upper_case_globals, dead_code)]\npub mod vr {{");
    for v in &model.variables {
        let _ = writeln!(w, "    pub const {}: u32 = {};", v.name(), v.value_reference);
    }
    let _ = writeln!(w, "}}\n");

    // Groups.
    for (group, path) in &model.groups {
        let _ = writeln!(w, "{}", group_accessor(model, group, path));
    }

    // VariableStore.
    let _ = writeln!(w, "impl VariableStore for Variables {{");
    let _ = writeln!(w, "    const MODEL_IDENTIFIER: &'static str = MODEL_IDENTIFIER;");
    let _ = writeln!(w, "    const GUID: &'static str = GUID;");
    let _ = writeln!(w, "    const VARIABLES: &'static [VariableSpec] = &[");
    for v in &model.variables {
        let d = &v.decl;
        let _ = writeln!(
            w,
            "        VariableSpec {{ name: {:?}, value_reference: {}, value_type: ValueType::{:?}, causality: Causality::{}, variability: Variability::{}, min: {}, max: {}, unit: {:?}, description: {:?} }},",
            d.name,
            v.value_reference,
            d.var_type,
            d.causality.rust_variant(),
            v.variability.rust_variant(),
            bound(d.min, "f64::NEG_INFINITY"),
            bound(d.max, "f64::INFINITY"),
            d.unit.as_deref().unwrap_or(""),
            d.description
        );
    }
    let _ = writeln!(w, "    ];\n");
    let states = model.continuous_states();
    if !states.is_empty() {
        let _ = writeln!(
            w,
            "    const CONTINUOUS_STATES: &'static [fmi2_export::ContinuousState] = &["
        );
        for (s, d) in states {
            let _ = writeln!(
                w,
                "        fmi2_export::ContinuousState {{ state: {}, derivative: {}, nominal: {} }},",
                s.value_reference,
                d.value_reference,
                fmt_f64(s.decl.nominal.unwrap_or(1.0))
            );
        }
        let _ = writeln!(w, "    ];\n");
    }
    let _ = writeln!(w, "    fn with_start_values() -> Self {{\n        Self {{");
    for v in &model.variables {
        let _ = writeln!(w, "            {}: {},", v.name(), start_literal(&v.decl));
    }
    let _ = writeln!(w, "        }}\n    }}\n");
    let _ = writeln!(
        w,
        "    fn index_of(value_reference: u32) -> Option<usize> {{\n        // Value references are assigned in declaration order.\n        let i = value_reference as usize;\n        (i < Self::VARIABLES.len()).then_some(i)\n    }}\n"
    );
    accessors(w, model, VarType::Real, "real", "f64", "Some(self.{})");
    accessors(w, model, VarType::Integer, "integer", "i32", "Some(self.{})");
    accessors(w, model, VarType::Boolean, "boolean", "bool", "Some(self.{})");
    accessors(w, model, VarType::String, "string", "&str", "Some(self.{}.as_str())");

    let _ = writeln!(w, "    fn write_state(&self, w: &mut StateWriter) {{");
    for v in &model.variables {
        let call = match v.decl.var_type {
            VarType::Real => "f64",
            VarType::Integer => "i32",
            VarType::Boolean => "bool",
            VarType::String => "str",
        };
        let arg = if v.decl.var_type == VarType::String {
            format!("&self.{}", v.name())
        } else {
            format!("self.{}", v.name())
        };
        let _ = writeln!(w, "        w.{call}({arg});");
    }
    let _ = writeln!(w, "    }}\n");
    let _ = writeln!(
        w,
        "    fn read_state(&mut self, r: &mut StateReader<'_>) -> Result<(), StateError> {{"
    );
    for v in &model.variables {
        let call = match v.decl.var_type {
            VarType::Real => "r.f64()?",
            VarType::Integer => "r.i32()?",
            VarType::Boolean => "r.bool()?",
            VarType::String => "r.str()?.into()",
        };
        let _ = writeln!(w, "        self.{} = {call};", v.name());
    }
    let _ = writeln!(w, "        Ok(())\n    }}\n}}");
    let _ = writeln!(w, "{}", DECLARATION_TESTS);
    s
}

/// Unit tests emitted into every generated module: the Rust accessors agree
/// with the generated modelDescription.xml read back through fmi-schema
/// (names, value references, types, causality, variability, descriptions,
/// start values) and every variable can be written and read as declared.
/// Each `fmu-*` crate needs `fmi-schema` as a dev-dependency.
const DECLARATION_TESTS: &str = r#"
#[cfg(test)]
mod declaration_tests {
    use super::*;
    use fmi_schema::fmi2::{Fmi2ModelDescription, ScalarVariableElement as E};

    fn others_unchanged(store: &Variables, start: &Variables, except: u32) {
        for spec in Variables::VARIABLES.iter().filter(|s| s.value_reference != except) {
            let vr = spec.value_reference;
            assert_eq!(store.get_real(vr), start.get_real(vr), "{} changed", spec.name);
            assert_eq!(store.get_integer(vr), start.get_integer(vr), "{} changed", spec.name);
            assert_eq!(store.get_boolean(vr), start.get_boolean(vr), "{} changed", spec.name);
            assert_eq!(store.get_string(vr), start.get_string(vr), "{} changed", spec.name);
        }
    }

    #[test]
    fn accessors_agree_with_the_model_description() {
        let md: Fmi2ModelDescription = fmi_schema::deserialize(MODEL_DESCRIPTION_XML).expect("generated XML parses");
        assert_eq!(md.guid, GUID);
        assert_eq!(md.co_simulation.as_ref().expect("CoSimulation").model_identifier, MODEL_IDENTIFIER);
        let xml: Vec<_> = md.get_model_variables().collect();
        assert_eq!(xml.len(), Variables::VARIABLES.len());
        let start = Variables::with_start_values();
        for (x, spec) in xml.iter().zip(Variables::VARIABLES) {
            let vr = spec.value_reference;
            assert_eq!(x.name, spec.name);
            assert_eq!(x.value_reference, vr, "{}", spec.name);
            assert_eq!(Variables::index_of(vr).map(|i| Variables::VARIABLES[i].name), Some(spec.name));
            assert_eq!(x.description.as_deref(), Some(spec.description), "{}", spec.name);
            assert_eq!(format!("{:?}", x.causality), format!("{:?}", spec.causality), "{}", spec.name);
            assert_eq!(format!("{:?}", x.variability.expect("variability")), format!("{:?}", spec.variability), "{}", spec.name);
            let mut store = start.clone();
            match (&x.elem, spec.value_type) {
                (E::Real(r), ValueType::Real) => {
                    if let Some(s) = r.start {
                        assert_eq!(start.get_real(vr), Some(s), "{} start", spec.name);
                    }
                    let v = start.get_real(vr).expect("a Real") + 0.5;
                    assert!(store.set_real(vr, v), "{}", spec.name);
                    assert_eq!(store.get_real(vr), Some(v));
                    assert!(!store.set_integer(vr, 1) && store.get_integer(vr).is_none(), "{} is not an Integer", spec.name);
                }
                (E::Integer(i), ValueType::Integer) => {
                    if let Some(s) = i.start {
                        assert_eq!(start.get_integer(vr), Some(s), "{} start", spec.name);
                    }
                    let v = start.get_integer(vr).expect("an Integer").wrapping_add(1);
                    assert!(store.set_integer(vr, v), "{}", spec.name);
                    assert_eq!(store.get_integer(vr), Some(v));
                    assert!(!store.set_real(vr, 1.0) && store.get_real(vr).is_none(), "{} is not a Real", spec.name);
                }
                (E::Boolean(_), ValueType::Boolean) => {
                    let v = !start.get_boolean(vr).expect("a Boolean");
                    assert!(store.set_boolean(vr, v));
                    assert_eq!(store.get_boolean(vr), Some(v));
                }
                (E::String, ValueType::String) => {
                    assert!(store.set_string(vr, "changed"));
                    assert_eq!(store.get_string(vr), Some("changed"));
                }
                (e, t) => panic!("{}: XML element {e:?} but declared {t:?}", spec.name),
            }
            others_unchanged(&store, &start, vr);
        }
        let unknown = Variables::VARIABLES.len() as u32 + 1000;
        assert!(Variables::index_of(unknown).is_none());
        assert!(start.get_real(unknown).is_none() && start.get_integer(unknown).is_none());
    }

    #[test]
    fn embedded_xml_is_the_reviewed_copy() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../modelDescription/generated/");
        let reviewed = std::fs::read_to_string(format!("{path}{MODEL_IDENTIFIER}.xml")).expect("reviewed XML (cargo xtask regen)");
        assert!(reviewed == MODEL_DESCRIPTION_XML, "modelDescription/generated/{MODEL_IDENTIFIER}.xml drifted: run `cargo xtask regen`");
    }

    #[test]
    fn state_round_trips() {
        let mut a = Variables::with_start_values();
        for spec in Variables::VARIABLES {
            if spec.value_type == ValueType::Real {
                a.set_real(spec.value_reference, spec.value_reference as f64 * 0.25 - 3.0);
            }
        }
        let mut w = StateWriter::new();
        a.write_state(&mut w);
        let bytes = w.into_bytes();
        let mut b = Variables::with_start_values();
        let mut r = StateReader::new(&bytes);
        b.read_state(&mut r).expect("read back");
        r.finish().expect("nothing left over");
        assert_eq!(a, b);
    }
}
"#;

fn accessors(w: &mut String, model: &Model, t: VarType, suffix: &str, ty: &str, get_expr: &str) {
    let vars: Vec<&Variable> = model.variables.iter().filter(|v| v.decl.var_type == t).collect();
    let _ = writeln!(w, "    fn get_{suffix}(&self, value_reference: u32) -> Option<{ty}> {{");
    if vars.is_empty() {
        let _ = writeln!(w, "        let _ = value_reference;\n        None\n    }}\n");
    } else {
        let _ = writeln!(w, "        match value_reference {{");
        for v in &vars {
            let _ = writeln!(
                w,
                "            {} => {},",
                v.value_reference,
                get_expr.replace("{}", v.name())
            );
        }
        let _ = writeln!(w, "            _ => None,\n        }}\n    }}\n");
    }
    let set_ty = if t == VarType::String { "&str" } else { ty };
    let _ = writeln!(
        w,
        "    fn set_{suffix}(&mut self, value_reference: u32, value: {set_ty}) -> bool {{"
    );
    if vars.is_empty() {
        let _ = writeln!(w, "        let _ = (value_reference, value);\n        false\n    }}\n");
    } else {
        let _ = writeln!(w, "        match value_reference {{");
        for v in &vars {
            let assign = if t == VarType::String {
                "value.to_string()"
            } else {
                "value"
            };
            let _ = writeln!(w, "            {} => self.{} = {assign},", v.value_reference, v.name());
        }
        let _ = writeln!(w, "            _ => return false,\n        }}\n        true\n    }}\n");
    }
}

/// The Rust items a pure crate generates from the declaration of one of its
/// parameter structs (`type_name`, parameters of `group`): `impl Default` with
/// the declared start values and `named_values()`, every field with its
/// parameter name in declaration order (Real groups only). `source` names the
/// declaration in the `@generated` header.
pub fn group_defaults(decls: &[VariableDecl], group: &str, type_name: &str, source: &str) -> String {
    let members: Vec<&VariableDecl> = decls
        .iter()
        .filter(|d| d.group.as_deref() == Some(group) && d.causality == Causality::Parameter)
        .collect();
    assert!(!members.is_empty(), "{source}: no parameter in group '{group}'");
    let mut s = String::new();
    let w = &mut s;
    let _ = writeln!(
        w,
        "// @generated by build.rs from {source} (group `{group}`): do not edit.\n"
    );
    let _ = writeln!(
        w,
        "impl Default for {type_name} {{\n    /// The start values declared in {source}.\n    fn default() -> Self {{\n        Self {{"
    );
    for d in &members {
        let _ = writeln!(w, "            {}: {},", field_of(d), start_literal(d));
    }
    let _ = writeln!(w, "        }}\n    }}\n}}\n");
    if members.iter().all(|d| d.var_type == VarType::Real) {
        let _ = writeln!(
            w,
            "impl {type_name} {{\n    /// Every field with its parameter name, in declaration order.\n    pub fn named_values(&self) -> [(&'static str, f64); {}] {{\n        [",
            members.len()
        );
        for d in &members {
            let _ = writeln!(w, "            ({:?}, self.{}),", d.name, field_of(d));
        }
        let _ = writeln!(w, "        ]\n    }}\n");
        let _ = writeln!(
            w,
            "    /// Every field, mutably, with its parameter name, in declaration order (set by name).\n    pub fn named_values_mut(&mut self) -> [(&'static str, &mut f64); {}] {{\n        [",
            members.len()
        );
        for d in &members {
            let _ = writeln!(w, "            ({:?}, &mut self.{}),", d.name, field_of(d));
        }
        let _ = writeln!(w, "        ]\n    }}\n}}");
    }
    s
}

/// `impl Default for <type_name>` with the declared start values of the parameters of
/// `group` whose field lies under `prefix` (`""`: the group's own fields; `"earth"`: the
/// fields `earth.*`, without the prefix). Vector elements `f[i]` are gathered into
/// `[..].into()`. `extra` lists the struct's fields that no parameter of the group sets,
/// as (field, Rust expression), e.g. the start of an ungrouped parameter ([`start_of`]).
pub fn struct_defaults(
    decls: &[VariableDecl],
    group: &str,
    prefix: &str,
    type_name: &str,
    source: &str,
    extra: &[(&str, String)],
) -> String {
    // Per field in order of first appearance: (element index, start literal) of each parameter.
    type Elements = Vec<(Option<usize>, String)>;
    let mut fields: Vec<(String, Elements)> = Vec::new();
    for d in decls
        .iter()
        .filter(|d| d.group.as_deref() == Some(group) && d.causality == Causality::Parameter)
    {
        let (top, index) = d.group_field().expect("checked at load");
        let field = if prefix.is_empty() {
            top
        } else {
            match top.strip_prefix(prefix).and_then(|f| f.strip_prefix('.')) {
                Some(f) => f,
                None => continue,
            }
        };
        assert!(
            !field.contains('.'),
            "{source}: field '{top}' is nested below '{prefix}'"
        );
        match fields.iter_mut().find(|(f, _)| f == field) {
            Some((_, elements)) => elements.push((index, start_literal(d))),
            None => fields.push((field.to_string(), vec![(index, start_literal(d))])),
        }
    }
    assert!(
        !fields.is_empty(),
        "{source}: no parameter in group '{group}' under '{prefix}'"
    );
    let mut s = String::new();
    let w = &mut s;
    let under = if prefix.is_empty() {
        String::new()
    } else {
        format!(", fields `{prefix}.*`")
    };
    let _ = writeln!(
        w,
        "// @generated by build.rs from {source} (group `{group}`{under}): do not edit.\n"
    );
    let _ = writeln!(
        w,
        "impl Default for {type_name} {{\n    /// The start values declared in {source}.\n    fn default() -> Self {{\n        Self {{"
    );
    for (field, mut elements) in fields {
        if let [(None, value)] = elements.as_slice() {
            let _ = writeln!(w, "            {field}: {value},");
            continue;
        }
        elements.sort_by_key(|(i, _)| i.unwrap_or(usize::MAX));
        assert!(
            elements.iter().enumerate().all(|(k, (i, _))| *i == Some(k)),
            "{source}: elements of '{field}' must be [0], [1], … once each"
        );
        let list: Vec<&str> = elements.iter().map(|(_, v)| v.as_str()).collect();
        let _ = writeln!(w, "            {field}: [{}].into(),", list.join(", "));
    }
    for (field, expr) in extra {
        let _ = writeln!(w, "            {field}: {expr},");
    }
    let _ = writeln!(w, "        }}\n    }}\n}}");
    s
}

/// The declared start value of variable `name` as a Rust literal.
pub fn start_of(decls: &[VariableDecl], name: &str) -> String {
    let d = decls
        .iter()
        .find(|d| d.name == name)
        .unwrap_or_else(|| panic!("no variable '{name}'"));
    start_literal(d)
}

/// `impl <type_name> { fn named_values(), fn first_non_finite() }`: the variables of `group`
/// (declaration order) with their fields in a `type_name`, and the name of the first whose
/// value is not finite.
pub fn group_first_non_finite(decls: &[VariableDecl], group: &str, type_name: &str, source: &str) -> String {
    let members: Vec<&VariableDecl> = decls.iter().filter(|d| d.group.as_deref() == Some(group)).collect();
    let mut s = format!(
        "// @generated by build.rs from {source} (group `{group}`): do not edit.\n\nimpl {type_name} {{\n    /// The values with their port names (declaration order).\n    pub fn named_values(&self) -> [(&'static str, f64); {}] {{\n        [\n",
        members.len()
    );
    for d in members {
        let (top, index) = d.group_field().expect("checked field");
        let sep = if top.is_empty() { "" } else { "." };
        let element = index.map(|i| format!("[{i}]")).unwrap_or_default();
        let _ = writeln!(s, "            ({:?}, self{sep}{top}{element}),", d.name);
    }
    s.push_str("        ]\n    }\n\n    /// The port name of the first value that is not finite, if any (declaration order).\n    pub fn first_non_finite(&self) -> Option<&'static str> {\n        self.named_values().into_iter().find(|(_, value)| !value.is_finite()).map(|(name, _)| name)\n    }\n}\n");
    s
}

/// `pub const <NAME>: [&str; n]`: the names of the variables of `group`, in declaration order.
pub fn group_names(decls: &[VariableDecl], group: &str, const_name: &str, doc: &str) -> String {
    let names: Vec<String> = decls
        .iter()
        .filter(|d| d.group.as_deref() == Some(group))
        .map(|d| format!("{:?}", d.name))
        .collect();
    format!(
        "/// {doc}\npub const {const_name}: [&str; {}] = [{}];\n",
        names.len(),
        names.join(", ")
    )
}

/// The struct field of a scalar parameter (its `field`, or its name).
fn field_of(d: &VariableDecl) -> &str {
    match d.group_field() {
        Ok((top, None)) if !top.is_empty() => top,
        _ => panic!("parameter '{}': a parameter group needs scalar fields", d.name),
    }
}

/// `pub const PRESETS`: the named missions of the controller interface as
/// (name, description, [(parameter, value)]) over the declared starts, for
/// `MissionParams::preset`.
pub fn mission_presets(presets: &[(String, crate::Preset)], source: &str) -> String {
    let mut s = format!("// @generated by build.rs from {source} (`presets`): do not edit.\n\n");
    s.push_str("/// A named mission: (name, description, the parameters set over their declared starts).\n");
    s.push_str("pub type Preset = (&'static str, &'static str, &'static [(&'static str, f64)]);\n\n");
    s.push_str("/// The named missions declared beside the mission parameters.\n");
    s.push_str("pub const PRESETS: &[Preset] = &[\n");
    for (name, p) in presets {
        let values: Vec<String> = p
            .values
            .iter()
            .map(|(k, v)| format!("({k:?}, {})", fmt_f64(*v)))
            .collect();
        let _ = writeln!(s, "    ({name:?}, {:?}, &[{}]),", p.description, values.join(", "));
    }
    s.push_str("];\n");
    s
}
