//! The avionics chain without FMI: plant → sensors (synthesised, Table D.1 noise) →
//! estimator → controller → plant, and controller commands → estimator, flying the
//! default mission. The controllers read the estimate exactly as they read the plant.

mod common;

use common::*;
use flight_mission::{ControllerInput, FlightController, Measurement, MissionParams, Phase};
use lqr_control::{LqrController, LqrParams};
use nalgebra::Vector3;
use state_estimator::{Ekf, Estimate, EstimatorParams};
use tailsitter_physics::{dcm_earth_to_body, idx, Airframe, Plant};
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

/// Second-order Butterworth low pass (bilinear transform with pre-warping) on the analogue
/// channels (accelerometer, gyro, magnetometer, pitot), as the avionics of thesis App. D.3.
struct Butterworth {
    b: [f64; 3],
    a: [f64; 2],
    x: [[f64; 2]; 10],
    y: [[f64; 2]; 10],
    started: bool,
}

impl Butterworth {
    fn new(cutoff: f64, sample: f64) -> Self {
        let k = (std::f64::consts::PI * cutoff * sample).tan();
        let norm = 1.0 / (1.0 + std::f64::consts::SQRT_2 * k + k * k);
        let b0 = k * k * norm;
        Self {
            b: [b0, 2.0 * b0, b0],
            a: [
                2.0 * (k * k - 1.0) * norm,
                (1.0 - std::f64::consts::SQRT_2 * k + k * k) * norm,
            ],
            x: [[0.0; 2]; 10],
            y: [[0.0; 2]; 10],
            started: false,
        }
    }

    fn filter(&mut self, m: &mut state_estimator::Measurements) {
        let mut ch = [
            m.accel.x, m.accel.y, m.accel.z, m.gyro.x, m.gyro.y, m.gyro.z, m.mag.x, m.mag.y, m.mag.z, m.pitot,
        ];
        for (i, v) in ch.iter_mut().enumerate() {
            if !self.started {
                self.x[i] = [*v; 2];
                self.y[i] = [*v; 2];
            }
            let y = self.b[0] * *v + self.b[1] * self.x[i][0] + self.b[2] * self.x[i][1]
                - self.a[0] * self.y[i][0]
                - self.a[1] * self.y[i][1];
            self.x[i] = [*v, self.x[i][0]];
            self.y[i] = [y, self.y[i][0]];
            *v = y;
        }
        self.started = true;
        m.accel = Vector3::new(ch[0], ch[1], ch[2]);
        m.gyro = Vector3::new(ch[3], ch[4], ch[5]);
        m.mag = Vector3::new(ch[6], ch[7], ch[8]);
        m.pitot = ch[9];
    }
}

struct Flight {
    /// Max distance of the true position from the reference (m).
    max_true_error: f64,
    /// Max estimation error of the position (m).
    max_est_error: f64,
    /// Max of the position estimation error over 3 √trace P_pp.
    max_error_ratio: f64,
    /// Max attitude estimation error (rad).
    max_att_error: f64,
    /// Max |true position − reference| after the first 5 s (m): the initial GPS-fix error
    /// has been flown out.
    max_true_error_after_5s: f64,
    final_phase: Phase,
    rejected: i32,
}

