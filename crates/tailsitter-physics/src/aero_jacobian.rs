//! Analytic Jacobian of the thesis's force model [`Airframe::forces_moments`] (§2.3) with
//! respect to its arguments, for linearisations (3.2.7–3.2.9) that would otherwise take
//! 2 × 13 evaluations of the model by central differences.
//!
//! Arguments, in the column order of [`FmJacobian`] (see [`arg`]): air-relative body velocity
//! v = (u, v, w) (m/s), body rates ω = (p, q, r) (rad/s), thrust T (N) and the six deflections
//! `[δe, δa, δr, δfc, δfd, δv]` (rad). Rows: force (X, Y, Z) (N), moment (L, M, N) (N m).
//!
//! Derivation (chain rule through the quantities of [`Airframe::forces_moments`]):
//!
//! * V̄ = |v|: ∇V̄ = x_w; α = atan2(w, u): ∇α = z_w / h with h = √(u² + w²);
//!   β = asin(v/V̄): ∇β = y_w / V̄ (x_w, y_w, z_w the wind axes (A.2.7) in body components).
//! * Wind axes: ∂x_w/∂v = (I − x_w x_wᵀ)/V̄, z_w = (−sin α, 0, cos α) ⇒
//!   ∂z_w/∂v = −(cos α, 0, sin α) ∇αᵀ, y_w = z_w × x_w ⇒ ∂y_w = ∂z_w × x_w + z_w × ∂x_w.
//! * Derivatives of Tables C.3/C.4: linear in α inside ±`alpha_interp_limit`, constant
//!   outside (their slope is 0 there).
//! * Induced velocity, implicitly from f(w) = w²(w² + 2V_x w + V̄²) − k² = 0, k = T/(2ρA):
//!   ∂w/∂V_x = −2w³/f', ∂w/∂V̄ = −2V̄w²/f', ∂w/∂T = 2k/(2ρA f'), f' = 4w³ + 6V_x w² + 2V̄²w.
//! * Slip-stream axes: the wind axes of v + 2w e_x, through ∂(v + 2w e_x).
//!
//! Defined where the model is differentiable: V̄ > [`AIRSPEED_EPS`] and the velocity (and
//! the slip-stream velocity) not along body y (h > 0); elsewhere
//! [`Airframe::forces_moments_jacobian`] returns `None` and a caller falls back to finite
//! differences. At exactly ±`alpha_interp_limit` the one-sided slope of the outside is used.

use nalgebra::{Matrix3, SMatrix, Vector3};

use crate::aero::{ForcesMoments, Surfaces, AIRSPEED_EPS};
use crate::airframe::{Airframe, Coefficients};

/// Number of arguments of the force model: v (3), ω (3), T, six deflections.
pub const N_FM_ARGS: usize = 13;

/// ∂(force, moment)/∂(v, ω, T, δ): rows X, Y, Z, L, M, N; columns as in [`arg`].
pub type FmJacobian = SMatrix<f64, 6, N_FM_ARGS>;

/// Column indices of [`FmJacobian`].
pub mod arg {
    /// Air-relative body velocity u, v, w (3 columns).
    pub const VELOCITY: usize = 0;
    /// Body rates p, q, r (3 columns).
    pub const RATES: usize = 3;
    /// Thrust T.
    pub const THRUST: usize = 6;
    /// Deflections δe, δa, δr, δfc, δfd, δv (6 columns, [`crate::Surfaces::to_array`] order).
    pub const SURFACES: usize = 7;
}

/// Gradient of a scalar with respect to the arguments.
type Grad = SMatrix<f64, 1, N_FM_ARGS>;
/// Jacobian of a vector (an axis) with respect to the arguments.
type Jac3 = SMatrix<f64, 3, N_FM_ARGS>;

/// Unit gradient of argument `k`.
#[inline]
fn unit(k: usize) -> Grad {
    let mut g = Grad::zeros();
    g[k] = 1.0;
    g
}

