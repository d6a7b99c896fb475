//! The plant standing on its gear in a steady wind with the thrust cut (a physics probe, no
//! controller): `gearstic_creep [SPEEDS]`. At rest on the gear, upright, surfaces centred, the
//! wind on the belly (face-on) or along the span (edge-on) for 5 s. Prints the horizontal
//! aerodynamic force at rest against the friction limits μ_k m g and μ_s m g, the distance
//! moved after the elastic deflection (from 1 s to 5 s) and in all, and the speed at 5 s.
use analysis::wind_envelope::plant;
use nalgebra::Vector3;
use tailsitter_physics::{idx, ContactAnchors, InputVector};

fn main() {
    let speeds: Vec<f64> = std::env::args()
        .nth(1)
        .map(|s| s.split(',').map(|v| v.parse().unwrap()).collect())
        .unwrap_or_else(|| vec![3.0, 5.0, 8.0, 10.0, 12.0]);
    let p = plant();
    let a = &p.airframe;
    let weight = a.mass * a.gravity;
    println!(
        "mu_k m g = {:.1} N, mu_s m g = {:.1} N",
        p.ground.friction * weight,
        p.ground.static_friction * weight
    );
    println!("wind m/s | face-on: F_aero (N), moved 1-5 s (mm), in all (mm), speed (m/s) | edge-on: same");
    for v in speeds {
        let run = |edge_on: bool| {
            let mut x = p.resting_on_ground(0.0, 0.0, 0.0);
            let mut anchors = ContactAnchors::FREE;
            anchors.update(&p.ground, a, &x);
            let x0 = x;
            // Heading 0: belly north, right wing east; the wind blows from the north (onto
            // the belly) or from the east (along the span).
            let wind = if edge_on {
                Vector3::new(0.0, -v, 0.0)
            } else {
                Vector3::new(-v, 0.0, 0.0)
            };
            let c = tailsitter_physics::dcm_earth_to_body(&x.fixed_rows::<4>(idx::Q1).into_owned());
            let f_aero = c.tr_mul(&p.forces_moments(&x, &wind).force_body).xy().norm();
            let h = 0.02;
            let mut x1 = x;
            for k in 0..(5.0 / h) as usize {
                if k == (1.0 / h) as usize {
                    x1 = x;
                }
                p.advance_in_contact(&mut x, &mut anchors, &InputVector::zeros(), &wind, h)
                    .unwrap();
            }
            let moved = |from: &tailsitter_physics::StateVector| {
                1e3 * Vector3::new(x[idx::POS_N] - from[idx::POS_N], x[idx::POS_E] - from[idx::POS_E], 0.0).norm()
            };
            let out = p.outputs_in_contact(&x, &anchors, &InputVector::zeros(), &wind);
            (f_aero, moved(&x1), moved(&x0), out.vel_ned.xy().norm())
        };
        let (f, e) = (run(false), run(true));
        println!(
            "{v:5.1} | {:6.1} {:8.2} {:8.1} {:7.4} | {:6.1} {:8.2} {:8.1} {:7.4}",
            f.0, f.1, f.2, f.3, e.0, e.1, e.2, e.3
        );
    }
}
