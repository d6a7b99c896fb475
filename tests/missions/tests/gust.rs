//! Issue 16: 1 − cos gusts of 5 m/s over 2 s along each earth axis, centred on the middle of a
//! phase of the default mission, on the global aerodynamic model (the cases of
//! `analysis::envelope_hover`). The tuned LQR must ride them out: complete, stay above the
//! ground and add less than 2 m (the criterion) to the largest position error of the
//! same flight in still air over the gust and the 8 s after it.

use closed_loop::{fly, Ordering, Scenario, Trace, Wind};
use flight_mission::MissionParams;
use lqr_control::{LqrController, LqrParams};
use tailsitter_physics::{AeroModel, Airframe, Ground, Plant};

/// Gust peak (m/s), duration (s), window after the gust (s), allowed added error (m).
const AMPLITUDE: f64 = 5.0;
const DURATION: f64 = 2.0;
const AFTER: f64 = 8.0;
const ADDED: f64 = 2.0;

fn plant() -> Plant {
    let mut p = Plant::new(Airframe::default());
    p.aero.model = AeroModel::Global;
    p.ground = Ground::default();
    p
}

fn flight(gust: Option<(usize, f64)>, ordering: Ordering) -> Trace {
    let p = plant();
    let m = MissionParams::default();
    let mut s = Scenario::mission(m);
    s.stop_time = m.end_time() + 5.0;
    s.ordering = ordering;
    if let Some((axis, t0)) = gust {
        s.wind = Wind::gust_along(axis, AMPLITUDE, t0, DURATION);
    }
    let mut c = LqrController::new(Airframe::default(), m, LqrParams::default()).unwrap();
    let x0 = p.trim_vertical_climb(m.v_vertical).unwrap().state;
    fly(&p, x0, &mut c, &s)
}

fn window_max(trace: &Trace, t0: f64) -> f64 {
    trace
        .window(t0, t0 + DURATION + AFTER)
        .map(|s| s.pos_error())
        .fold(0.0, f64::max)
}

/// (added error, lowest height above the start (m)) of a gust along `axis` in `phase`.
fn ride(axis: usize, phase: usize, calm: &Trace, ordering: Ordering) -> (f64, f64) {
    let starts = MissionParams::default().phase_starts();
    let t0 = 0.5 * (starts[phase] + starts[phase + 1]) - 0.5 * DURATION;
    let trace = flight(Some((axis, t0)), ordering);
    assert!(trace.completed(), "axis {axis} phase {phase}: {:?}", trace.failure);
    let lowest = trace
        .samples
        .iter()
        .map(|s| -s.measurement.pos_ned.z)
        .fold(f64::INFINITY, f64::min);
    (window_max(&trace, t0) - window_max(calm, t0), lowest)
}

/// The cases the mission-airspeed reference failed (3.5 m ahead in a level-flight tailwind,
/// 3.9 m low in a level-flight down gust, 3.8 m aside across the path, 2.1 m added by a
/// hover gust into the belly at α 42°, 3.0–3.6 m in the last vertical phase): ridden out now.
#[test]
fn tuned_lqr_rides_out_5_m_s_gusts() {
    let calm = flight(None, Ordering::GaussSeidel);
    assert!(calm.completed());
    let ground_below = -Ground::default().height;
    for (axis, phase) in [(0, 0), (0, 1), (1, 1), (0, 2), (1, 2), (2, 2), (0, 4), (1, 4)] {
        let (added, lowest) = ride(axis, phase, &calm, Ordering::GaussSeidel);
        assert!(added < ADDED, "axis {axis} phase {phase}: adds {added:.2} m");
        assert!(
            lowest > ground_below + 1.0,
            "axis {axis} phase {phase}: down to {lowest:.2} m"
        );
    }
}

/// The three cases the untrimmed reference failed (README, "Gusts", wind trim): the tailwind
/// gust in the back transition's pull-up (added 2.07 m Gauss-Seidel, 2.10 m Jacobi: the
/// reference held the still-air pitch and thrust while the tailwind took a quarter of the
/// dynamic pressure, so the aircraft sank outside the curve and fell 2 m behind in the
/// climb) and, under Jacobi, the east gust in vertical flight 2 (2.15 m: gains linearised at
/// the measured β of −66°). Each must add less than the criterion over its own ordering's
/// still-air flight.
#[test]
fn tuned_lqr_rides_out_back_transition_tailwind_and_vertical_2_crosswind() {
    for (ordering, cases) in [
        (Ordering::GaussSeidel, &[(0, 3)][..]),
        (Ordering::Jacobi, &[(0, 3), (1, 4)][..]),
    ] {
        let calm = flight(None, ordering);
        assert!(calm.completed());
        for &(axis, phase) in cases {
            let (added, _) = ride(axis, phase, &calm, ordering);
            assert!(
                added < ADDED,
                "{ordering:?} axis {axis} phase {phase}: adds {added:.2} m"
            );
        }
    }
}
