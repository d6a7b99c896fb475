//! Behaviour under faults: GPS dropout, spikes, non-finite and out-of-range values, a
//! restarted GPS receiver, a persistent GPS jump, initialisation without GPS, a re-initialisation
//! mid-run; and the outputs beyond the kinematic states (motor, servos, air data).

mod common;

use common::*;
use nalgebra::Vector3;
use state_estimator::{geodesy, Ekf, Reason, Sensor};
use tailsitter_physics::idx;

fn assert_finite(ekf: &Ekf, k: usize) {
    let e = ekf.estimate();
    let s = &ekf.state;
    assert!(
        s.pos
            .iter()
            .chain(s.vel.iter())
            .chain(s.quat.iter())
            .all(|v| v.is_finite())
            && s.cov.iter().all(|v| v.is_finite())
            && [
                e.airspeed,
                e.alpha,
                e.beta,
                e.induced_velocity,
                e.std_pos,
                e.std_vel,
                e.std_att
            ]
            .iter()
            .all(|v| v.is_finite()),
        "non-finite estimate at step {k}"
    );
}

#[test]
fn gps_dropout_of_10_s_in_level_flight_is_dead_reckoned_inside_3_sigma() {
    let truth = level_truth(50.0, Vector3::new(2.0, -1.0, 0.0));
    let params = unfiltered_params();
    let (t_off, t_on) = (20.0, 30.0);
    for seed in 0..10 {
        let mut std_at_loss = 0.0;
        let mut std_at_return = 0.0;
        let mut fused_after = false;
        let mut max_ratio: f64 = 0.0;
        run_filter(
            &truth,
            &params,
            seed,
            |k, sim, m| {
                let t = k as f64 * H;
                sim.gps_on = !(t >= t_off && t < t_on);
                m.gps_valid = sim.gps_on;
            },
            |k, ekf, rep| {
                let t = k as f64 * H;
                assert_finite(ekf, k);
                let e = errors(ekf, &truth, k);
                let est = ekf.estimate();
                if (t_off..t_on).contains(&t) {
                    if std_at_loss == 0.0 {
                        std_at_loss = est.std_pos;
                    }
                    std_at_return = est.std_pos;
                    // The reported σ covers the error: |e| ≤ 3 √trace P_pp.
                    max_ratio = max_ratio.max(e.pos.norm() / est.std_pos);
                    assert!(
                        e.pos.norm() <= 3.0 * est.std_pos,
                        "seed {seed}, t = {t}: error {} m outside 3σ = {} m",
                        e.pos.norm(),
                        3.0 * est.std_pos
                    );
                }
                if t >= t_on && t < t_on + 0.3 && rep.gps_fused {
                    fused_after = true;
                }
            },
        );
        assert!(
            std_at_return > 2.0 * std_at_loss,
            "seed {seed}: σ_pos must grow during the dropout: {std_at_loss} -> {std_at_return}"
        );
        assert!(
            fused_after,
            "seed {seed}: the first fix after the dropout must be fused"
        );
        eprintln!(
            "seed {seed}: σ_pos {std_at_loss:.2} m at loss -> {std_at_return:.2} m after 10 s; max |e|/σ {max_ratio:.2}"
        );
    }
}

