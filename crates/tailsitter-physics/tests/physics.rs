//! Physics tests: invariants, closed forms, trims, symmetry, step independence, errors.

use approx::assert_relative_eq;
use nalgebra::{Matrix3, SMatrix, Vector3, Vector4};
use tailsitter_physics::attitude::{rot_x, rot_y, rot_z};
use tailsitter_physics::idx::*;
use tailsitter_physics::*;

fn plant() -> Plant {
    Plant::new(Airframe::default())
}

fn quat(x: &StateVector) -> Vector4<f64> {
    x.fixed_rows::<4>(Q1).into_owned()
}

/// Airframe with no air: no aerodynamic force or moment at all.
fn vacuum() -> Plant {
    Plant::new(Airframe {
        air_density: 0.0,
        ..Airframe::default()
    })
}

fn zero_wind() -> Vector3<f64> {
    Vector3::zeros()
}

#[test]
fn validate_names_the_parameter() {
    assert!(Airframe::default().validate().is_ok());
    let e = Airframe {
        mass: 0.0,
        ..Airframe::default()
    }
    .validate()
    .unwrap_err()
    .to_string();
    assert!(e.contains("mass"), "{e}");
    let e = Airframe {
        i_yy: f64::NAN,
        ..Airframe::default()
    }
    .validate()
    .unwrap_err()
    .to_string();
    assert!(e.contains("i_yy"), "{e}");
    let e = Airframe {
        wing_area: -1.0,
        ..Airframe::default()
    }
    .validate()
    .unwrap_err()
    .to_string();
    assert!(e.contains("wing_area"), "{e}");
    let e = Airframe {
        thrust_min: 200.0,
        ..Airframe::default()
    }
    .validate()
    .unwrap_err()
    .to_string();
    assert!(e.contains("thrust_min"), "{e}");
    let e = Airframe {
        c_m_de_a1: f64::INFINITY,
        ..Airframe::default()
    }
    .validate()
    .unwrap_err()
    .to_string();
    assert!(e.contains("c_m_de_a1"), "{e}");
}

#[test]
fn coefficient_interpolation() {
    let a = Airframe::default();
    assert_eq!(a.coefficients(0.0).c_l_beta, a.c_l_beta_a0);
    assert_relative_eq!(a.coefficients(a.alpha_1).c_l_beta, a.c_l_beta_a1, epsilon = 1e-15);
    assert_relative_eq!(
        a.coefficients(0.5 * a.alpha_1).c_L_alpha,
        0.5 * (a.c_L_alpha_a0 + a.c_L_alpha_a1),
        epsilon = 1e-12
    );
    // Clamped beyond the limit.
    assert_eq!(a.coefficients(1.0).c_n_r, a.coefficients(a.alpha_interp_limit).c_n_r);
    assert_eq!(a.coefficients(-1.0).c_n_r, a.coefficients(-a.alpha_interp_limit).c_n_r);
}

#[test]
fn dcm_matches_euler_products_and_inverse() {
    for &(phi, theta, psi) in &[(0.3, -0.4, 2.0), (-1.2, 1.1, -2.9), (0.0, 0.0, 0.0), (2.5, 0.2, 0.7)] {
        let q = quat_from_euler_321(phi, theta, psi);
        assert_relative_eq!(q.norm(), 1.0, epsilon = 1e-14);
        let c = dcm_earth_to_body(&q);
        // (A.2.5) as the product, not the printed expansion.
        let c321 = rot_x(phi) * rot_y(theta) * rot_z(psi);
        assert_relative_eq!(c, c321, epsilon = 1e-14);
        assert_relative_eq!(c[(0, 2)], -theta.sin(), epsilon = 1e-14);
        assert_relative_eq!(euler_321_from_quat(&q), Vector3::new(phi, theta, psi), epsilon = 1e-12);
        assert_relative_eq!(quat_from_dcm(&c), q * q[3].signum(), epsilon = 1e-14);
        // 2-3-1 round trip (A.2.6), angles in the principal range.
        let q231 = quat_from_euler_231(phi, theta.clamp(-1.0, 1.0), psi);
        let e = euler_231_from_quat(&q231);
        assert_relative_eq!(
            dcm_from_euler_231(e.x, e.y, e.z),
            dcm_earth_to_body(&q231),
            epsilon = 1e-12
        );
        assert_relative_eq!(e, Vector3::new(phi, theta.clamp(-1.0, 1.0), psi), epsilon = 1e-12);
    }
    // Vertical flight: 3-2-1 θ = 90° is 2-3-1 (φ, θ, ψ) = (0, 0, 90°).
    let q = quat_from_euler_321(0.0, std::f64::consts::FRAC_PI_2, 0.0);
    assert_relative_eq!(
        euler_231(&q),
        Vector3::new(0.0, 0.0, std::f64::consts::FRAC_PI_2),
        epsilon = 1e-12
    );
}

