//! Construction of the controllers (issue 17) and the native default mission of each.
//!
//! `cargo bench -p closed-loop --bench construction`
//!
//! * `construction/profile`: the α- and thrust-limited flight-path profile of the default
//!   mission (`flight_mission::Profile`, both tuned controllers build it).
//! * `construction/lqr_trajectory`: the LQR's reference table (profile + force balance).
//! * `construction/lqr`, `construction/tsd`: `LqrController::new` (table + first gain),
//!   `TsdController::new`, default parameters, default mission.
//! * `mission/lqr_default`, `mission/tsd_default`: construction and the whole 35 s default
//!   mission flown natively (plant with its default thesis aerodynamics + controller,
//!   Gauss-Seidel, 20 ms), as `lqr-control`'s `mission_benchmark` flies it.

use closed_loop::{fly, Scenario};
use criterion::{black_box, criterion_group, criterion_main, Criterion};
use flight_mission::MissionParams;
use guidance::{PointMass, Profile, ProfileLimits};
use lqr_control::trajectory::{Trajectory, TrajectoryOptions};
use lqr_control::{LqrController, LqrParams};
use tailsitter_physics::{Airframe, Plant};
use tsd_control::{TsdController, TsdParams};

fn construction(c: &mut Criterion) {
    let af = Airframe::default();
    let m = MissionParams::default();
    let mut g = c.benchmark_group("construction");
    g.bench_function("profile", |b| {
        b.iter(|| {
            let pm = PointMass::from_level_trim(&af, m.v_level).unwrap();
            Profile::new(black_box(&m), &pm, &ProfileLimits::of(&m)).unwrap()
        })
    });
    g.bench_function("lqr_trajectory", |b| {
        b.iter(|| Trajectory::new(&af, black_box(&m), &TrajectoryOptions::default()).unwrap())
    });
    g.bench_function("lqr", |b| {
        b.iter(|| LqrController::new(af, black_box(m), LqrParams::default()).unwrap())
    });
    g.bench_function("tsd", |b| {
        b.iter(|| TsdController::new(af, black_box(m), TsdParams::default()).unwrap())
    });
    g.finish();
}

fn missions(c: &mut Criterion) {
    let m = MissionParams::default();
    let plant = Plant::new(Airframe::default());
    let x0 = plant.trim_vertical_climb(m.v_vertical).unwrap().state;
    let s = Scenario::mission(m);
    let mut g = c.benchmark_group("mission");
    g.bench_function("lqr_default", |b| {
        b.iter(|| {
            let mut ctl = LqrController::new(Airframe::default(), m, LqrParams::default()).unwrap();
            fly(&plant, x0, &mut ctl, &s)
        })
    });
    g.bench_function("tsd_default", |b| {
        b.iter(|| {
            let mut ctl = TsdController::new(Airframe::default(), m, TsdParams::default()).unwrap();
            fly(&plant, x0, &mut ctl, &s)
        })
    });
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20);
    targets = construction, missions
}
criterion_main!(benches);
