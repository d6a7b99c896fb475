//! Aerodynamic and propulsive forces and moments (thesis §2.3), without gravity.
//!
//! See the crate README for the full derivation. In short, for air-relative body velocity
//! `v_a = (u_a, v_a, w_a)`:
//!
//! * V̄ = |v_a|, α = atan2(w_a, u_a) (2.2.12), β = asin(v_a / V̄) (2.2.13); α = β = 0 when
//!   V̄ < [`AIRSPEED_EPS`] so every output is finite in hover.
//! * Induced velocity w from momentum theory (2.3.19–2.3.21), [`Airframe::induced_velocity`].
//! * Slip-stream speed V_s = V̄ + 2w (far wake, docs/DESIGN.md §4, (3.3.17)).
//! * Free-stream terms (wing/body: C_L0, C_Lα, C_Lq, C_D, C_Yβ, rate terms, C_m0, C_mα, C_mq,
//!   C_lβ, C_nβ, and the **ailerons** C_{Y,l,n}δa) use q̄ = ½ρV̄² and the free-stream
//!   wind axes (A.2.7, exact).
//! * Control terms of the surfaces in the slip-stream (elevator, rudder, collective and
//!   differential flaps, vertical flaps) use q̄_s = ½ρ(V̄+2w)², exactly the
//!   `((V+2w)/V)²` effectiveness scaling of (3.3.17), and act in the slip-stream axes: the
//!   wind axes (A.2.7) of the far-wake velocity `v_a + 2w e_x`, which coincide with the
//!   free-stream axes when w = 0 and with the body axes in hover.
//! * Rate terms: ½ρV̄²S·(b/2V̄)·C_p·p = ¼ρV̄Sb·C_p·p (2.3.5), written without dividing by V̄
//!   so they are finite (and vanish) at V̄ = 0. Roll/yaw rates enter in stability axes,
//!   p_s = p cos α + r sin α, r_s = r cos α − p sin α: the exact form of the small-angle
//!   bracket of (2.3.7), (2.3.9), (2.3.11), whose printed signs are wrong.
//! * Thrust T along +x body (2.3.15), no moment (counter-rotating propellers).

use nalgebra::Vector3;

use crate::airframe::{Airframe, Coefficients};

/// Below this airspeed (m/s) α, β are defined as 0 and the wind axes as the body axes.
pub const AIRSPEED_EPS: f64 = 1e-9;

/// Halley iterations a warm-started induced-velocity solve may take before it falls back to
/// the cold, bracketed one ([`Airframe::induced_velocity_from`]).
pub const WARM_ITERATIONS: usize = 4;

/// The six surface deflections (rad); positive deflection gives a negative moment (§2.3.1).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Surfaces {
    /// δe, in the slip-stream.
    pub elevator: f64,
    /// δa, outside the slip-stream (sees V̄ only).
    pub aileron: f64,
    /// δr, in the slip-stream.
    pub rudder: f64,
    /// δfc, in the slip-stream.
    pub flap_collective: f64,
    /// δfd, in the slip-stream.
    pub flap_differential: f64,
    /// δv, in the slip-stream.
    pub vertical_flap: f64,
}

impl Surfaces {
    /// From `[δe, δa, δr, δfc, δfd, δv]` (the order of the state and input vectors).
    #[inline]
    pub fn from_array(d: [f64; 6]) -> Self {
        Self {
            elevator: d[0],
            aileron: d[1],
            rudder: d[2],
            flap_collective: d[3],
            flap_differential: d[4],
            vertical_flap: d[5],
        }
    }

    /// `[δe, δa, δr, δfc, δfd, δv]`.
    #[inline]
    pub fn to_array(&self) -> [f64; 6] {
        [
            self.elevator,
            self.aileron,
            self.rudder,
            self.flap_collective,
            self.flap_differential,
            self.vertical_flap,
        ]
    }
}

impl From<[f64; 6]> for Surfaces {
    fn from(d: [f64; 6]) -> Self {
        Self::from_array(d)
    }
}

