//! `Ekf::step` alone (no FMI layer): updates (GPS at every 12th step, magnetometer, pitot,
//! zero sideslip) and the 18-state prediction, level flight at 25 m/s.

use criterion::{criterion_group, criterion_main, Criterion};
use nalgebra::Vector3;
use state_estimator::{Ekf, EstimatorParams, Measurements};
use std::hint::black_box;
use tailsitter_physics::{dcm_earth_to_body, idx, Airframe, Plant};

fn bench(c: &mut Criterion) {
    let plant = Plant::new(Airframe::default());
    let trim = plant.trim_level(25.0).unwrap();
    let x = trim.state;
    let params = EstimatorParams::default();
    let mut ekf = Ekf::new(params.clone()).unwrap();
    let y = plant.outputs(&x, &trim.inputs, &Vector3::zeros());
    let cbe = dcm_earth_to_body(&x.fixed_rows::<4>(idx::Q1).into_owned());
    let (la, lo, h) = ekf.frame().to_geodetic(&Vector3::zeros());
    let mut m = Measurements {
        gps_latitude: la,
        gps_longitude: lo,
        gps_height: h,
        gps_vel: y.vel_ned,
        gps_fix_count: 0,
        gps_valid: true,
        accel: y.specific_force_body,
        gyro: Vector3::zeros(),
        mag: cbe * params.earth.mag_ned(),
        pitot: x[idx::U],
    };
    ekf.initialize(&m);
    let mut k = 0i32;
    c.bench_function("ekf_step_20ms", |b| {
        b.iter(|| {
            if k % 12 == 0 {
                m.gps_fix_count += 1;
            }
            k += 1;
            black_box(ekf.step(black_box(&m), &trim.inputs, 0.02))
        })
    });
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(50);
    targets = bench
}
criterion_main!(benches);
