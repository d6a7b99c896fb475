//! The native LQR mission (plant + controller through `closed-loop`, Gauss-Seidel, 20 ms):
//! writes the trajectory (t, N, E, D, full precision) as CSV for before/after comparisons
//! and prints the CPU time of one whole mission (median over `runs`).
//!
//! `cargo run --release -p lqr-control --example mission_benchmark -- [default|violent] [out.csv|-] [runs=5] [plant integration step (s)]`
//!
//! `violent`: the fast mission (T1 = 3 s, T2 = 4 s, α up to ≈ 44°) with a 1 − cos gust of
//! 6 m/s (north, up) over 2 s at t = 12 s and 5 m position steps at 20 s and 23 s (the mission ends at 27 s).

use closed_loop::{fly, Scenario, Trace};
use flight_mission::MissionParams;
use lqr_control::{LqrController, LqrParams};
use std::io::Write;
use tailsitter_physics::{Airframe, Plant};

fn thread_cpu_time() -> f64 {
    let mut ts = libc::timespec { tv_sec: 0, tv_nsec: 0 };
    // SAFETY: `ts` is a valid, writable timespec; CLOCK_THREAD_CPUTIME_ID is always available on Linux.
    unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9
}

fn scenario(name: &str) -> Scenario {
    match name {
        "default" => Scenario::mission(MissionParams::default()),
        "violent" => Scenario::violent_manoeuvre(),
        other => panic!("unknown scenario {other} (default | violent)"),
    }
}

/// The flown trace, the number of gain solves and the CPU time (s) of the controller's
/// construction (reference trajectory + first gain).
fn fly_once(s: &Scenario, integration_step: Option<f64>) -> (Trace, u64, f64) {
    let mut plant = Plant::new(Airframe::default());
    if let Some(step) = integration_step {
        plant.integration_step = step;
    }
    let x0 = plant.trim_vertical_climb(s.mission.v_vertical).expect("trim").state;
    let c0 = thread_cpu_time();
    let mut c = LqrController::new(Airframe::default(), s.mission, LqrParams::default()).expect("controller");
    let construction = thread_cpu_time() - c0;
    let trace = fly(&plant, x0, &mut c, s);
    (trace, c.stats().solves, construction)
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let name = args.first().map(String::as_str).unwrap_or("default");
    let out = args.get(1).cloned();
    let runs: usize = args.get(2).and_then(|a| a.parse().ok()).unwrap_or(5);
    let integration_step: Option<f64> = args.get(3).and_then(|a| a.parse().ok());
    let s = scenario(name);
    let mut times = Vec::new();
    let mut constructions = Vec::new();
    let mut last = None;
    for _ in 0..runs.max(1) {
        let c0 = thread_cpu_time();
        let r = fly_once(&s, integration_step);
        times.push((thread_cpu_time() - c0) * 1e3);
        constructions.push(r.2 * 1e3);
        last = Some(r);
    }
    let (trace, solves, _) = last.expect("one run");
    times.sort_by(|a, b| a.total_cmp(b));
    constructions.sort_by(|a, b| a.total_cmp(b));
    if let Some(path) = out.filter(|p| p != "-") {
        let mut f = std::io::BufWriter::new(std::fs::File::create(&path).expect("csv"));
        writeln!(f, "t,N,E,D").expect("write");
        for smp in &trace.samples {
            writeln!(f, "{:e},{:e},{:e},{:e}", smp.t, smp.x[0], smp.x[1], smp.x[2]).expect("write");
        }
    }
    println!(
        "{name} mission: {} samples, {solves} gain solves, failure {:?}, max position error {:.4} m; CPU time per mission: median {:.2} ms (min {:.2}) over {} runs, of which the controller's construction (reference trajectory + first gain) median {:.2} ms",
        trace.samples.len(),
        trace.failure,
        trace.max_pos_error(),
        times[times.len() / 2],
        times[0],
        times.len(),
        constructions[constructions.len() / 2]
    );
}