/// A gradient with respect to the velocity only.
#[inline]
fn of_velocity(g: &Vector3<f64>) -> Grad {
    let mut r = Grad::zeros();
    r[0] = g.x;
    r[1] = g.y;
    r[2] = g.z;
    r
}

/// Wind axes (A.2.7) of a velocity and their derivatives with respect to that velocity.
struct Axes {
    speed: f64,
    alpha: f64,
    beta: f64,
    sa: f64,
    ca: f64,
    xw: Vector3<f64>,
    yw: Vector3<f64>,
    zw: Vector3<f64>,
    /// ∂x_w/∂v, ∂y_w/∂v, ∂z_w/∂v.
    dxw: Matrix3<f64>,
    dyw: Matrix3<f64>,
    dzw: Matrix3<f64>,
    /// ∇V̄, ∇α, ∇β with respect to v.
    dspeed: Vector3<f64>,
    dalpha: Vector3<f64>,
    dbeta: Vector3<f64>,
}

impl Axes {
    /// `None` where the axes are not differentiable (V̄ ≤ ε or h = 0).
    fn of(v: &Vector3<f64>) -> Option<Self> {
        let speed = v.norm();
        let h = (v.x * v.x + v.z * v.z).sqrt();
        if speed < AIRSPEED_EPS || h <= 0.0 {
            return None;
        }
        let xw = v / speed;
        let (sa, ca) = (v.z / h, v.x / h);
        let zw = Vector3::new(-sa, 0.0, ca);
        let yw = zw.cross(&xw);
        let dxw = (Matrix3::identity() - xw * xw.transpose()) / speed;
        let dalpha = zw / h;
        let dzw = -Vector3::new(ca, 0.0, sa) * dalpha.transpose();
        // ∂(z × x) = ∂z × x + z × ∂x = −[x]× ∂z + [z]× ∂x.
        let dyw = -xw.cross_matrix() * dzw + zw.cross_matrix() * dxw;
        Some(Self {
            speed,
            alpha: libm::atan2(v.z, v.x),
            beta: (v.y / speed).clamp(-1.0, 1.0).asin(),
            sa,
            ca,
            xw,
            yw,
            zw,
            dxw,
            dyw,
            dzw,
            dspeed: xw,
            dalpha,
            dbeta: yw / speed,
        })
    }
}

/// `Σ cᵢ(α) aᵢ` and its gradient, for terms (cᵢ, slope of cᵢ in α, aᵢ, ∇aᵢ).
#[inline]
fn sum(terms: &[(f64, f64, f64, Grad)], dalpha: &Grad) -> (f64, Grad) {
    let mut value = 0.0;
    let mut grad = Grad::zeros();
    for (c, slope, a, ga) in terms {
        value += c * a;
        grad += dalpha * (slope * a) + ga * *c;
    }
    (value, grad)
}

/// `∂(axis · s)` = ∂axis s + axis ∇sᵀ.
#[inline]
fn scaled(axis: &Vector3<f64>, daxis: &Jac3, s: f64, ds: &Grad) -> Jac3 {
    daxis * s + axis * ds
}

impl Airframe {
    /// Slopes dcᵢ/dα of the interpolated derivatives ([`Airframe::coefficients`]): the
    /// constant slope of the straight line inside ±`alpha_interp_limit`, 0 outside.
    pub fn coefficient_slopes(&self, alpha: f64) -> Coefficients {
        let lim = self.alpha_interp_limit;
        if alpha.abs() >= lim || alpha.is_nan() {
            return Coefficients::default();
        }
        let (hi, lo) = (self.coefficients(lim), self.coefficients(-lim));
        let k = 1.0 / (2.0 * lim);
        macro_rules! slope {
            ($($f:ident),*) => { Coefficients { $($f: (hi.$f - lo.$f) * k),* } };
        }
        slope!(
            c_L_alpha, c_m_alpha, c_Y_beta, c_l_beta, c_n_beta, c_Y_p, c_l_p, c_n_p, c_L_q, c_m_q, c_Y_r, c_l_r, c_n_r,
            c_L_de, c_m_de, c_Y_da, c_l_da, c_n_da, c_Y_dr, c_l_dr, c_n_dr, c_L_dfc, c_m_dfc, c_l_dfd, c_n_dfd, c_Y_dv,
            c_l_dv, c_n_dv
        )
    }

