//! Physics bounds of hovering and standing in a horizontal wind, from the plant alone (no
//! controller): the stationary hover trim of the nominal airframe on the global
//! aerodynamic model in a steady wind into the belly ("belly-on", the weathervane's
//! orientation) and along the span ("edge-on"), and the overturn margin of the aircraft
//! standing on its gear with the thrust cut.
//!
//! `cargo run --release -p lqr-control --example hover_lean [SPEEDS]` (default 3,5,8,10).
//!
//! Trim (belly-on): ground velocity zero, body rates zero; unknowns the tilt of the body x
//! axis from the vertical (a rotation vector in the earth's horizontal plane applied to the
//! vertical attitude), the thrust T, and the elevator, aileron and rudder — *tilted* — or the
//! same with the tilt into the wind replaced by the collective flap — *upright*: the flaps
//! in the slip-stream carry the wing's broadside force; residuals the plant's six
//! accelerations (u̇, v̇, ẇ, ṗ, q̇, ṙ). Newton's method with a central-difference Jacobian
//! ("no trim": it did not converge within the limits of the iteration). The overturn check takes the aerodynamic force and moment
//! of the upright aircraft (thrust zero, surfaces centred) about the downwind edge of the
//! gear (contact points of `tailsitter_physics::Ground`).
use nalgebra::{SMatrix, SVector, UnitQuaternion, Vector3, Vector4};
use tailsitter_physics::idx::*;
use tailsitter_physics::{quat_from_euler_321, AeroModel, Airframe, Ground, InputVector, Plant, StateVector};

/// The vertical attitude (nose up) with the belly towards bearing `psi0`, tilted by the
/// earth-frame horizontal rotation vector (`rn`, `re`) (rad).
fn attitude(psi0: f64, rn: f64, re: f64) -> Vector4<f64> {
    let q0 = quat_from_euler_321(0.0, std::f64::consts::FRAC_PI_2, psi0);
    let b2e = UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(q0[3], q0[0], q0[1], q0[2]));
    let tilt = UnitQuaternion::from_scaled_axis(Vector3::new(rn, re, 0.0));
    let q = tilt * b2e;
    Vector4::new(q.i, q.j, q.k, q.w)
}

/// Which unknowns the trim has: `Tilt` = (tilt_N, tilt_E, T, δe, δa, δr); `Upright` = the
/// tilt in the wind's direction (N) replaced by the direct-force surface of that axis:
/// the collective flap (belly-on, force along body z) or the vertical flap (edge-on, force
/// along body y) — the aircraft held vertical in the wind's plane.
#[derive(Clone, Copy, PartialEq)]
enum Unknowns {
    Tilt,
    Upright,
}

fn point(psi0: f64, mode: Unknowns, z: &SVector<f64, 6>) -> (StateVector, InputVector) {
    // The wind blows from the north: the tilt into it is the rotation about E (z[1]).
    let tilt_e = if mode == Unknowns::Tilt { z[1] } else { 0.0 };
    let q = attitude(psi0, z[0], tilt_e);
    let mut x = StateVector::zeros();
    x.fixed_rows_mut::<4>(Q1).copy_from(&q);
    x[THRUST] = z[2];
    x[ELEVATOR] = z[3];
    x[AILERON] = z[4];
    x[RUDDER] = z[5];
    let mut u = InputVector::zeros();
    u[THRUST_CMD] = z[2];
    u[ELEVATOR_CMD] = z[3];
    u[AILERON_CMD] = z[4];
    u[RUDDER_CMD] = z[5];
    if mode == Unknowns::Upright {
        let (state, cmd) = if psi0 == 0.0 {
            (FLAP_COLLECTIVE, FLAP_COLLECTIVE_CMD)
        } else {
            (VERTICAL_FLAP, VERTICAL_FLAP_CMD)
        };
        x[state] = z[1];
        u[cmd] = z[1];
    }
    (x, u)
}

fn residual(plant: &Plant, psi0: f64, mode: Unknowns, wind: &Vector3<f64>, z: &SVector<f64, 6>) -> SVector<f64, 6> {
    let (x, u) = point(psi0, mode, z);
    let d = plant.derivatives(&x, &u, wind);
    SVector::<f64, 6>::from_column_slice(&[d[U], d[V], d[W], d[P], d[Q], d[R]])
}

