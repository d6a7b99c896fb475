//! Benchmark of one gain computation and a DARE case for cross-checking against
//! `scipy.linalg.solve_discrete_are`: writes `<out>/dare_case_<t>.json` with Φ, Γ, Q, R
//! (row-major), the DARE solution P, the gain K and the timings in µs.
//!
//! `cargo run --release -p lqr-control --example dare_benchmark -- [t=15] [out=target/dare]`

use flight_mission::MissionParams;
use lqr_control::linalg::{dare_sda, lqr_gain};
use lqr_control::model::{EulerRep, NA};
use lqr_control::{LqrController, LqrParams};
use nalgebra::{DMatrix, SMatrix};
use std::hint::black_box;
use std::time::Instant;
use tailsitter_physics::Airframe;

fn rows<const R: usize, const C: usize>(m: &SMatrix<f64, R, C>) -> Vec<Vec<f64>> {
    (0..R).map(|i| (0..C).map(|j| m[(i, j)]).collect()).collect()
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let t: f64 = args.first().and_then(|a| a.parse().ok()).unwrap_or(15.0);
    let out = std::path::PathBuf::from(args.get(1).cloned().unwrap_or_else(|| "target/dare".into()));
    std::fs::create_dir_all(&out).expect("output folder");
    let m = MissionParams::default();
    let c = LqrController::new(Airframe::default(), m, LqrParams::default()).expect("controller");
    let p = c.trajectory().at(t);
    let rep = if p.euler_321.y > LqrParams::default().euler_switch_pitch {
        EulerRep::E231
    } else {
        EulerRep::E321
    };
    let x = p.state(rep);
    let sol = c.solve_gain(rep, &x, &p.u, t).expect("gain");
    let w = c.schedule().at(&m, t);
    let q = SMatrix::<f64, NA, NA>::from_diagonal(&w.q);

    let n = 2000;
    let t0 = Instant::now();
    for _ in 0..n {
        black_box(c.solve_gain(rep, black_box(&x), &p.u, t).expect("gain"));
    }
    let full_us = t0.elapsed().as_secs_f64() / n as f64 * 1e6;
    let t0 = Instant::now();
    for _ in 0..n {
        let pp = dare_sda(black_box(&sol.phi), &sol.gamma, &q, &w.r).expect("dare");
        black_box(lqr_gain(&sol.phi, &sol.gamma, &pp, &w.r).expect("gain"));
    }
    let dare_us = t0.elapsed().as_secs_f64() / n as f64 * 1e6;
    let pp = dare_sda(&sol.phi, &sol.gamma, &q, &w.r).expect("dare");
    let k = lqr_gain(&sol.phi, &sol.gamma, &pp, &w.r).expect("gain");
    let r = DMatrix::<f64>::from_diagonal(&nalgebra::DVector::from_column_slice(w.r.as_slice()));
    let r_rows: Vec<Vec<f64>> = (0..r.nrows())
        .map(|i| (0..r.ncols()).map(|j| r[(i, j)]).collect())
        .collect();
    let json = serde_json::json!({
        "t": t,
        "euler": format!("{rep:?}"),
        "phi": rows(&sol.phi),
        "gamma": rows(&sol.gamma),
        "q": rows(&q),
        "r": r_rows,
        "p": rows(&pp),
        "k": rows(&k),
        "us_relinearise_discretise_dare_checks": full_us,
        "us_dare_and_gain": dare_us,
    });
    let path = out.join(format!("dare_case_{t}.json"));
    std::fs::write(&path, serde_json::to_string_pretty(&json).expect("json")).expect("write");
    println!(
        "t = {t} s ({rep:?}): relinearisation + ZOH + DARE + checks {full_us:.1} µs, DARE + gain {dare_us:.1} µs -> {}",
        path.display()
    );
}
