//! The method on systems with known answers, and the sweep tables from actual runs.

use analysis::closed::{closed_loop_poles, poles_of_map, Analysable, Condition, OperatingPoint};
use analysis::controllers::Kind;
use analysis::linalg::{eigenvalues, match_poles, z_to_s, C64};
use analysis::sensitivity::{factors, nominal_index, track};
use analysis::sweep::{run, Config};
use flight_mission::{
    Command, ControlError, ControllerInput, ControllerOutput, Diagnostics, ParamError, Phase, SampledUnit,
};
use nalgebra::{DMatrix, DVector, Vector3};
use tailsitter_physics::{idx, Airframe, Plant};

/// Double integrator ẍ = u, ZOH over T, u = −k₁x − k₂v with gains chosen (analytically)
/// so that the discrete closed loop has poles z = e^{sT}, s = −2 ± 3i: the sampled-map
/// Jacobian must return exactly these s.
#[test]
fn double_integrator_with_known_gains() {
    let t = 0.02;
    let s = C64::new(-2.0, 3.0);
    let z1 = (s * t).exp();
    let (tr, det) = (2.0 * z1.re, z1.norm_sqr());
    // char. polynomial of Φ − ΓK: z² − (2 − k₁T²/2 − k₂T) z + (1 − k₂T + k₁T²/2)
    let k2 = (3.0 - tr - det) / (2.0 * t);
    let k1 = (2.0 - tr - k2 * t) * 2.0 / (t * t);
    let map = |z: &DVector<f64>| {
        let u = -k1 * z[0] - k2 * z[1];
        DVector::from_vec(vec![z[0] + t * z[1] + 0.5 * t * t * u, z[1] + t * u])
    };
    let (_, _, poles) = poles_of_map(map, &DVector::zeros(2), &[1e-4, 1e-4], t);
    assert_eq!(poles.len(), 2);
    for p in &poles {
        let target = if p.im > 0.0 { s } else { s.conj() };
        assert!((p - target).norm() < 1e-6, "{p} vs {target}");
    }
}

/// Same double integrator with an integrating controller state I' = I + T x (the
/// controller-state part of the map): poles = eigenvalues of the 3×3 closed-loop matrix.
#[test]
fn double_integrator_with_integrator_state() {
    let (t, k1, k2, ki) = (0.05, 4.0, 3.0, 2.0);
    let map = |z: &DVector<f64>| {
        let u = -k1 * z[0] - k2 * z[1] - ki * z[2];
        DVector::from_vec(vec![z[0] + t * z[1] + 0.5 * t * t * u, z[1] + t * u, z[2] + t * z[0]])
    };
    let m = DMatrix::from_row_slice(
        3,
        3,
        &[
            1.0 - 0.5 * t * t * k1,
            t - 0.5 * t * t * k2,
            -0.5 * t * t * ki,
            -t * k1,
            1.0 - t * k2,
            -t * ki,
            t,
            0.0,
            1.0,
        ],
    );
    let expected: Vec<C64> = eigenvalues(&m).into_iter().map(|z| z_to_s(z, t)).collect();
    let (_, _, poles) = poles_of_map(map, &DVector::zeros(3), &[1e-4; 3], t);
    let pairing = match_poles(&expected, &poles);
    for (e, j) in expected.iter().zip(pairing) {
        assert!((e - poles[j.unwrap()]).norm() < 1e-6);
    }
}