#[test]
fn gps_spikes_are_rejected_and_counted_never_fused() {
    let truth = level_truth(30.0, Vector3::zeros());
    let params = unfiltered_params();
    let (mn, me) = geodesy::LocalFrame::metres_per_radian(params.earth.site.ref_latitude, 0.0);
    let mut spiked = 0;
    let mut seen = Vec::new();
    let ekf = run_filter(
        &truth,
        &params,
        7,
        |k, sim, m| {
            // At the fixes at 10 s and 20 s: 60 m north / 60 m east in position, 15 m/s in
            // velocity at 15 s.
            if k == 500 || k == 1000 {
                m.gps_latitude += 60.0 / mn;
                m.gps_longitude += 60.0 / me;
                spiked += 1;
            }
            if k == 750 {
                m.gps_vel.y += 15.0;
            }
            let _ = sim;
        },
        |k, ekf, rep| {
            assert_finite(ekf, k);
            if matches!(k - 1, 500 | 750 | 1000) {
                seen.push((k - 1, *rep, errors(ekf, &truth, k).pos.norm(), ekf.estimate().std_pos));
            }
        },
    );
    assert_eq!(spiked, 2);
    for (k, rep, err, std) in seen {
        let sensor = if k == 750 {
            Sensor::GpsVelocity
        } else {
            Sensor::GpsPosition
        };
        let r = rep
            .rejections
            .iter()
            .flatten()
            .find(|r| r.sensor == sensor)
            .unwrap_or_else(|| panic!("step {k}: spike not rejected: {rep:?}"));
        assert!(matches!(r.reason, Reason::Innovation { d2, gate } if d2 > gate));
        assert!(err < 3.0 * std, "step {k}: the spike moved the estimate: error {err} m");
    }
    assert!(ekf.estimate().rejected_measurements >= 3);
}

#[test]
fn non_finite_and_out_of_range_values_are_rejected_not_propagated() {
    let truth = level_truth(20.0, Vector3::zeros());
    let params = unfiltered_params();
    // (step, what, expected sensor)
    type Fault = (usize, fn(&mut state_estimator::Measurements), Sensor);
    let faults: [Fault; 10] = [
        (200, |m| m.accel.x = f64::NAN, Sensor::Imu),
        (210, |m| m.gyro.z = f64::INFINITY, Sensor::Imu),
        (220, |m| m.accel.y = 1e4, Sensor::Imu),
        (230, |m| m.mag.x = f64::NAN, Sensor::Magnetometer),
        (240, |m| m.mag = Vector3::new(5.0, 0.0, 0.0), Sensor::Magnetometer),
        (250, |m| m.pitot = f64::NAN, Sensor::Pitot),
        (260, |m| m.pitot = 1e6, Sensor::Pitot),
        (300, |m| m.gps_latitude = f64::NAN, Sensor::GpsPosition),
        (325, |m| m.gps_latitude = 3.0, Sensor::GpsPosition),
        (350, |m| m.gps_vel.z = f64::NEG_INFINITY, Sensor::GpsVelocity),
    ];
    let mut hits = Vec::new();
    let ekf = run_filter(
        &truth,
        &params,
        3,
        |k, _, m| {
            for (step, f, _) in &faults {
                if *step == k {
                    f(m);
                }
            }
        },
        |k, ekf, rep| {
            assert_finite(ekf, k);
            for (step, _, sensor) in &faults {
                if *step == k - 1 {
                    hits.push((*step, *sensor, *rep));
                }
            }
        },
    );
    for (step, sensor, rep) in hits {
        let r = rep.rejections.iter().flatten().find(|r| r.sensor == sensor);
        let r = r.unwrap_or_else(|| panic!("step {step}: {sensor:?} fault not rejected: {rep:?}"));
        assert!(
            matches!(r.reason, Reason::NonFinite | Reason::OutOfRange(_)),
            "step {step}: {r}"
        );
    }
    let e = errors(&ekf, &truth, truth.len());
    let est = ekf.estimate();
    assert!(est.rejected_measurements >= faults.len() as i32);
    assert!(e.pos.norm() < 3.0 * est.std_pos && e.att.norm() < 3.0 * est.std_att);
}

