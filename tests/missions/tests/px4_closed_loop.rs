//! Closed-loop acceptance of the PX4 controller with the nonlinear plant through the
//! reference master of `closed-loop` (Gauss-Seidel and Jacobi), from the trimmed 3 m/s
//! climb; take-off → landing from rest on the gear. Bounds are the measured figures with a
//! margin (`cargo run --release -p missions --example controller_table` prints them side by
//! side with the LQR and TSD).
//!
//! The position error is against the missions' flight-path profile: in fixed-wing flight
//! the airspeed setpoint is corrected from the along-track error, the back transition's
//! height loop flies the profile's climb (crate README, "What differs from PX4"); what is
//! left is PX4's front transition, whose thrust holds height with the horizontal axes free
//! (it ends 6–8 m behind the profile; the level phase inherits that).

use closed_loop::{fly, MissionCheck, Ordering, Scenario, Trace};
use flight_mission::{MissionParams, Phase, SampledUnit};
use nalgebra::Vector3;
use px4_control::{Px4Controller, VtolMode};
use tailsitter_physics::{Airframe, Plant};

fn run(mission: MissionParams, ordering: Ordering) -> (Trace, MissionCheck, Vec<VtolMode>) {
    let plant = Plant::new(Airframe::default());
    let x0 = plant.trim_vertical_climb(mission.v_vertical).unwrap().state;
    let mut ctl = Px4Controller::with_mission(mission).unwrap();
    let mut scenario = Scenario::mission(mission);
    scenario.ordering = ordering;
    let trace = fly(&plant, x0, &mut ctl, &scenario);
    // The modes of the samples, replayed on a second controller fed the same inputs.
    let mut probe = Px4Controller::with_mission(mission).unwrap();
    let modes = trace
        .samples
        .iter()
        .map(|s| {
            let input = flight_mission::ControllerInput {
                t: s.t,
                measurement: s.measurement,
                ref_offset_ned: Vector3::zeros(),
            };
            probe.sample(&input).unwrap();
            probe.mode()
        })
        .collect();
    let check = MissionCheck::of(&trace, &mission, plant.trim_level(mission.v_level).unwrap().theta);
    println!("{check}max position error {:.2} m", trace.max_pos_error());
    (trace, check, modes)
}

/// First time (s) of `mode` in the run, if any.
fn first(trace: &Trace, modes: &[VtolMode], mode: VtolMode) -> Option<f64> {
    trace
        .samples
        .iter()
        .zip(modes)
        .find(|(_, m)| **m == mode)
        .map(|(s, _)| s.t)
}