/// Result of [`Airframe::forces_moments`]: aerodynamic + thrust force and moment about the CG
/// in body axes (no gravity), and the air-data quantities used to compute them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ForcesMoments {
    /// Aerodynamic + thrust force, body axes (N). Divide by m for the specific force.
    pub force_body: Vector3<f64>,
    /// Aerodynamic moment about the CG, body axes (L, M, N) (N m).
    pub moment_body: Vector3<f64>,
    /// Propeller induced velocity w (2.3.21) (m/s).
    pub induced_velocity: f64,
    /// Airspeed V̄ (m/s).
    pub airspeed: f64,
    /// Angle of attack α (2.2.12) (rad), 0 when V̄ ≈ 0.
    pub alpha: f64,
    /// Sideslip β (2.2.13) (rad), 0 when V̄ ≈ 0.
    pub beta: f64,
    /// Slip-stream speed V̄ + 2w over the surfaces behind the propellers (m/s).
    pub slipstream_speed: f64,
}

impl ForcesMoments {
    /// Force then moment, body axes: (X, Y, Z, L, M, N).
    pub fn wrench(&self) -> [f64; 6] {
        let (f, m) = (&self.force_body, &self.moment_body);
        [f.x, f.y, f.z, m.x, m.y, m.z]
    }
}

/// Columns of `DCM^BW` (A.2.7): the wind axes x_w, y_w, z_w in body components, of the
/// velocity `v` (body components). Returns (x_w, y_w, z_w, sin α, cos α).
#[inline]
pub(crate) fn wind_axes(v: &Vector3<f64>, speed: f64) -> (Vector3<f64>, Vector3<f64>, Vector3<f64>, f64, f64) {
    if speed < AIRSPEED_EPS {
        return (Vector3::x(), Vector3::y(), Vector3::z(), 0.0, 1.0);
    }
    let xw = v * (1.0 / speed);
    let h = (v.x * v.x + v.z * v.z).sqrt();
    let (sa, ca) = if h > 0.0 {
        let h_inv = 1.0 / h;
        (v.z * h_inv, v.x * h_inv)
    } else {
        (0.0, 1.0)
    };
    // z_w = (−sin α, 0, cos α), y_w = z_w × x_w = (−cα sβ, cβ, −sα sβ).
    let zw = Vector3::new(-sa, 0.0, ca);
    let yw = zw.cross(&xw);
    (xw, yw, zw, sa, ca)
}

impl Airframe {
    /// Induced velocity w ≥ 0 (m/s) of the propellers from momentum theory, the positive
    /// root of (2.3.19–2.3.21) generalised to sideslip:
    ///
    /// `T = 2ρA w V'`, `V'² = (V_x + w)² + (V̄² − V_x²) = w² + 2V_x w + V̄²`
    /// ⇒ `w⁴ + 2V_x w³ + V̄² w² = (T/(2ρA))²`
    ///
    /// with `V_x` the axial (body-x) airspeed component (V̄ cos α cos β; (2.3.21) writes
    /// V cos α) and `airspeed` = V̄ ≥ |V_x|. For pure axial flow this is (2.3.18),
    /// `T = 2ρA (V_0 + w) w`. Valid for any sign of `V_x` (the largest root is taken; in
    /// axial descent that is the branch with w > −V_x) and at V̄ = 0 (w = √(T/(2ρA))).
    /// Returns 0 for T ≤ 0 or ρ = 0. Halley's method (cubic convergence) from an upper
    /// bound with a bisection safeguard: ≈ 3 iterations instead of Newton's ≈ 5. It stops
    /// when a step is ≤ 1e-6 w: the error after it is then O(1e-18) w (cubic convergence),
    /// so the result is the root to rounding (a bisection step never stops it early), or when
    /// the bracket is below 1e-14 (1 + w).
    pub fn induced_velocity(&self, airspeed: f64, axial_airspeed: f64, thrust: f64) -> f64 {
        self.induced_velocity_from(airspeed, axial_airspeed, thrust, f64::NAN)
    }

