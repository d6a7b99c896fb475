//! Project tasks, run as `cargo xtask <task>`:
//! - `dist`: build the FMU libraries in release mode and write `dist/<modelIdentifier>.fmu`
//!   (modelDescription.xml, binaries/linux64/<id>.so, documentation/index.html);
//! - `ssp`: write the SSP 1.0 closed-loop systems `dist/<controller>.ssp` from the packaged FMUs
//!   (`dist` writes them too);
//! - `regen`: rewrite the reviewed copies `modelDescription/generated/<id>.xml` and the
//!   variable references `modelDescription/generated/<id>.md`.

mod ssp;

use clap::{Parser, Subcommand};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::Command;

/// FMUs this workspace can package: (crate, modelIdentifier, Markdown files
/// rendered into documentation/index.html: the FMU's readme, then its library's equations).
const FMUS: &[(&str, &str, &[&str])] = &[
    (
        "fmu-plant",
        "tailsitter_plant",
        &["fmu-plant/README.md", "crates/tailsitter-physics/README.md"],
    ),
    (
        "fmu-lqr",
        "tailsitter_lqr",
        &["fmu-lqr/README.md", "crates/lqr-control/README.md"],
    ),
    (
        "fmu-tsd",
        "tailsitter_tsd",
        &["fmu-tsd/README.md", "crates/tsd-control/README.md"],
    ),
    (
        "fmu-sensors",
        "tailsitter_sensors",
        &["fmu-sensors/README.md", "crates/sensor-model/README.md"],
    ),
    (
        "fmu-ekf",
        "tailsitter_ekf",
        &["fmu-ekf/README.md", "crates/state-estimator/README.md"],
    ),
];

#[derive(Parser)]
#[command(about = "Tail-sitter FMU project tasks")]
struct Cli {
    #[command(subcommand)]
    task: Task,
}

#[derive(Subcommand)]
enum Task {
    /// Build release binaries and package dist/<modelIdentifier>.fmu.
    Dist {
        /// Only these models (modelIdentifier); default: all.
        #[arg(long, value_delimiter = ',')]
        only: Vec<String>,
        /// Output folder.
        #[arg(long, default_value = "dist")]
        out: PathBuf,
    },
    /// Write dist/<controller>.ssp (plant + controller closed loop, SSP 1.0) from the packaged FMUs.
    Ssp {
        /// Folder holding the FMUs; the SSPs are written there.
        #[arg(long, default_value = "dist")]
        out: PathBuf,
    },
    /// Regenerate modelDescription/generated/<id>.xml from the declarations.
    Regen,
}

fn workspace_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("xtask lives in the workspace")
        .to_path_buf()
}

/// `path` relative to the workspace root unless absolute.
fn absolute(path: &Path) -> PathBuf {
    if path.is_absolute() {
        path.to_path_buf()
    } else {
        workspace_root().join(path)
    }
}

fn load(id: &str) -> Result<model_description::Model, String> {
    model_description::load(
        &workspace_root().join("modelDescription"),
        id,
        env!("CARGO_PKG_VERSION"),
    )
    .map_err(|e| e.to_string())
}

