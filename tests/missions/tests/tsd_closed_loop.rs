//! Closed-loop acceptance of the TSD controller with the nonlinear plant
//! (tailsitter-physics) through the reference master of `closed-loop`
//! (Gauss-Seidel: the controller samples the plant outputs at t, then the plant
//! advances 20 ms). The plant starts in its trimmed 3 m/s vertical climb.
//!
//! Run with `cargo test --release -p missions --test tsd_closed_loop -- --nocapture` to see the numbers.

use closed_loop::{fly, MissionCheck, Ordering, Scenario, Trace};
use flight_mission::MissionParams;
use nalgebra::Vector3;
use tailsitter_physics::{Airframe, Plant, StateVector};
use tsd_control::TsdController;

fn plant() -> Plant {
    Plant::new(Airframe::default())
}

fn climb_trim(plant: &Plant, v: f64) -> StateVector {
    plant.trim_vertical_climb(v).expect("vertical climb trim").state
}

fn level_trim_theta(plant: &Plant, v: f64) -> f64 {
    plant.trim_level(v).expect("level trim").theta
}

fn run(mission: MissionParams, ordering: Ordering) -> (Trace, MissionCheck) {
    let plant = plant();
    let x0 = climb_trim(&plant, mission.v_vertical);
    let mut ctl = TsdController::with_mission(mission).unwrap();
    let mut scenario = Scenario::mission(mission);
    scenario.ordering = ordering;
    let trace = fly(&plant, x0, &mut ctl, &scenario);
    let check = MissionCheck::of(&trace, &mission, level_trim_theta(&plant, mission.v_level));
    (trace, check)
}

fn report(name: &str, trace: &Trace, check: &MissionCheck, mission: &MissionParams) {
    println!("=== TSD {name} ===");
    if let Some(f) = &trace.failure {
        println!("FAILED: {f}");
    }
    print!("{check}");
    println!(
        "  max alpha over the mission: {:.2} deg",
        trace.max_alpha(0.0, mission.end_time() + 1.0).to_degrees()
    );
    let min_alpha = trace
        .samples
        .iter()
        .map(|s| s.measurement.alpha)
        .fold(f64::INFINITY, f64::min);
    println!("  min alpha over the mission: {:.2} deg", min_alpha.to_degrees());
    let max_dev_d = trace
        .samples
        .iter()
        .map(|s| (s.measurement.pos_ned.z - s.diagnostics.ref_pos_ned.z).abs())
        .fold(0.0, f64::max);
    println!("  max altitude deviation: {max_dev_d:.3} m");
}

#[test]
fn default_mission_gauss_seidel() {
    let mission = MissionParams::default();
    let (trace, check) = run(mission, Ordering::GaussSeidel);
    report(
        "default mission (T1 = 5 s, T2 = 10 s), Gauss-Seidel",
        &trace,
        &check,
        &mission,
    );
    assert!(trace.completed(), "{:?}", trace.failure);
    assert!(check.passed(), "{check}");
}

#[test]
fn fast_mission_gauss_seidel() {
    let mission = MissionParams::fast();
    let (trace, check) = run(mission, Ordering::GaussSeidel);
    report(
        "fast mission (T1 = 3 s, T2 = 4 s), Gauss-Seidel",
        &trace,
        &check,
        &mission,
    );
    assert!(trace.completed(), "{:?}", trace.failure);
    assert!(check.all_finite);
    let max_alpha = trace.max_alpha(0.0, mission.end_time() + 1.0);
    assert!(
        max_alpha < 20f64.to_radians(),
        "max alpha {:.2} deg",
        max_alpha.to_degrees()
    );
    assert!(check.passed(), "{check}");
}

#[test]
fn default_mission_jacobi() {
    let mission = MissionParams::default();
    let (trace, check) = run(mission, Ordering::Jacobi);
    report(
        "default mission, Jacobi (one sample extra delay)",
        &trace,
        &check,
        &mission,
    );
    assert!(trace.completed(), "{:?}", trace.failure);
    assert!(check.passed(), "{check}");
}