/// Scalar plant ẋ = a x + b u with the fixed gain u = −k x: the pole a − b k moves
/// linearly in b. The §5.1 measure of a sweep of b is then known in closed form:
/// max_k |f_k − 1|·b k / |a − b k| (one pole, so the RMS is that distance).
#[test]
fn analytic_sensitivity_of_a_scalar_loop() {
    let (a, b, k) = (1.0, 2.0, 3.0);
    let f = factors(1.5, 50);
    let points: Vec<Option<Vec<C64>>> = f.iter().map(|fk| Some(vec![C64::new(a - fk * b * k, 0.0)])).collect();
    let row = track(&points, nominal_index(&f)).unwrap();
    let expected = f.iter().map(|fk| (fk - 1.0).abs()).fold(0.0, f64::max) * b * k / (a - b * k).abs();
    assert!(
        (row.rms_percent - 100.0 * expected).abs() < 1e-9,
        "{} vs {}",
        row.rms_percent,
        100.0 * expected
    );
    // The locus is the straight line a − f b k.
    for (kk, fk) in f.iter().enumerate() {
        let (re, im) = row.loci[0][kk].unwrap();
        assert!((re - (a - fk * b * k)).abs() < 1e-12 && im == 0.0);
    }
    // Same through the sampled map (exact ZOH of the scalar loop, T = 1 ms): s → a − b k.
    let t = 1e-3;
    for fk in [f[0], 1.0, f[49]] {
        let bb = fk * b;
        let ead = (a * t).exp();
        let map = |z: &DVector<f64>| DVector::from_element(1, (ead - (ead - 1.0) / a * bb * k) * z[0]);
        let (_, _, p) = poles_of_map(map, &DVector::zeros(1), &[1e-3], t);
        assert!(
            (p[0].re - (a - bb * k)).abs() < 0.02 * (a - bb * k).abs(),
            "{} vs {}",
            p[0],
            a - bb * k
        );
    }
    // Two poles, one fixed: RMS = distance/√2.
    let points2: Vec<Option<Vec<C64>>> = f
        .iter()
        .map(|fk| Some(vec![C64::new(a - fk * b * k, 0.0), C64::new(-7.0, 0.0)]))
        .collect();
    let row2 = track(&points2, nominal_index(&f)).unwrap();
    assert!((row2.rms_percent - 100.0 * expected / 2f64.sqrt()).abs() < 1e-9);
}

/// A linear controller on the tail-sitter: trim commands plus rate damping and an
/// integrator on q (its only dynamic state).
#[derive(Debug, Clone, PartialEq)]
struct RateDamper {
    trim: Command,
    kq: f64,
    kp: f64,
    kr: f64,
    ki: f64,
    ts: f64,
    integ: f64,
}

impl SampledUnit for RateDamper {
    type Config = RateDamper;
    type Input = ControllerInput;
    type Output = ControllerOutput;

    fn build(config: &RateDamper) -> Result<Self, ParamError> {
        Ok(config.clone())
    }

    fn sample_time(config: &RateDamper) -> f64 {
        config.ts
    }

    fn save(&self, out: &mut impl FnMut(f64)) {
        out(self.integ);
    }

    fn restore(&mut self, next: &mut impl FnMut() -> Option<f64>) -> Result<(), ControlError> {
        self.integ = next().ok_or_else(|| ControlError("truncated".into()))?;
        Ok(())
    }

    fn sample(&mut self, input: &ControllerInput) -> Result<ControllerOutput, ControlError> {
        let w = input.measurement.rates;
        let mut c = self.trim;
        c.elevator -= self.kq * w.y + self.ki * self.integ;
        c.aileron -= self.kp * w.x;
        c.rudder -= self.kr * w.z;
        self.integ += self.ts * w.y;
        Ok(ControllerOutput {
            command: c,
            diagnostics: Diagnostics {
                ref_pos_ned: Vector3::zeros(),
                ref_airspeed: 0.0,
                phase: Phase::Level,
                pos_error: 0.0,
            },
            notice: None,
        })
    }
}

impl Analysable for RateDamper {
    fn dynamic_states(&self) -> Vec<(usize, &'static str)> {
        vec![(0, "∫q")]
    }
}

