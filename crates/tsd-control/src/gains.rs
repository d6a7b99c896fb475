//! Pole placement for the inner and outer loops (thesis §4.2, §4.3).
//!
//! Every loop is closed on its own low-order linear model, rebuilt at each sample from the
//! current airspeed and dynamic pressures (gain scheduling). The models and the
//! derivations, with the corrections to the printed equations, are in the crate README.

use nalgebra::{Matrix3, RowVector3, Vector3};

/// Desired characteristic polynomial of a third-order loop, s³ + a2 s² + a1 s + a0,
/// from a real pole and a complex pair re ± i·im: (s − p)(s² − 2 re s + re² + im²).
#[inline]
pub fn char_poly_3(real: f64, re: f64, im: f64) -> [f64; 3] {
    let c1 = -2.0 * re;
    let c0 = re * re + im * im;
    // (s − p)(s² + c1 s + c0)
    [c1 - real, c0 - real * c1, -real * c0]
}

/// Desired characteristic polynomial s² + a1 s + a0 of the complex pair re ± i·im.
#[inline]
pub fn char_poly_2_complex(re: f64, im: f64) -> [f64; 2] {
    [-2.0 * re, re * re + im * im]
}

/// Desired characteristic polynomial s² + a1 s + a0 of two real poles.
#[inline]
pub fn char_poly_2_real(p1: f64, p2: f64) -> [f64; 2] {
    [-(p1 + p2), p1 * p2]
}

/// Axial specific-acceleration gains (K_A, K_E) of (4.2.8) for the model (4.2.3–4.2.4):
/// with T_c = −K_A·A_W − K_E·E_A, Ė_A = A_W − A_Wr and A_W = T/m − D/m, the closed loop
/// has s² + (1 + K_A/m)/τ_T·s + K_E/(m τ_T) (4.2.7), hence K_A = m(τ_T a1 − 1),
/// K_E = m τ_T a0.
#[inline]
pub fn axial_gains(mass: f64, tau: f64, poly: [f64; 2]) -> (f64, f64) {
    (mass * (tau * poly[0] - 1.0), mass * tau * poly[1])
}

/// Ackermann's formula for the single-input third-order system ẋ = A x + B u:
/// the state feedback u = −K x with eig(A − B K) the roots of s³ + a2 s² + a1 s + a0.
/// `None` if the pair is (numerically) uncontrollable or a gain is not finite.
pub fn place_3(a: &Matrix3<f64>, b: &Vector3<f64>, poly: [f64; 3]) -> Option<RowVector3<f64>> {
    let ab = a * b;
    let a2b = a * ab;
    let ctrb = Matrix3::from_columns(&[*b, ab, a2b]);
    let inv = ctrb.try_inverse()?;
    let a2 = a * a;
    let a3 = a2 * a;
    let phi = a3 + a2 * poly[0] + a * poly[1] + Matrix3::identity() * poly[2];
    let k = inv.row(2) * phi;
    k.iter().all(|v| v.is_finite()).then_some(k)
}

/// Model of the normal specific-acceleration loop (4.2.9–4.2.17) in the states
/// x = (C_W, Q′, E_C), Q′ = Q + g₁/V̄ (the pitch rate relative to the gravity turn), with the
/// mixed actuator δm as input:
///
/// ```text
/// Ċ_W = a11 C_W + V̄ a11 Q′                       (C_W = V̄ a11 α + const, α̇ = Q + (C_W + g₁)/V̄)
/// Q̇′  = a21/(V̄ a11) C_W + a22 Q′ + b2 δm  (+ gravity terms cancelled by δmg, App. B)
/// Ė_C = C_W − C_Wr
/// ```
///
/// `z_alpha` = ∂C_W/∂α = V̄ a11 (the thrust's −T sin α included); `a11` is the path
/// rotation term (a11 = z_alpha/V̄ in the wind axes, scaled towards 0 when the loop is
/// resolved in the reference-path frame at low speed).
pub fn normal_model(a11: f64, a21: f64, a22: f64, b2: f64, z_alpha: f64) -> (Matrix3<f64>, Vector3<f64>) {
    let a = Matrix3::new(a11, z_alpha, 0.0, a21 / z_alpha, a22, 0.0, 1.0, 0.0, 0.0);
    (a, Vector3::new(0.0, b2, 0.0))
}

/// Steady state of the normal loop model ([`normal_model`]) holding C_W = `c`: the pitch rate
/// Q′* and the mixed deflection δm* with Ċ_W = Q̇′ = 0 in (4.2.9–4.2.10),
///
/// ```text
/// Q′* = −a11 c / Z_α,     δm* = −(a21/Z_α · c + a22 Q′*) / b2.
/// ```
///
/// In the wind axes (a11 = Z_α/V̄) Q′* = −c/V̄, i.e. Q* = −(C_W + g₁)/V̄: the body pitches with
/// the flight path it is turning (α̇ = 0 in (4.2.9)), at the trim α* = c/Z_α whose pitching
/// moment a21 α* + a22 Q* the deflection δm* balances (gravity terms: δmg of (4.2.16)).
/// Fed forward with the state error taken from it, u = δm* − K (x − x*) of (4.2.15) leaves the
/// integrator E_C nothing to find for a steady command: the closed loop (poles of Table 4.3)
/// is then driven only by the command's rate, not by the command itself.
pub fn normal_steady_state(model: &(Matrix3<f64>, Vector3<f64>), c: f64) -> (f64, f64) {
    let (a, b) = model;
    let (a11, z_alpha, a21_over_z, a22, b2) = (a[(0, 0)], a[(0, 1)], a[(1, 0)], a[(1, 1)], b[1]);
    let q = -a11 * c / z_alpha;
    (q, -(a21_over_z * c + a22 * q) / b2)
}