#[test]
fn quaternion_kinematics_match_dcm_kinematics() {
    // Ċ^BE = −[ω×] C^BE for body rates ω.
    let q = quat_from_euler_321(0.4, -0.7, 1.3);
    let w = Vector3::new(0.3, -1.1, 0.8);
    let qd = quat_derivative(&q, &w);
    let h = 1e-6;
    let cdot = (dcm_earth_to_body(&(q + qd * h)) - dcm_earth_to_body(&(q - qd * h))) / (2.0 * h);
    let expected: Matrix3<f64> = -w.cross_matrix() * dcm_earth_to_body(&q);
    assert_relative_eq!(cdot, expected, epsilon = 1e-8);
    assert_relative_eq!(q.dot(&qd), 0.0, epsilon = 1e-15);
}

#[test]
fn free_fall_matches_closed_form() {
    let p = vacuum();
    let mut x = StateVector::zeros();
    x.fixed_rows_mut::<4>(Q1)
        .copy_from(&quat_from_euler_321(0.2, 0.5, -0.3));
    let v0_ned = Vector3::new(3.0, -2.0, -5.0);
    let c = dcm_earth_to_body(&quat(&x));
    x.fixed_rows_mut::<3>(U).copy_from(&(c * v0_ned));
    let u = InputVector::zeros();
    let t = 2.0;
    p.advance(&mut x, &u, &zero_wind(), t).unwrap();
    let g = p.airframe.gravity;
    let expected = v0_ned * t + Vector3::new(0.0, 0.0, 0.5 * g * t * t);
    assert_relative_eq!(x.fixed_rows::<3>(POS_N).into_owned(), expected, epsilon = 1e-9);
    let y = p.outputs(&x, &u, &zero_wind());
    assert_relative_eq!(y.vel_ned, v0_ned + Vector3::new(0.0, 0.0, g * t), epsilon = 1e-9);
    assert_relative_eq!(y.specific_force_body.norm(), 0.0, epsilon = 1e-15);
}

#[test]
fn torque_free_rotation_conserves_energy_and_momentum() {
    let p = vacuum();
    let a = &p.airframe;
    let mut x = StateVector::zeros();
    x[Q4] = 1.0;
    x[P] = 1.5;
    x[Q] = -2.0;
    x[R] = 3.0;
    let inertia = Vector3::new(a.i_xx, a.i_yy, a.i_zz);
    let energy = |x: &StateVector| {
        let w = Vector3::new(x[P], x[Q], x[R]);
        0.5 * w.component_mul(&inertia).dot(&w)
    };
    let momentum_earth = |x: &StateVector| {
        let w = Vector3::new(x[P], x[Q], x[R]);
        dcm_earth_to_body(&quat(x)).tr_mul(&w.component_mul(&inertia))
    };
    let e0 = energy(&x);
    let h0 = momentum_earth(&x);
    let u = InputVector::zeros();
    for _ in 0..250 {
        p.advance(&mut x, &u, &zero_wind(), 0.02).unwrap();
        assert_relative_eq!(energy(&x), e0, max_relative = 1e-9);
        assert_relative_eq!(momentum_earth(&x), h0, epsilon = 1e-8);
        assert_relative_eq!(quat(&x).norm(), 1.0, epsilon = 1e-14);
    }
    // It really tumbled.
    assert!((x[P] - 1.5).abs() > 0.1);
}

#[test]
fn quaternion_norm_stays_one_in_a_manoeuvre() {
    let p = plant();
    let trim = p.trim_level(25.0).unwrap();
    let mut x = trim.state;
    let mut u = trim.inputs;
    u[AILERON_CMD] = 0.1;
    u[RUDDER_CMD] = -0.05;
    u[ELEVATOR_CMD] -= 0.05;
    for _ in 0..100 {
        p.advance(&mut x, &u, &zero_wind(), 0.02).unwrap();
        assert!((quat(&x).norm() - 1.0).abs() < 1e-14);
    }
    assert!(x[P].abs() > 0.01, "manoeuvre happened");
}

