//! Print the hover-in-wind campaign of issue 16 (`analysis::envelope_hover`) as a table.
//! `cargo run --release -p analysis --example hover_scan [filter]`; with `--json` the
//! `envelope_hover` key of report.json instead.
use analysis::envelope_hover::{cases, fly_case, Case};
use rayon::prelude::*;

fn main() {
    let filter = std::env::args().nth(1).unwrap_or_default();
    if filter == "--json" {
        println!(
            "{}",
            serde_json::to_string_pretty(&analysis::envelope_hover::report()).expect("json")
        );
        return;
    }
    let cases: Vec<_> = cases()
        .into_iter()
        .filter(|c| format!("{c:?}").contains(&filter))
        .collect();
    let out: Vec<_> = cases
        .par_iter()
        .map(|&(k, o, c, case)| fly_case(k, o, c, case))
        .collect();
    for ((k, o, c, case), r) in cases.iter().zip(out) {
        let name = match case {
            Case::Step { speed, from_deg } => format!("step {speed} m/s from {from_deg:>3}"),
            Case::Gust { axis, phase } => format!("gust {} phase {phase}", ["N", "E", "D"][*axis]),
        };
        println!(
            "{} {:<12} cfg{c} {name:<24} held {:<5} max {:8.2} m fin {:7.2} m |α| {:5.1} |β| {:5.1} tilt {:5.1} calm {:?} {}",
            k.name(),
            format!("{o:?}"),
            r.held,
            r.max_pos_error,
            r.final_pos_error,
            r.max_alpha_deg,
            r.max_beta_deg,
            r.max_tilt_deg,
            r.calm_max_pos_error.map(|e| (e * 100.0).round() / 100.0),
            r.failure.unwrap_or_default()
        );
    }
}
