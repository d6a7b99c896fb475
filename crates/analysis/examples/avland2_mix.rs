//! Which part of the estimate loses a default-mission cell in wind with the avionics chain
//! (a development probe): the controller is handed the estimate with the named fields
//! replaced by the truth.
//!
//! `avland2_mix lqr|tsd SPEED BEARING_INDEX [jacobi] [turb] FIELDS…`, FIELDS any of `none`,
//! `all`, `pos`, `vel`, `att`, `rates`, `air`, `act`, `sf`, comma-separated within a set,
//! each set flown once (e.g. `none all att air att,air`). Prints per set: the largest error
//! to the reference, the failure, and the estimate's largest errors (attitude, velocity,
//! wind, airspeed, α) up to the loss or the end.
use analysis::controllers::Kind;
use analysis::wind_envelope::{fly_on, plant, seed, trimmed_climb, wind, MissionKind, StateKind, WindForm};
use closed_loop::avionics::{substitute_truth, Avionics, AvionicsSource};
use closed_loop::{fly_with, Scenario, StateSource};
use flight_mission::{Command, Measurement};
use nalgebra::Vector3;
use tailsitter_physics::{dcm_earth_to_body, idx, InputVector, Plant, StateVector};

struct Mixed {
    inner: AvionicsSource,
    origin: Vector3<f64>,
    fields: Vec<String>,
    /// Largest |error| of the estimate: attitude (deg), velocity, wind (m/s), airspeed
    /// (m/s), α (deg).
    worst: [f64; 5],
    /// Time of the attitude's largest error (s).
    worst_att_t: f64,
}

impl StateSource for Mixed {
    fn measure(
        &mut self,
        t: f64,
        h: f64,
        plant: &Plant,
        x: &StateVector,
        u: &InputVector,
        w: &Vector3<f64>,
        truth: &Measurement,
    ) -> Result<Measurement, String> {
        let mut m = self.inner.measure(t, h, plant, x, u, w, truth)?;
        let e = self.inner.estimate();
        let att = state_estimator::attitude_error(&dcm_earth_to_body(&truth.quat), &dcm_earth_to_body(&e.quat))
            .norm()
            .to_degrees();
        if att > self.worst[0] {
            self.worst[0] = att;
            self.worst_att_t = t;
        }
        let errs = [
            (e.vel_ned - truth.vel_ned).norm(),
            (e.wind_ned - w).norm(),
            (e.airspeed - truth.airspeed).abs(),
            if truth.airspeed > 3.0 {
                (e.alpha - truth.alpha).abs().to_degrees()
            } else {
                0.0
            },
        ];
        for (k, v) in errs.iter().enumerate() {
            self.worst[k + 1] = self.worst[k + 1].max(*v);
        }
        for f in self.fields.iter().filter(|f| f.as_str() != "none") {
            assert!(substitute_truth(&mut m, truth, &self.origin, f), "unknown field {f}");
        }
        Ok(m)
    }
    fn flown(&mut self, t: f64, h: f64, command: &Command) -> Result<(), String> {
        self.inner.flown(t, h, command)
    }
}

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let kind = if a[1] == "lqr" { Kind::Lqr } else { Kind::Tsd };
    let speed: f64 = a[2].parse().unwrap();
    let b: usize = a[3].parse().unwrap();
    let jacobi = a.iter().any(|s| s == "jacobi");
    let form = if a.iter().any(|s| s == "turb") {
        WindForm::Turbulent
    } else {
        WindForm::Step
    };
    let plant = plant();
    let mission = MissionKind::Default.mission();
    let (x0, u0) = trimmed_climb(&plant, mission.v_vertical).unwrap();
    let mut scenario = Scenario::mission(mission);
    scenario.wind = wind(form, speed, b, plant.ground.height);
    if jacobi {
        scenario.ordering = closed_loop::Ordering::Jacobi;
    }
    // The envelope's own flight of the cell, for comparison.
    let mut c = kind.make_configured(&mission, 0).unwrap();
    let t = fly_on(&plant, x0, &u0, &mut c, &scenario, StateKind::Avionics, seed(b), |_| {
        false
    });
    let max = |t: &closed_loop::Trace| {
        t.samples
            .iter()
            .map(|s| (s.measurement.pos_ned - s.diagnostics.ref_pos_ned).norm())
            .fold(0.0, f64::max)
    };
    println!("envelope cell: max error {:.2} m, failure {:?}", max(&t), t.failure);
    let origin = Vector3::new(x0[idx::POS_N], x0[idx::POS_E], x0[idx::POS_D]);
    for set in a.iter().skip(4).filter(|s| !["jacobi", "turb"].contains(&s.as_str())) {
        let av = Avionics::new(seed(b), false, scenario.ordering, scenario.comm_step);
        let mut src = Mixed {
            inner: AvionicsSource::start(&av, &plant, &x0, &u0).unwrap(),
            origin,
            fields: set.split(',').map(String::from).collect(),
            worst: [0.0; 5],
            worst_att_t: 0.0,
        };
        let mut c = kind.make_configured(&mission, 0).unwrap();
        let trace = fly_with(&plant, x0, &mut c, &scenario, &mut src, |s| {
            (s.measurement.pos_ned - origin - s.diagnostics.ref_pos_ned).norm() > 50.0
        });
        let err = trace
            .samples
            .iter()
            .map(|s| (s.measurement.pos_ned - origin - s.diagnostics.ref_pos_ned).norm())
            .fold(0.0, f64::max);
        let w = src.worst;
        println!(
            "truth for {set:12}: max error {err:6.2} m (to t = {:.2}); estimate's worst: att {:.1} deg (t {:.2}), vel {:.2}, wind {:.2}, airspeed {:.2} m/s, alpha {:.1} deg",
            trace.samples.last().map_or(0.0, |s| s.t),
            w[0],
            src.worst_att_t,
            w[1],
            w[2],
            w[3],
            w[4]
        );
    }
}