#[test]
fn symmetric_flight_has_no_lateral_motion() {
    let p = plant();
    for trim in [p.trim_level(25.0).unwrap(), p.trim_vertical_climb(3.0).unwrap()] {
        let mut x = trim.state;
        let mut u = trim.inputs;
        u[ELEVATOR_CMD] += 0.1;
        u[THRUST_CMD] += 20.0;
        u[FLAP_COLLECTIVE_CMD] = 0.05;
        for _ in 0..100 {
            p.advance(&mut x, &u, &zero_wind(), 0.02).unwrap();
            for k in [
                POS_E,
                V,
                P,
                R,
                Q1,
                Q3,
                AILERON,
                RUDDER,
                FLAP_DIFFERENTIAL,
                VERTICAL_FLAP,
            ] {
                assert!(x[k].abs() < 1e-12, "{} = {}", idx::STATE_NAMES[k], x[k]);
            }
        }
        assert!(
            x[Q].abs() > 1e-3 || (x[U] - trim.state[U]).abs() > 0.1,
            "longitudinal motion happened"
        );
    }
}

#[test]
fn thrust_lag_matches_first_order_step() {
    let p = plant();
    let mut x = p.trim_vertical_climb(0.0).unwrap().state;
    x[THRUST] = 0.0;
    let mut u = InputVector::zeros();
    u[THRUST_CMD] = 50.0;
    let tau = p.airframe.tau_thrust;
    let mut t = 0.0;
    for _ in 0..25 {
        p.advance(&mut x, &u, &zero_wind(), 0.02).unwrap();
        t += 0.02;
        // DP5 with 20/3 ms steps on a 0.1 s lag: one step's error 50·|R(z) − eᶻ| with
        // R(z) − eᶻ ≈ z⁶/3600 (DP5's stability polynomial has z⁶/600), z = h/τ = 1/15: ≈ 1e-9 N.
        assert_relative_eq!(x[THRUST], 50.0 * (1.0 - (-t / tau).exp()), epsilon = 1e-7);
    }
    // Commands beyond the limits are clamped.
    u[THRUST_CMD] = 1e4;
    p.advance(&mut x, &u, &zero_wind(), 2.0).unwrap();
    assert!(x[THRUST] <= p.airframe.thrust_max && x[THRUST] > p.airframe.thrust_max - 1e-6);
}

#[test]
fn servo_slew_and_limits() {
    // In vacuum: the servos are decoupled from the body, which then cannot tumble.
    let p = vacuum();
    let a = p.airframe;
    let lim = a.deflection_limit;
    let mut x = p.trim_vertical_climb(0.0).unwrap().state;
    for k in SURFACES..SURFACES + 6 {
        x[k] = lim;
    }
    let mut u = p.trim_vertical_climb(0.0).unwrap().inputs;
    for k in SURFACES_CMD..SURFACES_CMD + 6 {
        u[k] = -1.0; // beyond the limit: clamped to −lim
    }
    // Rate-limited start: error 2 lim / τ ≫ rate limit.
    let dt = 0.01;
    let mut prev = x;
    let mut t = 0.0;
    for _ in 0..100 {
        p.advance(&mut x, &u, &zero_wind(), dt).unwrap();
        t += dt;
        for k in SURFACES..SURFACES + 6 {
            assert!(x[k].abs() <= lim + 1e-15, "deflection limit");
            assert!(
                (x[k] - prev[k]).abs() <= a.servo_rate_limit * dt * (1.0 + 1e-12),
                "slew rate"
            );
            if t <= 0.05 + 1e-12 {
                assert_relative_eq!(x[k], lim - a.servo_rate_limit * t, epsilon = 1e-12);
            }
        }
        prev = x;
    }
    for k in SURFACES..SURFACES + 6 {
        assert_relative_eq!(x[k], -lim, epsilon = 1e-6);
    }
    // First-order response inside the rate limit: small step of 0.01 rad.
    let mut x2 = x;
    let mut u2 = u;
    u2[ELEVATOR_CMD] = -lim + 0.01;
    x2[ELEVATOR] = -lim;
    p.advance(&mut x2, &u2, &zero_wind(), 0.05).unwrap();
    assert_relative_eq!(x2[ELEVATOR], -lim + 0.01 * (1.0 - (-1.0f64).exp()), epsilon = 1e-9);
}

