//! Dense linear algebra on statically sized matrices (no heap): zero-order-hold
//! discretisation by the matrix exponential, the discrete algebraic Riccati equation
//! (structured doubling), the thesis's finite-horizon backward Riccati iteration
//! (3.1.3–3.1.5), the LQR gain and a spectral-radius bound.

use nalgebra::{ArrayStorage, SMatrix, SVector};

/// Whether this CPU runs the AVX2 + FMA builds (checked once per call; cached by std).
#[inline]
#[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]
fn fused_build() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// Defines `$name`, an `unsafe` wrapper compiled for AVX2 + FMA that calls the
/// `#[inline(always)]` generic `$imp::<…, true>` (so the whole kernel is inlined and compiled
/// with those features: fused multiply-adds, 4-wide vectors). The public entry points call
/// it when [`fused_build`] says the CPU has both, else `$imp::<…, false>` (baseline target,
/// separate multiply and add). The two builds differ only in the matrix products'
/// multiply-adds ([`dense::madd`]), so they agree to rounding, not bit for bit; calling
/// `$imp::<…, true>` directly (software `fma`, also correctly rounded) gives the fused
/// build's bits on any CPU.
macro_rules! fused_wrapper {
    ($name:ident, $imp:ident, [$(const $g:ident: usize),*], ($($arg:ident: $ty:ty),*) -> $ret:ty) => {
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = "avx2,fma")]
        unsafe fn $name<$(const $g: usize),*>($($arg: $ty),*) -> $ret {
            $imp::<$($g,)* true>($($arg),*)
        }
    };
}

/// Call the fused wrapper `$fused` when the CPU has AVX2 + FMA, else `$imp::<…, false>`.
macro_rules! dispatch {
    ($fused:ident, $imp:ident, [$($g:ident),*], ($($arg:expr),*)) => {{
        #[cfg(target_arch = "x86_64")]
        {
            if fused_build() {
                // SAFETY: the CPU supports AVX2 and FMA (checked just above), the only
                // requirement of the `#[target_feature(enable = "avx2,fma")]` wrapper.
                return unsafe { $fused::<$($g),*>($($arg),*) };
            }
        }
        $imp::<$($g,)* false>($($arg),*)
    }};
}

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

/// Coefficients c_k = (2q−k)! q! / ((2q)! k! (q−k)!) of the diagonal [6/6] Padé approximant
/// of e^X (q = 6).
const PADE_6: [f64; 7] = [
    1.0,
    0.5,
    5.0 / 44.0,
    1.0 / 66.0,
    1.0 / 792.0,
    1.0 / 15840.0,
    1.0 / 665280.0,
];

/// Scaling of the scaling-and-squaring method: the smallest s ≥ 0 with ‖X‖₁ / 2^s ≤ 1/2,
/// where the [6/6] Padé error is below 1e-16 relative, and the factor 2^-s.
fn pade_scaling(norm_1: f64) -> (i32, f64) {
    let s = if norm_1 > 0.5 {
        (norm_1 / 0.5).log2().ceil() as i32
    } else {
        0
    };
    (s, 2f64.powi(-s))
}

/// The top R rows (column-major, C ≥ R columns; the identity occupies the first R columns)
/// of the Padé even part U = c₀ I + c₂ X² + c₄ X⁴ + c₆ X⁶ and of the odd part's factor
/// c₁ I + c₃ X² + c₅ X⁴ (V = X times it), from the top rows of X², X⁴, X⁶.
#[inline(always)]
fn pade_parts<const R: usize, const C: usize>(
    x2: &[[f64; R]; C],
    x4: &[[f64; R]; C],
    x6: &[[f64; R]; C],
) -> ([[f64; R]; C], [[f64; R]; C]) {
    let c = &PADE_6;
    let mut u = [[0.0; R]; C];
    let mut vi = [[0.0; R]; C];
    for j in 0..C {
        for i in 0..R {
            u[j][i] = x2[j][i] * c[2] + x4[j][i] * c[4] + x6[j][i] * c[6];
            vi[j][i] = x2[j][i] * c[3] + x4[j][i] * c[5];
        }
    }
    for i in 0..R {
        u[i][i] += c[0];
        vi[i][i] += c[1];
    }
    (u, vi)
}

/// E = D⁻¹ N of the Padé approximant (column-major, C columns; `den` is overwritten by its LU
/// factors); all NaN when D is singular, which the callers' finiteness checks report.
#[inline(always)]
fn pade_solve<const R: usize, const C: usize>(den: &mut [[f64; R]; R], num: &[[f64; R]; C]) -> [[f64; R]; C] {
    // Row-major right-hand side for the solver: the rows of N.
    let mut y = dense::transpose(num);
    let mut none = [[0.0; 0]; R];
    if dense::lu_solve2(den, &mut y, &mut none) {
        dense::transpose(&y)
    } else {
        [[f64::NAN; R]; C]
    }
}

/// Matrix exponential e^A by scaling and squaring with the diagonal [6/6] Padé
/// approximant: A is scaled by 2^-s so that ‖A/2^s‖₁ ≤ 1/2, where the [6/6] Padé
/// error is below 1e-16 relative (Moler & Van Loan, "Nineteen dubious ways", method 3).
pub fn expm<const N: usize>(a: &SMatrix<f64, N, N>) -> SMatrix<f64, N, N> {
    dispatch!(expm_fused, expm_impl, [N], (a))
}

fused_wrapper!(expm_fused, expm_impl, [const N: usize], (a: &SMatrix<f64, N, N>) -> SMatrix<f64, N, N>);

