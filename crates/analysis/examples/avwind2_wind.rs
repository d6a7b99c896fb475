//! The estimator's wind against the true wind on wind-envelope cells with the avionics
//! (a development probe): `avwind2_wind lqr|tsd default|tl|handover step|turb SPEEDS
//! BEARING_INDICES [off] [jacobi] [TRACE.csv]`. `off`: the aerodynamic specific-force update
//! switched off (`aero_force_update`). Prints per cell the largest distance to the reference,
//! the completion and the horizontal wind-estimate error |ŵ − w|, RMS and largest, in the
//! first vertical phase (from 1 s after the wind stepped in) and over the flight.
use analysis::takeoff_landing;
use analysis::wind_envelope::{plant, seed, trimmed_climb, wind, MissionKind, WindForm};
use closed_loop::avionics::{Avionics, AvionicsSource};
use closed_loop::{fly_with, Ordering, Scenario, StateSource};
use flight_mission::{Command, Measurement, Phase};
use nalgebra::Vector3;
use tailsitter_physics::{idx, InputVector, Plant, StateVector};

#[path = "support/cell_args.rs"]
mod cell_args;

/// The avionics chain, recording the estimated and the true wind at every step.
struct Recording {
    inner: AvionicsSource,
    /// (t, phase is the first vertical, estimated wind, true wind).
    rows: Vec<(f64, Vector3<f64>, Vector3<f64>)>,
}

impl StateSource for Recording {
    fn measure(
        &mut self,
        t: f64,
        h: f64,
        plant: &Plant,
        x: &StateVector,
        u: &InputVector,
        wind: &Vector3<f64>,
        truth: &Measurement,
    ) -> Result<Measurement, String> {
        self.rows.push((t, self.inner.estimate().wind_ned, *wind));
        self.inner.measure(t, h, plant, x, u, wind, truth)
    }

    fn flown(&mut self, t: f64, h: f64, command: &Command) -> Result<(), String> {
        self.inner.flown(t, h, command)
    }
}

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let cell_args::CellArgs {
        kind,
        mission: mission_kind,
        form,
        speeds,
        bearings,
    } = cell_args::parse(&a);
    let off = a.iter().any(|s| s == "off");
    let jacobi = a.iter().any(|s| s == "jacobi");
    let trace_path = a.iter().find(|s| s.ends_with(".csv")).cloned();
    let plant = plant();
    for &speed in &speeds {
        for &b in &bearings {
            let mission = mission_kind.mission();
            let mut scenario = Scenario::mission(mission);
            scenario.wind = wind(form, speed, b, plant.ground.height);
            scenario.ordering = if jacobi {
                Ordering::Jacobi
            } else {
                Ordering::GaussSeidel
            };
            let mut c = kind.make_configured(&mission, 0).unwrap();
            let (x0, u0) = match mission_kind {
                MissionKind::TakeoffLanding => {
                    scenario.stop_time = takeoff_landing::stop_time(&mission);
                    (plant.resting_on_ground(0.0, 0.0, 0.0), InputVector::zeros())
                }
                _ => trimmed_climb(&plant, mission.v_vertical).unwrap(),
            };
            let mut av = Avionics::new(seed(b), false, scenario.ordering, scenario.comm_step);
            av.estimator.tuning.aero_force_update = !off;
            for arg in &a {
                if let Some(v) = arg.strip_prefix("rel=") {
                    av.estimator.tuning.aero_force_model_error = v.parse().unwrap();
                }
                if let Some(v) = arg.strip_prefix("floor=") {
                    av.estimator.tuning.sigma_aero_force = v.parse().unwrap();
                }
            }
            let origin = Vector3::new(x0[idx::POS_N], x0[idx::POS_E], x0[idx::POS_D]);
            let mut src = Recording {
                inner: AvionicsSource::start(&av, &plant, &x0, &u0).unwrap(),
                rows: Vec::new(),
            };
            let mut stop = takeoff_landing::after_landing();
            let trace = fly_with(&plant, x0, &mut c, &scenario, &mut src, |s| {
                (s.measurement.pos_ned - origin - s.diagnostics.ref_pos_ned).norm() > 50.0
                    || (mission_kind == MissionKind::TakeoffLanding && stop(s))
            });
            let max_err = trace
                .samples
                .iter()
                .map(|s| (s.x.fixed_rows::<3>(idx::POS_N) - s.diagnostics.ref_pos_ned).norm())
                .fold(0.0, f64::max);
            let first_vertical: Vec<bool> = trace
                .samples
                .iter()
                .map(|s| s.diagnostics.phase == Phase::Vertical1)
                .collect();
            let stats = |sel: &dyn Fn(usize, f64) -> bool| {
                let (mut n, mut sq, mut mx) = (0usize, 0.0, 0.0f64);
                for (k, (t, w_est, w)) in src.rows.iter().enumerate() {
                    if sel(k, *t) && (*w).norm() > 0.0 || sel(k, *t) && speed == 0.0 {
                        let e = ((w_est - w).xy()).norm();
                        n += 1;
                        sq += e * e;
                        mx = mx.max(e);
                    }
                }
                ((sq / n.max(1) as f64).sqrt(), mx, n)
            };
            let t_on = if form == WindForm::Step { 3.0 } else { 1.0 };
            let hover = stats(&|k, t| t >= t_on && first_vertical.get(k).copied().unwrap_or(false));
            let all = stats(&|_, t| t >= t_on);
            println!(
                "{} {:?} {:?} {:>4} m/s b{} {}: max {:7.2} m completed {} | wind err hover RMS {:.2} max {:.2} (n {}) | flight RMS {:.2} max {:.2} {}",
                a[1],
                mission_kind,
                form,
                speed,
                b,
                if off { "off" } else { "on " },
                max_err,
                trace.completed(),
                hover.0,
                hover.1,
                hover.2,
                all.0,
                all.1,
                trace.failure.clone().unwrap_or_default()
            );
            if let Some(p) = &trace_path {
                let mut out = String::from("t,w_est_n,w_est_e,w_est_d,w_n,w_e,w_d\n");
                for (t, we, w) in &src.rows {
                    out.push_str(&format!(
                        "{t:.2},{:.3},{:.3},{:.3},{:.3},{:.3},{:.3}\n",
                        we.x, we.y, we.z, w.x, w.y, w.z
                    ));
                }
                std::fs::write(p, out).unwrap();
            }
        }
    }
}
