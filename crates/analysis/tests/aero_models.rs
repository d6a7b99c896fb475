//! The thesis-vs-global aerodynamic comparison (`analysis::aero_models`): its coefficient
//! curves against independent values, the invariance of attached-flow runs, and the data
//! files the Python renderer (`tailsim.aero_report`) reads.

use analysis::aero_models::{cases, coefficients, fly_case, run, Case};
use analysis::controllers::Kind;
use closed_loop::Scenario;
use flight_mission::MissionParams;
use tailsitter_physics::{AeroModel, Airframe, GlobalAero};

#[test]
fn coefficient_curves_of_both_models() {
    let a = Airframe::default();
    let g = GlobalAero::default();
    for deg in 0..=180 {
        let alpha = f64::from(deg).to_radians();
        let t = coefficients(&a, &g, AeroModel::Thesis, alpha);
        let gl = coefficients(&a, &g, AeroModel::Global, alpha);
        if alpha <= g.alpha_attached {
            for k in 0..3 {
                assert!((t[k] - gl[k]).abs() < 1e-12, "α {deg}: {t:?} vs {gl:?}");
            }
        }
        // Flat-plate bound: no lift or drag coefficient beyond 2 (C_N ≤ C_D90 < 2).
        assert!(gl[0].abs() <= 2.0 && gl[1] <= 2.0 && gl[1] >= 0.0, "α {deg}: {gl:?}");
    }
    // Broadside: the global model's drag is Viterna & Corrigan's C_D90 = 1.11 + 0.018 A
    // (A = 4.29) and its lift vanishes; the thesis's linear lift is above the flat-plate limit.
    let gl = coefficients(&a, &g, AeroModel::Global, core::f64::consts::FRAC_PI_2);
    assert!(
        (gl[1] - (1.11 + 0.018 * 4.29)).abs() < 1e-9 && gl[0].abs() < 1e-9,
        "{gl:?}"
    );
    let t = coefficients(&a, &g, AeroModel::Thesis, core::f64::consts::FRAC_PI_2);
    assert!(t[0] > 2.0, "{t:?}");
}

/// A run that never leaves attached flow flies the same with both models (they are
/// identical there, to rounding: 1e-12 relative in each force): hovering in still air.
#[test]
fn attached_runs_are_identical_on_both_models() {
    let hover = MissionParams {
        t_vertical_1: 40.0,
        ..MissionParams::default()
    };
    let mut scenario = Scenario::mission(hover);
    scenario.stop_time = 10.0;
    let case = Case {
        id: "hover_still",
        description: "hover in still air".into(),
        scenario,
    };
    for kind in Kind::ALL {
        let t = fly_case(&case, kind, AeroModel::Thesis);
        let g = fly_case(&case, kind, AeroModel::Global);
        assert!(t.passed && g.passed, "{t:?} {g:?}");
        assert_eq!(t.max_stall_fraction, 0.0);
        assert!((t.max_pos_error_m - g.max_pos_error_m).abs() < 1e-9, "{t:?} {g:?}");
        assert!((t.max_alpha_deg - g.max_alpha_deg).abs() < 1e-9, "{t:?} {g:?}");
        assert_eq!(t.first_stall_s, None);
    }
}

#[test]
fn writes_the_data_the_renderer_reads() {
    let dir = std::env::temp_dir().join(format!("aero-models-test-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let rows = run(&dir, &MissionParams::default(), &[1.0, 2.0]).unwrap();
    assert_eq!(rows.len(), cases(&MissionParams::default()).len() * Kind::ALL.len() * 2);
    for r in &rows {
        assert!((0.0..=1.0).contains(&r.max_stall_fraction), "{r:?}");
        assert!(r.max_pos_error_m.is_finite() && r.max_alpha_deg <= 180.0);
        assert!(!r.passed || r.completed);
    }
    // The thesis's model flies its own default mission (the controllers' acceptance).
    for kind in Kind::ALL {
        let r = rows
            .iter()
            .find(|r| r.case == "default" && r.controller == kind.name() && r.aero_model == 0)
            .unwrap();
        assert!(r.passed, "{r:?}");
    }
    let written: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("aero_models.json")).unwrap()).unwrap();
    let fixture = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/data/analysis/aero_models.json");
    let fixture: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(fixture).unwrap()).unwrap();
    let keys = |v: &serde_json::Value| v.as_object().unwrap().keys().cloned().collect::<Vec<_>>();
    for path in ["", "/coefficients", "/rows/0", "/cases/0", "/gusts", "/gusts/rows/0"] {
        assert_eq!(
            keys(written.pointer(path).unwrap()),
            keys(fixture.pointer(path).unwrap()),
            "{path}: refresh tests/data/analysis (cargo run --release -p analysis -- aero --out tests/data/analysis)"
        );
    }
    // 3 phases × 3 axes × every controller × 2 models.
    let gusts = written["gusts"]["rows"].as_array().unwrap();
    assert_eq!(gusts.len(), 3 * 3 * Kind::ALL.len() * 2);
    for f in ["aero_models.csv", "aero_coefficients.csv", "aero_gusts.csv"] {
        let text = std::fs::read_to_string(dir.join(f)).unwrap();
        assert!(text.lines().count() > rows.len().min(24), "{f}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
