//! Benchmark of one gain computation on the aircraft's own model, and the DARE case for
//! the comparison with `scipy.linalg.solve_discrete_are` (`scripts/bench_dare.py`):
//! writes `<out>/dare_case_<t>.json` with Φ, Γ, Q, R (row-major), the DARE solution P,
//! the gain K and the timings (µs), and prints the timings.
//!
//! `cargo run --release -p lqr-control --example dare_benchmark -- [t=15] [out=target/dare] [batches=15]`
//!
//! Each figure is the median over `batches` batches (each ≥ 20 ms of work) of the batch's
//! time per call, both wall-clock and CPU time of this thread (the CPU time is the robust
//! figure on a loaded machine: it excludes the time the thread waits for a core).

use flight_mission::MissionParams;
use lqr_control::linalg::{dare_sda, lqr_gain};
use lqr_control::model::NA;
use lqr_control::{LqrController, LqrParams};
use nalgebra::{DMatrix, SMatrix};
use std::hint::black_box;
use std::time::Instant;
use tailsitter_physics::Airframe;

fn rows<const R: usize, const C: usize>(m: &SMatrix<f64, R, C>) -> Vec<Vec<f64>> {
    (0..R).map(|i| (0..C).map(|j| m[(i, j)]).collect()).collect()
}

/// CPU time of the calling thread (s).
fn thread_cpu_time() -> f64 {
    let mut ts = libc::timespec { tv_sec: 0, tv_nsec: 0 };
    // SAFETY: `ts` is a valid, writable timespec; CLOCK_THREAD_CPUTIME_ID is always available on Linux.
    unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// (wall, cpu) medians in µs per call of `f` over `batches` batches.
fn time_us(batches: usize, mut f: impl FnMut()) -> (f64, f64) {
    // Calibrate the batch size to ≈ 20 ms of CPU time.
    let c0 = thread_cpu_time();
    let mut calib = 0usize;
    while thread_cpu_time() - c0 < 0.005 {
        f();
        calib += 1;
    }
    let reps = (calib * 4).max(1);
    let mut wall = Vec::with_capacity(batches);
    let mut cpu = Vec::with_capacity(batches);
    for _ in 0..batches {
        let c0 = thread_cpu_time();
        let t0 = Instant::now();
        for _ in 0..reps {
            f();
        }
        wall.push(t0.elapsed().as_secs_f64() / reps as f64 * 1e6);
        cpu.push((thread_cpu_time() - c0) / reps as f64 * 1e6);
    }
    (median(&mut wall), median(&mut cpu))
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let t: f64 = args.first().and_then(|a| a.parse().ok()).unwrap_or(15.0);
    let out = std::path::PathBuf::from(args.get(1).cloned().unwrap_or_else(|| "target/dare".into()));
    let batches: usize = args.get(2).and_then(|a| a.parse().ok()).unwrap_or(15);
    std::fs::create_dir_all(&out).expect("output folder");
    let m = MissionParams::default();
    let c = LqrController::new(Airframe::default(), m, LqrParams::default()).expect("controller");
    let (p, rep) = c.reference_and_euler_set(t);
    let x = p.state(rep);
    let sol = c.solve_gain(rep, &x, &p.u, t).expect("gain");
    let w = c.schedule().at(&m, t);
    let q = SMatrix::<f64, NA, NA>::from_diagonal(&w.q);

    let (full_wall, full_cpu) = time_us(batches, || {
        black_box(c.solve_gain(rep, black_box(&x), &p.u, t).expect("gain"));
    });
    let (dare_wall, dare_cpu) = time_us(batches, || {
        let pp = dare_sda(black_box(&sol.phi), &sol.gamma, &q, &w.r).expect("dare");
        black_box(lqr_gain(&sol.phi, &sol.gamma, &pp, &w.r).expect("gain"));
    });
    // Warm-started relinearisation from the solution one period (0.2 s) earlier on the
    // reference (the controller's steady-segment case).
    let prev = c.trajectory().at(t - 0.2);
    let warm = c.solve_gain(rep, &prev.state(rep), &prev.u, t - 0.2).expect("gain").p;
    let warm_accepted = c.solve_gain_warm(rep, &x, &p.u, t, warm.as_ref()).expect("gain").warm;
    let (warm_wall, warm_cpu) = time_us(batches, || {
        black_box(
            c.solve_gain_warm(rep, black_box(&x), &p.u, t, warm.as_ref())
                .expect("gain"),
        );
    });
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
        "batches": batches,
        "us_relinearise_discretise_dare_checks": full_cpu,
        "us_dare_and_gain": dare_cpu,
        "us_wall_relinearise_discretise_dare_checks": full_wall,
        "us_wall_dare_and_gain": dare_wall,
        "us_relinearise_warm": warm_cpu,
        "us_wall_relinearise_warm": warm_wall,
    });
    let path = out.join(format!("dare_case_{t}.json"));
    std::fs::write(&path, serde_json::to_string_pretty(&json).expect("json")).expect("write");
    println!(
        "t = {t} s ({rep:?}), medians of {batches} batches, CPU (wall) µs per call: relinearisation + ZOH + DARE + checks {full_cpu:.1} ({full_wall:.1}), warm-started {warm_cpu:.1} ({warm_wall:.1}, warm start {}), DARE + gain {dare_cpu:.1} ({dare_wall:.1}) -> {}",
        if warm_accepted { "accepted" } else { "refused: cold" },
        path.display()
    );
}