/// A 5 m step of the reference offset at `t_step` in a long phase; returns the settling
/// time (last time the error to the new reference exceeds 0.5 m, after the step) and the
/// final error.
fn step_response(mission: MissionParams, t_step: f64, offset: Vector3<f64>, t_end: f64) -> (Trace, f64, f64) {
    let plant = plant();
    let x0 = climb_trim(&plant, mission.v_vertical);
    let mut ctl = TsdController::with_mission(mission).unwrap();
    let mut scenario = Scenario::mission(mission);
    scenario.stop_time = t_end;
    scenario.ref_offset_steps = vec![(t_step, offset)];
    let trace = fly(&plant, x0, &mut ctl, &scenario);
    let mut last_out = t_step;
    let mut final_err = f64::NAN;
    for s in trace.window(t_step, t_end + 1.0) {
        let e = s.pos_error();
        if e > 0.5 {
            last_out = s.t;
        }
        final_err = e;
    }
    (trace, last_out - t_step, final_err)
}

#[test]
fn position_steps_settle() {
    // Vertical: a long first vertical phase. Level: a long level phase.
    let vertical = MissionParams::preset("step_vertical").unwrap();
    let level = MissionParams::preset("step_level").unwrap();
    let cases = [
        (
            "vertical, normal (north) 5 m",
            vertical,
            5.0,
            Vector3::new(5.0, 0.0, 0.0),
            35.0,
        ),
        (
            "vertical, lateral (east) 5 m",
            vertical,
            5.0,
            Vector3::new(0.0, 5.0, 0.0),
            35.0,
        ),
        (
            "level, normal (down) 5 m",
            level,
            15.0,
            Vector3::new(0.0, 0.0, 5.0),
            45.0,
        ),
        (
            "level, lateral (east) 5 m",
            level,
            15.0,
            Vector3::new(0.0, 5.0, 0.0),
            45.0,
        ),
    ];
    let mut failures = Vec::new();
    for (name, mission, t_step, offset, t_end) in cases {
        let (trace, settle, final_err) = step_response(mission, t_step, offset, t_end);
        let max_err = trace
            .window(t_step, t_end + 1.0)
            .map(|s| s.pos_error())
            .fold(0.0, f64::max);
        println!(
            "step {name}: settling (< 0.5 m) {settle:.2} s, final error {final_err:.3} m, max error {max_err:.2} m{}",
            trace
                .failure
                .as_ref()
                .map(|f| format!(" FAILED: {f}"))
                .unwrap_or_default()
        );
        if !trace.completed() || final_err >= 0.5 || settle > t_end - t_step - 1.0 {
            failures.push(name);
        }
    }
    assert!(failures.is_empty(), "did not settle: {failures:?}");
}

/// The controller keeps its nominal model while the plant's C_mα is 20 % larger
/// (the most sensitive parameter of §5) — and, separately, C_Lα 20 % smaller.
#[test]
fn default_mission_with_perturbed_plant() {
    let mission = MissionParams::default();
    let nominal = Airframe::default();
    let cases = [
        (
            "plant C_m_alpha x 1.2",
            Airframe {
                c_m_alpha_a0: nominal.c_m_alpha_a0 * 1.2,
                c_m_alpha_a1: nominal.c_m_alpha_a1 * 1.2,
                ..nominal
            },
        ),
        (
            "plant C_L_alpha x 0.8",
            Airframe {
                c_L_alpha_a0: nominal.c_L_alpha_a0 * 0.8,
                c_L_alpha_a1: nominal.c_L_alpha_a1 * 0.8,
                ..nominal
            },
        ),
        (
            "plant C_m_de x 0.8",
            Airframe {
                c_m_de_a0: nominal.c_m_de_a0 * 0.8,
                c_m_de_a1: nominal.c_m_de_a1 * 0.8,
                ..nominal
            },
        ),
    ];
    let mut failures = Vec::new();
    for (name, airframe) in cases {
        let plant = Plant::new(airframe);
        let x0 = climb_trim(&plant, mission.v_vertical);
        let mut ctl = TsdController::with_mission(mission).unwrap();
        let trace = fly(&plant, x0, &mut ctl, &Scenario::mission(mission));
        let check = MissionCheck::of(&trace, &mission, level_trim_theta(&plant, mission.v_level));
        report(name, &trace, &check, &mission);
        if !trace.completed() || !check.all_finite || check.final_pitch_error > 10f64.to_radians() {
            failures.push(name);
        }
        if trace.max_pos_error() > 5.0 {
            failures.push(name);
        }
    }
    assert!(failures.is_empty(), "{failures:?}");
}

