//! Regression data: the default mission flown by both controllers through the
//! reference master (Gauss-Seidel, 20 ms) must reproduce the stored reference
//! trajectories `tests/reference/tailsitter_{lqr,tsd}_default_ref.csv` to 1e-9
//! (relative to max(1, |value|)), like the Reference FMUs' `<model>_ref.csv`.
//!
//! The files were written by this test on reviewed code; regenerate them (only
//! after a deliberate change of behaviour, and review the diff) with
//!
//! ```sh
//! TAILSIM_REGEN_REFERENCE=1 cargo test -p closed-loop --test reference
//! ```
//!
//! `tests/test_reference.py` checks the packaged FMUs under the fmpy master
//! against the same files.

use std::path::PathBuf;

use closed_loop::{fly, Sample, Scenario};
use flight_mission::{FlightController, MissionParams};
use lqr_control::{LqrController, LqrParams};
use tailsitter_physics::{Airframe, Plant};
use tsd_control::TsdController;

/// Every `DECIMATION`-th communication point is stored.
const DECIMATION: usize = 5;
/// Tolerance, relative to max(1, |reference|).
const TOLERANCE: f64 = 1e-9;

/// Column names (the FMU port names) and how to read them from a sample.
#[allow(clippy::type_complexity)]
const COLUMNS: &[(&str, fn(&Sample) -> f64)] = &[
    ("time", |s| s.t),
    ("pos_n", |s| s.measurement.pos_ned.x),
    ("pos_e", |s| s.measurement.pos_ned.y),
    ("pos_d", |s| s.measurement.pos_ned.z),
    ("vel_n", |s| s.measurement.vel_ned.x),
    ("vel_e", |s| s.measurement.vel_ned.y),
    ("vel_d", |s| s.measurement.vel_ned.z),
    ("u", |s| s.measurement.vel_body.x),
    ("v", |s| s.measurement.vel_body.y),
    ("w", |s| s.measurement.vel_body.z),
    ("p", |s| s.measurement.rates.x),
    ("q", |s| s.measurement.rates.y),
    ("r", |s| s.measurement.rates.z),
    ("quat_1", |s| s.measurement.quat[0]),
    ("quat_2", |s| s.measurement.quat[1]),
    ("quat_3", |s| s.measurement.quat[2]),
    ("quat_4", |s| s.measurement.quat[3]),
    ("airspeed", |s| s.measurement.airspeed),
    ("alpha", |s| s.measurement.alpha),
    ("beta", |s| s.measurement.beta),
    ("thrust", |s| s.measurement.thrust),
    ("elevator", |s| s.measurement.surfaces[0]),
    ("aileron", |s| s.measurement.surfaces[1]),
    ("rudder", |s| s.measurement.surfaces[2]),
    ("flap_collective", |s| s.measurement.surfaces[3]),
    ("flap_differential", |s| s.measurement.surfaces[4]),
    ("vertical_flap", |s| s.measurement.surfaces[5]),
    ("accel_x", |s| s.measurement.specific_force_body.x),
    ("accel_y", |s| s.measurement.specific_force_body.y),
    ("accel_z", |s| s.measurement.specific_force_body.z),
    ("induced_velocity", |s| s.measurement.induced_velocity),
    ("thrust_cmd", |s| s.command.thrust),
    ("elevator_cmd", |s| s.command.elevator),
    ("aileron_cmd", |s| s.command.aileron),
    ("rudder_cmd", |s| s.command.rudder),
    ("flap_collective_cmd", |s| s.command.flap_collective),
    ("flap_differential_cmd", |s| s.command.flap_differential),
    ("vertical_flap_cmd", |s| s.command.vertical_flap),
    ("ref_pos_n", |s| s.diagnostics.ref_pos_ned.x),
    ("ref_pos_e", |s| s.diagnostics.ref_pos_ned.y),
    ("ref_pos_d", |s| s.diagnostics.ref_pos_ned.z),
    ("ref_airspeed", |s| s.diagnostics.ref_airspeed),
    ("phase", |s| s.diagnostics.phase.code() as f64),
];

fn reference_path(controller: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/reference")
        .join(format!("tailsitter_{controller}_default_ref.csv"))
}

/// The default mission from the plant's trimmed vertical climb (what the plant
/// FMU starts in with its default parameters), sampled every `DECIMATION` points.
fn fly_default(controller: &mut impl FlightController) -> Vec<Vec<f64>> {
    let mission = MissionParams::default();
    let plant = Plant::new(Airframe::default());
    let x0 = plant.trim_vertical_climb(mission.v_vertical).unwrap().state;
    let trace = fly(&plant, x0, controller, &Scenario::mission(mission));
    assert!(trace.completed(), "{:?}", trace.failure);
    trace
        .samples
        .iter()
        .step_by(DECIMATION)
        .map(|s| COLUMNS.iter().map(|(_, f)| f(s)).collect())
        .collect()
}

fn write_csv(path: &PathBuf, rows: &[Vec<f64>]) {
    let mut text = COLUMNS.iter().map(|(n, _)| *n).collect::<Vec<_>>().join(",");
    text.push('\n');
    for row in rows {
        // `{:?}` of f64: shortest text that reads back to the same double.
        text.push_str(&row.iter().map(|v| format!("{v:?}")).collect::<Vec<_>>().join(","));
        text.push('\n');
    }
    std::fs::write(path, text).unwrap();
}

fn check(controller: &str, rows: &[Vec<f64>]) {
    let path = reference_path(controller);
    if std::env::var_os("TAILSIM_REGEN_REFERENCE").is_some() {
        write_csv(&path, rows);
        eprintln!("wrote {}", path.display());
    }
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let names: Vec<&str> = COLUMNS.iter().map(|(n, _)| *n).collect();
    assert_eq!(header, names, "columns of {}", path.display());
    let stored: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    assert_eq!(stored.len(), rows.len(), "rows of {}", path.display());
    let mut worst = (0.0, "", 0.0);
    for (got, want) in rows.iter().zip(&stored) {
        for ((g, w), name) in got.iter().zip(want).zip(&names) {
            let err = (g - w).abs() / w.abs().max(1.0);
            if err > worst.0 || err.is_nan() {
                worst = (err, name, want[0]);
            }
        }
    }
    println!(
        "{controller}: worst relative deviation {:.1e} ({} at t = {})",
        worst.0, worst.1, worst.2
    );
    assert!(
        worst.0 <= TOLERANCE,
        "{controller}: {} at t = {} deviates by {:e} from {}",
        worst.1,
        worst.2,
        worst.0,
        path.display()
    );
}

#[test]
fn lqr_default_mission_matches_reference() {
    let mission = MissionParams::default();
    let mut c = LqrController::new(Airframe::default(), mission, LqrParams::default()).unwrap();
    check("lqr", &fly_default(&mut c));
}

#[test]
fn tsd_default_mission_matches_reference() {
    let mut c = TsdController::with_mission(MissionParams::default()).unwrap();
    check("tsd", &fly_default(&mut c));
}
