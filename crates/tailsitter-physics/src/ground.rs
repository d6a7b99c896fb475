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
//! For a point r at depth δ = (P + (DCM^BE)ᵀ r)_d − height > 0 with earth position p and
//! velocity v_P = (DCM^BE)ᵀ (v + ω × r):
//!
//! ```text
//! N   = max(0, k δ + c v_P,d)                       normal force (never pulls)
//! F_e = −k (p_t − a) − c v_t                        tangential spring-damper to the anchor a
//! F_t = F_e min(1, μ N / |F_e|)                     capped: μ = μ_s stuck, μ_k slipping
//! F   = (F_t,n, F_t,e, −N) (earth)                  moment r × DCM^BE F about the CG
//! ```
//!
//! with p_t, v_t the horizontal parts of p and v_P. **Stick-slip friction** is the
//! elasto-plastic (bristle) contact: each touching point is tied to an anchor a on the ground
//! by a tangential spring-damper with the normal gains (k, c) — the "reset integrator"
//! friction model of D.A. Haessig and B. Friedland, *On the modeling and simulation of
//! friction*, J. Dyn. Sys. Meas. Control 113(3), 354–362, 1991, a stiff-bristle form of
//! Dahl's model (P.R. Dahl, *A solid friction model*, Aerospace Corp. TOR-0158(3107-18)-1,
//! 1968; P. Dupont et al., *Single state elastoplastic friction models*, IEEE Trans. Autom.
//! Control 47(5), 787–792, 2002). Below μ_s N a point sticks: a steady tangential load F
//! deflects the gear elastically by F/k and then holds (no creep); above it the point slips
//! with kinetic friction μ_k N. The anchors are the contact's memory ([`ContactAnchors`]):
//! held over each integration (sub)step, so the right-hand side stays a smooth function of
//! the state inside a step, and updated after every accepted (sub)step
//! ([`ContactAnchors::update`]):
//!
//! * a point that leaves the ground is freed ([`Grip::Free`]); a free point touching
//!   has no spring yet (F_e = −c v_t, capped at μ_k N);
//! * a free or slipping point whose force is under μ_k N sticks ([`Grip::Stuck`]), a free
//!   one anchored where it touches; a stuck one stays stuck while |F_e| ≤ μ_s N;
//! * otherwise the point slips ([`Grip::Slipping`]): the anchor is dragged behind it, the
//!   spring's deflection turned along F_e and shortened to at most μ_k N / k. The spring's
//!   energy k|p_t − a|²/2 never grows at an update, so the updates dissipate.
//!
//! Static μ_s ≥ kinetic μ_k (validated); defaults μ_s = μ_k = 0.5 (Coulomb's law with
//! stiction at the sliding level). A higher μ_s is physical for rubber feet on dry concrete
//! (0.6–1.0) but trips this airframe: standing on its gear, it tips over a gear point once
//! the horizontal reaction exceeds N b/h, b the gear's half-spread across the load and h the
//! CG's height above the ground — b/h = 0.25/0.45 = 0.56 over the fin points, 0.4/0.45 =
//! 0.89 over the wing-root points. With μ_s = 0.8 a touchdown at 0.5–0.75 m/s over the
//! ground (the tuned TSD's landings in 8 m/s from behind) sticks and trips over the fin
//! points; with μ_s ≤ 0.56 the gear slides first. Belly-on in 10 m/s the wind's 42 N is
//! 95 % of μ m g = 44 N: held.
//!
//! **Stiffness vs the integration step.** Defaults k = 2500 N/m, c = 100 N s/m per point:
//! standing on the four gear points the heave mode has ω = √(4k/m) = 33 rad/s, ζ ≈ 0.67,
//! static compression mg/(4k) = 8.8 mm; rocking about the gear ≈ 26 rad/s; the stiffest
//! friction modes are the tangential springs (the same k and c per point: ω = √(4k/m) =
//! 33 rad/s sideways, the rocking about the gear with the spring at the lever `gear_length`
//! similar) and the tangential damper c through the lever on I_yy (|λ| ≈ 4 c l²/I_yy). At the
//! default 20/3 ms step |λ|h stays well inside the Dormand–Prince method's real-axis stability
//! limit 3.31 (R(z) = Σ₀⁵ zᵏ/k! + z⁶/600); where a contact point touches, a step whose error
//! estimate exceeds its tolerance is taken in halves, as at touchdown, where the normal
//! force switches on.
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
    /// Kinetic (sliding) friction coefficient μ_k.
    pub friction: f64,
    /// Static friction coefficient μ_s ≥ μ_k: a stuck point holds up to μ_s N.
    pub static_friction: f64,
}