#[inline(always)]
fn expm_impl<const N: usize, const F: bool>(a: &SMatrix<f64, N, N>) -> SMatrix<f64, N, N> {
    let (s, scale) = pade_scaling(a.column_iter().map(|c| c.abs().sum()).fold(0.0, f64::max));
    let mut x = a.data.0;
    for col in x.iter_mut() {
        for v in col.iter_mut() {
            *v *= scale;
        }
    }
    let x2 = dense::mul::<_, _, _, F>(&x, &x);
    let x4 = dense::mul::<_, _, _, F>(&x2, &x2);
    let x6 = dense::mul::<_, _, _, F>(&x4, &x2);
    // Even part U and odd part V = X·vi: N = U + V, D = U − V.
    let (u, vi) = pade_parts(&x2, &x4, &x6);
    let v = dense::mul::<_, _, _, F>(&x, &vi);
    let mut den = [[0.0; N]; N];
    let mut num = [[0.0; N]; N];
    for j in 0..N {
        for i in 0..N {
            num[j][i] = u[j][i] + v[j][i];
            den[j][i] = u[j][i] - v[j][i];
        }
    }
    let mut e = pade_solve(&mut den, &num);
    for _ in 0..s {
        e = dense::mul::<_, _, _, F>(&e, &e);
    }
    SMatrix::from_data(ArrayStorage(e))
}

/// Zero-order-hold discretisation (replacing the Euler approximation (3.2.10–3.2.11)):
/// `Φ = e^{A T}`, `Γ = ∫₀^T e^{A τ} dτ B`, both read off `exp([A B; 0 0] T)`.
/// `M` must be `NX + NU` (const generics cannot express the sum).
///
/// The exponential is [`expm`]'s scaling and squaring with the [6/6] Padé approximant,
/// computed on the top NX rows only: every power of Z = [A B; 0 0] T is [Aᵏ Aᵏ⁻¹B; 0 0],
/// the Padé numerator and denominator are [N₁ N₂; 0 I], [D₁ D₂; 0 I], so
/// e^Z = [D₁⁻¹N₁, D₁⁻¹(N₂ − D₂); 0 I], and a square of [E₁ E₂; 0 I] is
/// [E₁E₁, E₁E₂ + E₂; 0 I]. Each product is NX × NX by NX × M (≈ 0.44 of the M × M
/// product's work for 14 states and 7 inputs); the result equals [`expm`] of the augmented
/// matrix to rounding (test `block_zoh_equals_full_exponential`).
pub fn discretise_zoh<const NX: usize, const NU: usize, const M: usize>(
    a: &SMatrix<f64, NX, NX>,
    b: &SMatrix<f64, NX, NU>,
    ts: f64,
) -> (SMatrix<f64, NX, NX>, SMatrix<f64, NX, NU>) {
    assert_eq!(M, NX + NU, "augmented size must be NX + NU");
    let mut z = [[0.0; NX]; M];
    for j in 0..NX {
        for i in 0..NX {
            z[j][i] = a[(i, j)] * ts;
        }
    }
    for j in 0..NU {
        for i in 0..NX {
            z[NX + j][i] = b[(i, j)] * ts;
        }
    }
    let e = zoh_top::<NX, M>(&z);
    let mut phi = SMatrix::<f64, NX, NX>::zeros();
    let mut gamma = SMatrix::<f64, NX, NU>::zeros();
    for i in 0..NX {
        for j in 0..NX {
            phi[(i, j)] = e[j][i];
        }
        for j in 0..NU {
            gamma[(i, j)] = e[NX + j][i];
        }
    }
    (phi, gamma)
}

/// [`zoh_top_impl`] in the build this CPU runs (see `fused_wrapper!`).
fn zoh_top<const NX: usize, const M: usize>(z: &[[f64; NX]; M]) -> [[f64; NX]; M] {
    dispatch!(zoh_top_fused, zoh_top_impl, [NX, M], (z))
}

fused_wrapper!(zoh_top_fused, zoh_top_impl, [const NX: usize, const M: usize], (z: &[[f64; NX]; M]) -> [[f64; NX]; M]);

