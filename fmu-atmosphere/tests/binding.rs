//! The FMU binding through `FmuModel` (no C layer): start values, bad input and
//! parameters as errors with finite outputs, FMU state continuing bit-identically,
//! the step cost.

use fmi2_export::test_host::{assert_initialization_fails, assert_state_round_trip};
use fmi2_export::{FmuModel, Logger, VariableStore};
use tailsitter_atmosphere::{AtmosphereModel, Variables};

fn outputs(v: &Variables) -> [u64; 3] {
    [v.wind_n, v.wind_e, v.wind_d].map(f64::to_bits)
}

fn started(set: impl FnOnce(&mut Variables)) -> (Variables, AtmosphereModel) {
    let mut vars = Variables::with_start_values();
    set(&mut vars);
    let mut model = AtmosphereModel::new(&vars);
    model.initialize(&mut vars, 0.0, &mut Logger::null()).unwrap();
    (vars, model)
}

#[test]
fn start_values_give_no_wind_and_a_set_wind_blows_from_its_direction() {
    let (mut v, mut m) = started(|_| {});
    assert_eq!([v.wind_n, v.wind_e, v.wind_d], [0.0; 3]);
    m.do_step(&mut v, 0.0, 0.02, &mut Logger::null()).unwrap();
    assert_eq!([v.wind_n, v.wind_e, v.wind_d], [0.0; 3]);
    let (v, _) = started(|v| {
        v.wind_speed = 7.0;
        v.wind_from = std::f64::consts::FRAC_PI_2;
        v.pos_d = -6.1;
    });
    assert!(
        (v.wind_e + 7.0).abs() < 1e-12 && v.wind_n.abs() < 1e-12,
        "{} {}",
        v.wind_n,
        v.wind_e
    );
}

#[test]
fn non_finite_input_is_an_error_and_outputs_stay_finite() {
    let (mut v, mut m) = started(|v| v.turbulence_intensity = 1);
    let mut log = Logger::null();
    m.do_step(&mut v, 0.0, 0.02, &mut log).unwrap();
    let before = outputs(&v);
    v.airspeed = f64::NAN;
    let e = m.do_step(&mut v, 0.02, 0.02, &mut log).unwrap_err();
    assert!(e.message.contains("airspeed"), "{e}");
    assert_eq!(outputs(&v), before);
}

#[test]
fn bad_parameters_fail_initialization_with_the_reason() {
    assert_initialization_fails::<AtmosphereModel>(|v| v.wind_speed = f64::NAN, "wind_speed");
    assert_initialization_fails::<AtmosphereModel>(|v| v.turbulence_intensity = 4, "turbulence_intensity");
    assert_initialization_fails::<AtmosphereModel>(|v| v.wind_profile = -1, "wind_profile");
    assert_initialization_fails::<AtmosphereModel>(|v| v.turbulence_sample_time = 0.0, "turbulence_sample_time");
}

#[test]
fn fmu_state_round_trip_continues_bit_identically() {
    let (mut v, mut m) = started(|v| {
        v.turbulence_intensity = 3;
        v.wind_speed = 4.0;
        v.gust_amplitude_d = 2.0;
        v.gust_start = 1.0;
    });
    let mut log = Logger::null();
    v.airspeed = 18.0;
    for k in 0..33 {
        v.pos_d = -0.2 * k as f64;
        m.do_step(&mut v, k as f64 * 0.02, 0.02, &mut log).unwrap();
    }
    assert_state_round_trip(&mut m, &mut v, 33..200, 0.02, |v, k| v.pos_d = -0.2 * k as f64, outputs);
}

#[test]
fn declared_start_values_are_the_model_defaults() {
    let p =
        <tailsitter_atmosphere::AtmosphereBinding as controller_fmu::Binding>::config(&Variables::with_start_values())
            .unwrap();
    assert_eq!(p, atmosphere::Params::default());
}

#[test]
fn cost_of_a_20_ms_step_with_severe_turbulence() {
    // Informative (printed, loosely bounded): two internal samples per step at T = 10 ms,
    // the height changing every step (coefficients recomputed every step).
    let (mut v, mut m) = started(|v| {
        v.turbulence_intensity = 3;
        v.wind_speed = 8.0;
    });
    let mut log = Logger::null();
    v.airspeed = 20.0;
    let n = 20_000;
    let t = std::time::Instant::now();
    for k in 0..n {
        v.pos_d = -10.0 - 1e-3 * k as f64;
        m.do_step(&mut v, k as f64 * 0.02, 0.02, &mut log).unwrap();
    }
    let per_step = t.elapsed().as_secs_f64() / n as f64;
    eprintln!("one 20 ms step: {:.2} us", per_step * 1e6);
    assert!(per_step < 1e-3, "{per_step} s per step");
}

#[test]
fn initialize_is_idempotent_and_seeded() {
    let set = |v: &mut Variables| {
        v.turbulence_intensity = 2;
        v.pos_d = -12.0;
    };
    let (a, _) = started(set);
    let (b, mut m) = started(set);
    assert_eq!(outputs(&a), outputs(&b));
    let (c, _) = started(|v| {
        set(v);
        v.seed = -7;
    });
    assert_ne!(outputs(&c), outputs(&a));
    // Re-initialising the same instance (as the layer does after fmi2Reset) starts over.
    let mut v = b;
    for k in 0..10 {
        m.do_step(&mut v, k as f64 * 0.02, 0.02, &mut Logger::null()).unwrap();
    }
    m.initialize(&mut v, 0.0, &mut Logger::null()).unwrap();
    assert_eq!(outputs(&v), outputs(&a));
}
