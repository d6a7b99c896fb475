//! Print the trims and the open-loop level-flight eigenvalues.
use nalgebra::Vector3;
use tailsitter_physics::{idx::*, Airframe, Plant};

fn main() {
    let plant = Plant::new(Airframe::default());
    for v in [25.0, 15.0, 35.0] {
        match plant.trim_level(v) {
            Ok(t) => println!(
                "level {v} m/s: alpha {:.4} deg, de {:.4} deg, T {:.4} N, w {:.4}, res {:e}",
                t.alpha.to_degrees(),
                t.elevator.to_degrees(),
                t.thrust,
                t.induced_velocity,
                t.residual
            ),
            Err(e) => println!("level {v}: {e}"),
        }
    }
    for v in [3.0, 0.0] {
        match plant.trim_vertical_climb(v) {
            Ok(t) => println!(
                "vertical {v} m/s: theta {:.4} deg, de {:.6} deg, T {:.6} N, w {:.4}, res {:e}",
                t.theta.to_degrees(),
                t.elevator.to_degrees(),
                t.thrust,
                t.induced_velocity,
                t.residual
            ),
            Err(e) => println!("vertical {v}: {e}"),
        }
    }
    let t = plant.trim_level(25.0).unwrap();
    let (a, _) = plant.linearise(&t.state, &t.inputs, &Vector3::zeros());
    let long = [U, W, Q, Q2, Q4];
    let lat = [V, P, R, Q1, Q3];
    for (name, s) in [("long", long), ("lat", lat)] {
        let m = nalgebra::SMatrix::<f64, 5, 5>::from_fn(|i, j| a[(s[i], s[j])]);
        println!("{name}: {:?}", m.complex_eigenvalues().as_slice());
    }
}
