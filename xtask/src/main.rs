//! Project tasks, run as `cargo xtask <task>`:
//! - `dist`: build the FMU libraries in release mode for linux64 (x86_64-unknown-linux-gnu
//!   linked against glibc 2.17 by cargo-zigbuild) and win64 (x86_64-pc-windows-gnu,
//!   cross-linked with MinGW-w64) and write `dist/<modelIdentifier>.fmu`
//!   (modelDescription.xml, binaries/linux64/<id>.so, binaries/win64/<id>.dll,
//!   documentation/index.html); with the platform aarch64-linux also the separate ARM
//!   archives `dist/aarch64-linux/<modelIdentifier>.fmu` (see [`Platform::Aarch64Linux`]);
//!   and the FMI 3.0 archives `dist/fmi3/<modelIdentifier>.fmu` holding every platform's
//!   library (the same libraries; see [`fmi3`]);
//! - `ssp`: write the SSP 1.0 closed-loop systems `dist/<controller>.ssp` from the packaged FMUs
//!   (`dist` writes them too);
//! - `regen`: rewrite the reviewed copies `modelDescription/generated/<id>.xml`, the
//!   variable references `modelDescription/generated/<id>.md`, the generated Rust
//!   parameter defaults `modelDescription/generated/*_generated.rs` and the Python
//!   declarations `python/tailsim/declarations.json`.

mod fmi3;
mod ssp;

use clap::{Parser, Subcommand};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::Command;

/// An FMU this workspace packages: every `fmu-<name>` crate with a `[package.metadata.fmu]`
/// table in its Cargo.toml is one, with
/// modelIdentifier `tailsitter_<name>` (declared in `modelDescription/tailsitter_<name>.json`)
/// and the Markdown rendered into its documentation/index.html: the crate's README, then the
/// files listed under `[package.metadata.fmu] documentation` in its Cargo.toml (its
/// library's equations). A new FMU is found by its crate alone.
struct FmuCrate {
    krate: String,
    id: String,
    docs: Vec<PathBuf>,
}

/// The FMU crates of the workspace (`cargo metadata`), the plant first, then by name.
fn fmus() -> Result<Vec<FmuCrate>, String> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let out = Command::new(cargo)
        .args([
            "metadata",
            "--no-deps",
            "--format-version",
            "1",
            "--locked",
            "--offline",
        ])
        .current_dir(workspace_root())
        .output()
        .map_err(|e| format!("cargo metadata: {e}"))?;
    if !out.status.success() {
        return Err(format!("cargo metadata: {}", String::from_utf8_lossy(&out.stderr)));
    }
    let meta: serde_json::Value =
        serde_json::from_slice(&out.stdout).map_err(|e| format!("cargo metadata output: {e}"))?;
    let mut found = Vec::new();
    for p in meta["packages"].as_array().into_iter().flatten() {
        // An FMU crate says so with its `[package.metadata.fmu]` table.
        if p["metadata"]["fmu"].is_null() {
            continue;
        }
        let name = p["name"].as_str().unwrap_or_default();
        let short = name
            .strip_prefix("fmu-")
            .ok_or_else(|| format!("{name}: an FMU crate is named fmu-<name>"))?;
        let dir = PathBuf::from(p["manifest_path"].as_str().unwrap_or_default())
            .parent()
            .map(Path::to_path_buf)
            .unwrap_or_default();
        let mut docs = vec![dir.join("README.md")];
        for d in p["metadata"]["fmu"]["documentation"].as_array().into_iter().flatten() {
            docs.push(dir.join(d.as_str().ok_or("[package.metadata.fmu] documentation: not a string")?));
        }
        found.push(FmuCrate {
            krate: format!("fmu-{short}"),
            id: format!("tailsitter_{}", short.replace('-', "_")),
            docs,
        });
    }
    found.sort_by_key(|f| (f.id != ssp::PLANT, f.id.clone()));
    Ok(found)
}

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
        /// Platforms to build and pack (FMI 2.0 folder names, and aarch64-linux).
        #[arg(long, value_delimiter = ',', default_value = "linux64,win64,aarch64-linux")]
        platforms: Vec<Platform>,
    },
    /// Write dist/<controller>.ssp (plant + controller closed loop, SSP 1.0) from the packaged FMUs.
    Ssp {
        /// Folder holding the FMUs; the SSPs are written there.
        #[arg(long, default_value = "dist")]
        out: PathBuf,
    },
    /// Regenerate modelDescription/generated/ (XML, variable references, Rust defaults) from the declarations.
    Regen,
}

