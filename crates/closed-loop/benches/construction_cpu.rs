//! CPU time (of the measuring thread, so other processes on a loaded machine do not count)
//! of the figures of the `construction` bench: best and median over `RUNS` runs each.
//!
//! `cargo bench -p closed-loop --bench construction_cpu [-- RUNS]`

use closed_loop::{fly, Scenario};
use flight_mission::MissionParams;
use guidance::{PointMass, Profile, ProfileLimits};
use lqr_control::trajectory::{Trajectory, TrajectoryOptions};
use lqr_control::{LqrController, LqrParams};
use std::hint::black_box;
use tailsitter_physics::{Airframe, Plant};
use tsd_control::{TsdController, TsdParams};

fn thread_cpu_time() -> f64 {
    let mut ts = libc::timespec { tv_sec: 0, tv_nsec: 0 };
    // SAFETY: `ts` is a valid, writable timespec; CLOCK_THREAD_CPUTIME_ID is always available on Linux.
    unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9
}

fn measure(name: &str, runs: usize, mut f: impl FnMut()) {
    let mut t: Vec<f64> = (0..runs)
        .map(|_| {
            let t0 = thread_cpu_time();
            f();
            thread_cpu_time() - t0
        })
        .collect();
    t.sort_by(f64::total_cmp);
    println!(
        "{name:28} best {:8.3} ms  median {:8.3} ms  ({runs} runs)",
        t[0] * 1e3,
        t[runs / 2] * 1e3
    );
}

fn main() {
    // `cargo bench` passes `--bench`; a number is the run count.
    let runs: usize = std::env::args().skip(1).find_map(|a| a.parse().ok()).unwrap_or(20);
    let af = Airframe::default();
    let m = MissionParams::default();
    measure("construction/profile", runs, || {
        let pm = PointMass::from_level_trim(&af, m.v_level).unwrap();
        black_box(Profile::new(black_box(&m), &pm, &ProfileLimits::of(&m)).unwrap());
    });
    measure("construction/lqr_trajectory", runs, || {
        black_box(Trajectory::new(&af, black_box(&m), &TrajectoryOptions::default()).unwrap());
    });
    measure("construction/lqr", runs, || {
        black_box(LqrController::new(af, black_box(m), LqrParams::default()).unwrap());
    });
    measure("construction/tsd", runs, || {
        black_box(TsdController::new(af, black_box(m), TsdParams::default()).unwrap());
    });
    let plant = Plant::new(Airframe::default());
    let x0 = plant.trim_vertical_climb(m.v_vertical).unwrap().state;
    let s = Scenario::mission(m);
    let mission_runs = runs.div_ceil(4).max(3);
    measure("mission/lqr_default", mission_runs, || {
        let mut ctl = LqrController::new(af, m, LqrParams::default()).unwrap();
        black_box(fly(&plant, x0, &mut ctl, &s));
    });
    measure("mission/tsd_default", mission_runs, || {
        let mut ctl = TsdController::new(af, m, TsdParams::default()).unwrap();
        black_box(fly(&plant, x0, &mut ctl, &s));
    });
}
