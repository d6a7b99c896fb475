//! HTML tables of every port and parameter, for `documentation/index.html`.

use crate::{fmt_f64, Causality, Model, Start, VarType};
use quick_xml::escape::escape;
use std::fmt::Write;

/// One `<h2>` + `<table>` per causality, every variable with type, unit,
/// start, range, variability and description.
pub fn variable_tables(model: &Model) -> String {
    let mut out = String::new();
    let sections = [
        (Causality::Input, "Inputs"),
        (Causality::Output, "Outputs"),
        (Causality::Parameter, "Parameters"),
        (Causality::CalculatedParameter, "Calculated parameters"),
        (Causality::Local, "Locals"),
    ];
    for (causality, title) in sections {
        let vars: Vec<_> = model.variables.iter().filter(|v| v.decl.causality == causality).collect();
        if vars.is_empty() {
            continue;
        }
        let _ = writeln!(out, "<h2>{title} ({})</h2>", vars.len());
        let _ = writeln!(
            out,
            "<table>\n<tr><th>name</th><th>vr</th><th>type</th><th>unit</th><th>start</th><th>min</th><th>max</th><th>variability</th><th>description</th></tr>"
        );
        for v in vars {
            let d = &v.decl;
            let unit = match (&d.unit, &v.display_unit) {
                (Some(u), Some(du)) => format!("{u} (shown in {du})"),
                (Some(u), None) => u.clone(),
                _ => String::new(),
            };
            let num = |x: f64| if d.var_type == VarType::Integer { format!("{}", x as i64) } else { fmt_f64(x) };
            let start = match &d.start {
                Some(Start::Number(x)) => num(*x),
                Some(Start::Bool(b)) => b.to_string(),
                Some(Start::Text(s)) => s.clone(),
                None => "calculated".to_string(),
            };
            let _ = writeln!(
                out,
                "<tr><td><code>{}</code></td><td>{}</td><td>{:?}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
                escape(d.name.as_str()),
                v.value_reference,
                d.var_type,
                escape(unit.as_str()),
                escape(start.as_str()),
                d.min.map(num).unwrap_or_default(),
                d.max.map(num).unwrap_or_default(),
                v.variability.as_str(),
                escape(d.description.as_str())
            );
        }
        out.push_str("</table>\n");
    }
    out
}

/// Escape text for HTML.
pub fn escape_text(text: &str) -> String {
    escape(text).into_owned()
}