/// A binary platform of an FMI 2.0 archive.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
enum Platform {
    /// `binaries/linux64/<id>.so` of `dist/<id>.fmu`: x86_64-unknown-linux-gnu, linked
    /// against glibc 2.17 (the manylinux2014 baseline) by cargo-zigbuild.
    Linux64,
    /// `binaries/win64/<id>.dll` of `dist/<id>.fmu`: cross-built for x86_64-pc-windows-gnu.
    Win64,
    /// aarch64-unknown-linux-gnu, glibc 2.17, by cargo-zigbuild. FMI 2.0 names no ARM
    /// platform folder and an importer on ARM Linux looks in `linux64` (fmpy does), so
    /// these go into separate archives `<out>/aarch64-linux/<id>.fmu` whose
    /// `binaries/linux64/<id>.so` is the aarch64 library; `dist/<id>.fmu` never holds it.
    #[value(name = "aarch64-linux")]
    Aarch64Linux,
}

/// The Rust target of the win64 binaries (GNU ABI: links with Debian's MinGW-w64, no MSVC).
const WIN64_TARGET: &str = "x86_64-pc-windows-gnu";
/// The MinGW-w64 C compiler rustc links win64 binaries with (Debian `gcc-mingw-w64-x86-64`).
const MINGW_GCC: &str = "x86_64-w64-mingw32-gcc";
/// The oldest glibc the Linux binaries load on: they are linked against its symbol
/// versions (cargo-zigbuild's `<target>.<glibc>` suffix), so no `GLIBC_x.y` they need is
/// newer (tests/test_glibc.py checks every packaged library).
const GLIBC: &str = "2.17";

impl Platform {
    /// Folder under `binaries/` and file name of the library of model `id`.
    fn archive_path(self, id: &str) -> String {
        match self {
            Platform::Linux64 | Platform::Aarch64Linux => format!("binaries/linux64/{id}.so"),
            Platform::Win64 => format!("binaries/win64/{id}.dll"),
        }
    }

    /// The Rust target triple.
    fn target(self) -> &'static str {
        match self {
            Platform::Linux64 => "x86_64-unknown-linux-gnu",
            Platform::Win64 => WIN64_TARGET,
            Platform::Aarch64Linux => "aarch64-unknown-linux-gnu",
        }
    }

    /// Where cargo writes the release library of model `id`.
    fn built_path(self, root: &Path, id: &str) -> PathBuf {
        let dir = root.join("target").join(self.target()).join("release");
        match self {
            Platform::Linux64 | Platform::Aarch64Linux => dir.join(format!("lib{id}.so")),
            Platform::Win64 => dir.join(format!("{id}.dll")),
        }
    }

    /// The archive this platform's binaries go into, under the output folder.
    fn archive_folder(self, out: &Path) -> PathBuf {
        match self {
            Platform::Linux64 | Platform::Win64 => out.to_path_buf(),
            Platform::Aarch64Linux => out.join("aarch64-linux"),
        }
    }
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
        Task::Dist { only, out, platforms } => dist(&only, &out, &platforms),
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
    for FmuCrate { id, .. } in &fmus()? {
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
    let declarations = workspace_root().join("modelDescription");
    for c in model_description::defaults::CRATES {
        let (text, _) =
            model_description::defaults::generate(&declarations, c).map_err(|e| format!("{}: {e}", c.file))?;
        let path = dir.join(c.out);
        std::fs::write(&path, text).map_err(|e| format!("{}: {e}", path.display()))?;
        println!("wrote {}", path.display());
    }
    let root = workspace_root();
    let path = root.join(model_description::python::MODULE_PATH);
    let text =
        model_description::python::declarations_module(&root.join("modelDescription"), env!("CARGO_PKG_VERSION"))
            .map_err(|e| e.to_string())?;
    std::fs::write(&path, text).map_err(|e| format!("{}: {e}", path.display()))?;
    println!("wrote {}", path.display());
    Ok(())
}

