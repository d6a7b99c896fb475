//! CPU time of `Plant::advance` over one 20 ms communication step (the work of the plant
//! FMU's fmi2DoStep) in trimmed level flight at 25 m/s, vertical climb at 3 m/s and hover in
//! a 5 m/s wind, with the thesis's and the global aerodynamic model (`aero_model` 0 / 1): median
//! over `batches` batches of the thread's CPU time per call (robust on a loaded machine).
//!
//! `cargo run --release -p tailsitter-physics --example advance_benchmark -- [batches=15]`

use nalgebra::Vector3;
use std::hint::black_box;
use tailsitter_physics::{AeroModel, Airframe, Plant};

fn thread_cpu_time() -> f64 {
    let mut ts = libc::timespec { tv_sec: 0, tv_nsec: 0 };
    // SAFETY: `ts` is a valid, writable timespec; CLOCK_THREAD_CPUTIME_ID is always available on Linux.
    unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9
}

fn main() {
    let batches: usize = std::env::args().nth(1).and_then(|a| a.parse().ok()).unwrap_or(15);
    let thesis = Plant::new(Airframe::default());
    let mut global = thesis.clone();
    global.aero.model = AeroModel::Global;
    let calm = Vector3::zeros();
    let level = thesis.trim_level(25.0).unwrap();
    let vertical = thesis.trim_vertical_climb(3.0).unwrap();
    let hover = thesis.trim_vertical_climb(0.0).unwrap();
    // Hover in a 5 m/s horizontal wind: the global model's post-stall path.
    let gust = Vector3::new(5.0, 0.0, 0.0);
    for (name, plant, trim, wind) in [
        ("level 25 m/s, thesis aero", &thesis, level, calm),
        ("vertical 3 m/s, thesis aero", &thesis, vertical, calm),
        ("level 25 m/s, global aero", &global, level, calm),
        ("vertical 3 m/s, global aero", &global, vertical, calm),
        ("hover, 5 m/s wind, thesis aero", &thesis, hover, gust),
        ("hover, 5 m/s wind, global aero", &global, hover, gust),
    ] {
        let reps = 2000;
        let mut per_call = Vec::new();
        for _ in 0..batches {
            let c0 = thread_cpu_time();
            for _ in 0..reps {
                let mut x = trim.state;
                plant
                    .advance(black_box(&mut x), black_box(&trim.inputs), black_box(&wind), 0.02)
                    .unwrap();
                black_box(x);
            }
            per_call.push((thread_cpu_time() - c0) / reps as f64 * 1e6);
        }
        per_call.sort_by(|a, b| a.total_cmp(b));
        println!(
            "advance 20 ms, {name}: median {:.2} µs CPU (min {:.2}) over {batches} batches",
            per_call[batches / 2],
            per_call[0]
        );
    }
}
