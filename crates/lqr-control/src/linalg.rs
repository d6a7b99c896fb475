//! Dense linear algebra on statically sized matrices (no heap): zero-order-hold
//! discretisation by the matrix exponential, the discrete algebraic Riccati equation
//! (structured doubling), the thesis's finite-horizon backward Riccati iteration
//! (3.1.3–3.1.5), the LQR gain and a spectral-radius bound.

use nalgebra::{SMatrix, SVector};

/// Why a Riccati solve was rejected.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum RiccatiError {
    /// A matrix to invert was singular (or not finite).
    Singular(&'static str),
    /// The doubling iteration did not converge in the iteration budget.
    NotConverged,
    /// A non-finite value appeared.
    NonFinite,
    /// The relative residual of the DARE exceeds the tolerance.
    Residual(f64),
    /// The closed loop Φ − ΓK is not stable (bound on its spectral radius ≥ 1).
    Unstable(f64),
}

impl RiccatiError {
    /// A static description (for [`flight_mission::Notice::GainFallback`]).
    pub fn describe(&self) -> &'static str {
        match self {
            RiccatiError::Singular(what) => what,
            RiccatiError::NotConverged => "Riccati doubling did not converge",
            RiccatiError::NonFinite => "non-finite value in the Riccati solution",
            RiccatiError::Residual(_) => "DARE residual above tolerance",
            RiccatiError::Unstable(_) => "closed loop not stable (spectral radius >= 1)",
        }
    }
}

/// Matrix exponential e^A by scaling and squaring with the diagonal [6/6] Padé
/// approximant: A is scaled by 2^-s so that ‖A/2^s‖₁ ≤ 1/2, where the [6/6] Padé
/// error is below 1e-16 relative (Moler & Van Loan, "Nineteen dubious ways", method 3).
pub fn expm<const N: usize>(a: &SMatrix<f64, N, N>) -> SMatrix<f64, N, N> {
    // Padé coefficients c_k = (2q−k)! q! / ((2q)! k! (q−k)!), q = 6.
    const C: [f64; 7] = [
        1.0,
        0.5,
        5.0 / 44.0,
        1.0 / 66.0,
        1.0 / 792.0,
        1.0 / 15840.0,
        1.0 / 665280.0,
    ];
    let norm = a.column_iter().map(|c| c.abs().sum()).fold(0.0, f64::max);
    let mut s = 0i32;
    if norm > 0.5 {
        s = (norm / 0.5).log2().ceil() as i32;
    }
    let x = a * 2f64.powi(-s);
    let id = SMatrix::<f64, N, N>::identity();
    let x2 = x * x;
    let x4 = x2 * x2;
    let x6 = x4 * x2;
    // Even part U and odd part V: N = U + V, D = U − V.
    let u = id * C[0] + x2 * C[2] + x4 * C[4] + x6 * C[6];
    let v = x * (id * C[1] + x2 * C[3] + x4 * C[5]);
    let num = u + v;
    let den = u - v;
    let mut e = match Lu::new(&den) {
        Some(lu) => lu.solve(&num),
        None => SMatrix::from_element(f64::NAN),
    };
    for _ in 0..s {
        e = e * e;
    }
    e
}

/// Zero-order-hold discretisation (replacing the Euler approximation (3.2.10–3.2.11)):
/// `Φ = e^{A T}`, `Γ = ∫₀^T e^{A τ} dτ B`, both read off `exp([A B; 0 0] T)`.
/// `M` must be `NX + NU` (const generics cannot express the sum).
pub fn discretise_zoh<const NX: usize, const NU: usize, const M: usize>(
    a: &SMatrix<f64, NX, NX>,
    b: &SMatrix<f64, NX, NU>,
    ts: f64,
) -> (SMatrix<f64, NX, NX>, SMatrix<f64, NX, NU>) {
    assert_eq!(M, NX + NU, "augmented size must be NX + NU");
    let mut big = SMatrix::<f64, M, M>::zeros();
    big.fixed_view_mut::<NX, NX>(0, 0).copy_from(&(a * ts));
    big.fixed_view_mut::<NX, NU>(0, NX).copy_from(&(b * ts));
    let e = expm(&big);
    (
        e.fixed_view::<NX, NX>(0, 0).into_owned(),
        e.fixed_view::<NX, NU>(0, NX).into_owned(),
    )
}

