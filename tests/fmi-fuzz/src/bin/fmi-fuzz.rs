//! Long-run driver (see scripts/hardening.sh):
//!
//! - `fmi-fuzz fuzz [--seconds N] [--seed S] [--sequences N] [--calls N] [--max-calls N]
//!   [--coverage] [--progress FILE]`: the call-sequence fuzzer over every required FMU until
//!   the time, sequence or total-call (`--calls`) budget is spent (`--max-calls`: calls per
//!   sequence); before each sequence, FILE (default
//!   `target/fmi-fuzz-progress.txt`) is overwritten with its index and seed-state, and a
//!   fatal signal (abort, crash) prints them to stderr;
//! - `fmi-fuzz fuzz --replay 0xSTATE [--max-calls N]` (a seed-state as logged) or
//!   `fmi-fuzz fuzz --replay INDEX [--seed S] [--max-calls N]` (a decimal sequence index of
//!   seed S): that one sequence alone, printing every call, status and log message;
//! - `fmi-fuzz cycles [--n N]`: instantiate → simulate → get/serialize/deserialize/set state →
//!   free, N times per FMU (the valgrind memcheck driver);
//! - `fmi-fuzz rss [--n N] [--full]`: RSS before/after N instantiate/state/free cycles per FMU
//!   (`--full`: with initialisation and a step).
//!
//! `TAILSITTER_FMUS=a,b` narrows the FMUs; exit code 1 on any violation.

use fmi_fuzz::fuzz::{sequence_state, Config, Fuzzer};
use fmi_fuzz::{cycle, light_cycle, load_required, rss_kib, workspace_root};
use std::time::{Duration, Instant};

fn arg<T: std::str::FromStr>(args: &[String], name: &str, default: T) -> T {
    args.iter()
        .position(|a| a == name)
        .and_then(|i| args.get(i + 1))
        .map(|v| v.parse().unwrap_or_else(|_| panic!("bad value for {name}: {v}")))
        .unwrap_or(default)
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let fmus = load_required();
    let ids: Vec<&str> = fmus.iter().map(|f| f.id.as_str()).collect();
    match args.first().map(String::as_str) {
        Some("fuzz") => {
            let seconds: u64 = arg(&args, "--seconds", 60);
            let seed: u64 = arg(&args, "--seed", 0x5eed);
            let sequences: u64 = arg(&args, "--sequences", u64::MAX);
            let max_calls = arg(&args, "--max-calls", 60);
            if let Some(r) = args.iter().position(|a| a == "--replay").and_then(|i| args.get(i + 1)) {
                let (index, state) = match r.strip_prefix("0x") {
                    Some(hex) => (0, u64::from_str_radix(hex, 16).expect("--replay 0x<seed-state in hex>")),
                    None => {
                        let index: u64 = r.parse().expect("--replay <sequence index> or 0x<seed-state>");
                        (index, sequence_state(seed, index))
                    }
                };
                let report = Fuzzer::new(&fmus, seed).replay(index, state, max_calls);
                report.print();
                std::process::exit(i32::from(report.violations > 0));
            }
            let progress = args
                .iter()
                .position(|a| a == "--progress")
                .and_then(|i| args.get(i + 1))
                .map_or_else(|| workspace_root().join("target/fmi-fuzz-progress.txt"), Into::into);
            let cfg = Config {
                seed,
                sequences,
                max_total_calls: arg(&args, "--calls", u64::MAX),
                deadline: Some(Instant::now() + Duration::from_secs(seconds)),
                max_calls,
                per_fmu_cap: Default::default(),
                progress_file: Some(progress),
            };
            let t0 = Instant::now();
            let report = Fuzzer::new(&fmus, seed).run(&cfg);
            let secs = t0.elapsed().as_secs_f64();
            println!(
                "FMUs {ids:?}, seed {seed:#x}, {secs:.1} s, {} FMI calls ({:.0} calls/s)",
                report.calls,
                report.calls as f64 / secs.max(1e-9)
            );
            if args.iter().any(|a| a == "--coverage") {
                report.print_coverage();
            }
            report.print_coverage_summary();
            report.print();
            std::process::exit(i32::from(report.violations > 0));
        }
        Some("cycles") => {
            let n: usize = arg(&args, "--n", 20);
            let mut failures = 0;
            for fmu in &fmus {
                // Panics (with the FMU's reason) if the library refuses the declared GUID.
                drop(fmu.instance("probe", false));
                let failed = (0..n).filter(|_| !cycle(fmu, 50)).count();
                println!(
                    "{}: {n} cycles of instantiate → 50 steps → state/serialize → free: {failed} failed",
                    fmu.id
                );
                failures += failed;
            }
            println!("failures: {failures}");
            std::process::exit(i32::from(failures > 0));
        }
        Some("rss") => {
            let n: usize = arg(&args, "--n", 10_000);
            let full = args.iter().any(|a| a == "--full");
            for fmu in &fmus {
                let run = |f: &fmi_fuzz::Fmu| if full { cycle(f, 1) } else { light_cycle(f) };
                for _ in 0..200 {
                    run(fmu);
                }
                let before = rss_kib();
                let t0 = Instant::now();
                for i in 0..n {
                    assert!(run(fmu), "{}: cycle {i} failed", fmu.id);
                }
                let after = rss_kib();
                println!(
                    "{}: RSS {before} KiB → {after} KiB after {n} {} cycles ({:+} KiB, {:.1} s)",
                    fmu.id,
                    if full {
                        "full (init + step)"
                    } else {
                        "instantiate/state/free"
                    },
                    after as i64 - before as i64,
                    t0.elapsed().as_secs_f64()
                );
            }
        }
        _ => {
            eprintln!(
                "usage: fmi-fuzz fuzz [--seconds N] [--seed S] [--sequences N] [--calls N] [--max-calls N] [--coverage] [--progress FILE]"
            );
            eprintln!("       fmi-fuzz fuzz --replay 0xSEED_STATE|INDEX [--seed S] [--max-calls N]");
            eprintln!("       fmi-fuzz cycles [--n N]");
            eprintln!("       fmi-fuzz rss [--n N] [--full]");
            std::process::exit(2);
        }
    }
}
