//! Small dense linear-algebra helpers: eigen-decomposition of real matrices with
//! eigenvectors (Schur eigenvalues + complex inverse iteration), central-difference
//! Jacobians, the z → s mapping of sampled-data poles, and greedy pole matching.

use nalgebra::{Complex, DMatrix, DVector};

/// Complex number type used for poles.
pub type C64 = Complex<f64>;

/// One eigenvalue with its (unit-norm) right eigenvector.
#[derive(Debug, Clone)]
pub struct Eigen {
    /// Eigenvalue.
    pub value: C64,
    /// Right eigenvector, ‖v‖₂ = 1.
    pub vector: DVector<C64>,
}

/// Eigenvalues of a real square matrix (real Schur form), sorted by real part then
/// imaginary part (deterministic order). Empty if the matrix has non-finite entries or the
/// QR iteration does not converge in 10 000 steps (nalgebra's default would loop forever).
pub fn eigenvalues(a: &DMatrix<f64>) -> Vec<C64> {
    if !a.iter().all(|v| v.is_finite()) {
        return Vec::new();
    }
    let Some(schur) = nalgebra::linalg::Schur::try_new(a.clone(), 1e-14, 10_000) else {
        return Vec::new();
    };
    let mut ev: Vec<C64> = schur.complex_eigenvalues().iter().copied().collect();
    ev.sort_by(|x, y| x.re.total_cmp(&y.re).then(x.im.total_cmp(&y.im)));
    ev
}

/// Eigenvalues and eigenvectors of a real square matrix. Vectors by three steps of
/// inverse iteration on `A − (λ + ε)I` in complex arithmetic.
pub fn eigen(a: &DMatrix<f64>) -> Vec<Eigen> {
    let n = a.nrows();
    let ac: DMatrix<C64> = a.map(|v| C64::new(v, 0.0));
    eigenvalues(a)
        .into_iter()
        .map(|lambda| {
            let shift = lambda + C64::new(1e-10 * lambda.norm().max(1.0), 1e-10 * lambda.norm().max(1.0));
            let m = &ac - DMatrix::<C64>::identity(n, n) * shift;
            let lu = m.lu();
            let mut v = DVector::<C64>::from_fn(n, |i, _| C64::new(1.0 + 0.1 * i as f64, 0.05 * i as f64));
            for _ in 0..3 {
                if let Some(w) = lu.solve(&v) {
                    let nrm = w.norm();
                    if nrm.is_finite() && nrm > 0.0 {
                        v = w / C64::new(nrm, 0.0);
                    }
                }
            }
            Eigen {
                value: lambda,
                vector: v,
            }
        })
        .collect()
}

/// Central-difference Jacobian of `f` at `z0`, step `h[j]` in coordinate j.
pub fn jacobian(f: impl Fn(&DVector<f64>) -> DVector<f64>, z0: &DVector<f64>, h: &[f64]) -> DMatrix<f64> {
    let n = z0.len();
    let mut cols = Vec::with_capacity(n);
    tailsitter_physics::numeric::central_differences(z0, n, |j, _| Some(h[j]), f, |_, col| cols.push(col));
    let m = cols.first().map_or(0, |c: &DVector<f64>| c.len());
    DMatrix::from_fn(m, n, |i, j| cols[j][i])
}

/// Map a discrete pole z of a map sampled every `t` seconds to the s-plane, s = ln(z)/T
/// (principal branch: a negative real z maps to Im s = π/T).
pub fn z_to_s(z: C64, t: f64) -> C64 {
    if z.norm() == 0.0 {
        return C64::new(f64::NEG_INFINITY, 0.0);
    }
    z.ln() / t
}

/// Natural frequency |s| (rad/s).
pub fn natural_frequency(s: C64) -> f64 {
    s.norm()
}

/// Damping ratio −Re s/|s| (1 for a stable real pole, −1 for an unstable one).
pub fn damping(s: C64) -> f64 {
    let w = s.norm();
    if w == 0.0 {
        0.0
    } else {
        -s.re / w
    }
}

/// Greedy one-to-one matching: pairs (i, j) of `a[i]` and `b[j]`, closest pairs first.
/// Returns for every `a[i]` the index of its partner in `b` (`None` when `b` ran out).
pub fn match_poles(a: &[C64], b: &[C64]) -> Vec<Option<usize>> {
    let mut pairs: Vec<(f64, usize, usize)> = Vec::with_capacity(a.len() * b.len());
    for (i, x) in a.iter().enumerate() {
        for (j, y) in b.iter().enumerate() {
            pairs.push(((x - y).norm(), i, j));
        }
    }
    pairs.sort_by(|p, q| p.0.total_cmp(&q.0).then(p.1.cmp(&q.1)).then(p.2.cmp(&q.2)));
    let mut out = vec![None; a.len()];
    let mut used = vec![false; b.len()];
    for (_, i, j) in pairs {
        if out[i].is_none() && !used[j] {
            out[i] = Some(j);
            used[j] = true;
        }
    }
    out
}

/// Format a pole as `re ± im i` (only the upper half of a pair is usually printed).
pub fn fmt_pole(s: C64) -> String {
    if s.im.abs() < 1e-6 * s.norm().max(1e-12) || s.im.abs() < 1e-9 {
        format!("{:.3}", s.re)
    } else {
        format!("{:.3} ± {:.3}i", s.re, s.im.abs())
    }
}

/// Keep one pole per complex-conjugate pair (the one with Im ≥ 0) and the real poles.
pub fn upper_half(p: &[C64]) -> Vec<C64> {
    p.iter().copied().filter(|s| s.im >= -1e-9).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn eigen_of_rotation_generator() {
        let a = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, -4.0, -0.4]);
        let e = eigen(&a);
        assert_eq!(e.len(), 2);
        for ei in &e {
            assert!((ei.value.re + 0.2).abs() < 1e-12);
            let ac = a.map(|v| C64::new(v, 0.0));
            let r = &ac * &ei.vector - &ei.vector * ei.value;
            assert!(r.norm() < 1e-8, "residual {}", r.norm());
        }
    }

    #[test]
    fn z_to_s_inverts_exp() {
        let s = C64::new(-3.0, 2.0);
        let z = (s * 0.02).exp();
        assert!((z_to_s(z, 0.02) - s).norm() < 1e-12);
    }
}