/// LU factorisation with partial pivoting of a square static matrix (no heap), usable
/// for any const size (nalgebra's `lu()` needs type-level sizes in generic code).
pub struct Lu<const N: usize> {
    lu: SMatrix<f64, N, N>,
    perm: [usize; N],
}

impl<const N: usize> Lu<N> {
    /// Factorise; `None` if a pivot is zero or not finite.
    pub fn new(a: &SMatrix<f64, N, N>) -> Option<Self> {
        let mut lu = *a;
        let mut perm = [0usize; N];
        for (i, p) in perm.iter_mut().enumerate() {
            *p = i;
        }
        for k in 0..N {
            let mut piv = k;
            let mut best = lu[(k, k)].abs();
            for i in (k + 1)..N {
                let v = lu[(i, k)].abs();
                if v > best {
                    best = v;
                    piv = i;
                }
            }
            if !(best > 0.0 && best.is_finite()) {
                return None;
            }
            if piv != k {
                lu.swap_rows(k, piv);
                perm.swap(k, piv);
            }
            let d = lu[(k, k)];
            for i in (k + 1)..N {
                let l = lu[(i, k)] / d;
                lu[(i, k)] = l;
                if l != 0.0 {
                    for j in (k + 1)..N {
                        lu[(i, j)] -= l * lu[(k, j)];
                    }
                }
            }
        }
        Some(Self { lu, perm })
    }

    /// Solve A X = B.
    pub fn solve<const C: usize>(&self, b: &SMatrix<f64, N, C>) -> SMatrix<f64, N, C> {
        let mut x = SMatrix::<f64, N, C>::zeros();
        for i in 0..N {
            x.set_row(i, &b.row(self.perm[i]));
        }
        for c in 0..C {
            for i in 0..N {
                let mut s = x[(i, c)];
                for k in 0..i {
                    s -= self.lu[(i, k)] * x[(k, c)];
                }
                x[(i, c)] = s;
            }
            for i in (0..N).rev() {
                let mut s = x[(i, c)];
                for k in (i + 1)..N {
                    s -= self.lu[(i, k)] * x[(k, c)];
                }
                x[(i, c)] = s / self.lu[(i, i)];
            }
        }
        x
    }
}

fn symmetrise<const N: usize>(m: &mut SMatrix<f64, N, N>) {
    for i in 0..N {
        for j in (i + 1)..N {
            let v = 0.5 * (m[(i, j)] + m[(j, i)]);
            m[(i, j)] = v;
            m[(j, i)] = v;
        }
    }
}

fn all_finite<const R: usize, const C: usize>(m: &SMatrix<f64, R, C>) -> bool {
    m.iter().all(|x| x.is_finite())
}

/// Steady-state solution P of the discrete algebraic Riccati equation
/// `P = Φᵀ P Φ − Φᵀ P Γ (R + Γᵀ P Γ)⁻¹ Γᵀ P Φ + Q` (the fixed point of (3.1.3–3.1.4))
/// by the structured doubling algorithm SDA-1 (Chu, Fan, Lin 2005):
///
/// ```text
/// A₀ = Φ, G₀ = Γ R⁻¹ Γᵀ, H₀ = Q,  W_k = I + G_k H_k
/// A_{k+1} = A_k W_k⁻¹ A_k
/// G_{k+1} = G_k + A_k W_k⁻¹ G_k A_kᵀ
/// H_{k+1} = H_k + A_kᵀ H_k W_k⁻¹ A_k      → P (quadratically)
/// ```
///
/// `r_diag` is the diagonal of R (control weights are diagonal, (3.4.2)). After k
/// doublings H_k equals the finite-horizon Riccati iterate of 2^k steps, so the
/// solution is the N → ∞ limit of the thesis's backward iteration.
pub fn dare_sda<const N: usize, const U: usize>(
    phi: &SMatrix<f64, N, N>,
    gamma: &SMatrix<f64, N, U>,
    q: &SMatrix<f64, N, N>,
    r_diag: &SVector<f64, U>,
) -> Result<SMatrix<f64, N, N>, RiccatiError> {
    if r_diag.iter().any(|r| r.is_nan() || *r <= 0.0) {
        return Err(RiccatiError::Singular("control weight R not positive definite"));
    }
    let mut gr = *gamma;
    for (j, mut col) in gr.column_iter_mut().enumerate() {
        col /= r_diag[j];
    }
    let mut g = gr * gamma.transpose();
    symmetrise(&mut g);
    let mut a = *phi;
    let mut h = *q;
    let id = SMatrix::<f64, N, N>::identity();
    for _ in 0..60 {
        let w = id + g * h;
        let lu = Lu::new(&w).ok_or(RiccatiError::Singular("I + G H singular in doubling"))?;
        let x1 = lu.solve(&a);
        let x2 = lu.solve(&g);
        let h_new = h + a.transpose() * h * x1;
        let g_new = g + a * x2 * a.transpose();
        let a_new = a * x1;
        let mut h_new = h_new;
        symmetrise(&mut h_new);
        g = g_new;
        symmetrise(&mut g);
        if !all_finite(&h_new) || !all_finite(&g) || !all_finite(&a_new) {
            return Err(RiccatiError::NonFinite);
        }
        let change = (h_new - h).norm();
        h = h_new;
        a = a_new;
        if change <= 1e-13 * h.norm() {
            return Ok(h);
        }
    }
    Err(RiccatiError::NotConverged)
}

