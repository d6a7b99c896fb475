//! The trims docs/DESIGN.md and docs/TRANSITION.md quote, as JSON: the plant's level trim at
//! the mission's V_L and its vertical-climb trim at V_V (`Plant::trim_level`,
//! `Plant::trim_vertical_climb`, the default airframe) on the thesis's aerodynamic model (the
//! controllers' design model) and on the global one (the plant FMU's default), and the
//! point-mass model's climb thrust T_climb = m g + D at V_V (`transition_bound::Model`).
//!
//! `cargo run --release -p analysis --example design_trims -- docs/design_trims.json`
//! (then `python -m tailsim.reports.docs --write`).
use analysis::transition_bound::{Model, TrimLaw};
use flight_mission::MissionParams;
use serde_json::json;
use tailsitter_physics::{AeroModel, Airframe, Plant, Trim};

fn trim(t: &Trim, a: &Airframe) -> serde_json::Value {
    let qbar_s = 0.5 * a.air_density * t.airspeed * t.airspeed * a.wing_area;
    json!({
        "airspeed": t.airspeed,
        "alpha_deg": t.alpha.to_degrees(),
        "theta_deg": t.theta.to_degrees(),
        "thrust": t.thrust,
        "elevator_deg": t.elevator.to_degrees(),
        "induced_velocity": t.induced_velocity,
        // the lift coefficient the weight asks of the whole airframe (surfaces included)
        "c_l_needed": (a.mass * a.gravity - t.thrust * t.alpha.sin()) / qbar_s,
        "residual": t.residual,
    })
}

fn main() -> Result<(), String> {
    let out = std::env::args().nth(1).ok_or("usage: design_trims OUT.json")?;
    let mission = MissionParams::default();
    let airframe = Airframe::default();
    let mut models = serde_json::Map::new();
    for (name, model) in [("thesis", AeroModel::Thesis), ("global", AeroModel::Global)] {
        let mut plant = Plant::new(airframe);
        plant.aero.model = model;
        let level = plant
            .trim_level(mission.v_level)
            .map_err(|e| format!("{name} level trim: {e}"))?;
        let climb = plant
            .trim_vertical_climb(mission.v_vertical)
            .map_err(|e| format!("{name} climb trim: {e}"))?;
        models.insert(
            name.into(),
            json!({"level": trim(&level, &airframe), "climb": trim(&climb, &airframe)}),
        );
    }
    let point_mass = Model::new(TrimLaw::ElevatorOnly, 0.0);
    let doc = json!({
        "command": "cargo run --release -p analysis --example design_trims -- docs/design_trims.json",
        "v_level": mission.v_level,
        "v_vertical": mission.v_vertical,
        "mass": airframe.mass,
        "gravity": airframe.gravity,
        "plant": models,
        "point_mass_t_climb": point_mass.climb_thrust(mission.v_vertical),
    });
    let text = serde_json::to_string_pretty(&doc).map_err(|e| e.to_string())? + "\n";
    std::fs::write(&out, text).map_err(|e| format!("{out}: {e}"))?;
    println!("wrote {out}");
    Ok(())
}
