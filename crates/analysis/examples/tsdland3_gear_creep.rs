//! How far the plant creeps on its gear in a steady wind with the thrust cut (a physics
//! probe, no controller): `tsdland3_gear_creep [SPEEDS]`. At rest on the gear, upright,
//! surfaces centred, the wind on the belly (face-on) or along the span (edge-on) for 5 s:
//! the horizontal distance moved and the speed at the end. The ground's friction is
//! regularised (`tailsitter_physics::ground`, v_ε = 0.05 m/s): a steady tangential load F
//! below μN creeps at v = v_ε r/√(1 − r²), r = F/(μN), where a Coulomb contact would stick.
use analysis::wind_envelope::plant;
use nalgebra::Vector3;
use tailsitter_physics::{idx, InputVector};

fn main() {
    let speeds: Vec<f64> = std::env::args()
        .nth(1)
        .map(|s| s.split(',').map(|v| v.parse().unwrap()).collect())
        .unwrap_or_else(|| vec![3.0, 5.0, 8.0, 10.0]);
    let p = plant();
    println!("wind m/s | face-on: moved in 5 s (m), speed at 5 s (m/s) | edge-on: moved, speed");
    for v in speeds {
        let run = |edge_on: bool| {
            let mut x = p.resting_on_ground(0.0, 0.0, 0.0);
            let x0 = x;
            // Heading 0: belly north, right wing east; the wind blows towards the belly's
            // opposite (from the north) or along the span (from the east).
            let wind = if edge_on {
                Vector3::new(0.0, -v, 0.0)
            } else {
                Vector3::new(-v, 0.0, 0.0)
            };
            let h = 0.005;
            for _ in 0..(5.0 / h) as usize {
                p.advance(&mut x, &InputVector::zeros(), &wind, h).unwrap();
            }
            let d = Vector3::new(x[idx::POS_N] - x0[idx::POS_N], x[idx::POS_E] - x0[idx::POS_E], 0.0).norm();
            let out = p.outputs(&x, &InputVector::zeros(), &wind);
            (d, out.vel_ned.xy().norm())
        };
        let (a, b) = (run(false), run(true));
        println!("{v:5.1} | {:6.3} {:6.3} | {:6.3} {:6.3}", a.0, a.1, b.0, b.1);
    }
}
