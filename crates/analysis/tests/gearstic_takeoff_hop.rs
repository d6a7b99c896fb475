//! The take-off-to-landing evaluation takes the landing's touchdown, not a hop on the gear at
//! take-off: a synthetic trace lifts off, falls back onto the gear, climbs, flies to the
//! target and lands there at 0.3 m/s.

use analysis::controllers::Kind;
use analysis::takeoff_landing::{self, evaluate, MAX_MISS_DISTANCE, MAX_TOUCHDOWN_SPEED};
use closed_loop::{Ordering, Sample, Trace};
use flight_mission::{Command, Diagnostics, Phase};
use nalgebra::Vector3;
use tailsitter_physics::{dcm_earth_to_body, idx, InputVector, StateVector};

const H: f64 = 0.02;

#[test]
fn a_hop_at_take_off_is_not_the_touchdown() {
    let (plant, x0) = takeoff_landing::plant();
    let mission = takeoff_landing::mission();
    let g = plant.ground;
    let target = Vector3::new(mission.landing_target_n, mission.landing_target_e, 0.0);
    // The CG's pos_d where the gear just touches; the resting state is 8.8 mm lower.
    let touching = g.height - g.gear_length;
    let c = dcm_earth_to_body(&x0.fixed_rows::<4>(idx::Q1).into_owned());
    // (time, n, e, pos_d, down speed, phase) of each sample.
    let mut path: Vec<(f64, f64, f64, f64, Phase)> = Vec::new();
    let mut push = |n: f64, e: f64, d: f64, vd: f64, phase: Phase| path.push((n, e, d, vd, phase));
    for _ in 0..50 {
        push(0.0, 0.0, x0[idx::POS_D], 0.0, Phase::OnGround);
    }
    // The hop: 4 cm off the gear for 0.2 s, back on the gear 0.3 m north for 0.2 s.
    for _ in 0..10 {
        push(0.0, 0.0, touching - 0.04, 0.0, Phase::TakeOff);
    }
    for _ in 0..10 {
        push(0.3, 0.0, x0[idx::POS_D], 0.0, Phase::TakeOff);
    }
    // Up to 30 m, across to the target, down to the gear at 0.3 m/s.
    for k in 1..=100 {
        push(0.0, 0.0, touching - 0.3 * k as f64, -15.0, Phase::Vertical1);
    }
    for k in 0..=100 {
        push(target.x * k as f64 / 100.0, 0.0, touching - 30.0, 0.0, Phase::Level);
    }
    for k in (1..=100).rev() {
        let phase = if k > 20 { Phase::Descent } else { Phase::Flare };
        push(target.x, 0.0, touching - 0.3 * H * k as f64, 0.3, phase);
    }
    push(target.x, 0.0, touching + 0.003, 0.3, Phase::Flare);
    for _ in 0..300 {
        push(target.x, 0.0, x0[idx::POS_D], 0.0, Phase::Landed);
    }
    let samples = path
        .iter()
        .enumerate()
        .map(|(k, &(n, e, d, vd, phase))| {
            let mut x: StateVector = x0;
            x[idx::POS_N] = n;
            x[idx::POS_E] = e;
            x[idx::POS_D] = d;
            x.fixed_rows_mut::<3>(idx::U)
                .copy_from(&(c * Vector3::new(0.0, 0.0, vd)));
            let wind = Vector3::zeros();
            let measurement = flight_mission::measure(&plant, &x, &InputVector::zeros(), &wind);
            Sample {
                t: k as f64 * H,
                x,
                measurement,
                command: Command::default(),
                diagnostics: Diagnostics {
                    ref_pos_ned: measurement.pos_ned,
                    ref_airspeed: 0.0,
                    phase,
                    pos_error: 0.0,
                },
                wind,
                theta: core::f64::consts::FRAC_PI_2,
            }
        })
        .collect();
    let trace = Trace {
        samples,
        failure: None,
        notices: Vec::new(),
    };
    let f = evaluate(&plant, Kind::Tsd, Ordering::GaussSeidel, &mission, &trace);
    let landing = path.iter().position(|p| p.4 == Phase::Landed).unwrap() as f64 * H - H;
    assert!(
        (f.liftoff_time.unwrap() - 50.0 * H).abs() < 1e-9,
        "{:?}",
        f.liftoff_time
    );
    assert!(
        (f.touchdown_time.unwrap() - landing).abs() < 1e-9,
        "{:?}",
        f.touchdown_time
    );
    assert!(f.miss_touchdown < 1e-9 && f.miss_final < MAX_MISS_DISTANCE, "{f:?}");
    assert!((f.touchdown_speed - 0.3).abs() < 1e-9, "{}", f.touchdown_speed);
    assert!(
        f.touchdown_speed < MAX_TOUCHDOWN_SPEED && !f.bounced && f.passed,
        "{f:?}"
    );
}
