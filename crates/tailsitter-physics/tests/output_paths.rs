//! The cheap paths the plant FMU takes after a step (issue 17): the outputs and the
//! derivatives from one force evaluation, the free-stream stall test that gates the
//! stall-fraction event and the airborne test that gates the contact summary, each
//! against the full computation it replaces.

use nalgebra::{Vector3, Vector4};
use tailsitter_physics::idx::*;
use tailsitter_physics::{quat_from_euler_321, AeroModel, Airframe, Ground, InputVector, Plant, StateVector};

/// States over attitudes, flow directions (attached, stalled, reversed, sideslip), rates,
/// thrust and deflections; quaternions of norm 1 and not.
fn states() -> Vec<StateVector> {
    let mut out = Vec::new();
    let mut k = 0.0;
    for (u, v, w) in [
        (25.0, 0.0, 2.0),
        (3.0, 1.0, 8.0),
        (-6.0, 0.5, 1.0),
        (0.0, 0.0, 0.0),
        (10.0, -9.0, -3.0),
        (1.0, 0.0, -12.0),
    ] {
        for (phi, theta, psi) in [(0.0, 0.1, 0.0), (0.3, 1.4, -2.0), (-2.5, -0.7, 0.4)] {
            for norm in [1.0, 1.0 + 3e-9] {
                k += 1.0;
                let mut x = StateVector::zeros();
                let q: Vector4<f64> = quat_from_euler_321(phi, theta, psi) * norm;
                x.fixed_rows_mut::<4>(Q1).copy_from(&q);
                x[POS_N] = 3.0 * k;
                x[POS_D] = -20.0 - k;
                x[U] = u;
                x[V] = v;
                x[W] = w;
                x[P] = 0.2 - 0.03 * k;
                x[Q] = -0.4 + 0.05 * k;
                x[R] = 0.1;
                x[THRUST] = 2.0 * k;
                for s in 0..6 {
                    x[SURFACES + s] = 0.01 * (k - 2.0 * s as f64);
                }
                out.push(x);
            }
        }
    }
    out
}

fn plants() -> Vec<Plant> {
    let thesis = Plant::new(Airframe::default());
    let mut global = thesis.clone();
    global.aero.model = AeroModel::Global;
    let mut grounded = global.clone();
    grounded.ground = Ground {
        height: -15.0,
        ..Ground::default()
    };
    vec![thesis, global, grounded]
}

/// Bit patterns, so that a sign of zero counts as a difference only where allowed.
fn same(a: f64, b: f64) -> bool {
    a.to_bits() == b.to_bits() || (a == 0.0 && b == 0.0)
}

#[test]
fn outputs_and_derivatives_equal_the_separate_calls() {
    let mut u = InputVector::zeros();
    u[THRUST_CMD] = 40.0;
    u[ELEVATOR_CMD] = 0.1;
    u[AILERON_CMD] = -0.05;
    let mut checked = 0;
    for plant in plants() {
        for wind in [Vector3::zeros(), Vector3::new(4.0, -2.0, 1.0)] {
            for x in states() {
                let (y, dx) = plant.outputs_and_derivatives(&x, &u, &wind);
                let y_ref = plant.outputs(&x, &u, &wind);
                let mut xn = x;
                let n = x.fixed_rows::<4>(Q1).norm();
                for k in Q1..=Q4 {
                    xn[k] /= n;
                }
                let dx_ref = plant.derivatives(&xn, &u, &wind);
                assert_eq!(y, y_ref, "outputs at {x:?}");
                for k in 0..dx.len() {
                    assert!(same(dx[k], dx_ref[k]), "ẋ[{k}] {} ≠ {} at {x:?}", dx[k], dx_ref[k]);
                }
                checked += 1;
            }
        }
    }
    assert_eq!(checked, 3 * 2 * 36);
}

#[test]
fn stall_fraction_is_positive_only_where_the_free_stream_is_separated() {
    let u = InputVector::zeros();
    let mut separated = 0;
    let mut attached = 0;
    for plant in plants() {
        for wind in [Vector3::zeros(), Vector3::new(6.0, 0.0, -1.0)] {
            for x in states() {
                let y = plant.outputs(&x, &u, &wind);
                let sep = plant.free_stream_separated(&x, &wind);
                assert!(
                    y.stall_fraction == 0.0 || sep,
                    "stall fraction {} without a separated free stream at {x:?}",
                    y.stall_fraction
                );
                if sep {
                    separated += 1;
                } else {
                    attached += 1;
                }
            }
        }
    }
    // Both branches exercised.
    assert!(separated > 20 && attached > 20, "{separated} / {attached}");
}

#[test]
fn clearly_airborne_means_no_contact_point_touches() {
    let plant = &plants()[2];
    let g = &plant.ground;
    let a = &plant.airframe;
    let mut airborne = 0;
    let mut near = 0;
    for x0 in states() {
        // From well inside the ground to well above it, through the bound in 1 mm steps.
        for i in 0..2000 {
            let mut x = x0;
            x[POS_D] = g.height - 1.0 + 1e-3 * i as f64 - 0.5;
            let cs = g.contact_state(a, &x);
            if g.clearly_airborne(a, &x) {
                airborne += 1;
                assert_eq!(cs.points, 0, "a point touches at {x:?}");
            } else {
                near += 1;
            }
        }
    }
    assert!(airborne > 1000 && near > 1000, "{airborne} / {near}");
    assert!(Ground::none().clearly_airborne(a, &states()[0]));
}

/// α (2.2.12) is musl's atan2 (the `libm` crate, no rounding-mode switches): within one unit
/// in the last place of the platform's atan2, over every quadrant, so the change of library
/// moves trajectories by rounding only.
#[test]
fn angle_of_attack_is_atan2_to_one_ulp() {
    let a = Airframe::default();
    let mut worst: f64 = 0.0;
    for i in 0..400 {
        let ang = -3.1 + 6.2 * i as f64 / 399.0;
        for speed in [0.3, 7.0, 25.0] {
            let v = Vector3::new(
                speed * ang.cos(),
                0.1 * speed * (0.3 * i as f64).sin(),
                speed * ang.sin(),
            );
            let fm = a.forces_moments(&v, &Vector3::zeros(), 10.0, &Default::default());
            let reference = v.z.atan2(v.x);
            let ulp = f64::EPSILON * reference.abs();
            worst = worst.max((fm.alpha - reference).abs() / ulp);
        }
    }
    assert!(worst <= 1.0, "α differs from atan2 by {worst} ulp");
}
