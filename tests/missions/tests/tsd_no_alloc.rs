//! `update` must not allocate (static nalgebra types only): count heap allocations
//! made while the controller flies the recorded measurements of a closed-loop run,
//! and time one update.

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

use closed_loop::{fly, Scenario};
use flight_mission::{ControllerInput, MissionParams, SampledUnit};
use tailsitter_physics::{Airframe, Plant};
use tsd_control::TsdController;

struct Counting;

static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
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

#[test]
fn update_does_not_allocate_and_is_cheap() {
    let mission = MissionParams::default();
    let plant = Plant::new(Airframe::default());
    let x0 = plant.trim_vertical_climb(mission.v_vertical).unwrap().state;
    let mut ctl = TsdController::with_mission(mission).unwrap();
    let trace = fly(&plant, x0, &mut ctl, &Scenario::mission(mission));
    assert!(trace.completed());
    let inputs: Vec<ControllerInput> = trace
        .samples
        .iter()
        .map(|s| ControllerInput {
            t: s.t,
            measurement: s.measurement,
            ref_offset_ned: Default::default(),
        })
        .collect();

    let mut ctl = TsdController::with_mission(mission).unwrap();
    let before = ALLOCATIONS.load(Ordering::Relaxed);
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
    let after = ALLOCATIONS.load(Ordering::Relaxed);
    let n = (REPEAT * inputs.len()) as f64;
    println!(
        "TSD update: {:.2} µs per call ({} calls, checksum {sink:.1}), {} allocations",
        elapsed.as_secs_f64() * 1e6 / n,
        n,
        after - before
    );
    assert_eq!(after, before, "update allocated");
}
