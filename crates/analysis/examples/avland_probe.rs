//! The take-off-to-landing cell in still air with the avionics chain, truth against the
//! estimate (a development probe): `avland_probe lqr|tsd|px4 BEARING_INDEX [jacobi] [EVERY_S]`.
//! Prints t, phase, true and estimated position/velocity (relative to the start), the
//! reference, true and estimated airspeed, the estimator's wind and its position σ.
use analysis::controllers::Kind;
use analysis::takeoff_landing;
use analysis::wind_envelope::{plant, seed};
use closed_loop::avionics::{Avionics, AvionicsSource};
use closed_loop::{fly_with, Ordering, Scenario, StateSource};
use flight_mission::{Command, Measurement};
use nalgebra::Vector3;
use tailsitter_physics::{idx, InputVector, Plant, StateVector};

struct Logged {
    inner: AvionicsSource,
    origin: Vector3<f64>,
    every: usize,
    k: usize,
    /// Fields taken from the truth instead of the estimate.
    mix: Vec<String>,
}

impl StateSource for Logged {
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
        let m = self.inner.measure(t, h, plant, x, u, wind, truth)?;
        if self.k % self.every == 0 {
            let e = self.inner.estimate();
            let p = truth.pos_ned - self.origin;
            println!(
                "{t:7.2} pos T({:7.2},{:6.2},{:7.2}) E({:7.2},{:6.2},{:7.2}) vel T({:6.2},{:6.2},{:6.2}) E({:6.2},{:6.2},{:6.2}) Va T{:5.2} E{:5.2} a T{:6.1} E{:6.1} wind({:5.2},{:5.2},{:5.2}) sp{:5.2} sv{:5.2} rej{}",
                p.x, p.y, p.z, e.pos_ned.x, e.pos_ned.y, e.pos_ned.z,
                truth.vel_ned.x, truth.vel_ned.y, truth.vel_ned.z, e.vel_ned.x, e.vel_ned.y, e.vel_ned.z,
                truth.airspeed, e.airspeed, truth.alpha.to_degrees(), e.alpha.to_degrees(),
                e.wind_ned.x, e.wind_ned.y, e.wind_ned.z, e.std_pos, e.std_vel, e.rejected_measurements
            );
        }
        self.k += 1;
        let mut m = m;
        for f in &self.mix {
            assert!(
                closed_loop::avionics::substitute_truth(&mut m, truth, &self.origin, f),
                "unknown field {f}"
            );
        }
        Ok(m)
    }
    fn flown(&mut self, t: f64, h: f64, command: &Command) -> Result<(), String> {
        self.inner.flown(t, h, command)
    }
}

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let kind = match a[1].as_str() {
        "lqr" => Kind::Lqr,
        "tsd" => Kind::Tsd,
        _ => Kind::Px4,
    };
    let b: usize = a[2].parse().unwrap();
    let ordering = if a.iter().any(|s| s == "jacobi") {
        Ordering::Jacobi
    } else {
        Ordering::GaussSeidel
    };
    let every_s: f64 = a.get(3).and_then(|s| s.parse().ok()).unwrap_or(1.0);
    let plant = plant();
    let mission = takeoff_landing::mission();
    let x0 = plant.resting_on_ground(0.0, 0.0, 0.0);
    let mut scenario = Scenario::mission(mission);
    scenario.stop_time = takeoff_landing::stop_time(&mission);
    scenario.ordering = ordering;
    let av = Avionics::new(seed(b), false, ordering, scenario.comm_step);
    let origin = Vector3::new(x0[idx::POS_N], x0[idx::POS_E], x0[idx::POS_D]);
    let inner = AvionicsSource::start(&av, &plant, &x0, &InputVector::zeros()).unwrap();
    let every = ((every_s / scenario.comm_step).round() as usize).max(1);
    let mix: Vec<String> = std::env::var("MIX")
        .map(|v| v.split(',').filter(|s| !s.is_empty()).map(String::from).collect())
        .unwrap_or_default();
    let mut src = Logged {
        inner,
        origin,
        every,
        k: 0,
        mix,
    };
    let mut c = kind.make_configured(&mission, 0).unwrap();
    let mut landed: Option<f64> = None;
    let trace = fly_with(&plant, x0, &mut c, &scenario, &mut src, |s| {
        if std::env::var("REF").is_ok() {
            println!(
                "      ref({:7.2},{:6.2},{:7.2}) {:?}",
                s.diagnostics.ref_pos_ned.x,
                s.diagnostics.ref_pos_ned.y,
                s.diagnostics.ref_pos_ned.z,
                s.diagnostics.phase
            );
        }
        if landed.is_none() && s.diagnostics.phase == flight_mission::Phase::Landed {
            landed = Some(s.t);
        }
        landed.is_some_and(|t| s.t >= t + 5.0)
            || (s.measurement.pos_ned - origin - s.diagnostics.ref_pos_ned).norm() > 50.0
    });
    let f = takeoff_landing::evaluate(&plant, kind, ordering, &mission, &trace);
    println!(
        "end t = {:.2} failure {:?}",
        trace.samples.last().unwrap().t,
        trace.failure
    );
    println!("landing {f:?}");
}
