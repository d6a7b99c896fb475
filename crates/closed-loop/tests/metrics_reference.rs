//! The Rust side of the metric agreement test: [`MissionCheck`], the wind profiles and the
//! reference-offset steps evaluated on a stored trajectory and time grid, against the values
//! stored in `tests/data/mission_metrics_rust.json`. `tests/test_metrics_agree.py` checks
//! that the Python metrics (`tailsim.metrics`) and profiles (`tailsim.master`) give the same
//! numbers from the same files. The stored trajectory (`tests/data/mission_metrics_trajectory.csv`)
//! is the LQR default mission flown by the fmpy master.
//!
//! After a deliberate change of the metrics, rewrite the reference with
//! `UPDATE_METRICS_REFERENCE=1 cargo test -p closed-loop --test metrics_reference`.

use std::path::PathBuf;

use closed_loop::{wind_from, CheckSample, Criteria, MissionCheck, Scenario, Wind};
use flight_mission::MissionParams;
use nalgebra::Vector3;
use serde_json::{json, Value};

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/data")
        .join(name)
}

/// Pitch of the level trim the check compares against (rad): an input of the reference,
/// near the plant's trim (7.41°).
const THETA_LEVEL_TRIM: f64 = 0.1293;

fn trajectory() -> Vec<CheckSample> {
    let text = std::fs::read_to_string(data("mission_metrics_trajectory.csv")).expect("stored trajectory");
    let mut lines = text.lines();
    let header: Vec<&str> = lines
        .next()
        .expect("header")
        .split(',')
        .map(|h| h.split(' ').next().unwrap_or(h))
        .collect();
    let col = |name: &str| header.iter().position(|h| *h == name).expect(name);
    let (t, phase, airspeed, theta) = (col("time"), col("phase"), col("airspeed"), col("theta"));
    let pos = [col("pos_n"), col("pos_e"), col("pos_d")];
    let reference = [col("ref_pos_n"), col("ref_pos_e"), col("ref_pos_d")];
    lines
        .map(|line| {
            let v: Vec<f64> = line.split(',').map(|x| x.parse().expect("number")).collect();
            let e = Vector3::from_fn(|i, _| v[pos[i]] - v[reference[i]]);
            CheckSample {
                t: v[t],
                phase: v[phase] as usize,
                pos_error: e.norm(),
                airspeed: v[airspeed],
                theta: v[theta],
                finite: v.iter().all(|x| x.is_finite()),
            }
        })
        .collect()
}

fn computed() -> Value {
    let mission = MissionParams::default();
    let samples = trajectory();
    let check = MissionCheck::of_samples(&samples, &mission, THETA_LEVEL_TRIM);
    let c = Criteria::get();

    let step = Wind::Step {
        t_start: 2.1,
        wind: Vector3::new(1.0, 2.0, 3.0),
    };
    let gust = Wind::OneMinusCosine {
        t_start: 1.0,
        duration: 2.0,
        amplitude: Vector3::new(0.0, 0.0, 6.0),
    };
    let mut scenario = Scenario::mission(mission);
    scenario.ref_offset_steps = vec![(2.1, Vector3::new(0.0, 5.0, 0.0))];
    let mut times: Vec<f64> = (0..=160).map(|k| f64::from(k) * 0.02).collect();
    times.extend([2.1 - 1e-12, 2.1 - 1e-6, 2.1 + 1e-12, 1.0 - 1e-12, 3.0 + 1e-12]);
    let profiles: Vec<Value> = times
        .iter()
        .map(|&t| {
            json!({
                "t": t,
                "step": step.at(t).as_slice(),
                "gust": gust.at(t).as_slice(),
                "ref_offset": scenario.ref_offset(t).as_slice(),
            })
        })
        .collect();

    // Steady winds from eight bearings (rad) at 7 m/s, switched on at 2.1 s (issue 16).
    let bearings: Vec<f64> = (0..8)
        .map(|k| f64::from(k) * std::f64::consts::FRAC_PI_4 + 0.1)
        .collect();
    let winds_from: Vec<Value> = bearings
        .iter()
        .map(|&b| {
            json!({
                "bearing": b,
                "wind": wind_from(b, 7.0).as_slice(),
                "step_before": Wind::step_from(2.1, b, 7.0).at(2.1 - 1e-6).as_slice(),
                "step_at": Wind::step_from(2.1, b, 7.0).at(105.0 * 0.02).as_slice(),
            })
        })
        .collect();

    json!({
        "winds_from": winds_from,
        "inputs": {
            "theta_level_trim": THETA_LEVEL_TRIM,
            "mission": {
                "t_vertical_1": mission.t_vertical_1,
                "t_transition_1": mission.t_transition_1,
                "t_level": mission.t_level,
                "t_transition_2": mission.t_transition_2,
                "t_vertical_2": mission.t_vertical_2,
                "v_level": mission.v_level,
            },
            "step": {"t_start": 2.1, "value": [1.0, 2.0, 3.0]},
            "gust": {"t_start": 1.0, "duration": 2.0, "amplitude": [0.0, 0.0, 6.0]},
            "ref_offset": {"t": 2.1, "value": [0.0, 5.0, 0.0]},
        },
        "criteria": {
            "level_window": c.level_window,
            "level_airspeed_error_max": c.level_airspeed_error_max,
            "level_pitch_error_max_rad": c.level_pitch_error_max,
            "final_pitch_error_max_rad": c.final_pitch_error_max,
            "edge_tolerance": c.edge_tolerance,
        },
        "mission_check": {
            "level_airspeed_error": check.level_airspeed_error,
            "level_pitch_error": check.level_pitch_error,
            "final_pitch_error": check.final_pitch_error,
            "all_finite": check.all_finite,
            "passed": check.passed(),
            "phase_samples": check.phase_errors.iter().map(|e| e.samples).collect::<Vec<_>>(),
            "phase_max": check.phase_errors.iter().map(|e| e.max).collect::<Vec<_>>(),
            "phase_rms": check.phase_errors.iter().map(|e| e.rms).collect::<Vec<_>>(),
        },
        "profiles": profiles,
    })
}

