//! The native LQR mission (plant + controller through `closed-loop`, Gauss-Seidel, 20 ms):
//! writes the trajectory (t, N, E, D, full precision) as CSV for before/after comparisons
//! and prints the CPU time of one whole mission (median over `runs`).
//!
//! `cargo run --release -p missions --example mission_benchmark -- [default|violent] [out.csv|-] [runs=5] [plant integration step (s)|-] [relinearisation period T_l (s)]`
//!
//! The last argument overrides the LQR's `relinearisation_period` (default 0.2 s, the
//! thesis's T_l): e.g. `1e9` relinearises only at the start, which gives the mission's cost
//! without the periodic gain solves (docs/PERFORMANCE.md, "relinearisation period").
//!
//! After the timed runs three more, instrumented (monotonic clock around each controller
//! sample), splits the mission into construction, relinearising samples, other samples and
//! the plant with the loop; the fastest of the three is printed (the instrumentation adds
//! ≈ 2 × 25 ns per sample). With `runs` = 1 only the one mission is flown (for counting its
//! instructions: `valgrind --tool=callgrind`).
//!
//! `violent`: the fast mission (T1 = 3 s, T2 = 4 s, α up to ≈ 44°) with a 1 − cos gust of
//! 6 m/s (north, up) over 2 s at t = 12 s and 5 m position steps at 20 s and 23 s (the mission ends at 27 s).

use closed_loop::{fly, Scenario, Trace};
use flight_mission::{ControlError, ControllerInput, ControllerOutput, MissionParams, ParamError, SampledUnit};
use lqr_control::{LqrController, LqrParams};
use std::io::Write;
use std::time::{Duration, Instant};
use tailsitter_physics::{Airframe, Plant};

fn thread_cpu_time() -> f64 {
    let mut ts = libc::timespec { tv_sec: 0, tv_nsec: 0 };
    // SAFETY: `ts` is a valid, writable timespec; CLOCK_THREAD_CPUTIME_ID is always available on Linux.
    unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9
}

fn scenario(name: &str) -> Scenario {
    match name {
        "default" => Scenario::mission(MissionParams::default()),
        "violent" => Scenario::violent_manoeuvre(),
        other => panic!("unknown scenario {other} (default | violent)"),
    }
}

/// The overrides of the command line: plant integration step and LQR relinearisation period.
#[derive(Clone, Copy, Default)]
struct Setup {
    integration_step: Option<f64>,
    relinearisation_period: Option<f64>,
}

impl Setup {
    fn plant(&self) -> Plant {
        let mut plant = Plant::new(Airframe::default());
        if let Some(step) = self.integration_step {
            plant.integration_step = step;
        }
        plant
    }

    fn params(&self) -> LqrParams {
        let mut params = LqrParams::default();
        if let Some(period) = self.relinearisation_period {
            params.relinearisation_period = period;
        }
        params
    }
}

/// The flown trace, the number of gain solves (all, warm-started) and the CPU time (s) of
/// the controller's construction (reference trajectory + first gain).
fn fly_once(s: &Scenario, setup: Setup) -> (Trace, (u64, u64), f64) {
    let plant = setup.plant();
    let x0 = plant.trim_vertical_climb(s.mission.v_vertical).expect("trim").state;
    let c0 = thread_cpu_time();
    let mut c = LqrController::new(Airframe::default(), s.mission, setup.params()).expect("controller");
    let construction = thread_cpu_time() - c0;
    let trace = fly(&plant, x0, &mut c, s);
    (trace, (c.stats().solves, c.stats().warm_solves), construction)
}

/// The controller with the time spent in its samples, split by whether the sample solved
/// for new gains.
#[derive(Clone)]
struct Timed {
    controller: LqrController,
    relinearising: (Duration, u64),
    other: (Duration, u64),
}

impl SampledUnit for Timed {
    type Config = <LqrController as SampledUnit>::Config;
    type Input = ControllerInput;
    type Output = ControllerOutput;
    fn build(config: &Self::Config) -> Result<Self, ParamError> {
        Ok(Self {
            controller: LqrController::build(config)?,
            relinearising: Default::default(),
            other: Default::default(),
        })
    }
    fn sample_time(config: &Self::Config) -> f64 {
        LqrController::sample_time(config)
    }
    fn sample(&mut self, input: &ControllerInput) -> Result<ControllerOutput, ControlError> {
        let solves = self.controller.stats().solves;
        let start = Instant::now();
        let out = self.controller.sample(input);
        let spent = start.elapsed();
        let bucket = if self.controller.stats().solves != solves {
            &mut self.relinearising
        } else {
            &mut self.other
        };
        bucket.0 += spent;
        bucket.1 += 1;
        out
    }
    fn save(&self, out: &mut impl FnMut(f64)) {
        self.controller.save(out)
    }
    fn restore(&mut self, next: &mut impl FnMut() -> Option<f64>) -> Result<(), ControlError> {
        self.controller.restore(next)
    }
}

