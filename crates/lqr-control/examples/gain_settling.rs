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

/// The gains of the backward iteration at mission time `t` over `n` steps, with the scaling
/// of each gain and the (input, state) pairs worth plotting.
struct Settling {
    rep: EulerRep,
    /// K after each step.
    history: Vec<SMatrix<f64, NU, NA>>,
    /// Typical deviations 1/√weight of the states and inputs (R included).
    dev_x: Vec<f64>,
    dev_u: Vec<f64>,
    /// (input, state) of the gains ≥ 1 % of the mean scaled magnitude.
    series: Vec<(usize, usize)>,
}

impl Settling {
    fn compute(t: f64, n: usize) -> Self {
        let m = MissionParams::default();
        let c = LqrController::new(Airframe::default(), m, LqrParams::default()).expect("controller");
        let (p, rep) = c.reference_and_euler_set(t);
        let sol = c.solve_gain(rep, &p.state(rep), &p.u, t).expect("gain");
        let w = c.schedule().at(&m, t);
        let q = SMatrix::<f64, NA, NA>::from_diagonal(&w.q);
        // Scaling: K_ij · dev_j / dev_i with dev = 1/√weight (R included in the input weight).
        let dev_x: Vec<f64> = w.q.iter().map(|x| 1.0 / x.sqrt()).collect();
        let dev_u: Vec<f64> = w.r.iter().map(|x| 1.0 / x.sqrt()).collect();
        let mut history: Vec<SMatrix<f64, NU, NA>> = Vec::with_capacity(n);
        let mut record = |_: usize, k: &SMatrix<f64, NU, NA>| history.push(*k);
        riccati_backward(&sol.phi, &sol.gamma, &q, &w.r, n, Some(&mut record)).expect("iteration");
        let mut s = Self {
            rep,
            history,
            dev_x,
            dev_u,
            series: Vec::new(),
        };
        let last = *s.history.last().expect("N >= 1");
        let mut mean = 0.0;
        for i in 0..INPUTS.len() {
            for j in 0..NA {
                mean += s.scaled(&last, i, j).abs();
            }
        }
        mean /= (INPUTS.len() * NA) as f64;
        for i in 0..INPUTS.len() {
            for j in 0..NA {
                if s.scaled(&last, i, j).abs() >= 0.01 * mean {
                    s.series.push((i, j));
                }
            }
        }
        s
    }

    /// Gain K_ij scaled by (state deviation / input deviation).
    fn scaled(&self, k: &SMatrix<f64, NU, NA>, i: usize, j: usize) -> f64 {
        k[(i, j)] * self.dev_x[j] / self.dev_u[i]
    }

    fn csv(&self) -> String {
        let mut csv = String::from("step");
        for (i, j) in &self.series {
            let _ = write!(csv, ",{}<-{}", INPUTS[*i], STATES[*j]);
        }
        csv.push('\n');
        for (s, k) in self.history.iter().enumerate() {
            let _ = write!(csv, "{}", s + 1);
            for (i, j) in &self.series {
                let _ = write!(csv, ",{:.6e}", self.scaled(k, *i, *j));
            }
            csv.push('\n');
        }
        csv
    }

    /// SVG: one panel per actuator, each gain normalised by its final value.
    fn svg(&self, t: f64) -> String {
        let (wpx, hpx) = (900.0, 220.0);
        let rep = self.rep;
        let mut svg = format!(
            "<svg xmlns='http://www.w3.org/2000/svg' width='{wpx}' height='{}' font-family='sans-serif' font-size='11'>\n",
            hpx * INPUTS.len() as f64 + 30.0
        );
        let _ = writeln!(
            svg,
            "<text x='10' y='15'>Gain settling, backward Riccati iteration at t = {t} s ({rep:?}): K(step)/K(N), gains ≥ 1 % of mean</text>"
        );
        for (panel, name) in INPUTS.iter().enumerate() {
            self.svg_panel(&mut svg, panel, name, (wpx, hpx));
        }
        let _ = writeln!(
            svg,
            "<text x='{}' y='{}'>step (N = {})</text>",
            wpx / 2.0,
            hpx * INPUTS.len() as f64 + 25.0,
            self.history.len()
        );
        svg.push_str("</svg>\n");
        svg
    }

    fn svg_panel(&self, svg: &mut String, panel: usize, name: &str, (wpx, hpx): (f64, f64)) {
        let n = self.history.len();
        let last = self.history.last().expect("N >= 1");
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
        for (idx, (i, j)) in self.series.iter().enumerate().filter(|(_, (i, _))| *i == panel) {
            let fin = self.scaled(last, *i, *j);
            let mut pts = String::new();
            for (s, k) in self.history.iter().enumerate() {
                let x = 50.0 + (wpx - 70.0) * (s as f64 + 1.0) / n as f64;
                let _ = write!(pts, "{x:.1},{:.1} ", ymap(self.scaled(k, *i, *j) / fin));
            }
            let hue = (idx * 47) % 360;
            let _ = writeln!(svg, "<polyline fill='none' stroke='hsl({hue},70%,40%)' points='{pts}'><title>{name} from {}</title></polyline>", STATES[*j]);
        }
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let t: f64 = args.first().and_then(|a| a.parse().ok()).unwrap_or(15.0);
    let n: usize = args.get(1).and_then(|a| a.parse().ok()).unwrap_or(1000);
    let out = std::path::PathBuf::from(args.get(2).cloned().unwrap_or_else(|| "target/gain_settling".into()));
    std::fs::create_dir_all(&out).expect("output folder");
    let s = Settling::compute(t, n);
    let stem = format!("gain_settling_{t}");
    std::fs::write(out.join(format!("{stem}.csv")), s.csv()).expect("write csv");
    std::fs::write(out.join(format!("{stem}.svg")), s.svg(t)).expect("write svg");
    println!(
        "{} gains recorded over {n} steps -> {}",
        s.series.len(),
        out.join(stem).display()
    );
}