/// The top NX rows of exp([Z₁ Z₂; 0 0]) given the top rows `z` = [Z₁ Z₂] (column-major,
/// M columns); see [`discretise_zoh`].
#[inline(always)]
fn zoh_top_impl<const NX: usize, const M: usize, const F: bool>(z: &[[f64; NX]; M]) -> [[f64; NX]; M] {
    // ‖Z‖₁ (the zero rows add nothing to the column sums).
    let (s, scale) = pade_scaling(
        z.iter()
            .map(|c| c.iter().map(|v| v.abs()).sum::<f64>())
            .fold(0.0, f64::max),
    );
    let mut x = *z;
    dense::scale(&mut x, scale);
    // Top rows of a product of two block matrices [P₁ P₂; 0 0] [Q₁ Q₂; 0 0] = P₁ [Q₁ Q₂].
    let left = |m: &[[f64; NX]; M]| -> [[f64; NX]; NX] { core::array::from_fn(|j| m[j]) };
    let x_l = left(&x);
    let x2 = dense::mul::<NX, NX, M, F>(&x_l, &x);
    let x4 = dense::mul::<NX, NX, M, F>(&left(&x2), &x2);
    let x6 = dense::mul::<NX, NX, M, F>(&left(&x4), &x2);
    // Even part U = c₀ I + c₂ Z² + c₄ Z⁴ + c₆ Z⁶, odd part V = Z (c₁ I + c₃ Z² + c₅ Z⁴):
    // top rows; the bottom rows are [0 c₀ I] and 0.
    let (u, vi) = pade_parts(&x2, &x4, &x6);
    // V's top rows: Z₁ vi_top + Z₂ [0 c₁ I] = Z₁ vi_top + [0 c₁ Z₂].
    let mut v = dense::mul::<NX, NX, M, F>(&x_l, &vi);
    for j in NX..M {
        for i in 0..NX {
            v[j][i] += PADE_6[1] * x[j][i];
        }
    }
    // D E = N with D = [D₁ D₂; 0 I], N = [N₁ N₂; 0 I]: E's top rows solve
    // D₁ [E₁ E₂] = [N₁, N₂ − D₂] (the bottom rows of E are [0 I]).
    let mut den = [[0.0; NX]; NX];
    for j in 0..NX {
        for i in 0..NX {
            den[j][i] = u[j][i] - v[j][i];
        }
    }
    let mut rhs = [[0.0; NX]; M];
    for j in 0..M {
        for i in 0..NX {
            rhs[j][i] = u[j][i] + v[j][i];
        }
    }
    for j in NX..M {
        for i in 0..NX {
            rhs[j][i] -= u[j][i] - v[j][i];
        }
    }
    let mut e = pade_solve(&mut den, &rhs);
    // Squarings: [E₁ E₂; 0 I]² = [E₁ E₁, E₁ E₂ + E₂; 0 I].
    for _ in 0..s {
        let mut sq = dense::mul::<NX, NX, M, F>(&left(&e), &e);
        for j in NX..M {
            for i in 0..NX {
                sq[j][i] += e[j][i];
            }
        }
        e = sq;
    }
    e
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
/// solution is the N → ∞ limit of the thesis's backward iteration. The iteration stops
/// when ‖H_{k+1} − H_k‖_F ≤ 1e-13 ‖H_{k+1}‖_F.
///
/// The iteration runs on [`dense`] kernels (column-major arrays, constant trip counts,
/// no heap) compiled twice: for the baseline target and, selected at run time when the
/// CPU has them, for AVX2 + FMA (fused multiply-adds in the products). The two agree to
/// rounding (not bit for bit, see `fused_wrapper!`). The H and G updates are symmetric
/// congruences (H W⁻¹ = (I + H G)⁻¹ H and W⁻¹ G are symmetric), computed as half products
/// ([`dense::sym_mul_add`]), so every H_k, G_k and the returned P are exactly symmetric.
pub fn dare_sda<const N: usize, const U: usize>(
    phi: &SMatrix<f64, N, N>,
    gamma: &SMatrix<f64, N, U>,
    q: &SMatrix<f64, N, N>,
    r_diag: &SVector<f64, U>,
) -> Result<SMatrix<f64, N, N>, RiccatiError> {
    dispatch!(dare_sda_fused, dare_sda_impl, [N, U], (phi, gamma, q, r_diag))
}

fused_wrapper!(
    dare_sda_fused,
    dare_sda_impl,
    [const N: usize, const U: usize],
    (
        phi: &SMatrix<f64, N, N>,
        gamma: &SMatrix<f64, N, U>,
        q: &SMatrix<f64, N, N>,
        r_diag: &SVector<f64, U>
    ) -> Result<SMatrix<f64, N, N>, RiccatiError>
);

#[inline(always)]
fn dare_sda_impl<const N: usize, const U: usize, const F: bool>(
    phi: &SMatrix<f64, N, N>,
    gamma: &SMatrix<f64, N, U>,
    q: &SMatrix<f64, N, N>,
    r_diag: &SVector<f64, U>,
) -> Result<SMatrix<f64, N, N>, RiccatiError> {
    if r_diag.iter().any(|r| r.is_nan() || *r <= 0.0) {
        return Err(RiccatiError::Singular("control weight R not positive definite"));
    }
    // G₀ = Γ R⁻¹ Γᵀ.
    let mut gr = gamma.data.0;
    for (j, col) in gr.iter_mut().enumerate() {
        let rj = r_diag[j];
        for v in col.iter_mut() {
            *v /= rj;
        }
    }
    let gt = dense::transpose(&gamma.data.0);
    let mut g = dense::mul::<_, _, _, F>(&gr, &gt);
    dense::symmetrise(&mut g);
    let mut a = phi.data.0;
    let mut h = q.data.0;
    for _ in 0..60 {
        // W = I + G H; X₁ = W⁻¹ A, X₂ = W⁻¹ G.
        let mut w = dense::mul::<_, _, _, F>(&g, &h);
        for (i, col) in w.iter_mut().enumerate() {
            col[i] += 1.0;
        }
        // Row-major right-hand sides: Aᵀ's columns are A's rows, G is symmetric.
        let at = dense::transpose(&a);
        let mut y1 = at;
        let mut y2 = g;
        if !dense::lu_solve2(&mut w, &mut y1, &mut y2) {
            return Err(RiccatiError::Singular("I + G H singular in doubling"));
        }
        // y1, y2 are X₁ = W⁻¹ A and X₂ = W⁻¹ G row-major: used as right factors as they are.
        // H ← H + Aᵀ (H X₁), G ← G + (A X₂) Aᵀ: both updates are symmetric (H W⁻¹ = (I + H G)⁻¹ H
        // and W⁻¹ G are), so only their lower triangles are computed and mirrored.
        let h_new = dense::sym_mul_add::<_, _, F>(&h, &at, &dense::mul_rows::<_, _, _, F>(&h, &y1));
        g = dense::sym_mul_add::<_, _, F>(&g, &dense::mul_rows::<_, _, _, F>(&a, &y2), &at);
        a = dense::mul_rows::<_, _, _, F>(&a, &y1);
        let change2 = dense::diff_norm2(&h_new, &h);
        h = h_new;
        let g_norm2 = dense::norm2(&g);
        let h_norm2 = dense::norm2(&h);
        let a_norm2 = dense::norm2(&a);
        if !(h_norm2.is_finite() && g_norm2.is_finite() && a_norm2.is_finite()) {
            return Err(RiccatiError::NonFinite);
        }
        // Stop when the last change is below 1e-13 relative, or when ‖A_{k+1}‖_F² ≤ 1e-13:
        // 0 ≤ P − H_{k+1} ≤ A_{k+1}ᵀ P A_{k+1} (Lin & Xu 2006, Thm 3.1: P − H_k =
        // A_kᵀ (P⁻¹ + G_k)⁻¹ A_k with G_k ≥ 0), so then ‖P − H_{k+1}‖₂ ≤ 1e-13 ‖P‖₂.
        // The second test saves the last doubling, whose change is already ≈ 1e-19.
        if change2.sqrt() <= 1e-13 * h_norm2.sqrt() || a_norm2 <= 1e-13 {
            return Ok(SMatrix::from_data(ArrayStorage(h)));
        }
    }
    Err(RiccatiError::NotConverged)
}

/// One Newton step (Kleinman 1968, Hewer 1971) on the DARE from an approximate solution
/// `p0` (e.g. the previous relinearisation's P): with K₀ = (R + Γᵀ P₀ Γ)⁻¹ Γᵀ P₀ Φ and
/// A_c = Φ − Γ K₀, the DARE's Fréchet derivative at P₀ is X ↦ A_cᵀ X A_c − X, so the
/// Newton correction X solves the Stein equation
///
/// ```text
/// X = A_cᵀ X A_c + 𝓡(P₀),   𝓡(P) = Φᵀ P Φ − P − Φᵀ P Γ K(P) + Q   (the DARE residual)
/// ```
///
/// and P₁ = P₀ + X; the error falls quadratically (relative 4e-7 → 1e-13 on the aircraft's
/// level flight). The Stein equation is solved by Smith's doubling, X_{k+1} = X_k +
/// A_kᵀ X_k A_k, A_{k+1} = A_k², whose truncation error is A_kᵀ X A_k: it stops when
/// ‖A_k‖²_F ‖X_k‖_F ≤ 1e-15 ‖P₀‖_F, i.e. when the correction is exact far below the
/// rounding of P. Only the correction (small) is iterated, so a step costs three 17×17
/// products per doubling against SDA's LU solve and five products.
///
/// A start whose relative residual ‖𝓡(P₀)‖_F / ‖P₀‖_F is already at most `converged` is
/// returned as it is (X = 0, no doubling): a model that has not changed since the last
/// solve (steady flight) costs only the residual. 0 always takes the step.
///
/// Returns P₁ and the relative size ‖X‖_F / ‖P₁‖_F of the correction. `Err` when
/// ‖𝓡(P₀)‖_F > `max_residual` ‖P₀‖_F (P₀ too far from the solution for one step to reach
/// rounding: checked before the doubling, so a far start costs only the residual), when K₀ cannot
/// be formed, when A_c is not stable (the doubling does not contract within 40 doublings)
/// or on non-finite values; the caller must then solve cold ([`dare_sda`]) and should in
/// any case accept P₁ only after checking its residual ([`dare_residual`]).
pub fn dare_newton_step<const N: usize, const U: usize>(
    phi: &SMatrix<f64, N, N>,
    gamma: &SMatrix<f64, N, U>,
    q: &SMatrix<f64, N, N>,
    r_diag: &SVector<f64, U>,
    p0: &SMatrix<f64, N, N>,
    max_residual: f64,
    converged: f64,
) -> Result<(SMatrix<f64, N, N>, f64), RiccatiError> {
    let k0 = lqr_gain(phi, gamma, p0, r_diag)?;
    let ptp = phi.transpose() * p0;
    // 𝓡(P₀) = Φᵀ P₀ Φ − P₀ − (Φᵀ P₀ Γ) K₀ + Q, symmetrised (symmetric in exact arithmetic).
    let mut res = ptp * phi - p0 - (ptp * gamma) * k0 + q;
    symmetrise(&mut res);
    let rel_res = res.norm() / p0.norm().max(f64::MIN_POSITIVE);
    if rel_res.is_nan() || rel_res > max_residual {
        return Err(RiccatiError::Residual(rel_res));
    }
    if rel_res <= converged {
        return Ok((*p0, 0.0));
    }
    let ac = phi - gamma * k0;
    if !(all_finite(&res) && all_finite(&ac)) {
        return Err(RiccatiError::NonFinite);
    }
    let tol2 = (1e-15 * p0.norm()).powi(2);
    let x = stein_smith(&ac, &res, tol2)?;
    let mut p1 = p0 + SMatrix::<f64, N, N>::from_data(ArrayStorage(x));
    symmetrise(&mut p1);
    let rel = SMatrix::<f64, N, N>::from_data(ArrayStorage(x)).norm() / p1.norm().max(f64::MIN_POSITIVE);
    Ok((p1, rel))
}

/// [`stein_smith_impl`] in the build this CPU runs (see `fused_wrapper!`).
fn stein_smith<const N: usize>(
    ac: &SMatrix<f64, N, N>,
    e: &SMatrix<f64, N, N>,
    tol2: f64,
) -> Result<[[f64; N]; N], RiccatiError> {
    dispatch!(stein_smith_fused, stein_smith_impl, [N], (ac, e, tol2))
}

fused_wrapper!(
    stein_smith_fused,
    stein_smith_impl,
    [const N: usize],
    (ac: &SMatrix<f64, N, N>, e: &SMatrix<f64, N, N>, tol2: f64) -> Result<[[f64; N]; N], RiccatiError>
);

/// Smith's doubling for X = A_cᵀ X A_c + E (E symmetric): see [`dare_newton_step`]. Stops
/// when ‖A_k‖⁴_F ‖X_k‖²_F ≤ `tol2`, the square of the bound ‖A_k‖²_F ‖X_k‖_F of the
/// truncation error A_kᵀ X A_k.
#[inline(always)]
fn stein_smith_impl<const N: usize, const F: bool>(
    ac: &SMatrix<f64, N, N>,
    e: &SMatrix<f64, N, N>,
    tol2: f64,
) -> Result<[[f64; N]; N], RiccatiError> {
    let mut a = ac.data.0;
    let mut x = e.data.0;
    for _ in 0..40 {
        let at = dense::transpose(&a);
        // X ← X + Aᵀ (X A): a symmetric congruence, computed as a half product.
        x = dense::sym_mul_add::<_, _, F>(&x, &at, &dense::mul::<_, _, _, F>(&x, &a));
        a = dense::mul::<_, _, _, F>(&a, &a);
        let a2 = dense::norm2(&a);
        let x2 = dense::norm2(&x);
        if !(a2.is_finite() && x2.is_finite()) {
            return Err(RiccatiError::NonFinite);
        }
        if a2 * a2 * x2 <= tol2 {
            return Ok(x);
        }
    }
    Err(RiccatiError::NotConverged)
}

/// Dense kernels on column-major arrays `[[f64; R]; C]` (nalgebra's static storage):
/// constant trip counts and column-wise updates (no reductions in the inner loops) so
/// that the compiler vectorises them for the target it compiles for. All
/// `#[inline(always)]`, so that a `#[target_feature]` caller gets them compiled for its
/// features.
// Index loops over constant ranges are the point here (they vectorise); iterator
// adaptors over partial ranges do not always.
#[allow(clippy::needless_range_loop)]
pub mod dense {
    /// `acc + a b`: fused (one rounding, [`f64::mul_add`]) when `F`, else a product and a sum.
    #[inline(always)]
    pub fn madd<const F: bool>(acc: f64, a: f64, b: f64) -> f64 {
        if F {
            a.mul_add(b, acc)
        } else {
            acc + a * b
        }
    }

    /// Two columns of `A B` at once (each column of A loaded once per pair), rows
    /// `first_row..R` (the rows above are left 0); `b_pair(k)` gives row k of the two
    /// columns of B. Multiply-adds fused when `F` ([`madd`]).
    #[inline(always)]
    fn column_pair<const R: usize, const K: usize, const F: bool>(
        a: &[[f64; R]; K],
        first_row: usize,
        b_pair: impl Fn(usize) -> (f64, f64),
    ) -> ([f64; R], [f64; R]) {
        let mut acc0 = [0.0; R];
        let mut acc1 = [0.0; R];
        for (k, ak) in a.iter().enumerate() {
            let (s0, s1) = b_pair(k);
            for i in first_row..R {
                acc0[i] = madd::<F>(acc0[i], ak[i], s0);
                acc1[i] = madd::<F>(acc1[i], ak[i], s1);
            }
        }
        (acc0, acc1)
    }

    /// `A B`, two result columns at a time (each column of A loaded once per pair);
    /// multiply-adds fused when `F` ([`madd`]).
    #[inline(always)]
    pub fn mul<const R: usize, const K: usize, const C: usize, const F: bool>(
        a: &[[f64; R]; K],
        b: &[[f64; K]; C],
    ) -> [[f64; R]; C] {
        let mut c = [[0.0; R]; C];
        let mut j = 0;
        while j + 1 < C {
            let (b0, b1) = (&b[j], &b[j + 1]);
            (c[j], c[j + 1]) = column_pair::<R, K, F>(a, 0, |k| (b0[k], b1[k]));
            j += 2;
        }
        if j < C {
            let mut acc = [0.0; R];
            for (ak, &s) in a.iter().zip(b[j].iter()) {
                for i in 0..R {
                    acc[i] = madd::<F>(acc[i], ak[i], s);
                }
            }
            c[j] = acc;
        }
        c
    }

    /// `A B` with B given row-major (`b[k]` = row k of B): the operations of
    /// `mul(a, &transpose(b))` without the transpose.
    #[inline(always)]
    pub fn mul_rows<const R: usize, const K: usize, const C: usize, const F: bool>(
        a: &[[f64; R]; K],
        b: &[[f64; C]; K],
    ) -> [[f64; R]; C] {
        let mut c = [[0.0; R]; C];
        let mut j = 0;
        while j + 1 < C {
            (c[j], c[j + 1]) = column_pair::<R, K, F>(a, 0, |k| (b[k][j], b[k][j + 1]));
            j += 2;
        }
        if j < C {
            let mut acc = [0.0; R];
            for k in 0..K {
                let s = b[k][j];
                for i in 0..R {
                    acc[i] = madd::<F>(acc[i], a[k][i], s);
                }
            }
            c[j] = acc;
        }
        c
    }

    /// `D + A B` for a product known to be symmetric (and D symmetric): the columns of the
    /// upper half skip the rows above the 4-aligned row block `L = ⌊N/2⌋ & !3` (constant trip
    /// counts), and the upper triangle is mirrored from the lower, so the result is exactly
    /// symmetric at ≈ 80 % of the full product's work.
    #[inline(always)]
    pub fn sym_mul_add<const N: usize, const K: usize, const F: bool>(
        d: &[[f64; N]; N],
        a: &[[f64; N]; K],
        b: &[[f64; K]; N],
    ) -> [[f64; N]; N] {
        let lo = (N / 2) & !3;
        let mut c = [[0.0; N]; N];
        let mut j = 0;
        while j + 1 < lo {
            let (b0, b1) = (&b[j], &b[j + 1]);
            (c[j], c[j + 1]) = column_pair::<N, K, F>(a, 0, |k| (b0[k], b1[k]));
            j += 2;
        }
        while j < N {
            let j1 = (j + 1).min(N - 1);
            let (b0, b1) = (&b[j], &b[j1]);
            (c[j], c[j1]) = column_pair::<N, K, F>(a, lo, |k| (b0[k], b1[k]));
            j += 2;
        }
        for (cj, dj) in c.iter_mut().zip(d.iter()) {
            for i in 0..N {
                cj[i] += dj[i];
            }
        }
        for j in 0..N {
            for i in (j + 1)..N {
                c[i][j] = c[j][i];
            }
        }
        c
    }

    /// `D + A B`.
    #[inline(always)]
    pub fn mul_add<const R: usize, const K: usize, const C: usize, const F: bool>(
        d: &[[f64; R]; C],
        a: &[[f64; R]; K],
        b: &[[f64; K]; C],
    ) -> [[f64; R]; C] {
        let mut c = mul::<R, K, C, F>(a, b);
        for (cj, dj) in c.iter_mut().zip(d.iter()) {
            for i in 0..R {
                cj[i] += dj[i];
            }
        }
        c
    }

    /// `Aᵀ`.
    #[inline(always)]
    pub fn transpose<const R: usize, const C: usize>(a: &[[f64; R]; C]) -> [[f64; C]; R] {
        let mut t = [[0.0; C]; R];
        for (j, aj) in a.iter().enumerate() {
            for (i, v) in aj.iter().enumerate() {
                t[i][j] = *v;
            }
        }
        t
    }

    /// `M ← s M`.
    #[inline(always)]
    pub fn scale<const R: usize, const C: usize>(m: &mut [[f64; R]; C], s: f64) {
        for col in m.iter_mut() {
            for v in col.iter_mut() {
                *v *= s;
            }
        }
    }

    /// `(M + Mᵀ)/2` in place.
    #[inline(always)]
    pub fn symmetrise<const N: usize>(m: &mut [[f64; N]; N]) {
        for j in 0..N {
            for i in (j + 1)..N {
                let v = 0.5 * (m[j][i] + m[i][j]);
                m[j][i] = v;
                m[i][j] = v;
            }
        }
    }

    /// Squared Frobenius norm.
    #[inline(always)]
    pub fn norm2<const R: usize, const C: usize>(a: &[[f64; R]; C]) -> f64 {
        let mut acc = [0.0; R];
        for aj in a {
            for i in 0..R {
                acc[i] += aj[i] * aj[i];
            }
        }
        acc.iter().sum()
    }

    /// Squared Frobenius norm of `A − B`.
    #[inline(always)]
    pub fn diff_norm2<const R: usize, const C: usize>(a: &[[f64; R]; C], b: &[[f64; R]; C]) -> f64 {
        let mut acc = [0.0; R];
        for (aj, bj) in a.iter().zip(b.iter()) {
            for i in 0..R {
                let d = aj[i] - bj[i];
                acc[i] += d * d;
            }
        }
        acc.iter().sum()
    }

    /// Solve `W X₁ = B₁` and `W X₂ = B₂` in place by Gaussian elimination with partial
    /// pivoting; `W` is overwritten. The right-hand sides are given and returned
    /// row-major (`y[i]` = row i, i.e. the column-major arrays of B₁ᵀ, B₂ᵀ), so that every
    /// elimination and substitution step is one whole-row update. `false` if a pivot is
    /// zero or not finite.
    #[inline(always)]
    pub fn lu_solve2<const N: usize, const C1: usize, const C2: usize>(
        w: &mut [[f64; N]; N],
        y1: &mut [[f64; C1]; N],
        y2: &mut [[f64; C2]; N],
    ) -> bool {
        for k in 0..N {
            let mut piv = k;
            let mut best = w[k][k].abs();
            for i in (k + 1)..N {
                let v = w[k][i].abs();
                if v > best {
                    best = v;
                    piv = i;
                }
            }
            if !(best > 0.0 && best.is_finite()) {
                return false;
            }
            if piv != k {
                for col in w.iter_mut() {
                    col.swap(k, piv);
                }
                y1.swap(k, piv);
                y2.swap(k, piv);
            }
            // Multipliers l_i = w_ik / w_kk below the pivot, zero elsewhere, so that the
            // rank-1 update of W runs over whole columns (constant trip count).
            let d = w[k][k];
            let mut l = [0.0; N];
            for i in (k + 1)..N {
                l[i] = w[k][i] / d;
            }
            for col in w.iter_mut().skip(k + 1) {
                let s = col[k];
                for i in 0..N {
                    col[i] -= l[i] * s;
                }
            }
            // Local copies of the pivot rows: no aliasing with the rows updated.
            let (r1, r2) = (y1[k], y2[k]);
            for i in (k + 1)..N {
                let li = l[i];
                let row1 = &mut y1[i];
                for j in 0..C1 {
                    row1[j] -= li * r1[j];
                }
                let row2 = &mut y2[i];
                for j in 0..C2 {
                    row2[j] -= li * r2[j];
                }
            }
        }
        // Back substitution: row k /= u_kk, then subtract u_ik · row k from the rows above.
        for k in (0..N).rev() {
            let d = w[k][k];
            let mut r1 = y1[k];
            let mut r2 = y2[k];
            for v in r1.iter_mut() {
                *v /= d;
            }
            for v in r2.iter_mut() {
                *v /= d;
            }
            y1[k] = r1;
            y2[k] = r2;
            for i in 0..k {
                let u = w[k][i];
                let row1 = &mut y1[i];
                for j in 0..C1 {
                    row1[j] -= u * r1[j];
                }
                let row2 = &mut y2[i];
                for j in 0..C2 {
                    row2[j] -= u * r2[j];
                }
            }
        }
        true
    }
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
    dispatch!(spectral_radius_bound_fused, spectral_radius_bound_impl, [N], (m))
}

fused_wrapper!(spectral_radius_bound_fused, spectral_radius_bound_impl, [const N: usize], (m: &SMatrix<f64, N, N>) -> f64);

#[inline(always)]
fn spectral_radius_bound_impl<const N: usize, const F: bool>(m: &SMatrix<f64, N, N>) -> f64 {
    let n0 = dense::norm2(&m.data.0).sqrt();
    if !n0.is_finite() {
        return f64::INFINITY;
    }
    if n0 == 0.0 {
        return 0.0;
    }
    let mut x = m.data.0;
    dense::scale(&mut x, 1.0 / n0);
    let mut log = n0.ln();
    let mut power = 1.0;
    for _ in 0..16 {
        let mut y = dense::mul::<_, _, _, F>(&x, &x);
        let n = dense::norm2(&y).sqrt();
        if n == 0.0 {
            return 0.0;
        }
        if !n.is_finite() {
            return f64::INFINITY;
        }
        dense::scale(&mut y, 1.0 / n);
        x = y;
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
    fn block_zoh_equals_full_exponential() {
        // The block-structured ZOH against `expm` of the augmented matrix [A B; 0 0] T, on an
        // unstructured 9-state, 4-input pair scaled so that the exponential needs squarings.
        let a = test_matrix::<9, 9>(11) * 30.0;
        let b = test_matrix::<9, 4>(12) * 50.0;
        let ts = 0.02;
        let mut big = SMatrix::<f64, 13, 13>::zeros();
        big.fixed_view_mut::<9, 9>(0, 0).copy_from(&(a * ts));
        big.fixed_view_mut::<9, 4>(0, 9).copy_from(&(b * ts));
        let e = expm(&big);
        let (phi, gamma) = discretise_zoh::<9, 4, 13>(&a, &b, ts);
        let phi_full = e.fixed_view::<9, 9>(0, 0).into_owned();
        let gamma_full = e.fixed_view::<9, 4>(0, 9).into_owned();
        assert!(
            (phi - phi_full).amax() <= 1e-14 * phi_full.amax(),
            "{}",
            (phi - phi_full).amax()
        );
        assert!((gamma - gamma_full).amax() <= 1e-14 * gamma_full.amax());
        // e^{AT} alone by the general exponential.
        let phi_alone = expm(&(a * ts));
        assert!((phi - phi_alone).amax() <= 1e-14 * phi_alone.amax());
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

    /// A well-conditioned but unstructured test matrix (entries from a fixed sequence).
    fn test_matrix<const R: usize, const C: usize>(seed: u64) -> SMatrix<f64, R, C> {
        let mut state = seed;
        SMatrix::from_fn(|_, _| {
            // 64-bit LCG (Knuth's MMIX constants), mapped to [−1, 1).
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 52) as f64 - 1.0
        })
    }

    #[test]
    fn dense_kernels_match_nalgebra() {
        let a = test_matrix::<17, 13>(1);
        let b = test_matrix::<13, 9>(2);
        let c = SMatrix::<f64, 17, 9>::from_data(ArrayStorage(dense::mul::<_, _, _, false>(&a.data.0, &b.data.0)));
        assert!((c - a * b).norm() < 1e-14 * (a.norm() * b.norm()));
        let t = SMatrix::<f64, 13, 17>::from_data(ArrayStorage(dense::transpose(&a.data.0)));
        assert_eq!(t, a.transpose());
        // W X = B for a pivoting-demanding W (zero leading entry), two right-hand sides.
        let mut w = test_matrix::<17, 17>(3) + SMatrix::<f64, 17, 17>::identity() * 0.5;
        w[(0, 0)] = 0.0;
        let b1 = test_matrix::<17, 5>(4);
        let b2 = test_matrix::<17, 17>(5);
        let mut wa = w.data.0;
        let mut y1 = dense::transpose(&b1.data.0);
        let mut y2 = dense::transpose(&b2.data.0);
        assert!(dense::lu_solve2(&mut wa, &mut y1, &mut y2));
        let x1 = SMatrix::<f64, 17, 5>::from_data(ArrayStorage(dense::transpose(&y1)));
        let x2 = SMatrix::<f64, 17, 17>::from_data(ArrayStorage(dense::transpose(&y2)));
        assert!((w * x1 - b1).norm() < 1e-12 * b1.norm(), "{}", (w * x1 - b1).norm());
        assert!((w * x2 - b2).norm() < 1e-12 * b2.norm());
        // A singular W is reported.
        let mut s = w.data.0;
        s[3] = s[5];
        let (mut y1, mut y2) = (dense::transpose(&b1.data.0), dense::transpose(&b2.data.0));
        assert!(!dense::lu_solve2(&mut s, &mut y1, &mut y2));
    }

    /// A 9-state, 3-input DARE problem (Φ, Γ, Q, R diagonal) shared by the build and Newton tests.
    fn problem_9x3() -> (
        SMatrix<f64, 9, 9>,
        SMatrix<f64, 9, 3>,
        SMatrix<f64, 9, 9>,
        SVector<f64, 3>,
    ) {
        let phi = test_matrix::<9, 9>(6) * 0.4 + SMatrix::<f64, 9, 9>::identity();
        let gamma = test_matrix::<9, 3>(7);
        let q = SMatrix::<f64, 9, 9>::from_diagonal(&SVector::<f64, 9>::from_fn(|i, _| 1.0 + i as f64));
        (phi, gamma, q, SVector::<f64, 3>::new(0.5, 2.0, 7.0))
    }

    #[test]
    fn simd_and_baseline_builds_agree() {
        // The dispatched build equals the `_impl` of its own flavour bit for bit (software
        // `fma` is correctly rounded like the instruction), and the fused and unfused
        // flavours agree to rounding.
        let (phi, gamma, q, r) = problem_9x3();
        let p = dare_sda(&phi, &gamma, &q, &r).unwrap();
        let p_fused = dare_sda_impl::<9, 3, true>(&phi, &gamma, &q, &r).unwrap();
        let p_plain = dare_sda_impl::<9, 3, false>(&phi, &gamma, &q, &r).unwrap();
        assert_eq!(p, if fused_build() { p_fused } else { p_plain });
        assert!(
            (p_fused - p_plain).norm() <= 1e-13 * p.norm(),
            "{}",
            (p_fused - p_plain).norm() / p.norm()
        );
        let k = lqr_gain(&phi, &gamma, &p, &r).unwrap();
        assert!(dare_residual(&phi, &gamma, &q, &p, &k) < 1e-12);
        let m = phi * 0.3;
        let (e_fused, e_plain) = (expm_impl::<9, true>(&m), expm_impl::<9, false>(&m));
        assert_eq!(expm(&m), if fused_build() { e_fused } else { e_plain });
        assert!((e_fused - e_plain).norm() <= 1e-14 * e_plain.norm());
        let cl = phi - gamma * k;
        let (s_fused, s_plain) = (
            spectral_radius_bound_impl::<9, true>(&cl),
            spectral_radius_bound_impl::<9, false>(&cl),
        );
        assert_eq!(
            spectral_radius_bound(&cl),
            if fused_build() { s_fused } else { s_plain }
        );
        assert!((s_fused - s_plain).abs() <= 1e-12 * s_plain);
    }

    #[test]
    fn newton_step_converges_quadratically_to_the_doubling_solution() {
        // A 9-state, 3-input problem: from P perturbed by ε (relative), one Newton step leaves
        // an error O(ε²); a far start is refused before the doubling.
        let (phi, gamma, q, r) = problem_9x3();
        let p = dare_sda(&phi, &gamma, &q, &r).unwrap();
        let d = test_matrix::<9, 9>(8);
        let sym = (d + d.transpose()) * (0.5 * p.amax() / d.amax());
        let mut p1 = p;
        for eps in [1e-3, 1e-4, 1e-5] {
            let rel;
            (p1, rel) = dare_newton_step(&phi, &gamma, &q, &r, &(p + sym * eps), 1.0, 0.0).unwrap();
            let err = (p1 - p).amax() / p.amax();
            // Measured: 4.4e2 ε² (this random pair is poorly conditioned).
            assert!(rel > 0.1 * eps && rel < 10.0 * eps, "{rel} vs {eps}");
            assert!(err < 1e3 * eps * eps, "ε = {eps}: error {err}");
            assert_eq!(p1, p1.transpose());
        }
        // A second step from the last: at rounding.
        let (p2, _) = dare_newton_step(&phi, &gamma, &q, &r, &p1, 1.0, 0.0).unwrap();
        assert!((p2 - p).amax() < 1e-12 * p.amax(), "{}", (p2 - p).amax() / p.amax());
        assert!(matches!(
            dare_newton_step(&phi, &gamma, &q, &r, &(p + sym * 1e-2), 1e-9, 0.0),
            Err(RiccatiError::Residual(_))
        ));
        // A converged start (the doubling's P: residual ≈ 1e-16) is returned untouched when
        // `converged` admits it, and stepped otherwise; a start off by 1e-5 is stepped.
        assert!(dare_residual(&phi, &gamma, &q, &p, &lqr_gain(&phi, &gamma, &p, &r).unwrap()) < 1e-13);
        assert_eq!(
            dare_newton_step(&phi, &gamma, &q, &r, &p, 1.0, 1e-13).unwrap(),
            (p, 0.0)
        );
        let (stepped, rel) = dare_newton_step(&phi, &gamma, &q, &r, &p, 1.0, 0.0).unwrap();
        assert!(rel > 0.0 && (stepped - p).amax() < 1e-12 * p.amax());
        let (far, rel) = dare_newton_step(&phi, &gamma, &q, &r, &(p + sym * 1e-5), 1.0, 1e-13).unwrap();
        assert!(rel > 1e-6 && (far - p).amax() < 1e-7 * p.amax());
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