/// The friction state of one contact point (module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Grip {
    /// Not touching, or touching since the last update (no anchor yet).
    #[default]
    Free,
    /// Held by its anchor up to μ_s N.
    Stuck,
    /// Sliding with kinetic friction μ_k N; the anchor is dragged behind.
    Slipping,
}

impl Grip {
    /// 0 free, 1 stuck, 2 slipping (the FMU state's encoding).
    pub fn index(self) -> u8 {
        match self {
            Grip::Free => 0,
            Grip::Stuck => 1,
            Grip::Slipping => 2,
        }
    }

    /// Inverse of [`Grip::index`].
    pub fn from_index(i: u8) -> Option<Self> {
        match i {
            0 => Some(Grip::Free),
            1 => Some(Grip::Stuck),
            2 => Some(Grip::Slipping),
            _ => None,
        }
    }
}

/// Anchor of one contact point: where its tangential spring is tied to the ground.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Anchor {
    /// Earth north position of the anchor (m) (unused while free).
    pub n: f64,
    /// Earth east position of the anchor (m).
    pub e: f64,
    /// Friction state.
    pub grip: Grip,
}

/// The ground contact's memory: one [`Anchor`] per contact point, in the order of
/// [`Ground::points`]. Part of the plant's state besides the [`StateVector`] (the FMU
/// serialises it with the FMU state); [`ContactAnchors::default`] has every point free.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ContactAnchors {
    /// Anchors by contact point.
    pub points: [Anchor; N_CONTACT_POINTS],
}

impl ContactAnchors {
    /// Every point free (what an airborne state has).
    pub const FREE: Self = Self {
        points: [Anchor {
            n: 0.0,
            e: 0.0,
            grip: Grip::Free,
        }; N_CONTACT_POINTS],
    };

    /// Whether every point is free.
    #[inline]
    pub fn all_free(&self) -> bool {
        self.points.iter().all(|p| p.grip == Grip::Free)
    }

    /// Stored tangential spring energy Σ k |p_t − a|²/2 of the anchored points at `x` (J).
    pub fn spring_energy(&self, g: &Ground, a: &Airframe, x: &StateVector) -> f64 {
        let c = dcm_earth_to_body(&Vector4::new(x[Q1], x[Q2], x[Q3], x[Q4]));
        let pos = Vector3::new(x[POS_N], x[POS_E], x[POS_D]);
        let mut e = 0.0;
        for (anchor, r) in self.points.iter().zip(g.points(a)) {
            if anchor.grip != Grip::Free {
                let p = pos + c.tr_mul(&r);
                e += 0.5 * g.stiffness * ((p.x - anchor.n).powi(2) + (p.y - anchor.e).powi(2));
            }
        }
        e
    }

    /// Update the anchors after an accepted (sub)step ending at `x` (module docs): free the
    /// points off the ground, stick or slip the touching ones. Returns whether anything
    /// changed (the right-hand side at `x` then changed too). Does not allocate.
    #[inline]
    pub fn update(&mut self, g: &Ground, a: &Airframe, x: &StateVector) -> bool {
        if g.clearly_airborne(a, x) || x[POS_D].is_nan() {
            if self.all_free() {
                return false;
            }
            *self = Self::FREE;
            return true;
        }
        self.update_near(g, a, x)
    }

    /// [`ContactAnchors::update`] near the ground.
    #[inline(never)]
    fn update_near(&mut self, g: &Ground, a: &Airframe, x: &StateVector) -> bool {
        let c = dcm_earth_to_body(&Vector4::new(x[Q1], x[Q2], x[Q3], x[Q4]));
        let pos = Vector3::new(x[POS_N], x[POS_E], x[POS_D]);
        let v = Vector3::new(x[U], x[V], x[W]);
        let omega = Vector3::new(x[P], x[Q], x[R]);
        let mut changed = false;
        for (anchor, r) in self.points.iter_mut().zip(g.points(a)) {
            let p = pos + c.tr_mul(&r);
            let depth = p.z - g.height;
            let vp = c.tr_mul(&(v + omega.cross(&r)));
            let n = g.stiffness * depth + g.damping * vp.z;
            let old = *anchor;
            if !(depth > 0.0 && n > 0.0) {
                anchor.grip = Grip::Free;
            } else {
                let (fx, fy) = g.spring_damper(anchor, &p, &vp);
                let f = (fx * fx + fy * fy).sqrt();
                match anchor.grip {
                    Grip::Stuck if f <= g.static_friction * n => {}
                    Grip::Free | Grip::Slipping if f <= g.friction * n => {
                        if anchor.grip == Grip::Free {
                            anchor.n = p.x;
                            anchor.e = p.y;
                        }
                        anchor.grip = Grip::Stuck;
                    }
                    _ => {
                        // Slip: the deflection d = p_t − a turned against F_e (F_e = −k d
                        // then points along F_e) and shortened to at most μ_k N / k.
                        let (dn, de) = match anchor.grip {
                            Grip::Free => (0.0, 0.0),
                            _ => (p.x - anchor.n, p.y - anchor.e),
                        };
                        let d = (dn * dn + de * de).sqrt().min(g.friction * n / g.stiffness);
                        anchor.n = p.x + d * fx / f;
                        anchor.e = p.y + d * fy / f;
                        anchor.grip = Grip::Slipping;
                    }
                }
            }
            changed |= *anchor != old;
        }
        changed
    }
}