/// The tail-sitter wiring (quaternion chart, controller-state perturbation, measurement,
/// plant step): the sampled-map poles of plant + a known linear controller equal those of
/// Φ − ΓK from the ZOH discretisation of the plant's continuous linearisation (which has
/// one extra pole, z = 1, along the quaternion's norm).
#[test]
fn tail_sitter_map_matches_zoh_of_linearisation() {
    let plant = Plant::new(Airframe::default());
    let trim = plant.trim_level(25.0).unwrap();
    let t = 0.02;
    let u0 = trim.inputs;
    let ctl = RateDamper {
        trim: Command {
            thrust: u0[idx::THRUST_CMD],
            elevator: u0[idx::ELEVATOR_CMD],
            ..Default::default()
        },
        kq: 0.05,
        kp: 0.04,
        kr: 0.03,
        ki: 0.2,
        ts: t,
        integ: 0.0,
    };
    let op = OperatingPoint {
        t: 10.0,
        x: trim.state,
        controller: ctl,
    };
    let ours: Vec<C64> = closed_loop_poles(&plant, &op, t)
        .discrete
        .iter()
        .map(|e| e.value)
        .collect();
    assert_eq!(ours.len(), 20);

    let (a, b) = plant.linearise(&trim.state, &trim.inputs, &Vector3::zeros());
    let mut aug = DMatrix::<f64>::zeros(27, 27);
    for i in 0..20 {
        for j in 0..20 {
            aug[(i, j)] = a[(i, j)] * t;
        }
        for j in 0..7 {
            aug[(i, 20 + j)] = b[(i, j)] * t;
        }
    }
    let e = aug.exp();
    let phi = e.view((0, 0), (20, 20)).into_owned();
    let gamma = e.view((0, 20), (20, 7)).into_owned();
    let mut k = DMatrix::<f64>::zeros(7, 21);
    k[(idx::ELEVATOR_CMD, idx::Q)] = 0.05;
    k[(idx::AILERON_CMD, idx::P)] = 0.04;
    k[(idx::RUDDER_CMD, idx::R)] = 0.03;
    k[(idx::ELEVATOR_CMD, 20)] = 0.2;
    let mut m = DMatrix::<f64>::zeros(21, 21);
    m.view_mut((0, 0), (20, 20)).copy_from(&phi);
    let gk = &gamma * &k;
    let top = m.view((0, 0), (20, 21)) - gk;
    m.view_mut((0, 0), (20, 21)).copy_from(&top);
    m[(20, idx::Q)] = t;
    m[(20, 20)] = 1.0;
    let reference = eigenvalues(&m);
    let pairing = match_poles(&ours, &reference);
    for (z, j) in ours.iter().zip(&pairing) {
        let r = reference[j.unwrap()];
        // z = 1 is a repeated eigenvalue (positions, heading): looser there.
        let tol = if (r - C64::new(1.0, 0.0)).norm() < 1e-3 {
            2e-3
        } else {
            1e-6
        };
        assert!((z - r).norm() < tol, "{z} vs {r}");
    }
    // The unmatched reference pole is the quaternion-norm direction at z = 1.
    let used: Vec<usize> = pairing.iter().flatten().copied().collect();
    let left: Vec<C64> = (0..21).filter(|i| !used.contains(i)).map(|i| reference[i]).collect();
    assert_eq!(left.len(), 1);
    assert!((left[0] - C64::new(1.0, 0.0)).norm() < 2e-3, "{}", left[0]);
}

/// The same object keys at every level (arrays: their first elements; `null` matches anything).
fn same_structure(a: &serde_json::Value, b: &serde_json::Value, at: &str) -> Result<(), String> {
    use serde_json::Value;
    match (a, b) {
        (Value::Object(x), Value::Object(y)) => {
            let (kx, ky): (Vec<_>, Vec<_>) = (x.keys().collect(), y.keys().collect());
            if kx != ky {
                return Err(format!("{at}: keys {kx:?} against {ky:?}"));
            }
            x.iter()
                .try_for_each(|(k, v)| same_structure(v, &y[k], &format!("{at}.{k}")))
        }
        (Value::Array(x), Value::Array(y)) => match (x.first(), y.first()) {
            (Some(p), Some(q)) => same_structure(p, q, &format!("{at}[0]")),
            _ => Ok(()),
        },
        (Value::Null, _) | (_, Value::Null) => Ok(()),
        (Value::Number(_), Value::Number(_))
        | (Value::String(_), Value::String(_))
        | (Value::Bool(_), Value::Bool(_)) => Ok(()),
        _ => Err(format!("{at}: {a} against {b}")),
    }
}

