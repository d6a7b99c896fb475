//! The FMU binding through `FmuModel` (no C layer): start values, bad input and
//! parameters as errors with finite outputs, FMU state continuing bit-identically.

use fmi2_export::test_host::{assert_initialization_fails, assert_state_round_trip};
use fmi2_export::{FmuModel, Logger, VariableStore};
use tailsitter_sensors::{SensorsModel, Variables};

/// The Real outputs: the GPS's six, then the ten analogue channels.
fn reals(v: &Variables) -> [f64; 16] {
    [
        v.gps_latitude,
        v.gps_longitude,
        v.gps_height,
        v.gps_vel_n,
        v.gps_vel_e,
        v.gps_vel_d,
        v.imu_accel_x,
        v.imu_accel_y,
        v.imu_accel_z,
        v.imu_gyro_p,
        v.imu_gyro_q,
        v.imu_gyro_r,
        v.mag_x,
        v.mag_y,
        v.mag_z,
        v.pitot_airspeed,
    ]
}

fn outputs(v: &Variables) -> Vec<u64> {
    reals(v)
        .iter()
        .map(|x| x.to_bits())
        .chain([v.gps_fix_count as u64, v.gps_valid as u64])
        .collect()
}

fn started() -> (Variables, SensorsModel) {
    let mut vars = Variables::with_start_values();
    let mut model = SensorsModel::new(&vars);
    model.initialize(&mut vars, 0.0, &mut Logger::null()).unwrap();
    (vars, model)
}

#[test]
fn start_values_give_a_level_aircraft_at_rest_at_the_reference_point() {
    let (v, _) = started();
    assert_eq!(v.gps_fix_count, 1);
    assert!(v.gps_valid);
    // GPS within 5σ of the reference point (σ from Table D.1).
    assert!((v.gps_latitude - v.ref_latitude).abs() < 5.0 * v.gps_latlon_std);
    assert!((v.gps_height - v.ref_height).abs() < 5.0 * v.gps_height_std);
    // Accelerometer reads −g on z (delivered noise: Table D.1's σ).
    assert!((v.imu_accel_z + 9.81).abs() < 5.0 * v.accel_std);
    // Level, heading north: the magnetometer sees the NED field; its down component is
    // F sin I (negative: the field points up in the southern hemisphere).
    let down = v.mag_field_total * v.mag_inclination.sin();
    assert!((v.mag_z - down).abs() < 5.0 * v.mag_std);
    for g in [
        v.accel_noise_gain,
        v.gyro_noise_gain,
        v.mag_noise_gain,
        v.pitot_noise_gain,
    ] {
        assert!(g > 0.1 && g < 1.0, "{g}");
    }
}

#[test]
fn non_finite_input_is_an_error_and_outputs_stay_finite() {
    let (mut v, mut m) = started();
    let mut log = Logger::null();
    m.do_step(&mut v, 0.0, 0.02, &mut log).unwrap();
    let before = outputs(&v);
    v.vel_e = f64::NAN;
    let e = m.do_step(&mut v, 0.02, 0.02, &mut log).unwrap_err();
    assert!(e.message.contains("vel_e"), "{e}");
    assert_eq!(outputs(&v), before);
    m.update_outputs(&mut v).unwrap();
    assert_eq!(outputs(&v), before);
    v.vel_e = 0.0;
    v.quat_4 = 0.0;
    assert!(m
        .do_step(&mut v, 0.02, 0.02, &mut log)
        .unwrap_err()
        .message
        .contains("quaternion"));
}

#[test]
fn bad_parameters_fail_initialization_with_the_reason() {
    assert_initialization_fails::<SensorsModel>(|v| v.filter_bandwidth = 30.0, "filter_bandwidth");
    assert_initialization_fails::<SensorsModel>(|v| v.fault_mode = 3, "fault_mode");
    assert_initialization_fails::<SensorsModel>(|v| v.gyro_std = f64::NAN, "gyro_std");
    assert_initialization_fails::<SensorsModel>(|v| v.quat_1 = 0.7, "quaternion");
}

#[test]
fn initialize_is_idempotent_and_seeded() {
    let (a, _) = started();
    let (b, _) = started();
    assert_eq!(outputs(&a), outputs(&b));
    let mut v = Variables::with_start_values();
    v.seed = -7;
    let mut m = SensorsModel::new(&v);
    m.initialize(&mut v, 0.0, &mut Logger::null()).unwrap();
    assert_ne!(outputs(&v)[6..16], outputs(&a)[6..16]);
    // Re-initialising the same instance (as the layer does after fmi2Reset) starts over.
    m.initialize(&mut v, 0.0, &mut Logger::null()).unwrap();
    let first = outputs(&v);
    m.do_step(&mut v, 0.0, 0.02, &mut Logger::null()).unwrap();
    m.initialize(&mut v, 0.0, &mut Logger::null()).unwrap();
    assert_eq!(outputs(&v), first);
}