fn dist(only: &[String], out: &Path, platforms: &[Platform]) -> Result<(), String> {
    let root = workspace_root();
    let all = fmus()?;
    let selected: Vec<_> = all.iter().filter(|f| only.is_empty() || only.contains(&f.id)).collect();
    if selected.is_empty() {
        return Err(format!(
            "no FMU matches {only:?}; known: {:?}",
            all.iter().map(|f| &f.id).collect::<Vec<_>>()
        ));
    }
    if platforms.is_empty() {
        return Err("--platforms is empty".into());
    }
    for platform in platforms {
        build(&root, &selected, *platform)?;
    }
    let out = absolute(out);
    // The archives to write: `out` (linux64, win64) and `out/aarch64-linux`, each with
    // the platforms whose binaries it holds.
    let mut archives: Vec<(PathBuf, Vec<Platform>)> = Vec::new();
    for &platform in platforms {
        let folder = platform.archive_folder(&out);
        match archives.iter_mut().find(|(f, _)| *f == folder) {
            Some((_, list)) => list.push(platform),
            None => archives.push((folder, vec![platform])),
        }
    }
    for FmuCrate { id, docs, .. } in selected.iter().copied() {
        let model = load(id)?;
        let mut readme = String::new();
        for path in docs {
            let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
            readme.push_str(&text);
            readme.push_str("\n\n");
        }
        for (folder, archive_platforms) in &archives {
            let mut binaries = Vec::new();
            for platform in archive_platforms {
                let lib = platform.built_path(&root, id);
                let bytes = std::fs::read(&lib).map_err(|e| format!("{}: {e}", lib.display()))?;
                binaries.push((platform.archive_path(id), bytes));
            }
            std::fs::create_dir_all(folder).map_err(|e| format!("{}: {e}", folder.display()))?;
            let path = folder.join(format!("{id}.fmu"));
            let html = documentation(&model, &readme, archive_platforms);
            write_fmu(&path, &model, &binaries, &html)?;
            println!(
                "wrote {} ({} variables, guid {})",
                path.display(),
                model.variables.len(),
                model.guid
            );
        }
    }
    let ids: Vec<&str> = selected.iter().map(|f| f.id.as_str()).collect();
    fmi3::write_archives(&root, &out, &ids, platforms)?;
    // The closed-loop systems of whatever FMUs the folder now holds, when its archives
    // were rewritten.
    let has = |id: &str| out.join(format!("{id}.fmu")).exists();
    let rewritten = archives.iter().any(|(f, _)| *f == out);
    if rewritten && has(ssp::PLANT) && ssp::CONTROLLERS.iter().any(|c| has(c)) {
        ssp::write_all(&out)?;
    }
    Ok(())
}