fn assert_default_mission(ordering: Ordering) {
    let mission = MissionParams::default();
    let (trace, check, modes) = run(mission, ordering);
    assert!(trace.completed(), "{:?}", trace.failure);
    // The criteria: level airspeed within 1 m/s (measured GS / Jacobi 0.40 / 0.42 m/s), pitch
    // within 5° (0.36° / 0.45°), upright at the end (0.00° / 0.07°).
    assert!(check.passed(), "{check}");
    assert!(check.level_airspeed_error < 0.6, "{check}");
    assert!(check.level_pitch_error < 1f64.to_radians(), "{check}");
    assert!(check.final_pitch_error < 0.5f64.to_radians(), "{check}");
    // Vertical flight on the multicopter position controller: on the reference.
    assert!(check.phase_errors[0].max < 0.05, "{check}");
    // Front transition: fixed-wing flight once the ramp is over and the airspeed reaches
    // VT_ARSP_TRANS = v_level, 0.4 s after T1 = 5 s (the profile reaches it at 9.6 s).
    let fw = first(&trace, &modes, VtolMode::FixedWing).expect("fixed-wing flight");
    assert!(fw > 5.0 + 4.5 && fw < 11.0, "fixed wing at {fw} s");
    // Back transition: on the request at 20 s, upright (multicopter flight) before T2 = 10 s
    // is over.
    let back = first(&trace, &modes, VtolMode::BackTransition).expect("back transition");
    assert!((back - 20.0).abs() < 0.03, "{back}");
    let mc = trace
        .samples
        .iter()
        .zip(&modes)
        .find(|(s, m)| s.t > back && **m == VtolMode::Multicopter)
        .map(|(s, _)| s.t)
        .expect("multicopter flight again");
    assert!(mc < 30.0, "multicopter at {mc} s");
    // Errors against the profile (measured GS / Jacobi: 8.4 / 8.5 m in T1, 9.5 / 9.6 m
    // level, 11.6 / 11.4 m in T2, 3.8 / 3.9 m in the second vertical phase). Flying the
    // profile's climb through T2 is what keeps the last two small: holding 6 m/s of climb
    // at most, they were 77 m and 103 m.
    assert!(check.phase_errors[1].max < 10.0, "{check}");
    assert!(check.phase_errors[2].max < 11.0, "{check}");
    assert!(check.phase_errors[3].max < 13.0, "{check}");
    assert!(check.phase_errors[4].max < 5.0, "{check}");
    assert!(trace.max_pos_error() < 13.0, "{}", trace.max_pos_error());
    // α through the front transition and level flight: that of flight (measured 16.5°).
    let alpha = trace
        .window(5.0, 20.0)
        .filter(|s| s.measurement.airspeed >= 5.0)
        .map(|s| s.measurement.alpha.abs())
        .fold(0.0, f64::max);
    assert!(alpha < 20f64.to_radians(), "{}", alpha.to_degrees());
}

#[test]
fn default_mission_gauss_seidel() {
    assert_default_mission(Ordering::GaussSeidel);
}

#[test]
fn default_mission_jacobi() {
    assert_default_mission(Ordering::Jacobi);
}

/// The fast mission (T1 = 3 s, T2 = 4 s): PX4's ramps at 30°/s and 22.5°/s. It meets the
/// criteria (level airspeed within 0.30 m/s of v_level, pitch 0.2° / 0.35°, upright within
/// 0.3° / 1.1°); the largest error 9.1 / 9.3 m (level flight).
#[test]
fn fast_mission() {
    for ordering in [Ordering::GaussSeidel, Ordering::Jacobi] {
        let mission = MissionParams::fast();
        let (trace, check, modes) = run(mission, ordering);
        assert!(trace.completed(), "{:?}", trace.failure);
        assert!(check.passed(), "{check}");
        assert!(check.level_airspeed_error < 0.45, "{check}");
        assert!(check.final_pitch_error < 2f64.to_radians(), "{check}");
        // Fixed-wing flight after the 3 s ramp's pitch threshold and VT_ARSP_TRANS.
        let fw = first(&trace, &modes, VtolMode::FixedWing).expect("fixed-wing flight");
        assert!(fw > 7.0 && fw < 9.0, "fixed wing at {fw} s");
        assert!(check.phase_errors[1].max < 7.5, "{check}");
        assert!(check.phase_errors[2].max < 10.5, "{check}");
        assert!(trace.max_pos_error() < 10.5, "{}", trace.max_pos_error());
    }
}

/// Take-off from rest on the gear, the mission, landing 460 m north on the global
/// aerodynamics with the ground plane: landed on the target and upright.
#[test]
fn takeoff_to_landing() {
    let mission = analysis::takeoff_landing::mission();
    let (plant, x0) = analysis::takeoff_landing::plant();
    for ordering in [Ordering::GaussSeidel, Ordering::Jacobi] {
        let mut ctl = Px4Controller::with_mission(mission).unwrap();
        let mut s = Scenario::mission(mission);
        s.ordering = ordering;
        s.stop_time = analysis::takeoff_landing::stop_time(&mission);
        let trace = fly(&plant, x0, &mut ctl, &s);
        assert!(trace.completed(), "{:?}", trace.failure);
        let last = trace.samples.last().unwrap();
        assert_eq!(last.diagnostics.phase, Phase::Landed);
        let miss = (last.measurement.pos_ned.xy() - nalgebra::Vector2::new(460.0, 0.0)).norm();
        assert!(miss < 0.5, "miss distance {miss} m");
        assert!((last.theta - core::f64::consts::FRAC_PI_2).abs() < 2f64.to_radians());
        // On the profile as in the default mission, take-off and landing included (measured
        // 11.6 / 11.4 m).
        let theta = Plant::new(Airframe::default())
            .trim_level(mission.v_level)
            .unwrap()
            .theta;
        let check = MissionCheck::of(&trace, &mission, theta);
        let flight = check.phase_errors.iter().map(|e| e.max).fold(0.0, f64::max);
        assert!(flight < 13.0, "{flight} m");
    }
}