#[test]
fn fmu_state_round_trip_continues_bit_identically() {
    let (mut v, mut m) = started();
    let mut log = Logger::null();
    v.airspeed = 18.0;
    v.p = 0.2;
    for k in 0..33 {
        m.do_step(&mut v, k as f64 * 0.02, 0.02, &mut log).unwrap();
    }
    assert_state_round_trip(&mut m, &mut v, 33..200, 0.02, |_, _| {}, outputs);
}

#[test]
fn declared_start_values_are_the_model_defaults() {
    let p = <tailsitter_sensors::SensorsBinding as controller_fmu::Binding>::config(&Variables::with_start_values())
        .unwrap();
    let d = sensor_model::Params::default();
    // Angles are declared in rad from the same degrees: equal to the last bits or nearly.
    let (ps, ds) = (p.site, d.site);
    for (a, b) in [
        (ps.ref_latitude, ds.ref_latitude),
        (ps.ref_longitude, ds.ref_longitude),
        (ps.mag_declination, ds.mag_declination),
        (ps.mag_inclination, ds.mag_inclination),
    ] {
        assert!((a - b).abs() < 1e-12, "{a} vs {b}");
    }
    let same_angles = sensor_model::Params {
        site: sensor_model::Site {
            ref_latitude: ds.ref_latitude,
            ref_longitude: ds.ref_longitude,
            mag_declination: ds.mag_declination,
            mag_inclination: ds.mag_inclination,
            ..ps
        },
        ..p
    };
    assert_eq!(same_angles, d);
}

/// Through the FMU's variables at the declared defaults (accelerometer 1 kHz, gyro 200 Hz,
/// magnetometer and pitot 50 Hz, 8 Hz Butterworth), the aircraft held level at the reference
/// point with 25 m/s airspeed: each delivered channel's sample σ is Table D.1's (pitot:
/// σ_Δp/(ρ₀V̄)) within 5 %. 40 000 steps of 20 ms after a 1 s start-up: 39 950 outputs per
/// analogue channel (correlated over ≈ 20 ms: statistical error of σ ≈ 0.5 %), 3196 GPS
/// fixes (1.3 %).
#[test]
fn delivered_noise_is_table_d1() {
    let (mut v, mut m) = started();
    let mut log = Logger::null();
    v.airspeed = 25.0;
    let (steps, h) = (40_000, 0.02);
    let mut analog = vec![Vec::new(); 10];
    let mut gps = vec![Vec::new(); 6];
    let mut fixes = v.gps_fix_count;
    for k in 0..steps {
        m.do_step(&mut v, k as f64 * h, h, &mut log).unwrap();
        if k < 50 {
            fixes = v.gps_fix_count;
            continue;
        }
        let r = reals(&v);
        let (g, a) = r.split_at(6);
        a.iter().zip(analog.iter_mut()).for_each(|(x, s)| s.push(*x));
        if v.gps_fix_count != fixes {
            fixes = v.gps_fix_count;
            g.iter().zip(gps.iter_mut()).for_each(|(x, s)| s.push(*x));
        }
    }
    let std = |x: &[f64]| {
        let n = x.len() as f64;
        let mean = x.iter().sum::<f64>() / n;
        (x.iter().map(|y| (y - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
    };
    let sigma = [
        v.accel_std,
        v.accel_std,
        v.accel_std,
        v.gyro_std,
        v.gyro_std,
        v.gyro_std,
        v.mag_std,
        v.mag_std,
        v.mag_std,
        v.pitot_std / (sensor_model::RHO_0 * 25.0),
        v.gps_latlon_std,
        v.gps_latlon_std,
        v.gps_height_std,
        v.gps_vel_std,
        v.gps_vel_std,
        v.gps_vel_std,
    ];
    for (c, x) in analog.iter().chain(gps.iter()).enumerate() {
        let ratio = std(x) / sigma[c];
        println!("FMU channel {c}: n = {}, σ/σ_Table D.1 = {ratio:.4}", x.len());
        assert!((ratio - 1.0).abs() < 0.05, "channel {c}: {ratio}");
    }
}
