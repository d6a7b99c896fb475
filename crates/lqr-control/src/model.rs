//! The LQR's model for control (thesis §2.4, candidate 2 of §3.2.3): the full-state
//! Euler-angle model
//!
//! ```text
//! x = [V α β p q r φ θ ψ N E h T]ᵀ,   u = [T_c δe δa δr δfc δfd δv]ᵀ
//! ```
//!
//! built on the same force model as the plant ([`Airframe::forces_moments`], §2.3) with
//! the controller's own [`Airframe`], and rigid-body equations written here from first
//! principles instead of the printed (2.4.6–2.4.29) (which carry typos, docs/DESIGN.md §5):
//!
//! * body velocity `v = V (cα cβ, sβ, sα cβ)` (inverse of (2.2.12–2.2.13), no wind);
//! * `v̇ = F/m + DCM^BE (0, 0, g) − ω × v` ((2.2.19–2.2.21), gravity (2.3.14));
//! * `V̇ = v·v̇ / V`, `α̇ = (u ẇ − w u̇)/(u² + w²)`, `β̇ = (v̇ − sβ V̇)/(V cβ)`;
//! * `I ω̇ = M − ω × I ω` with diagonal inertia ((2.2.22–2.2.24), (2.2.17));
//! * Euler kinematics 3-2-1 (2.2.1)/(2.4.16–2.4.18) or 2-3-1, re-derived (the printed
//!   (2.2.2), (2.4.19–2.4.21) are wrong): for `DCM^BE = T¹_φ T³_θ T²_ψ` (A.2.6),
//!   `p = φ̇ + sθ ψ̇`, `q = cφ cθ ψ̇ + sφ θ̇`, `r = −sφ cθ ψ̇ + cφ θ̇`, hence
//!   `φ̇ = p − tanθ (q cφ − r sφ)`, `θ̇ = q sφ + r cφ`, `ψ̇ = (q cφ − r sφ)/cθ`;
//! * position (2.4.22–2.4.24) as `(Ṅ, Ė, −ḣ) = DCM^BEᵀ v`;
//! * thrust lag (2.3.16)/(2.4.28) with τ_T: `Ṫ = (T_c − T)/τ_T`.
//!
//! The surfaces are taken as direct inputs (the servo lag of App. D.5 is not modelled,
//! as in the thesis). Linearisation (3.2.7–3.2.9) is analytic ([`linearise_analytic`]),
//! with central differences ([`linearise_central`]) as the fallback.

use nalgebra::{Matrix3, SMatrix, SVector, Vector3, Vector4};
use tailsitter_physics::aero_jacobian::arg;
use tailsitter_physics::numeric::central_differences;
use tailsitter_physics::{
    dcm_earth_to_body, dcm_from_euler_231, euler_231_from_quat, euler_321_from_quat, Airframe, FmJacobian,
    ForcesMoments, Surfaces,
};

/// Number of model states.
pub const NX: usize = 13;
/// Number of inputs.
pub const NU: usize = 7;
/// Model states plus the airspeed integrator (3.2.12–3.2.14) and the three earth-frame
/// position integrators ∫ΔN, ∫ΔE, ∫Δh (extension of the thesis): `[x_IV, x (13), x_IN, x_IE, x_Ih]`.
pub const NA: usize = NX + 4;
/// Index of ∫ΔN in the augmented state (∫ΔE, ∫Δh follow).
pub const I_POS: usize = NX + 1;

/// Model state vector.
pub type X = SVector<f64, NX>;
/// Input vector.
pub type U = SVector<f64, NU>;

/// Indices into [`X`].
pub mod ix {
    pub const V: usize = 0;
    pub const ALPHA: usize = 1;
    pub const BETA: usize = 2;
    pub const P: usize = 3;
    pub const Q: usize = 4;
    pub const R: usize = 5;
    pub const PHI: usize = 6;
    pub const THETA: usize = 7;
    pub const PSI: usize = 8;
    pub const N: usize = 9;
    pub const E: usize = 10;
    pub const H: usize = 11;
    pub const T: usize = 12;
}

/// The Euler sequence of the attitude states (§2.2.1).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EulerRep {
    /// 3-2-1 (ψ about z, θ about y, φ about x), (A.2.5): level flight and transitions.
    E321 = 0,
    /// 2-3-1 (ψ about y, θ about z, φ about x), (A.2.6): vertical flight.
    E231 = 1,
}