#[test]
fn restarted_gps_receiver_counter_going_back_is_accepted_as_new_fixes() {
    let truth = level_truth(20.0, Vector3::zeros());
    let params = unfiltered_params();
    let mut restart = None;
    let mut fused_after = 0;
    let ekf = run_filter(
        &truth,
        &params,
        11,
        |k, sim, m| {
            if k == 500 {
                // The receiver restarts: this fix is its first, counting from 1 again.
                sim.fix_count = 1;
                m.gps_fix_count = 1;
            }
        },
        |k, ekf, rep| {
            assert_finite(ekf, k);
            if let Some(r) = rep.gps_restart {
                restart = Some((k - 1, r));
            }
            if k > 500 && rep.gps_fused {
                fused_after += 1;
            }
        },
    );
    let (k, (from, to)) = restart.expect("restart reported");
    assert_eq!(k, 500);
    assert!(from > 30 && to == 1, "{from} -> {to}");
    // 10 s at 4 Hz after the restart: every fix fused (none lost to the counter).
    assert!(fused_after >= 39, "fixes fused after the restart: {fused_after}");
    let e = errors(&ekf, &truth, truth.len());
    assert!(e.pos.norm() < 3.0 * ekf.estimate().std_pos);
}

#[test]
fn persistent_gps_jump_resets_the_position_after_repeated_rejections() {
    let truth = level_truth(20.0, Vector3::zeros());
    let params = unfiltered_params();
    let (mn, _) = geodesy::LocalFrame::metres_per_radian(params.earth.site.ref_latitude, 0.0);
    let mut reset_at = None;
    let ekf = run_filter(
        &truth,
        &params,
        5,
        |k, _, m| {
            if k >= 500 {
                m.gps_latitude += 300.0 / mn; // the GPS is 300 m north from now on
            }
        },
        |k, ekf, rep| {
            assert_finite(ekf, k);
            if rep.gps_reset[0] && reset_at.is_none() {
                reset_at = Some(k - 1);
            }
        },
    );
    // 8 rejected fixes at 4 Hz: the reset comes ≈ 1.75–2 s after the jump.
    let k = reset_at.expect("position reset");
    assert!((585..=605).contains(&k), "reset at step {k}");
    // Following the GPS now: 300 m north of the truth.
    let e = errors(&ekf, &truth, truth.len());
    assert!((e.pos.x + 300.0).abs() < 15.0, "{}", e.pos);
}

#[test]
fn initialisation_without_gps_then_a_fix_far_away() {
    let truth = level_truth(20.0, Vector3::zeros());
    let params = unfiltered_params();
    let mut resets = 0;
    let ekf = run_filter(
        &truth,
        &params,
        9,
        |k, sim, m| {
            sim.gps_on = k >= 100;
            m.gps_valid = sim.gps_on;
        },
        |k, ekf, rep| {
            assert_finite(ekf, k);
            resets += rep.gps_reset[0] as i32;
        },
    );
    // The aircraft is 50 m (2 s at 25 m/s) from the origin at the first fix: inside the
    // 50 m σ without GPS, so fused directly or after a reset, either way converged.
    let e = errors(&ekf, &truth, truth.len());
    assert!(
        e.pos.norm() < 3.0 * ekf.estimate().std_pos,
        "{} (resets {resets})",
        e.pos
    );
    assert!(ekf.estimate().std_pos < 10.0);
}

#[test]
fn reinitialisation_mid_run_restarts_cleanly() {
    let truth = level_truth(20.0, Vector3::zeros());
    let params = unfiltered_params();
    let mut ekf = Ekf::new(params.clone()).unwrap();
    let mut sim = SensorSim::new(&params, 21);
    let m = sim.measure(&ekf, &truth, 0);
    ekf.initialize(&m);
    for k in 0..truth.len() {
        let m = sim.measure(&ekf, &truth, k);
        if k == 400 {
            let r = ekf.initialize(&m);
            assert!(r.from_gps && r.attitude_from_sensors);
            assert!((r.accel_ratio - 1.0).abs() < 0.1, "steady flight: |f| ≈ g");
            assert_eq!(ekf.estimate().rejected_measurements, 0);
        }
        ekf.step(&m, &truth.u[k], H);
        assert_finite(&ekf, k);
    }
    let e = errors(&ekf, &truth, truth.len());
    assert!(e.pos.norm() < 3.0 * ekf.estimate().std_pos);
    assert!(e.att.norm() < 3.0 * ekf.estimate().std_att);
}