/// Model of the directional loop (4.2.27–4.2.31) in the states x = (B_W, R′, E_B),
/// R′ = R_s − g₂/V̄, with the mixed rudder δR as input:
///
/// ```text
/// Ḃ_W = a11 B_W − V̄ a11 R′                      (B_W = V̄ a11 β, β̇ = (B_W + g₂)/V̄ − R_s)
/// Ṙ′  = a31/(V̄ a11) B_W + a33 R′ + b32 δR  (+ terms cancelled by δR_f, corrected (4.2.29))
/// Ė_B = B_W − B_Wr
/// ```
///
/// `y_beta` = ∂B_W/∂β = V̄ a11; `a11` the path rotation term as in [`normal_model`].
pub fn directional_model(a11: f64, a31: f64, a33: f64, b32: f64, y_beta: f64) -> (Matrix3<f64>, Vector3<f64>) {
    let a = Matrix3::new(a11, -y_beta, 0.0, a31 / y_beta, a33, 0.0, 1.0, 0.0, 0.0);
    (a, Vector3::new(0.0, b32, 0.0))
}

/// Combined roll-rate and normal-vector-direction gains (K_P, K_E, K_φ) (4.3.7–4.3.11).
///
/// States (P, E_P, φ) with Ṗ = a22 P + b21 δA, Ė_P = P − P_R, φ̇ = P_Wc − P (4.3.1),
/// control δA = −K_P P − K_E E_P and P_R = P_Wc + K_φ φ. With P_Wc = 0 the closed loop
/// is
///
/// ```text
/// | s − (a22 − b21 K_P)   b21 K_E   0  |
/// | −1                    s         K_φ| = s³ + (b21 K_P − a22) s² + b21 K_E s + b21 K_E K_φ
/// | 1                     0         s  |
/// ```
///
/// so K_P = (a2 + a22)/b21, K_E = a1/b21, K_φ = a0/a1. (The printed (4.3.10–4.3.11) carry
/// a sign error in K_φ from the sign convention of φ in (4.3.9).)
pub fn roll_nvd_gains(a22: f64, b21: f64, poly: [f64; 3]) -> Option<(f64, f64, f64)> {
    let kp = (poly[0] + a22) / b21;
    let ke = poly[1] / b21;
    let kphi = poly[2] / poly[1];
    (kp.is_finite() && ke.is_finite() && kphi.is_finite()).then_some((kp, ke, kphi))
}

/// The closed-loop matrix of [`roll_nvd_gains`] (for tests and analysis).
pub fn roll_nvd_closed_loop(a22: f64, b21: f64, kp: f64, ke: f64, kphi: f64) -> Matrix3<f64> {
    Matrix3::new(a22 - b21 * kp, -b21 * ke, 0.0, 1.0, 0.0, -kphi, -1.0, 0.0, 0.0)
}