impl EulerRep {
    /// `DCM^BE` of the angles `[φ, θ, ψ]` in this sequence.
    pub fn dcm(self, a: &Vector3<f64>) -> Matrix3<f64> {
        match self {
            EulerRep::E321 => {
                tailsitter_physics::attitude::rot_x(a.x)
                    * tailsitter_physics::attitude::rot_y(a.y)
                    * tailsitter_physics::attitude::rot_z(a.z)
            }
            EulerRep::E231 => dcm_from_euler_231(a.x, a.y, a.z),
        }
    }

    /// The angles `[φ, θ, ψ]` of a quaternion (A.2.8, scalar last) in this sequence.
    pub fn angles(self, q: &Vector4<f64>) -> Vector3<f64> {
        match self {
            EulerRep::E321 => euler_321_from_quat(q),
            EulerRep::E231 => euler_231_from_quat(q),
        }
    }

    /// The angles of a `DCM^BE` in this sequence.
    pub fn angles_of_dcm(self, c: &Matrix3<f64>) -> Vector3<f64> {
        self.angles(&tailsitter_physics::quat_from_dcm(c))
    }

    /// Euler-angle rates from body rates: (2.2.1) for 3-2-1; the re-derived 2-3-1 form
    /// (module docs) replacing the printed (2.2.2)/(2.4.19–2.4.21).
    pub fn rates(self, a: &Vector3<f64>, w: &Vector3<f64>) -> Vector3<f64> {
        let (sf, cf) = a.x.sin_cos();
        let (st, ct) = a.y.sin_cos();
        let (p, q, r) = (w.x, w.y, w.z);
        match self {
            EulerRep::E321 => {
                let k = q * sf + r * cf;
                Vector3::new(p + k * st / ct, q * cf - r * sf, k / ct)
            }
            EulerRep::E231 => {
                let k = q * cf - r * sf;
                Vector3::new(p - k * st / ct, q * sf + r * cf, k / ct)
            }
        }
    }
}

/// Wrap an angle difference to (−π, π].
pub fn wrap_pi(a: f64) -> f64 {
    let t = core::f64::consts::TAU;
    let mut x = a % t;
    if x > core::f64::consts::PI {
        x -= t;
    } else if x <= -core::f64::consts::PI {
        x += t;
    }
    x
}

/// Body velocity of airspeed, α, β (inverse of (2.2.12–2.2.13)).
#[inline]
pub fn body_velocity(v: f64, alpha: f64, beta: f64) -> Vector3<f64> {
    let (sa, ca) = alpha.sin_cos();
    let (sb, cb) = beta.sin_cos();
    Vector3::new(v * ca * cb, v * sb, v * sa * cb)
}

/// State derivative `ẋ = f(x) + g(x) u` (2.4.1) of the model for control (module docs).
pub fn derivatives(af: &Airframe, rep: EulerRep, x: &X, u: &U) -> X {
    let speed = x[ix::V];
    let (alpha, beta) = (x[ix::ALPHA], x[ix::BETA]);
    let w = Vector3::new(x[ix::P], x[ix::Q], x[ix::R]);
    let ang = Vector3::new(x[ix::PHI], x[ix::THETA], x[ix::PSI]);
    let thrust = x[ix::T];
    let vb = body_velocity(speed, alpha, beta);
    let surfaces = Surfaces::from_array([u[1], u[2], u[3], u[4], u[5], u[6]]);
    let fm = af.forces_moments(&vb, &w, thrust, &surfaces);
    let c = rep.dcm(&ang);
    let g_body = c * Vector3::new(0.0, 0.0, af.gravity);
    let a = fm.force_body / af.mass + g_body - w.cross(&vb);
    let vdot = vb.dot(&a) / speed;
    let uw2 = vb.x * vb.x + vb.z * vb.z;
    let alpha_dot = (vb.x * a.z - vb.z * a.x) / uw2;
    let beta_dot = (a.y - beta.sin() * vdot) / (speed * beta.cos());
    let inertia = Vector3::new(af.i_xx, af.i_yy, af.i_zz);
    let iw = inertia.component_mul(&w);
    let wdot = (fm.moment_body - w.cross(&iw)).component_div(&inertia);
    let angdot = rep.rates(&ang, &w);
    let vel_ned = c.transpose() * vb;
    let tdot = (u[0] - thrust) / af.tau_thrust;
    X::from_column_slice(&[
        vdot, alpha_dot, beta_dot, wdot.x, wdot.y, wdot.z, angdot.x, angdot.y, angdot.z, vel_ned.x, vel_ned.y,
        -vel_ned.z, tdot,
    ])
}

