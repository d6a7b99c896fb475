//! `fmi2DoStep` of the plant FMU over a 20 ms communication step, called
//! through the same generic C-ABI functions the exported symbols use
//! (state checks, argument checks, lazy outputs included). Issue bar:
//! ≤ 20 µs per step (≥ 1000× real time); goal ≤ 5 µs.

use criterion::{criterion_group, criterion_main, Criterion};
use fmi2_export::ffi;
use fmi2_export::fmi_sys::fmi2::*;
use std::hint::black_box;
use tailsitter_plant::{vr, PlantModel};

fn bench(c: &mut Criterion) {
    // The layer's shared test host (a recording logger; doStep logs nothing here).
    let host = fmi2_export::test_host::Host::new();
    for (label, initial_condition, speed) in [("level_25", 1, 25.0), ("vertical_3", 0, 3.0)] {
        // SAFETY: the host outlives the instance, freed below.
        let inst = unsafe { host.initializing::<PlantModel>("bench") };
        // SAFETY: live instance in Initialization Mode.
        unsafe {
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
            // Hold the trim: set the command inputs to the trim's (trim_thrust, trim_elevator).
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
        }
        let mut t = 0.0;
        let h = 0.02;
        c.bench_function(&format!("fmi2DoStep_20ms_{label}"), |b| {
            b.iter(|| {
                // SAFETY: live instance in StepComplete.
                let status = unsafe { ffi::do_step::<PlantModel>(inst, black_box(t), h, 1) };
                assert_eq!(status, fmi2Status_fmi2OK);
                t += h;
            })
        });
        // SAFETY: live instance, freed once.
        unsafe { ffi::free_instance::<PlantModel>(inst) };
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(50);
    targets = bench
}
criterion_main!(benches);