    /// [`Airframe::forces_moments`] and its analytic Jacobian (module docs) with respect to
    /// (v, ω, T, δ). `None` where the model is not differentiable (V̄ ≤ [`AIRSPEED_EPS`],
    /// or the free-stream or slip-stream velocity along body y).
    pub fn forces_moments_jacobian(
        &self,
        v_air_body: &Vector3<f64>,
        omega_body: &Vector3<f64>,
        thrust: f64,
        surfaces: &Surfaces,
    ) -> Option<(ForcesMoments, FmJacobian)> {
        let fm = self.forces_moments(v_air_body, omega_body, thrust, surfaces);
        let v = v_air_body;
        let fr = Axes::of(v)?;
        let (alpha, beta, speed) = (fr.alpha, fr.beta, fr.speed);
        let c = self.coefficients(alpha);
        let cs = self.coefficient_slopes(alpha);
        let d = surfaces;
        let (p, q, r) = (omega_body.x, omega_body.y, omega_body.z);
        let (rho, s, b, cbar) = (self.air_density, self.wing_area, self.wing_span, self.mean_chord);

        let g_v = of_velocity(&fr.dspeed);
        let g_a = of_velocity(&fr.dalpha);
        let g_b = of_velocity(&fr.dbeta);
        let zero = Grad::zeros();
        let e_q = unit(arg::RATES + 1);
        let [e_de, e_da, e_dr, e_dfc, e_dfd, e_dv] = core::array::from_fn(|k| unit(arg::SURFACES + k));
        // Stability-axis rates p_s = p cα + r sα, r_s = r cα − p sα.
        let ps = p * fr.ca + r * fr.sa;
        let rs = r * fr.ca - p * fr.sa;
        let g_ps = g_a * rs + unit(arg::RATES) * fr.ca + unit(arg::RATES + 2) * fr.sa;
        let g_rs = g_a * (-ps) - unit(arg::RATES) * fr.sa + unit(arg::RATES + 2) * fr.ca;

        let qs = 0.5 * rho * speed * speed * s;
        let g_qs = g_v * (rho * speed * s);
        let kr = 0.25 * rho * speed * s;
        let g_kr = g_v * (0.25 * rho * s);

        // Free stream (2.3.6–2.3.13), each bracket Σ cᵢ(α) aᵢ with its gradient.
        let one = (1.0, zero);
        let alpha_ = (alpha, g_a);
        let beta_ = (beta, g_b);
        let term = |c: f64, slope: f64, a: &(f64, Grad)| (c, slope, a.0, a.1);
        let (de, da, dr, dfc, dfd, dv) = (
            (d.elevator, e_de),
            (d.aileron, e_da),
            (d.rudder, e_dr),
            (d.flap_collective, e_dfc),
            (d.flap_differential, e_dfd),
            (d.vertical_flap, e_dv),
        );
        let (ps_, rs_, q_) = ((ps, g_ps), (rs, g_rs), (q, e_q));
        let (cl, g_cl) = sum(
            &[
                term(self.c_L0, 0.0, &one),
                term(c.c_L_alpha, cs.c_L_alpha, &alpha_),
                term(c.c_L_de, cs.c_L_de, &de),
                term(c.c_L_dfc, cs.c_L_dfc, &dfc),
            ],
            &g_a,
        );
        let k_ind = core::f64::consts::PI * self.aspect_ratio * self.oswald_efficiency;
        let cd = self.c_D0 + cl * cl / k_ind;
        let g_cd = g_cl * (2.0 * cl / k_ind);
        let (cl_w, g_cl_w) = sum(
            &[term(self.c_L0, 0.0, &one), term(c.c_L_alpha, cs.c_L_alpha, &alpha_)],
            &g_a,
        );
        let (cl_q, g_cl_q) = sum(&[term(c.c_L_q, cs.c_L_q, &q_)], &g_a);
        let lift = qs * cl_w + kr * cbar * cl_q;
        let g_lift = g_qs * cl_w + g_cl_w * qs + (g_kr * cl_q + g_cl_q * kr) * cbar;
        let drag = qs * cd;
        let g_drag = g_qs * cd + g_cd * qs;
        // Side force and rolling/yawing moments share the pattern qs·X(β, δa) + kr·Y(p_s, r_s).
        let lateral = |cb: (f64, f64), cda: (f64, f64), cp: (f64, f64), cr: (f64, f64), arm: f64| {
            let (x, gx) = sum(&[term(cb.0, cb.1, &beta_), term(cda.0, cda.1, &da)], &g_a);
            let (y, gy) = sum(&[term(cp.0, cp.1, &ps_), term(cr.0, cr.1, &rs_)], &g_a);
            let value = qs * x + kr * arm * y;
            let grad = g_qs * x + gx * qs + (g_kr * y + gy * kr) * arm;
            (value, grad)
        };
        let (side, g_side) = lateral(
            (c.c_Y_beta, cs.c_Y_beta),
            (c.c_Y_da, cs.c_Y_da),
            (c.c_Y_p, cs.c_Y_p),
            (c.c_Y_r, cs.c_Y_r),
            b,
        );
        let (l_fs, g_l_fs) = lateral(
            (c.c_l_beta, cs.c_l_beta),
            (c.c_l_da, cs.c_l_da),
            (c.c_l_p, cs.c_l_p),
            (c.c_l_r, cs.c_l_r),
            b,
        );
        let (n_fs, g_n_fs) = lateral(
            (c.c_n_beta, cs.c_n_beta),
            (c.c_n_da, cs.c_n_da),
            (c.c_n_p, cs.c_n_p),
            (c.c_n_r, cs.c_n_r),
            b,
        );
        let (l_fs, g_l_fs, n_fs, g_n_fs) = (l_fs * b, g_l_fs * b, n_fs * b, g_n_fs * b);
        let (cm, g_cm) = sum(
            &[term(self.c_m0, 0.0, &one), term(c.c_m_alpha, cs.c_m_alpha, &alpha_)],
            &g_a,
        );
        let (cm_q, g_cm_q) = sum(&[term(c.c_m_q, cs.c_m_q, &q_)], &g_a);
        let m_fs = qs * cbar * cm + kr * cbar * cbar * cm_q;
        let g_m_fs = (g_qs * cm + g_cm * qs) * cbar + (g_kr * cm_q + g_cm_q * kr) * (cbar * cbar);

        // Slip-stream: induced velocity (implicit derivative), q̄_s, slip-stream axes.
        let wi = fm.induced_velocity;
        let mut g_wi = Grad::zeros();
        let denom = 2.0 * rho * self.prop_disc_area;
        if wi > 0.0 && thrust > 0.0 && denom > 0.0 {
            let vx = v.x;
            let v2 = (speed * speed).max(vx * vx);
            let der = 4.0 * wi * wi * wi + 6.0 * vx * wi * wi + 2.0 * v2 * wi;
            if der > 0.0 {
                let k = thrust / denom;
                g_wi = g_v * (-2.0 * speed * wi * wi / der);
                g_wi[arg::VELOCITY] += -2.0 * wi * wi * wi / der;
                g_wi[arg::THRUST] = 2.0 * k / (der * denom);
            }
        }
        let vs = speed + 2.0 * wi;
        let g_vs = g_v + g_wi * 2.0;
        let qss = 0.5 * rho * vs * vs * s;
        let g_qss = g_vs * (rho * vs * s);
        let v_wake = Vector3::new(v.x + 2.0 * wi, v.y, v.z);
        let ws = Axes::of(&v_wake)?;
        // ∂v_wake/∂(args) = [I 0] + 2 e_x ∇w.
        let mut j_wake = Jac3::zeros();
        j_wake
            .fixed_view_mut::<3, 3>(0, arg::VELOCITY)
            .copy_from(&Matrix3::identity());
        for k in 0..N_FM_ARGS {
            j_wake[(0, k)] += 2.0 * g_wi[k];
        }
        let (dxs, dys, dzs) = (ws.dxw * j_wake, ws.dyw * j_wake, ws.dzw * j_wake);
        let slip = |terms: &[(f64, f64, (f64, Grad))], arm: f64| {
            let mut value = 0.0;
            let mut grad = Grad::zeros();
            for (cv, slope, (a, ga)) in terms {
                value += cv * a;
                grad += g_a * (slope * a) + ga * *cv;
            }
            (qss * arm * value, (g_qss * value + grad * qss) * arm)
        };
        let (lift_s, g_lift_s) = slip(&[(c.c_L_de, cs.c_L_de, de), (c.c_L_dfc, cs.c_L_dfc, dfc)], 1.0);
        let (side_s, g_side_s) = slip(&[(c.c_Y_dr, cs.c_Y_dr, dr), (c.c_Y_dv, cs.c_Y_dv, dv)], 1.0);
        let (l_s, g_l_s) = slip(
            &[
                (c.c_l_dr, cs.c_l_dr, dr),
                (c.c_l_dfd, cs.c_l_dfd, dfd),
                (c.c_l_dv, cs.c_l_dv, dv),
            ],
            b,
        );
        let (m_s, g_m_s) = slip(&[(c.c_m_de, cs.c_m_de, de), (c.c_m_dfc, cs.c_m_dfc, dfc)], cbar);
        let (n_s, g_n_s) = slip(
            &[
                (c.c_n_dr, cs.c_n_dr, dr),
                (c.c_n_dfd, cs.c_n_dfd, dfd),
                (c.c_n_dv, cs.c_n_dv, dv),
            ],
            b,
        );

        // Body force and moment (DCM^BW (A.2.7)), product rule term by term.
        let mut dxw = Jac3::zeros();
        let mut dyw = Jac3::zeros();
        let mut dzw = Jac3::zeros();
        dxw.fixed_view_mut::<3, 3>(0, arg::VELOCITY).copy_from(&fr.dxw);
        dyw.fixed_view_mut::<3, 3>(0, arg::VELOCITY).copy_from(&fr.dyw);
        dzw.fixed_view_mut::<3, 3>(0, arg::VELOCITY).copy_from(&fr.dzw);
        let mut jf = scaled(&fr.xw, &dxw, -drag, &(-g_drag))
            + scaled(&fr.yw, &dyw, side, &g_side)
            + scaled(&fr.zw, &dzw, -lift, &(-g_lift))
            + scaled(&ws.yw, &dys, side_s, &g_side_s)
            + scaled(&ws.zw, &dzs, -lift_s, &(-g_lift_s));
        jf[(0, arg::THRUST)] += 1.0;
        let jm = scaled(&fr.xw, &dxw, l_fs, &g_l_fs)
            + scaled(&fr.yw, &dyw, m_fs, &g_m_fs)
            + scaled(&fr.zw, &dzw, n_fs, &g_n_fs)
            + scaled(&ws.xw, &dxs, l_s, &g_l_s)
            + scaled(&ws.yw, &dys, m_s, &g_m_s)
            + scaled(&ws.zw, &dzs, n_s, &g_n_s);
        let mut j = FmJacobian::zeros();
        j.fixed_view_mut::<3, N_FM_ARGS>(0, 0).copy_from(&jf);
        j.fixed_view_mut::<3, N_FM_ARGS>(3, 0).copy_from(&jm);
        Some((fm, j))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::numeric::central_differences;
    use nalgebra::SVector;

    /// (v, ω, T, δ) packed as one argument vector.
    fn eval(a: &Airframe, z: &SVector<f64, N_FM_ARGS>) -> SVector<f64, 6> {
        let fm = a.forces_moments(
            &Vector3::new(z[0], z[1], z[2]),
            &Vector3::new(z[3], z[4], z[5]),
            z[6],
            &Surfaces::from_array([z[7], z[8], z[9], z[10], z[11], z[12]]),
        );
        SVector::<f64, 6>::from(fm.wrench())
    }

    /// Against central differences at flight conditions across the envelope (level flight,
    /// transition, hover with sideslip, tail-first, descending through the disc): the
    /// difference is the finite differences' own error, O(h²f''') + O(ε f/h) with
    /// h = 1e-5·max(1, |z|), ≈ 1e-10·(f''' scale) + 1e-11·|f| — bounded here by 1e-8 (1 + |J|)
    /// per entry (1.2e-9 measured).
    #[test]
    fn jacobian_matches_central_differences() {
        let a = Airframe::default();
        let cases: [[f64; N_FM_ARGS]; 6] = [
            [24.79, 0.0, 3.22, 0.0, 0.0, 0.0, 9.28, -0.105, 0.0, 0.0, 0.0, 0.0, 0.0],
            [
                12.0, 1.5, 5.0, 0.3, -0.4, 0.2, 40.0, 0.1, -0.05, 0.08, 0.03, -0.02, 0.04,
            ],
            [3.0, -1.0, 0.4, -0.5, 0.6, 0.7, 88.0, -0.2, 0.1, -0.1, 0.15, 0.05, -0.1],
            [
                -6.0, 2.0, 1.0, 0.1, 0.2, -0.3, 20.0, 0.05, 0.02, 0.01, -0.03, 0.04, 0.02,
            ],
            [-2.0, 0.3, -0.5, 0.0, 0.1, 0.0, 60.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
            [30.0, -3.0, -2.0, 1.0, 0.5, -0.5, 2.0, 0.2, 0.2, 0.2, 0.2, 0.2, 0.2],
        ];
        let mut worst = 0.0f64;
        for z in cases {
            let z = SVector::<f64, N_FM_ARGS>::from(z);
            let (fm, j) = a
                .forces_moments_jacobian(
                    &Vector3::new(z[0], z[1], z[2]),
                    &Vector3::new(z[3], z[4], z[5]),
                    z[6],
                    &Surfaces::from_array([z[7], z[8], z[9], z[10], z[11], z[12]]),
                )
                .expect("differentiable");
            assert_eq!(fm.force_body.x, eval(&a, &z)[0]);
            let mut fd = FmJacobian::zeros();
            central_differences(
                &z,
                N_FM_ARGS,
                |_, v| Some(1e-5 * v.abs().max(1.0)),
                |zp| eval(&a, zp),
                |k, col| fd.set_column(k, &col),
            );
            for (x, y) in j.iter().zip(fd.iter()) {
                worst = worst.max((x - y).abs() / (1.0 + y.abs()));
                assert!((x - y).abs() <= 1e-8 * (1.0 + y.abs()), "{x} vs {y} at {z}\n{j}\n{fd}");
            }
        }
        println!("worst relative difference {worst:e}");
    }

    #[test]
    fn not_differentiable_without_airspeed() {
        let a = Airframe::default();
        let s = Surfaces::default();
        assert!(a
            .forces_moments_jacobian(&Vector3::zeros(), &Vector3::zeros(), 80.0, &s)
            .is_none());
        assert!(a
            .forces_moments_jacobian(&Vector3::new(0.0, 2.0, 0.0), &Vector3::zeros(), 0.0, &s)
            .is_none());
    }

    #[test]
    fn slopes_are_zero_beyond_the_interpolation_limit() {
        let a = Airframe::default();
        let lim = a.alpha_interp_limit;
        let h = 1e-4;
        let inside = a.coefficient_slopes(0.5 * lim);
        let fd = (a.coefficients(0.5 * lim + h).c_m_alpha - a.coefficients(0.5 * lim - h).c_m_alpha) / (2.0 * h);
        assert!((inside.c_m_alpha - fd).abs() <= 1e-9 * (1.0 + fd.abs()));
        assert_eq!(a.coefficient_slopes(1.5 * lim), Coefficients::default());
    }
}
