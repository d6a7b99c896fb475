//! `dist/tailsitter_plant.fmu` loaded through the `fmi` crate (rust-fmi's
//! importer, independent of our export layer): instantiate, initialise, fly
//! 5 s of the default trimmed climb, check the physics, get/set values, reset.

use fmi::fmi2::import::Fmi2Import;
use fmi::fmi2::instance::{CoSimulation, Common};
use fmi::traits::FmiImport;
use std::path::PathBuf;

fn fmu(id: &str) -> PathBuf {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../dist")
        .join(format!("{id}.fmu"));
    assert!(p.exists(), "{} missing: run `cargo xtask dist` first", p.display());
    p
}

fn vr(import: &Fmi2Import, name: &str) -> u32 {
    import
        .model_description()
        .model_variable_by_name(name)
        .unwrap_or_else(|_| panic!("no variable {name}"))
        .value_reference
}

fn get(inst: &mut fmi::fmi2::instance::InstanceCS, vr: u32) -> f64 {
    let mut v = [0.0];
    Common::get_real(inst, &[vr], &mut v).expect("get_real");
    v[0]
}

#[test]
fn plant_fmu_climbs_at_3_m_per_s_through_the_fmi_crate() {
    let import: Fmi2Import = fmi::import::from_path(fmu("tailsitter_plant")).expect("load FMU");
    assert_eq!(import.model_description().fmi_version, "2.0");
    let (pos_d, vel_d, theta, airspeed) = (
        vr(&import, "pos_d"),
        vr(&import, "vel_d"),
        vr(&import, "theta"),
        vr(&import, "airspeed"),
    );
    let mut inst = import.instantiate_cs("plant", false, false).expect("instantiate");
    assert_eq!(Common::get_version(&inst), "2.0");
    Common::setup_experiment(&mut inst, None, 0.0, None).unwrap();
    Common::enter_initialization_mode(&mut inst).unwrap();
    Common::exit_initialization_mode(&mut inst).unwrap();
    let h = 0.02;
    for k in 0..250 {
        inst.do_step(k as f64 * h, h, true).expect("do_step");
    }
    // Trimmed vertical climb at 3 m/s, nose up: 15 m up after 5 s.
    assert!(
        (get(&mut inst, vel_d) + 3.0).abs() < 1e-3,
        "vel_d = {}",
        get(&mut inst, vel_d)
    );
    assert!(
        (get(&mut inst, pos_d) + 15.0).abs() < 1e-2,
        "pos_d = {}",
        get(&mut inst, pos_d)
    );
    assert!((get(&mut inst, theta) - std::f64::consts::FRAC_PI_2).abs() < 1e-3);
    assert!((get(&mut inst, airspeed) - 3.0).abs() < 1e-3);

    // A bad value reference is an error, not a crash.
    let mut v = [0.0];
    assert!(Common::get_real(&mut inst, &[1_000_000], &mut v).is_err());
    // A NaN input is refused.
    let thrust_cmd = vr(&import, "thrust_cmd");
    assert!(Common::set_real(&mut inst, &[thrust_cmd], &[f64::NAN]).is_err());

    // Reset: back to the initial climb.
    Common::reset(&mut inst).unwrap();
    Common::setup_experiment(&mut inst, None, 0.0, None).unwrap();
    Common::enter_initialization_mode(&mut inst).unwrap();
    Common::exit_initialization_mode(&mut inst).unwrap();
    assert_eq!(get(&mut inst, pos_d), 0.0);
    Common::terminate(&mut inst).unwrap();
}

#[test]
fn plant_fmu_starts_in_level_flight_when_asked() {
    let import: Fmi2Import = fmi::import::from_path(fmu("tailsitter_plant")).expect("load FMU");
    let (speed, trim_thrust, trim_alpha, airspeed) = (
        vr(&import, "initial_speed"),
        vr(&import, "trim_thrust"),
        vr(&import, "trim_alpha"),
        vr(&import, "airspeed"),
    );
    let condition = vr(&import, "initial_condition");
    let mut inst = import.instantiate_cs("plant", false, false).expect("instantiate");
    Common::setup_experiment(&mut inst, None, 0.0, None).unwrap();
    Common::enter_initialization_mode(&mut inst).unwrap();
    Common::set_integer(&mut inst, &[condition], &[1]).unwrap();
    Common::set_real(&mut inst, &[speed], &[25.0]).unwrap();
    Common::exit_initialization_mode(&mut inst).unwrap();
    let alpha = get(&mut inst, trim_alpha).to_degrees();
    assert!((4.0..10.0).contains(&alpha), "level trim alpha {alpha} deg");
    let thrust = get(&mut inst, trim_thrust);
    assert!((5.0..40.0).contains(&thrust), "level trim thrust {thrust} N");
    assert!((get(&mut inst, airspeed) - 25.0).abs() < 1e-9);
}