#[test]
fn induced_velocity_satisfies_momentum_theory() {
    let a = Airframe::default();
    let k = 2.0 * a.air_density * a.prop_disc_area;
    for &(v, vx, t) in &[
        (0.0, 0.0, 88.29),
        (3.0, 3.0, 88.376),
        (25.0, 25.0 * 0.13f64.cos(), 9.3),
        (10.0, -10.0, 88.0), // axial descent
        (2.0, -2.0, 88.0),
        (5.0, -1.0, 40.0), // oblique, descending
        (12.0, 0.0, 60.0), // edgewise
        (40.0, 40.0, 150.0),
        (1e-3, 1e-3, 1e-6),
    ] {
        let w = a.induced_velocity(v, vx, t);
        assert!(w >= 0.0);
        let vprime = (w * w + 2.0 * vx * w + v * v).sqrt();
        assert_relative_eq!(k * w * vprime, t, max_relative = 1e-10);
        if vx == v || vx == -v {
            assert_relative_eq!(a.induced_velocity_axial(vx, t), w, max_relative = 1e-10);
        }
        if vx == v {
            // (2.3.18): T = ρA(V0 + w)2w for axial flow.
            assert_relative_eq!(
                a.air_density * a.prop_disc_area * (v + w) * 2.0 * w,
                t,
                max_relative = 1e-10
            );
        }
        if vx < 0.0 && vx == -v {
            assert!(w > -vx, "normal working state branch");
        }
    }
    // Hover closed form.
    assert_relative_eq!(
        a.induced_velocity(0.0, 0.0, 88.29),
        (88.29 / k).sqrt(),
        max_relative = 1e-12
    );
    assert_eq!(a.induced_velocity(10.0, 10.0, 0.0), 0.0);
}