// `impl Default for Ground`: the start values of group `ground` of
// modelDescription/tailsitter_plant.json, generated by build.rs.
include!(concat!(env!("OUT_DIR"), "/ground_generated.rs"));

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
        let bad = InvalidParameter::err;
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
        if !(self.static_friction.is_finite() && self.static_friction >= self.friction) {
            return bad(
                "ground_static_friction",
                self.static_friction,
                "finite and >= ground_friction (static >= kinetic)",
            );
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

    /// The tangential spring-damper force F_e = −k (p_t − a) − c v_t (earth n, e) of a
    /// touching point at `p` moving at `vp`, before the friction cap (no spring while free).
    #[inline(always)]
    fn spring_damper(&self, anchor: &Anchor, p: &Vector3<f64>, vp: &Vector3<f64>) -> (f64, f64) {
        let (dn, de) = match anchor.grip {
            Grip::Free => (0.0, 0.0),
            _ => (p.x - anchor.n, p.y - anchor.e),
        };
        (
            -self.stiffness * dn - self.damping * vp.x,
            -self.stiffness * de - self.damping * vp.y,
        )
    }

    /// Contact force and moment about the CG in body axes (N, N m) at a state, given its
    /// DCM^BE `c` and the contact points' anchors (module docs). Zero without contact; does
    /// not allocate.
    #[inline(always)]
    pub fn contact(
        &self,
        a: &Airframe,
        x: &StateVector,
        c: &Matrix3<f64>,
        anchors: &ContactAnchors,
    ) -> (Vector3<f64>, Vector3<f64>) {
        // Cheap test first (no square root): gear_length + max(half span, half height) bounds
        // the gear's reach, so this returns only where the exact test below returns too.
        // Inlined into the caller (no result through memory on the hot, airborne path).
        if x[POS_D] + self.bound(a) <= self.height || x[POS_D].is_nan() {
            return (Vector3::zeros(), Vector3::zeros());
        }
        self.contact_near(a, x, c, anchors)
    }

    /// [`Ground::contact`] once the cheap bound no longer rules contact out.
    #[inline(never)]
    fn contact_near(
        &self,
        a: &Airframe,
        x: &StateVector,
        c: &Matrix3<f64>,
        anchors: &ContactAnchors,
    ) -> (Vector3<f64>, Vector3<f64>) {
        let mut force = Vector3::zeros();
        let mut moment = Vector3::zeros();
        if x[POS_D] + self.reach(a) <= self.height {
            return (force, moment);
        }
        let pos = Vector3::new(x[POS_N], x[POS_E], x[POS_D]);
        let v = Vector3::new(x[U], x[V], x[W]);
        let omega = Vector3::new(x[P], x[Q], x[R]);
        for (anchor, r) in anchors.points.iter().zip(self.points(a)) {
            let p = pos + c.tr_mul(&r);
            let depth = p.z - self.height;
            if depth <= 0.0 {
                continue;
            }
            let vp = c.tr_mul(&(v + omega.cross(&r)));
            let n = (self.stiffness * depth + self.damping * vp.z).max(0.0);
            let mu = match anchor.grip {
                Grip::Stuck => self.static_friction,
                Grip::Free | Grip::Slipping => self.friction,
            };
            let (fx, fy) = self.spring_damper(anchor, &p, &vp);
            let (f2, cap) = (fx * fx + fy * fy, mu * n);
            let s = if f2 > cap * cap { cap / f2.sqrt() } else { 1.0 };
            let f_body = c * Vector3::new(s * fx, s * fy, -n);
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
