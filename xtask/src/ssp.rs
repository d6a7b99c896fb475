//! SSP 1.0 system packages `dist/<controller>.ssp`: the closed loop of plant + controller as one
//! archive a system-level tool loads (fmpy's `simulate_ssp`, libcosim's `from_ssp_file`, ...).
//!
//! Layout of the archive:
//! - `SystemStructure.ssd`: one system with the components `plant` and `controller`
//!   (`resources/<modelIdentifier>.fmu`), connected by port name (docs/DESIGN.md §2): every controller
//!   input named like a plant output reads it, every controller output named like a plant input
//!   drives it. Each component with parameters has exactly one inline parameter binding (one
//!   parameter set named after the component): the controller's holds the mission (§3) and its
//!   design model, the plant's its initial trim speed `v_vertical`. Default experiment 0–35 s.
//!   The fixed step (0.02 s = `sample_time`) is given twice, in the vendor annotations the
//!   importers need: OSP's `FixedStepAlgorithm` on the default experiment (libcosim) and
//!   OpenModelica's `FixedStepMaster` on the system (OMSimulator, which cannot create a system
//!   without it); tools that do not know an annotation ignore it.
//! - `resources/tailsitter_plant.fmu`, `resources/<controller>.fmu`: the packaged FMUs, verbatim.
//! - with `dist/tailsitter_atmosphere.fmu` present, a third component `atmosphere`
//!   (`resources/tailsitter_atmosphere.fmu`) wired by name too: plant `pos_n/e/d`, `airspeed` →
//!   atmosphere, atmosphere `wind_n/e/d` → plant, its parameters bound to their declared defaults
//!   (no wind, no turbulence, no gust: the closed loop flies as without it, bit for bit). A user
//!   sets wind and turbulence in that parameter set. The avionics systems get it likewise.
//!
//! The SSD is the same for every controller except the controller component's source and the
//! connections it needs (a controller reads the subset of plant outputs it declares as inputs):
//! swapping the controller swaps one component.
//!
//! Reader constraints the writer respects (checked by tests/test_ssp.py, tests/test_ssp_omsimulator.py):
//! - fmpy 0.3.32 validates the SSD against the SSP 1.0 schema and needs a connection for every
//!   declared input connector, so plant inputs that nothing drives (`wind_*`) and controller inputs
//!   without a plant output (`ref_offset_*`) are not declared as connectors;
//! - libcosim reads the SSD with fixed prefixes (`ssd:`, `ssc:`, `ssv:`, `osp:`) and needs a type
//!   element on every connector; namespace declarations sit on the root element only (libcosim would
//!   read an `xmlns` attribute on an element it iterates as a child);
//! - one `ParameterBinding` per component: with several inline bindings OMSimulator applies only
//!   the last (`Values::importFromSnapshot` keys every inline binding as "inline") and libcosim only
//!   the first, silently; fmpy reads them all. With `.ssv` files (`source=`) OMSimulator applies
//!   each, libcosim still only the first;
//! - OMSimulator (acb56d9d) reads the SSD with fixed prefixes too (`ssd:`, `ssc:`, `oms:`) and looks
//!   at the first `ssc:Annotation` of the system's `ssd:Annotations` only. Its command line
//!   replaces the default experiment's stop time by its `--stopTime` flag (default 1 s);
//!   the library (`oms_importFile`) reads it (docs/OMSIMULATOR.md).

// Rust's shortest round-trip representation, as in modelDescription.xml; a valid xs:double.
use model_description::fmt_f64 as real;
use model_description::xml::{element, empty};
use quick_xml::events::{BytesStart, Event};
use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::sync::LazyLock;

/// The plant every system holds.
pub const PLANT: &str = "tailsitter_plant";
/// The declarations' folder.
fn declarations_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../modelDescription")
}

/// Controllers a system is written for (each when its FMU exists): the models declared in
/// `modelDescription/` whose outputs include every command of the controller interface (the
/// rule of `tailsim.controllers`), in the order of their identifiers.
pub static CONTROLLERS: LazyLock<Vec<&'static str>> = LazyLock::new(|| {
    let dir = declarations_dir();
    let (interface, _) = model_description::load_declarations(&dir, "fragments/controller_interface.json")
        .unwrap_or_else(|e| panic!("controller interface declaration: {e}"));
    let commands: Vec<String> = interface
        .into_iter()
        .filter(|d| d.group.as_deref() == Some("command"))
        .map(|d| d.name)
        .collect();
    let mut ids: Vec<String> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .filter_map(|e| e.ok()?.file_name().to_str()?.strip_suffix(".json").map(str::to_string))
        .collect();
    ids.sort();
    ids.into_iter()
        .filter(|id| {
            let model = model_description::load(&dir, id, "0").unwrap_or_else(|e| panic!("declaration {id}: {e}"));
            commands.iter().all(|c| {
                model
                    .variables
                    .iter()
                    .any(|v| v.name() == c && v.decl.causality == model_description::Causality::Output)
            })
        })
        .map(|id| &*id.leak())
        .collect()
});

/// The parameters of group `group` in declaration `file` (below `modelDescription/`) with
/// their declared (numeric) defaults; `what` names them in a panic.
fn declared_parameters(file: &str, group: &str, what: &str) -> Vec<(&'static str, f64)> {
    let (decls, _) = model_description::load_declarations(&declarations_dir(), file)
        .unwrap_or_else(|e| panic!("{what} declaration: {e}"));
    decls
        .into_iter()
        .filter(|d| d.group.as_deref() == Some(group) && d.causality == model_description::Causality::Parameter)
        .map(|d| match d.start {
            Some(model_description::Start::Number(x)) => (&*d.name.leak(), x),
            other => panic!("{what} parameter {} has start {other:?}", d.name),
        })
        .collect()
}