/// A tiny campaign (N = 2, one parameter, one gust amplitude): Table 5.1, the robustness
/// and gust tables come from actual runs, are cached, and a re-run computes nothing.
#[test]
fn tiny_campaign_tables_come_from_runs_and_are_cached() {
    let dir = std::env::temp_dir().join(format!("analysis-test-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let mut cfg = Config::full(&dir);
    cfg.n = 2;
    cfg.params = vec!["Cmde".into()];
    cfg.conditions = vec![Condition::Level];
    cfg.gust_amplitudes = vec![1.0];
    cfg.progress = false;
    // The hover campaign (issue 16) is covered by its own tests; the fixture holds its output.
    cfg.envelope_hover = false;
    let s = run(&cfg).unwrap();
    assert_eq!(s.cache_hits, 0);
    // Table 5.1: the thesis's 2 controllers (PX4 is not in it, and the report says so).
    let sens: Vec<_> = s.sensitivity.iter().filter(|r| r.param == "Cmde").collect();
    assert_eq!(sens.len(), 2);
    assert!(sens.iter().all(|r| r.controller.in_thesis()));
    for r in &sens {
        let row = r.row.as_ref().expect("nominal point flies");
        assert!(row.rms_percent > 0.0 && row.rms_percent.is_finite());
        assert_eq!(row.failed_points, 0);
    }
    // The report's data: Table 5.1 in report.json (rendered by tailsim.analysis_report) and CSV.
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("report.json")).unwrap()).unwrap();
    let param = &report["params"][0];
    assert_eq!(param["name"], "C_mδe");
    // Thesis Table 5.1, C_mδe: LQR 59.0 %, TSD 105.0 %.
    assert_eq!(param["thesis_percent"]["LQR"], 59.0);
    assert_eq!(param["thesis_percent"]["TSD"], 105.0);
    let rows = report["sensitivity"]["rows"].as_array().unwrap();
    for r in &sens {
        let row = rows
            .iter()
            .find(|x| x["controller"] == r.controller.name() && x["param"] == "Cmde")
            .expect("row of C_mδe");
        let rms = row["row"]["rms_percent"].as_f64().unwrap();
        assert!((rms - r.row.as_ref().unwrap().rms_percent).abs() < 1e-12, "{row}");
    }
    // Same structure as the stored campaign output the Python renderer is tested on.
    let fixture = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/data/analysis/report.json");
    let fixture: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(fixture).unwrap()).unwrap();
    if let Err(e) = same_structure(&report, &fixture, "report.json") {
        panic!("{e}: refresh tests/data/analysis/ (see tests/test_analysis_report.py) and the renderer");
    }
    let table = std::fs::read_to_string(dir.join("table_5_1.csv")).unwrap();
    assert_eq!(table.lines().filter(|l| l.starts_with("Cmde,")).count(), 2, "{table}");
    assert_eq!(report["sensitivity"]["not_applicable"][0]["controller"], "PX4");
    // Poles of every controller at both conditions, PX4's among them.
    let nk = Kind::ALL.len();
    assert_eq!(s.closed_loop.len(), nk * 2);
    assert!(s
        .closed_loop
        .iter()
        .any(|(k, _, j)| *k == Kind::Px4 && j.error.is_none() && !j.poles.is_empty()));
    // Robustness: every controller × 2 aerodynamic models, factors 1/τ and 1.
    assert_eq!(s.robustness.len(), nk * 2);
    for r in &s.robustness {
        assert_eq!(r.outcomes.len(), 2);
        assert_eq!(r.factors[1], 1.0);
    }
    robustness_on_both_models(&s.robustness);
    assert_eq!(s.gusts.len(), nk * 3 * 3);
    let rb = report["robustness"]["rows"].as_array().unwrap();
    assert_eq!(rb.len(), nk * 2);
    assert!(rb.iter().all(|r| r["param"] == "Cmde" && r["points"] == 2));
    for ctl in Kind::ALL.map(Kind::name) {
        for model in [0, 1] {
            assert_eq!(
                rb.iter()
                    .filter(|r| r["controller"] == ctl && r["aero_model"] == model)
                    .count(),
                1,
                "{ctl} on aero_model {model}"
            );
        }
    }
    let csv = std::fs::read_to_string(dir.join("robustness.csv")).unwrap();
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let col = header
        .iter()
        .position(|h| *h == "aero_model")
        .expect("aero_model column");
    for model in ["0", "1"] {
        assert_eq!(
            csv.lines()
                .skip(1)
                .filter(|l| l.split(',').nth(col) == Some(model))
                .count(),
            nk * 2,
            "{csv}"
        );
    }
    assert_eq!(report["gusts"]["rows"].as_array().unwrap().len(), nk * 3 * 3);
    let cache_lines = std::fs::read_to_string(dir.join("cache/poles.jsonl"))
        .unwrap()
        .lines()
        .count();
    assert!(cache_lines >= 6, "{cache_lines}");
    // Re-run: everything from the cache, same tables.
    let s2 = run(&cfg).unwrap();
    assert_eq!(s2.cache_hits, s2.jobs);
    assert_eq!(std::fs::read_to_string(dir.join("table_5_1.csv")).unwrap(), table);
    let _ = std::fs::remove_dir_all(&dir);
}

