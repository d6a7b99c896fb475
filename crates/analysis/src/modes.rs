//! Open-loop modes of the plant (thesis §3.4.2 "Modal Analysis", Tables 3.2 and 3.3).
//!
//! The 20-state plant is linearised at a trim ([`Plant::linearise`]) and transformed to the
//! thesis's rigid-body coordinates z = (V̄, α, β, p, q, r, φ, θ, ψ) (Table 3.1; 3-2-1 Euler
//! angles in level flight, 2-3-1 in vertical flight where 3-2-1 is singular, A.2.6):
//! A_z = (∂z/∂x)·A_x·(∂x/∂z), both chart Jacobians by central differences. Position
//! (pure integrators, no dependence of the forces on position), thrust and servo states
//! (decoupled first-order lags at −1/τ_T = −10 and −1/τ_s = −20 rad/s with the commands
//! held) are left out, which also removes the quaternion's redundant norm direction.

use nalgebra::{DMatrix, SMatrix, SVector, Vector3};
use serde::{Deserialize, Serialize};
use tailsitter_physics::numeric::central_differences;
use tailsitter_physics::{
    euler_231_from_quat, euler_321_from_quat, idx, quat_from_euler_231, quat_from_euler_321, PhysicsError, Plant,
    StateVector, Trim,
};

use crate::linalg::{damping, eigen, natural_frequency, C64};

/// Names of the rigid-body coordinates.
pub const COORDS: [&str; 9] = ["V", "α", "β", "p", "q", "r", "φ", "θ", "ψ"];

/// Which Euler sequence the attitude coordinates use.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EulerSet {
    /// 3-2-1 (level flight).
    E321,
    /// 2-3-1 (vertical flight).
    E231,
}

fn z_of(x: &StateVector, set: EulerSet) -> [f64; 9] {
    let (u, v, w) = (x[idx::U], x[idx::V], x[idx::W]);
    let vbar = (u * u + v * v + w * w).sqrt();
    let q = x.fixed_rows::<4>(idx::Q1).into_owned();
    let e = match set {
        EulerSet::E321 => euler_321_from_quat(&q),
        EulerSet::E231 => euler_231_from_quat(&q),
    };
    [
        vbar,
        w.atan2(u),
        (v / vbar).asin(),
        x[idx::P],
        x[idx::Q],
        x[idx::R],
        e[0],
        e[1],
        e[2],
    ]
}

fn x_of(z: &[f64], base: &StateVector, set: EulerSet) -> StateVector {
    let mut x = *base;
    let (vbar, a, b) = (z[0], z[1], z[2]);
    x[idx::U] = vbar * a.cos() * b.cos();
    x[idx::V] = vbar * b.sin();
    x[idx::W] = vbar * a.sin() * b.cos();
    x[idx::P] = z[3];
    x[idx::Q] = z[4];
    x[idx::R] = z[5];
    let q = match set {
        EulerSet::E321 => quat_from_euler_321(z[6], z[7], z[8]),
        EulerSet::E231 => quat_from_euler_231(z[6], z[7], z[8]),
    };
    // Keep the sign of the base quaternion (q and −q are the same attitude).
    let qb = base.fixed_rows::<4>(idx::Q1).into_owned();
    let q = if q.dot(&qb) < 0.0 { -q } else { q };
    x.fixed_rows_mut::<4>(idx::Q1).copy_from(&q);
    x
}

/// The 9×9 rigid-body state matrix at a trim (still air).
pub fn rigid_body_matrix(plant: &Plant, trim: &Trim, set: EulerSet) -> DMatrix<f64> {
    let wind = Vector3::zeros();
    let (ax, _) = plant.linearise(&trim.state, &trim.inputs, &wind);
    let z0 = z_of(&trim.state, set);
    let h = 1e-6;
    // ∂x/∂z (20×9)
    let mut xz = SMatrix::<f64, 20, 9>::zeros();
    central_differences(
        &z0,
        9,
        |_, _| Some(h),
        |z| x_of(z, &trim.state, set),
        |j, col| xz.set_column(j, &col),
    );
    // ∂z/∂x (9×20)
    let mut zx = SMatrix::<f64, 9, 20>::zeros();
    central_differences(
        &trim.state,
        20,
        |_, _| Some(h),
        |x| SVector::<f64, 9>::from(z_of(x, set)),
        |j, col| zx.set_column(j, &col),
    );
    let az = zx * ax * xz;
    DMatrix::from_fn(9, 9, |i, j| az[(i, j)])
}

