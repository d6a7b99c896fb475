//! Gain settling over the backward Riccati iteration (3.1.3–3.1.5), the analogue of
//! the thesis's Fig. 3.19: the model is linearised on the reference at a mission time,
//! the iteration is run for N steps from S(N) = Q₁ and every gain from a state to
//! T_c, δe, δa, δr is recorded, scaled by (state max deviation / input max deviation)
//! (dimensionless, as the thesis's "scaling matrices"); gains below 1 % of the mean
//! scaled magnitude are omitted. Writes `<out>/gain_settling_<t>.csv` and `.svg`.
//!
//! `cargo run --release -p lqr-control --example gain_settling -- [t=15] [N=1000] [out=target/gain_settling]`

use flight_mission::MissionParams;
use lqr_control::linalg::riccati_backward;
use lqr_control::model::{EulerRep, NA, NU};
use lqr_control::{LqrController, LqrParams};
use nalgebra::SMatrix;
use std::fmt::Write as _;
use tailsitter_physics::Airframe;

const STATES: [&str; NA] = [
    "Vint", "V", "alpha", "beta", "p", "q", "r", "phi", "theta", "psi", "N", "E", "h", "T", "Nint", "Eint", "hint",
];
const INPUTS: [&str; 4] = ["Tc", "de", "da", "dr"];

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let t: f64 = args.first().and_then(|a| a.parse().ok()).unwrap_or(15.0);
    let n: usize = args.get(1).and_then(|a| a.parse().ok()).unwrap_or(1000);
    let out = std::path::PathBuf::from(args.get(2).cloned().unwrap_or_else(|| "target/gain_settling".into()));
    std::fs::create_dir_all(&out).expect("output folder");

    let m = MissionParams::default();
    let c = LqrController::new(Airframe::default(), m, LqrParams::default()).expect("controller");
    let p = c.trajectory().at(t);
    let rep = if p.euler_321.y > LqrParams::default().euler_switch_pitch {
        EulerRep::E231
    } else {
        EulerRep::E321
    };
    let sol = c.solve_gain(rep, &p.state(rep), &p.u, t).expect("gain");
    let w = c.schedule().at(&m, t);
    let q = SMatrix::<f64, NA, NA>::from_diagonal(&w.q);
    // Scaling: K_ij · dev_j / dev_i with dev = 1/√weight (R included in the input weight).
    let dev_x: Vec<f64> = w.q.iter().map(|x| 1.0 / x.sqrt()).collect();
    let dev_u: Vec<f64> = w.r.iter().map(|x| 1.0 / x.sqrt()).collect();
    let mut history: Vec<SMatrix<f64, NU, NA>> = Vec::with_capacity(n);
    let mut record = |_: usize, k: &SMatrix<f64, NU, NA>| history.push(*k);
    riccati_backward(&sol.phi, &sol.gamma, &q, &w.r, n, Some(&mut record)).expect("iteration");

    let scaled = |k: &SMatrix<f64, NU, NA>, i: usize, j: usize| k[(i, j)] * dev_x[j] / dev_u[i];
    let last = history.last().expect("N >= 1");
    let mut mean = 0.0;
    for i in 0..INPUTS.len() {
        for j in 0..NA {
            mean += scaled(last, i, j).abs();
        }
    }
    mean /= (INPUTS.len() * NA) as f64;
    let mut series = Vec::new();
    for i in 0..INPUTS.len() {
        for j in 0..NA {
            if scaled(last, i, j).abs() >= 0.01 * mean {
                series.push((i, j));
            }
        }
    }

    let mut csv = String::from("step");
    for (i, j) in &series {
        let _ = write!(csv, ",{}<-{}", INPUTS[*i], STATES[*j]);
    }
    csv.push('\n');
    for (s, k) in history.iter().enumerate() {
        let _ = write!(csv, "{}", s + 1);
        for (i, j) in &series {
            let _ = write!(csv, ",{:.6e}", scaled(k, *i, *j));
        }
        csv.push('\n');
    }
    let stem = format!("gain_settling_{t}");
    std::fs::write(out.join(format!("{stem}.csv")), csv).expect("write csv");

    // SVG: one panel per actuator, each gain normalised by its final value.
    let (wpx, hpx) = (900.0, 220.0);
    let mut svg = format!(
        "<svg xmlns='http://www.w3.org/2000/svg' width='{wpx}' height='{}' font-family='sans-serif' font-size='11'>\n",
        hpx * INPUTS.len() as f64 + 30.0
    );
    let _ = writeln!(
        svg,
        "<text x='10' y='15'>Gain settling, backward Riccati iteration at t = {t} s ({rep:?}): K(step)/K(N), gains ≥ 1 % of mean</text>"
    );
    for (panel, name) in INPUTS.iter().enumerate() {
        let y0 = 30.0 + panel as f64 * hpx;
        let _ = writeln!(
            svg,
            "<rect x='50' y='{y0}' width='{}' height='{}' fill='none' stroke='black'/>",
            wpx - 70.0,
            hpx - 40.0
        );
        let _ = writeln!(svg, "<text x='55' y='{}'>{name}</text>", y0 + 14.0);
        let ymap = |v: f64| y0 + (hpx - 40.0) * (1.0 - (v.clamp(-0.5, 1.5) + 0.5) / 2.0);
        for (label, v) in [("1", 1.0), ("0", 0.0)] {
            let _ = writeln!(svg, "<text x='30' y='{}'>{label}</text>", ymap(v) + 4.0);
        }
        for (idx, (i, j)) in series.iter().enumerate().filter(|(_, (i, _))| *i == panel) {
            let fin = scaled(last, *i, *j);
            let mut pts = String::new();
            for (s, k) in history.iter().enumerate() {
                let x = 50.0 + (wpx - 70.0) * (s as f64 + 1.0) / n as f64;
                let _ = write!(pts, "{x:.1},{:.1} ", ymap(scaled(k, *i, *j) / fin));
            }
            let hue = (idx * 47) % 360;
            let _ = writeln!(svg, "<polyline fill='none' stroke='hsl({hue},70%,40%)' points='{pts}'><title>{name} from {}</title></polyline>", STATES[*j]);
        }
    }
    let _ = writeln!(
        svg,
        "<text x='{}' y='{}'>step (N = {n})</text>",
        wpx / 2.0,
        hpx * INPUTS.len() as f64 + 25.0
    );
    svg.push_str("</svg>\n");
    std::fs::write(out.join(format!("{stem}.svg")), svg).expect("write svg");
    println!(
        "{} gains recorded over {n} steps -> {}",
        series.len(),
        out.join(stem).display()
    );
}