/// 5 m steps of the reference in a long vertical phase: the multicopter position controller
/// settles within 0.5 m in 2.0 s (north, along the belly) and 3.4 s (east, along the wing).
#[test]
fn vertical_position_steps_settle() {
    let mission = MissionParams::preset("step_vertical").unwrap();
    let plant = Plant::new(Airframe::default());
    let x0 = plant.trim_vertical_climb(mission.v_vertical).unwrap().state;
    for (offset, bound) in [(Vector3::new(5.0, 0.0, 0.0), 3.0), (Vector3::new(0.0, 5.0, 0.0), 5.0)] {
        let mut ctl = Px4Controller::with_mission(mission).unwrap();
        let mut s = Scenario::mission(mission);
        s.stop_time = 35.0;
        s.ref_offset_steps = vec![(5.0, offset)];
        let trace = fly(&plant, x0, &mut ctl, &s);
        assert!(trace.completed(), "{:?}", trace.failure);
        let mut last_out = 5.0;
        for smp in trace.window(5.0, 36.0) {
            if smp.pos_error() > 0.5 {
                last_out = smp.t;
            }
        }
        let final_err = trace.samples.last().unwrap().pos_error();
        assert!(
            last_out - 5.0 < bound && final_err < 0.2,
            "{offset}: {} s, {final_err} m",
            last_out - 5.0
        );
    }
}

/// 5 m steps of the reference 5 s into a 40 s level phase, settling within 0.5 m on the
/// stepped axis. East (L1 on the offset line): 8.7 s. Down (TECS): 21.7 s — TECS's height
/// loop is first order with FW_T_ALT_TC = 5 s (11.5 s to 10 % at best), and the descent
/// trades height for speed, overshoots by 0.75 m and comes back on TECS's slow integrators;
/// it ends within 0.12 m.
#[test]
fn level_position_steps_settle() {
    let mission = MissionParams::preset("step_level").unwrap();
    let plant = Plant::new(Airframe::default());
    let x0 = plant.trim_vertical_climb(mission.v_vertical).unwrap().state;
    let (t_step, t_end) = (15.0, 45.0);
    for (offset, bound) in [(Vector3::new(0.0, 5.0, 0.0), 10.0), (Vector3::new(0.0, 0.0, 5.0), 24.0)] {
        let mut ctl = Px4Controller::with_mission(mission).unwrap();
        let mut s = Scenario::mission(mission);
        s.stop_time = t_end;
        s.ref_offset_steps = vec![(t_step, offset)];
        let trace = fly(&plant, x0, &mut ctl, &s);
        assert!(trace.completed(), "{:?}", trace.failure);
        let axis = offset.normalize();
        let err = |smp: &closed_loop::Sample| (smp.measurement.pos_ned - smp.diagnostics.ref_pos_ned).dot(&axis).abs();
        let mut last_out = t_step;
        for smp in trace.window(t_step, t_end + 1.0) {
            if err(smp) > 0.5 {
                last_out = smp.t;
            }
        }
        let final_err = err(trace.samples.last().unwrap());
        assert!(
            last_out - t_step < bound && final_err < 0.2,
            "{offset}: {} s, {final_err} m",
            last_out - t_step
        );
    }
}
