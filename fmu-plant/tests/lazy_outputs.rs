//! Outputs are computed lazily after fmi2DoStep (`LAZY_STEP_OUTPUTS`, issue 17): a get
//! after any number of steps reads the outputs of the current state, whether or not the
//! steps in between were read, and a set after the step (the wind) is seen by the get.

use fmi2_export::ffi;
use fmi2_export::fmi_sys::fmi2::*;
use fmi2_export::{Causality, ValueType, VariableStore};
use tailsitter_plant::{vr, PlantModel, Variables};

fn outputs() -> Vec<u32> {
    Variables::VARIABLES
        .iter()
        .filter(|s| s.causality == Causality::Output && s.value_type == ValueType::Real)
        .map(|s| s.value_reference)
        .collect()
}

/// `steps` steps of 20 ms in level flight with an elevator doublet, reading every output
/// after each step (`read_every_step`) or only at the end; the final outputs.
fn fly(steps: usize, read_every_step: bool) -> Vec<f64> {
    let host = fmi2_export::test_host::Host::new();
    let vrs = outputs();
    let mut y = vec![0.0; vrs.len()];
    // SAFETY: the host outlives the instance, freed below; calls in legal states.
    unsafe {
        let inst = host.initializing::<PlantModel>("lazy");
        assert_eq!(ffi::exit_initialization_mode::<PlantModel>(inst), fmi2Status_fmi2OK);
        for k in 0..steps {
            let de = if (k / 10) % 2 == 0 { 0.05 } else { -0.05 };
            assert_eq!(
                ffi::set_real::<PlantModel>(inst, &vr::elevator_cmd, 1, &de),
                fmi2Status_fmi2OK
            );
            assert_eq!(
                ffi::do_step::<PlantModel>(inst, k as f64 * 0.02, 0.02, 1),
                fmi2Status_fmi2OK
            );
            if read_every_step {
                assert_eq!(
                    ffi::get_real::<PlantModel>(inst, vrs.as_ptr(), vrs.len(), y.as_mut_ptr()),
                    fmi2Status_fmi2OK
                );
            }
        }
        assert_eq!(
            ffi::get_real::<PlantModel>(inst, vrs.as_ptr(), vrs.len(), y.as_mut_ptr()),
            fmi2Status_fmi2OK
        );
        ffi::free_instance::<PlantModel>(inst);
    }
    y
}

#[test]
fn outputs_after_steps_do_not_depend_on_reading_them() {
    let a = fly(60, true);
    let b = fly(60, false);
    assert_eq!(a, b);
    // The outputs moved with the state (not the initial trim's).
    let vrs = outputs();
    let at = |v: u32| a[vrs.iter().position(|&x| x == v).unwrap()];
    let (u, w) = (at(vr::u), at(vr::w));
    assert!(at(vr::q).abs() > 1e-3, "pitch rate {}", at(vr::q));
    // No wind: α = atan2(w, u) (2.2.12) (to the last bit: the physics uses musl's atan2)
    // and V̄ = |v| of the state read with them.
    let alpha = w.atan2(u);
    assert!((at(vr::alpha) - alpha).abs() <= 2.0 * f64::EPSILON * alpha.abs().max(1e-300));
    let speed = (u * u + at(vr::v).powi(2) + w * w).sqrt();
    assert!((at(vr::airspeed) - speed).abs() <= 1e-12 * speed);
}

#[test]
fn a_wind_set_after_the_step_is_in_the_outputs() {
    let host = fmi2_export::test_host::Host::new();
    // SAFETY: as above.
    unsafe {
        let inst = host.initializing::<PlantModel>("wind");
        assert_eq!(ffi::exit_initialization_mode::<PlantModel>(inst), fmi2Status_fmi2OK);
        assert_eq!(ffi::do_step::<PlantModel>(inst, 0.0, 0.02, 1), fmi2Status_fmi2OK);
        let vrs = [vr::airspeed, vr::vel_n];
        let mut calm = [0.0; 2];
        assert_eq!(
            ffi::get_real::<PlantModel>(inst, vrs.as_ptr(), 2, calm.as_mut_ptr()),
            fmi2Status_fmi2OK
        );
        // The default start climbs vertically; a 5 m/s horizontal wind set after the step:
        // the airspeed read next includes it (V̄² = V² + 5²), the inertial velocity does not
        // change.
        let wind_n = -5.0;
        assert_eq!(
            ffi::set_real::<PlantModel>(inst, &vr::wind_n, 1, &wind_n),
            fmi2Status_fmi2OK
        );
        let mut windy = [0.0; 2];
        assert_eq!(
            ffi::get_real::<PlantModel>(inst, vrs.as_ptr(), 2, windy.as_mut_ptr()),
            fmi2Status_fmi2OK
        );
        assert_eq!(windy[1], calm[1]);
        let expected = (calm[0] * calm[0] + 25.0).sqrt();
        assert!(
            (windy[0] - expected).abs() < 1e-6,
            "airspeed {} → {}",
            calm[0],
            windy[0]
        );
        ffi::free_instance::<PlantModel>(inst);
    }
}
