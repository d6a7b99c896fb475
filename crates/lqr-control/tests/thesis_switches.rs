//! The configuration-following switches (docs/THESIS.md D-3.3, D-3.5, D-3.15): −1 follows
//! `configuration` (thesis = the printed form), 0 / 1 override it in either configuration.

use flight_mission::MissionParams;
use lqr_control::trajectory::{Trajectory, TrajectoryMode, TrajectoryOptions};
use lqr_control::{LqrController, LqrParams};
use tailsitter_physics::Airframe;

fn switches(p: &LqrParams) -> [i32; 4] {
    [p.discretisation, p.integrator_clamp, p.integrator_freeze, p.thrust_lead]
}

#[test]
fn switches_follow_the_configuration_unless_set() {
    let tuned = LqrParams::default().effective().unwrap();
    assert_eq!(switches(&tuned), [0, 1, 1, 1]);
    let thesis = LqrParams {
        configuration: 1,
        ..LqrParams::default()
    };
    assert_eq!(switches(&thesis.effective().unwrap()), [1, 0, 0, 0]);
    let overridden = LqrParams {
        discretisation: 0,
        integrator_freeze: 1,
        ..thesis.clone()
    };
    assert_eq!(switches(&overridden.effective().unwrap()), [0, 0, 1, 0]);
    let tuned_printed = LqrParams {
        discretisation: 1,
        integrator_clamp: 0,
        thrust_lead: 0,
        ..LqrParams::default()
    };
    assert_eq!(switches(&tuned_printed.effective().unwrap()), [1, 0, 1, 0]);
    // Resolved values are kept when resolved again.
    let twice = thesis.effective().unwrap().effective().unwrap();
    assert_eq!(switches(&twice), [1, 0, 0, 0]);
    for bad in [-2, 2] {
        let p = LqrParams {
            thrust_lead: bad,
            ..LqrParams::default()
        };
        assert!(p.effective().is_err());
    }
}

#[test]
fn first_order_discretisation_is_the_printed_form() {
    // Γ_I's integrator row is exactly 0 in the printed (3.2.14); the exact hold gives O(T_s²).
    let m = MissionParams::default();
    let gains = |discretisation| {
        let p = LqrParams {
            configuration: 1,
            discretisation,
            ..LqrParams::default()
        };
        let c = LqrController::new(Airframe::default(), m, p).unwrap();
        let p0 = c.trajectory().at(0.0);
        let (_, rep) = c.gain();
        c.solve_gain(rep, &p0.state(rep), &p0.u, 0.0).unwrap()
    };
    let first = gains(1);
    let zoh = gains(0);
    assert!(first.gamma.row(0).iter().all(|v| *v == 0.0));
    assert!(zoh.gamma.row(0).iter().any(|v| *v != 0.0));
    // Φ_I = [1 T_s H_I; 0 Φ] (corrected 3.2.13, leak 0).
    assert_eq!(first.phi[(0, 0)], 1.0);
    assert_eq!(first.phi[(0, 1)], m.sample_time);
    assert!((first.phi - zoh.phi).amax() < 0.05);
}

#[test]
fn thrust_lead_off_commands_the_printed_thrust() {
    let af = Airframe::default();
    let m = MissionParams::default();
    let opt = |thrust_lead| TrajectoryOptions {
        mode: TrajectoryMode::Thesis,
        limited_path: false,
        thrust_lead,
        ..Default::default()
    };
    let printed = Trajectory::new(&af, &m, &opt(false)).unwrap();
    let lead = Trajectory::new(&af, &m, &opt(true)).unwrap();
    let mut largest_lead: f64 = 0.0;
    for (p, l) in printed.points().iter().zip(lead.points()) {
        assert_eq!(p.u[0], p.thrust.clamp(af.thrust_min, af.thrust_max));
        assert_eq!(p.thrust, l.thrust);
        largest_lead = largest_lead.max((l.u[0] - p.u[0]).abs());
    }
    assert!(largest_lead > 0.1, "the lead changes the command in the transitions");
}
