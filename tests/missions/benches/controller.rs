//! Timing of the LQR controller (was printed by tests that could not fail):
//! one relinearisation + ZOH discretisation + gain computation at t = 15 s (level
//! flight) with the DARE (doubling) and the thesis's backward iteration (N = 200),
//! and one sample of the default mission with and without the periodic
//! relinearisation (inputs replayed from a closed-loop run).

use closed_loop::{fly, Scenario};
use criterion::{black_box, criterion_group, criterion_main, Criterion};
use flight_mission::{MissionParams, SampledUnit};
use lqr_control::model::EulerRep;
use lqr_control::{LqrController, LqrParams};
use tailsitter_physics::{Airframe, Plant};

#[path = "../tests/support/replay.rs"]
mod replay;
use replay::recorded_inputs;

fn controller(params: LqrParams) -> LqrController {
    LqrController::new(Airframe::default(), MissionParams::default(), params).unwrap()
}

fn gains(c: &mut Criterion) {
    for (name, method) in [("gain_dare_doubling", 0), ("gain_backward_n200", 1)] {
        let ctl = controller(LqrParams {
            riccati_method: method,
            ..Default::default()
        });
        let p = ctl.trajectory().at(15.0);
        let x = p.state(EulerRep::E321);
        c.bench_function(name, |b| {
            b.iter(|| ctl.solve_gain(EulerRep::E321, black_box(&x), &p.u, 15.0).unwrap())
        });
    }
}

fn samples(c: &mut Criterion) {
    let m = MissionParams::default();
    let plant = Plant::new(Airframe::default());
    let x0 = plant.trim_vertical_climb(m.v_vertical).unwrap().state;
    let scenario = Scenario::mission(m);
    let trace = fly(&plant, x0, &mut controller(LqrParams::default()), &scenario);
    let inputs = recorded_inputs(&trace, &scenario);
    for (name, period) in [
        ("mission_samples_relinearised", 0.2),
        ("mission_samples_fixed_gain", 1e6),
    ] {
        let fresh = controller(LqrParams {
            relinearisation_period: period,
            ..Default::default()
        });
        c.bench_function(name, |b| {
            b.iter(|| {
                let mut ctl = fresh.clone();
                for input in &inputs {
                    black_box(ctl.sample(black_box(input)).unwrap());
                }
            })
        });
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10);
    targets = gains, samples
}
criterion_main!(benches);