/// Where the (wall-clock) time of one instrumented mission goes: total, construction, the
/// relinearising and the other samples (time, count), the plant and the loop.
type Breakdown = (Duration, Duration, (Duration, u64), (Duration, u64), Duration);

/// One instrumented mission.
fn breakdown(s: &Scenario, setup: Setup) -> Breakdown {
    let plant = setup.plant();
    let x0 = plant.trim_vertical_climb(s.mission.v_vertical).expect("trim").state;
    let start = Instant::now();
    let controller = LqrController::new(Airframe::default(), s.mission, setup.params()).expect("controller");
    let construction = start.elapsed();
    let mut timed = Timed {
        controller,
        relinearising: Default::default(),
        other: Default::default(),
    };
    let _ = fly(&plant, x0, &mut timed, s);
    let total = start.elapsed();
    let rest = total.saturating_sub(construction + timed.relinearising.0 + timed.other.0);
    (total, construction, timed.relinearising, timed.other, rest)
}

/// Prints the fastest of three instrumented missions.
fn print_breakdown(s: &Scenario, setup: Setup) {
    let (total, construction, relinearising, other, rest) = (0..3)
        .map(|_| breakdown(s, setup))
        .min_by_key(|b| b.0)
        .expect("three runs");
    let ms = |d: Duration| d.as_secs_f64() * 1e3;
    let each = |(d, n): (Duration, u64)| d.as_secs_f64() * 1e6 / n.max(1) as f64;
    println!(
        "breakdown, fastest of three instrumented runs (wall): total {:.2} ms = construction {:.2} + {} relinearising samples {:.2} ({:.1} µs each) + {} other samples {:.2} ({:.2} µs each) + plant and loop {:.2} ms",
        ms(total),
        ms(construction),
        relinearising.1,
        ms(relinearising.0),
        each(relinearising),
        other.1,
        ms(other.0),
        each(other),
        ms(rest)
    );
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let name = args.first().map(String::as_str).unwrap_or("default");
    let out = args.get(1).cloned();
    let runs: usize = args.get(2).and_then(|a| a.parse().ok()).unwrap_or(5);
    let setup = Setup {
        integration_step: args.get(3).and_then(|a| a.parse().ok()),
        relinearisation_period: args.get(4).and_then(|a| a.parse().ok()),
    };
    let s = scenario(name);
    let mut times = Vec::new();
    let mut constructions = Vec::new();
    let mut last = None;
    for _ in 0..runs.max(1) {
        let c0 = thread_cpu_time();
        let r = fly_once(&s, setup);
        times.push((thread_cpu_time() - c0) * 1e3);
        constructions.push(r.2 * 1e3);
        last = Some(r);
    }
    let (trace, (solves, warm_solves), _) = last.expect("one run");
    times.sort_by(|a, b| a.total_cmp(b));
    constructions.sort_by(|a, b| a.total_cmp(b));
    if let Some(path) = out.filter(|p| p != "-") {
        let mut f = std::io::BufWriter::new(std::fs::File::create(&path).expect("csv"));
        writeln!(f, "t,N,E,D").expect("write");
        for smp in &trace.samples {
            writeln!(f, "{:e},{:e},{:e},{:e}", smp.t, smp.x[0], smp.x[1], smp.x[2]).expect("write");
        }
    }
    println!(
        "{name} mission: {} samples, {solves} gain solves ({warm_solves} warm-started), failure {:?}, max position error {:.4} m; CPU time per mission: median {:.2} ms (min {:.2}) over {} runs, of which the controller's construction (reference trajectory + first gain) median {:.2} ms",
        trace.samples.len(),
        trace.failure,
        trace.max_pos_error(),
        times[times.len() / 2],
        times[0],
        times.len(),
        constructions[constructions.len() / 2]
    );
    if runs > 1 {
        print_breakdown(&s, setup);
    }
}
