//! fmi2DoStep (and a Real get/set) must not allocate on the success path:
//! counted with a per-thread counting global allocator.

mod common;

use common::{cstring, vr, Host, Toy, TOY_GUID};
use fmi2_export::fmi_sys::fmi2::*;
use fmi2_export::testing::{allocations, CountingAllocator};
use std::ptr::null;

fmi2_export::export_fmu!(Toy);

#[global_allocator]
static GLOBAL: CountingAllocator = CountingAllocator;

#[test]
fn do_step_does_not_allocate() {
    let host = Host::new();
    let name = cstring("toy");
    let guid = cstring(TOY_GUID);
    unsafe {
        let c = fmi2Instantiate(
            name.as_ptr(),
            fmi2Type_fmi2CoSimulation,
            guid.as_ptr(),
            null(),
            &*host.callbacks,
            0,
            0,
        );
        assert!(!c.is_null());
        assert_eq!(fmi2EnterInitializationMode(c), fmi2Status_fmi2OK);
        assert_eq!(fmi2ExitInitializationMode(c), fmi2Status_fmi2OK);
        let before = allocations();
        let mut y = 0.0;
        for k in 0..1000 {
            let u = (k as f64 * 0.01).sin();
            assert_eq!(fmi2SetReal(c, &vr::U, 1, &u), fmi2Status_fmi2OK);
            assert_eq!(fmi2DoStep(c, k as f64 * 0.01, 0.01, 1), fmi2Status_fmi2OK);
            assert_eq!(fmi2GetReal(c, &vr::Y, 1, &mut y), fmi2Status_fmi2OK);
        }
        assert_eq!(allocations() - before, 0, "allocations on the step path");
        // The counter works: a failing call (which logs) does allocate.
        let before = allocations();
        assert_eq!(fmi2DoStep(c, 0.0, 0.01, 1), fmi2Status_fmi2Error);
        assert!(allocations() > before);
        fmi2FreeInstance(c);
    }
}
