//! Criterion benchmarks of the LQR's gain computation and of the native LQR mission
//! (issue 17): DARE + gain on the 17×17 / 17×7 matrices of the default mission at
//! t = 15 s (level flight) and t = 2 s (vertical flight); one whole relinearisation
//! (model Jacobians + ZOH + DARE + gain + residual and stability checks), cold and
//! warm-started from the previous period's solution (`relinearisation_warm_…`); the default
//! mission flown natively (plant + LQR through `closed-loop`, Gauss-Seidel, 20 ms).
//!
//! `cargo bench -p missions --bench gain`

use closed_loop::{fly, Scenario};
use criterion::{criterion_group, criterion_main, Criterion};
use flight_mission::MissionParams;
use lqr_control::linalg::{dare_sda, lqr_gain};
use lqr_control::model::{linearise_analytic, linearise_central, EulerRep, NA};
use lqr_control::{LqrController, LqrParams};
use nalgebra::SMatrix;
use std::hint::black_box;
use tailsitter_physics::{Airframe, Plant};

fn gain(c: &mut Criterion) {
    let m = MissionParams::default();
    let ctl = LqrController::new(Airframe::default(), m, LqrParams::default()).unwrap();
    for t in [15.0, 2.0] {
        let p = ctl.trajectory().at(t);
        let rep = if p.euler_321.y > LqrParams::default().euler_switch_pitch {
            EulerRep::E231
        } else {
            EulerRep::E321
        };
        let x = p.state(rep);
        let sol = ctl.solve_gain(rep, &x, &p.u, t).unwrap();
        let w = ctl.schedule().at(&m, t);
        let q = SMatrix::<f64, NA, NA>::from_diagonal(&w.q);
        c.bench_function(&format!("dare_and_gain_t{t}"), |b| {
            b.iter(|| {
                let pp = dare_sda(black_box(&sol.phi), &sol.gamma, &q, &w.r).unwrap();
                lqr_gain(&sol.phi, &sol.gamma, &pp, &w.r).unwrap()
            })
        });
        c.bench_function(&format!("relinearisation_t{t}"), |b| {
            b.iter(|| ctl.solve_gain(rep, black_box(&x), &p.u, t).unwrap())
        });
        // Warm: started from the solution one relinearisation period (0.2 s) earlier on the
        // reference, as the controller does in a steady segment (one Newton step accepted).
        let p_prev = ctl.trajectory().at(t - 0.2);
        let warm = ctl
            .solve_gain(rep, &p_prev.state(rep), &p_prev.u, t - 0.2)
            .unwrap()
            .p
            .unwrap();
        assert!(ctl.solve_gain_warm(rep, &x, &p.u, t, Some(&warm)).unwrap().warm);
        c.bench_function(&format!("relinearisation_warm_t{t}"), |b| {
            b.iter(|| ctl.solve_gain_warm(rep, black_box(&x), &p.u, t, Some(&warm)).unwrap())
        });
        // The model's Jacobians alone: analytic (the default) against central differences.
        let af = Airframe::default();
        c.bench_function(&format!("jacobians_analytic_t{t}"), |b| {
            b.iter(|| linearise_analytic(&af, rep, black_box(&x), &p.u).unwrap())
        });
        c.bench_function(&format!("jacobians_central_t{t}"), |b| {
            b.iter(|| linearise_central(&af, rep, black_box(&x), &p.u))
        });
    }
}

fn mission(c: &mut Criterion) {
    let s = Scenario::mission(MissionParams::default());
    let plant = Plant::new(Airframe::default());
    let x0 = plant.trim_vertical_climb(s.mission.v_vertical).unwrap().state;
    let mut g = c.benchmark_group("native_mission");
    g.sample_size(10);
    g.bench_function("lqr_default_35s", |b| {
        b.iter(|| {
            let mut ctl = LqrController::new(Airframe::default(), s.mission, LqrParams::default()).unwrap();
            let trace = fly(&plant, black_box(x0), &mut ctl, &s);
            assert!(trace.failure.is_none());
            trace.samples.len()
        })
    });
    g.finish();
}

criterion_group!(benches, gain, mission);
criterion_main!(benches);
