//! The whole avionics loop natively (no FMI): plant (RK4, 2 ms) → sensor model (200 Hz IMU,
//! 50 Hz magnetometer and pitot, 4 Hz GPS, 8 Hz Butterworth) → estimator (with the model
//! prediction) → controller → plant, Gauss-Seidel at 20 ms, over the 35 s default mission.
//! Real-time factor = 35 s / the time per mission (issue 14's target: ≥ 200×).

use criterion::{criterion_group, criterion_main, Criterion};
use flight_mission::{ControllerInput, FlightController, Measurement, MissionParams};
use lqr_control::{LqrController, LqrParams};
use nalgebra::Vector3;
use state_estimator::{Ekf, EstimatorParams, Measurements};
use std::hint::black_box;
use tailsitter_physics::{idx, Airframe, Plant};
use tsd_control::{TsdController, TsdParams};

const H: f64 = 0.02;

fn mission<C: FlightController>(c: &mut C) -> f64 {
    let plant = Plant::new(Airframe::default());
    let m = MissionParams::default();
    let trim = plant.trim_vertical_climb(m.v_vertical).unwrap();
    let (mut x, mut u) = (trim.state, trim.inputs);
    let wind = Vector3::zeros();
    let truth = |x: &tailsitter_physics::StateVector, u: &tailsitter_physics::InputVector| {
        let y = plant.outputs(x, u, &wind);
        sensor_model::Truth {
            pos_ned: Vector3::new(x[idx::POS_N], x[idx::POS_E], x[idx::POS_D]),
            vel_ned: y.vel_ned,
            rates: Vector3::new(x[idx::P], x[idx::Q], x[idx::R]),
            quat: x.fixed_rows::<4>(idx::Q1).into_owned(),
            airspeed: y.airspeed,
            alpha: y.alpha,
            beta: y.beta,
            specific_force: y.specific_force_body,
        }
    };
    let meas = |m: &sensor_model::Measurements| Measurements {
        gps_latitude: m.gps_latitude,
        gps_longitude: m.gps_longitude,
        gps_height: m.gps_height,
        gps_vel: m.gps_vel,
        gps_fix_count: m.gps_fix_count as i32,
        gps_valid: m.gps_valid,
        accel: m.accel(),
        gyro: m.gyro(),
        mag: m.mag(),
        pitot: m.pitot_airspeed(),
    };
    let mut sensors = sensor_model::SensorModel::new(sensor_model::Params::default()).unwrap();
    let mut ekf = Ekf::new(EstimatorParams::default()).unwrap();
    ekf.initialize(&meas(&sensors.start(&truth(&x, &u), 0.0).unwrap()), &u);
    let n = (m.end_time() / H).round() as usize;
    for k in 0..n {
        let t = k as f64 * H;
        let s = meas(&sensors.step(&truth(&x, &u), t, H).unwrap());
        let e = ekf.estimate();
        let input = ControllerInput {
            t,
            measurement: Measurement {
                pos_ned: e.pos_ned,
                vel_ned: e.vel_ned,
                vel_body: e.vel_body,
                rates: e.rates,
                quat: e.quat,
                airspeed: e.airspeed,
                alpha: e.alpha,
                beta: e.beta,
                thrust: e.thrust,
                surfaces: e.surfaces,
                specific_force_body: e.specific_force,
                induced_velocity: e.induced_velocity,
            },
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