/// `cargo build --release` of the selected FMU crates for one platform (the Linux
/// platforms: `cargo zigbuild`, linked against glibc [`GLIBC`]).
fn build(root: &Path, selected: &[&FmuCrate], platform: Platform) -> Result<(), String> {
    let mut cargo = match platform {
        Platform::Win64 => {
            let mut cargo = Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".into()));
            win64_environment(&mut cargo)?;
            cargo.current_dir(root).args(["build", "--target", WIN64_TARGET]);
            cargo
        }
        Platform::Linux64 | Platform::Aarch64Linux => {
            let mut cargo = zigbuild(root)?;
            // Zig reports its include folder relative to the working directory when it
            // lies below it (`.venv/...`), and cargo-zigbuild hands that to bindgen, which
            // runs in fmi-sys' folder and then finds no <stddef.h>. From target/ the path
            // is absolute; cargo still finds .cargo/config.toml in the parent folders.
            let dir = root.join("target");
            std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
            cargo
                .current_dir(dir)
                .arg("zigbuild")
                .arg("--manifest-path")
                .arg(root.join("Cargo.toml"));
            cargo.args(["--target", &format!("{}.{GLIBC}", platform.target())]);
            cargo
        }
    };
    cargo.args(["--release", "--locked"]);
    for f in selected {
        cargo.args(["-p", &f.krate]);
    }
    let status = cargo.status().map_err(|e| format!("running cargo: {e}"))?;
    if !status.success() {
        return Err(format!("cargo build --release for {platform:?} failed"));
    }
    Ok(())
}

/// cargo-zigbuild, with Zig: the PyPI wheels `cargo-zigbuild` and `ziglang` pinned in
/// tests/requirements.txt, which scripts/setup.sh installs into `.venv`. The venv's
/// `bin` goes first on the PATH, so cargo-zigbuild finds Zig as `python3 -m ziglang`.
/// Zig links against stubs of the requested glibc's symbol versions; the Rust code
/// and its floating point are rustc's, as in a plain `cargo build`.
fn zigbuild(root: &Path) -> Result<Command, String> {
    let bin = root.join(".venv/bin");
    let exe = bin.join("cargo-zigbuild");
    if !exe.exists() {
        return Err(format!(
            "{} missing: run scripts/setup.sh (installs cargo-zigbuild and Zig from tests/requirements.txt)",
            exe.display()
        ));
    }
    let mut path = vec![bin];
    path.extend(std::env::split_paths(&std::env::var_os("PATH").unwrap_or_default()));
    let mut cargo = Command::new(exe);
    cargo.env("PATH", std::env::join_paths(path).map_err(|e| e.to_string())?);
    Ok(cargo)
}

/// Check the win64 cross tool chain and point bindgen at MinGW's compiler headers.
///
/// fmi-sys runs bindgen on the FMI headers for the target; for windows-gnu, clang parses
/// MinGW's `<malloc.h>`, which includes `<mm_malloc.h>` from the compiler's own include
/// folder, which the libclang bindgen loads does not find by itself. MinGW gcc knows it
/// (`-print-file-name=include`).
fn win64_environment(cargo: &mut Command) -> Result<(), String> {
    let setup = "run scripts/setup.sh (installs the rustup target x86_64-pc-windows-gnu and \
                 Debian's gcc-mingw-w64-x86-64), or pass --platforms linux64";
    let installed = Command::new("rustup")
        .args(["target", "list", "--installed"])
        .output()
        .map(|o| {
            String::from_utf8_lossy(&o.stdout)
                .lines()
                .any(|l| l.trim() == WIN64_TARGET)
        })
        .unwrap_or(true); // no rustup: let cargo report a missing target itself
    if !installed {
        return Err(format!("the Rust target {WIN64_TARGET} is not installed: {setup}"));
    }
    let include = Command::new(MINGW_GCC)
        .arg("-print-file-name=include")
        .output()
        .map_err(|e| format!("{MINGW_GCC}: {e}: {setup}"))?;
    let include = String::from_utf8_lossy(&include.stdout).trim().to_string();
    if include.is_empty() || !Path::new(&include).join("mm_malloc.h").exists() {
        return Err(format!(
            "{MINGW_GCC} reports no include folder with mm_malloc.h ({include:?}): {setup}"
        ));
    }
    let key = "BINDGEN_EXTRA_CLANG_ARGS_x86_64_pc_windows_gnu";
    if std::env::var_os(key).is_none() {
        cargo.env(key, format!("-isystem {include}"));
    }
    Ok(())
}

