//! Ground contact (issue 13): standing still on the tail gear, take-off, landing, sliding and
//! crashes that never produce a non-finite value.

use nalgebra::Vector3;
use tailsitter_physics::idx::*;
use tailsitter_physics::{
    dcm_earth_to_body, quat_from_euler_321, Airframe, Ground, InputVector, PhysicsError, Plant, StateVector,
};

/// The FMU's defaults: global aerodynamics (tail-first flight is physical) and the ground.
fn plant() -> Plant {
    let mut p = Plant::new(Airframe::default());
    p.aero.model = tailsitter_physics::AeroModel::Global;
    p.ground = Ground::default();
    p
}

fn still() -> Vector3<f64> {
    Vector3::zeros()
}

/// Pitch from DCM element (1,3) = −sin θ (A.2.5), well defined at 90°.
fn pitch(x: &StateVector) -> f64 {
    let q = x.fixed_rows::<4>(Q1).into_owned();
    (-dcm_earth_to_body(&q)[(0, 2)]).clamp(-1.0, 1.0).asin()
}

#[test]
fn resting_state_is_an_exact_equilibrium() {
    let p = plant();
    let x = p.resting_on_ground(3.0, -2.0, 0.7);
    let d = p.derivatives(&x, &InputVector::zeros(), &still());
    // Weight carried by the four tail points: no acceleration at all.
    assert!(d.rows(U, 10).amax() < 1e-12, "{d}");
    let y = p.outputs(&x, &InputVector::zeros(), &still());
    assert_eq!(y.ground.points, 4);
    // The accelerometer reads +g along the nose (body x up) while standing.
    assert!((y.specific_force_body.x - p.airframe.gravity).abs() < 1e-9);
}

/// Dropped 3 cm and tilted 2°, it settles on its gear and then stays put for 60 s: no creep,
/// no bounce.
#[test]
fn standing_on_the_ground_for_60_s_does_not_creep_or_bounce() {
    let p = plant();
    let mut x = p.resting_on_ground(0.0, 0.0, 0.0);
    x[POS_D] -= 0.03;
    let q = quat_from_euler_321(0.0, 88f64.to_radians(), 0.0);
    x.fixed_rows_mut::<4>(Q1).copy_from(&q);
    let u = InputVector::zeros();
    for _ in 0..150 {
        p.advance(&mut x, &u, &still(), 0.02).unwrap();
    }
    let x_settled = x;
    for _ in 0..3000 {
        p.advance(&mut x, &u, &still(), 0.02).unwrap();
        let y = p.outputs(&x, &u, &still());
        assert_eq!(y.ground.points, 4, "lifted off the ground (bounce)");
    }
    let drift = (x.fixed_rows::<3>(POS_N) - x_settled.fixed_rows::<3>(POS_N)).norm();
    assert!(drift < 1e-4, "crept {drift} m in 60 s");
    assert!(x.fixed_rows::<3>(U).norm() < 1e-6);
    assert!(x.fixed_rows::<3>(P).norm() < 1e-6);
    assert!((pitch(&x) - core::f64::consts::FRAC_PI_2).abs() < 1e-3);
    // Static compression mg/(4k) below the gear height.
    let g = &p.ground;
    let expected_d = g.height - g.gear_length + p.airframe.mass * p.airframe.gravity / (4.0 * g.stiffness);
    assert!((x[POS_D] - expected_d).abs() < 1e-4);
}

#[test]
fn takes_off_with_thrust_above_weight() {
    let p = plant();
    let a = &p.airframe;
    let mut x = p.resting_on_ground(0.0, 0.0, 0.0);
    let mut u = InputVector::zeros();
    u[THRUST_CMD] = 1.3 * a.mass * a.gravity;
    for _ in 0..100 {
        p.advance(&mut x, &u, &still(), 0.02).unwrap();
    }
    let y = p.outputs(&x, &u, &still());
    assert_eq!(y.ground.points, 0);
    assert!(y.ground.clearance > 1.0, "clearance {}", y.ground.clearance);
    assert!(y.vel_ned.z < -1.0);
    assert!((pitch(&x) - core::f64::consts::FRAC_PI_2).abs() < 1e-6);
}

