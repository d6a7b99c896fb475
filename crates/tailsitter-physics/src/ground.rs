//! Ground contact: a horizontal ground plane and spring-damper contact points with Coulomb
//! friction, so the tail-sitter can stand nose-up on its tail gear, take off and land
//! (issue 13).
//!
//! # Model
//!
//! The ground is the plane `pos_d = height` (NED, down positive). Contact points, body axes
//! (assumed geometry — the thesis gives none): four on the tail/landing gear at
//! `(−gear_length, ±gear_half_span, 0)` and `(−gear_length, 0, ±gear_half_height)`
//! (wing-root gear and fins), one at the nose `(nose_length, 0, 0)` and the two wing tips
//! `(0, ±b/2, 0)`, so that any attitude touches the ground with a point, not with the CG.
//! For a point r at depth δ = (P + (DCM^BE)ᵀ r)_d − height > 0 with earth velocity
//! v_P = (DCM^BE)ᵀ (v + ω × r):
//!
//! ```text
//! N   = max(0, k δ + c v_P,d)                       normal force (never pulls)
//! F_t = −μ N v_t / √(|v_t|² + v_ε²)                 friction, v_t horizontal part of v_P
//! F   = (F_t,n, F_t,e, −N) (earth)                  moment r × DCM^BE F about the CG
//! ```
//!
//! Friction is regularised with v_ε = [`FRICTION_V_EPS`] = 0.05 m/s (smooth, no
//! stick-slip state): at rest with no tangential load it is exactly zero; a steady tangential
//! load F creeps at ≈ v_ε F/(μN).
//!
//! **Stiffness vs the integration step.** Defaults k = 2500 N/m, c = 100 N s/m per point:
//! standing on the four gear points the heave mode has ω = √(4k/m) = 33 rad/s, ζ ≈ 0.67,
//! static compression mg/(4k) = 8.8 mm; rocking about the gear ≈ 26 rad/s; the stiffest
//! friction mode (the regularised friction acts like a damper μN/v_ε per point, through the
//! lever `gear_length` on I_yy) has |λ| ≈ 4μNl²/(v_ε I_yy) ≈ 400 s⁻¹. At the default 20/3 ms
//! step that is |λ|h ≈ 2.7, inside the Dormand–Prince method's real-axis stability limit 3.31
//! (R(z) = Σ₀⁵ zᵏ/k! + z⁶/600) but not accurate: there the step's error estimate exceeds
//! its tolerance and the step is taken in halves (|λ|h ≤ 1.3 or less), as it is at touchdown,
//! where the normal force switches on (a dropped aircraft costs ≈ 56 instead of ≈ 20
//! right-hand sides per 20 ms while it settles).
//!
//! **Default height.** `height` = 10 m: the default experiment starts in a 3 m/s vertical
//! climb at the origin, i.e. 10 m above the ground after an (unsimulated) take-off; the
//! thesis's mission never descends below its start altitude, so the ground is never touched.
//! [`Ground::default`] matches the FMU's start values; [`Ground::none`] (height = +∞) is what
//! [`crate::Plant::new`] uses, so library users opt in.

use nalgebra::{Matrix3, Vector3, Vector4};

use crate::airframe::{Airframe, InvalidParameter};
use crate::attitude::{dcm_earth_to_body, quat_from_euler_321};
use crate::idx::*;
use crate::plant::Plant;
use crate::StateVector;

/// Regularisation speed of the friction law (m/s).
pub const FRICTION_V_EPS: f64 = 0.05;
/// Touchdown speed above which the FMU logs a hard touchdown (m/s).
pub const HARD_TOUCHDOWN_SPEED: f64 = 1.0;
/// Number of contact points.
pub const N_CONTACT_POINTS: usize = 7;

/// Ground plane and contact-point parameters (FMU parameters `ground_height`, `gear_*`,
/// `nose_length`, `ground_*`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ground {
    /// Height of the ground plane as a `pos_d` value (m) (NED, down positive); +∞ = no ground.
    pub height: f64,
    /// Distance of the tail contact points behind the CG along −x body (m).
    pub gear_length: f64,
    /// Lateral (body y) half-spread of the two wing-root gear points (m).
    pub gear_half_span: f64,
    /// Body-z half-spread of the two fin gear points (m).
    pub gear_half_height: f64,
    /// Distance of the nose contact point ahead of the CG (m).
    pub nose_length: f64,
    /// Spring stiffness per contact point (N/m).
    pub stiffness: f64,
    /// Damping per contact point (N s/m).
    pub damping: f64,
    /// Coulomb friction coefficient μ.
    pub friction: f64,
}

