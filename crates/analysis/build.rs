//! Hashes the source of every crate whose code decides the sweep results
//! (physics, mission, guidance, closed loop and its mission criteria, both controllers, the
//! atmosphere, sensors and estimator, the declarations their parameter defaults are generated from, this crate) into
//! `RESULTS_SOURCE_HASH`, part of every cache key: editing any of them
//! invalidates the cached results instead of serving stale ones.

use std::path::{Path, PathBuf};

const SOURCES: &[&str] = &[
    "../tailsitter-physics/src",
    "../flight-mission/src",
    "../guidance/src",
    "../closed-loop/src",
    "../lqr-control/src",
    "../lqr-control/resources",
    "../tsd-control/src",
    "../atmosphere/src",
    "../sensor-model/src",
    "../state-estimator/src",
    "../../modelDescription/tailsitter_atmosphere.json",
    "../../modelDescription/tailsitter_sensors.json",
    "../../modelDescription/tailsitter_ekf.json",
    "../../modelDescription/fragments",
    "../../modelDescription/tailsitter_plant.json",
    "../../modelDescription/tailsitter_lqr.json",
    "../../modelDescription/tailsitter_tsd.json",
    "../../modelDescription/src/defaults.rs",
    "src",
];

fn files(dir: &Path, out: &mut Vec<PathBuf>) {
    if dir.is_file() {
        out.push(dir.to_path_buf());
        return;
    }
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    for entry in entries.flatten() {
        let path = entry.path();
        if path.is_dir() {
            files(&path, out);
        } else {
            out.push(path);
        }
    }
}

fn main() {
    let mut paths = Vec::new();
    for dir in SOURCES {
        println!("cargo:rerun-if-changed={dir}");
        files(Path::new(dir), &mut paths);
    }
    paths.sort();
    // FNV-1a 64 over (path, contents) of every file.
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for path in &paths {
        let bytes = std::fs::read(path).unwrap_or_default();
        for b in path.to_string_lossy().as_bytes().iter().chain(bytes.iter()) {
            h ^= u64::from(*b);
            h = h.wrapping_mul(0x0000_0100_0000_01b3);
        }
    }
    println!("cargo:rustc-env=RESULTS_SOURCE_HASH={h:016x}");
}