    /// [`Airframe::induced_velocity`] warm-started from `start` (a nearby root, e.g. the
    /// previous integration stage's; NaN or ≤ 0 for a cold start). From a warm start Halley's method
    /// runs without the bracket and stops on the same test (a Halley step ≤ 1e-6 w, after
    /// which the error is O(1e-18) w by cubic convergence: the root to rounding, whatever the
    /// start); if it does not within [`WARM_ITERATIONS`] iterations, or leaves w > 0, the cold,
    /// bracketed solve runs. Purely axial flow uses the closed form either way.
    pub fn induced_velocity_from(&self, airspeed: f64, axial_airspeed: f64, thrust: f64, start: f64) -> f64 {
        let denom = 2.0 * self.air_density * self.prop_disc_area;
        if thrust <= 0.0 || denom <= 0.0 || !thrust.is_finite() {
            return 0.0;
        }
        let k = thrust / denom; // w V' = k
        let vx = axial_airspeed;
        let v2 = (airspeed * airspeed).max(vx * vx);
        // Unique positive root (so a warm start cannot land on another branch): g(w) =
        // w²(w² + 2V_x w + V̄²) increases on w > 0 when 2w² + 3V_x w + V̄² > 0 there, i.e.
        // V_x ≥ 0 or 9V_x² ≤ 8V̄²; otherwise (steep axial descent) the cold solve takes the largest.
        let monotone = vx >= 0.0 || 9.0 * vx * vx <= 8.0 * v2;
        if monotone && start > 0.0 && start.is_finite() && v2 != vx * vx {
            let k2 = k * k;
            let mut w = start;
            for _ in 0..WARM_ITERATIONS {
                let w2 = w * w;
                let val = w2 * (w2 + 2.0 * vx * w + v2) - k2;
                if val == 0.0 {
                    return w;
                }
                let der = 4.0 * w2 * w + 6.0 * vx * w2 + 2.0 * v2 * w;
                let der2 = 12.0 * w2 + 12.0 * vx * w + 2.0 * v2;
                let den = 2.0 * der * der - val * der2;
                if !(der > 0.0 && den > 0.0) {
                    break;
                }
                let next = w - 2.0 * val * der / den;
                if !(next > 0.0 && next.is_finite()) {
                    break;
                }
                let step = (next - w).abs();
                w = next;
                if step <= 1e-6 * w {
                    return w;
                }
            }
        }
        self.induced_velocity_cold(airspeed, axial_airspeed, thrust)
    }

    fn induced_velocity_cold(&self, airspeed: f64, axial_airspeed: f64, thrust: f64) -> f64 {
        let denom = 2.0 * self.air_density * self.prop_disc_area;
        if thrust <= 0.0 || denom <= 0.0 || !thrust.is_finite() {
            return 0.0;
        }
        let k = thrust / denom; // w V' = k
        let vx = axial_airspeed;
        let v2 = (airspeed * airspeed).max(vx * vx); // V̄² ≥ V_x² by construction
        let k2 = k * k;
        // Start at the axial-flow root of w (w + V_x) = k, w_ax = (−V_x + √(V_x² + 4k))/2 (exact
        // when V̄ = |V_x|; hover √k). Since V'² = (w + V_x)² + (V̄² − V_x²) ≥ (w + V_x)² and
        // w_ax + V_x ≥ 0, f(w_ax) ≥ 0: it is an upper bound of the root.
        let mut lo = 0.0;
        // (Written without cancellation for V_x > 0: (−V_x + √(V_x² + 4k))/2 = 2k/(V_x + √(…)).)
        let root = (vx * vx + 4.0 * k).sqrt();
        let mut hi = if vx > 0.0 {
            2.0 * k / (vx + root)
        } else {
            0.5 * (root - vx)
        };
        if v2 == vx * vx {
            // Purely axial flow (vertical flight): w_ax is the root, (2.3.18).
            return hi;
        }
        let mut w = hi;
        for _ in 0..100 {
            // f = w²(w² + 2V_x w + V̄²) − k², f', f''.
            let w2 = w * w;
            let val = w2 * (w2 + 2.0 * vx * w + v2) - k2;
            if val == 0.0 {
                break;
            }
            let der = 4.0 * w2 * w + 6.0 * vx * w2 + 2.0 * v2 * w;
            let der2 = 12.0 * w2 + 12.0 * vx * w + 2.0 * v2;
            if val > 0.0 {
                hi = w;
            } else {
                lo = w;
            }
            // Halley: w − 2 f f' / (2 f'² − f f'').
            let den = 2.0 * der * der - val * der2;
            let mut next = if der > 0.0 && den > 0.0 {
                w - 2.0 * val * der / den
            } else {
                f64::NAN
            };
            let halley = next >= lo && next <= hi;
            if !halley {
                next = 0.5 * (lo + hi);
            }
            let step = (next - w).abs();
            w = next;
            if (halley && step <= 1e-6 * w) || hi - lo <= 1e-14 * (1.0 + w) {
                break;
            }
        }
        w
    }

