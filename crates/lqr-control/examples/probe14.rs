use flight_mission::MissionParams;
use lqr_control::linalg::*;
use lqr_control::model::{linearise_analytic, EulerRep, NU};
use lqr_control::{LqrController, LqrParams};
use nalgebra::{SMatrix, SVector};
use std::hint::black_box;
use tailsitter_physics::Airframe;
fn time(name: &str, mut f: impl FnMut()) {
    for _ in 0..200 {
        f();
    }
    let mut best = f64::INFINITY;
    for _ in 0..7 {
        let t0 = std::time::Instant::now();
        for _ in 0..2000 {
            f();
        }
        best = best.min(t0.elapsed().as_secs_f64() / 2000.0 * 1e6);
    }
    println!("{name}: {best:.2} us");
}
fn main() {
    let m = MissionParams::default();
    let c = LqrController::new(Airframe::default(), m, LqrParams::default()).unwrap();
    let t = 15.0;
    let p = c.trajectory().at(t);
    let rep = EulerRep::E321;
    let x = p.state(rep);
    let sol = c.solve_gain(rep, &x, &p.u, t).unwrap();
    let w = c.schedule().at(&m, t);
    let phi: SMatrix<f64, 14, 14> = sol.phi.fixed_view::<14, 14>(0, 0).into_owned();
    let gamma: SMatrix<f64, 14, 7> = sol.gamma.fixed_view::<14, 7>(0, 0).into_owned();
    let q = SMatrix::<f64, 14, 14>::from_diagonal(&w.q.fixed_rows::<14>(0).into_owned());
    let r: SVector<f64, NU> = w.r;
    let af = Airframe::default();
    time("jacobians", || {
        black_box(linearise_analytic(&af, rep, black_box(&x), &p.u));
    });
    let big = SMatrix::<f64, 21, 21>::from_fn(|i, j| {
        if i < 14 && j < 14 {
            phi[(i, j)] - if i == j { 1.0 } else { 0.0 }
        } else {
            0.0
        }
    });
    time("expm21", || {
        black_box(expm(black_box(&big)));
    });
    time("dare14", || {
        black_box(dare_sda(black_box(&phi), &gamma, &q, &r).unwrap());
    });
    let pp = dare_sda(&phi, &gamma, &q, &r).unwrap();
    time("gain14", || {
        black_box(lqr_gain(black_box(&phi), &gamma, &pp, &r).unwrap());
    });
    let k = lqr_gain(&phi, &gamma, &pp, &r).unwrap();
    time("residual14", || {
        black_box(dare_residual(black_box(&phi), &gamma, &q, &pp, &k));
    });
    let cl = phi - gamma * k;
    time("specbound14", || {
        black_box(spectral_radius_bound(black_box(&cl)));
    });
    time("schur14", || {
        black_box(black_box(cl).schur());
    });
    time("solve_gain", || {
        black_box(c.solve_gain(rep, black_box(&x), &p.u, t).unwrap());
    });
}
