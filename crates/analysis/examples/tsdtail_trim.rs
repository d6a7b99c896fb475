//! Quasi-static trim along the still-air front transition in a steady wind, from the plant
//! alone (no controller): `tsdtail_trim SPEED BEARING_DEG [HEADINGS_DEG]`.
//!
//! At each 0.25 s of the default mission's front transition (and the last second of the
//! first vertical phase) the tuned TSD's still-air reference gives the ground velocity v and
//! the specific acceleration Σ^RE = a − g (NED). In the wind w (from `BEARING_DEG` at
//! `SPEED`) the airframe must make m Σ^RE with thrust and aerodynamics at the air velocity
//! v − w, with the moments balanced (body rates zero: quasi-static). Unknowns: the attitude
//! (nose up, belly towards the heading ψ, then tilted about the body y and z axes), the
//! thrust and the six surfaces; six equations. Solved per heading ψ (held through the
//! transition; `HEADINGS_DEG` comma-separated, default every 15°) by minimum-norm Newton
//! steps (scaled unknowns) continued in time from the hover. Printed per heading: the
//! largest thrust and |deflection| over the transition and whether each point is inside the
//! limits (150 N, ±25°); and the best heading per time point.
use analysis::wind_envelope::plant;
use flight_mission::MissionParams;
use nalgebra::{DMatrix, DVector, UnitQuaternion, Vector3};
use tailsitter_physics::{idx, Plant, StateVector};
use tsd_control::TsdController;

const N_U: usize = 9;

/// Residual (force N ×3 in NED, moment N m ×3 in body) at heading `psi` and unknowns `u`
/// = (tilt about body y, tilt about body z, thrust, δe, δa, δr, δfc, δfd, δv).
fn residual(p: &Plant, psi: f64, v: &Vector3<f64>, sigma: &Vector3<f64>, w: &Vector3<f64>, u: &[f64]) -> DVector<f64> {
    let up = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), psi)
        * UnitQuaternion::from_axis_angle(&Vector3::y_axis(), core::f64::consts::FRAC_PI_2);
    let r = up * UnitQuaternion::from_scaled_axis(Vector3::new(0.0, u[0], u[1]));
    let mut x = StateVector::zeros();
    // Quaternion (i, j, k, w) and body velocity.
    x.fixed_rows_mut::<4>(idx::Q1).copy_from(&r.quaternion().coords);
    x.fixed_rows_mut::<3>(idx::U).copy_from(&(r.inverse() * v));
    x[idx::THRUST] = u[2];
    for k in 0..6 {
        x[idx::ELEVATOR + k] = u[3 + k];
    }
    let fm = p.forces_moments(&x, w);
    let m = p.airframe.mass;
    let f = r * fm.force_body - m * sigma;
    DVector::from_vec(vec![
        f.x,
        f.y,
        f.z,
        fm.moment_body.x,
        fm.moment_body.y,
        fm.moment_body.z,
    ])
}

/// Scale of each unknown in the minimum-norm step (rad, N, rad).
const SCALE: [f64; N_U] = [4.0, 4.0, 200.0, 0.44, 0.44, 0.44, 0.44, 0.44, 0.44];

fn solve(
    p: &Plant,
    psi: f64,
    v: &Vector3<f64>,
    sigma: &Vector3<f64>,
    w: &Vector3<f64>,
    u0: &[f64; N_U],
) -> Option<[f64; N_U]> {
    let mut u = *u0;
    for _ in 0..60 {
        let r0 = residual(p, psi, v, sigma, w, &u);
        if r0.norm() < 1e-7 {
            return Some(u);
        }
        let mut j = DMatrix::zeros(6, N_U);
        for c in 0..N_U {
            let mut du = u;
            let h = 1e-6 * SCALE[c];
            du[c] += h;
            j.set_column(c, &((residual(p, psi, v, sigma, w, &du) - &r0) / h * SCALE[c]));
        }
        let jt = j.transpose();
        let step = &jt * (&j * &jt).try_inverse()? * (-&r0);
        let size = step.amax();
        let k = if size > 0.3 { 0.3 / size } else { 1.0 };
        for c in 0..N_U {
            u[c] += k * step[c] * SCALE[c];
        }
    }
    (residual(p, psi, v, sigma, w, &u).norm() < 1e-5).then_some(u)
}

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let speed: f64 = a[1].parse().unwrap();
    let bearing = a[2].parse::<f64>().unwrap().to_radians();
    let headings: Vec<f64> = a.get(3).map_or_else(
        || (0..24).map(|k| -180.0 + 15.0 * k as f64).collect(),
        |s| s.split(',').map(|v| v.parse().unwrap()).collect(),
    );
    let p = plant();
    let lim = p.airframe.deflection_limit;
    let tmax = p.airframe.thrust_max;
    let mission = MissionParams::default();
    let c = TsdController::with_mission(mission).unwrap();
    let s = mission.phase_starts();
    let w = -speed * Vector3::new(bearing.cos(), bearing.sin(), 0.0);
    let times: Vec<f64> = (0..=((s[2] - s[1] + 1.0) / 0.25) as usize)
        .map(|k| s[1] - 1.0 + 0.25 * k as f64)
        .collect();
    // Per time: the best (smallest largest-ratio) heading.
    let mut best: Vec<(f64, f64, [f64; N_U])> = vec![(f64::INFINITY, f64::NAN, [0.0; N_U]); times.len()];
    println!(
        "wind {speed} m/s from {:.0}°; heading: largest T (N), largest |δ| (deg), points within 150 N / 25° of {}",
        bearing.to_degrees(),
        times.len()
    );
    for &psi_deg in &headings {
        let psi = psi_deg.to_radians();
        let mut u = [0.0; N_U];
        u[2] = p.airframe.mass * p.airframe.gravity;
        let (mut t_max, mut d_max, mut ok, mut solved) = (0.0f64, 0.0f64, 0, 0);
        for (i, &t) in times.iter().enumerate() {
            let r = c.trajectory().at(t);
            let Some(sol) = solve(&p, psi, &r.vel, &r.specific_accel, &w, &u) else {
                continue;
            };
            solved += 1;
            u = sol;
            let d = sol[3..].iter().fold(0.0f64, |m, x| m.max(x.abs()));
            t_max = t_max.max(sol[2]);
            d_max = d_max.max(d);
            let ratio = (sol[2] / tmax).max(d / lim).max(-sol[2] / tmax * 100.0);
            if ratio <= 1.0 {
                ok += 1;
            }
            if ratio < best[i].0 {
                best[i] = (ratio, psi_deg, sol);
            }
        }
        println!(
            "ψ {psi_deg:6.1}: T {t_max:6.1}  |δ| {:5.1}  solved {solved}/{}  within limits {ok}",
            d_max.to_degrees(),
            times.len()
        );
    }
    println!("t (s): best heading (deg), its ratio to the limits, T (N), tilts y/z (deg), δe δa δr δfc δfd δv (deg); air velocity (N, E, D)");
    for (i, &t) in times.iter().enumerate() {
        let (ratio, psi, u) = best[i];
        let r = c.trajectory().at(t);
        let air = r.vel - w;
        let d: Vec<String> = u[3..].iter().map(|x| format!("{:5.1}", x.to_degrees())).collect();
        println!(
            "{t:5.2}: ψ {psi:6.1} ratio {ratio:5.2} T {:6.1} tilt {:6.1} {:6.1} δ [{}] air ({:5.1}, {:5.1}, {:5.1})",
            u[2],
            u[0].to_degrees(),
            u[1].to_degrees(),
            d.join(" "),
            air.x,
            air.y,
            air.z
        );
    }
}