/// Guidance gains (K_P, K_V) of (4.3.24–4.3.26): P̈ + K_V Ṗ + K_P P = 0 with poles re ± i·im.
#[inline]
pub fn guidance_gains(re: f64, im: f64) -> (f64, f64) {
    let p = char_poly_2_complex(re, im);
    (p[1], p[0])
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Complex;

    /// The steady state is an equilibrium of the model's (C_W, Q′) rows at C_W = c, and in the
    /// wind axes the body pitches with the path: Q′* = −c/V̄ (α̇ = 0 in (4.2.9)).
    #[test]
    fn normal_steady_state_is_an_equilibrium_turning_with_the_path() {
        // A 15 m/s transition condition: Z_α = −60 m/s², a21 = −40, a22 = −3 1/s, b2 = −150.
        let (v, z_alpha) = (15.0, -60.0);
        let model = normal_model(z_alpha / v, -40.0, -3.0, -150.0, z_alpha);
        let c = -12.0;
        let (q, dm) = normal_steady_state(&model, c);
        let x = Vector3::new(c, q, 0.0);
        let xdot = model.0 * x + model.1 * dm;
        assert!(xdot[0].abs() < 1e-12 && xdot[1].abs() < 1e-12, "{xdot:?}");
        assert!((q + c / v).abs() < 1e-12, "{q}");
        // Trim α* = c/Z_α = 0.2 rad; the moment −40·0.2 − 3·0.8 = −10.4 rad/s² is balanced by
        // δm* = −10.4/150.
        assert!((dm - (-10.4 / 150.0)).abs() < 1e-12, "{dm}");
    }

    fn eig3(m: &Matrix3<f64>) -> Vec<Complex<f64>> {
        let mut e: Vec<_> = m.complex_eigenvalues().iter().copied().collect();
        e.sort_by(|a, b| a.re.partial_cmp(&b.re).unwrap().then(a.im.partial_cmp(&b.im).unwrap()));
        e
    }

    fn expect(mut want: Vec<Complex<f64>>, got: Vec<Complex<f64>>) {
        want.sort_by(|a, b| a.re.partial_cmp(&b.re).unwrap().then(a.im.partial_cmp(&b.im).unwrap()));
        for (w, g) in want.iter().zip(got.iter()) {
            assert!((w - g).norm() < 1e-6 * (1.0 + w.norm()), "want {want:?} got {got:?}");
        }
    }

    #[test]
    fn char_poly_roots() {
        let p = char_poly_3(-14.0, -15.0, 5.0);
        // s = −14 is a root.
        let s = -14.0f64;
        assert!((s.powi(3) + p[0] * s * s + p[1] * s + p[2]).abs() < 1e-9);
        let s = Complex::new(-15.0, 5.0);
        let v = s * s * s + s * s * p[0] + s * p[1] + p[2];
        assert!(v.norm() < 1e-9);
    }

    #[test]
    fn axial_loop_has_the_placed_poles() {
        let (m, tau) = (9.0, 0.1);
        let (ka, ke) = axial_gains(m, tau, char_poly_2_real(-10.0, -15.0));
        assert!((ka - 13.5).abs() < 1e-12 && (ke - 135.0).abs() < 1e-12);
        // (4.2.6): A_cl = [[−(1 + K_A/m)/τ, −K_E/τ], [1/m, 0]] in (T, E_A).
        let acl = nalgebra::Matrix2::new(-(1.0 + ka / m) / tau, -ke / tau, 1.0 / m, 0.0);
        let mut e: Vec<f64> = acl.complex_eigenvalues().iter().map(|c| c.re).collect();
        e.sort_by(|a, b| a.partial_cmp(b).unwrap());
        assert!((e[0] + 15.0).abs() < 1e-9 && (e[1] + 10.0).abs() < 1e-9, "{e:?}");
    }

    #[test]
    fn normal_and_directional_loops_have_the_placed_poles() {
        // Level flight at 25 m/s and vertical climb at 3 m/s (numbers of the nominal airframe).
        for (a11, a21, a22, b2, v) in [(-4.2, -120.0, -7.0, -300.0, 25.0), (-3.7, -4.5, -0.3, -270.0, 3.0)] {
            let (a, b) = normal_model(a11, a21, a22, b2, v * a11);
            let k = place_3(&a, &b, char_poly_3(-14.0, -15.0, 5.0)).unwrap();
            let acl = a - b * k;
            expect(
                vec![
                    Complex::new(-14.0, 0.0),
                    Complex::new(-15.0, 5.0),
                    Complex::new(-15.0, -5.0),
                ],
                eig3(&acl),
            );
            // The thesis's closed forms (4.2.16): K_Q = (α2 + a11 + a22)/b2.
            let p = char_poly_3(-14.0, -15.0, 5.0);
            assert!((k[1] - (p[0] + a11 + a22) / b2).abs() < 1e-9 * k[1].abs().max(1.0));
            assert!((k[2] - p[2] / (v * a11 * b2)).abs() < 1e-9 * k[2].abs().max(1.0));
        }
        for (a11, a31, a33, b32, v) in [(-1.8, 40.0, -2.0, -90.0, 25.0), (-3.3, 0.5, -0.1, -60.0, 3.0)] {
            let (a, b) = directional_model(a11, a31, a33, b32, v * a11);
            let k = place_3(&a, &b, char_poly_3(-10.0, -7.0, 3.5)).unwrap();
            expect(
                vec![
                    Complex::new(-10.0, 0.0),
                    Complex::new(-7.0, 3.5),
                    Complex::new(-7.0, -3.5),
                ],
                eig3(&(a - b * k)),
            );
        }
    }

    #[test]
    fn roll_nvd_loop_has_the_placed_poles() {
        for (a22, b21) in [(-9.0, -139.0), (-0.4, -38.0)] {
            let poly = char_poly_3(-3.5, -9.0, 4.5);
            let (kp, ke, kphi) = roll_nvd_gains(a22, b21, poly).unwrap();
            expect(
                vec![
                    Complex::new(-3.5, 0.0),
                    Complex::new(-9.0, 4.5),
                    Complex::new(-9.0, -4.5),
                ],
                eig3(&roll_nvd_closed_loop(a22, b21, kp, ke, kphi)),
            );
        }
    }

    #[test]
    fn guidance_poles() {
        let (kp, kv) = guidance_gains(-0.75, 0.45);
        let m = nalgebra::Matrix2::new(0.0, 1.0, -kp, -kv);
        for e in m.complex_eigenvalues().iter() {
            assert!((e.re + 0.75).abs() < 1e-12 && (e.im.abs() - 0.45).abs() < 1e-12);
        }
    }
}
