//! The thesis configuration (`configuration = 1`, the TSD as printed) with each deviation
//! switch flipped alone, on the thesis's own setting: linear aerodynamics (the native plant,
//! `aero_model = 0`), true state, calm air, nominal plant = design model.
//!
//! Per variant: the default mission (T1/T2 = 5/10 s) — largest position error, the final
//! vertical flight's largest error, final pitch error, criteria passed; the same mission with
//! a 30 s final vertical flight (final pitch, largest error in it); a 1 m east step of the
//! reference in a 30 s hover (largest and final error); the fast mission T1/T2 = 3/4 s (largest
//! error, α_max in T1–T2, passed); and the rightmost closed-loop pole of the vertical climb
//! (Jacobian of the sampled closed-loop map one second before the end of vertical flight 1,
//! the method of crates/analysis `closed::poles_at`).
//!
//! `cargo run --release -p tsd-control --example thesis_switches [-- <v_vertical> ...]`
//! (default 3 m/s; the rows "V_V = …" fly the printed design at other climb speeds).

use analysis::closed::{chart_of_plant, plant_from_chart, PLANT_COORDS};
use closed_loop::{fly, measure, plant_inputs, MissionCheck, Scenario};
use flight_mission::{ControllerInput, MissionParams, SampledUnit};
use nalgebra::{DMatrix, Vector3};
use tailsitter_physics::{Airframe, InputVector, Plant, StateVector};
use tsd_control::{TsdController, TsdParams};

/// Name of the map's coordinate `i`: the plant's 19 minimal coordinates, then the four integrators.
fn coord(i: usize) -> &'static str {
    const INTEGRATORS: [&str; 4] = ["I_axial", "I_normal", "I_roll", "I_directional"];
    PLANT_COORDS
        .get(i)
        .copied()
        .unwrap_or_else(|| INTEGRATORS[i - PLANT_COORDS.len()])
}