    /// Induced velocity for purely axial flow at `axial_airspeed` V₀ (any sign), the closed-form
    /// root of (2.3.18) `T = ρA(V₀ + w)2w`: w = (−V₀ + √(V₀² + 2T/(ρA)))/2 (0 for T ≤ 0).
    /// Equal to [`Airframe::induced_velocity`]`(|V₀|, V₀, T)`.
    pub fn induced_velocity_axial(&self, axial_airspeed: f64, thrust: f64) -> f64 {
        let denom = 2.0 * self.air_density * self.prop_disc_area;
        if thrust <= 0.0 || denom <= 0.0 || !thrust.is_finite() {
            return 0.0;
        }
        let v0 = axial_airspeed;
        0.5 * (-v0 + (v0 * v0 + 4.0 * thrust / denom).sqrt())
    }

    /// Aerodynamic plus thrust force and moment in body axes, without gravity (§2.3).
    ///
    /// * `v_air_body`: air-relative velocity of the CG in body axes, i.e. inertial velocity
    ///   minus wind, both in body axes (m/s).
    /// * `omega_body`: body rates (p, q, r) (rad/s).
    /// * `thrust`: total thrust T of both propellers (N) (the thrust *state*, not the command).
    /// * `surfaces`: actual deflections (rad).
    ///
    /// The model (see module docs and README): lift L, drag D, side force Y computed in the
    /// wind axes and rotated exactly to body axes with `DCM^BW` (A.2.7);
    ///
    /// ```text
    /// L = q̄S(C_L0 + C_Lα α) + ¼ρV̄Sc̄ C_Lq q + q̄_s S(C_Lδe δe + C_Lδfc δfc)
    /// D = q̄S(C_D0 + C_L²/(πAe)),  C_L = C_L0 + C_Lα α + C_Lδe δe + C_Lδfc δfc   (2.3.12–13)
    /// Y = q̄S(C_Yβ β + C_Yδa δa) + ¼ρV̄Sb(C_Yp p_s + C_Yr r_s) + q̄_s S(C_Yδr δr + C_Yδv δv)
    /// l = q̄Sb(C_lβ β + C_lδa δa) + ¼ρV̄Sb²(C_lp p_s + C_lr r_s) + q̄_s Sb(C_lδr δr + C_lδfd δfd + C_lδv δv)
    /// m = q̄Sc̄(C_m0 + C_mα α) + ¼ρV̄Sc̄² C_mq q + q̄_s Sc̄(C_mδe δe + C_mδfc δfc)
    /// n = q̄Sb(C_nβ β + C_nδa δa) + ¼ρV̄Sb²(C_np p_s + C_nr r_s) + q̄_s Sb(C_nδr δr + C_nδfd δfd + C_nδv δv)
    /// ```
    ///
    /// with q̄ = ½ρV̄², q̄_s = ½ρ(V̄+2w)², derivatives from [`Airframe::coefficients`]`(α)`;
    /// the free-stream parts are rotated with the free-stream wind axes, the slip-stream
    /// control parts with the slip-stream axes (wind axes of `v_a + 2w e_x`). Wind-axis
    /// force components are (−D, Y, −L) (2.3.6–2.3.8). Thrust adds (T, 0, 0).
    /// The induced drag uses C_L of (2.3.12) (control lift at the free-stream pressure), so
    /// it vanishes in hover.
    ///
    /// ```
    /// use nalgebra::Vector3;
    /// use tailsitter_physics::{Airframe, Surfaces};
    /// let a = Airframe::default();
    /// // Hover: no airspeed, the elevator still pitches the aircraft through the slip-stream.
    /// let s = Surfaces { elevator: 0.1, ..Surfaces::default() };
    /// let fm = a.forces_moments(&Vector3::zeros(), &Vector3::zeros(), a.mass * a.gravity, &s);
    /// assert_eq!((fm.airspeed, fm.alpha, fm.beta), (0.0, 0.0, 0.0));
    /// assert!(fm.moment_body.y < 0.0); // positive deflection, negative moment (§2.3.1)
    /// assert!(fm.induced_velocity > 11.0 && fm.slipstream_speed > 23.0);
    /// ```
    #[inline]
    pub fn forces_moments(
        &self,
        v_air_body: &Vector3<f64>,
        omega_body: &Vector3<f64>,
        thrust: f64,
        surfaces: &Surfaces,
    ) -> ForcesMoments {
        self.forces_moments_from(v_air_body, omega_body, thrust, surfaces, f64::NAN)
    }

