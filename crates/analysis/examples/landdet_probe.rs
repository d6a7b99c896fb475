//! The land detector's inputs around the touchdown of one take-off-to-landing cell (a
//! development probe): `landdet_probe lqr|tsd SPEED BEARING_INDEX [avionics] [jacobi] [quiet]`.
//! Prints, from the flare on, per sample: t, phase, the true CG height above its rest height
//! at the target, the estimate's and the reference's, true and measured vertical speed, the measured thrust
//! and the gear's share of the weight (f_x/g − T/W) the detector sees, the tilt rate, the
//! plant's contact points (`quiet`: none of these); then the largest gear share seen in the
//! air in the descent and flare and the flight's touchdown figures.
use analysis::controllers::Kind;
use analysis::takeoff_landing;
use analysis::wind_envelope::{plant, seed, wind, WindForm};
use closed_loop::avionics::{Avionics, AvionicsSource};
use closed_loop::{fly_with, Ordering, Scenario, StateSource};
use flight_mission::{Command, Measurement, Phase};
use guidance::ground::CONTACT_GRAVITY;
use nalgebra::Vector3;
use std::cell::RefCell;
use std::rc::Rc;
use tailsitter_physics::{idx, InputVector, Plant, StateVector};

/// The perfect state or the avionics chain, keeping the controller's last measurement.
struct Probe {
    avionics: Option<AvionicsSource>,
    /// Start position (the tuned estimator's positions are relative to it).
    origin: Vector3<f64>,
    last: Rc<RefCell<Option<Measurement>>>,
}

impl StateSource for Probe {
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
        let m = match &mut self.avionics {
            Some(a) => {
                let mut m = a.measure(t, h, plant, x, u, wind, truth)?;
                m.pos_ned += self.origin;
                m
            }
            None => *truth,
        };
        *self.last.borrow_mut() = Some(m);
        Ok(match self.avionics {
            Some(_) => Measurement {
                pos_ned: m.pos_ned - self.origin,
                ..m
            },
            None => m,
        })
    }
    fn flown(&mut self, t: f64, h: f64, command: &Command) -> Result<(), String> {
        match &mut self.avionics {
            Some(a) => a.flown(t, h, command),
            None => Ok(()),
        }
    }
}

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let kind = if a[1] == "lqr" { Kind::Lqr } else { Kind::Tsd };
    let speed: f64 = a[2].parse().expect("SPEED");
    let b: usize = a[3].parse().expect("BEARING_INDEX");
    let has = |w: &str| a.iter().any(|s| s == w);
    let ordering = if has("jacobi") {
        Ordering::Jacobi
    } else {
        Ordering::GaussSeidel
    };
    let plant = plant();
    let mission = takeoff_landing::mission();
    let x0 = plant.resting_on_ground(0.0, 0.0, 0.0);
    let mut scenario = Scenario::mission(mission);
    scenario.stop_time = takeoff_landing::stop_time(&mission);
    scenario.ordering = ordering;
    scenario.wind = wind(WindForm::Step, speed, b, plant.ground.height);
    let origin = Vector3::new(x0[idx::POS_N], x0[idx::POS_E], x0[idx::POS_D]);
    let avionics = has("avionics").then(|| {
        let av = Avionics::new(seed(b), false, ordering, scenario.comm_step);
        AvionicsSource::start(&av, &plant, &x0, &InputVector::zeros()).expect("chain starts")
    });
    let last = Rc::new(RefCell::new(None));
    let mut src = Probe {
        avionics,
        origin,
        last: Rc::clone(&last),
    };
    let weight = plant.airframe.mass * plant.airframe.gravity;
    let target = origin + Vector3::new(mission.landing_target_n, mission.landing_target_e, 0.0);
    let mut c = kind.make_configured(&mission, 0).expect("controller");
    let mut stop = takeoff_landing::after_landing();
    let mut printing = false;
    // Largest gear share the detector saw in the descent and flare before the first contact.
    let mut air_share = f64::NEG_INFINITY;
    let mut touched = false;
    let quiet = has("quiet");
    // The controller's frame: NED, or relative to the start with the tuned estimator.
    let frame = if has("avionics") { origin.z } else { 0.0 };
    let trace = fly_with(&plant, x0, &mut c, &scenario, &mut src, |s| {
        let m = last.borrow().unwrap_or(s.measurement);
        printing |= s.diagnostics.phase == Phase::Flare;
        let contact = plant
            .outputs(&s.x, &closed_loop::plant_inputs(&s.command), &s.wind)
            .ground;
        let share = m.specific_force_body.x / CONTACT_GRAVITY - m.thrust / weight;
        touched |= contact.points > 0 && matches!(s.diagnostics.phase, Phase::Descent | Phase::Flare);
        if !touched && matches!(s.diagnostics.phase, Phase::Descent | Phase::Flare) {
            air_share = air_share.max(share);
        }
        if printing && !quiet {
            println!(
                "{:7.2} {:?} h T{:6.3} E{:6.3} R{:6.3} vz T{:6.3} E{:6.3} T/W{:5.2} gear{:6.2} qr{:6.3} pts {} cmd{:6.1}",
                s.t,
                s.diagnostics.phase,
                target.z - s.x[idx::POS_D],
                target.z - m.pos_ned.z,
                target.z - frame - s.diagnostics.ref_pos_ned.z,
                s.measurement.vel_ned.z,
                m.vel_ned.z,
                m.thrust / weight,
                share,
                m.rates.yz().norm(),
                contact.points,
                s.command.thrust,
            );
        }
        stop(s)
    });
    let f = takeoff_landing::evaluate(&plant, kind, ordering, &mission, &trace);
    println!(
        "air share max {air_share:.3} touchdown {:?} landed {:?} speed {:.3} miss {:.3}/{:.3} tilt {:.1}/{:.1} bounced {} rebound {:.4} passed {} failure {:?}",
        f.touchdown_time,
        f.landed_time,
        f.touchdown_speed,
        f.miss_touchdown,
        f.miss_final,
        f.tilt_touchdown_deg,
        f.tilt_final_deg,
        f.bounced,
        f.rebound_height,
        f.passed,
        f.failure
    );
}
