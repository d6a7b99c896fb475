//! The tuned TSD's take-off-to-landing cells with the landing's figures (a development
//! probe, flown as the wind envelope flies them, stopping 5 s after the landing):
//! `tsdland_probe step|turb SPEEDS BEARING_INDICES|all [jacobi] [avionics] [lqr]` (`lqr`: the
//! tuned LQR instead of the TSD). Per cell: held,
//! largest error to the own reference and its phase, miss at rest, touchdown speed, tilt at
//! touchdown and at the end, the largest tilt and the mean collective flap over the last
//! 10 s before the touchdown, and whether every landing criterion is met.
use analysis::controllers::Kind;
use analysis::takeoff_landing::{self, tilt};
use analysis::wind_envelope::{fly_on, plant, seed, wind, StateKind, WindForm, BEARINGS_DEG, HELD_MAX_ERROR};
use closed_loop::{Ordering, Sample, Scenario};
use flight_mission::Phase;
use rayon::prelude::*;
use tailsitter_physics::InputVector;

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let form = if a[1] == "step" {
        WindForm::Step
    } else {
        WindForm::Turbulent
    };
    let speeds: Vec<f64> = a[2].split(',').map(|s| s.parse().unwrap()).collect();
    let bearings: Vec<usize> = if a[3] == "all" {
        (0..BEARINGS_DEG.len()).collect()
    } else {
        a[3].split(',').map(|s| s.parse().unwrap()).collect()
    };
    let ordering = if a.iter().any(|s| s == "jacobi") {
        Ordering::Jacobi
    } else {
        Ordering::GaussSeidel
    };
    let kind = if a.iter().any(|s| s == "lqr") {
        Kind::Lqr
    } else {
        Kind::Tsd
    };
    let state = if a.iter().any(|s| s == "avionics") {
        StateKind::Avionics
    } else {
        StateKind::Perfect
    };
    let jobs: Vec<(f64, usize)> = speeds
        .iter()
        .flat_map(|&s| bearings.iter().map(move |&b| (s, b)))
        .collect();
    let rows: Vec<(bool, String)> = jobs
        .par_iter()
        .map(|&(speed, b)| {
            let plant = plant();
            let mission = takeoff_landing::mission();
            let x0 = plant.resting_on_ground(0.0, 0.0, 0.0);
            let mut scenario = Scenario::mission(mission);
            scenario.stop_time = takeoff_landing::stop_time(&mission);
            scenario.wind = wind(form, speed, b, plant.ground.height);
            scenario.ordering = ordering;
            let mut c = kind.make_configured(&mission, 0).unwrap();
            let mut landed: Option<f64> = None;
            let stop = |s: &Sample| {
                if landed.is_none() && s.diagnostics.phase == Phase::Landed {
                    landed = Some(s.t);
                }
                landed.is_some_and(|t| s.t >= t + takeoff_landing::AFTER_LANDING - 1e-9)
            };
            let trace = fly_on(&plant, x0, &InputVector::zeros(), &mut c, &scenario, state, seed(b), stop);
            let f = takeoff_landing::evaluate(&plant, kind, ordering, &mission, &trace);
            let (mut max_error, mut worst) = (0.0f64, (0.0, Phase::OnGround));
            for s in &trace.samples {
                if s.pos_error() > max_error {
                    max_error = s.pos_error();
                    worst = (s.t, s.diagnostics.phase);
                }
            }
            if let Some(i) = std::env::args().position(|s| s == "trace") {
                let from: f64 = std::env::args().nth(i + 1).and_then(|x| x.parse().ok()).unwrap_or(140.0);
                for s in trace.samples.iter().filter(|s| s.t >= from).step_by(std::env::var("TRACE_STEP").ok().and_then(|v| v.parse().ok()).unwrap_or(25)) {
                    let c = &s.command;
                    let q = &s.measurement.quat;
                    let r = nalgebra::UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(q[3], q[0], q[1], q[2]));
                    let (nose, belly, span) = (r * nalgebra::Vector3::x(), r * nalgebra::Vector3::z(), r * nalgebra::Vector3::y());
                    let lb = nose.xy().dot(&belly.xy()) / belly.xy().norm();
                    let ls = nose.xy().dot(&span.xy()) / span.xy().norm();
                    let e = s.measurement.pos_ned - s.diagnostics.ref_pos_ned;
                    let bh = belly.xy() / belly.xy().norm();
                    print!(
                        "lean b {:6.1} s {:6.1} belly@ {:5.0} e_b {:5.2} ",
                        lb.asin().to_degrees(),
                        ls.asin().to_degrees(),
                        bh.y.atan2(bh.x).to_degrees(),
                        e.xy().dot(&bh)
                    );
                    println!(
                        "{:7.2} {:8} tilt {:6.1} err {:5.2} vz {:5.2} T {:6.1} δe {:6.1} δfc {:6.1} δr {:6.1} δv {:6.1}",
                        s.t,
                        takeoff_landing::phase_name(s.diagnostics.phase.code()),
                        tilt(&s.x).to_degrees(),
                        s.pos_error(),
                        s.measurement.vel_ned.z,
                        c.thrust,
                        c.elevator.to_degrees(),
                        c.flap_collective.to_degrees(),
                        c.rudder.to_degrees(),
                        c.vertical_flap.to_degrees()
                    );
                }
            }
            let td = f.touchdown_time.unwrap_or(f64::INFINITY);
            // How far the aircraft moved on the gear before the take-off (the controller's
            // target is measured from the last sample on the gear, the criteria's from the first).
            let pad = trace
                .samples
                .iter()
                .take_while(|s| s.t < mission.takeoff_spinup_time)
                .last()
                .map_or(nalgebra::Vector3::repeat(f64::NAN), |s| s.measurement.pos_ned);
            let slid = (pad - trace.samples[0].measurement.pos_ned).xy().norm();
            // Miss from the controller's own target (the pad measured at the take-off).
            let own_target = pad.xy() + nalgebra::Vector2::new(mission.landing_target_n, mission.landing_target_e);
            let own_miss = trace
                .samples
                .last()
                .map_or(f64::NAN, |s| (s.measurement.pos_ned.xy() - own_target).norm());
            // The landing's first contact (not a take-off bounce) and the tilt there.
            let contact = takeoff_landing::first_landing_contact(&plant, &trace);
            let td = contact.map_or(td, |s| s.t);
            let tilt_contact = contact.map_or(f64::NAN, |s| tilt(&s.x).to_degrees());
            // Largest lean towards the belly and along the span in the last 3 s (deg).
            let (mut lean_b, mut lean_s) = (0.0f64, 0.0f64);
            for s in trace.samples.iter().filter(|s| s.t < td && s.t >= td - 3.0) {
                let q = &s.measurement.quat;
                let r = nalgebra::UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(q[3], q[0], q[1], q[2]));
                let (nose, belly, span) = (r * nalgebra::Vector3::x(), r * nalgebra::Vector3::z(), r * nalgebra::Vector3::y());
                lean_b = lean_b.max((nose.xy().dot(&belly.xy()) / belly.xy().norm()).asin().to_degrees().abs());
                lean_s = lean_s.max((nose.xy().dot(&span.xy()) / span.xy().norm()).asin().to_degrees().abs());
            }
            let late = trace
                .samples
                .iter()
                .filter(|s| s.t < td && s.t >= td - 3.0)
                .map(|s| tilt(&s.x).to_degrees())
                .fold(0.0, f64::max);
            let last: Vec<&Sample> = trace
                .samples
                .iter()
                .filter(|s| s.t < td && s.t >= td - 10.0)
                .collect();
            let lean = last.iter().map(|s| tilt(&s.x).to_degrees()).fold(0.0, f64::max);
            let flap = last.iter().map(|s| s.command.flap_collective.to_degrees()).sum::<f64>() / last.len().max(1) as f64;
            let completed = trace.completed() && f.landed_time.is_some() && f.miss_final < HELD_MAX_ERROR;
            let held = completed && max_error < HELD_MAX_ERROR;
            (
                f.passed,
                format!(
                    "{speed:>4} {:>5}  held {:5} max {:6.2} ({:6.1} s {:8})  miss {:6.2}  td {:5.2}  tilt td {:5.1} end {:5.1} last10 {:5.1}  δfc {:6.1}  L {} lift {:.2} td@ {:.2} landed@ {:.2} slid {:.2} gt {:.1} own {:.2} last3 {:.1} contact {:.1} lb {:.0} ls {:.0} {}",
                    BEARINGS_DEG[b],
                    held,
                    max_error,
                    worst.0,
                    takeoff_landing::phase_name(worst.1.code()),
                    f.miss_final,
                    f.touchdown_speed,
                    f.tilt_touchdown_deg,
                    f.tilt_final_deg,
                    lean,
                    flap,
                    f.passed,
                    f.liftoff_time.unwrap_or(f64::NAN),
                    td,
                    f.landed_time.unwrap_or(f64::NAN),
                    slid,
                    f.ground_tilt_deg,
                    own_miss,
                    late,
                    tilt_contact,
                    lean_b,
                    lean_s,
                    trace.failure.as_deref().unwrap_or("")
                ),
            )
        })
        .collect();
    for (_, r) in &rows {
        println!("{r}");
    }
    println!("landing passed {}/{}", rows.iter().filter(|r| r.0).count(), rows.len());
}
