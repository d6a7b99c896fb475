//! `sample` must not allocate (statically sized nalgebra types only, the stages' values on
//! the stack): count the heap allocations made while a fresh controller flies the recorded
//! measurements of closed-loop runs (the default mission and the violent manoeuvre, with
//! relinearisations, Euler switches, warm starts and saturations).

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

use closed_loop::{fly, Scenario};
use flight_mission::{ControllerInput, SampledUnit};
use lqr_control::{LqrController, LqrParams};
use tailsitter_physics::{Airframe, Plant};

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
fn sample_does_not_allocate() {
    for s in [Scenario::mission(Default::default()), Scenario::violent_manoeuvre()] {
        let plant = Plant::new(Airframe::default());
        let x0 = plant.trim_vertical_climb(s.mission.v_vertical).unwrap().state;
        let new = || LqrController::new(Airframe::default(), s.mission, LqrParams::default()).unwrap();
        let mut c = new();
        let trace = fly(&plant, x0, &mut c, &s);
        assert!(trace.failure.is_none(), "{:?}", trace.failure);
        let inputs: Vec<ControllerInput> = trace
            .samples
            .iter()
            .map(|x| ControllerInput {
                t: x.t,
                measurement: x.measurement,
                ref_offset_ned: s.ref_offset(x.t),
            })
            .collect();
        let mut c = new();
        let before = ALLOCATIONS.load(Ordering::Relaxed);
        let mut sink = 0.0;
        for input in &inputs {
            sink += c.sample(input).unwrap().command.thrust;
        }
        let allocations = ALLOCATIONS.load(Ordering::Relaxed) - before;
        assert!(sink.is_finite());
        assert!(c.stats().solves > 100);
        assert_eq!(allocations, 0, "{allocations} allocations in {} samples", inputs.len());
    }
}
