//! The flown back transitions of docs/TRANSITION.md as JSON: every controller on the default
//! mission with T2 shortened ([`T2_VALUES`]), on the thesis and the global aerodynamics
//! ([`flown`]), with the profile's own times.
//!
//! `cargo run --release -p analysis --example transition_flown -- docs/transition_flown.json`
//! (then `python -m tailsim.reports.docs --write`).
use analysis::controllers::Kind;
use analysis::transition_bound::{flown, mission, POS_ERROR_LIMIT, T2_VALUES};
use rayon::prelude::*;
use serde_json::json;
use tailsitter_physics::AeroModel;

/// NaN (never reached) as JSON null.
fn num(x: f64) -> serde_json::Value {
    if x.is_finite() {
        json!(x)
    } else {
        serde_json::Value::Null
    }
}

fn main() {
    let out = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "docs/transition_flown.json".into());
    let jobs: Vec<(AeroModel, Kind, f64)> = [AeroModel::Thesis, AeroModel::Global]
        .into_iter()
        .flat_map(|m| Kind::ALL.into_iter().flat_map(move |k| T2_VALUES.map(|t2| (m, k, t2))))
        .collect();
    let rows: Vec<serde_json::Value> = jobs
        .par_iter()
        .map(|&(model, kind, t2)| {
            let r = flown(kind, model, t2);
            json!({
                "controller": r.controller,
                "aero": r.aero,
                "t2": r.t2,
                "completed": r.completed,
                "tracked": r.tracked(),
                "max_pos_error": num(r.max_pos_error),
                "max_alpha_deg": num(r.max_alpha_deg),
                "rotation": num(r.rotation),
                "transition": num(r.transition),
                "profile_rotation": num(r.profile_rotation),
                "profile_transition": num(r.profile_transition),
            })
        })
        .collect();
    let m = mission(T2_VALUES[0]);
    let doc = json!({
        "command": format!("cargo run --release -p analysis --example transition_flown -- {out}"),
        "pos_error_limit": POS_ERROR_LIMIT,
        "mission": {
            "t_vertical_1": m.t_vertical_1, "t_transition_1": m.t_transition_1, "t_level": m.t_level,
            "t_vertical_2": m.t_vertical_2, "v_vertical": m.v_vertical,
            "transition_alpha_max_deg": m.transition_alpha_max.to_degrees(),
            "transition_thrust_fraction": m.transition_thrust_fraction, "sample_time": m.sample_time,
        },
        "rows": rows,
    });
    std::fs::write(&out, serde_json::to_string_pretty(&doc).unwrap() + "\n").unwrap();
    println!("wrote {out}: {} flights", jobs.len());
}
