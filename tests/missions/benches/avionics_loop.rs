//! The whole avionics loop natively (no FMI): plant (RK4, 2 ms) → sensor model (1 kHz accel., 200 Hz gyro,
//! 50 Hz magnetometer and pitot, 4 Hz GPS, 8 Hz Butterworth) → estimator (with the model
//! prediction) → controller → plant, Gauss-Seidel at 20 ms, over the 35 s default mission.
//! Real-time factor = 35 s / the time per mission (issue 14's target: ≥ 200×).

use criterion::{criterion_group, criterion_main, Criterion};
use flight_mission::{ControllerInput, FlightController, MissionParams};
use lqr_control::{LqrController, LqrParams};
use nalgebra::Vector3;
use state_estimator::{Ekf, EstimatorParams};
use std::hint::black_box;

use closed_loop::avionics::{measurement_of as measurement, to_estimator, truth};
use tailsitter_physics::{idx, Airframe, Plant};
use tsd_control::{TsdController, TsdParams};

const H: f64 = 0.02;

fn mission<C: FlightController>(c: &mut C) -> f64 {
    let plant = Plant::new(Airframe::default());
    let m = MissionParams::default();
    let trim = plant.trim_vertical_climb(m.v_vertical).unwrap();
    let (mut x, mut u) = (trim.state, trim.inputs);
    let wind = Vector3::zeros();
    let mut sensors = sensor_model::SensorModel::new(sensor_model::Params::default()).unwrap();
    let mut ekf = Ekf::new(EstimatorParams::default()).unwrap();
    ekf.initialize(&to_estimator(
        &sensors.start(&truth(&plant, &x, &u, &wind), 0.0).unwrap(),
    ));
    let n = (m.end_time() / H).round() as usize;
    for k in 0..n {
        let t = k as f64 * H;
        let s = to_estimator(&sensors.step(&truth(&plant, &x, &u, &wind), t, H).unwrap());
        let input = ControllerInput {
            t,
            measurement: measurement(&ekf.estimate()),
            ref_offset_ned: Vector3::zeros(),
        };
        u = closed_loop::plant_inputs(&c.sample(&input).unwrap().command);
        ekf.step(&s, &u, H);
        plant.advance(&mut x, &u, &wind, H).unwrap();
    }
    x[idx::POS_D]
}

fn bench(c: &mut Criterion) {
    let m = MissionParams::default();
    let mut g = c.benchmark_group("avionics_loop_35s_mission");
    g.sample_size(10);
    g.bench_function("lqr", |b| {
        b.iter(|| {
            let mut ctl = LqrController::new(Airframe::default(), m, LqrParams::default()).unwrap();
            black_box(mission(&mut ctl))
        })
    });
    g.bench_function("tsd", |b| {
        b.iter(|| {
            let mut ctl = TsdController::new(Airframe::default(), m, TsdParams::default()).unwrap();
            black_box(mission(&mut ctl))
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