fn write_fmu(
    path: &Path,
    model: &model_description::Model,
    binaries: &[(String, Vec<u8>)],
    documentation: &str,
) -> Result<(), String> {
    let file = std::fs::File::create(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut zip = zip::ZipWriter::new(file);
    let options = zip::write::SimpleFileOptions::default().compression_method(zip::CompressionMethod::Deflated);
    let xml = model_description::xml::model_description(model).into_bytes();
    let entries = [("modelDescription.xml", &xml[..])]
        .into_iter()
        .chain(binaries.iter().map(|(name, bytes)| (name.as_str(), &bytes[..])))
        .chain([("documentation/index.html", documentation.as_bytes())]);
    for (name, bytes) in entries {
        zip.start_file(name, options).map_err(|e| format!("{name}: {e}"))?;
        zip.write_all(bytes).map_err(|e| format!("{name}: {e}"))?;
    }
    zip.finish().map_err(|e| e.to_string())?;
    Ok(())
}

/// documentation/index.html: the model's README (its equations) rendered from
/// Markdown, then a table of every port and parameter from the declaration.
fn documentation(model: &model_description::Model, readme: &str, platforms: &[Platform]) -> String {
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
version {version}, GUID <code>{guid}</code>.</p>\n{platforms}\n{body}\n{tables}</body>\n</html>\n",
        name = model_description::html::escape_text(&model.model_name),
        id = model.model_identifier,
        version = model.version,
        guid = model.guid,
        tables = model_description::html::variable_tables(model),
        platforms = platforms_section(model, platforms),
    )
}

/// The "Platforms and interfaces" table of documentation/index.html.
fn platforms_section(model: &model_description::Model, platforms: &[Platform]) -> String {
    let interfaces = if model.model_exchange() {
        "FMI 2.0 Co-Simulation and Model Exchange (one binary serves both; Model Exchange: \
         continuous states with <code>der_*</code> derivatives, no event indicators)"
    } else {
        "FMI 2.0 Co-Simulation"
    };
    let mut rows = String::new();
    for platform in platforms {
        let (folder, built, runtime) = match platform {
            Platform::Linux64 => (
                platform.archive_path(&model.model_identifier),
                "x86_64-unknown-linux-gnu",
                "glibc 2.17 or later (every x86-64 Linux since RHEL/CentOS 7, the manylinux2014 baseline)",
            ),
            Platform::Aarch64Linux => (
                platform.archive_path(&model.model_identifier),
                "<strong>aarch64</strong>-unknown-linux-gnu (64-bit ARM: this archive is for ARM Linux \
                 only; FMI 2.0 has no ARM folder name and importers on ARM Linux read <code>linux64</code>)",
                "glibc 2.17 or later (every aarch64 Linux distribution)",
            ),
            Platform::Win64 => (
                platform.archive_path(&model.model_identifier),
                "x86_64-pc-windows-gnu (MinGW-w64)",
                "Windows 10 or later system DLLs only (KERNEL32, ntdll, msvcrt, …); no MinGW runtime DLL",
            ),
        };
        rows.push_str(&format!(
            "<tr><td><code>{folder}</code></td><td>{built}</td><td>{runtime}</td></tr>\n"
        ));
    }
    let aarch64 = if platforms.contains(&Platform::Aarch64Linux) {
        "The x86-64 and Windows binaries are in the archive of the same name one folder up."
    } else {
        "aarch64 Linux ships as separate archives (<code>aarch64-linux/&lt;modelIdentifier&gt;.fmu</code>: FMI 2.0 \
         has no ARM folder name distinct from x86-64's <code>linux64</code>)."
    };
    format!(
        "<h2>Platforms and interfaces</h2>\n<p>{interfaces}.</p>\n<table>\n<tr><th>binary</th><th>built for</th>\
<th>needs at run time</th></tr>\n{rows}</table>\n<p>{aarch64} Not shipped: macOS (needs Apple's SDK), FMI 3.0.</p>\n"
    )
}
