//! Stick-slip friction of the gear contact (module `tailsitter_physics::ground`): a load
//! below μ_s N holds without creeping, a slide decelerates at μ_k g, contact transitions
//! dissipate and stay finite, and the result does not depend on the step.

use nalgebra::Vector3;
use tailsitter_physics::idx::*;
use tailsitter_physics::{
    dcm_earth_to_body, quat_from_euler_321, Airframe, ContactAnchors, Grip, Ground, InputVector, Plant, StateVector,
};

/// The FMU's defaults: global aerodynamics and the ground.
fn plant() -> Plant {
    let mut p = Plant::new(Airframe::default());
    p.aero.model = tailsitter_physics::AeroModel::Global;
    p.ground = Ground::default();
    p
}

/// The plant without air (no aerodynamic force; gravity and the ground only).
fn vacuum() -> Plant {
    let mut p = plant();
    p.airframe.air_density = 0.0;
    p
}

fn horizontal(x: &StateVector) -> Vector3<f64> {
    Vector3::new(x[POS_N], x[POS_E], 0.0)
}

fn at_rest(p: &Plant) -> (StateVector, ContactAnchors) {
    let x = p.resting_on_ground(0.0, 0.0, 0.0);
    let mut a = ContactAnchors::FREE;
    a.update(&p.ground, &p.airframe, &x);
    (x, a)
}

/// Horizontal aerodynamic force on the aircraft standing at `x` in `wind` (N).
fn wind_force(p: &Plant, x: &StateVector, wind: &Vector3<f64>) -> f64 {
    let c = dcm_earth_to_body(&x.fixed_rows::<4>(Q1).into_owned());
    c.tr_mul(&p.forces_moments(x, wind).force_body).xy().norm()
}

/// Fly `seconds` in communication steps of `h` with the thrust cut.
fn fly(p: &Plant, x: &mut StateVector, a: &mut ContactAnchors, wind: &Vector3<f64>, h: f64, seconds: f64) {
    for _ in 0..(seconds / h).round() as usize {
        p.advance_in_contact(x, a, &InputVector::zeros(), wind, h).unwrap();
    }
}

/// Stands in `wind` for 5 s (the gear's elastic deflection and the lean settle), then 10 s:
/// the drift over the 10 s (m), where it stood after 5 s, and the anchors at the end.
fn stand(p: &Plant, wind: &Vector3<f64>) -> (f64, Vector3<f64>, ContactAnchors, StateVector) {
    let (mut x, mut a) = at_rest(p);
    fly(p, &mut x, &mut a, wind, 0.02, 5.0);
    let settled = horizontal(&x);
    fly(p, &mut x, &mut a, wind, 0.02, 10.0);
    ((horizontal(&x) - settled).norm(), settled, a, x)
}

/// The default gear (μ_s = μ_k = 0.5) in 10 m/s on the belly (from the north at heading 0,
/// about 42 N, 95 % of μ m g; the regularised law crept at 0.1 m/s under this load) and
/// along the span, and a gear with μ_s = 0.8 in 11 m/s on the belly (about 50 N: more than
/// kinetic friction μ_k m g = 44 N, less than μ_s m g = 71 N). After 5 s the aircraft does
/// not move by 1 mm in 10 s, every touching point stuck.
#[test]
fn a_load_below_static_friction_holds_without_creeping() {
    let default = plant();
    let mut grippy = plant();
    grippy.ground.static_friction = 0.8;
    let weight = default.airframe.mass * default.airframe.gravity;
    for (p, wind, lower, upper) in [
        (&default, Vector3::new(-10.0, 0.0, 0.0), 0.9, 1.0),
        (&default, Vector3::new(0.0, -10.0, 0.0), 0.0, 1.0),
        (&grippy, Vector3::new(-11.0, 0.0, 0.0), 1.0, 0.8 * 0.8 / 0.5),
    ] {
        let f = wind_force(p, &p.resting_on_ground(0.0, 0.0, 0.0), &wind) / (p.ground.friction * weight);
        assert!(f > lower && f < upper, "wind {wind:?}: {f} μ_k m g");
        let (drift, settled, a, x) = stand(p, &wind);
        assert!(drift < 1e-3, "wind {wind:?}: drift {drift} m over 10 s");
        // The elastic deflection and the lean: centimetres, not a slide.
        assert!(settled.norm() < 0.05, "{settled:?}");
        // Every touching point stuck (the upwind fin point may lift: the aircraft leans).
        assert!(a.points.iter().all(|q| q.grip != Grip::Slipping), "{a:?}");
        assert!(a.points.iter().filter(|q| q.grip == Grip::Stuck).count() >= 3, "{a:?}");
        assert!(x.fixed_rows::<3>(U).norm() < 1e-6);
    }
}

