//! The controllers' `sample` must not allocate (statically sized nalgebra types only, the
//! stages' values on the stack): count the heap allocations of this thread made while a
//! fresh controller flies the recorded measurements of closed-loop runs. The count is per
//! thread, so the tests of this file may run in parallel.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

use closed_loop::{fly, Scenario};
use flight_mission::{MissionParams, SampledUnit};
use lqr_control::{LqrController, LqrParams};
use tailsitter_physics::{Airframe, Plant};
use tsd_control::TsdController;

#[path = "support/replay.rs"]
mod replay;
use replay::recorded_inputs;

struct Counting;

thread_local! {
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

fn allocations() -> usize {
    ALLOCATIONS.with(Cell::get)
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        // A const-initialised Cell: no allocation and no destructor; `try_with` because a
        // thread may still allocate while its locals are being torn down.
        let _ = ALLOCATIONS.try_with(|n| n.set(n.get() + 1));
        // SAFETY: forwarded unchanged to the system allocator.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: forwarded unchanged to the system allocator.
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// The LQR over the default mission and the violent manoeuvre (relinearisations, Euler
/// switches, warm starts and saturations).
#[test]
fn lqr_sample_does_not_allocate() {
    for s in [Scenario::mission(Default::default()), Scenario::violent_manoeuvre()] {
        let plant = Plant::new(Airframe::default());
        let x0 = plant.trim_vertical_climb(s.mission.v_vertical).unwrap().state;
        let new = || LqrController::new(Airframe::default(), s.mission, LqrParams::default()).unwrap();
        let mut c = new();
        let trace = fly(&plant, x0, &mut c, &s);
        assert!(trace.failure.is_none(), "{:?}", trace.failure);
        let inputs = recorded_inputs(&trace, &s);
        let mut c = new();
        let before = allocations();
        let mut sink = 0.0;
        for input in &inputs {
            sink += c.sample(input).unwrap().command.thrust;
        }
        let allocations = allocations() - before;
        assert!(sink.is_finite());
        assert!(c.stats().solves > 100);
        assert_eq!(allocations, 0, "{allocations} allocations in {} samples", inputs.len());
    }
}

/// The TSD over the default mission, 20 times (reset between), timed.
#[test]
fn tsd_update_does_not_allocate_and_is_cheap() {
    let mission = MissionParams::default();
    let plant = Plant::new(Airframe::default());
    let x0 = plant.trim_vertical_climb(mission.v_vertical).unwrap().state;
    let mut ctl = TsdController::with_mission(mission).unwrap();
    let scenario = Scenario::mission(mission);
    let trace = fly(&plant, x0, &mut ctl, &scenario);
    assert!(trace.completed());
    let inputs = recorded_inputs(&trace, &scenario);

    let mut ctl = TsdController::with_mission(mission).unwrap();
    let before = allocations();
    let start = std::time::Instant::now();
    let mut sink = 0.0;
    const REPEAT: usize = 20;
    for _ in 0..REPEAT {
        ctl.reset();
        for input in &inputs {
            sink += ctl.sample(input).unwrap().command.thrust;
        }
    }
    let elapsed = start.elapsed();
    let after = allocations();
    let n = (REPEAT * inputs.len()) as f64;
    println!(
        "TSD update: {:.2} µs per call ({} calls, checksum {sink:.1}), {} allocations",
        elapsed.as_secs_f64() * 1e6 / n,
        n,
        after - before
    );
    assert_eq!(after, before, "update allocated");
}