/// LQR gain `K = (R + Γᵀ P Γ)⁻¹ Γᵀ P Φ` ((3.1.5) with S = P).
pub fn lqr_gain<const N: usize, const U: usize>(
    phi: &SMatrix<f64, N, N>,
    gamma: &SMatrix<f64, N, U>,
    p: &SMatrix<f64, N, N>,
    r_diag: &SVector<f64, U>,
) -> Result<SMatrix<f64, U, N>, RiccatiError> {
    let gtp = gamma.transpose() * p;
    let mut s = gtp * gamma;
    for i in 0..U {
        s[(i, i)] += r_diag[i];
    }
    symmetrise(&mut s);
    let rhs = gtp * phi;
    let k = s
        .cholesky()
        .ok_or(RiccatiError::Singular("R + Γᵀ P Γ not positive definite"))?
        .solve(&rhs);
    if all_finite(&k) {
        Ok(k)
    } else {
        Err(RiccatiError::NonFinite)
    }
}

/// Relative residual ‖Φᵀ P Φ − P − Φᵀ P Γ K + Q‖_F / ‖P‖_F of the DARE with
/// `K = (R + Γᵀ P Γ)⁻¹ Γᵀ P Φ`.
pub fn dare_residual<const N: usize, const U: usize>(
    phi: &SMatrix<f64, N, N>,
    gamma: &SMatrix<f64, N, U>,
    q: &SMatrix<f64, N, N>,
    p: &SMatrix<f64, N, N>,
    k: &SMatrix<f64, U, N>,
) -> f64 {
    let ptp = phi.transpose() * p;
    let res = ptp * phi - p - ptp * gamma * k + q;
    res.norm() / p.norm().max(f64::MIN_POSITIVE)
}

/// Receives (step, K(step)) during [`riccati_backward`].
pub type GainCallback<'a, const N: usize, const U: usize> = &'a mut dyn FnMut(usize, &SMatrix<f64, U, N>);