/// Sliding on the gear without air from 3 m/s along the span: the deceleration is kinetic
/// friction μ_k g, measured from the speeds 0.1 s and 0.5 s into the slide, to 1 %; then it
/// stops near v0²/(2 μ_k g) and sticks. (Along the span the gear's base, ±0.4 m, keeps the
/// aircraft on its four points: μ_k times the CG's 0.45 m height is less than the base.
/// Belly first, over the fins' ±0.25 m, the same slide tips it over.)
#[test]
fn a_slide_decelerates_with_kinetic_friction() {
    let p = vacuum();
    for heading_of_slide in [90.0f64, 270.0] {
        let (mut x, mut a) = at_rest(&p);
        let psi = heading_of_slide.to_radians();
        let c = dcm_earth_to_body(&x.fixed_rows::<4>(Q1).into_owned());
        let v0 = 3.0;
        x.fixed_rows_mut::<3>(U)
            .copy_from(&(c * Vector3::new(v0 * psi.cos(), v0 * psi.sin(), 0.0)));
        let speed = |x: &StateVector| {
            let c = dcm_earth_to_body(&x.fixed_rows::<4>(Q1).into_owned());
            c.tr_mul(&x.fixed_rows::<3>(U).into_owned()).xy().norm()
        };
        let h = 0.02;
        fly(&p, &mut x, &mut a, &Vector3::zeros(), h, 0.1);
        let v1 = speed(&x);
        fly(&p, &mut x, &mut a, &Vector3::zeros(), h, 0.4);
        let v2 = speed(&x);
        let decel = (v1 - v2) / 0.4;
        let expected = p.ground.friction * p.airframe.gravity;
        assert!(
            (decel / expected - 1.0).abs() < 0.01,
            "slide towards {heading_of_slide} deg: {decel} m/s² against μ_k g = {expected}"
        );
        fly(&p, &mut x, &mut a, &Vector3::zeros(), h, 3.0);
        assert!(speed(&x) < 1e-3, "{}", speed(&x));
        let stopped = horizontal(&x);
        fly(&p, &mut x, &mut a, &Vector3::zeros(), h, 5.0);
        assert!((horizontal(&x) - stopped).norm() < 1e-3);
        // Stopped near v0²/(2 μ_k g) from the start.
        let d = stopped.norm() / (v0 * v0 / (2.0 * expected));
        assert!((0.9..1.1).contains(&d), "{d}");
    }
}

/// Mechanical energy: kinetic (translation and rotation), potential, the normal springs' and
/// the tangential springs' (anchors).
fn energy(p: &Plant, x: &StateVector, a: &ContactAnchors) -> f64 {
    let af = &p.airframe;
    let g = &p.ground;
    let v = x.fixed_rows::<3>(U).norm_squared();
    let rot = af.i_xx * x[P] * x[P] + af.i_yy * x[Q] * x[Q] + af.i_zz * x[R] * x[R];
    let c = dcm_earth_to_body(&x.fixed_rows::<4>(Q1).into_owned());
    let pos = Vector3::new(x[POS_N], x[POS_E], x[POS_D]);
    let normal: f64 = g
        .points(af)
        .iter()
        .map(|r| (pos + c.tr_mul(r)).z - g.height)
        .filter(|d| *d > 0.0)
        .map(|d| 0.5 * g.stiffness * d * d)
        .sum();
    0.5 * af.mass * v + 0.5 * rot - af.mass * af.gravity * x[POS_D] + normal + a.spring_energy(g, af, x)
}

