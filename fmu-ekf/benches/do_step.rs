//! `fmi2DoStep` of the estimator FMU over a 20 ms communication step, called through the
//! same generic C-ABI functions the exported symbols use (state checks, argument checks,
//! lazy outputs included), with a new GPS fix every 250 ms and the magnetometer, pitot and
//! sideslip updates every step. Issue bar: ≤ 50 µs per step.

use criterion::{criterion_group, criterion_main, Criterion};
use fmi2_export::ffi;
use fmi2_export::fmi_sys::fmi2::*;
use std::hint::black_box;
use tailsitter_ekf::{vr, EkfModel};

fn bench(c: &mut Criterion) {
    // The layer's shared test host (a recording logger; doStep logs nothing here).
    let host = fmi2_export::test_host::Host::new();
    // SAFETY: the host outlives the instance, freed below.
    let inst = unsafe { host.initializing::<EkfModel>("bench") };
    // SAFETY: live instance in Initialization Mode.
    unsafe {
        assert_eq!(ffi::exit_initialization_mode::<EkfModel>(inst), fmi2Status_fmi2OK);
    }
    let mut t = 0.0;
    let mut k = 0i32;
    let h = 0.02;
    c.bench_function("fmi2DoStep_20ms_ekf", |b| {
        b.iter(|| {
            // SAFETY: live instance in StepComplete.
            unsafe {
                if k % 12 == 0 {
                    let fix = k / 12 + 1;
                    assert_eq!(
                        ffi::set_integer::<EkfModel>(inst, &vr::gps_fix_count, 1, &fix),
                        fmi2Status_fmi2OK
                    );
                }
                let gyro = 1e-3 * ((k % 7) as f64 - 3.0);
                assert_eq!(
                    ffi::set_real::<EkfModel>(inst, &vr::imu_gyro_q, 1, &gyro),
                    fmi2Status_fmi2OK
                );
                let status = ffi::do_step::<EkfModel>(inst, black_box(t), h, 1);
                assert_eq!(status, fmi2Status_fmi2OK);
            }
            t += h;
            k += 1;
        })
    });
    // SAFETY: live instance, freed once.
    unsafe { ffi::free_instance::<EkfModel>(inst) };
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(50);
    targets = bench
}
criterion_main!(benches);
