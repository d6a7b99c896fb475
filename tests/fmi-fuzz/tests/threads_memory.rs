//! Threads and memory through the real C ABI (target/x86_64-unknown-linux-gnu/release libraries):
//! 64 instances stepped concurrently give bit-identical results to sequential
//! runs, and 10 000 instantiate/state/free cycles (plus full life cycles with
//! initialisation and a step) do not grow the resident set (numbers printed; run with --nocapture).

use fmi_fuzz::model_description_types::VarType;
use fmi_fuzz::{cycle, light_cycle, load_required, rss_kib, Fmu, Var, OK};
use std::sync::{Barrier, Mutex};

/// The tests of this file run one at a time: RSS is per process, and the
/// 64-thread test's stacks and malloc arenas would blur the RSS measurements.
static SERIAL: Mutex<()> = Mutex::new(());

fn serial() -> std::sync::MutexGuard<'static, ()> {
    SERIAL.lock().unwrap_or_else(|e| e.into_inner())
}

/// Instance `i`: Real inputs nudged by an amount depending on `i`, then `steps`
/// steps; returns the bit patterns of every value after each step.
fn run(fmu: &Fmu, i: usize, steps: usize, barrier: Option<&Barrier>) -> Vec<u64> {
    let mut inst = fmu.instance(&format!("t{i}"), false);
    inst.initialize();
    let inputs: Vec<&Var> = fmu
        .vars_of(VarType::Real)
        .filter(|v| v.causality == fmi_fuzz::model_description_types::Causality::Input && v.start.is_some())
        .collect();
    let vrs: Vec<u32> = inputs.iter().map(|v| v.vr).collect();
    let values: Vec<f64> = inputs
        .iter()
        .enumerate()
        .map(|(k, v)| {
            let x0 = v.start.unwrap_or(0.0);
            (x0 + 1e-3 * ((i * 7 + k) % 13) as f64 * x0.abs().max(1.0)).clamp(v.min, v.max)
        })
        .collect();
    assert_eq!(inst.set_reals(&vrs, &values), OK, "{}: set inputs", fmu.id);
    if let Some(b) = barrier {
        b.wait();
    }
    let h = fmu.default_step;
    let mut out = Vec::new();
    for k in 0..steps {
        out.push(u64::from(inst.step(k as f64 * h, h)));
        out.extend(inst.snapshot_bits().1);
    }
    out
}

#[test]
fn sixty_four_concurrent_instances_match_sequential_runs() {
    let _serial = serial();
    const N: usize = 64;
    const STEPS: usize = 100;
    for fmu in &load_required() {
        let sequential: Vec<Vec<u64>> = (0..N).map(|i| run(fmu, i, STEPS, None)).collect();
        let barrier = Barrier::new(N);
        let concurrent: Vec<Vec<u64>> = std::thread::scope(|s| {
            let handles: Vec<_> = (0..N)
                .map(|i| {
                    s.spawn({
                        let b = &barrier;
                        move || run(fmu, i, STEPS, Some(b))
                    })
                })
                .collect();
            handles.into_iter().map(|h| h.join().expect("thread")).collect()
        });
        let differing = (0..N).filter(|&i| sequential[i] != concurrent[i]).count();
        let distinct = sequential.iter().collect::<std::collections::BTreeSet<_>>().len();
        println!(
            "{}: {N} instances × {STEPS} steps on {N} threads: {differing} differ from the sequential runs \
             ({distinct} distinct trajectories, {} values compared)",
            fmu.id,
            N * sequential[0].len()
        );
        assert_eq!(
            differing, 0,
            "{}: concurrent results differ from sequential ones",
            fmu.id
        );
        assert!(distinct > 1, "{}: the inputs did not make the instances differ", fmu.id);
    }
}

/// Run `n` cycles of `what` on `fmu` (after up to 200 warm-up cycles): the resident set
/// must not grow by 4 MiB (10 000 cycles leaking even 400 bytes each would add ~4 MiB).
fn assert_rss_flat(fmu: &Fmu, what: &str, n: usize, cycle: impl Fn(&Fmu) -> bool) {
    for _ in 0..n.min(200) {
        assert!(cycle(fmu));
    }
    let before = rss_kib();
    let mut mid = 0;
    for i in 0..n {
        assert!(cycle(fmu), "{}: cycle {i} failed", fmu.id);
        if i == n / 2 {
            mid = rss_kib();
        }
    }
    let after = rss_kib();
    println!(
        "{}: {what}: RSS {before} KiB → {mid} KiB → {after} KiB over {n} cycles ({:+} KiB)",
        fmu.id,
        after as i64 - before as i64
    );
    assert!(
        after < before + 4096,
        "{}: RSS grew from {before} KiB to {after} KiB",
        fmu.id
    );
}

#[test]
fn ten_thousand_instantiate_free_cycles_do_not_grow_the_resident_set() {
    let _serial = serial();
    const CYCLES: usize = 10_000;
    for fmu in &load_required() {
        assert_rss_flat(fmu, "instantiate/setup/state/serialize/free", CYCLES, light_cycle);
    }
}

#[test]
fn full_life_cycles_do_not_grow_the_resident_set() {
    let _serial = serial();
    // With initialisation and a step; fewer for the LQR FMU (~40 ms per initialisation).
    for fmu in &load_required() {
        let n = if fmu.id == "tailsitter_lqr" { 300 } else { 5_000 };
        assert_rss_flat(fmu, "full life cycle", n, |f| cycle(f, 1));
    }
}