/// Jacobians `F = ∂ẋ/∂x`, `G = ∂ẋ/∂u` at (x, u) (3.2.8–3.2.9): analytic
/// ([`linearise_analytic`]) where the force model is differentiable, central differences
/// ([`linearise_central`]) elsewhere (no airspeed, flow along body y).
pub fn linearise(af: &Airframe, rep: EulerRep, x: &X, u: &U) -> (SMatrix<f64, NX, NX>, SMatrix<f64, NX, NU>) {
    linearise_analytic(af, rep, x, u).unwrap_or_else(|| linearise_central(af, rep, x, u))
}

/// Jacobians of [`derivatives`] by central differences (step 1e-6·(1 + |value|)).
pub fn linearise_central(af: &Airframe, rep: EulerRep, x: &X, u: &U) -> (SMatrix<f64, NX, NX>, SMatrix<f64, NX, NU>) {
    let mut f = SMatrix::<f64, NX, NX>::zeros();
    let mut g = SMatrix::<f64, NX, NU>::zeros();
    // Positions do not enter the dynamics: their columns are exactly zero.
    central_differences(
        x,
        NX,
        |j, v| (j != ix::N && j != ix::E && j != ix::H).then(|| 1e-6 * (1.0 + v.abs())),
        |xp| derivatives(af, rep, xp, u),
        |j, col| f.set_column(j, &col),
    );
    central_differences(
        u,
        NU,
        |_, v| Some(1e-6 * (1.0 + v.abs())),
        |up| derivatives(af, rep, x, up),
        |j, col| g.set_column(j, &col),
    );
    (f, g)
}

impl EulerRep {
    /// ∂DCM^BE/∂φ, ∂/∂θ, ∂/∂ψ. For `DCM = R₁(φ) R₂(θ) R₃(ψ)` (frame rotations about the
    /// axes e₁, e₂, e₃, dR_k/da = −\[e_k\]× R_k): ∂/∂φ = −\[e₁\]× C, ∂/∂θ = −\[R₁ e₂\]× C,
    /// ∂/∂ψ = −C \[e₃\]× (3-2-1: e₁ e₂ e₃ = x y z; 2-3-1: x z y).
    pub fn dcm_partials(self, a: &Vector3<f64>) -> [Matrix3<f64>; 3] {
        let c = self.dcm(a);
        let (e2, e3) = match self {
            EulerRep::E321 => (Vector3::y(), Vector3::z()),
            EulerRep::E231 => (Vector3::z(), Vector3::y()),
        };
        let r1e2 = tailsitter_physics::attitude::rot_x(a.x) * e2;
        [
            -Vector3::<f64>::x().cross_matrix() * c,
            -r1e2.cross_matrix() * c,
            -c * e3.cross_matrix(),
        ]
    }

    /// ∂(Euler-angle rates)/∂(φ, θ, ψ) and ∂/∂(p, q, r) of [`EulerRep::rates`].
    pub fn rates_partials(self, a: &Vector3<f64>, w: &Vector3<f64>) -> (Matrix3<f64>, Matrix3<f64>) {
        let (sf, cf) = a.x.sin_cos();
        let (st, ct) = a.y.sin_cos();
        let (q, r) = (w.y, w.z);
        let t = st / ct;
        let ct2 = ct * ct;
        match self {
            EulerRep::E321 => {
                let k = q * sf + r * cf;
                let kf = q * cf - r * sf;
                (
                    Matrix3::new(kf * t, k / ct2, 0.0, -k, 0.0, 0.0, kf / ct, k * st / ct2, 0.0),
                    Matrix3::new(1.0, sf * t, cf * t, 0.0, cf, -sf, 0.0, sf / ct, cf / ct),
                )
            }
            EulerRep::E231 => {
                let k = q * cf - r * sf;
                let kf = -q * sf - r * cf;
                (
                    Matrix3::new(-kf * t, -k / ct2, 0.0, k, 0.0, 0.0, kf / ct, k * st / ct2, 0.0),
                    Matrix3::new(1.0, -cf * t, sf * t, 0.0, sf, cf, 0.0, cf / ct, -sf / ct),
                )
            }
        }
    }
}