/// Gauss-Seidel per 20 ms: controller(t) on the estimate at t → estimator step with the
/// measurements at t and the command for [t, t + h) → plant step.
fn fly_on_estimates<C: FlightController>(c: &mut C, seed: u64, butterworth: bool) -> Flight {
    let mut lp = butterworth.then(|| Butterworth::new(8.0, H));
    let plant = Plant::new(Airframe::default());
    let m = MissionParams::default();
    let trim = plant.trim_vertical_climb(m.v_vertical).unwrap();
    let mut x = trim.state;
    let params = EstimatorParams::default();
    let mut ekf = Ekf::new(params.clone()).unwrap();
    let mut sim = SensorSim::new(&params, seed);
    let wind = Vector3::zeros();
    let mut m0 = sim.measure_state(&ekf, &plant, &x, &trim.inputs, &wind, 0);
    if let Some(lp) = lp.as_mut() {
        lp.filter(&mut m0);
    }
    ekf.initialize(&m0, &trim.inputs);
    let n = (m.end_time() / H).round() as usize;
    let mut f = Flight {
        max_true_error: 0.0,
        max_est_error: 0.0,
        max_error_ratio: 0.0,
        max_att_error: 0.0,
        max_true_error_after_5s: 0.0,
        final_phase: Phase::Vertical1,
        rejected: 0,
    };
    for k in 0..n {
        let t = k as f64 * H;
        // The sensors at t (their values do not depend on the command of this step).
        let meas = if k == 0 {
            m0
        } else {
            let mut m = sim.measure_state(&ekf, &plant, &x, &trim.inputs, &wind, k);
            if let Some(lp) = lp.as_mut() {
                lp.filter(&mut m);
            }
            m
        };
        let input = ControllerInput {
            t,
            measurement: measurement(&ekf.estimate()),
            ref_offset_ned: Vector3::zeros(),
        };
        let out = c
            .sample(&input)
            .unwrap_or_else(|e| panic!("controller failed at t = {t}: {e}"));
        let u = closed_loop::plant_inputs(&out.command);
        let pos = Vector3::new(x[idx::POS_N], x[idx::POS_E], x[idx::POS_D]);
        let true_error = (pos - out.diagnostics.ref_pos_ned).norm();
        f.max_true_error = f.max_true_error.max(true_error);
        if t >= 5.0 {
            f.max_true_error_after_5s = f.max_true_error_after_5s.max(true_error);
        }
        let q_true = x.fixed_rows::<4>(idx::Q1).into_owned();
        f.max_att_error = f.max_att_error.max(
            state_estimator::attitude_error(&dcm_earth_to_body(&q_true), &dcm_earth_to_body(&ekf.estimate().quat))
                .norm(),
        );
        let e = (pos - ekf.estimate().pos_ned).norm();
        f.max_est_error = f.max_est_error.max(e);
        f.max_error_ratio = f.max_error_ratio.max(e / (3.0 * ekf.estimate().std_pos));
        f.final_phase = out.diagnostics.phase;
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
    let f = fly_on_estimates(&mut c, 1, false);
    eprintln!(
        "LQR on estimates: max |true position − reference| {:.2} m ({:.2} m after 5 s), max position estimation error {:.2} m (≤ {:.2} × 3σ), max attitude error {:.2}°, rejected {}",
        f.max_true_error, f.max_true_error_after_5s, f.max_est_error, f.max_error_ratio, f.max_att_error.to_degrees(), f.rejected
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
    let mut c = TsdController::new(Airframe::default(), m, TsdParams::default()).unwrap();
    let f = fly_on_estimates(&mut c, 2, false);
    eprintln!(
        "TSD on estimates: max |true position − reference| {:.2} m ({:.2} m after 5 s), max position estimation error {:.2} m (≤ {:.2} × 3σ), max attitude error {:.2}°, rejected {}",
        f.max_true_error, f.max_true_error_after_5s, f.max_est_error, f.max_error_ratio, f.max_att_error.to_degrees(), f.rejected
    );
    assert_eq!(f.final_phase, Phase::Vertical2);
    assert!(f.max_error_ratio < 1.0, "estimation error {} × 3σ", f.max_error_ratio);
    assert!(f.max_true_error < 8.0, "true tracking error {}", f.max_true_error);
}

/// With the avionics' 8 Hz second-order Butterworth on the analogue channels (App. D.3:
/// ≈ 28 ms group delay, noise coloured), which the filter does not model, the LQR still
/// flies the mission on the estimates.
#[test]
fn lqr_flies_the_mission_with_butterworth_filtered_sensors() {
    let m = MissionParams::default();
    let mut c = LqrController::new(Airframe::default(), m, LqrParams::default()).unwrap();
    let f = fly_on_estimates(&mut c, 1, true);
    eprintln!(
        "LQR on estimates, 8 Hz Butterworth: max |true position − reference| {:.2} m, max attitude error {:.2}°, rejected {}",
        f.max_true_error,
        f.max_att_error.to_degrees(),
        f.rejected
    );
    assert_eq!(f.final_phase, Phase::Vertical2);
    assert!(f.max_error_ratio < 1.0, "estimation error {} × 3σ", f.max_error_ratio);
    assert!(f.max_true_error < 8.0, "true tracking error {}", f.max_true_error);
}

/// KNOWN ISSUE (reproducer): the TSD controller on the estimates with the 8 Hz Butterworth
/// on the analogue channels loses the mission (max |true position − reference| ≈ 83 m,
/// attitude error ≈ 99°). The TSD on the *true* state with the same filter on rates and
/// specific force flies (2.8 m), and on the estimates without the filter too (1.9 m): the
/// filter's unmodelled delay plus the estimator's one-step hold of the rates and specific
/// force (outputs at t + h are the samples of t) exceed the margin of TSD's fast inner
/// loops. Giving p, q, r and accel_* direct feedthrough from the IMU inputs brings it to
/// 15 m; modelling the Butterworth in the filter is the remaining step.
#[test]
#[ignore = "known issue: TSD + estimator + unmodelled 8 Hz Butterworth"]
fn tsd_flies_the_mission_with_butterworth_filtered_sensors() {
    let m = MissionParams::default();
    let mut c = TsdController::new(Airframe::default(), m, TsdParams::default()).unwrap();
    let f = fly_on_estimates(&mut c, 2, true);
    eprintln!(
        "TSD on estimates, 8 Hz Butterworth: max |true position − reference| {:.2} m, max attitude error {:.2}°",
        f.max_true_error,
        f.max_att_error.to_degrees()
    );
    assert!(f.max_true_error < 8.0, "true tracking error {}", f.max_true_error);
}
