//! `Plant::advance` over one 20 ms communication step (the default integrator: three
//! Dormand–Prince steps of 20/3 ms).

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use nalgebra::Vector3;
use tailsitter_physics::{Airframe, Plant};

fn bench(c: &mut Criterion) {
    let plant = Plant::new(Airframe::default());
    let wind = Vector3::zeros();
    for (name, trim) in [
        ("advance_20ms_level_25", plant.trim_level(25.0).unwrap()),
        ("advance_20ms_vertical_3", plant.trim_vertical_climb(3.0).unwrap()),
    ] {
        c.bench_function(name, |b| {
            b.iter(|| {
                let mut x = trim.state;
                plant
                    .advance(
                        black_box(&mut x),
                        black_box(&trim.inputs),
                        black_box(&wind),
                        black_box(0.02),
                    )
                    .unwrap();
                x
            })
        });
    }
    // Issue 13: hovering in a 5 m/s horizontal wind (free wing stalled, immersed part
    // attached): the global model's post-stall path, against the thesis model.
    let hover = plant.trim_vertical_climb(0.0).unwrap();
    let gust = Vector3::new(5.0, 0.0, 0.0);
    for model in [
        tailsitter_physics::AeroModel::Thesis,
        tailsitter_physics::AeroModel::Global,
    ] {
        let mut p = plant.clone();
        p.aero.model = model;
        c.bench_function(
            &format!("advance_20ms_hover_wind_5_aero_model_{}", model.index()),
            |b| {
                b.iter(|| {
                    let mut x = hover.state;
                    p.advance(
                        black_box(&mut x),
                        black_box(&hover.inputs),
                        black_box(&gust),
                        black_box(0.02),
                    )
                    .unwrap();
                    x
                })
            },
        );
    }
    let trim = plant.trim_level(25.0).unwrap();
    c.bench_function("derivatives", |b| {
        b.iter(|| plant.derivatives(black_box(&trim.state), black_box(&trim.inputs), black_box(&wind)))
    });
}

fn parts(c: &mut Criterion) {
    let a = Airframe::default();
    let v = Vector3::new(24.79, 0.0, 3.22);
    let w = Vector3::new(0.0, 0.0, 0.0);
    let s = tailsitter_physics::Surfaces {
        elevator: -0.105,
        ..Default::default()
    };
    c.bench_function("induced_velocity_level", |b| {
        b.iter(|| a.induced_velocity(black_box(25.0), black_box(24.79), black_box(9.28)))
    });
    c.bench_function("forces_moments_level", |b| {
        b.iter(|| a.forces_moments(black_box(&v), black_box(&w), black_box(9.28), black_box(&s)))
    });
    c.bench_function("coefficients", |b| b.iter(|| a.coefficients(black_box(0.13))));
}

criterion_group!(benches, bench, parts);
criterion_main!(benches);
