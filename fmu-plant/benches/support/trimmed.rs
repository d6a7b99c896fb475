//! The plant FMU in trimmed flight through the generic C-ABI functions, shared by the
//! `do_step` bench and the `do_step_workload` example (one set-up, so the two measure the
//! same workload).

use fmi2_export::ffi;
use fmi2_export::fmi_sys::fmi2::*;
use fmi2_export::test_host::Host;
use fmi2_export::{Causality, ValueType, VariableStore};
use tailsitter_plant::{vr, PlantModel, Variables};

/// Value references of every real output (what a master reads each step).
pub fn real_outputs() -> Vec<u32> {
    Variables::VARIABLES
        .iter()
        .filter(|s| s.causality == Causality::Output && s.value_type == ValueType::Real)
        .map(|s| s.value_reference)
        .collect()
}

/// An instance in Step Mode at the plant's own trim (FMU defaults: global aerodynamics +
/// ground) for `initial_condition` (0 vertical climb, 1 level flight) at `speed` (m/s),
/// with the trim's thrust and elevator set as the commands, so that it holds the trim.
///
/// # Safety
/// `host` must outlive the instance; the caller frees it with `ffi::free_instance`.
pub unsafe fn trimmed_instance(host: &Host, name: &str, initial_condition: i32, speed: f64) -> fmi2Component {
    // SAFETY: the caller keeps `host` alive; every call on the live instance in the state it needs.
    unsafe {
        let inst = host.initializing::<PlantModel>(name);
        let ic = [initial_condition];
        assert_eq!(
            ffi::set_integer::<PlantModel>(inst, &vr::initial_condition, 1, ic.as_ptr()),
            fmi2Status_fmi2OK
        );
        assert_eq!(
            ffi::set_real::<PlantModel>(inst, &vr::initial_speed, 1, &speed),
            fmi2Status_fmi2OK
        );
        assert_eq!(ffi::exit_initialization_mode::<PlantModel>(inst), fmi2Status_fmi2OK);
        let mut trim = [0.0; 2];
        let trim_vrs = [vr::trim_thrust, vr::trim_elevator];
        assert_eq!(
            ffi::get_real::<PlantModel>(inst, trim_vrs.as_ptr(), 2, trim.as_mut_ptr()),
            fmi2Status_fmi2OK
        );
        let cmd_vrs = [vr::thrust_cmd, vr::elevator_cmd];
        assert_eq!(
            ffi::set_real::<PlantModel>(inst, cmd_vrs.as_ptr(), 2, trim.as_ptr()),
            fmi2Status_fmi2OK
        );
        inst
    }
}
