//! Which Rust parameter structs take their `impl Default` from which declared group: the
//! table [`CRATES`] drives each pure crate's build script ([`build`]), `cargo xtask regen`
//! (the reviewed copies `modelDescription/generated/<out>`) and the test that no declared
//! type gets a hand-written `impl Default` again.

use crate::{load_declarations, rust, DeclError};
use std::path::{Path, PathBuf};

/// A field of a struct that no parameter of its group sets.
#[derive(Debug, Clone, Copy)]
pub enum Extra {
    /// The start value of the ungrouped variable of this name.
    Start(&'static str),
    /// The variant of an enum (path prefix, e.g. `FaultMode`) indexed by the Integer start
    /// value of the ungrouped variable `name`.
    Variant {
        name: &'static str,
        variants: &'static [&'static str],
    },
    /// The field type's own (generated) `Default`: a struct of another group.
    Default,
}

/// One struct whose `impl Default` is generated.
#[derive(Debug, Clone, Copy)]
pub struct StructDefaults {
    /// The Rust type, as named in its crate.
    pub type_name: &'static str,
    /// The declared parameter group.
    pub group: &'static str,
    /// `""`: the group's own fields; else only the fields `<prefix>.*`, without the prefix.
    pub prefix: &'static str,
    /// Fields set from outside the group: (field, source).
    pub extra: &'static [(&'static str, Extra)],
    /// Also generate `named_values()` / `named_values_mut()` (Real groups only).
    pub named_values: bool,
}

/// Generated defaults of a crate: one file `OUT_DIR/<out>` (a crate may have several).
#[derive(Debug, Clone, Copy)]
pub struct CrateDefaults {
    /// Package name; its sources are `crates/<krate>/src`.
    pub krate: &'static str,
    /// Declaration file, relative to `modelDescription/`.
    pub file: &'static str,
    /// Generated file name (in `OUT_DIR` and `modelDescription/generated/`).
    pub out: &'static str,
    pub structs: &'static [StructDefaults],
}

const fn plain(type_name: &'static str, group: &'static str, prefix: &'static str) -> StructDefaults {
    StructDefaults {
        type_name,
        group,
        prefix,
        extra: &[],
        named_values: false,
    }
}

/// [`plain`] with the `named_values` table as well.
const fn named(type_name: &'static str, group: &'static str) -> StructDefaults {
    StructDefaults {
        named_values: true,
        ..plain(type_name, group, "")
    }
}

/// Every generated `impl Default`.
pub const CRATES: &[CrateDefaults] = &[
    CrateDefaults {
        krate: "tailsitter-physics",
        file: "tailsitter_plant.json",
        out: "airframe_generated.rs",
        structs: &[named("Airframe", "airframe")],
    },
    CrateDefaults {
        krate: "tailsitter-physics",
        file: "tailsitter_plant.json",
        out: "ground_generated.rs",
        structs: &[plain("Ground", "ground", "")],
    },
    CrateDefaults {
        krate: "tailsitter-physics",
        file: "tailsitter_plant.json",
        out: "global_aero_generated.rs",
        structs: &[StructDefaults {
            extra: &[(
                "model",
                Extra::Variant {
                    name: "aero_model",
                    variants: &["AeroModel::Thesis", "AeroModel::Global"],
                },
            )],
            ..plain("GlobalAero", "global_aero", "")
        }],
    },
    CrateDefaults {
        krate: "tailsitter-physics",
        file: "fragments/site.json",
        out: "site_generated.rs",
        structs: &[plain("Site", "site", "")],
    },
    CrateDefaults {
        krate: "flight-mission",
        file: "fragments/controller_interface.json",
        out: "mission_generated.rs",
        structs: &[named("MissionParams", "mission")],
    },
    CrateDefaults {
        krate: "lqr-control",
        file: "tailsitter_lqr.json",
        out: "lqr_params_generated.rs",
        structs: &[plain("LqrParams", "lqr", "")],
    },
    CrateDefaults {
        krate: "tsd-control",
        file: "tailsitter_tsd.json",
        out: "tsd_params_generated.rs",
        structs: &[plain("TsdParams", "tsd", "")],
    },
    CrateDefaults {
        krate: "px4-control",
        file: "tailsitter_px4.json",
        out: "px4_params_generated.rs",
        structs: &[plain("Px4Params", "px4", "")],
    },
    CrateDefaults {
        krate: "sensor-model",
        file: "tailsitter_sensors.json",
        out: "sensor_params_generated.rs",
        structs: &[StructDefaults {
            extra: &[
                ("site", Extra::Default),
                ("seed", Extra::Start("seed")),
                (
                    "fault_mode",
                    Extra::Variant {
                        name: "fault_mode",
                        variants: &["FaultMode::None", "FaultMode::Stuck", "FaultMode::Offset"],
                    },
                ),
            ],
            ..plain("Params", "params", "")
        }],
    },
    CrateDefaults {
        krate: "state-estimator",
        file: "tailsitter_ekf.json",
        out: "estimator_params_generated.rs",
        structs: &[
            plain("SensorNoise", "estimator", "noise"),
            plain("ProcessNoise", "estimator", "process"),
            StructDefaults {
                extra: &[("site", Extra::Default)],
                ..plain("Earth", "estimator", "earth")
            },
            StructDefaults {
                extra: &[("gps_reset_after", Extra::Start("gps_reset_after"))],
                ..plain("Tuning", "estimator", "tuning")
            },
            plain("AnalogFilter", "estimator", "filter"),
            plain("Prediction", "estimator", "prediction"),
        ],
    },
];

