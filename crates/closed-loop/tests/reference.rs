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

/// The columns of a sample: (FMU port name, value).
fn columns(s: &Sample) -> Vec<(&'static str, f64)> {
    let c = &s.command;
    let g = &s.diagnostics;
    let mut row = vec![("time", s.t)];
    row.extend(s.measurement.named_values());
    row.extend([
        ("thrust_cmd", c.thrust),
        ("elevator_cmd", c.elevator),
        ("aileron_cmd", c.aileron),
        ("rudder_cmd", c.rudder),
        ("flap_collective_cmd", c.flap_collective),
        ("flap_differential_cmd", c.flap_differential),
        ("vertical_flap_cmd", c.vertical_flap),
        ("ref_pos_n", g.ref_pos_ned.x),
        ("ref_pos_e", g.ref_pos_ned.y),
        ("ref_pos_d", g.ref_pos_ned.z),
        ("ref_airspeed", g.ref_airspeed),
        ("phase", g.phase.code() as f64),
    ]);
    row
}

fn reference_path(controller: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/reference")
        .join(format!("tailsitter_{controller}_default_ref.csv"))
}

/// The default mission from the plant's trimmed vertical climb (what the plant
/// FMU starts in with its default parameters), sampled every `DECIMATION` points.
/// The column names and the decimated rows of the default mission.
fn fly_default(controller: &mut impl FlightController) -> (Vec<&'static str>, Vec<Vec<f64>>) {
    let mission = MissionParams::default();
    let plant = Plant::new(Airframe::default());
    let x0 = plant.trim_vertical_climb(mission.v_vertical).unwrap().state;
    let trace = fly(&plant, x0, controller, &Scenario::mission(mission));
    assert!(trace.completed(), "{:?}", trace.failure);
    let names = columns(&trace.samples[0]).iter().map(|c| c.0).collect();
    let rows = trace
        .samples
        .iter()
        .step_by(DECIMATION)
        .map(|s| columns(s).iter().map(|c| c.1).collect())
        .collect();
    (names, rows)
}

fn write_csv(path: &PathBuf, names: &[&str], rows: &[Vec<f64>]) {
    let mut text = names.join(",");
    text.push('\n');
    for row in rows {
        // `{:?}` of f64: shortest text that reads back to the same double.
        text.push_str(&row.iter().map(|v| format!("{v:?}")).collect::<Vec<_>>().join(","));
        text.push('\n');
    }
    std::fs::write(path, text).unwrap();
}

fn check(controller: &str, (names, rows): (Vec<&str>, Vec<Vec<f64>>)) {
    let path = reference_path(controller);
    if std::env::var_os("TAILSIM_REGEN_REFERENCE").is_some() {
        write_csv(&path, &names, &rows);
        eprintln!("wrote {}", path.display());
    }
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
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
    check("lqr", fly_default(&mut c));
}

#[test]
fn tsd_default_mission_matches_reference() {
    let mut c = TsdController::with_mission(MissionParams::default()).unwrap();
    check("tsd", fly_default(&mut c));
}