/// The largest momentum-theory root to full precision: f(w) = w²(w² + 2V_x w + V̄²) − k² is
/// ≥ 0 at w_axial; scan down from there on a grid of 10⁵ points for the first f < 0, then
/// bisect that interval (200 halvings).
fn induced_velocity_by_bisection(a: &Airframe, v: f64, vx: f64, t: f64) -> f64 {
    let k = t / (2.0 * a.air_density * a.prop_disc_area);
    let f = |w: f64| w * w * (w * w + 2.0 * vx * w + v * v) - k * k;
    let w_ax = 0.5 * (-vx + (vx * vx + 4.0 * k).sqrt());
    let n = 100_000;
    let mut hi = w_ax;
    let mut lo = 0.0;
    for i in (0..n).rev() {
        let w = w_ax * i as f64 / n as f64;
        if f(w) < 0.0 {
            lo = w;
            break;
        }
        hi = w;
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if f(mid) > 0.0 {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    0.5 * (lo + hi)
}

/// How closely the induced velocity `exact` at airspeed `v` (axial component `vx`) is
/// determined in f64: f is evaluated to ≈ ε · (sum of |terms|), so a root is determined to
/// that over |f'| (ill-conditioned near V' → 0 in descent).
fn induced_velocity_rounding_limit(exact: f64, v: f64, vx: f64) -> f64 {
    let terms = exact * exact * (exact * exact + 2.0 * vx.abs() * exact + v * v);
    let der = (4.0 * exact.powi(3) + 6.0 * vx * exact * exact + 2.0 * v * v * exact).abs();
    4e-15 * exact + 16.0 * f64::EPSILON * terms / der
}

#[test]
fn induced_velocity_is_the_root_to_rounding() {
    // Halley's early stop must not cost accuracy: compare with bisection over forward,
    // oblique, edgewise and descending flow, low and high thrust.
    let a = Airframe::default();
    for v in [0.0, 0.7, 3.0, 12.0, 25.0, 45.0] {
        for c in [1.0, 0.99, 0.9, 0.5, 0.0, -0.3, -0.8, -1.0] {
            for t in [0.05, 2.0, 9.3, 40.0, 88.3, 150.0] {
                let vx = v * c;
                let w = a.induced_velocity(v, vx, t);
                let exact = induced_velocity_by_bisection(&a, v, vx, t);
                let tol = induced_velocity_rounding_limit(exact, v, vx);
                assert!((w - exact).abs() <= tol, "V = {v}, V_x = {vx}, T = {t}: {w} vs {exact}");
            }
        }
    }
}

#[test]
fn warm_started_induced_velocity_is_the_same_root() {
    // Starts from 0.5 % to 4× the root, and in steep axial descent (several positive roots:
    // the warm start must not pick another branch), give the cold solve's root to rounding.
    let a = Airframe::default();
    for v in [0.7, 3.0, 12.0, 25.0, 45.0] {
        for c in [0.99, 0.9, 0.5, 0.0, -0.3, -0.8, -0.97, -0.999] {
            for t in [0.05, 2.0, 9.3, 40.0, 88.3, 150.0] {
                let vx = v * c;
                let cold = a.induced_velocity(v, vx, t);
                let exact = induced_velocity_by_bisection(&a, v, vx, t);
                let tol = induced_velocity_rounding_limit(exact, v, vx);
                for f in [0.25, 0.9, 0.995, 1.0, 1.005, 1.1, 4.0] {
                    let warm = a.induced_velocity_from(v, vx, t, f * cold);
                    assert!(
                        (warm - exact).abs() <= tol,
                        "V = {v}, V_x = {vx}, T = {t}, start {f} w: {warm} vs {exact} (cold {cold})"
                    );
                }
            }
        }
    }
}

proptest::proptest! {
    #[test]
    fn induced_velocity_any_condition(v in 0.0f64..80.0, c in -1.0f64..1.0, t in 0.01f64..150.0) {
        let a = Airframe::default();
        let vx = v * c;
        let w = a.induced_velocity(v, vx, t);
        let k = 2.0 * a.air_density * a.prop_disc_area;
        let vprime = (w * w + 2.0 * vx * w + v * v).sqrt();
        proptest::prop_assert!(w > 0.0);
        proptest::prop_assert!((k * w * vprime - t).abs() <= 1e-9 * t);
    }
}

fn assert_steady(p: &Plant, trim: &Trim, what: &str) {
    let d = p.derivatives(&trim.state, &trim.inputs, &zero_wind());
    for k in U..N_STATES {
        assert!(d[k].abs() < 1e-8, "{what}: d{}/dt = {}", idx::STATE_NAMES[k], d[k]);
    }
    let mut x = trim.state;
    p.advance(&mut x, &trim.inputs, &zero_wind(), 0.5).unwrap();
    for k in U..N_STATES {
        assert!(
            (x[k] - trim.state[k]).abs() < 1e-7,
            "{what}: {} drifted {} -> {}",
            idx::STATE_NAMES[k],
            trim.state[k],
            x[k]
        );
    }
    let vel = p.outputs(&trim.state, &trim.inputs, &zero_wind()).vel_ned;
    assert_relative_eq!(x.fixed_rows::<3>(POS_N).into_owned(), vel * 0.5, epsilon = 1e-7);
}

#[test]
fn level_trim_25() {
    let p = plant();
    let t = p.trim_level(25.0).unwrap();
    println!(
        "level 25 m/s: α = {:.3}°, δe = {:.3}°, T = {:.4} N, w = {:.3} m/s",
        t.alpha.to_degrees(),
        t.elevator.to_degrees(),
        t.thrust,
        t.induced_velocity
    );
    // docs/DESIGN.md §4: α ≈ 7.5°, δe ≈ −6°.
    assert!((t.alpha.to_degrees() - 7.5).abs() < 0.3, "α = {}", t.alpha.to_degrees());
    assert!(
        (t.elevator.to_degrees() + 6.0).abs() < 0.5,
        "δe = {}",
        t.elevator.to_degrees()
    );
    assert_relative_eq!(t.theta, t.alpha, epsilon = 1e-12);
    assert!(t.thrust > 5.0 && t.thrust < 15.0);
    assert_relative_eq!(t.airspeed, 25.0, epsilon = 1e-12);
    assert_steady(&p, &t, "level 25");
    // The accelerometer reads −g in body axes in steady flight.
    let y = p.outputs(&t.state, &t.inputs, &zero_wind());
    let g_body = dcm_earth_to_body(&quat(&t.state)) * Vector3::new(0.0, 0.0, p.airframe.gravity);
    assert_relative_eq!(y.specific_force_body, -g_body, epsilon = 1e-9);
}

#[test]
fn vertical_climb_and_hover_trims() {
    let p = plant();
    let a = p.airframe;
    let mg = a.mass * a.gravity;
    let t = p.trim_vertical_climb(3.0).unwrap();
    println!(
        "vertical 3 m/s: T = {:.6} N, w = {:.4} m/s, δe = {:.3e} rad, θ = {:.6}°",
        t.thrust,
        t.induced_velocity,
        t.elevator,
        t.theta.to_degrees()
    );
    // T = m g + drag (C_L = 0 at α = 0): q̄ S C_D0.
    assert_relative_eq!(
        t.thrust,
        mg + 0.5 * a.air_density * 9.0 * a.wing_area * a.c_D0,
        max_relative = 1e-9
    );
    assert!((t.induced_velocity - 10.0).abs() < 1.0);
    assert!(t.elevator.abs() < 1e-9);
    assert_relative_eq!(t.theta, std::f64::consts::FRAC_PI_2, epsilon = 1e-9);
    let y = p.outputs(&t.state, &t.inputs, &zero_wind());
    assert_relative_eq!(y.vel_ned, Vector3::new(0.0, 0.0, -3.0), epsilon = 1e-9);
    assert_steady(&p, &t, "vertical 3");

    let h = p.trim_vertical_climb(0.0).unwrap();
    assert_relative_eq!(h.thrust, mg, max_relative = 1e-9);
    let k = 2.0 * a.air_density * a.prop_disc_area;
    assert_relative_eq!(h.induced_velocity, (mg / k).sqrt(), max_relative = 1e-9);
    assert_steady(&p, &h, "hover");
    assert!(p.trim_vertical_climb(-1.0).is_err());
    assert!(p.trim_level(0.0).is_err());
}

#[test]
fn hover_outputs_finite_and_well_defined() {
    let p = plant();
    let h = p.trim_vertical_climb(0.0).unwrap();
    let mut x = h.state;
    x[P] = 0.3;
    x[Q] = -0.2;
    x[R] = 0.1;
    let y = p.outputs(&x, &h.inputs, &zero_wind());
    assert_eq!((y.airspeed, y.alpha, y.beta), (0.0, 0.0, 0.0));
    assert!(y.specific_force_body.iter().all(|v| v.is_finite()));
    let d = p.derivatives(&x, &h.inputs, &zero_wind());
    assert!(d.iter().all(|v| v.is_finite()));
    // Tiny airspeeds in any direction: finite, bounded α/β.
    for dir in [
        Vector3::new(0.0, 0.0, 1.0),
        Vector3::new(-1.0, 0.0, 0.0),
        Vector3::new(0.0, -1.0, 0.0),
    ] {
        for s in [1e-12, 1e-6, 1e-2] {
            let mut x = h.state;
            x.fixed_rows_mut::<3>(U).copy_from(&(dir * s));
            let y = p.outputs(&x, &h.inputs, &zero_wind());
            assert!(y.alpha.is_finite() && y.beta.is_finite() && y.alpha.abs() <= std::f64::consts::PI);
            assert!(p.derivatives(&x, &h.inputs, &zero_wind()).iter().all(|v| v.is_finite()));
        }
    }
    // Hover: the elevator in the slip-stream still gives a pitching moment.
    let mut u = h.inputs;
    u[ELEVATOR_CMD] = 0.1;
    let mut x = h.state;
    x[ELEVATOR] = 0.1;
    assert!(p.derivatives(&x, &u, &zero_wind())[Q] < -1.0);
}

#[test]
fn wind_is_subtracted_in_earth_axes() {
    let p = plant();
    let t = p.trim_level(25.0).unwrap();
    let wind = Vector3::new(-5.0, 3.0, 1.0);
    let mut x = t.state;
    let c = dcm_earth_to_body(&quat(&x));
    // Same air-relative velocity: inertial = air + wind.
    let v = x.fixed_rows::<3>(U) + c * wind;
    x.fixed_rows_mut::<3>(U).copy_from(&v);
    let y = p.outputs(&x, &t.inputs, &wind);
    assert_relative_eq!(y.airspeed, 25.0, epsilon = 1e-12);
    assert_relative_eq!(y.alpha, t.alpha, epsilon = 1e-12);
    let d = p.derivatives(&x, &t.inputs, &wind);
    // Only the transport term ω × v differs (ω = 0 here): steady.
    assert!(d.rows(U, N_STATES - U).amax() < 1e-8);
    assert_relative_eq!(y.vel_ned, Vector3::new(25.0, 0.0, 0.0) + wind, epsilon = 1e-9);
}

#[test]
fn communication_step_independence() {
    let p = plant();
    let t = p.trim_level(25.0).unwrap();
    let mut u = t.inputs;
    u[ELEVATOR_CMD] -= 0.05;
    u[AILERON_CMD] = 0.05;
    u[THRUST_CMD] += 10.0;
    let wind = Vector3::new(2.0, -1.0, 0.5);
    let run = |p: &Plant, h: f64| {
        let mut x = t.state;
        let n = (1.2 / h).round() as usize;
        for _ in 0..n {
            p.advance(&mut x, &u, &wind, h).unwrap();
        }
        x
    };
    // Communication steps that are multiples of the integration step (20/3 ms by default)
    // integrate with the very same internal steps: equal up to round-off.
    let step = p.integration_step;
    let x1 = run(&p, step);
    let x20 = run(&p, 0.020);
    let x40 = run(&p, 0.040);
    assert!((x1 - t.state).amax() > 0.1, "it moved");
    assert!((x1 - x20).amax() < 1e-9, "{}", (x1 - x20).amax());
    assert!((x1 - x40).amax() < 1e-9, "{}", (x1 - x40).amax());
    // With a 5 ms step: 5, 10 and 20 ms communication steps.
    let mut p5 = p.clone();
    p5.integration_step = 0.005;
    let y5 = run(&p5, 0.005);
    for h in [0.010, 0.020] {
        let y = run(&p5, h);
        assert!((y5 - y).amax() < 1e-9, "h = {h}: {}", (y5 - y).amax());
    }
    // Steps that are not multiples (1, 2, 10, 12.5 ms) differ by the integration error only.
    for h in [0.001, 0.002, 0.010, 0.0125] {
        let x = run(&p, h);
        assert!((x1 - x).amax() < 1e-6, "h = {h}: {}", (x1 - x).amax());
    }
}

#[test]
fn non_finite_and_envelope_errors() {
    let p = plant();
    let t = p.trim_level(25.0).unwrap();
    let mut x = t.state;
    let mut u = t.inputs;
    u[THRUST_CMD] = f64::NAN;
    let e = p.advance(&mut x, &u, &zero_wind(), 0.02).unwrap_err();
    assert!(e.to_string().contains("thrust_cmd"), "{e}");
    assert_eq!(x, t.state, "state untouched");
    let e = p
        .advance(&mut x, &t.inputs, &Vector3::new(0.0, f64::INFINITY, 0.0), 0.02)
        .unwrap_err();
    assert!(e.to_string().contains("wind_e"), "{e}");
    x[U] = f64::NAN;
    let e = p.advance(&mut x, &t.inputs, &zero_wind(), 0.02).unwrap_err();
    assert_eq!(e.to_string(), "state u is NaN");
    let mut x = t.state;
    x[U] = 500.0;
    let e = p.advance(&mut x, &t.inputs, &zero_wind(), 0.02).unwrap_err();
    assert!(e.to_string().contains("speed"), "{e}");
    let mut x = t.state;
    let e = p
        .advance(&mut x, &t.inputs, &Vector3::new(-300.0, 0.0, 0.0), 0.02)
        .unwrap_err();
    assert!(e.to_string().starts_with("airspeed"), "{e}");
    let mut x = t.state;
    x[R] = 60.0;
    assert!(p
        .advance(&mut x, &t.inputs, &zero_wind(), 0.02)
        .unwrap_err()
        .to_string()
        .contains("r 60"));
    let mut x = t.state;
    assert!(p.advance(&mut x, &t.inputs, &zero_wind(), f64::NAN).is_err());
    assert!(p.advance(&mut x, &t.inputs, &zero_wind(), 0.0).is_ok());
}

/// Open-loop level-flight modes at 25 m/s vs the thesis (Tables 3.2/3.3).
#[test]
fn open_loop_modes_level_flight() {
    let p = plant();
    let t = p.trim_level(25.0).unwrap();
    let (a, b) = p.linearise(&t.state, &t.inputs, &zero_wind());
    // Longitudinal (u, w, q, q2, q4) and lateral (v, p, r, q1, q3) blocks decouple at a
    // symmetric trim; servo, thrust and position states only cascade (block triangular).
    let long = [U, W, Q, Q2, Q4];
    let lat = [V, P, R, Q1, Q3];
    for &i in &long {
        for &j in &lat {
            assert!(a[(i, j)].abs() < 1e-6 && a[(j, i)].abs() < 1e-6, "coupling {i},{j}");
        }
    }
    let sub = |s: [usize; 5]| SMatrix::<f64, 5, 5>::from_fn(|i, j| a[(s[i], s[j])]).complex_eigenvalues();
    let mut el: Vec<_> = sub(long).iter().copied().collect();
    let mut ed: Vec<_> = sub(lat).iter().copied().collect();
    el.sort_by(|x, y| y.im.abs().partial_cmp(&x.im.abs()).unwrap());
    ed.sort_by(|x, y| y.im.abs().partial_cmp(&x.im.abs()).unwrap());
    let short = el[0];
    let phugoid = el[2];
    let dutch = ed[0];
    let mut reals: Vec<f64> = ed[2..].iter().map(|c| c.re).filter(|r| r.abs() > 1e-6).collect();
    reals.sort_by(|x, y| x.partial_cmp(y).unwrap());
    let (roll, spiral) = (reals[0], reals[1]);
    println!("mode          this model             thesis (Tables 3.2/3.3)");
    println!(
        "phugoid       {:8.4} ± {:7.4}i    -0.006 ± 0.462i",
        phugoid.re,
        phugoid.im.abs()
    );
    println!(
        "short period  {:8.4} ± {:7.4}i   -10.44 ± 24.2i",
        short.re,
        short.im.abs()
    );
    println!(
        "Dutch roll    {:8.4} ± {:7.4}i    -3.33 ± 14.06i",
        dutch.re,
        dutch.im.abs()
    );
    println!("roll          {:8.4}              -10.34", roll);
    println!("spiral        {:8.4}              +0.225", spiral);
    // Short period: stable, ω_n within a factor 2 of the DESIGN estimate (≈ 18 rad/s).
    let wn_sp = short.norm();
    assert!(short.re < -3.0 && (9.0..36.0).contains(&wn_sp), "short period {short}");
    // Phugoid: lightly damped, period around 2π/0.5 s.
    assert!(
        phugoid.re.abs() < 0.2 && (0.3..0.8).contains(&phugoid.im.abs()),
        "phugoid {phugoid}"
    );
    // Dutch roll stable oscillation, roll subsidence fast, spiral slow.
    assert!(
        dutch.re < 0.0 && (5.0..25.0).contains(&dutch.im.abs()),
        "Dutch roll {dutch}"
    );
    assert!(roll < -3.0, "roll {roll}");
    assert!(spiral.abs() < 0.5, "spiral {spiral}");
    // Control effectiveness signs: +δe gives −q̇ (thesis §2.3.1), thrust raises u̇.
    assert!(b[(Q, ELEVATOR_CMD)] == 0.0 && a[(Q, ELEVATOR)] < 0.0);
    assert!(a[(U, THRUST)] > 0.0 && a[(P, AILERON)] < 0.0 && a[(R, RUDDER)] < 0.0);
}

proptest::proptest! {
    /// Any state inside the envelope (any attitude, flow direction, rates, deflections,
    /// thrust, wind) gives finite derivatives and outputs, and α, β in range.
    #[test]
    fn derivatives_and_outputs_finite_everywhere(
        angles in proptest::array::uniform3(-3.2f64..3.2),
        vel in proptest::array::uniform3(-60.0f64..60.0),
        rates in proptest::array::uniform3(-5.0f64..5.0),
        surf in proptest::array::uniform6(-0.5f64..0.5),
        thrust in 0.0f64..150.0,
        wind in proptest::array::uniform3(-10.0f64..10.0),
        scale in proptest::sample::select(vec![0.0, 1e-9, 1e-3, 1.0]),
    ) {
        let p = plant();
        let mut x = StateVector::zeros();
        x.fixed_rows_mut::<4>(Q1).copy_from(&quat_from_euler_321(angles[0], angles[1], angles[2]));
        for k in 0..3 {
            x[U + k] = vel[k] * scale;
            x[P + k] = rates[k];
        }
        x[THRUST] = thrust;
        for k in 0..6 {
            x[SURFACES + k] = surf[k];
        }
        let u = InputVector::from_fn(|i, _| if i == 0 { thrust } else { surf[i - 1] });
        let wind = Vector3::from(wind) * scale;
        let d = p.derivatives(&x, &u, &wind);
        proptest::prop_assert!(d.iter().all(|v| v.is_finite()));
        let y = p.outputs(&x, &u, &wind);
        proptest::prop_assert!(y.airspeed.is_finite() && y.induced_velocity.is_finite());
        proptest::prop_assert!(y.alpha.abs() <= std::f64::consts::PI && y.beta.abs() <= std::f64::consts::FRAC_PI_2);
        proptest::prop_assert!(y.specific_force_body.iter().all(|v| v.is_finite()));
    }
}

/// Regression: with featherweight inertias the moment residual floors at
/// round-off above the Newton tolerance; the trim must still converge.
#[test]
fn trim_converges_with_tiny_inertias() {
    let airframe = Airframe {
        i_xx: 1e-4,
        i_yy: 1e-4,
        i_zz: 1e-4,
        ..Airframe::default()
    };
    let trim = Plant::new(airframe)
        .trim_vertical_climb(3.0)
        .expect("trim with tiny inertias");
    // Independent of the inertias: climbing vertically at V = 3 m/s with α = 0 the
    // thrust carries the weight and the drag, T = m·g + ½ρV²·S·C_D0 (C_L = C_L0 = 0,
    // so no induced drag), = 88.29 + 0.086 N with the App. C numbers.
    let v = 3.0;
    let expected =
        airframe.mass * airframe.gravity + 0.5 * airframe.air_density * v * v * airframe.wing_area * airframe.c_D0;
    assert!((trim.thrust - expected).abs() < 1e-6, "{} vs {expected}", trim.thrust);
}

/// Regression (fuzzing): a huge communication step ran for minutes; it is refused at once.
#[test]
fn enormous_steps_are_refused_promptly() {
    let p = plant();
    let trim = p.trim_vertical_climb(3.0).unwrap();
    let mut x = trim.state;
    let err = p.advance(&mut x, &trim.inputs, &zero_wind(), 1e6).unwrap_err();
    assert!(err.to_string().contains("step size h"), "{err}");
    assert_eq!(x, trim.state, "state untouched");
    // The largest accepted step still integrates.
    p.advance(
        &mut x,
        &trim.inputs,
        &zero_wind(),
        MAX_SUBSTEPS * p.integration_step * 0.001,
    )
    .unwrap();
}
