//! A fixed workload of the plant FMU's `fmi2DoStep` for instruction counting
//! (`valgrind --tool=callgrind`, repeatable on a shared machine where timings are
//! not) and for comparing trajectories between builds: the same C-ABI path as
//! `benches/do_step.rs` (FMU defaults: global aerodynamics + ground), trimmed level
//! flight at 25 m/s or vertical climb at 3 m/s with the trim's commands held.
//!
//! `cargo run --release -p fmu-plant --example do_step_workload -- level|vertical [steps=500] [get]`
//!
//! With `get`, every real output is read after each step (what a co-simulation
//! master does). Prints the CPU time per step and the final state to 17 digits.

use fmi2_export::ffi;
use fmi2_export::fmi_sys::fmi2::*;
use std::hint::black_box;
use tailsitter_plant::{vr, PlantModel};

#[path = "../benches/support/trimmed.rs"]
mod trimmed;

fn thread_cpu_time() -> f64 {
    let mut ts = libc::timespec { tv_sec: 0, tv_nsec: 0 };
    // SAFETY: `ts` is a valid, writable timespec; CLOCK_THREAD_CPUTIME_ID is always available on Linux.
    unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let (initial_condition, speed) = match args.get(1).map(String::as_str) {
        Some("vertical") => (0, 3.0),
        Some("level") | None => (1, 25.0),
        Some(other) => panic!("unknown case {other}: level or vertical"),
    };
    let steps: usize = args.get(2).and_then(|a| a.parse().ok()).unwrap_or(500);
    let get = args.get(3).is_some_and(|a| a == "get");
    let outputs = trimmed::real_outputs();
    let mut values = vec![0.0; outputs.len()];
    let host = fmi2_export::test_host::Host::new();
    // SAFETY: the host outlives the instance, freed below; every call on a live instance
    // in the state it needs.
    unsafe {
        let inst = trimmed::trimmed_instance(&host, "workload", initial_condition, speed);
        let h = 0.02;
        let c0 = thread_cpu_time();
        for k in 0..steps {
            let status = ffi::do_step::<PlantModel>(inst, black_box(k as f64 * h), h, 1);
            assert_eq!(status, fmi2Status_fmi2OK);
            if get {
                let status = ffi::get_real::<PlantModel>(inst, outputs.as_ptr(), outputs.len(), values.as_mut_ptr());
                assert_eq!(status, fmi2Status_fmi2OK);
                black_box(&values);
            }
        }
        let per_step = (thread_cpu_time() - c0) / steps as f64 * 1e6;
        let state = [
            vr::pos_n,
            vr::pos_e,
            vr::pos_d,
            vr::u,
            vr::v,
            vr::w,
            vr::quat_1,
            vr::quat_2,
            vr::quat_3,
            vr::quat_4,
            vr::p,
            vr::q,
            vr::r,
            vr::thrust,
        ];
        let mut x = [0.0; 14];
        assert_eq!(
            ffi::get_real::<PlantModel>(inst, state.as_ptr(), state.len(), x.as_mut_ptr()),
            fmi2Status_fmi2OK
        );
        println!(
            "{} steps{}: {per_step:.3} µs CPU per step",
            steps,
            if get { " + getReal of every output" } else { "" }
        );
        println!("final state: {}", x.map(|v| format!("{v:.17e}")).join(" "));
        ffi::free_instance::<PlantModel>(inst);
    }
}