/// Stationary hover trim: (tilt from vertical (deg), T (N), δe, δa, δr (deg)), or None.
fn trim(plant: &Plant, psi0: f64, mode: Unknowns, wind: &Vector3<f64>) -> Option<(f64, SVector<f64, 6>)> {
    let a = &plant.airframe;
    let mut z = SVector::<f64, 6>::from_column_slice(&[1e-3, 1e-3, a.mass * a.gravity, 0.0, 0.0, 0.0]);
    for _ in 0..400 {
        let r = residual(plant, psi0, mode, wind, &z);
        if r.amax() < 1e-10 {
            let (x, _) = point(psi0, mode, &z);
            let c = tailsitter_physics::dcm_earth_to_body(&Vector4::new(x[Q1], x[Q2], x[Q3], x[Q4]));
            // Body x in earth axes: first row of DCM^BE; tilt = angle from "up" (−D).
            let up = -c[(0, 2)];
            return Some((up.clamp(-1.0, 1.0).acos().to_degrees(), z));
        }
        let mut jac = SMatrix::<f64, 6, 6>::zeros();
        for j in 0..6 {
            let h = 1e-6 * z[j].abs().max(1.0);
            let (mut zp, mut zm) = (z, z);
            zp[j] += h;
            zm[j] -= h;
            jac.set_column(
                j,
                &((residual(plant, psi0, mode, wind, &zp) - residual(plant, psi0, mode, wind, &zm)) / (2.0 * h)),
            );
        }
        let dz = jac.lu().solve(&r)?;
        let scale = (0.1 / dz.amax().max(1e-300)).min(1.0);
        z -= scale * dz;
    }
    None
}

fn main() {
    let speeds: Vec<f64> = std::env::args()
        .nth(1)
        .map(|s| s.split(',').map(|v| v.parse().unwrap()).collect())
        .unwrap_or_else(|| vec![3.0, 5.0, 8.0, 10.0]);
    let af = Airframe::default();
    let mut plant = Plant::new(af);
    plant.aero.model = AeroModel::Global;
    let ground = Ground::default();
    let w = af.mass * af.gravity;
    println!(
        "airframe: m g = {w:.1} N, T_max = {:.0} N, S = {} m², C_D90 = {:.3}; gear: CG {} m above the tail points, \
         half-spread {} m (span) / {} m (belly-back)",
        af.thrust_max,
        af.wing_area,
        plant.aero.c_D_90,
        ground.gear_length,
        ground.gear_half_span,
        ground.gear_half_height
    );
    for &s in &speeds {
        // Wind from the north (blowing south): belly-on = belly north (ψ0 = 0), edge-on =
        // belly east (ψ0 = 90°, span along the wind).
        let wind = Vector3::new(-s, 0.0, 0.0);
        for (name, psi0) in [("belly-on", 0.0), ("edge-on", std::f64::consts::FRAC_PI_2)] {
            // Edge-on the trim's Newton iteration finds no solution from the vertical start
            // (singular Jacobian): only the standing check is made there.
            let modes: &[Unknowns] = if psi0 == 0.0 {
                &[Unknowns::Tilt, Unknowns::Upright]
            } else {
                &[]
            };
            for &mode in modes {
                let label = if mode == Unknowns::Tilt { "tilted" } else { "upright" };
                match trim(&plant, psi0, mode, &wind) {
                    Some((tilt, z)) => println!(
                        "{s:4.1} m/s {name:9} hover {label:7}: tilt {tilt:5.1}°, T {:6.1} N, {} {:6.1}°, δe {:6.1}°, δa {:6.1}°, δr {:6.1}° (limit {:.0}°)",
                        z[2],
                        if mode == Unknowns::Tilt { "rot_E" } else if psi0 == 0.0 { "δfc" } else { "δv" },
                        z[1].to_degrees(),
                        z[3].to_degrees(),
                        z[4].to_degrees(),
                        z[5].to_degrees(),
                        af.deflection_limit.to_degrees()
                    ),
                    None => println!("{s:4.1} m/s {name:9} hover {label:7}: no trim"),
                }
            }
            // Standing upright on the gear (tail points at x = −gear_length), thrust cut:
            // aerodynamic force and moment about the CG; overturning moment about the
            // downwind gear edge vs the weight's restoring moment.
            let (x, _) = point(psi0, Unknowns::Tilt, &SVector::zeros());
            let fm = plant.forces_moments(&x, &wind);
            let c = tailsitter_physics::dcm_earth_to_body(&Vector4::new(x[Q1], x[Q2], x[Q3], x[Q4]));
            let f_e = c.transpose() * fm.force_body;
            let m_e = c.transpose() * fm.moment_body;
            // Downwind edge: the wind blows south (−N); the pivot lies `half` south of the CG
            // and `gear_length` below it, r_p = (−half, 0, h). Moment about the pivot's E axis
            // of the aerodynamic force (at the CG), the aerodynamic moment and the weight:
            // M_E = M_aero,E − h F_N − half (F_D + m g); it tips over (downwind) when the
            // first two exceed the last.
            let h = ground.gear_length;
            let half = if psi0 == 0.0 {
                ground.gear_half_height
            } else {
                ground.gear_half_span
            };
            let overturn = m_e.y - f_e.x * h;
            let restoring = (w + f_e.z) * half; // lift (−D force) reduces the weight on the gear
            println!(
                "{s:4.1} m/s {name:9} standing: F_h {:5.1} N, overturning {overturn:5.1} N m vs restoring {restoring:5.1} N m",
                -f_e.x
            );
        }
    }
}