impl Default for Ground {
    fn default() -> Self {
        Self {
            height: 10.0,
            gear_length: 0.45,
            gear_half_span: 0.4,
            gear_half_height: 0.25,
            nose_length: 0.4,
            stiffness: 2500.0,
            damping: 100.0,
            friction: 0.5,
        }
    }
}

/// Contact summary at one state.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ContactState {
    /// Number of contact points touching the ground.
    pub points: u32,
    /// Largest downward speed of a contact point touching or within 1 mm of the ground,
    /// else of the lowest point (m/s); used for the touchdown speed.
    pub sink_rate: f64,
    /// Height of the lowest contact point above the ground (m) (negative = penetration).
    pub clearance: f64,
}

impl Ground {
    /// No ground at all (height +∞).
    pub fn none() -> Self {
        Self {
            height: f64::INFINITY,
            ..Self::default()
        }
    }

    /// Finite, non-negative geometry and gains, positive stiffness (height may be +∞).
    pub fn validate(&self) -> Result<(), InvalidParameter> {
        let bad = |name, value, requirement| {
            Err(InvalidParameter {
                name,
                value,
                requirement,
            })
        };
        if self.height.is_nan() || self.height == f64::NEG_INFINITY {
            return bad("ground_height", self.height, "a number (or +inf for no ground)");
        }
        for (name, value) in [
            ("gear_length", self.gear_length),
            ("gear_half_span", self.gear_half_span),
            ("gear_half_height", self.gear_half_height),
            ("nose_length", self.nose_length),
            ("ground_damping", self.damping),
            ("ground_friction", self.friction),
        ] {
            if !(value.is_finite() && value >= 0.0) {
                return bad(name, value, "finite and >= 0");
            }
        }
        if !(self.stiffness.is_finite() && self.stiffness > 0.0) {
            return bad("ground_stiffness", self.stiffness, "finite and > 0");
        }
        Ok(())
    }

    /// The contact points in body axes (m).
    #[inline]
    pub fn points(&self, a: &Airframe) -> [Vector3<f64>; N_CONTACT_POINTS] {
        let l = -self.gear_length;
        [
            Vector3::new(l, self.gear_half_span, 0.0),
            Vector3::new(l, -self.gear_half_span, 0.0),
            Vector3::new(l, 0.0, self.gear_half_height),
            Vector3::new(l, 0.0, -self.gear_half_height),
            Vector3::new(self.nose_length, 0.0, 0.0),
            Vector3::new(0.0, 0.5 * a.wing_span, 0.0),
            Vector3::new(0.0, -0.5 * a.wing_span, 0.0),
        ]
    }

    /// Largest distance of a contact point from the CG (m): nothing can touch while the CG
    /// is higher than this above the ground.
    #[inline]
    fn reach(&self, a: &Airframe) -> f64 {
        let g = (self.gear_length * self.gear_length + (self.gear_half_span.max(self.gear_half_height)).powi(2)).sqrt();
        g.max(self.nose_length).max(0.5 * a.wing_span)
    }

    /// gear_length + max(half span, half height), the nose and the wing tips: an upper bound
    /// of every contact point's distance from the CG without a square root (m).
    #[inline(always)]
    fn bound(&self, a: &Airframe) -> f64 {
        (self.gear_length + self.gear_half_span.max(self.gear_half_height))
            .max(self.nose_length)
            .max(0.5 * a.wing_span)
    }

    /// Whether no contact point can touch the ground at `x` (the CG higher above the
    /// ground than any point reaches, with a margin for rounding): [`Ground::contact_state`]
    /// would count no touching point. Cheap (no attitude needed).
    #[inline]
    pub fn clearly_airborne(&self, a: &Airframe, x: &StateVector) -> bool {
        x[POS_D] + self.bound(a) * (1.0 + 1e-12) < self.height
    }