/// Analytic Jacobians of [`derivatives`] by the chain rule through the force model's
/// Jacobian ([`Airframe::forces_moments_jacobian`]) and the rigid-body equations of the
/// module docs: with v = V(cα cβ, sβ, sα cβ) and a = F/m + DCM (0, 0, g) − ω × v,
/// `∂V̇ = (aᵀ∂v + vᵀ∂a)/V − V̇ ∂V/V`, `∂α̇ = ∂(u a_z − w a_x)/(u² + w²) − α̇ ∂(u² + w²)/(u² + w²)`,
/// `∂β̇ = (∂a_y − cβ V̇ ∂β − sβ ∂V̇)/(V cβ) − β̇ ∂(V cβ)/(V cβ)`,
/// `∂ω̇ = I⁻¹(∂M − ∂(ω × Iω))` with `∂(ω × Iω)/∂ω = [ω]× I − [Iω]×`, the Euler kinematics by
/// [`EulerRep::rates_partials`], the position rates `DCMᵀ v` by [`EulerRep::dcm_partials`].
/// `None` where the force model is not differentiable (no airspeed, flow along body y).
pub fn linearise_analytic(
    af: &Airframe,
    rep: EulerRep,
    x: &X,
    u: &U,
) -> Option<(SMatrix<f64, NX, NX>, SMatrix<f64, NX, NU>)> {
    let speed = x[ix::V];
    let (alpha, beta) = (x[ix::ALPHA], x[ix::BETA]);
    let w = Vector3::new(x[ix::P], x[ix::Q], x[ix::R]);
    let ang = Vector3::new(x[ix::PHI], x[ix::THETA], x[ix::PSI]);
    let (sa, ca) = alpha.sin_cos();
    let (sb, cb) = beta.sin_cos();
    let vb = body_velocity(speed, alpha, beta);
    if speed * cb == 0.0 || vb.x * vb.x + vb.z * vb.z == 0.0 {
        return None;
    }
    let surfaces = Surfaces::from_array([u[1], u[2], u[3], u[4], u[5], u[6]]);
    let (fm, jfm) = af.forces_moments_jacobian(&vb, &w, x[ix::T], &surfaces)?;
    let c = rep.dcm(&ang);
    let dc = rep.dcm_partials(&ang);

    // ∂v/∂(V, α, β).
    let jv = Matrix3::from_columns(&[
        Vector3::new(ca * cb, sb, sa * cb),
        Vector3::new(-speed * sa * cb, 0.0, speed * ca * cb),
        Vector3::new(-speed * ca * sb, speed * cb, -speed * sa * sb),
    ]);
    let body = BodyPartials::new(af, &fm, &jfm, (&c, &dc), &w, vb, jv);
    let mut f = SMatrix::<f64, NX, NX>::zeros();
    let mut g = SMatrix::<f64, NX, NU>::zeros();
    air_data_rows(&mut f, &mut g, speed, (sb, cb), &body);
    rate_rows(&mut f, &mut g, af, &jfm, &body.jv, &w);
    kinematic_rows(&mut f, rep, (&ang, &w), (&c, &dc), &body);
    // Ṫ = (T_c − T)/τ_T.
    f[(ix::T, ix::T)] = -1.0 / af.tau_thrust;
    g[(ix::T, 0)] = 1.0 / af.tau_thrust;
    Some((f, g))
}

/// The body air velocity v and acceleration a = F/m + DCM (0, 0, g) − ω × v with their
/// partials over x and u (2.2.19–2.2.21), shared by the rows of [`linearise_analytic`].
struct BodyPartials {
    vb: Vector3<f64>,
    /// ∂v/∂(V, α, β).
    jv: Matrix3<f64>,
    /// ∂v/∂x (non-zero in the V, α, β columns only).
    dv: SMatrix<f64, 3, NX>,
    a: Vector3<f64>,
    da: SMatrix<f64, 3, NX>,
    da_u: SMatrix<f64, 3, NU>,
}