/// The thesis's finite-horizon backward Riccati iteration (3.1.3–3.1.5) over `horizon`
/// steps from S(N) = Q₁, with constant Φ, Γ (static LQR, §3.1.3):
///
/// ```text
/// M(k)   = S(k) − S(k) Γ [Q₂ + Γᵀ S(k) Γ]⁻¹ Γᵀ S(k)
/// S(k−1) = Φᵀ M(k) Φ + Q₁
/// K(k−1) = [Q₂ + Γᵀ S(k) Γ]⁻¹ Γᵀ S(k) Φ      (computed in the last step only)
/// ```
///
/// `on_gain` receives (step, K) after every step when given (gain-settling study,
/// Fig. 3.19) — computing K at every step costs a little more.
pub fn riccati_backward<const N: usize, const U: usize>(
    phi: &SMatrix<f64, N, N>,
    gamma: &SMatrix<f64, N, U>,
    q: &SMatrix<f64, N, N>,
    r_diag: &SVector<f64, U>,
    horizon: usize,
    mut on_gain: Option<GainCallback<'_, N, U>>,
) -> Result<(SMatrix<f64, U, N>, SMatrix<f64, N, N>), RiccatiError> {
    let mut s = *q;
    let mut k = SMatrix::<f64, U, N>::zeros();
    for step in 0..horizon.max(1) {
        let gts = gamma.transpose() * s;
        let mut inner = gts * gamma;
        for i in 0..U {
            inner[(i, i)] += r_diag[i];
        }
        symmetrise(&mut inner);
        let chol = inner
            .cholesky()
            .ok_or(RiccatiError::Singular("Q2 + Γᵀ S Γ not positive definite"))?;
        let last = step + 1 == horizon.max(1);
        if last || on_gain.is_some() {
            k = chol.solve(&(gts * phi));
            if let Some(f) = on_gain.as_mut() {
                f(step + 1, &k);
            }
        }
        // (3.1.3): M = S − Sᵀ Γ inner⁻¹ Γᵀ S  (S symmetric).
        let m = s - gts.transpose() * chol.solve(&gts);
        let mut s_next = phi.transpose() * m * phi + q; // (3.1.4)
        symmetrise(&mut s_next);
        if !all_finite(&s_next) {
            return Err(RiccatiError::NonFinite);
        }
        s = s_next;
    }
    if all_finite(&k) {
        Ok((k, s))
    } else {
        Err(RiccatiError::NonFinite)
    }
}