/// The generated file of `c` and every declaration file read.
pub fn generate(dir: &Path, c: &CrateDefaults) -> Result<(String, Vec<PathBuf>), DeclError> {
    let (decls, sources) = load_declarations(dir, c.file)?;
    let source = format!("modelDescription/{}", c.file);
    let mut text = String::new();
    for s in c.structs {
        let extra: Vec<(&str, String)> = s
            .extra
            .iter()
            .map(|(field, e)| {
                let value = match e {
                    Extra::Start(name) => rust::start_of(&decls, name),
                    Extra::Default => "Default::default()".to_string(),
                    Extra::Variant { name, variants } => {
                        let start = rust::start_of(&decls, name);
                        let index: usize = start.parse().map_err(|_| DeclError(format!("{name}: start {start}")))?;
                        variants
                            .get(index)
                            .ok_or_else(|| DeclError(format!("{name}: start {start} names no variant")))?
                            .to_string()
                    }
                };
                Ok((*field, value))
            })
            .collect::<Result<_, DeclError>>()?;
        if !text.is_empty() {
            text.push('\n');
        }
        if s.named_values {
            assert!(
                s.prefix.is_empty() && extra.is_empty(),
                "{}: named values of a whole group only",
                s.type_name
            );
            text += &rust::group_defaults(&decls, s.group, s.type_name, &source);
        } else {
            text += &rust::struct_defaults(&decls, s.group, s.prefix, s.type_name, &source, &extra);
        }
    }
    Ok((text, sources))
}

/// The entries of crate `krate` in [`CRATES`].
pub fn of(krate: &str) -> Vec<&'static CrateDefaults> {
    let entries: Vec<_> = CRATES.iter().filter(|c| c.krate == krate).collect();
    assert!(!entries.is_empty(), "no generated defaults for crate '{krate}'");
    entries
}

/// Build-script entry: writes every `OUT_DIR/<out>` of the calling crate
/// (`CARGO_PKG_NAME`) and prints `cargo:rerun-if-changed` for every declaration read.
pub fn build() {
    let var = |name: &str| PathBuf::from(std::env::var(name).unwrap_or_else(|_| panic!("{name} set by cargo")));
    let krate = std::env::var("CARGO_PKG_NAME").expect("set by cargo");
    let dir = var("CARGO_MANIFEST_DIR").join("../../modelDescription");
    for c in of(&krate) {
        let (text, sources) = generate(&dir, c).unwrap_or_else(|e| panic!("declaration {}: {e}", c.file));
        std::fs::write(var("OUT_DIR").join(c.out), text).unwrap_or_else(|e| panic!("write {}: {e}", c.out));
        for s in sources {
            println!("cargo:rerun-if-changed={}", s.display());
        }
    }
}