/// A pole and the two map coordinates with the largest share of its eigenvector.
type Pole = (nalgebra::Complex<f64>, [&'static str; 2]);

/// Rightmost closed-loop pole (s-plane) of the vertical climb of `mission`: the sampled map
/// (plant's 19 minimal coordinates, the four integrators) linearised by central differences
/// one second before the end of vertical flight 1.
fn vertical_poles(plant: &Plant, p: TsdParams, mission: MissionParams) -> Option<Vec<Pole>> {
    let ts = mission.sample_time;
    let x0 = plant.trim_vertical_climb(mission.v_vertical).ok()?.state;
    let mut ctl = TsdController::new(Airframe::default(), mission, p).ok()?;
    let t_op = ((mission.t_vertical_1 - 1.0) / ts).round() * ts;
    let mut sc = Scenario::mission(mission);
    sc.stop_time = t_op - ts;
    let tr = fly(plant, x0, &mut ctl, &sc);
    let last = tr.samples.last()?;
    let mut x = last.x;
    plant
        .advance(&mut x, &plant_inputs(&last.command), &Vector3::zeros(), ts)
        .ok()?;
    let t = last.t + ts;
    let save = |c: &TsdController| {
        let mut v = Vec::new();
        c.save(&mut |y| v.push(y));
        v
    };
    let base_c = save(&ctl);
    let dyn_idx = [1usize, 2, 3, 4];
    let step = |z: &[f64]| -> (StateVector, Vec<f64>) {
        let xs = plant_from_chart(&x, &z[..19]);
        let mut c = ctl.clone();
        let mut s = base_c.clone();
        for (k, i) in dyn_idx.iter().enumerate() {
            s[*i] += z[19 + k];
        }
        let mut it = s.iter().copied();
        c.restore(&mut || it.next()).expect("state");
        let m = measure(plant, &xs, &InputVector::zeros(), &Vector3::zeros());
        let input = ControllerInput {
            t,
            measurement: m,
            ref_offset_ned: Vector3::zeros(),
        };
        let mut xn = xs;
        if let Ok(out) = c.sample(&input) {
            let _ = plant.advance(&mut xn, &plant_inputs(&out.command), &Vector3::zeros(), ts);
        }
        (xn, save(&c))
    };
    let n = 19 + dyn_idx.len();
    let (bx, bs) = step(&vec![0.0; n]);
    // Steps of crates/analysis `closed.rs`: 1e-5 m positions, 1e-4 N thrust, 1e-6 otherwise.
    let mut h = vec![1e-6; n];
    h[..3].fill(1e-5);
    h[12] = 1e-4;
    for (k, i) in dyn_idx.iter().enumerate() {
        h[19 + k] = 1e-6 * bs[*i].abs().max(1.0);
    }
    let eval = |z: &[f64]| -> Vec<f64> {
        let (xn, sn) = step(z);
        let mut out = chart_of_plant(&bx, &xn).to_vec();
        out.extend(dyn_idx.iter().map(|i| sn[*i] - bs[*i]));
        out
    };
    let mut jac = DMatrix::zeros(n, n);
    for j in 0..n {
        let mut zp = vec![0.0; n];
        zp[j] = h[j];
        let mut zm = vec![0.0; n];
        zm[j] = -h[j];
        let (fp, fm) = (eval(&zp), eval(&zm));
        for i in 0..n {
            jac[(i, j)] = (fp[i] - fm[i]) / (2.0 * h[j]);
        }
    }
    let schur = nalgebra::linalg::Schur::try_new(jac.clone(), 1e-14, 10_000)?;
    type C = nalgebra::Complex<f64>;
    let jc: DMatrix<C> = jac.map(|v| C::new(v, 0.0));
    let mut poles: Vec<Pole> = schur
        .complex_eigenvalues()
        .iter()
        .filter(|z| z.im >= 0.0)
        .map(|z| {
            // Eigenvector by inverse iteration; its coordinates scaled to comparable units
            // (as they are: m, m/s, rad, rad/s, N, rad and the integrators' units).
            let shift = z + C::new(1e-9, 1e-9);
            let lu = (&jc - DMatrix::<C>::identity(n, n) * shift).lu();
            let mut v = nalgebra::DVector::<C>::from_element(n, C::new(1.0, 0.0));
            for _ in 0..3 {
                if let Some(w) = lu.solve(&v) {
                    let nrm = w.norm();
                    if nrm.is_finite() && nrm > 0.0 {
                        v = w / C::new(nrm, 0.0);
                    }
                }
            }
            let mut order: Vec<usize> = (0..n).collect();
            order.sort_by(|a, b| v[*b].norm().total_cmp(&v[*a].norm()));
            (
                C::new(z.norm().ln() / ts, z.im.atan2(z.re) / ts),
                [coord(order[0]), coord(order[1])],
            )
        })
        .collect();
    poles.sort_by(|a, b| b.0.re.total_cmp(&a.0.re));
    poles.truncate(3);
    Some(poles)
}

struct Row {
    max_err: f64,
    v2_err: f64,
    final_pitch: f64,
    passed: bool,
    long_v2: (f64, f64),
    step: (f64, f64),
    fast: (f64, f64, bool),
    poles: Option<Vec<Pole>>,
}

fn evaluate(plant: &Plant, p: TsdParams, v_vertical: f64) -> Row {
    let theta_trim = plant.trim_level(25.0).expect("level trim").theta;
    let run = |mission: MissionParams, sc: Scenario| {
        let x0 = plant.trim_vertical_climb(mission.v_vertical).expect("climb trim").state;
        let mut ctl = TsdController::new(Airframe::default(), mission, p).expect("parameters");
        let tr = fly(plant, x0, &mut ctl, &sc);
        let check = MissionCheck::of(&tr, &mission, theta_trim);
        (tr, check)
    };
    let mission = MissionParams {
        v_vertical,
        ..MissionParams::default()
    };
    let (tr, check) = run(mission, Scenario::mission(mission));
    let passed = check.passed() && tr.completed();
    let long = MissionParams {
        t_vertical_2: 30.0,
        ..mission
    };
    let (_, long_check) = run(long, Scenario::mission(long));
    let hover = MissionParams {
        t_vertical_1: 40.0,
        ..mission
    };
    let mut sc = Scenario::mission(hover);
    sc.stop_time = 32.0;
    sc.ref_offset_steps = vec![(2.0, Vector3::new(0.0, 1.0, 0.0))];
    let (tr_step, _) = run(hover, sc);
    let step_max = tr_step.window(2.0, 40.0).map(|s| s.pos_error()).fold(0.0, f64::max);
    let step_final = tr_step.samples.last().map_or(f64::INFINITY, |s| s.pos_error());
    let fast = MissionParams {
        t_transition_1: 3.0,
        t_transition_2: 4.0,
        ..mission
    };
    let (tr_fast, fast_check) = run(fast, Scenario::mission(fast));
    let s = fast.phase_starts();
    Row {
        max_err: tr.max_pos_error(),
        v2_err: check.phase_errors[4].max,
        final_pitch: check.final_pitch_error.to_degrees(),
        passed,
        long_v2: (
            long_check.final_pitch_error.to_degrees(),
            long_check.phase_errors[4].max,
        ),
        step: (step_max, step_final),
        fast: (
            tr_fast.max_pos_error(),
            tr_fast.max_alpha(s[1], s[4]).to_degrees(),
            fast_check.passed() && tr_fast.completed(),
        ),
        poles: vertical_poles(plant, p, mission),
    }
}

fn main() {
    let plant = Plant::new(Airframe::default());
    let printed = TsdParams {
        configuration: 1,
        ..TsdParams::default()
    };
    let mut variants: Vec<(String, TsdParams, f64)> = vec![
        ("tuned (configuration 0)".into(), TsdParams::default(), 3.0),
        ("printed (configuration 1)".into(), printed, 3.0),
    ];
    for (name, value) in printed.switches() {
        let flipped = if name == "slipstream_in_design" { 0 } else { 1 };
        debug_assert_eq!(value, -1);
        let mut p = printed;
        let slot = match name {
            "limited_profile" => &mut p.limited_profile,
            "weathervane_heading" => &mut p.weathervane_heading,
            "hover_wind_design" => &mut p.hover_wind_design,
            "guidance_axial_schedule" => &mut p.guidance_axial_schedule,
            "guidance_lateral_pair" => &mut p.guidance_lateral_pair,
            "guidance_feedback_bound" => &mut p.guidance_feedback_bound,
            "normal_feedforward" => &mut p.normal_feedforward,
            "weathercock_feedforward" => &mut p.weathercock_feedforward,
            "low_speed_path_frame" => &mut p.low_speed_path_frame,
            "feedforward_preview" => &mut p.feedforward_preview,
            "tuned_level_guidance" => &mut p.tuned_level_guidance,
            "normal_thrust_term" => &mut p.normal_thrust_term,
            "lateral_thrust_term" => &mut p.lateral_thrust_term,
            "slipstream_in_design" => &mut p.slipstream_in_design,
            "roll_differential_flaps" => &mut p.roll_differential_flaps,
            "alpha_dependent_mixing" => &mut p.alpha_dependent_mixing,
            "antiwindup_all_loops" => &mut p.antiwindup_all_loops,
            "normal_vector_blend" => &mut p.normal_vector_blend,
            "integrators_as_accelerations" => &mut p.integrators_as_accelerations,
            other => panic!("switch {other} not listed"),
        };
        *slot = flipped;
        variants.push((format!("printed, {name} = {flipped}"), p, 3.0));
    }
    // The physical additions of the former configuration 1 together (D-4.1–D-4.6, D-4.14,
    // D-4.19, D-4.24).
    let former = TsdParams {
        normal_thrust_term: 1,
        lateral_thrust_term: 1,
        roll_differential_flaps: 1,
        alpha_dependent_mixing: 1,
        antiwindup_all_loops: 1,
        normal_vector_blend: 1,
        integrators_as_accelerations: 1,
        ..printed
    };
    variants.push(("former configuration 1 (additions on)".into(), former, 3.0));
    let speeds: Vec<f64> = std::env::args().skip(1).filter_map(|a| a.parse().ok()).collect();
    let speeds = if speeds.is_empty() {
        vec![2.0, 5.0, 8.0, 10.0]
    } else {
        speeds
    };
    for v in speeds {
        variants.push((format!("printed, V_V = {v} m/s"), printed, v));
        variants.push((
            format!("printed + normal_thrust_term, V_V = {v} m/s"),
            TsdParams {
                normal_thrust_term: 1,
                ..printed
            },
            v,
        ));
        variants.push((
            format!("printed, slipstream_in_design = 0, V_V = {v} m/s"),
            TsdParams {
                slipstream_in_design: 0,
                ..printed
            },
            v,
        ));
    }
    println!(
        "| variant | V_V | default mission: max err (m) / V2 max (m) / final pitch (°) / passed | 30 s V2: final pitch (°) / max err (m) | 1 m hover step: max / final (m) | T1/T2 = 3/4 s: max err (m) / α_max (°) / passed | three rightmost vertical-climb poles (1/s) (largest eigenvector coordinates) |"
    );
    println!("|---|---|---|---|---|---|---|");
    for (name, p, v) in variants {
        let r = evaluate(&plant, p, v);
        let pole = r.poles.map_or("–".to_string(), |ps| {
            ps.iter()
                .map(|(s, who)| format!("{:+.2} ± {:.2}i ({}, {})", s.re, s.im.abs(), who[0], who[1]))
                .collect::<Vec<_>>()
                .join("; ")
        });
        println!(
            "| {name} | {v} | {:.2} / {:.2} / {:.1} / {} | {:.1} / {:.2} | {:.2} / {:.2} | {:.2} / {:.1} / {} | {pole} |",
            r.max_err,
            r.v2_err,
            r.final_pitch,
            if r.passed { "yes" } else { "no" },
            r.long_v2.0,
            r.long_v2.1,
            r.step.0,
            r.step.1,
            r.fast.0,
            r.fast.1,
            if r.fast.2 { "yes" } else { "no" },
        );
    }
}
