//! Physics bounds of an upright landing in wind, from the plant alone (no controller):
//! `tsd_wind_bounds [SPEEDS]`.
//!
//! 1. **Hover at rest in a steady wind**: the smallest tilt from the vertical at which the
//!    airframe can hang still (zero inertial velocity and rates) with the forces and the
//!    trimmed moment balanced, over every thrust (0 … thrust_max) and surface deflection
//!    (±deflection_limit). Face-on (belly into the wind, nose tilted into it about the
//!    body y axis; unknowns thrust, elevator, collective flaps; balanced: the horizontal
//!    and vertical force, the pitching moment) and edge-on (the wind along the span, nose
//!    tilted into it about the body z axis; unknowns thrust, rudder, vertical flap;
//!    balanced: the horizontal and vertical force, the yawing moment). Newton from the hover
//!    trim at each tilt of a 0.25° scan, the first tilt with a solution inside the limits.
//! 2. **Standing on the gear, thrust cut**: the plant at rest on its gear, upright, surfaces
//!    centred, in the steady wind for 5 s, face-on and edge-on: the tilt it ends at.
use analysis::wind_envelope::plant;
use nalgebra::{Matrix3, UnitQuaternion, Vector3};
use tailsitter_physics::{idx, InputVector, Plant, StateVector};

/// Hovering still at `tilt` (rad) in the wind `speed` (m/s), face-on or edge-on, with the
/// three unknowns `u` = (thrust, surface a, surface b).
fn residual(p: &Plant, edge_on: bool, speed: f64, tilt: f64, u: &Vector3<f64>) -> Vector3<f64> {
    let up = UnitQuaternion::from_axis_angle(&Vector3::y_axis(), core::f64::consts::FRAC_PI_2);
    // Body → earth; face-on: belly north, wind from the north, nose tilted north; edge-on:
    // right wing east, wind from the east, nose tilted east.
    let (r, wind) = if edge_on {
        (
            UnitQuaternion::from_axis_angle(&Vector3::x_axis(), tilt) * up,
            Vector3::new(0.0, -speed, 0.0),
        )
    } else {
        (
            UnitQuaternion::from_axis_angle(&Vector3::y_axis(), -tilt) * up,
            Vector3::new(-speed, 0.0, 0.0),
        )
    };
    let mut x = StateVector::zeros();
    let q = r.quaternion();
    x[idx::Q1] = q.i;
    x[idx::Q2] = q.j;
    x[idx::Q3] = q.k;
    x[idx::Q4] = q.w;
    x[idx::THRUST] = u[0];
    if edge_on {
        x[idx::RUDDER] = u[1];
        x[idx::VERTICAL_FLAP] = u[2];
    } else {
        x[idx::ELEVATOR] = u[1];
        x[idx::FLAP_COLLECTIVE] = u[2];
    }
    let fm = p.forces_moments(&x, &wind);
    let a = &p.airframe;
    let f = r * fm.force_body + Vector3::new(0.0, 0.0, a.mass * a.gravity);
    if edge_on {
        Vector3::new(f.y, f.z, fm.moment_body.z)
    } else {
        Vector3::new(f.x, f.z, fm.moment_body.y)
    }
}

/// The smallest tilt (deg) of a hover at rest, and its thrust (N) and deflections (deg).
fn min_hover_tilt(p: &Plant, edge_on: bool, speed: f64) -> Option<(f64, Vector3<f64>)> {
    let a = &p.airframe;
    let lim = a.deflection_limit;
    for k in 0..=360 {
        let tilt = (k as f64 * 0.25).to_radians();
        let mut u = Vector3::new(a.mass * a.gravity, 0.0, 0.0);
        for _ in 0..40 {
            let r0 = residual(p, edge_on, speed, tilt, &u);
            if r0.norm() < 1e-6 {
                break;
            }
            let mut j = Matrix3::zeros();
            for c in 0..3 {
                let mut du = u;
                let h = if c == 0 { 1e-4 } else { 1e-6 };
                du[c] += h;
                j.set_column(c, &((residual(p, edge_on, speed, tilt, &du) - r0) / h));
            }
            match j.lu().solve(&(-r0)) {
                Some(step) => u += step.map(|s| s.clamp(-20.0, 20.0)),
                None => break,
            }
            u[1] = u[1].clamp(-1.5, 1.5);
            u[2] = u[2].clamp(-1.5, 1.5);
        }
        let ok = residual(p, edge_on, speed, tilt, &u).norm() < 1e-4
            && (0.0..=a.thrust_max).contains(&u[0])
            && u[1].abs() <= lim
            && u[2].abs() <= lim;
        if ok {
            return Some((
                tilt.to_degrees(),
                Vector3::new(u[0], u[1].to_degrees(), u[2].to_degrees()),
            ));
        }
    }
    None
}

/// Tilt (deg) after 5 s standing on the gear, thrust cut, surfaces centred, in the wind.
fn standing_tilt(p: &Plant, edge_on: bool, speed: f64) -> f64 {
    let mut x = p.resting_on_ground(0.0, 0.0, 0.0);
    // Heading 0: belly north, right wing east.
    let wind = if edge_on {
        Vector3::new(0.0, -speed, 0.0)
    } else {
        Vector3::new(-speed, 0.0, 0.0)
    };
    let u = InputVector::zeros();
    let h = 0.005;
    let mut max_tilt: f64 = 0.0;
    for _ in 0..(5.0 / h) as usize {
        if p.advance(&mut x, &u, &wind, h).is_err() {
            return f64::NAN;
        }
        let q = UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(
            x[idx::Q4],
            x[idx::Q1],
            x[idx::Q2],
            x[idx::Q3],
        ));
        let nose = q * Vector3::x();
        max_tilt = max_tilt.max((-nose.z).clamp(-1.0, 1.0).acos().to_degrees());
    }
    max_tilt
}

fn main() {
    let speeds: Vec<f64> = std::env::args()
        .nth(1)
        .map(|s| s.split(',').map(|v| v.parse().unwrap()).collect())
        .unwrap_or_else(|| vec![1.0, 2.0, 3.0, 5.0, 8.0, 10.0]);
    let p = plant();
    println!("wind m/s | hover face-on: min tilt deg (T N, de, dfc deg) | hover edge-on: min tilt deg (T N, dr, dv deg) | on the gear 5 s, thrust 0: largest tilt face-on / edge-on deg");
    for v in speeds {
        let show = |r: Option<(f64, Vector3<f64>)>| match r {
            Some((t, u)) => format!("{t:5.2} ({:5.1}, {:5.1}, {:5.1})", u[0], u[1], u[2]),
            None => "none within the limits".to_string(),
        };
        println!(
            "{v:5.1} | {} | {} | {:6.1} / {:6.1}",
            show(min_hover_tilt(&p, false, v)),
            show(min_hover_tilt(&p, true, v)),
            standing_tilt(&p, false, v),
            standing_tilt(&p, true, v)
        );
    }
}
