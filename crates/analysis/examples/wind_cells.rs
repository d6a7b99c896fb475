//! Selected cells of the wind envelope with per-phase errors (a development probe):
//! `wind_cells lqr|tsd default|tl|handover step|turb SPEEDS BEARING_INDICES [TRACE.csv]`,
//! SPEEDS and BEARING_INDICES comma-separated. With a trace file (one cell) the time history
//! (t, phase, error, position, reference, θ, heading, wind) is written.
use analysis::controllers::Kind;
use analysis::wind_envelope::{MissionKind, WindForm, BEARINGS_DEG};
use rayon::prelude::*;

fn main() {
    let a: Vec<String> = std::env::args().collect();
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
    let speeds: Vec<f64> = a[4].split(',').map(|s| s.parse().unwrap()).collect();
    let bearings: Vec<usize> = if a[5] == "all" {
        (0..BEARINGS_DEG.len()).collect()
    } else {
        a[5].split(',').map(|s| s.parse().unwrap()).collect()
    };
    let trace = a.get(6).cloned();
    let jobs: Vec<(f64, usize)> = speeds
        .iter()
        .flat_map(|&s| bearings.iter().map(move |&b| (s, b)))
        .collect();
    let cells: Vec<_> = jobs
        .par_iter()
        .map(|&(s, b)| {
            (
                s,
                b,
                analysis::wind_envelope::fly_cell_phases(kind, mission, form, s, b, trace.as_deref()),
            )
        })
        .collect();
    for (s, b, (c, phases)) in cells {
        let ph: Vec<String> = phases.iter().map(|e| format!("{e:5.2}")).collect();
        println!(
            "{:>4} m/s {:>5}°  held {:5}  max {:7.2}  phases [{}]  land {:?} td {:?} {}",
            s,
            BEARINGS_DEG[b],
            c.held,
            c.max_error,
            ph.join(" "),
            c.landing_distance.map(|v| (v * 100.0).round() / 100.0),
            c.touchdown_speed.map(|v| (v * 100.0).round() / 100.0),
            c.failure.unwrap_or_default()
        );
    }
}