/// Drops onto the gear, the nose and a wing tip with sideways speed, spin and tilt, without
/// air and thrust: every state and anchor stays finite, the energy never grows from one
/// communication step to the next (the springs' and the anchors' updates dissipate), and
/// every drop ends at rest.
#[test]
fn contact_transitions_dissipate_and_stay_finite() {
    let p = vacuum();
    let g = p.ground;
    for (k, (pitch_deg, roll_deg, sideways, rate)) in [
        (90.0, 0.0, 2.0, 0.0),
        (80.0, 10.0, 4.0, 1.0),
        (45.0, 30.0, 6.0, -2.0),
        (0.0, 0.0, 3.0, 0.5),
        (-30.0, 60.0, 1.0, 3.0),
        (90.0, 0.0, 0.0, 0.0),
    ]
    .into_iter()
    .enumerate()
    {
        let mut x = StateVector::zeros();
        let q = quat_from_euler_321(f64::to_radians(roll_deg), f64::to_radians(pitch_deg), k as f64);
        x.fixed_rows_mut::<4>(Q1).copy_from(&q);
        x[POS_D] = g.height - 1.5;
        let c = dcm_earth_to_body(&q);
        x.fixed_rows_mut::<3>(U)
            .copy_from(&(c * Vector3::new(sideways, 0.5 * sideways, 1.0)));
        x[P] = rate;
        x[Q] = -rate;
        let mut a = ContactAnchors::FREE;
        let mut e = energy(&p, &x, &a);
        for step in 0..1000 {
            p.advance_in_contact(&mut x, &mut a, &InputVector::zeros(), &Vector3::zeros(), 0.02)
                .unwrap();
            assert!(x.iter().all(|v| v.is_finite()), "drop {k}, step {step}: {x:?}");
            assert!(a.points.iter().all(|q| q.n.is_finite() && q.e.is_finite()));
            let e_new = energy(&p, &x, &a);
            assert!(e_new <= e + 1e-6, "drop {k}, step {step}: energy {e} -> {e_new} J");
            e = e_new;
        }
        assert!(
            x.fixed_rows::<3>(U).norm() < 1e-2 && x.fixed_rows::<3>(P).norm() < 1e-2,
            "drop {k}: {x:?}"
        );
    }
}

/// The same stand in wind (11 m/s, μ_s = 0.8) and the same slide with communication steps 5, 20 and 40 ms and a
/// finer integration step (2.5 ms): the standing position agrees to 0.1 mm, the slide's
/// stopping point to 1 %.
#[test]
fn the_contact_does_not_depend_on_the_step() {
    let mut stand = Vec::new();
    let mut slide = Vec::new();
    for (h, step) in [(0.005, None), (0.02, None), (0.04, None), (0.02, Some(0.0025))] {
        let mut p = plant();
        if let Some(s) = step {
            p.integration_step = s;
        }
        p.ground.static_friction = 0.8;
        let (mut x, mut a) = at_rest(&p);
        fly(&p, &mut x, &mut a, &Vector3::new(-11.0, 0.0, 0.0), h, 8.0);
        stand.push(horizontal(&x));
        let mut pv = vacuum();
        pv.integration_step = p.integration_step;
        let (mut x, mut a) = at_rest(&pv);
        let c = dcm_earth_to_body(&x.fixed_rows::<4>(Q1).into_owned());
        x.fixed_rows_mut::<3>(U).copy_from(&(c * Vector3::new(2.0, 1.0, 0.0)));
        fly(&pv, &mut x, &mut a, &Vector3::zeros(), h, 3.0);
        slide.push(horizontal(&x));
    }
    for k in 1..stand.len() {
        assert!((stand[k] - stand[0]).norm() < 1e-4, "{stand:?}");
        assert!((slide[k] - slide[0]).norm() < 0.01 * slide[0].norm(), "{slide:?}");
    }
}

/// Standing stuck on the gear costs about what flight costs: at most 40 right-hand sides per
/// 20 ms in still air and in 5 and 10 m/s (measured 19, 20 and 31; airborne 19).
#[test]
fn standing_stuck_costs_what_flight_costs() {
    let p = plant();
    for w in [0.0, 5.0, 10.0] {
        let (mut x, mut a) = at_rest(&p);
        let mut evals = 0u64;
        for _ in 0..500 {
            p.advance_counting_in_contact(
                &mut x,
                &mut a,
                &InputVector::zeros(),
                &Vector3::new(-w, 0.0, 0.0),
                0.02,
                &mut evals,
            )
            .unwrap();
        }
        let per_step = evals as f64 / 500.0;
        assert!(per_step <= 40.0, "wind {w} m/s: {per_step} right-hand sides per 20 ms");
    }
}
