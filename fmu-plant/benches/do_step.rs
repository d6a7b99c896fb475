//! `fmi2DoStep` of the plant FMU over a 20 ms communication step, called
//! through the same generic C-ABI functions the exported symbols use
//! (state checks, argument checks, lazy outputs included), alone and followed by the
//! fmi2GetReal of every output a master makes each step (the outputs are computed on that
//! read). Issue bar:
//! ≤ 20 µs per step (≥ 1000× real time); goal ≤ 5 µs (thesis aerodynamics), ≤ 10 µs with the
//! default global model (issue 13).
//!
//! Two groups: wall-clock time (criterion's default) and the CPU time of the benchmarking
//! thread (`cpu/…`), the robust figure on a shared machine (it excludes the time the thread
//! waits for a core).

use criterion::measurement::{Measurement, ValueFormatter};
use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use fmi2_export::ffi;
use fmi2_export::fmi_sys::fmi2::*;
use std::hint::black_box;
use tailsitter_plant::PlantModel;

#[path = "support/trimmed.rs"]
mod trimmed;

/// CPU time of the calling thread (`CLOCK_THREAD_CPUTIME_ID`), in ns.
struct ThreadCpuTime;

fn thread_cpu_ns() -> u64 {
    let mut ts = libc::timespec { tv_sec: 0, tv_nsec: 0 };
    // SAFETY: `ts` is a valid, writable timespec; CLOCK_THREAD_CPUTIME_ID is always available on Linux.
    unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    ts.tv_sec as u64 * 1_000_000_000 + ts.tv_nsec as u64
}

impl Measurement for ThreadCpuTime {
    type Intermediate = u64;
    type Value = u64;
    fn start(&self) -> u64 {
        thread_cpu_ns()
    }
    fn end(&self, start: u64) -> u64 {
        thread_cpu_ns() - start
    }
    fn add(&self, a: &u64, b: &u64) -> u64 {
        a + b
    }
    fn zero(&self) -> u64 {
        0
    }
    fn to_f64(&self, v: &u64) -> f64 {
        *v as f64
    }
    fn formatter(&self) -> &dyn ValueFormatter {
        &CpuFormatter
    }
}

/// Nanoseconds shown in µs.
struct CpuFormatter;

impl ValueFormatter for CpuFormatter {
    fn scale_values(&self, _typical: f64, values: &mut [f64]) -> &'static str {
        for v in values.iter_mut() {
            *v *= 1e-3;
        }
        "µs (CPU)"
    }
    fn scale_throughputs(&self, _typical: f64, _throughput: &Throughput, values: &mut [f64]) -> &'static str {
        for v in values.iter_mut() {
            *v *= 1e-3;
        }
        "µs (CPU)"
    }
    fn scale_for_machines(&self, _values: &mut [f64]) -> &'static str {
        "ns"
    }
}

fn wall(c: &mut Criterion) {
    bench(c, "");
}

fn cpu(c: &mut Criterion<ThreadCpuTime>) {
    bench(c, "cpu/");
}

fn bench<M: Measurement + 'static>(c: &mut Criterion<M>, prefix: &str) {
    // The layer's shared test host (a recording logger; doStep logs nothing here).
    let host = fmi2_export::test_host::Host::new();
    let outputs = trimmed::real_outputs();
    let mut values = vec![0.0; outputs.len()];
    // One fresh instance per benchmark (and per 10,000 s of flight, below).
    for (label, initial_condition, speed) in [("level_25", 1, 25.0), ("vertical_3", 0, 3.0)] {
        // Alone, then followed by what a co-simulation master does each step: every output
        // read (the outputs are computed lazily, on that read).
        for (kind, get) in [("fmi2DoStep", false), ("fmi2DoStep_getReal", true)] {
            // SAFETY: the host outlives the instance, freed below.
            let mut inst = unsafe { trimmed::trimmed_instance(&host, "bench", initial_condition, speed) };
            let mut t = 0.0;
            let h = 0.02;
            c.bench_function(&format!("{prefix}{kind}_20ms_{label}"), |b| {
                b.iter(|| {
                    // A fresh instance every 10,000 s of flight (250 km level): a fast step
                    // flies millions of steps per run, and the position envelope (1e6 m)
                    // must not be reached. Once per 500,000 steps: nothing in the median.
                    if t >= 10_000.0 {
                        // SAFETY: live instance freed once; the host outlives the new one.
                        unsafe {
                            ffi::free_instance::<PlantModel>(inst);
                            inst = trimmed::trimmed_instance(&host, "bench", initial_condition, speed);
                        }
                        t = 0.0;
                    }
                    // SAFETY: live instance in StepComplete; `values` as long as `outputs`.
                    unsafe {
                        let status = ffi::do_step::<PlantModel>(inst, black_box(t), h, 1);
                        assert_eq!(status, fmi2Status_fmi2OK);
                        if get {
                            let status =
                                ffi::get_real::<PlantModel>(inst, outputs.as_ptr(), outputs.len(), values.as_mut_ptr());
                            assert_eq!(status, fmi2Status_fmi2OK);
                        }
                    }
                    black_box(&values);
                    t += h;
                })
            });
            // SAFETY: live instance, freed once.
            unsafe { ffi::free_instance::<PlantModel>(inst) };
        }
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(50);
    targets = wall
}
criterion_group! {
    name = benches_cpu;
    config = Criterion::default().with_measurement(ThreadCpuTime).sample_size(50);
    targets = cpu
}
criterion_main!(benches, benches_cpu);