/// Mission parameters (docs/DESIGN.md §3) with their declared defaults, bound on the
/// controller: the `mission` group of `modelDescription/fragments/controller_interface.json`.
pub static MISSION: LazyLock<Vec<(&'static str, f64)>> =
    LazyLock::new(|| declared_parameters("fragments/controller_interface.json", "mission", "mission"));

/// The atmosphere of the systems (a component when its FMU is in the folder).
pub const ATMOSPHERE: &str = "tailsitter_atmosphere";

/// The atmosphere's parameters (group `params` of `modelDescription/tailsitter_atmosphere.json`)
/// with their declared defaults: calm air.
pub static ATMOSPHERE_PARAMS: LazyLock<Vec<(&'static str, f64)>> =
    LazyLock::new(|| declared_parameters(&format!("{ATMOSPHERE}.json"), "params", "atmosphere"));

/// A mission parameter's declared default.
fn mission_default(name: &str) -> f64 {
    MISSION
        .iter()
        .find(|(n, _)| *n == name)
        .map(|m| m.1)
        .unwrap_or_else(|| panic!("mission parameter {name} not declared"))
}

/// The plant's airframe parameters (group `airframe` of `modelDescription/tailsitter_plant.json`)
/// with their declared values: the controllers' design model (`design_airframe`, the same names),
/// bound on the controller component after the mission.
///
/// **The honest default**: the design model is the *declared nominal* airframe, bound as values
/// of its own, not connected to the plant's parameters. A user who changes the plant's airframe
/// (a parameter set on the plant: a heavier aircraft, another C_mα) gets a controller that still
/// designs on the nominal aircraft — as a real controller would, which never knows the aircraft
/// it flies. Giving it the true plant (perfect model knowledge, the comparison issue 15 found
/// flattering to the LQR) takes a deliberate second change: the same values on the controller.
/// One source: the values come from the plant's declaration, as the controllers' defaults do.
pub static DESIGN_AIRFRAME: LazyLock<Vec<(&'static str, f64)>> =
    LazyLock::new(|| declared_parameters(&format!("{PLANT}.json"), "airframe", "airframe"));

/// Default experiment: the default mission (docs/DESIGN.md §3), from t = 0 to the end
/// of its last phase.
fn stop_time() -> f64 {
    [
        "t_vertical_1",
        "t_transition_1",
        "t_level",
        "t_transition_2",
        "t_vertical_2",
    ]
    .iter()
    .map(|n| mission_default(n))
    .sum()
}

const NS_SSD: &str = "http://ssp-standard.org/SSP1/SystemStructureDescription";
const NS_SSC: &str = "http://ssp-standard.org/SSP1/SystemStructureCommon";
const NS_SSV: &str = "http://ssp-standard.org/SSP1/SystemStructureParameterValues";
const NS_OSP: &str = "http://opensimulationplatform.com/SSP/OSPAnnotations";
/// OMSimulator's annotation namespace, as OMSimulator writes it (`Snapshot.cpp`).
const NS_OMS: &str = "https://raw.githubusercontent.com/OpenModelica/OMSimulator/master/schema/oms.xsd";
/// OMSimulator's fixed-step master (`SystemWC::getSolverName`).
const OMS_FIXED_STEP_MASTER: &str = "oms-ma";
/// The relative tolerance OMSimulator passes to fmi2SetupExperiment (its `--tolerance` default;
/// without the attribute the library would pass 0, which the FMUs reject).
const OMS_RELATIVE_TOLERANCE: &str = "0.0001";

/// One scalar variable of an FMU, as far as the SSD needs it.
#[derive(Debug, Clone, PartialEq)]
pub struct Port {
    pub name: String,
    pub causality: String,
    /// Real, Integer, Boolean, String or Enumeration.
    pub kind: String,
    pub unit: Option<String>,
}

/// A unit definition: name and the attributes of its BaseUnit (same names in FMI 2.0 and SSC).
#[derive(Debug, Clone, PartialEq)]
pub struct Unit {
    pub name: String,
    pub base: Vec<(String, String)>,
}

/// What the SSD needs of one FMU.
#[derive(Debug, Clone)]
pub struct FmuInfo {
    pub model_identifier: String,
    pub ports: Vec<Port>,
    pub units: Vec<Unit>,
}

impl FmuInfo {
    fn with<'a>(&'a self, causality: &'a str) -> impl Iterator<Item = &'a Port> + 'a {
        self.ports.iter().filter(move |p| p.causality == causality)
    }

    fn port(&self, name: &str) -> Option<&Port> {
        self.ports.iter().find(|p| p.name == name)
    }
}

/// Write `<dir>/<controller>.ssp` for every controller whose FMU is in `dir`; the plant FMU must be.
pub fn write_all(dir: &Path) -> Result<Vec<PathBuf>, String> {
    let plant_fmu = dir.join(format!("{PLANT}.fmu"));
    if !plant_fmu.exists() {
        return Err(format!("{} missing: run `cargo xtask dist` first", plant_fmu.display()));
    }
    let atmosphere_fmu = dir.join(format!("{ATMOSPHERE}.fmu"));
    let atmosphere_fmu = atmosphere_fmu.exists().then_some(atmosphere_fmu);
    let mut written = Vec::new();
    for id in CONTROLLERS.iter() {
        let controller_fmu = dir.join(format!("{id}.fmu"));
        if !controller_fmu.exists() {
            println!("skipping {id}.ssp: {} missing", controller_fmu.display());
            continue;
        }
        let path = dir.join(format!("{id}.ssp"));
        write_ssp(&path, &plant_fmu, &controller_fmu, atmosphere_fmu.as_deref())?;
        println!("wrote {}", path.display());
        written.push(path);
    }
    if written.is_empty() {
        return Err(format!("no controller FMU in {}", dir.display()));
    }
    let has = |id: &str| dir.join(format!("{id}.fmu")).exists();
    if has(SENSORS) && has(ESTIMATOR) {
        for id in CONTROLLERS.iter().filter(|id| has(id)) {
            let path = write_avionics_ssp(dir, id)?;
            println!("wrote {}", path.display());
            written.push(path);
        }
    }
    Ok(written)
}

/// Write one SSP archive: the SSD and the FMUs (plant, controller, the atmosphere if given)
/// under `resources/`.
pub fn write_ssp(
    path: &Path,
    plant_fmu: &Path,
    controller_fmu: &Path,
    atmosphere_fmu: Option<&Path>,
) -> Result<(), String> {
    let read = |p: &Path| std::fs::read(p).map_err(|e| format!("{}: {e}", p.display()));
    let (plant_bytes, controller_bytes) = (read(plant_fmu)?, read(controller_fmu)?);
    let plant = fmu_info(&plant_bytes).map_err(|e| format!("{}: {e}", plant_fmu.display()))?;
    let controller = fmu_info(&controller_bytes).map_err(|e| format!("{}: {e}", controller_fmu.display()))?;
    let atmosphere_bytes = atmosphere_fmu.map(read).transpose()?;
    let atmosphere = match (&atmosphere_bytes, atmosphere_fmu) {
        (Some(b), Some(p)) => Some(fmu_info(b).map_err(|e| format!("{}: {e}", p.display()))?),
        _ => None,
    };
    let ssd = system_description(&plant, &controller, atmosphere.as_ref())?;
    let file = std::fs::File::create(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut zip = zip::ZipWriter::new(file);
    let deflated = zip::write::SimpleFileOptions::default().compression_method(zip::CompressionMethod::Deflated);
    // The FMUs are zip archives already: store them.
    let stored = zip::write::SimpleFileOptions::default().compression_method(zip::CompressionMethod::Stored);
    let mut entries = vec![
        ("SystemStructure.ssd".to_string(), ssd.into_bytes(), deflated),
        (resource(&plant.model_identifier), plant_bytes, stored),
        (resource(&controller.model_identifier), controller_bytes, stored),
    ];
    if let (Some(info), Some(bytes)) = (atmosphere, atmosphere_bytes) {
        entries.push((resource(&info.model_identifier), bytes, stored));
    }
    for (name, bytes, options) in entries {
        zip.start_file(name.as_str(), options)
            .map_err(|e| format!("{name}: {e}"))?;
        zip.write_all(&bytes).map_err(|e| format!("{name}: {e}"))?;
    }
    zip.finish().map_err(|e| e.to_string())?;
    Ok(())
}

fn resource(model_identifier: &str) -> String {
    format!("resources/{model_identifier}.fmu")
}

/// Read modelDescription.xml out of an FMU archive.
pub fn fmu_info(fmu: &[u8]) -> Result<FmuInfo, String> {
    let mut archive = zip::ZipArchive::new(std::io::Cursor::new(fmu)).map_err(|e| e.to_string())?;
    let mut xml = String::new();
    archive
        .by_name("modelDescription.xml")
        .map_err(|e| format!("modelDescription.xml: {e}"))?
        .read_to_string(&mut xml)
        .map_err(|e| format!("modelDescription.xml: {e}"))?;
    parse_model_description(&xml)
}

fn attribute(e: &BytesStart, name: &str) -> Result<Option<String>, String> {
    match e.try_get_attribute(name).map_err(|err| err.to_string())? {
        Some(a) => Ok(Some(a.unescape_value().map_err(|err| err.to_string())?.into_owned())),
        None => Ok(None),
    }
}

/// The model identifier, scalar variables and unit definitions of an FMI 2.0 model description.
pub fn parse_model_description(xml: &str) -> Result<FmuInfo, String> {
    let mut reader = quick_xml::Reader::from_str(xml);
    let mut info = FmuInfo {
        model_identifier: String::new(),
        ports: Vec::new(),
        units: Vec::new(),
    };
    // The ScalarVariable whose type element comes next.
    let mut pending: Option<(String, String)> = None;
    loop {
        let event = reader.read_event().map_err(|e| format!("modelDescription.xml: {e}"))?;
        let e = match &event {
            Event::Start(e) | Event::Empty(e) => e,
            Event::End(e) if e.name().as_ref() == b"ScalarVariable" => {
                if let Some((name, _)) = pending.take() {
                    return Err(format!("variable {name} has no type element"));
                }
                continue;
            }
            Event::Eof => break,
            _ => continue,
        };
        match e.name().as_ref() {
            b"CoSimulation" => info.model_identifier = attribute(e, "modelIdentifier")?.unwrap_or_default(),
            b"Unit" => info.units.push(Unit {
                name: attribute(e, "name")?.ok_or("Unit without name")?,
                base: Vec::new(),
            }),
            b"BaseUnit" => {
                let unit = info.units.last_mut().ok_or("BaseUnit outside Unit")?;
                for a in e.attributes() {
                    let a = a.map_err(|err| err.to_string())?;
                    let value = a.unescape_value().map_err(|err| err.to_string())?.into_owned();
                    unit.base
                        .push((String::from_utf8_lossy(a.key.as_ref()).into_owned(), value));
                }
            }
            b"ScalarVariable" => {
                let name = attribute(e, "name")?.ok_or("ScalarVariable without name")?;
                // FMI 2.0 default causality is local.
                let causality = attribute(e, "causality")?.unwrap_or_else(|| "local".into());
                pending = Some((name, causality));
            }
            kind @ (b"Real" | b"Integer" | b"Boolean" | b"String" | b"Enumeration") => {
                if let Some((name, causality)) = pending.take() {
                    info.ports.push(Port {
                        name,
                        causality,
                        kind: String::from_utf8_lossy(kind).into_owned(),
                        unit: attribute(e, "unit")?,
                    });
                }
            }
            _ => {}
        }
    }
    if info.model_identifier.is_empty() {
        return Err("no CoSimulation modelIdentifier".into());
    }
    Ok(info)
}

/// A connection `start.connector → end.connector` (same connector name at both ends).
#[derive(Debug, Clone, PartialEq)]
pub struct Connection {
    pub start: &'static str,
    pub end: &'static str,
    pub name: String,
}

/// Connections by name (docs/DESIGN.md §2): plant outputs → controller inputs, controller outputs →
/// plant inputs. Errors if types differ or a plant command input (`*_cmd`) is left undriven.
pub fn connections(plant: &FmuInfo, controller: &FmuInfo) -> Result<Vec<Connection>, String> {
    let mut out = links_between(plant, "plant", controller, "controller")?;
    out.extend(links_between(controller, "controller", plant, "plant")?);
    require_driven(&out, plant, "plant", is_command, controller)?;
    Ok(out)
}

/// A command input (`*_cmd`): what a controller drives.
fn is_command(p: &Port) -> bool {
    p.name.ends_with("_cmd")
}

/// Errors unless every input of `fmu` (component `id`) that `which` selects is the end of one of
/// `links`; `driver` is the FMU that should drive them.
fn require_driven(
    links: &[Connection],
    fmu: &FmuInfo,
    id: &str,
    which: impl Fn(&Port) -> bool,
    driver: &FmuInfo,
) -> Result<(), String> {
    let undriven: Vec<_> = fmu
        .with("input")
        .filter(|p| which(p) && !links.iter().any(|c| c.end == id && c.name == p.name))
        .map(|p| p.name.as_str())
        .collect();
    if undriven.is_empty() {
        Ok(())
    } else {
        Err(format!(
            "{} does not drive {id} inputs {undriven:?}",
            driver.model_identifier
        ))
    }
}

type Xml = model_description::xml::XmlWriter;
type XmlResult = std::io::Result<()>;

/// The connectors of one component: every output (recorded by tools that record connectors), and
/// the inputs a connection drives.
fn component(w: &mut Xml, name: &str, fmu: &FmuInfo, inputs: &[&str], parameter_sets: &[ParamSet]) -> XmlResult {
    let source = resource(&fmu.model_identifier);
    let attributes = [
        ("name", name),
        ("type", "application/x-fmu-sharedlibrary"),
        ("source", source.as_str()),
    ];
    element(w, "ssd:Component", attributes, |w| {
        let connected =
            |p: &&Port| p.causality == "output" || (p.causality == "input" && inputs.contains(&p.name.as_str()));
        element(w, "ssd:Connectors", [], |w| {
            fmu.ports.iter().filter(connected).try_for_each(|p| {
                let unit = p.unit.as_deref().filter(|_| p.kind == "Real");
                let connector = [("name", p.name.as_str()), ("kind", p.causality.as_str())];
                element(w, "ssd:Connector", connector, |w| {
                    empty(w, &format!("ssc:{}", p.kind), unit.map(|u| ("unit", u)))
                })
            })
        })?;
        // One binding, one set: importers that take one binding per component (OMSimulator the
        // last, libcosim the first) see every parameter.
        let parameters: Vec<_> = parameter_sets.iter().flat_map(|(_, p)| p.iter().cloned()).collect();
        if parameters.is_empty() {
            return Ok(());
        }
        element(w, "ssd:ParameterBindings", [], |w| {
            element(w, "ssd:ParameterBinding", [], |w| {
                element(w, "ssd:ParameterValues", [], |w| parameter_set(w, name, &parameters))
            })
        })
    })
}

/// Groups of a component's parameters: (group, [(name, type element, value)]); a component's
/// groups are written as its one parameter set, in this order.
type ParamSet = (&'static str, Vec<(&'static str, String, String)>);

/// An inline SSV parameter set named `set`: (name, type element, value).
fn parameter_set(w: &mut Xml, set: &str, parameters: &[(&str, String, String)]) -> XmlResult {
    element(w, "ssv:ParameterSet", [("version", "1.0"), ("name", set)], |w| {
        element(w, "ssv:Parameters", [], |w| {
            parameters.iter().try_for_each(|(name, kind, value)| {
                element(w, "ssv:Parameter", [("name", *name)], |w| {
                    empty(w, &format!("ssv:{kind}"), [("value", value.as_str())])
                })
            })
        })
    })
}

/// Parameter values for `fmu`, checking each is a parameter of the declared type.
fn bindings(
    fmu: &FmuInfo,
    values: &[(&'static str, &str, String)],
) -> Result<Vec<(&'static str, String, String)>, String> {
    values
        .iter()
        .map(|(name, kind, value)| match fmu.port(name) {
            Some(p) if p.causality == "parameter" && p.kind == *kind => Ok((*name, kind.to_string(), value.clone())),
            Some(p) => Err(format!(
                "{}.{name} is a {} {}, not a {kind} parameter",
                fmu.model_identifier, p.causality, p.kind
            )),
            None => Err(format!("{} has no parameter {name}", fmu.model_identifier)),
        })
        .collect()
}

/// The controller's parameters: the declared mission, then the design model (the plant's
/// declared nominal airframe, [`DESIGN_AIRFRAME`]: the honest default).
fn controller_sets(controller: &FmuInfo) -> Result<Vec<ParamSet>, String> {
    let mission: Vec<_> = MISSION.iter().map(|(n, v)| (*n, "Real", real(*v))).collect();
    let design: Vec<_> = DESIGN_AIRFRAME.iter().map(|(n, v)| (*n, "Real", real(*v))).collect();
    Ok(vec![
        ("mission", bindings(controller, &mission)?),
        ("design_model", bindings(controller, &design)?),
    ])
}

/// The plant's parameters: it starts in the trimmed vertical climb at the mission's
/// climb speed (docs/DESIGN.md §3).
fn plant_sets(plant: &FmuInfo) -> Result<Vec<ParamSet>, String> {
    let start = [
        ("initial_condition", "Integer", "0".to_string()),
        ("initial_speed", "Real", real(mission_default("v_vertical"))),
    ];
    Ok(vec![("plant", bindings(plant, &start)?)])
}

/// The atmosphere component, if given: its links by name (plant → atmosphere, atmosphere →
/// plant) join `links`, and its parameters (the declared defaults,
/// [`ATMOSPHERE_PARAMS`]: calm) is returned. Every atmosphere input must be a plant output.
fn add_atmosphere<'a>(
    plant: &FmuInfo,
    atmosphere: Option<&'a FmuInfo>,
    links: &mut Vec<Connection>,
) -> Result<Option<(&'a FmuInfo, Vec<ParamSet>)>, String> {
    let Some(atmosphere) = atmosphere else {
        return Ok(None);
    };
    links.extend(links_between(plant, "plant", atmosphere, "atmosphere")?);
    links.extend(links_between(atmosphere, "atmosphere", plant, "plant")?);
    require_driven(links, atmosphere, "atmosphere", |_| true, plant)?;
    let values: Vec<_> = ATMOSPHERE_PARAMS
        .iter()
        .map(|(n, v)| match atmosphere.port(n).map(|p| p.kind.as_str()) {
            Some("Integer") => (*n, "Integer", format!("{}", *v as i64)),
            _ => (*n, "Real", real(*v)),
        })
        .collect();
    Ok(Some((atmosphere, vec![("atmosphere", bindings(atmosphere, &values)?)])))
}

/// SystemStructure.ssd of the closed loop, with the atmosphere component if given.
pub fn system_description(
    plant: &FmuInfo,
    controller: &FmuInfo,
    atmosphere: Option<&FmuInfo>,
) -> Result<String, String> {
    let mut links = connections(plant, controller)?;
    let atmosphere = add_atmosphere(plant, atmosphere, &mut links)?;
    let controller_parameters = controller_sets(controller)?;
    let plant_parameters = plant_sets(plant)?;
    let name = format!("{}_closed_loop", controller.model_identifier);
    let description = format!(
        "Tail-sitter closed loop: {} flying {} (docs/DESIGN.md section 2 port wiring by name, section 3 mission).",
        controller.model_identifier, plant.model_identifier
    );
    let mut elements = vec![
        ("controller", controller, controller_parameters),
        ("plant", plant, plant_parameters),
    ];
    elements.extend(atmosphere.map(|(fmu, sets)| ("atmosphere", fmu, sets)));
    write_ssd(&name, &description, &elements, &links)
}

/// The estimator and sensors of the avionics systems `dist/<controller>_avionics.ssp`.
pub const SENSORS: &str = "tailsitter_sensors";
pub const ESTIMATOR: &str = "tailsitter_ekf";

/// Connections by name from `from` outputs to `to` inputs (same type).
fn links_between(
    from: &FmuInfo,
    from_id: &'static str,
    to: &FmuInfo,
    to_id: &'static str,
) -> Result<Vec<Connection>, String> {
    let mut out = Vec::new();
    for output in from.with("output") {
        if let Some(input) = to.port(&output.name).filter(|p| p.causality == "input") {
            if input.kind != output.kind {
                return Err(format!(
                    "{}: {} output is {}, {} input is {}",
                    output.name, from.model_identifier, output.kind, to.model_identifier, input.kind
                ));
            }
            out.push(Connection {
                start: from_id,
                end: to_id,
                name: output.name.clone(),
            });
        }
    }
    Ok(out)
}

/// SystemStructure.ssd of avionics in the loop: plant → sensors → estimator → controller →
/// plant and controller → estimator (the commands), every connection explicit and by name.
/// The sensors and the estimator keep their (equal) defaults of the shared parameters; the
/// atmosphere, if given, is wired and bound as in the closed loop.
pub fn avionics_system_description(
    plant: &FmuInfo,
    sensors: &FmuInfo,
    ekf: &FmuInfo,
    controller: &FmuInfo,
    atmosphere: Option<&FmuInfo>,
) -> Result<String, String> {
    let mut links = links_between(plant, "plant", sensors, "sensors")?;
    links.extend(links_between(sensors, "sensors", ekf, "estimator")?);
    links.extend(links_between(ekf, "estimator", controller, "controller")?);
    links.extend(links_between(controller, "controller", plant, "plant")?);
    links.extend(links_between(controller, "controller", ekf, "estimator")?);
    let atmosphere = add_atmosphere(plant, atmosphere, &mut links)?;
    require_driven(&links, plant, "plant", is_command, controller)?;
    require_driven(&links, ekf, "estimator", is_command, controller)?;
    require_driven(&links, ekf, "estimator", |p| !is_command(p), sensors)?;
    let controller_parameters = controller_sets(controller)?;
    let plant_parameters = plant_sets(plant)?;
    // SSP importers (fmpy, libcosim) are Jacobi masters: the estimator fuses the sensors'
    // outputs of the previous step, one `sample_time` old (its `measurement_latency`), and
    // the plant gets the controller's output one step later (its `prediction_lead`).
    let jacobi_delays: Vec<_> = ["measurement_latency", "prediction_lead"]
        .into_iter()
        .filter(|n| ekf.port(n).is_some())
        .map(|n| (n, "Real", real(mission_default("sample_time"))))
        .collect();
    let estimator_parameters = bindings(ekf, &jacobi_delays)?;
    let name = format!("{}_avionics", controller.model_identifier);
    let description = format!(
        "Tail-sitter with avionics in the loop: {} flying {} on the estimates of {} from {} (port wiring by name).",
        controller.model_identifier, plant.model_identifier, ekf.model_identifier, sensors.model_identifier
    );
    let mut elements = vec![
        ("controller", controller, controller_parameters),
        ("estimator", ekf, vec![("estimator", estimator_parameters)]),
        ("sensors", sensors, Vec::new()),
        ("plant", plant, plant_parameters),
    ];
    elements.extend(atmosphere.map(|(fmu, sets)| ("atmosphere", fmu, sets)));
    write_ssd(&name, &description, &elements, &links)
}

/// Write `<dir>/<controller>_avionics.ssp` (plant, sensors, estimator, controller).
pub fn write_avionics_ssp(dir: &Path, controller_id: &str) -> Result<PathBuf, String> {
    let read = |id: &str| {
        let p = dir.join(format!("{id}.fmu"));
        std::fs::read(&p).map_err(|e| format!("{}: {e}", p.display()))
    };
    let mut bytes = vec![read(PLANT)?, read(SENSORS)?, read(ESTIMATOR)?, read(controller_id)?];
    if dir.join(format!("{ATMOSPHERE}.fmu")).exists() {
        bytes.push(read(ATMOSPHERE)?);
    }
    let infos = bytes.iter().map(|b| fmu_info(b)).collect::<Result<Vec<_>, _>>()?;
    let ssd = avionics_system_description(&infos[0], &infos[1], &infos[2], &infos[3], infos.get(4))?;
    let path = dir.join(format!("{controller_id}_avionics.ssp"));
    let file = std::fs::File::create(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut zip = zip::ZipWriter::new(file);
    let deflated = zip::write::SimpleFileOptions::default().compression_method(zip::CompressionMethod::Deflated);
    let stored = zip::write::SimpleFileOptions::default().compression_method(zip::CompressionMethod::Stored);
    zip.start_file("SystemStructure.ssd", deflated)
        .map_err(|e| e.to_string())?;
    zip.write_all(ssd.as_bytes()).map_err(|e| e.to_string())?;
    for (info, b) in infos.iter().zip(&bytes) {
        let name = resource(&info.model_identifier);
        zip.start_file(name.as_str(), stored)
            .map_err(|e| format!("{name}: {e}"))?;
        zip.write_all(b).map_err(|e| format!("{name}: {e}"))?;
    }
    zip.finish().map_err(|e| e.to_string())?;
    Ok(path)
}

/// One element of a system: its name, FMU and parameter bindings.
type Element<'a> = (&'a str, &'a FmuInfo, Vec<ParamSet>);

/// SystemStructure.ssd of `elements` wired by `links`, with the default mission experiment.
fn write_ssd(name: &str, description: &str, elements: &[Element], links: &[Connection]) -> Result<String, String> {
    let mut units: Vec<&Unit> = Vec::new();
    for u in elements.iter().flat_map(|e| e.1.units.iter()) {
        if !units.iter().any(|known| known.name == u.name) {
            units.push(u);
        }
    }
    let (stop, base_step) = (real(stop_time()), real(mission_default("sample_time")));
    let root = [
        ("xmlns:ssd", NS_SSD),
        ("xmlns:ssc", NS_SSC),
        ("xmlns:ssv", NS_SSV),
        ("xmlns:osp", NS_OSP),
        ("xmlns:oms", NS_OMS),
        ("version", "1.0"),
        ("name", name),
        (
            "generationTool",
            concat!("tailsitter xtask ", env!("CARGO_PKG_VERSION")),
        ),
    ];
    model_description::xml::document(|w| {
        element(w, "ssd:SystemStructureDescription", root, |w| {
            element(w, "ssd:System", [("name", name), ("description", description)], |w| {
                element(w, "ssd:Elements", [], |w| {
                    elements.iter().try_for_each(|(name, fmu, parameters)| {
                        let inputs: Vec<&str> = links
                            .iter()
                            .filter(|c| c.end == *name)
                            .map(|c| c.name.as_str())
                            .collect();
                        component(w, name, fmu, &inputs, parameters)
                    })
                })?;
                element(w, "ssd:Connections", [], |w| {
                    links.iter().try_for_each(|c| {
                        let ends = [
                            ("startElement", c.start),
                            ("startConnector", c.name.as_str()),
                            ("endElement", c.end),
                            ("endConnector", c.name.as_str()),
                        ];
                        empty(w, "ssd:Connection", ends)
                    })
                })?;
                oms_fixed_step_master(w, &base_step)
            })?;
            if !units.is_empty() {
                element(w, "ssd:Units", [], |w| {
                    units.iter().try_for_each(|u| {
                        element(w, "ssc:Unit", [("name", u.name.as_str())], |w| {
                            empty(w, "ssc:BaseUnit", u.base.iter().map(|(k, v)| (k.as_str(), v.as_str())))
                        })
                    })
                })?;
            }
            let experiment = [("startTime", "0.0"), ("stopTime", stop.as_str())];
            element(w, "ssd:DefaultExperiment", experiment, |w| {
                element(w, "ssd:Annotations", [], |w| {
                    element(w, "ssc:Annotation", [("type", "com.opensimulationplatform")], |w| {
                        element(w, "osp:Algorithm", [], |w| {
                            empty(w, "osp:FixedStepAlgorithm", [("baseStepSize", base_step.as_str())])
                        })
                    })
                })
            })
        })
    })
    .map_err(|e| e.to_string())
}

/// The system's `ssd:Annotations`: OMSimulator's fixed-step master at `step` seconds
/// (`SystemWC::importFromSSD_SimulationInformation`). Without it OMSimulator (acb56d9d) cannot
/// type the system and aborts (`[NewSystem] internal error`, then std::logic_error).
fn oms_fixed_step_master(w: &mut Xml, step: &str) -> XmlResult {
    element(w, "ssd:Annotations", [], |w| {
        element(w, "ssc:Annotation", [("type", "org.openmodelica")], |w| {
            element(w, "oms:Annotations", [], |w| {
                element(w, "oms:SimulationInformation", [], |w| {
                    let master = [
                        ("description", OMS_FIXED_STEP_MASTER),
                        ("stepSize", step),
                        ("relativeTolerance", OMS_RELATIVE_TOLERANCE),
                    ];
                    empty(w, "oms:FixedStepMaster", master)
                })
            })
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn port(name: &str, causality: &str, kind: &str) -> Port {
        Port {
            name: name.into(),
            causality: causality.into(),
            kind: kind.into(),
            unit: None,
        }
    }

    fn plant() -> FmuInfo {
        FmuInfo {
            model_identifier: PLANT.into(),
            ports: vec![
                port("thrust_cmd", "input", "Real"),
                port("wind_n", "input", "Real"),
                port("theta", "output", "Real"),
                port("pos_d", "output", "Real"),
                port("initial_condition", "parameter", "Integer"),
                port("initial_speed", "parameter", "Real"),
            ],
            units: vec![Unit {
                name: "m".into(),
                base: vec![("m".into(), "1".into())],
            }],
        }
    }

    fn controller() -> FmuInfo {
        let mut ports = vec![
            port("thrust_cmd", "output", "Real"),
            port("phase", "output", "Integer"),
            port("pos_d", "input", "Real"),
            port("ref_offset_n", "input", "Real"),
        ];
        ports.extend(MISSION.iter().map(|(n, _)| port(n, "parameter", "Real")));
        ports.extend(DESIGN_AIRFRAME.iter().map(|(n, _)| port(n, "parameter", "Real")));
        FmuInfo {
            model_identifier: "tailsitter_tsd".into(),
            ports,
            units: vec![],
        }
    }

    #[test]
    fn controllers_are_the_models_including_the_controller_interface() {
        assert_eq!(*CONTROLLERS, ["tailsitter_lqr", "tailsitter_px4", "tailsitter_tsd"]);
    }

    #[test]
    fn connects_by_name_both_ways() {
        let c = connections(&plant(), &controller()).unwrap();
        let names: Vec<_> = c.iter().map(|c| (c.start, c.end, c.name.as_str())).collect();
        assert_eq!(
            names,
            [("plant", "controller", "pos_d"), ("controller", "plant", "thrust_cmd")]
        );
    }

    #[test]
    fn undriven_command_is_an_error() {
        let mut c = controller();
        c.ports.retain(|p| p.name != "thrust_cmd");
        assert!(connections(&plant(), &c).unwrap_err().contains("thrust_cmd"));
    }

    #[test]
    fn design_model_is_the_plants_declared_airframe_bound_on_the_controller_only() {
        let ssd = system_description(&plant(), &controller(), None).unwrap();
        // 79 airframe parameters, the first the mass of 9 kg (thesis App. C.1.1)
        assert!(DESIGN_AIRFRAME.len() > 70, "{}", DESIGN_AIRFRAME.len());
        assert_eq!(DESIGN_AIRFRAME[0], ("mass", 9.0));
        let set = ssd
            .find(r#"<ssv:ParameterSet version="1.0" name="controller">"#)
            .expect("controller set");
        let controller_end = ssd
            .find(r#"<ssd:Component name="plant""#)
            .expect("plant after controller");
        assert!(set < controller_end, "the design model is bound on the controller");
        assert!(ssd[set..].contains(r#"<ssv:Parameter name="mass">"#));
        // the plant's own airframe is not bound: a parameter set on the plant changes the plant only
        assert!(!ssd[controller_end..].contains(r#"<ssv:Parameter name="mass">"#));
        // a controller without a design model is refused, not silently left on its defaults
        let mut c = controller();
        c.ports.retain(|p| p.name != "mass");
        assert!(system_description(&plant(), &c, None).unwrap_err().contains("mass"));
    }

    #[test]
    fn ssd_declares_only_connected_inputs_and_binds_the_mission() {
        let ssd = system_description(&plant(), &controller(), None).unwrap();
        assert!(ssd.contains(r#"<ssd:Connector name="pos_d" kind="input">"#));
        assert!(!ssd.contains("wind_n"), "undriven plant input declared");
        assert!(!ssd.contains("ref_offset_n"), "unconnected controller input declared");
        assert!(ssd.contains(r#"<ssd:Connector name="phase" kind="output">"#));
        assert!(ssd.contains(r#"<ssv:Parameter name="t_level">"#));
        assert!(ssd.contains(r#"<ssv:Integer value="0"/>"#));
        assert!(ssd.contains(r#"<osp:FixedStepAlgorithm baseStepSize="0.02"/>"#));
        assert!(ssd.contains(r#"stopTime="35.0""#));
    }

    /// The count of non-overlapping `needle`s in `haystack`.
    fn count(haystack: &str, needle: &str) -> usize {
        haystack.matches(needle).count()
    }

    #[test]
    fn one_parameter_binding_per_component_holding_every_parameter() {
        let ssd = system_description(&plant(), &controller(), Some(&atmosphere())).unwrap();
        // controller, plant, atmosphere: one binding and one set each, named after the component
        assert_eq!(count(&ssd, "<ssd:ParameterBinding>"), 3);
        assert_eq!(count(&ssd, "<ssv:ParameterSet "), 3);
        for name in ["controller", "plant", "atmosphere"] {
            assert!(ssd.contains(&format!(r#"<ssv:ParameterSet version="1.0" name="{name}">"#)));
        }
        let controller_set =
            &ssd[ssd.find(r#"name="controller">"#).unwrap()..ssd.find(r#"<ssd:Component name="plant""#).unwrap()];
        let n = MISSION.len() + DESIGN_AIRFRAME.len();
        assert_eq!(count(controller_set, "<ssv:Parameter "), n);
        // the mission first, then the design model
        let (t_level, mass) = (
            controller_set.find(r#""t_level""#).unwrap(),
            controller_set.find(r#""mass""#).unwrap(),
        );
        assert!(t_level < mass);
        let (sensors, ekf, c) = avionics();
        let ssd = avionics_system_description(&plant(), &sensors, &ekf, &c, None).unwrap();
        assert_eq!(count(&ssd, "<ssd:ParameterBinding>"), 2, "controller and plant");
    }

    #[test]
    fn openmodelica_fixed_step_master_is_the_systems_first_annotation() {
        let ssd = system_description(&plant(), &controller(), None).unwrap();
        let master = r#"<ssd:Annotations>
      <ssc:Annotation type="org.openmodelica">
        <oms:Annotations>
          <oms:SimulationInformation>
            <oms:FixedStepMaster description="oms-ma" stepSize="0.02" relativeTolerance="0.0001"/>
          </oms:SimulationInformation>
        </oms:Annotations>
      </ssc:Annotation>
    </ssd:Annotations>
  </ssd:System>"#;
        assert!(ssd.contains(master), "{ssd}");
        assert_eq!(count(&ssd, "<ssc:Annotation "), 2, "OMSimulator's and OSP's");
        // the namespace is declared on the root only (libcosim reads xmlns attributes on children)
        assert_eq!(count(&ssd, "xmlns:oms="), 1);
        assert!(ssd.contains(&format!(r#"xmlns:oms="{NS_OMS}" version="1.0""#)));
    }

    fn avionics() -> (FmuInfo, FmuInfo, FmuInfo) {
        let sensors = FmuInfo {
            model_identifier: SENSORS.into(),
            ports: vec![port("pos_d", "input", "Real"), port("gps_height", "output", "Real")],
            units: vec![],
        };
        let ekf = FmuInfo {
            model_identifier: ESTIMATOR.into(),
            ports: vec![
                port("gps_height", "input", "Real"),
                port("thrust_cmd", "input", "Real"),
                port("pos_d", "output", "Real"),
            ],
            units: vec![],
        };
        let mut controller = controller();
        controller.ports.retain(|p| p.name != "phase");
        (sensors, ekf, controller)
    }

    #[test]
    fn avionics_system_wires_the_chain_by_name() {
        let (sensors, ekf, controller) = avionics();
        let ssd = avionics_system_description(&plant(), &sensors, &ekf, &controller, None).unwrap();
        for (from, to, name) in [
            ("plant", "sensors", "pos_d"),
            ("sensors", "estimator", "gps_height"),
            ("estimator", "controller", "pos_d"),
            ("controller", "plant", "thrust_cmd"),
            ("controller", "estimator", "thrust_cmd"),
        ] {
            let c = format!(
                r#"<ssd:Connection startElement="{from}" startConnector="{name}" endElement="{to}" endConnector="{name}"/>"#
            );
            assert!(ssd.contains(&c), "{c} missing");
        }
        assert!(!ssd.contains(r#"startElement="plant" startConnector="pos_d" endElement="controller""#));
    }

    #[test]
    fn avionics_system_refuses_an_undriven_estimator_input() {
        let (sensors, mut ekf, controller) = avionics();
        ekf.ports.push(port("mag_x", "input", "Real"));
        let e = avionics_system_description(&plant(), &sensors, &ekf, &controller, None).unwrap_err();
        assert!(e.contains("mag_x"), "{e}");
    }

    fn atmosphere() -> FmuInfo {
        let mut ports = vec![port("pos_d", "input", "Real"), port("wind_n", "output", "Real")];
        for (n, _) in ATMOSPHERE_PARAMS.iter() {
            let kind = if matches!(
                *n,
                "wind_profile" | "turbulence_model" | "turbulence_intensity" | "seed"
            ) {
                "Integer"
            } else {
                "Real"
            };
            ports.push(port(n, "parameter", kind));
        }
        FmuInfo {
            model_identifier: ATMOSPHERE.into(),
            ports,
            units: vec![],
        }
    }

    #[test]
    fn atmosphere_is_wired_by_name_and_bound_calm() {
        let ssd = system_description(&plant(), &controller(), Some(&atmosphere())).unwrap();
        for (from, to, name) in [("plant", "atmosphere", "pos_d"), ("atmosphere", "plant", "wind_n")] {
            let c = format!(
                r#"<ssd:Connection startElement="{from}" startConnector="{name}" endElement="{to}" endConnector="{name}"/>"#
            );
            assert!(ssd.contains(&c), "{c} missing");
        }
        let set = ssd
            .find(r#"<ssv:ParameterSet version="1.0" name="atmosphere">"#)
            .expect("atmosphere set");
        let value_of = |name: &str| {
            let at = ssd[set..]
                .find(&format!(r#"<ssv:Parameter name="{name}">"#))
                .unwrap_or_else(|| panic!("{name} not bound"));
            let rest = &ssd[set + at..];
            let v = rest.find("value=\"").expect("value") + 7;
            let (kind, value) = (&rest[..v], &rest[v..v + rest[v..].find('"').expect("quote")]);
            (kind.contains("ssv:Integer"), value.to_string())
        };
        assert_eq!(value_of("wind_speed"), (false, "0.0".to_string()));
        assert_eq!(value_of("turbulence_intensity"), (true, "0".to_string()));
        assert_eq!(value_of("gust_amplitude_n"), (false, "0.0".to_string()));
        // without the atmosphere the plant's wind inputs stay undeclared
        assert!(!system_description(&plant(), &controller(), None)
            .unwrap()
            .contains("wind_n"));
        // an atmosphere input no plant output drives is refused
        let mut a = atmosphere();
        a.ports.push(port("humidity", "input", "Real"));
        assert!(system_description(&plant(), &controller(), Some(&a))
            .unwrap_err()
            .contains("humidity"));
    }

    #[test]
    fn missing_mission_parameter_is_an_error() {
        let mut c = controller();
        c.ports.retain(|p| p.name != "t_level");
        assert!(system_description(&plant(), &c, None).unwrap_err().contains("t_level"));
    }

    #[test]
    fn parses_a_model_description() {
        let xml = r#"<?xml version="1.0"?><fmiModelDescription fmiVersion="2.0">
  <CoSimulation modelIdentifier="m"/>
  <UnitDefinitions><Unit name="m/s"><BaseUnit m="1" s="-1"/></Unit></UnitDefinitions>
  <ModelVariables>
    <ScalarVariable name="a&amp;b" valueReference="0" causality="output"><Real unit="m/s"/></ScalarVariable>
    <ScalarVariable name="k" valueReference="1" causality="parameter" variability="fixed"><Integer start="1"/></ScalarVariable>
    <ScalarVariable name="x" valueReference="2"><Real/></ScalarVariable>
  </ModelVariables></fmiModelDescription>"#;
        let info = parse_model_description(xml).unwrap();
        assert_eq!(info.model_identifier, "m");
        assert_eq!(
            info.units,
            [Unit {
                name: "m/s".into(),
                base: vec![("m".into(), "1".into()), ("s".into(), "-1".into())]
            }]
        );
        assert_eq!(info.ports[0].name, "a&b");
        assert_eq!(info.ports[0].unit.as_deref(), Some("m/s"));
        assert_eq!(info.ports[1].kind, "Integer");
        assert_eq!(info.ports[2].causality, "local");
    }
}