impl BodyPartials {
    /// From the force model's forces `fm` and Jacobian `jfm`, the DCM and its partials, ω,
    /// v and ∂v/∂(V, α, β) `jv`.
    fn new(
        af: &Airframe,
        fm: &ForcesMoments,
        jfm: &FmJacobian,
        (c, dc): (&Matrix3<f64>, &[Matrix3<f64>; 3]),
        w: &Vector3<f64>,
        vb: Vector3<f64>,
        jv: Matrix3<f64>,
    ) -> Self {
        let jf = jfm.fixed_rows::<3>(0);
        let m = af.mass;
        let mut dv = SMatrix::<f64, 3, NX>::zeros();
        dv.fixed_columns_mut::<3>(ix::V).copy_from(&jv);
        let a = fm.force_body / m + c * Vector3::new(0.0, 0.0, af.gravity) - w.cross(&vb);
        let mut da = SMatrix::<f64, 3, NX>::zeros();
        let mut da_u = SMatrix::<f64, 3, NU>::zeros();
        let jf_v = jf.fixed_columns::<3>(arg::VELOCITY) * jv;
        da.fixed_columns_mut::<3>(ix::V)
            .copy_from(&(jf_v / m - w.cross_matrix() * jv));
        da.fixed_columns_mut::<3>(ix::P)
            .copy_from(&(jf.fixed_columns::<3>(arg::RATES) / m + vb.cross_matrix()));
        for (k, dck) in dc.iter().enumerate() {
            da.set_column(ix::PHI + k, &(dck.column(2) * af.gravity));
        }
        da.set_column(ix::T, &(jf.column(arg::THRUST) / m));
        for k in 0..6 {
            da_u.set_column(1 + k, &(jf.column(arg::SURFACES + k) / m));
        }
        Self {
            vb,
            jv,
            dv,
            a,
            da,
            da_u,
        }
    }
}

/// Rows V̇ = v·a/V, α̇ = (u a_z − w a_x)/(u² + w²) and β̇ = (a_y − sβ V̇)/(V cβ) of F and G.
fn air_data_rows(
    f: &mut SMatrix<f64, NX, NX>,
    g: &mut SMatrix<f64, NX, NU>,
    speed: f64,
    (sb, cb): (f64, f64),
    b: &BodyPartials,
) {
    let (vb, a, dv, da, da_u) = (&b.vb, &b.a, &b.dv, &b.da, &b.da_u);
    // V̇ = v·a/V.
    let vdot = vb.dot(a) / speed;
    let mut dvdot = (a.transpose() * dv + vb.transpose() * da) / speed;
    dvdot[ix::V] -= vdot / speed;
    let dvdot_u = vb.transpose() * da_u / speed;
    f.set_row(ix::V, &dvdot);
    g.set_row(ix::V, &dvdot_u);

    // α̇ = (u a_z − w a_x)/(u² + w²).
    let den = vb.x * vb.x + vb.z * vb.z;
    let alpha_dot = (vb.x * a.z - vb.z * a.x) / den;
    let dnum = dv.row(0) * a.z + da.row(2) * vb.x - dv.row(2) * a.x - da.row(0) * vb.z;
    let dden = (dv.row(0) * vb.x + dv.row(2) * vb.z) * 2.0;
    f.set_row(ix::ALPHA, &((dnum - dden * alpha_dot) / den));
    g.set_row(ix::ALPHA, &((da_u.row(2) * vb.x - da_u.row(0) * vb.z) / den));

    // β̇ = (a_y − sβ V̇)/(V cβ).
    let dd = speed * cb;
    let beta_dot = (a.y - sb * vdot) / dd;
    let mut dn = da.row(1) - dvdot * sb;
    dn[ix::BETA] -= cb * vdot;
    let mut ddd = SMatrix::<f64, 1, NX>::zeros();
    ddd[ix::V] = cb;
    ddd[ix::BETA] = -speed * sb;
    f.set_row(ix::BETA, &((dn - ddd * beta_dot) / dd));
    g.set_row(ix::BETA, &((da_u.row(1) - dvdot_u * sb) / dd));
}