/// One open-loop mode.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Mode {
    /// Conventional name (level flight) or a description by dominant coordinates.
    pub name: String,
    /// Eigenvalue (upper half-plane member of a pair) (1/s).
    pub re: f64,
    /// Imaginary part (rad/s).
    pub im: f64,
    /// Damping ratio.
    pub damping: f64,
    /// Natural frequency (rad/s).
    pub omega_n: f64,
    /// Mode shape over [`COORDS`]: (magnitude, phase in degrees), normalised so that the
    /// largest of the displayed components is 1 ∠ 0° (V in m/s, angles rad, rates rad/s).
    pub shape: Vec<(f64, f64)>,
}

/// Open-loop modes at a trim.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ModeSet {
    /// "level 25 m/s" etc.
    pub condition: String,
    /// Trim α (deg), δe (deg), T (N).
    pub trim: (f64, f64, f64),
    /// The modes, conventional names in level flight.
    pub modes: Vec<Mode>,
}

fn shape(v: &[C64], rows: &[usize]) -> Vec<(f64, f64)> {
    let k = rows
        .iter()
        .copied()
        .max_by(|a, b| v[*a].norm().total_cmp(&v[*b].norm()))
        .unwrap_or(0);
    let r = v[k];
    v.iter()
        .map(|c| {
            let n = c / r;
            (n.norm(), n.arg().to_degrees())
        })
        .collect()
}

/// Longitudinal coordinates (Table 3.2 rows) and lateral (Table 3.3 rows).
pub const LONG_ROWS: [usize; 4] = [0, 1, 4, 7];
/// Lateral rows β, p, r, φ, ψ.
pub const LAT_ROWS: [usize; 5] = [2, 3, 5, 6, 8];

/// Modes of the rigid-body matrix `a`; with `conventional` the level-flight names of
/// §3.4.2 (phugoid, short period, Dutch roll, roll, spiral, heading) are assigned.
pub fn modes_of(a: &DMatrix<f64>, v_trim: f64, conventional: bool) -> Vec<Mode> {
    let e = eigen(a);
    let mut out: Vec<(Mode, bool)> = Vec::new();
    for ei in e.iter().filter(|e| e.value.im >= -1e-9) {
        let v: Vec<C64> = ei.vector.iter().copied().collect();
        // Scale V by the trim speed to compare it with angles for the classification.
        let w = |i: usize| if i == 0 { v[i].norm() / v_trim } else { v[i].norm() };
        let long: f64 = LONG_ROWS.iter().map(|&i| w(i).powi(2)).sum();
        let lat: f64 = LAT_ROWS.iter().map(|&i| w(i).powi(2)).sum();
        let is_long = long >= lat;
        let rows: Vec<usize> = if is_long { LONG_ROWS.to_vec() } else { LAT_ROWS.to_vec() };
        let s = ei.value;
        out.push((
            Mode {
                name: String::new(),
                re: s.re,
                im: s.im.max(0.0),
                damping: damping(s),
                omega_n: natural_frequency(s),
                shape: shape(&v, &rows),
            },
            is_long,
        ));
    }
    if conventional {
        let complex = |m: &Mode| m.im > 1e-6;
        let mut long_c: Vec<usize> = (0..out.len()).filter(|&i| out[i].1 && complex(&out[i].0)).collect();
        long_c.sort_by(|&a, &b| out[a].0.omega_n.total_cmp(&out[b].0.omega_n));
        if long_c.len() >= 2 {
            out[long_c[0]].0.name = "phugoid".into();
            out[*long_c.last().unwrap()].0.name = "short period".into();
        }
        let lat_c: Vec<usize> = (0..out.len()).filter(|&i| !out[i].1 && complex(&out[i].0)).collect();
        if let Some(&i) = lat_c
            .iter()
            .max_by(|&&a, &&b| out[a].0.omega_n.total_cmp(&out[b].0.omega_n))
        {
            out[i].0.name = "Dutch roll".into();
        }
        let mut lat_r: Vec<usize> = (0..out.len()).filter(|&i| !out[i].1 && !complex(&out[i].0)).collect();
        lat_r.sort_by(|&a, &b| out[a].0.re.total_cmp(&out[b].0.re));
        let mut real_named = 0;
        for &i in &lat_r {
            if out[i].0.omega_n < 1e-5 {
                out[i].0.name = "heading (ψ neutral)".into();
            } else if real_named == 0 {
                out[i].0.name = "roll".into();
                real_named += 1;
            } else if real_named == 1 {
                out[i].0.name = "spiral".into();
                real_named += 1;
            }
        }
    }
    for (m, is_long) in out.iter_mut() {
        if m.name.is_empty() {
            let k = (0..9)
                .max_by(|&a, &b| m.shape[a].0.total_cmp(&m.shape[b].0))
                .unwrap_or(0);
            m.name = format!("{} ({})", if *is_long { "longitudinal" } else { "lateral" }, COORDS[k]);
        }
    }
    let mut modes: Vec<Mode> = out.into_iter().map(|m| m.0).collect();
    modes.sort_by(|a, b| b.omega_n.total_cmp(&a.omega_n));
    modes
}