    /// [`Airframe::forces_moments`] with the induced-velocity solve warm-started from
    /// `w_start` ([`Airframe::induced_velocity_from`]; NaN for a cold start).
    #[inline]
    pub fn forces_moments_from(
        &self,
        v_air_body: &Vector3<f64>,
        omega_body: &Vector3<f64>,
        thrust: f64,
        surfaces: &Surfaces,
        w_start: f64,
    ) -> ForcesMoments {
        let va = v_air_body;
        let speed = va.norm();
        let (alpha, beta) = if speed < AIRSPEED_EPS {
            (0.0, 0.0)
        } else {
            (libm::atan2(va.z, va.x), (va.y / speed).clamp(-1.0, 1.0).asin())
        };
        let (xw, yw, zw, sa, ca) = wind_axes(va, speed);
        let c: Coefficients = self.coefficients(alpha);
        let (p, q, r) = (omega_body.x, omega_body.y, omega_body.z);
        let ps = p * ca + r * sa;
        let rs = r * ca - p * sa;
        let d = surfaces;

        let rho = self.air_density;
        let s = self.wing_area;
        let b = self.wing_span;
        let cbar = self.mean_chord;
        let qs = 0.5 * rho * speed * speed * s; // q̄ S
        let kr = 0.25 * rho * speed * s; // q̄ S / V̄ · ½ (rate terms)

        // Slip-stream.
        let wi = self.induced_velocity_from(speed, va.x, thrust, w_start);
        let vs = speed + 2.0 * wi;
        let qss = 0.5 * rho * vs * vs * s; // q̄_s S
        let v_wake = Vector3::new(va.x + 2.0 * wi, va.y, va.z);
        let (xs, ys, zs, _, _) = wind_axes(&v_wake, v_wake.norm());

        // Free-stream wind-axis forces (2.3.6–2.3.8, 2.3.12–2.3.13).
        let cl = self.c_L0 + c.c_L_alpha * alpha + c.c_L_de * d.elevator + c.c_L_dfc * d.flap_collective;
        let cd = self.c_D0 + cl * cl * (1.0 / (core::f64::consts::PI * self.aspect_ratio * self.oswald_efficiency));
        let lift_fs = qs * (self.c_L0 + c.c_L_alpha * alpha) + kr * cbar * c.c_L_q * q;
        let drag = qs * cd;
        let side_fs = qs * (c.c_Y_beta * beta + c.c_Y_da * d.aileron) + kr * b * (c.c_Y_p * ps + c.c_Y_r * rs);
        // Free-stream wind-axis moments (2.3.9–2.3.11).
        let l_fs = qs * b * (c.c_l_beta * beta + c.c_l_da * d.aileron) + kr * b * b * (c.c_l_p * ps + c.c_l_r * rs);
        let m_fs = qs * cbar * (self.c_m0 + c.c_m_alpha * alpha) + kr * cbar * cbar * c.c_m_q * q;
        let n_fs = qs * b * (c.c_n_beta * beta + c.c_n_da * d.aileron) + kr * b * b * (c.c_n_p * ps + c.c_n_r * rs);

        // Slip-stream control terms.
        let lift_s = qss * (c.c_L_de * d.elevator + c.c_L_dfc * d.flap_collective);
        let side_s = qss * (c.c_Y_dr * d.rudder + c.c_Y_dv * d.vertical_flap);
        let l_s = qss * b * (c.c_l_dr * d.rudder + c.c_l_dfd * d.flap_differential + c.c_l_dv * d.vertical_flap);
        let m_s = qss * cbar * (c.c_m_de * d.elevator + c.c_m_dfc * d.flap_collective);
        let n_s = qss * b * (c.c_n_dr * d.rudder + c.c_n_dfd * d.flap_differential + c.c_n_dv * d.vertical_flap);

        // DCM^BW (A.2.7): body = x_w X_w + y_w Y_w + z_w Z_w.
        let force_body = xw * (-drag)
            + yw * side_fs
            + zw * (-lift_fs)
            + ys * side_s
            + zs * (-lift_s)
            + Vector3::new(thrust, 0.0, 0.0);
        let moment_body = xw * l_fs + yw * m_fs + zw * n_fs + xs * l_s + ys * m_s + zs * n_s;

        ForcesMoments {
            force_body,
            moment_body,
            induced_velocity: wi,
            airspeed: speed,
            alpha,
            beta,
            slipstream_speed: vs,
        }
    }
}
