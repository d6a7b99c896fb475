//! The minimum back-transition times of docs/TRANSITION.md as JSON (the point-mass model
//! trimmed in pitch, `analysis::transition_bound`): the trimmed lift of both trim laws, the
//! rotation and complete-transition bounds of every trim law × α_max × α lag, the rotation
//! without the pitch-rate derivatives and both bounds on the global aerodynamics, and the
//! profile's own times with T2 = 0.5 s.
//!
//! `cargo run --release -p analysis --example transition_bounds -- docs/transition_bounds.json`
//! (then `python -m tailsim.reports.docs --write`).
use analysis::transition_bound::{
    complete_bound, fastest_profile_limits, mission, profile_time, profile_time_within, rotation_bound, Bound, Model,
    TrimLaw, ALPHA_LAG,
};
use rayon::prelude::*;
use serde_json::{json, Value};
use tailsitter_physics::AeroModel;

/// NaN (not reached) and ±∞ (no switch) as JSON null.
fn num(x: f64) -> Value {
    if x.is_finite() {
        json!(x)
    } else {
        Value::Null
    }
}

fn bound(b: &Bound) -> Value {
    json!({
        "time": num(b.time), "entry": num(b.entry), "holds": b.holds,
        "t_cut": num(b.switches.t_cut), "v_on": num(b.switches.v_on),
        "gamma_s_deg": num(b.switches.gamma_s.to_degrees()),
        "peak_n": num(b.peak_n), "peak_n_total": num(b.peak_n_total), "v_at_peak": num(b.v_at_peak),
        "max_flap_deg": num(b.max_flap.to_degrees()), "saturated": b.saturated,
    })
}

const ALPHAS_DEG: [f64; 2] = [12.0, 15.0];
const V_LEVEL: f64 = 25.0;

fn main() {
    let out = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "docs/transition_bounds.json".into());
    let trims: Vec<Value> = TrimLaw::ALL
        .iter()
        .map(|&trim| {
            let m = Model::new(trim, 0.0);
            let no_rates = Model { rate_terms: false, ..m };
            let (alpha_trim, t_trim) = m.level_trim(V_LEVEL);
            let w = m.airframe.mass * m.airframe.gravity;
            let a2 = 2f64.to_radians();
            let at: Vec<Value> = ALPHAS_DEG
                .iter()
                .map(|&deg| {
                    let a = deg.to_radians();
                    let thrusts: Vec<Value> = [0.0, t_trim, m.airframe.thrust_max]
                        .iter()
                        .map(|&thrust| {
                            let f = no_rates.trimmed(V_LEVEL, a, thrust, 0.0);
                            json!({
                                "thrust": thrust, "n_aero": f.lift / w, "n_total": (f.lift + thrust * a.sin()) / w,
                                "delta_e_deg": f.delta_e.to_degrees(), "delta_fc_deg": f.delta_fc.to_degrees(),
                                "saturated": f.saturated,
                            })
                        })
                        .collect();
                    json!({"alpha_deg": deg, "cl_trimmed": no_rates.trimmed_cl(a), "at_25_m_s": thrusts})
                })
                .collect();
            json!({
                "trim": trim.name(), "cl_slope_small_alpha": m.trimmed_cl(a2) / a2,
                "level_trim_alpha_deg": alpha_trim.to_degrees(), "level_trim_thrust": t_trim, "alpha": at,
            })
        })
        .collect();
    // (trim, τ_α, α_max, aerodynamics, pitch-rate derivatives, with the complete transition)
    let mut cases = Vec::new();
    for trim in TrimLaw::ALL {
        for tau in [0.0, ALPHA_LAG] {
            for deg in ALPHAS_DEG {
                cases.push((trim, tau, deg, AeroModel::Thesis, true, true));
            }
        }
        for deg in ALPHAS_DEG {
            cases.push((trim, 0.0, deg, AeroModel::Thesis, false, false));
            cases.push((trim, 0.0, deg, AeroModel::Global, true, true));
        }
    }
    let bounds: Vec<Value> = cases
        .par_iter()
        .map(|&(trim, tau, deg, aero, rates, complete)| {
            let m = Model {
                aero,
                rate_terms: rates,
                ..Model::new(trim, tau)
            };
            let a = deg.to_radians();
            json!({
                "trim": trim.name(), "tau_alpha": tau, "alpha_max_deg": deg,
                "aero": if aero == AeroModel::Global { "global" } else { "thesis" }, "rate_terms": rates,
                "rotation": bound(&rotation_bound(&m, a, V_LEVEL)),
                "complete": if complete { bound(&complete_bound(&m, a, V_LEVEL)) } else { Value::Null },
            })
        })
        .collect();
    let profile: Vec<Value> = ALPHAS_DEG
        .iter()
        .map(|&deg| {
            let limits = fastest_profile_limits(deg.to_radians());
            let m = mission(0.5);
            json!({
                "t2": 0.5, "alpha_max_deg": deg,
                "rotation_within_2_deg": num(profile_time_within(&m, &limits, true, 2f64.to_radians())),
                "rotation_within_5_deg": num(profile_time(&m, &limits, true)),
                "complete": num(profile_time(&m, &limits, false)),
            })
        })
        .collect();
    let doc = json!({
        "command": format!("cargo run --release -p analysis --example transition_bounds -- {out}"),
        "v_level": V_LEVEL, "alpha_lag": ALPHA_LAG, "trims": trims, "bounds": bounds, "profile": profile,
    });
    std::fs::write(&out, serde_json::to_string_pretty(&doc).unwrap() + "\n").unwrap();
    println!("wrote {out}: {} bounds", cases.len());
}