/// configuration = 1, the TSD as printed (docs/THESIS.md D-4.x): at the project's V_V = 3 m/s
/// the wind-axes loops are unstable in the climb (normal and directional integrator modes,
/// `examples/thesis_switches.rs`), so a 5 s final vertical is flown but a 30 s one is lost; at
/// V_V = 8 m/s the printed design holds it.
#[test]
fn thesis_configuration_holds_vertical_flight_only_at_a_fast_climb() {
    let plant = plant();
    let params = tsd_control::TsdParams {
        configuration: 1,
        ..Default::default()
    };
    let mut finals = Vec::new();
    for v_vertical in [3.0, 8.0] {
        let mission = MissionParams {
            v_vertical,
            t_vertical_2: 30.0,
            ..MissionParams::default()
        };
        let x0 = climb_trim(&plant, mission.v_vertical);
        let mut ctl = TsdController::new(Airframe::default(), mission, params).unwrap();
        let trace = fly(&plant, x0, &mut ctl, &Scenario::mission(mission));
        let check = MissionCheck::of(&trace, &mission, level_trim_theta(&plant, mission.v_level));
        print!("thesis configuration, V_V = {v_vertical} m/s, 30 s final vertical:\n{check}");
        let e = check.phase_errors;
        // Undisturbed trimmed climb: exact.
        assert!(e[0].max < 1e-6, "{:?}", e[0]);
        // Transitions and level flight: a few metres.
        for (k, p) in e.iter().enumerate().take(4).skip(1) {
            assert!(p.max < 3.0, "phase {k}: {p:?}");
        }
        finals.push((check.final_pitch_error.to_degrees(), e[4].max));
    }
    // 3 m/s: lost (measured 176° off vertical); 8 m/s: held (0.0°, 0.98 m).
    assert!(finals[0].0 > 30.0, "{finals:?}");
    assert!(finals[1].0 < 2.0 && finals[1].1 < 2.0, "{finals:?}");
}

/// The guidance feedback of the tuned configuration is bounded by GUIDANCE_FEEDBACK_LIMIT; the
/// thesis configuration's is the linear law K_P e_P (4.3.24). A 20 m offset of the reference at
/// the trimmed climb (zero velocity error, still air): Σ − Σ_ff has norm 5 m/s² (tuned) and
/// K_P·20 m with K_P = 0.5² + 0.2² = 0.29 1/s² (thesis, vertical-flight pair of Table 4.3).
#[test]
fn guidance_feedback_is_bounded_in_the_tuned_configuration() {
    use flight_mission::{ControllerInput, SampledUnit};
    use tsd_control::{TsdParams, GUIDANCE_FEEDBACK_LIMIT};
    let plant = plant();
    let mission = MissionParams::default();
    let x0 = climb_trim(&plant, mission.v_vertical);
    let meas = closed_loop::measure(
        &plant,
        &x0,
        &tailsitter_physics::InputVector::zeros(),
        &Vector3::zeros(),
    );
    for (configuration, want) in [(0, GUIDANCE_FEEDBACK_LIMIT), (1, 0.29 * 20.0)] {
        let params = TsdParams {
            configuration,
            ..TsdParams::default()
        };
        let mut ctl = TsdController::new(Airframe::default(), mission, params).unwrap();
        let lead = ctl.params().feedforward_lead;
        let sigma_ff = ctl.trajectory().at(lead).specific_accel;
        ctl.sample(&ControllerInput {
            t: 0.0,
            measurement: meas,
            ref_offset_ned: Vector3::new(20.0, 0.0, 0.0),
        })
        .unwrap();
        let feedback = ctl.internals().sigma_cmd - sigma_ff;
        assert!(
            (feedback.norm() - want).abs() < 1e-9 && feedback.x > 0.0,
            "configuration {configuration}: {feedback:?}"
        );
    }
}