/// Open-loop modes in level flight at `v` (3-2-1 Euler).
pub fn level_modes(plant: &Plant, v: f64) -> Result<ModeSet, PhysicsError> {
    let t = plant.trim_level(v)?;
    let a = rigid_body_matrix(plant, &t, EulerSet::E321);
    Ok(ModeSet {
        condition: format!("level flight {v} m/s"),
        trim: (t.alpha.to_degrees(), t.elevator.to_degrees(), t.thrust),
        modes: modes_of(&a, v, true),
    })
}

/// Open-loop modes in a vertical climb at `v` (2-3-1 Euler).
pub fn vertical_modes(plant: &Plant, v: f64) -> Result<ModeSet, PhysicsError> {
    let t = plant.trim_vertical_climb(v)?;
    let a = rigid_body_matrix(plant, &t, EulerSet::E231);
    Ok(ModeSet {
        condition: format!("vertical climb {v} m/s (2-3-1 Euler angles)"),
        trim: (t.alpha.to_degrees(), t.elevator.to_degrees(), t.thrust),
        modes: modes_of(&a, v.max(1.0), false),
    })
}

/// A thesis mode: (name, eigenvalue, shape rows (coordinate, magnitude, phase deg)).
pub type ThesisMode = (&'static str, C64, Vec<(&'static str, f64, f64)>);

/// Thesis Tables 3.2/3.3, uncontrolled column: (mode, eigenvalue, shape rows as
/// (coordinate, magnitude, phase deg)).
pub fn thesis_open_loop() -> Vec<ThesisMode> {
    vec![
        (
            "phugoid",
            C64::new(-0.006, 0.462),
            vec![
                ("V", 1.0, 0.0),
                ("α", 0.001, 175.0),
                ("q", 0.022, -7.0),
                ("θ", 0.0477, -97.0),
            ],
        ),
        (
            "short period",
            C64::new(-10.44, 24.204),
            vec![
                ("V", 0.136, -54.0),
                ("α", 0.045, -105.0),
                ("q", 1.0, 0.0),
                ("θ", 0.042, -116.0),
            ],
        ),
        (
            "Dutch roll",
            C64::new(-3.334, 14.06),
            vec![
                ("β", 0.071, 84.0),
                ("p", 0.124, -111.0),
                ("r", 1.0, 0.0),
                ("φ", 0.090, 146.0),
                ("ψ", 0.692, -103.0),
            ],
        ),
        (
            "roll",
            C64::new(-10.340, 0.0),
            vec![
                ("β", 0.030, 0.0),
                ("p", 1.0, 0.0),
                ("r", 0.088, 0.0),
                ("φ", 0.097, 180.0),
                ("ψ", 0.009, 180.0),
            ],
        ),
        (
            "spiral",
            C64::new(0.225, 0.0),
            vec![
                ("β", 0.007, 0.0),
                ("p", 0.024, 0.0),
                ("r", 0.280, 0.0),
                ("φ", 0.556, 0.0),
                ("ψ", 1.0, 0.0),
            ],
        ),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn level_modes_named_and_short_period_near_design_estimate() {
        let plant = Plant::new(tailsitter_physics::Airframe::default());
        let m = level_modes(&plant, 25.0).unwrap();
        let sp = m.modes.iter().find(|m| m.name == "short period").expect("short period");
        // docs/DESIGN.md §4: ≈ −7 ± 17i with these airframe numbers.
        assert!(sp.re < -4.0 && sp.re > -11.0, "{sp:?}");
        assert!(sp.im > 12.0 && sp.im < 22.0, "{sp:?}");
        for name in ["phugoid", "Dutch roll", "roll", "spiral"] {
            assert!(m.modes.iter().any(|m| m.name == name), "{name} missing: {:?}", m.modes);
        }
    }
}
