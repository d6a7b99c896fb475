//! Selected cells of the wind envelope with per-phase errors (a development probe):
//! `wind_cells lqr|tsd default|tl|handover step|turb SPEEDS BEARING_INDICES [AXIS…] [TRACE.csv]`,
//! SPEEDS and BEARING_INDICES comma-separated (or `all`), AXIS any of `perfect`, `avionics`,
//! `avionics_app_d`, `gauss-seidel`, `jacobi`, `tuned`, `thesis` (default perfect,
//! Gauss-Seidel, tuned). With a trace file (one cell) the time history (t, phase, error,
//! position, reference, θ, heading, wind) is written.
use analysis::wind_envelope::{fly_job, Axes, Configuration, Job, OrderingKind, StateKind, BEARINGS_DEG};
use rayon::prelude::*;

#[path = "support/cell_args.rs"]
mod cell_args;

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let cell_args::CellArgs {
        kind,
        mission,
        form,
        speeds,
        bearings,
    } = cell_args::parse(&a);
    let mut axes = Axes::default();
    let mut trace = None;
    for arg in &a[6..] {
        match arg.as_str() {
            "perfect" => axes.state = StateKind::Perfect,
            "avionics" => axes.state = StateKind::Avionics,
            "avionics_app_d" => axes.state = StateKind::AvionicsAppD,
            "gauss-seidel" => axes.ordering = OrderingKind::GaussSeidel,
            "jacobi" => axes.ordering = OrderingKind::Jacobi,
            "tuned" => axes.configuration = Configuration::Tuned,
            "thesis" => axes.configuration = Configuration::Thesis,
            path => trace = Some(path.to_string()),
        }
    }
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
                fly_job(&Job::new(kind, mission, form, s, b).on(axes), trace.as_deref()),
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