fn main() {
    let cli = Cli::parse();
    let result = match cli.task {
        Task::Dist { only, out } => dist(&only, &out),
        Task::Ssp { out } => ssp::write_all(&absolute(&out)).map(|_| ()),
        Task::Regen => regen(),
    };
    if let Err(e) = result {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
}

fn regen() -> Result<(), String> {
    let dir = workspace_root().join("modelDescription/generated");
    std::fs::create_dir_all(&dir).map_err(|e| e.to_string())?;
    for (_, id, _) in FMUS {
        let model = load(id)?;
        let files = [
            (format!("{id}.xml"), model_description::xml::model_description(&model)),
            (
                format!("{id}.md"),
                model_description::html::variable_reference_markdown(&model),
            ),
        ];
        for (name, text) in files {
            let path = dir.join(name);
            std::fs::write(&path, text).map_err(|e| format!("{}: {e}", path.display()))?;
            println!("wrote {}", path.display());
        }
    }
    Ok(())
}

fn dist(only: &[String], out: &Path) -> Result<(), String> {
    let root = workspace_root();
    let selected: Vec<_> = FMUS
        .iter()
        .filter(|(_, id, _)| only.is_empty() || only.iter().any(|o| o == id))
        .collect();
    if selected.is_empty() {
        return Err(format!(
            "no FMU matches {only:?}; known: {:?}",
            FMUS.iter().map(|f| f.1).collect::<Vec<_>>()
        ));
    }
    let mut cargo = Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".into()));
    cargo.current_dir(&root).args(["build", "--release", "--locked"]);
    for (krate, _, _) in &selected {
        cargo.args(["-p", krate]);
    }
    let status = cargo.status().map_err(|e| format!("running cargo: {e}"))?;
    if !status.success() {
        return Err("cargo build --release failed".into());
    }
    let out = absolute(out);
    std::fs::create_dir_all(&out).map_err(|e| e.to_string())?;
    for (_, id, docs) in selected {
        let model = load(id)?;
        let lib = root.join(format!("target/release/lib{id}.so"));
        let binary = std::fs::read(&lib).map_err(|e| format!("{}: {e}", lib.display()))?;
        let mut readme = String::new();
        for doc in *docs {
            let path = root.join(doc);
            let text = std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
            readme.push_str(&text);
            readme.push_str("\n\n");
        }
        let path = out.join(format!("{id}.fmu"));
        write_fmu(&path, &model, &binary, &readme)?;
        println!(
            "wrote {} ({} variables, guid {})",
            path.display(),
            model.variables.len(),
            model.guid
        );
    }
    // The closed-loop systems of whatever FMUs the folder now holds.
    let has = |id: &str| out.join(format!("{id}.fmu")).exists();
    if has(ssp::PLANT) && ssp::CONTROLLERS.iter().any(|c| has(c)) {
        ssp::write_all(&out)?;
    }
    Ok(())
}

fn write_fmu(path: &Path, model: &model_description::Model, binary: &[u8], readme: &str) -> Result<(), String> {
    let file = std::fs::File::create(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut zip = zip::ZipWriter::new(file);
    let options = zip::write::SimpleFileOptions::default().compression_method(zip::CompressionMethod::Deflated);
    let id = &model.model_identifier;
    let entries: [(String, Vec<u8>); 3] = [
        (
            "modelDescription.xml".into(),
            model_description::xml::model_description(model).into_bytes(),
        ),
        (format!("binaries/linux64/{id}.so"), binary.to_vec()),
        (
            "documentation/index.html".into(),
            documentation(model, readme).into_bytes(),
        ),
    ];
    for (name, bytes) in entries {
        zip.start_file(name.as_str(), options)
            .map_err(|e| format!("{name}: {e}"))?;
        zip.write_all(&bytes).map_err(|e| format!("{name}: {e}"))?;
    }
    zip.finish().map_err(|e| e.to_string())?;
    Ok(())
}

/// documentation/index.html: the model's README (its equations) rendered from
/// Markdown, then a table of every port and parameter from the declaration.
fn documentation(model: &model_description::Model, readme: &str) -> String {
    let mut body = String::new();
    pulldown_cmark::html::push_html(
        &mut body,
        pulldown_cmark::Parser::new_ext(readme, pulldown_cmark::Options::all()),
    );
    format!(
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>{name}</title>\n<style>\
body{{font-family:sans-serif;max-width:70em;margin:2em auto;line-height:1.4}}\
table{{border-collapse:collapse;font-size:90%}}td,th{{border:1px solid #ccc;padding:2px 6px;vertical-align:top}}\
th{{background:#eee}}code{{background:#f4f4f4}}</style>\n</head>\n<body>\n<h1>{name}</h1>\n<p>modelIdentifier <code>{id}</code>, \
version {version}, GUID <code>{guid}</code>. FMI 2.0 Co-Simulation, linux64.</p>\n{body}\n{tables}</body>\n</html>\n",
        name = model_description::html::escape_text(&model.model_name),
        id = model.model_identifier,
        version = model.version,
        guid = model.guid,
        tables = model_description::html::variable_tables(model),
    )
}