/// An upper bound of the spectral radius ρ(M): ‖M^(2^k)‖^(1/2^k) with k = 16 repeated
/// squarings (Gelfand's formula; the bound exceeds ρ by at most a factor κ^(1/65536),
/// κ the eigenvector condition number, so a value < 1 proves stability). Each square is
/// normalised and the scale accumulated in logarithms, so nothing overflows.
pub fn spectral_radius_bound<const N: usize>(m: &SMatrix<f64, N, N>) -> f64 {
    let n0 = m.norm();
    if !n0.is_finite() {
        return f64::INFINITY;
    }
    if n0 == 0.0 {
        return 0.0;
    }
    let mut x = m / n0;
    let mut log = n0.ln();
    let mut power = 1.0;
    for _ in 0..16 {
        let y = x * x;
        let n = y.norm();
        if n == 0.0 {
            return 0.0;
        }
        if !n.is_finite() {
            return f64::INFINITY;
        }
        x = y / n;
        log = 2.0 * log + n.ln();
        power *= 2.0;
    }
    (log / power).exp()
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix1, Matrix2, Vector1, Vector2};

    #[test]
    fn expm_double_integrator_and_rotation() {
        let a = Matrix2::new(0.0, 1.0, 0.0, 0.0);
        let e = expm(&(a * 3.0));
        assert!((e - Matrix2::new(1.0, 3.0, 0.0, 1.0)).norm() < 1e-14);
        let w = 7.3;
        let rot = expm(&Matrix2::new(0.0, w, -w, 0.0));
        let (s, c) = w.sin_cos();
        assert!((rot - Matrix2::new(c, s, -s, c)).norm() < 1e-12, "{rot}");
    }

    #[test]
    fn zoh_double_integrator_is_exact() {
        // ẋ = [0 1; 0 0] x + [0; 1] u: Φ = [1 T; 0 1], Γ = [T²/2; T].
        let a = Matrix2::new(0.0, 1.0, 0.0, 0.0);
        let b = Vector2::new(0.0, 1.0);
        let ts = 0.02;
        let (phi, gamma) = discretise_zoh::<2, 1, 3>(&a, &b, ts);
        assert!((phi - Matrix2::new(1.0, ts, 0.0, 1.0)).norm() < 1e-15);
        assert!((gamma - Vector2::new(ts * ts / 2.0, ts)).norm() < 1e-15);
        // A first-order lag ẋ = −x/τ + u/τ: Φ = e^{−T/τ}, Γ = 1 − e^{−T/τ}.
        let tau = 0.1;
        let (phi, gamma) = discretise_zoh::<1, 1, 2>(&Matrix1::new(-1.0 / tau), &Matrix1::new(1.0 / tau), ts);
        let e = (-ts / tau).exp();
        assert!((phi[0] - e).abs() < 1e-15 && (gamma[0] - (1.0 - e)).abs() < 1e-15);
    }

    #[test]
    fn scalar_dare_closed_form() {
        // x⁺ = a x + b u, weights q, r: p = q + a²p − a²b²p²/(r + b²p) ⇔
        // b² p² + (r(1 − a²) − q b²) p − q r = 0.
        for &(a, b, q, r) in &[
            (1.2f64, 0.5f64, 2.0f64, 0.7f64),
            (0.9, 1.0, 1.0, 1.0),
            (1.0, 0.02, 100.0, 3.0),
        ] {
            let bq = r * (1.0 - a * a) - q * b * b;
            let p_exact = (-bq + (bq * bq + 4.0 * b * b * q * r).sqrt()) / (2.0 * b * b);
            let p = dare_sda(&Matrix1::new(a), &Matrix1::new(b), &Matrix1::new(q), &Vector1::new(r)).unwrap();
            assert!((p[0] - p_exact).abs() < 1e-10 * p_exact, "{} vs {}", p[0], p_exact);
            let k = lqr_gain(&Matrix1::new(a), &Matrix1::new(b), &p, &Vector1::new(r)).unwrap();
            assert!((a - b * k[0]).abs() < 1.0);
        }
    }

    #[test]
    fn double_integrator_dare_known_solution() {
        // Φ = [1 1; 0 1], Γ = [0; 1], Q = I, R = 1 has the known stabilising solution
        // a unique stabilising solution: check the residual and the backward-iteration limit.
        let phi = Matrix2::new(1.0, 1.0, 0.0, 1.0);
        let gamma = Vector2::new(0.0, 1.0);
        let q = Matrix2::identity();
        let r = Vector1::new(1.0);
        let p = dare_sda(&phi, &gamma, &q, &r).unwrap();
        let k = lqr_gain(&phi, &gamma, &p, &r).unwrap();
        assert!(dare_residual(&phi, &gamma, &q, &p, &k) < 1e-13);
        // The doubling limit equals a long backward iteration (3.1.3–3.1.5).
        let (k_back, p_back) = riccati_backward(&phi, &gamma, &q, &r, 2000, None).unwrap();
        assert!((p - p_back).norm() < 1e-9 * p.norm());
        assert!((k - k_back).norm() < 1e-9 * k.norm());
        let rho = spectral_radius_bound(&(phi - gamma * k));
        assert!(rho < 1.0, "{rho}");
    }

    #[test]
    fn double_integrator_scalar_weights_closed_form() {
        // Φ = I (2×2), Γ = I, Q = I, R = I decouples into scalar DAREs with a = b = q = r = 1:
        // p² − p − 1 = 0 ⇒ p = golden ratio.
        let p = dare_sda(
            &Matrix2::identity(),
            &Matrix2::identity(),
            &Matrix2::identity(),
            &Vector2::new(1.0, 1.0),
        )
        .unwrap();
        let golden = (1.0 + 5f64.sqrt()) / 2.0;
        assert!((p - Matrix2::identity() * golden).norm() < 1e-12);
    }

    #[test]
    fn backward_iteration_converges_to_dare_as_horizon_grows() {
        let phi = Matrix2::new(1.0, 0.02, 0.0, 1.0);
        let gamma = Vector2::new(0.0002, 0.02);
        let q = Matrix2::new(4.0, 0.0, 0.0, 1.0);
        let r = Vector1::new(0.1);
        let p = dare_sda(&phi, &gamma, &q, &r).unwrap();
        let k = lqr_gain(&phi, &gamma, &p, &r).unwrap();
        let mut last = f64::INFINITY;
        for n in [25, 50, 100, 200, 400, 800, 1600] {
            let (kn, _) = riccati_backward(&phi, &gamma, &q, &r, n, None).unwrap();
            let err = (kn - k).norm() / k.norm();
            assert!(err <= last * 1.0000001, "error grew at N = {n}: {err} > {last}");
            last = err;
        }
        assert!(last < 1e-8, "{last}");
    }

    #[test]
    fn spectral_radius_bound_is_tight() {
        let m = Matrix2::new(0.9, 100.0, 0.0, 0.5);
        let rho = spectral_radius_bound(&m);
        assert!((0.9..0.901).contains(&rho), "{rho}");
        let m = Matrix2::new(0.0, 1.0, -1.0, 0.0) * 1.01;
        assert!((spectral_radius_bound(&m) - 1.01).abs() < 1e-4);
    }
}
