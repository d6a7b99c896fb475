//! The avionics chain without FMI: plant → sensors (synthesised, Table D.1 noise) →
//! estimator → controller → plant, and controller commands → estimator, flying the
//! default mission. The controllers read the estimate exactly as they read the plant.

mod common;

use common::*;
use flight_mission::{ControllerInput, FlightController, Measurement, MissionParams, Phase};
use lqr_control::{LqrController, LqrParams};
use nalgebra::Vector3;
use state_estimator::{Ekf, Estimate, EstimatorParams};
use tailsitter_physics::{idx, Airframe, Plant};
use tsd_control::{TsdController, TsdParams};

/// The estimate as the controller's measurement (the plant outputs of the same names).
fn measurement(e: &Estimate) -> Measurement {
    Measurement {
        pos_ned: e.pos_ned,
        vel_ned: e.vel_ned,
        vel_body: e.vel_body,
        rates: e.rates,
        quat: e.quat,
        airspeed: e.airspeed,
        alpha: e.alpha,
        beta: e.beta,
        thrust: e.thrust,
        surfaces: e.surfaces,
        specific_force_body: e.specific_force,
        induced_velocity: e.induced_velocity,
    }
}

struct Flight {
    /// Max distance of the true position from the reference (m).
    max_true_error: f64,
    /// Max estimation error of the position (m).
    max_est_error: f64,
    /// Max of the position estimation error over 3 √trace P_pp.
    max_error_ratio: f64,
    final_phase: Phase,
    rejected: i32,
}

/// Gauss-Seidel per 20 ms: controller(t) on the estimate at t → estimator step with the
/// measurements at t and the command for [t, t + h) → plant step.
fn fly_on_estimates<C: FlightController>(c: &mut C, seed: u64) -> Flight {
    let plant = Plant::new(Airframe::default());
    let m = MissionParams::default();
    let trim = plant.trim_vertical_climb(m.v_vertical).unwrap();
    let mut x = trim.state;
    let params = EstimatorParams::default();
    let mut ekf = Ekf::new(params.clone()).unwrap();
    let mut sim = SensorSim::new(&params, seed);
    let wind = Vector3::zeros();
    let m0 = sim.measure_state(&ekf, &plant, &x, &trim.inputs, &wind, 0);
    ekf.initialize(&m0, &trim.inputs);
    let n = (m.end_time() / H).round() as usize;
    let mut f = Flight {
        max_true_error: 0.0,
        max_est_error: 0.0,
        max_error_ratio: 0.0,
        final_phase: Phase::Vertical1,
        rejected: 0,
    };
    for k in 0..n {
        let t = k as f64 * H;
        let input = ControllerInput {
            t,
            measurement: measurement(&ekf.estimate()),
            ref_offset_ned: Vector3::zeros(),
        };
        let out = c
            .update(&input)
            .unwrap_or_else(|e| panic!("controller failed at t = {t}: {e}"));
        let u = closed_loop::plant_inputs(&out.command);
        let pos = Vector3::new(x[idx::POS_N], x[idx::POS_E], x[idx::POS_D]);
        f.max_true_error = f.max_true_error.max((pos - out.diagnostics.ref_pos_ned).norm());
        let e = (pos - ekf.estimate().pos_ned).norm();
        f.max_est_error = f.max_est_error.max(e);
        f.max_error_ratio = f.max_error_ratio.max(e / (3.0 * ekf.estimate().std_pos));
        f.final_phase = out.diagnostics.phase;
        let meas = if k == 0 {
            m0
        } else {
            sim.measure_state(&ekf, &plant, &x, &u, &wind, k)
        };
        ekf.step(&meas, &u, H);
        plant
            .advance(&mut x, &u, &wind, H)
            .unwrap_or_else(|e| panic!("plant failed after t = {t}: {e}"));
    }
    f.rejected = ekf.estimate().rejected_measurements;
    f
}

#[test]
fn lqr_flies_the_mission_on_the_estimates() {
    let m = MissionParams::default();
    let mut c = LqrController::new(Airframe::default(), m, LqrParams::default()).unwrap();
    let f = fly_on_estimates(&mut c, 1);
    eprintln!(
        "LQR on estimates: max |true position − reference| {:.2} m, max position estimation error {:.2} m (≤ {:.2} × 3σ), rejected {}",
        f.max_true_error, f.max_est_error, f.max_error_ratio, f.rejected
    );
    assert_eq!(f.final_phase, Phase::Vertical2);
    // The estimate stays inside its reported 3σ (√trace) while the controller flies on it.
    // The controller flies the estimate: the true distance from the reference is its own
    // tracking error (0.39 m on the true state) plus the estimation error, which starts
    // at the first GPS fix's (σ 4 m per axis).
    assert!(f.max_error_ratio < 1.0, "estimation error {} × 3σ", f.max_error_ratio);
    assert!(f.max_true_error < 8.0, "true tracking error {}", f.max_true_error);
}

#[test]
fn tsd_flies_the_mission_on_the_estimates() {
    let m = MissionParams::default();
    let mut c = TsdController::new(TsdParams::default(), m, Airframe::default()).unwrap();
    let f = fly_on_estimates(&mut c, 2);
    eprintln!(
        "TSD on estimates: max |true position − reference| {:.2} m, max position estimation error {:.2} m (≤ {:.2} × 3σ), rejected {}",
        f.max_true_error, f.max_est_error, f.max_error_ratio, f.rejected
    );
    assert_eq!(f.final_phase, Phase::Vertical2);
    assert!(f.max_error_ratio < 1.0, "estimation error {} × 3σ", f.max_error_ratio);
    assert!(f.max_true_error < 8.0, "true tracking error {}", f.max_true_error);
}