/// Free fall from 1 m onto the gear: the touchdown speed is √(2 g h), then it comes to rest.
#[test]
fn lands_from_a_drop_and_comes_to_rest() {
    let p = plant();
    let a = &p.airframe;
    let mut x = p.resting_on_ground(0.0, 0.0, 0.0);
    let rest_d = x[POS_D];
    let h = 1.0;
    x[POS_D] -= h + a.mass * a.gravity / (4.0 * p.ground.stiffness);
    let u = InputVector::zeros();
    let mut touchdown = None;
    let mut was = 0;
    for _ in 0..400 {
        let before = p.ground.contact_state(a, &x);
        p.advance(&mut x, &u, &still(), 0.005).unwrap();
        let after = p.ground.contact_state(a, &x);
        if was == 0 && after.points > 0 && touchdown.is_none() {
            touchdown = Some(before.sink_rate.max(after.sink_rate));
        }
        was = after.points;
    }
    let v_td = touchdown.expect("never touched down");
    let expected = (2.0 * a.gravity * h).sqrt();
    assert!(
        (v_td - expected).abs() < a.gravity * 0.005 + 1e-3,
        "touchdown {v_td} vs {expected}"
    );
    for _ in 0..200 {
        p.advance(&mut x, &u, &still(), 0.02).unwrap();
    }
    assert!(x.fixed_rows::<3>(U).norm() < 1e-4);
    assert!((x[POS_D] - rest_d).abs() < 1e-3);
    assert_eq!(p.ground.contact_state(a, &x).points, 4);
}

/// Sliding sideways on the gear at 0.5 m/s, Coulomb friction stops it within a distance of
/// the order of v²/(2μg).
#[test]
fn friction_stops_a_slide() {
    let p = plant();
    let a = &p.airframe;
    let mut x = p.resting_on_ground(0.0, 0.0, 0.0);
    let v0 = 0.5;
    let c = dcm_earth_to_body(&x.fixed_rows::<4>(Q1).into_owned());
    let v = c * Vector3::new(0.0, v0, 0.0); // along the wing span (east at ψ = 0)
    x.fixed_rows_mut::<3>(U).copy_from(&v);
    let u = InputVector::zeros();
    for _ in 0..250 {
        p.advance(&mut x, &u, &still(), 0.02).unwrap();
    }
    let d = x[POS_E];
    let coulomb = v0 * v0 / (2.0 * p.ground.friction * a.gravity);
    assert!(x.fixed_rows::<3>(U).norm() < 1e-3, "still sliding");
    assert!(
        d > 0.5 * coulomb && d < 2.0 * coulomb,
        "slid {d} m, Coulomb {coulomb} m"
    );
    assert!((pitch(&x) - core::f64::consts::FRAC_PI_2).abs() < 0.05);
}

/// Hitting the ground at up to 20 m/s in any attitude: every state stays finite; the only
/// possible error is an envelope report, never a non-finite value.
#[test]
fn crashes_are_finite() {
    let p = plant();
    let mut seed = 3u64;
    let mut rnd = |lo: f64, hi: f64| {
        seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        lo + (hi - lo) * ((seed >> 11) as f64 / (1u64 << 53) as f64)
    };
    for _ in 0..40 {
        let mut x = StateVector::zeros();
        let q = quat_from_euler_321(rnd(-3.0, 3.0), rnd(-1.5, 1.5), rnd(-3.0, 3.0));
        x.fixed_rows_mut::<4>(Q1).copy_from(&q);
        let v_ned = Vector3::new(rnd(-15.0, 15.0), rnd(-15.0, 15.0), rnd(2.0, 15.0));
        x.fixed_rows_mut::<3>(U).copy_from(&(dcm_earth_to_body(&q) * v_ned));
        x[POS_D] = p.ground.height - 1.0;
        x[P] = rnd(-5.0, 5.0);
        x[Q] = rnd(-5.0, 5.0);
        x[R] = rnd(-5.0, 5.0);
        x[THRUST] = rnd(0.0, 100.0);
        let mut u = InputVector::zeros();
        u[THRUST_CMD] = x[THRUST];
        for _ in 0..150 {
            match p.advance(&mut x, &u, &still(), 0.02) {
                Ok(()) => assert!(x.iter().all(|v| v.is_finite())),
                Err(PhysicsError::Envelope { .. }) => break,
                Err(e) => panic!("unexpected error {e}"),
            }
        }
        let y = p.outputs(&x, &u, &still());
        assert!(y.specific_force_body.iter().all(|v| v.is_finite()));
    }
}