/// Rows ω̇ = I⁻¹(M − ω × Iω) of F and G (2.2.22–2.2.24), `jv` = ∂v/∂(V, α, β).
fn rate_rows(
    f: &mut SMatrix<f64, NX, NX>,
    g: &mut SMatrix<f64, NX, NU>,
    af: &Airframe,
    jfm: &FmJacobian,
    jv: &Matrix3<f64>,
    w: &Vector3<f64>,
) {
    let jm = jfm.fixed_rows::<3>(3);
    let inertia = Vector3::new(af.i_xx, af.i_yy, af.i_zz);
    let iw = inertia.component_mul(w);
    let mut dwdot = SMatrix::<f64, 3, NX>::zeros();
    dwdot
        .fixed_columns_mut::<3>(ix::V)
        .copy_from(&(jm.fixed_columns::<3>(arg::VELOCITY) * jv));
    dwdot.fixed_columns_mut::<3>(ix::P).copy_from(
        &(jm.fixed_columns::<3>(arg::RATES)
            - (w.cross_matrix() * Matrix3::from_diagonal(&inertia) - iw.cross_matrix())),
    );
    dwdot.set_column(ix::T, &jm.column(arg::THRUST));
    let mut dwdot_u = SMatrix::<f64, 3, NU>::zeros();
    for k in 0..6 {
        dwdot_u.set_column(1 + k, &jm.column(arg::SURFACES + k));
    }
    for i in 0..3 {
        f.set_row(ix::P + i, &(dwdot.row(i) / inertia[i]));
        g.set_row(ix::P + i, &(dwdot_u.row(i) / inertia[i]));
    }
}

/// Rows of the Euler kinematics ([`EulerRep::rates_partials`]) and of the position rates
/// (Ṅ, Ė, −ḣ) = DCMᵀ v (2.4.22–2.4.24) of F.
fn kinematic_rows(
    f: &mut SMatrix<f64, NX, NX>,
    rep: EulerRep,
    (ang, w): (&Vector3<f64>, &Vector3<f64>),
    (c, dc): (&Matrix3<f64>, &[Matrix3<f64>; 3]),
    b: &BodyPartials,
) {
    let (d_ang, d_w) = rep.rates_partials(ang, w);
    f.fixed_view_mut::<3, 3>(ix::PHI, ix::PHI).copy_from(&d_ang);
    f.fixed_view_mut::<3, 3>(ix::PHI, ix::P).copy_from(&d_w);

    let mut dpos = SMatrix::<f64, 3, NX>::zeros();
    dpos.fixed_columns_mut::<3>(ix::V).copy_from(&(c.transpose() * b.jv));
    for (k, dck) in dc.iter().enumerate() {
        dpos.set_column(ix::PHI + k, &(dck.transpose() * b.vb));
    }
    f.set_row(ix::N, &dpos.row(0));
    f.set_row(ix::E, &dpos.row(1));
    f.set_row(ix::H, &(-dpos.row(2)));
}

/// The model state of a measured quaternion attitude and the other measured quantities,
/// attitude in the sequence `rep`.
#[allow(clippy::too_many_arguments)]
pub fn state_of(
    rep: EulerRep,
    airspeed: f64,
    alpha: f64,
    beta: f64,
    rates: &Vector3<f64>,
    quat: &Vector4<f64>,
    pos_ned: &Vector3<f64>,
    thrust: f64,
) -> X {
    let a = rep.angles(quat);
    X::from_column_slice(&[
        airspeed, alpha, beta, rates.x, rates.y, rates.z, a.x, a.y, a.z, pos_ned.x, pos_ned.y, -pos_ned.z, thrust,
    ])
}

/// Quaternion → DCM shorthand.
pub fn dcm_of_quat(q: &Vector4<f64>) -> Matrix3<f64> {
    dcm_earth_to_body(q)
}

#[cfg(test)]
mod tests {
    use super::*;
    use tailsitter_physics::{quat_from_euler_321, Plant};