#[test]
fn motor_servo_and_air_data_outputs_follow_the_plant() {
    let truth = mission_truth(Vector3::zeros());
    let params = unfiltered_params();
    let mut worst = [0.0f64; 6];
    run_filter(
        &truth,
        &params,
        4,
        |_, _, _| {},
        |k, ekf, _| {
            let x = &truth.x[k];
            let u = &truth.u[k.min(truth.len() - 1)];
            let y = truth.plant.outputs(x, u, &truth.wind);
            let est = ekf.estimate();
            worst[0] = worst[0].max((est.thrust - x[idx::THRUST]).abs());
            for s in 0..6 {
                worst[1] = worst[1].max((est.surfaces[s] - x[idx::SURFACES + s]).abs());
            }
            let t = k as f64 * H;
            // Air data where the airspeed is well defined (level flight, 25 m/s).
            if (12.0..19.0).contains(&t) {
                worst[2] = worst[2].max((est.airspeed - y.airspeed).abs());
                worst[3] = worst[3].max((est.alpha - y.alpha).abs());
                worst[4] = worst[4].max((est.beta - y.beta).abs());
            }
            worst[5] = worst[5].max((est.induced_velocity - y.induced_velocity).abs());
        },
    );
    eprintln!("worst: thrust {:.2e} N, surfaces {:.2e} rad, airspeed {:.3} m/s, alpha {:.4} rad, beta {:.4} rad, induced velocity {:.3} m/s", worst[0], worst[1], worst[2], worst[3], worst[4], worst[5]);
    // Same model and commands as the plant: only the integration differs (exact vs RK4).
    assert!(worst[0] < 1e-6, "thrust {}", worst[0]);
    assert!(worst[1] < 1e-6, "surfaces {}", worst[1]);
    // Air data from estimated velocity, attitude and wind (velocity σ ≈ 0.1 m/s, attitude
    // σ ≈ 0.5°, wind converging through the pitot): airspeed to 1 m/s, α, β to 2°.
    assert!(worst[2] < 1.0, "airspeed {}", worst[2]);
    assert!(worst[3] < 2f64.to_radians(), "alpha {}", worst[3]);
    assert!(worst[4] < 2f64.to_radians(), "beta {}", worst[4]);
    assert!(worst[5] < 1.0, "induced velocity {}", worst[5]);
}

#[test]
fn hover_gives_finite_air_data() {
    let plant = tailsitter_physics::Plant::new(tailsitter_physics::Airframe::default());
    let trim = plant.trim_vertical_climb(0.0).unwrap();
    let mut x = trim.state;
    let mut xs = Vec::new();
    for _ in 0..500 {
        xs.push(x);
        plant.advance(&mut x, &trim.inputs, &Vector3::zeros(), H).unwrap();
    }
    xs.push(x);
    let truth = Truth {
        plant,
        wind: Vector3::zeros(),
        u: vec![trim.inputs; xs.len() - 1],
        x: xs,
    };
    let ekf = run_filter(
        &truth,
        &unfiltered_params(),
        2,
        |_, _, _| {},
        |k, ekf, _| {
            assert_finite(ekf, k);
            let e = ekf.estimate();
            assert!(e.alpha.abs() <= std::f64::consts::PI && e.beta.abs() <= std::f64::consts::FRAC_PI_2);
        },
    );
    // At hover the airspeed estimate is the wind uncertainty: small, finite.
    let e = ekf.estimate();
    assert!(e.airspeed < 3.0, "hover airspeed estimate {}", e.airspeed);
    let y = truth.plant.outputs(&truth.x[500], &truth.u[0], &Vector3::zeros());
    assert!((e.induced_velocity - y.induced_velocity).abs() < 1.0);
}