/// `GlobalAero::default()` is the FMU's start values (`Ground`'s are generated from them).
#[test]
fn global_aero_defaults_match_json_start_values() {
    use tailsitter_physics::{AeroModel, GlobalAero};
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../modelDescription/tailsitter_plant.json"
    );
    let json: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    let start = |name: &str| {
        json["variables"]
            .as_array()
            .unwrap()
            .iter()
            .find(|v| v["name"] == name)
            .unwrap_or_else(|| panic!("no variable {name}"))["start"]
            .as_f64()
            .unwrap()
    };
    let a = GlobalAero::default();
    assert_eq!(start("aero_model") as i32, AeroModel::Global.index());
    for (name, value) in [
        ("alpha_attached", a.alpha_attached),
        ("alpha_stalled", a.alpha_stalled),
        ("beta_attached", a.beta_attached),
        ("beta_stalled", a.beta_stalled),
        ("c_D_90", a.c_D_90),
    ] {
        assert!((start(name) - value).abs() <= 1e-15 * value.abs().max(1.0), "{name}");
    }
}

/// A hard landing, 15 m/s straight down onto the gear: the default step (20/3 ms, checked
/// Dormand–Prince) agrees with a step 64 times finer through the impact, the contact's
/// stiffness notwithstanding (the checked step halves deeper wherever a contact point may
/// touch). Compared over 0.2 s from 5 cm above the ground: position and rates.
#[test]
fn a_hard_touchdown_is_integrated_to_the_fine_step() {
    let coarse = plant();
    let mut fine = plant();
    fine.integration_step = coarse.integration_step / 64.0;
    let a = &coarse.airframe;
    let mut x0 = coarse.resting_on_ground(0.0, 0.0, 0.0);
    x0[POS_D] -= 0.05 + a.mass * a.gravity / (4.0 * coarse.ground.stiffness);
    // 15 m/s down the earth's z: the nose-up body's x axis points up, so body u = −15.
    x0[U] = -15.0;
    let u = InputVector::zeros();
    let (mut xc, mut xf) = (x0, x0);
    let (mut worst_pos, mut worst_rate) = (0.0f64, 0.0f64);
    let mut touched = false;
    for _ in 0..10 {
        coarse.advance(&mut xc, &u, &still(), 0.02).unwrap();
        fine.advance(&mut xf, &u, &still(), 0.02).unwrap();
        touched |= coarse.ground.contact_state(a, &xc).points > 0;
        worst_pos = worst_pos.max((xc.fixed_rows::<3>(POS_N) - xf.fixed_rows::<3>(POS_N)).norm());
        worst_rate = worst_rate.max((xc.fixed_rows::<3>(P) - xf.fixed_rows::<3>(P)).norm());
    }
    assert!(touched, "never touched down");
    assert!(worst_pos < 1e-7, "position off the fine step by {worst_pos:e} m");
    assert!(worst_rate < 1e-6, "rates off the fine step by {worst_rate:e} rad/s");
}

/// The work of one communication step is bounded: with a tolerance the error estimate never
/// meets (0), a checked step resting on the gear would refine every internal step to the
/// contact depth (2²⁰ substeps, ≈ 2·10⁷ evaluations per 20 ms: a host blocked for minutes
/// over a whole flight, as one campaign run was). Now it stops refining after
/// `MAX_CHECKED_SUBSTEPS` and the step still ends on the ground, finite.
#[test]
fn a_checked_step_on_the_ground_has_bounded_work() {
    use tailsitter_physics::{Integrator, MAX_CHECKED_SUBSTEPS};
    let mut plant = Plant::new(Airframe::default());
    plant.ground = Ground::default();
    plant.integrator = Integrator::Dp5Checked {
        tolerance: 0.0,
        max_halvings: 4,
    };
    let mut x = plant.resting_on_ground(0.0, 0.0, 0.0);
    x[W] = -0.5;
    let u = InputVector::zeros();
    let mut evals = 0u64;
    plant
        .advance_counting(&mut x, &u, &Vector3::zeros(), 0.02, &mut evals)
        .expect("the step on the ground succeeds");
    // Three internal steps at the default step, each at most MAX_CHECKED_SUBSTEPS substeps
    // plus the climb back to its grid (≤ 2·20), 7 evaluations each.
    let bound = 3 * (MAX_CHECKED_SUBSTEPS + 40) * 7 + 3;
    assert!(evals <= bound, "{evals} evaluations > {bound}");
    assert!(
        evals > 3 * MAX_CHECKED_SUBSTEPS,
        "the refinement ran: {evals} evaluations"
    );
    assert!(x.iter().all(|v| v.is_finite()));
}