    #[test]
    fn euler_rates_match_the_dcm_derivative() {
        // Ċ = −[ω×] C for C = DCM^BE; check both sequences' kinematics by finite differences.
        let w = Vector3::new(0.3, -0.5, 0.7);
        for rep in [EulerRep::E321, EulerRep::E231] {
            for a in [
                Vector3::new(0.2, 0.4, -0.3),
                Vector3::new(-0.1, 1.2, 0.5),
                Vector3::new(0.05, -0.3, 1.4),
            ] {
                let c = rep.dcm(&a);
                let dt = 1e-6;
                let c2 = rep.dcm(&(a + rep.rates(&a, &w) * dt));
                let cdot = (c2 - c) / dt;
                let wx = Matrix3::new(0.0, -w.z, w.y, w.z, 0.0, -w.x, -w.y, w.x, 0.0);
                assert!((cdot + wx * c).norm() < 1e-5, "{rep:?} {a}");
                // angles round trip
                let back = rep.angles_of_dcm(&c);
                assert!((back - a).norm() < 1e-12, "{rep:?}: {back} vs {a}");
            }
        }
    }

    /// The analytic Jacobians against central differences (whose own error is
    /// O(h² f‴) + O(ε f/h) ≈ 1e-10 relative at h = 1e-6 (1 + |x|)): level flight, a
    /// transition point with rates and sideslip (3-2-1), vertical flight (2-3-1) and a
    /// point beyond the interpolation limit. Tolerance 2e-8 (1 + |entry|) (3.6e-9 measured).
    #[test]
    fn analytic_jacobians_match_central_differences() {
        let af = Airframe::default();
        let cases = [
            (
                EulerRep::E321,
                [25.0, 0.129, 0.0, 0.0, 0.0, 0.0, 0.0, 0.129, 0.0, 0.0, 0.0, 10.0, 9.28],
                [9.28, -0.105, 0.0, 0.0, 0.0, 0.0, 0.0],
            ),
            (
                EulerRep::E321,
                [14.0, 0.35, 0.05, 0.2, -0.3, 0.1, 0.1, 0.6, -0.2, 5.0, 1.0, 12.0, 45.0],
                [50.0, -0.05, 0.03, -0.02, 0.04, 0.01, -0.03],
            ),
            (
                EulerRep::E231,
                [
                    3.0, 0.02, -0.01, 0.05, 0.1, -0.02, 0.03, 0.04, -0.05, 0.0, 0.0, 2.0, 88.0,
                ],
                [88.0, 0.02, 0.0, 0.01, 0.0, 0.0, 0.0],
            ),
            (
                EulerRep::E321,
                [6.0, 0.7, -0.1, 0.0, 0.4, 0.0, 0.0, 1.0, 0.3, 0.0, 0.0, 0.0, 70.0],
                [70.0, 0.1, 0.0, 0.0, 0.0, 0.0, 0.0],
            ),
        ];
        let mut worst = 0.0f64;
        for (rep, x, u) in cases {
            let (x, u) = (X::from(x), U::from(u));
            let (fa, ga) = linearise_analytic(&af, rep, &x, &u).expect("differentiable");
            let (fc, gc) = linearise_central(&af, rep, &x, &u);
            for (a, c) in fa.iter().zip(fc.iter()).chain(ga.iter().zip(gc.iter())) {
                worst = worst.max((a - c).abs() / (1.0 + c.abs()));
                assert!(
                    (a - c).abs() <= 2e-8 * (1.0 + c.abs()),
                    "{rep:?} {a} vs {c}\n{fa}{fc}\n{ga}{gc}"
                );
            }
        }
        println!("worst relative difference {worst:e}");
        // No airspeed: not differentiable (`linearise` falls back to central differences).
        let x = X::from_column_slice(&[0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 88.0]);
        assert!(linearise_analytic(&af, EulerRep::E231, &x, &U::zeros()).is_none());
    }

    #[test]
    fn trimmed_level_flight_is_an_equilibrium_of_the_model() {
        let af = Airframe::default();
        let plant = Plant::new(af);
        let trim = plant.trim_level(25.0).unwrap();
        let q = quat_from_euler_321(0.0, trim.theta, 0.0);
        let x = state_of(
            EulerRep::E321,
            25.0,
            trim.alpha,
            0.0,
            &Vector3::zeros(),
            &q,
            &Vector3::zeros(),
            trim.thrust,
        );
        let u = U::from_column_slice(trim.inputs.as_slice());
        let d = derivatives(&af, EulerRep::E321, &x, &u);
        for i in 0..ix::N {
            assert!(d[i].abs() < 1e-6, "state {i}: {}", d[i]);
        }
        assert!((d[ix::N] - 25.0).abs() < 1e-6);
    }
}