    /// Contact force and moment about the CG in body axes (N, N m) at a state, given its
    /// DCM^BE `c` (module docs). Zero without contact; does not allocate.
    #[inline(always)]
    pub fn contact(&self, a: &Airframe, x: &StateVector, c: &Matrix3<f64>) -> (Vector3<f64>, Vector3<f64>) {
        // Cheap test first (no square root): gear_length + max(half span, half height) bounds
        // the gear's reach, so this returns only where the exact test below returns too.
        // Inlined into the caller (no result through memory on the hot, airborne path).
        if x[POS_D] + self.bound(a) <= self.height || x[POS_D].is_nan() {
            return (Vector3::zeros(), Vector3::zeros());
        }
        self.contact_near(a, x, c)
    }

    /// [`Ground::contact`] once the cheap bound no longer rules contact out.
    #[inline(never)]
    fn contact_near(&self, a: &Airframe, x: &StateVector, c: &Matrix3<f64>) -> (Vector3<f64>, Vector3<f64>) {
        let mut force = Vector3::zeros();
        let mut moment = Vector3::zeros();
        if x[POS_D] + self.reach(a) <= self.height {
            return (force, moment);
        }
        let pos = Vector3::new(x[POS_N], x[POS_E], x[POS_D]);
        let v = Vector3::new(x[U], x[V], x[W]);
        let omega = Vector3::new(x[P], x[Q], x[R]);
        for r in self.points(a) {
            let p = pos + c.tr_mul(&r);
            let depth = p.z - self.height;
            if depth <= 0.0 {
                continue;
            }
            let vp = c.tr_mul(&(v + omega.cross(&r)));
            let n = (self.stiffness * depth + self.damping * vp.z).max(0.0);
            let vt2 = vp.x * vp.x + vp.y * vp.y;
            let k = -self.friction * n / (vt2 + FRICTION_V_EPS * FRICTION_V_EPS).sqrt();
            let f_body = c * Vector3::new(k * vp.x, k * vp.y, -n);
            force += f_body;
            moment += r.cross(&f_body);
        }
        (force, moment)
    }

    /// Contact summary (touching points, sink rate, clearance) at a state.
    pub fn contact_state(&self, a: &Airframe, x: &StateVector) -> ContactState {
        if !self.height.is_finite() {
            return ContactState {
                points: 0,
                sink_rate: 0.0,
                clearance: f64::INFINITY,
            };
        }
        let q = Vector4::new(x[Q1], x[Q2], x[Q3], x[Q4]);
        let c = dcm_earth_to_body(&q);
        let pos = Vector3::new(x[POS_N], x[POS_E], x[POS_D]);
        let v = Vector3::new(x[U], x[V], x[W]);
        let omega = Vector3::new(x[P], x[Q], x[R]);
        let mut out = ContactState {
            points: 0,
            sink_rate: f64::NEG_INFINITY,
            clearance: f64::INFINITY,
        };
        let mut lowest_sink = 0.0;
        for r in self.points(a) {
            let p = pos + c.tr_mul(&r);
            let clearance = self.height - p.z;
            let sink = c.tr_mul(&(v + omega.cross(&r))).z;
            if clearance < 0.0 {
                out.points += 1;
            }
            if clearance < 1e-3 {
                out.sink_rate = out.sink_rate.max(sink);
            }
            if clearance < out.clearance {
                out.clearance = clearance;
                lowest_sink = sink;
            }
        }
        if out.sink_rate == f64::NEG_INFINITY {
            out.sink_rate = lowest_sink;
        }
        out
    }
}

impl Plant {
    /// State at rest on the ground: nose up (3-2-1 θ = 90°, belly towards `heading` ψ), the
    /// four tail points carrying the weight with the static compression mg/(4k), no
    /// velocity, no rates, no thrust, surfaces neutral. Needs a finite ground height.
    pub fn resting_on_ground(&self, pos_n: f64, pos_e: f64, heading: f64) -> StateVector {
        let a = &self.airframe;
        let g = &self.ground;
        let mut x = StateVector::zeros();
        let q = quat_from_euler_321(0.0, core::f64::consts::FRAC_PI_2, heading);
        x.fixed_rows_mut::<4>(Q1).copy_from(&q);
        x[POS_N] = pos_n;
        x[POS_E] = pos_e;
        x[POS_D] = g.height - g.gear_length + a.mass * a.gravity / (4.0 * g.stiffness);
        x[THRUST] = a.thrust_min;
        x
    }
}
