//! `fmi2DoStep` of the sensor FMU over a 20 ms communication step at the default
//! rates (accelerometers at the thesis's 1 kHz, gyro 200 Hz, magnetometer and pitot
//! 50 Hz, GPS 4 Hz), and with the accelerometers at 200 Hz, called through the same
//! generic C-ABI functions the exported symbols use.

use criterion::{criterion_group, criterion_main, Criterion};
use fmi2_export::ffi;
use fmi2_export::fmi_sys::fmi2::*;
use std::hint::black_box;
use tailsitter_sensors::{vr, SensorsModel};

fn bench(c: &mut Criterion) {
    // The layer's shared test host (a recording logger; doStep logs nothing here).
    let host = fmi2_export::test_host::Host::new();
    for (label, accel_rate) in [("accel_200Hz", 200.0), ("default_rates", 1000.0)] {
        // SAFETY: the host outlives the instance, freed below.
        let inst = unsafe { host.initializing::<SensorsModel>("bench") };
        // SAFETY: live instance in Initialization Mode.
        unsafe {
            let rates = [accel_rate];
            let rate_vrs = [vr::accel_rate];
            assert_eq!(
                ffi::set_real::<SensorsModel>(inst, rate_vrs.as_ptr(), 1, rates.as_ptr()),
                fmi2Status_fmi2OK
            );
            assert_eq!(ffi::exit_initialization_mode::<SensorsModel>(inst), fmi2Status_fmi2OK);
            // A level flight at 25 m/s, rolling slowly: every channel non-trivial.
            let vrs = [vr::airspeed, vr::vel_n, vr::p, vr::alpha];
            let values = [25.0, 25.0, 0.1, 0.1];
            assert_eq!(
                ffi::set_real::<SensorsModel>(inst, vrs.as_ptr(), 4, values.as_ptr()),
                fmi2Status_fmi2OK
            );
        }
        let mut t = 0.0;
        let h = 0.02;
        c.bench_function(&format!("sensors_fmi2DoStep_20ms_{label}"), |b| {
            b.iter(|| {
                // SAFETY: live instance in StepComplete.
                let status = unsafe { ffi::do_step::<SensorsModel>(inst, black_box(t), h, 1) };
                assert_eq!(status, fmi2Status_fmi2OK);
                t += h;
            })
        });
        // SAFETY: live instance, freed once.
        unsafe { ffi::free_instance::<SensorsModel>(inst) };
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(50);
    targets = bench
}
criterion_main!(benches);
