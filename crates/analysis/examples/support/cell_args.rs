//! The wind-envelope probes' common positional arguments:
//! `lqr|tsd default|tl|handover step|turb SPEEDS BEARING_INDICES`, SPEEDS and
//! BEARING_INDICES comma-separated (or `all` bearings).
use analysis::controllers::Kind;
use analysis::wind_envelope::{MissionKind, WindForm, BEARINGS_DEG};

/// The cells a probe flies: controller, mission, wind form, speeds (m/s), bearing indices.
pub struct CellArgs {
    pub kind: Kind,
    pub mission: MissionKind,
    pub form: WindForm,
    pub speeds: Vec<f64>,
    pub bearings: Vec<usize>,
}

/// Reads `a[1..=5]` (`a[0]` is the program).
pub fn parse(a: &[String]) -> CellArgs {
    let kind = if a[1] == "lqr" { Kind::Lqr } else { Kind::Tsd };
    let mission = match a[2].as_str() {
        "default" => MissionKind::Default,
        "tl" => MissionKind::TakeoffLanding,
        _ => MissionKind::Handover,
    };
    let form = if a[3] == "step" {
        WindForm::Step
    } else {
        WindForm::Turbulent
    };
    let speeds = a[4].split(',').map(|s| s.parse().unwrap()).collect();
    let bearings = if a[5] == "all" {
        (0..BEARINGS_DEG.len()).collect()
    } else {
        a[5].split(',').map(|s| s.parse().unwrap()).collect()
    };
    CellArgs {
        kind,
        mission,
        form,
        speeds,
        bearings,
    }
}