/// The robustness sweep on both aerodynamic models (issue 13), checked against what each
/// model is independently of the sweep's code:
/// * every flight equals the mission flown here directly on a plant built for its label:
///   `Plant::new` as it is for `aero_model` 0 (the thesis's linear model, what the sweep flew
///   before the global model existed) and `aero.model = Global` for 1 (so a row cannot carry
///   the wrong label or ignore its model where the models' flights differ);
/// * at factor 1 (the nominal airframe) the mission meets the controller issues' criteria on
///   the thesis's model with both controllers (their acceptance);
/// * the global model is the thesis's inside attached flow, so a flight that never left
///   attached flow on either model is identical on both, and any flight that differs left it
///   (stall fraction > 0 on one of the models).
fn robustness_on_both_models(results: &[analysis::sweep::RobustnessResult]) {
    use closed_loop::{fly, MissionCheck, Scenario};
    use flight_mission::MissionParams;
    use tailsitter_physics::AeroModel;

    let m = MissionParams::default();
    let direct = |airframe: &Airframe, model: i32, kind: Kind| {
        let plant = if model == 0 {
            Plant::new(*airframe)
        } else {
            let mut p = Plant::new(*airframe);
            p.aero.model = AeroModel::Global;
            p
        };
        let x0 = plant.trim_vertical_climb(m.v_vertical).unwrap().state;
        let theta = plant.trim_level(m.v_level).unwrap().theta;
        let trace = fly(&plant, x0, &mut kind.make(&m), &Scenario::mission(m));
        let passed = trace.completed() && MissionCheck::of(&trace, &m, theta).passed();
        (passed, trace.max_pos_error())
    };
    for kind in Kind::ALL {
        let get = |model: i32| {
            results
                .iter()
                .find(|r| r.controller == kind && r.aero_model == model)
                .unwrap_or_else(|| panic!("{kind:?} on aero_model {model}"))
        };
        let (thesis, global) = (get(0), get(1));
        assert_eq!(thesis.factors, global.factors);
        let param = analysis::sensitivity::params()
            .into_iter()
            .find(|p| p.id == thesis.param)
            .unwrap();
        for row in [thesis, global] {
            for (f, o) in row.factors.iter().zip(&row.outcomes) {
                let (passed, err) = direct(&param.scaled(&Airframe::default(), *f), row.aero_model, kind);
                assert_eq!(
                    (o.passed, o.max_pos_error),
                    (passed, err),
                    "{kind:?} model {} ×{f}",
                    row.aero_model
                );
            }
        }
        assert_eq!(thesis.factors[1], 1.0);
        assert!(thesis.outcomes[1].passed, "{kind:?}: {:?}", thesis.outcomes[1]);
        // Identical where attached on both; a difference only after leaving attached flow.
        for (t, g) in thesis.outcomes.iter().zip(&global.outcomes) {
            let same = t.passed == g.passed && (t.max_pos_error - g.max_pos_error).abs() <= 1e-6;
            if t.max_stall_fraction == 0.0 && g.max_stall_fraction == 0.0 {
                assert!(same, "{kind:?}: attached on both models but {t:?} vs {g:?}");
            }
            if !same {
                assert!(
                    t.max_stall_fraction > 0.0 || g.max_stall_fraction > 0.0,
                    "{kind:?}: {t:?} vs {g:?}"
                );
            }
        }
    }
}