/// Equal JSON, numbers to 1 ulp-level (serde_json's default parser may round the last bit).
fn same(a: &Value, b: &Value, at: &str) -> Result<(), String> {
    match (a, b) {
        (Value::Number(x), Value::Number(y)) => {
            let (x, y) = (x.as_f64().unwrap_or(f64::NAN), y.as_f64().unwrap_or(f64::NAN));
            if (x - y).abs() <= 1e-15 * x.abs().max(y.abs()) {
                Ok(())
            } else {
                Err(format!("{at}: computed {x}, stored {y}"))
            }
        }
        (Value::Array(x), Value::Array(y)) if x.len() == y.len() => x
            .iter()
            .zip(y)
            .enumerate()
            .try_for_each(|(i, (x, y))| same(x, y, &format!("{at}[{i}]"))),
        (Value::Object(x), Value::Object(y)) if x.len() == y.len() => x.iter().try_for_each(|(k, v)| {
            y.get(k)
                .ok_or_else(|| format!("{at}.{k}: not stored"))
                .and_then(|w| same(v, w, &format!("{at}.{k}")))
        }),
        _ if a == b => Ok(()),
        _ => Err(format!("{at}: computed {a}, stored {b}")),
    }
}

#[test]
fn stored_rust_metrics_are_what_rust_computes() {
    let path = data("mission_metrics_rust.json");
    let now = computed();
    if std::env::var_os("UPDATE_METRICS_REFERENCE").is_some() {
        let text = serde_json::to_string_pretty(&now).expect("json") + "\n";
        std::fs::write(&path, text).expect("write reference");
    }
    let stored: Value = serde_json::from_str(&std::fs::read_to_string(&path).expect("stored reference")).expect("json");
    if let Err(e) = same(&now, &stored, "") {
        panic!("{e} (rerun with UPDATE_METRICS_REFERENCE=1 after a deliberate change)");
    }
    // The trajectory exercises the window edge: level flight ends at t = 20 s, its window
    // starts at 15 s, a communication point stored as exactly 15 and one as 20.
    let samples = trajectory();
    assert!(samples.iter().any(|s| s.t == 15.0) && samples.iter().any(|s| s.t == 20.0));
    let check = &now["mission_check"];
    assert_eq!(check["passed"], json!(true));
    assert!(check["level_airspeed_error"].as_f64().unwrap() > 0.0);
    // Level flight lasts 10 s: 500 communication points of 0.02 s.
    assert_eq!(check["phase_samples"][2], json!(500));
}
