//! A global aerodynamic model valid for every α ∈ (−180°, 180°], β ∈ [−90°, 90°] and V̄ → 0:
//! the thesis's linear model (§2.3) inside attached flow, blended C¹ into a post-stall
//! flat-plate model, with the wing split into a part immersed in the propeller slip-stream
//! and a free part (issue 13). Selected by [`AeroModel`]; [`AeroModel::Thesis`] is
//! [`Airframe::forces_moments`] unchanged.
//!
//! # Model
//!
//! **Attached flow (the thesis's model, exactly).** Where |α| ≤ `alpha_attached` (10°) and
//! |β| ≤ `beta_attached` (15°) of the free stream the forces and moments are those of
//! [`Airframe::forces_moments`] (to rounding): every thesis trim, mode and table is unchanged.
//!
//! **Stall weight.** With the C¹ smoothstep S(t) = 3t² − 2t³ (t clamped to [0, 1]),
//!
//! ```text
//! σ(α, β) = 1 − (1 − S((|α| − α_a)/(α_s − α_a))) (1 − S((|β| − β_a)/(β_s − β_a)))
//! ```
//!
//! 0 in attached flow, 1 beyond α_s = 25° or β_s = 30°, C¹ everywhere (|α| only enters
//! where S is flat, and S is flat again at α = ±180°, so there is no seam at the wrap).
//!
//! **Post-stall (flat plate), body axes.** For a local flow v = (u, v, w), V = |v|,
//! q̄ = ½ρV², s_x = u/V, s_y = v/V, s_n = w/V (sine of the angle between the flow and the
//! wing plane, valid on the whole sphere including tail-first flight):
//!
//! ```text
//! C_N = C_D90 s_n / (0.56 + 0.44 |s_n|)              normal force of the wing plate
//! C_Yn = −C_Y90 s_y / (0.56 + 0.44 |s_y|)            normal force of the side surfaces
//! F = q̄S (−C_D0 s_x, −C_D0 s_y + C_Yn, −C_N)          skin friction along the plate + normal forces
//! ```
//!
//! The normal-force shape s_n/(0.56 + 0.44 |s_n|) is an empirical flat-plate fit of the
//! wind-turbine post-stall literature, where it is usually attributed to Lindenburg (ECN).
//! That attribution could not be confirmed in a primary source, so the shape stands here on
//! its own agreement with measured data: Sheldahl & Klimas's NACA 0015 table
//! (`tests/data/sheldahl_klimas_naca0015.csv`) gives C_N = C_l cos α + C_d sin α = 0.835 C_N(90°)
//! at 45° and 0.57 C_N(90°) at 30°; the fit gives 0.812 and 0.641, and the lift and drag it
//! implies are checked over 0–180° in `tests/global_aero.rs`. At α = 90° it is C_D90 (flat
//! plate: C_L = C_N cos α peaks near 45°, C_D = C_N sin α rises to C_D90 broadside).
//! C_D90 defaults to Viterna & Corrigan's (1982) finite-wing value 1.11 + 0.018 A = 1.187 for
//! A = 4.29 (the formula as implemented in NREL's AirfoilPrep.py, `Polar.extrapolate`,
//! wisdem.github.io/AirfoilPreppy). It is the φ-theory structure of Lustosa, Defaÿ &
//! Moschetta (JGCD 42(2), 2019) — force = −½ρS‖v‖Φ v, singularity-free on the sphere —
//! with the plate's normal coefficient made non-linear to follow measured post-stall data.
//! C_Y90 = C_D90 |C_Yβ| / C_Lα (α = 0 columns): the side surfaces' broadside force scales
//! with their share of the lift slope (no new parameter). Unlike the Gazebo/PX4
//! `LiftDragPlugin` (a straight post-stall line from α_stall, C⁰ at the seam and
//! unbounded past 90°) every coefficient here is bounded and C¹.
//!
//! **Reversed flow (tail first).** Near α = ±180° the wing is a symmetric section flown
//! backwards: the sharp trailing edge leads. Thin-airfoil theory gives the same lift slope
//! whichever edge leads, but a sharp leading edge carries no suction, so the force stays
//! normal to the chord (C_N = C_Lα s_n, C_L = C_N cos δ, C_D = C_N sin δ + skin friction) and
//! the flow separates early from the sharp edge. With the incidence δ = atan2(|w|, −u) of
//! the flow on the reversed chord, each half wing's normal coefficient is
//!
//! ```text
//! C_N/s_n = plate + r (C_Lα − plate),   r = (1 − S(δ; δ_a, δ_s)) (1 − S(|β|; β_a, β_s))
//! ```
//!
//! (C_Lα the thesis's α = 0 slope: the reversed wing has the same planform), acting at the
//! reversed quarter chord (x_cp below, s_x = −1). Defaults δ_a = 7°, δ_s = 22° from Sheldahl &
//! Klimas's NACA 0015 data, which are linear to 175°, peak at 170° (c_l = −0.85, c_d = 0.14)
//! and rejoin the plate curve by 165°; checked against those data in `tests/global_aero.rs`
//! (section: |ΔC_l| ≤ 0.15 over 165–180°, slope within 20 %, C_d within 0.015). r is C¹: S
//! is flat at δ = 0 (the |w| kink) and r = 0 for u ≥ 0 and near u = w = 0 (|β| → 90°).
//!
//! **Post-stall moments.** The plate's normal force acts at
//! x_cp = x_np − (c̄/4)(1 − s_x) ahead of the CG, with x_np = c̄ C_mα/C_Lα the neutral point of
//! the thesis's attached model: the centre of pressure moves aft by c̄/4 to mid-chord at 90°
//! (Sheldahl & Klimas: C_m,c/4 ≈ −0.5 at C_N ≈ 1.8) and to the reversed quarter chord
//! tail-first. The side normal force acts at x = b C_nβ/C_Yβ, z = −b C_lβ/C_Yβ (where the
//! thesis's β derivatives put it).
//!
//! **Slip-stream split.** The two propellers (disc area A each A/2, diameter
//! D = √(2A/π) = 0.406 m) wash a span 2D of the wing: immersed fraction
//! η = min(1, 2D/b) = 0.518 for b = 1.569 m. The immersed part sees the local flow
//! v_s = v_a + 2w e_x (far-wake slip-stream speed along body x combined with the free
//! stream, DESIGN.md §4), with its own α_s, β_s, q̄_s and stall weight σ_s. With F_th the
//! thesis's static wing terms and F_ps the post-stall terms at a given flow:
//!
//! ```text
//! F_wing = (1 − σ) F_th(v_a) + σ [(1 − η) F_ps(v_a) + η ((1 − σ_s) F_th(v_s) + σ_s F_ps(v_s))]
//! ```
//!
//! In attached free-stream flow this is the thesis's model (the slip-stream does not change
//! the wing's attached forces there, as in the thesis); once the free stream stalls the
//! immersed part follows its own local flow, so at high thrust it stays attached while the
//! free part stalls. Stall fraction (share of the wing in post-stall flow):
//! σ ((1 − η) + η σ_s), output as `stall_fraction`.
//!
//! **Rotation.** In attached flow the thesis's rate terms (C_Lq, C_mq, C_Yp, …, ¼ρV̄S…),
//! weighted by the attached share: (1 − σ) at the free stream plus σ η (1 − σ_s) at the
//! immersed part's local flow (¼ρV_sS…, so the wing in the propeller wash damps pitch and
//! roll in hover). After stall each half wing (area S/2, at (x_cp, ±b/4, 0)) and the side surfaces feel the
//! local velocity of their own point, v + ω × r, and their force acts there: the plate damps
//! rotation itself (pitch, roll and yaw), the thesis's rate terms are blended out with σ, and
//! every post-stall force does non-positive work F·(v + ω × r) ≤ 0 in still air.
//!
//! **Derivative interpolation.** The thesis clamps the α of its table interpolation at 11.8°,
//! a kink inside the blend band; the global model saturates it C¹ instead
//! ([`GlobalAero::coefficient_alpha`]), identical for |α| ≤ α_a.
//!
//! **Controls.** Surfaces in the slip-stream (elevator, rudder, flaps) keep the thesis's
//! terms at q̄_s scaled by e_s = (1 − σ_s) + σ_s s_x,s; the ailerons (free stream) by
//! e = (1 − σ) + σ s_x: as in φ-theory a flap's force follows the chordwise flow over it,
//! so its effect fades to zero in broadside flow and reverses tail-first.
//!
//! **Bounds.** The linear model is only used where |α|, |β| < α_s, β_s, so every force
//! coefficient stays below max(C_Lα α_s, C_D90, …) ≈ 1.5 of its own dynamic pressure.
//! Limits: quasi-steady (no dynamic stall or hysteresis), no jet-height correction of the
//! immersed strip (an upper estimate of the slip-stream lift), no asymmetric stall (spin).
//! References: R.E. Sheldahl & P.C. Klimas, SAND80-2114, Sandia, 1981 (OSTI 6548367);
//! L.A. Viterna & R.D. Corrigan, "Fixed pitch rotor performance of large horizontal axis wind
//! turbines", NASA Lewis Research Center, 1982; L.R. Lustosa, F. Defaÿ & J.-M. Moschetta, "Global
//! singularity-free aerodynamic model for algorithmic flight control of tail sitters",
//! J. Guidance, Control, and Dynamics 42(2), 2019.

use nalgebra::Vector3;

use crate::aero::{wind_axes, ForcesMoments, Surfaces, AIRSPEED_EPS};
use crate::airframe::{Airframe, Coefficients, InvalidParameter};

/// Which aerodynamic model the plant uses (FMU parameter `aero_model`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum AeroModel {
    /// 0: the thesis's linear derivatives at every angle ([`Airframe::forces_moments`]).
    Thesis,
    /// 1: the global model of this module (the FMU's default; [`crate::Plant::new`] uses
    /// [`AeroModel::Thesis`]).
    #[default]
    Global,
}

impl AeroModel {
    /// From the FMU integer (0 = thesis, 1 = global).
    pub fn from_index(i: i32) -> Option<Self> {
        match i {
            0 => Some(Self::Thesis),
            1 => Some(Self::Global),
            _ => None,
        }
    }

    /// The FMU integer.
    pub fn index(self) -> i32 {
        match self {
            Self::Thesis => 0,
            Self::Global => 1,
        }
    }
}

/// Aerodynamic regime (FMU output `aero_regime`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum AeroRegime {
    /// 0: the whole wing in attached flow: the thesis's model holds.
    #[default]
    Attached,
    /// 1: partly stalled (blend region, or the free wing stalled with the immersed part attached).
    Transition,
    /// 2: the whole wing in post-stall flow.
    Stalled,
}

impl AeroRegime {
    /// From a stall fraction in [0, 1].
    pub fn of(stall_fraction: f64) -> Self {
        if stall_fraction <= 0.0 {
            Self::Attached
        } else if stall_fraction >= 1.0 - 1e-9 {
            Self::Stalled
        } else {
            Self::Transition
        }
    }

    /// The FMU integer (0, 1, 2).
    pub fn index(self) -> i32 {
        match self {
            Self::Attached => 0,
            Self::Transition => 1,
            Self::Stalled => 2,
        }
    }
}

/// Parameters of the global model (FMU parameters of the same names).
#[allow(non_snake_case)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GlobalAero {
    /// The model in use.
    pub model: AeroModel,
    /// |α| up to which the flow is attached: the thesis's model exactly (rad) (10°).
    pub alpha_attached: f64,
    /// |α| from which the flow is fully separated (rad) (25°). With α_a = 10° this puts the
    /// model's C_Lmax at 0.99 (α = 16°), within 5 % of 0.945 = 0.9 × the section maximum
    /// c_l,max = 1.05 of a thick symmetric section (NACA 0015 at Re 7·10⁵, Sheldahl & Klimas 1981), the usual
    /// finite-wing estimate for an unswept wing (Raymer, Aircraft Design, §12.4).
    pub alpha_stalled: f64,
    /// |β| up to which the thesis's lateral model holds (rad) (15°).
    pub beta_attached: f64,
    /// |β| from which the side flow is fully separated (rad) (30°).
    pub beta_stalled: f64,
    /// Broadside (α = 90°) normal-force coefficient C_D90 of the wing (Viterna & Corrigan
    /// 1982: 1.11 + 0.018 A = 1.187 for A = 4.29).
    pub c_D_90: f64,
    /// Reversed flow (tail first): incidence δ = angle between the flow and the −x axis in
    /// the wing's x–z plane up to which the reversed wing is attached (rad) (7°).
    pub alpha_reverse_attached: f64,
    /// Reversed flow: incidence δ from which the reversed wing is fully separated (rad)
    /// (22°). The reversed NACA 0015 section of Sheldahl & Klimas (1981) is linear to 175°,
    /// peaks at 170° (c_l = 0.85) and is back on the flat-plate curve at 165° (section band
    /// 5°–15°); scaled to the wing as the forward band (section 7°–17° → wing 10°–25°,
    /// geometric α × c_lα/C_Lα ≈ 1.45) this gives 7°–22°, and the wing's reversed
    /// C_Lmax ≈ 0.9 × 0.85 (the forward finite-wing rule, `alpha_stalled`).
    pub alpha_reverse_stalled: f64,
}

// `impl Default for GlobalAero`: the start values of group `global_aero` of
// modelDescription/tailsitter_plant.json (`model` from `aero_model`), generated by build.rs.
include!(concat!(env!("OUT_DIR"), "/global_aero_generated.rs"));

/// Diagnostics of one evaluation of the global model.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct AeroDiagnostics {
    /// Share of the wing in post-stall flow, σ((1 − η) + η σ_s) ∈ [0, 1].
    pub stall_fraction: f64,
    /// Stall weight σ of the free stream.
    pub sigma_free: f64,
    /// Stall weight σ_s of the slip-stream (immersed part).
    pub sigma_slipstream: f64,
    /// Angle of attack of the immersed part's local flow (rad) ([`GlobalAero::forces_moments`]
    /// leaves it 0 while the free stream is attached, where it is not needed).
    pub alpha_slipstream: f64,
}

/// C¹ smoothstep: 0 for x ≤ x0, 1 for x ≥ x1, 3t² − 2t³ between.
#[inline]
fn smoothstep(x: f64, x0: f64, x1: f64) -> f64 {
    let t = ((x - x0) * (1.0 / (x1 - x0))).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// Air data of one flow: speed, α (2.2.12), β (2.2.13), wind axes (A.2.7) in body components.
#[derive(Debug, Clone, Copy)]
struct Flow {
    v: Vector3<f64>,
    speed: f64,
    alpha: f64,
    beta: f64,
    xw: Vector3<f64>,
    yw: Vector3<f64>,
    zw: Vector3<f64>,
    sa: f64,
    ca: f64,
}

impl Flow {
    /// Speed and wind axes only (α = β = 0 placeholders): for a flow whose angles are known
    /// not to be needed.
    #[inline]
    fn axes_of(v: Vector3<f64>) -> Self {
        let speed = v.norm();
        let (xw, yw, zw, sa, ca) = wind_axes(&v, speed);
        Self {
            v,
            speed,
            alpha: 0.0,
            beta: 0.0,
            xw,
            yw,
            zw,
            sa,
            ca,
        }
    }

    #[inline]
    fn of(v: Vector3<f64>) -> Self {
        let flow = Self::axes_of(v);
        if flow.speed < AIRSPEED_EPS {
            return flow;
        }
        Self {
            alpha: libm::atan2(v.z, v.x),
            beta: flow.xw.y.clamp(-1.0, 1.0).asin(),
            ..flow
        }
    }
}

/// A force and a moment about the CG, body axes.
type Wrench = (Vector3<f64>, Vector3<f64>);

impl GlobalAero {
    /// Every parameter finite; 0 ≤ α_a < α_s ≤ 90°, 0 ≤ β_a < β_s ≤ 90°, C_D90 > 0,
    /// 0 ≤ δ_a < δ_s < 90° (reversed flow).
    pub fn validate(&self) -> Result<(), InvalidParameter> {
        let bad = InvalidParameter::err;
        let half_pi = core::f64::consts::FRAC_PI_2;
        for (name, value) in [
            ("alpha_attached", self.alpha_attached),
            ("alpha_stalled", self.alpha_stalled),
            ("beta_attached", self.beta_attached),
            ("beta_stalled", self.beta_stalled),
            ("c_D_90", self.c_D_90),
            ("alpha_reverse_attached", self.alpha_reverse_attached),
            ("alpha_reverse_stalled", self.alpha_reverse_stalled),
        ] {
            if !value.is_finite() {
                return bad(name, value, "finite");
            }
        }
        if self.alpha_attached < 0.0 {
            return bad("alpha_attached", self.alpha_attached, ">= 0");
        }
        if !(self.alpha_stalled > self.alpha_attached && self.alpha_stalled <= half_pi) {
            return bad("alpha_stalled", self.alpha_stalled, "> alpha_attached and <= pi/2");
        }
        if self.beta_attached < 0.0 {
            return bad("beta_attached", self.beta_attached, ">= 0");
        }
        if !(self.beta_stalled > self.beta_attached && self.beta_stalled <= half_pi) {
            return bad("beta_stalled", self.beta_stalled, "> beta_attached and <= pi/2");
        }
        if self.c_D_90 <= 0.0 {
            return bad("c_D_90", self.c_D_90, "positive");
        }
        if self.alpha_reverse_attached < 0.0 {
            return bad("alpha_reverse_attached", self.alpha_reverse_attached, ">= 0");
        }
        if !(self.alpha_reverse_stalled > self.alpha_reverse_attached && self.alpha_reverse_stalled < half_pi) {
            return bad(
                "alpha_reverse_stalled",
                self.alpha_reverse_stalled,
                "> alpha_reverse_attached and < pi/2",
            );
        }
        Ok(())
    }

    /// Stall weight σ(α, β) ∈ [0, 1] (module docs): 0 in attached flow, 1 fully separated.
    #[inline]
    pub fn stall_weight(&self, alpha: f64, beta: f64) -> f64 {
        let sa = smoothstep(alpha.abs(), self.alpha_attached, self.alpha_stalled);
        let sb = smoothstep(beta.abs(), self.beta_attached, self.beta_stalled);
        1.0 - (1.0 - sa) * (1.0 - sb)
    }

    /// Stall weight σ of the free stream at the air-relative body velocity `v_air_body`: the
    /// σ of [`GlobalAero::forces_moments`] and [`GlobalAero::diagnostics`] (0 below
    /// [`AIRSPEED_EPS`]). The stall fraction is positive only where this is.
    #[inline]
    pub fn free_stream_stall_weight(&self, v_air_body: &Vector3<f64>) -> f64 {
        let fr = Flow::of(*v_air_body);
        self.stall_weight(fr.alpha, fr.beta)
    }

    /// Span fraction η = min(1, 2D/b) of the wing washed by the two propellers, D = √(2A/π)
    /// the diameter of one disc (A = `prop_disc_area` of both).
    #[inline]
    pub fn immersed_fraction(airframe: &Airframe) -> f64 {
        let d = (2.0 * airframe.prop_disc_area / core::f64::consts::PI).sqrt();
        (2.0 * d / airframe.wing_span).clamp(0.0, 1.0)
    }

    /// Thesis static wing/body terms (2.3.6–2.3.13 without rates and controls) at one flow,
    /// with the control lift `cl_ctrl` in the induced drag (2.3.12–13), as in
    /// [`Airframe::forces_moments`].
    #[inline]
    fn thesis_static(a: &Airframe, f: &Flow, c: &Coefficients, cl_ctrl: f64) -> Wrench {
        let qs = 0.5 * a.air_density * f.speed * f.speed * a.wing_area;
        let cl_wing = a.c_L0 + c.c_L_alpha * f.alpha;
        let cl = cl_wing + cl_ctrl;
        let cd = a.c_D0 + cl * cl * (1.0 / (core::f64::consts::PI * a.aspect_ratio * a.oswald_efficiency));
        let force = f.xw * (-qs * cd) + f.yw * (qs * c.c_Y_beta * f.beta) + f.zw * (-qs * cl_wing);
        let moment = f.xw * (qs * a.wing_span * c.c_l_beta * f.beta)
            + f.yw * (qs * a.mean_chord * (a.c_m0 + c.c_m_alpha * f.alpha))
            + f.zw * (qs * a.wing_span * c.c_n_beta * f.beta);
        (force, moment)
    }

    /// The thesis's rate terms (2.3.5–2.3.11) at one flow: ¼ρVS(…), stability-axis p_s, r_s.
    #[inline]
    fn thesis_rates(a: &Airframe, f: &Flow, c: &Coefficients, omega: &Vector3<f64>) -> Wrench {
        let kr = 0.25 * a.air_density * f.speed * a.wing_area;
        let (b, cbar) = (a.wing_span, a.mean_chord);
        let (p, q, r) = (omega.x, omega.y, omega.z);
        let ps = p * f.ca + r * f.sa;
        let rs = r * f.ca - p * f.sa;
        let force = f.yw * (kr * b * (c.c_Y_p * ps + c.c_Y_r * rs)) + f.zw * (-kr * cbar * c.c_L_q * q);
        let moment = f.xw * (kr * b * b * (c.c_l_p * ps + c.c_l_r * rs))
            + f.yw * (kr * cbar * cbar * c.c_m_q * q)
            + f.zw * (kr * b * b * (c.c_n_p * ps + c.c_n_r * rs));
        (force, moment)
    }

    /// The α at which the derivatives of Tables C.3/C.4 are interpolated. The thesis clamps
    /// it at ±`alpha_interp_limit` L (11.8°), a kink inside the blend band; here it is α for
    /// |α| ≤ α_a (so attached flow is the thesis's model exactly) and saturates C¹ beyond:
    /// α_a + (L − α_a)(t − t²/4), t = (|α| − α_a)/(L − α_a) ≤ 2, reaching L at
    /// |α| = 2L − α_a (13.6°). If L ≤ α_a the thesis's clamp lies in attached flow and is kept.
    #[inline]
    pub fn coefficient_alpha(&self, a: &Airframe, alpha: f64) -> f64 {
        let lim = a.alpha_interp_limit;
        let a0 = self.alpha_attached;
        let x = alpha.abs();
        if lim <= a0 || x <= a0 {
            return alpha;
        }
        let t = (x - a0) / (lim - a0);
        let y = if t >= 2.0 {
            lim
        } else {
            a0 + (lim - a0) * (t - 0.25 * t * t)
        };
        y.copysign(alpha)
    }

    /// Weight r ∈ [0, 1] of the attached reversed-flow normal force for a local air velocity
    /// v (module docs, "Reversed flow"): r = (1 − S(δ; δ_a, δ_s)) (1 − S(|β|; β_a, β_s)) with
    /// δ = atan2(|w|, −u) the incidence of the flow on the reversed chord. 0 whenever u ≥ 0
    /// (δ ≥ 90° > δ_s) and near u = w = 0, where the β factor vanishes; C¹ everywhere (S is
    /// flat at δ = 0, where |w| has its kink, and at |β| = 0).
    #[inline]
    pub fn reverse_attached_weight(&self, v: &Vector3<f64>) -> f64 {
        if v.x >= 0.0 {
            return 0.0;
        }
        let vn = v.norm();
        if vn < AIRSPEED_EPS {
            return 0.0;
        }
        let delta = v.z.abs().atan2(-v.x);
        if delta >= self.alpha_reverse_stalled {
            return 0.0;
        }
        let beta = (v.y / vn).clamp(-1.0, 1.0).asin();
        (1.0 - smoothstep(delta, self.alpha_reverse_attached, self.alpha_reverse_stalled))
            * (1.0 - smoothstep(beta.abs(), self.beta_attached, self.beta_stalled))
    }

    /// Post-stall flat-plate force and moment (module docs) for the local air velocity
    /// `v_cg` at the CG of one wing part (free stream, or free stream + slip-stream) and the
    /// body rates: each half wing (area S/2) at r = (x_cp, ±b/4, 0) and the side surfaces at
    /// (x_side, 0, z_side) feel the local velocity of their own point, v_cg + ω × r, and their
    /// force acts there. So rotation is damped by the plate itself, and the power
    /// F·(v_cg + ω × r) of every force is ≤ 0 (dissipative) by construction.
    #[inline]
    fn post_stall(&self, a: &Airframe, v_cg: &Vector3<f64>, omega: &Vector3<f64>) -> Wrench {
        let speed = v_cg.norm();
        let sx_cg = if speed < AIRSPEED_EPS { 1.0 } else { v_cg.x / speed };
        let x_np = if a.c_L_alpha_a0 != 0.0 {
            a.mean_chord * a.c_m_alpha_a0 / a.c_L_alpha_a0
        } else {
            0.0
        };
        let x_cp = x_np - 0.25 * a.mean_chord * (1.0 - sx_cg);
        let half_rho = 0.5 * a.air_density;
        let mut force = Vector3::zeros();
        let mut moment = Vector3::zeros();
        for y in [0.25 * a.wing_span, -0.25 * a.wing_span] {
            let r = Vector3::new(x_cp, y, 0.0);
            let v = v_cg + omega.cross(&r);
            // q̄ (S/2) s_i = ½ρ (S/2) |v| v_i: smooth, zero at |v| = 0.
            let k = half_rho * 0.5 * a.wing_area * v.norm();
            let vn = v.norm();
            let sn = if vn < AIRSPEED_EPS { 0.0 } else { v.z / vn };
            let plate = self.c_D_90 / (0.56 + 0.44 * sn.abs());
            // Tail first at small incidence the reversed wing is attached: C_N = C_Lα s_n.
            let w_rev = self.reverse_attached_weight(&v);
            let cn_over_sn = plate + w_rev * (a.c_L_alpha_a0.max(0.0) - plate);
            let f = Vector3::new(-k * a.c_D0 * v.x, -k * a.c_D0 * v.y, -k * cn_over_sn * v.z);
            force += f;
            moment += r.cross(&f);
        }
        let (cy90, x_side, z_side) = side_geometry(a, self.c_D_90);
        if cy90 > 0.0 {
            let r = Vector3::new(x_side, 0.0, z_side);
            let v = v_cg + omega.cross(&r);
            let vn = v.norm();
            let sy = if vn < AIRSPEED_EPS { 0.0 } else { v.y / vn };
            let f = Vector3::new(
                0.0,
                -half_rho * a.wing_area * vn * cy90 / (0.56 + 0.44 * sy.abs()) * v.y,
                0.0,
            );
            force += f;
            moment += r.cross(&f);
        }
        (force, moment)
    }

    /// Aerodynamic plus thrust force and moment of the global model, same arguments and
    /// result as [`Airframe::forces_moments`], plus the regime diagnostics. Equal to
    /// [`Airframe::forces_moments`] wherever σ = 0 (attached free stream).
    pub fn forces_moments(
        &self,
        a: &Airframe,
        v_air_body: &Vector3<f64>,
        omega_body: &Vector3<f64>,
        thrust: f64,
        surfaces: &Surfaces,
    ) -> (ForcesMoments, AeroDiagnostics) {
        self.forces_moments_from(a, v_air_body, omega_body, thrust, surfaces, f64::NAN)
    }

    /// [`GlobalAero::forces_moments`] with the induced-velocity solve warm-started from
    /// `w_start` ([`Airframe::induced_velocity_from`]; NaN for a cold start).
    #[inline(always)]
    pub fn forces_moments_from(
        &self,
        a: &Airframe,
        v_air_body: &Vector3<f64>,
        omega_body: &Vector3<f64>,
        thrust: f64,
        surfaces: &Surfaces,
        w_start: f64,
    ) -> (ForcesMoments, AeroDiagnostics) {
        let fr = Flow::of(*v_air_body);
        let c = a.coefficients(self.coefficient_alpha(a, fr.alpha));
        let d = surfaces;
        let rho = a.air_density;
        let s = a.wing_area;
        let b = a.wing_span;
        let cbar = a.mean_chord;
        let qs = 0.5 * rho * fr.speed * fr.speed * s;

        // Slip-stream flow over the immersed part and the surfaces behind the propellers.
        let wi = a.induced_velocity_from(fr.speed, fr.v.x, thrust, w_start);
        let vs = fr.speed + 2.0 * wi;
        let qss = 0.5 * rho * vs * vs * s;
        let v_wake = Vector3::new(fr.v.x + 2.0 * wi, fr.v.y, fr.v.z);

        let sigma = self.stall_weight(fr.alpha, fr.beta);
        // With the free stream attached the slip-stream is too: u ≥ 0 there, so
        // |α_s| ≤ |α| and |β_s| ≤ |β| (V_s ≥ V̄), σ_s = 0 and its angles are not needed.
        let (fs, sigma_s) = if sigma > 0.0 {
            let fs = Flow::of(v_wake);
            let sigma_s = self.stall_weight(fs.alpha, fs.beta);
            (fs, sigma_s)
        } else {
            (Flow::axes_of(v_wake), 0.0)
        };
        // η only weighs stalled shares: not needed (and its square root not taken) at σ = 0,
        // where the stall fraction σ((1 − η) + η σ_s) is 0 for any η ∈ [0, 1].
        let eta = if sigma > 0.0 { Self::immersed_fraction(a) } else { 0.0 };

        // Attached share of the free stream: the thesis's static (2.3.6–2.3.13) and rate
        // (2.3.5) terms. Stalled share: the plate (post_stall, damped by its point
        // velocities) and, for the immersed part, its own local flow — attached (thesis terms
        // at ¼ρV_sS…, q̄_s) or stalled.
        let mut force = Vector3::zeros();
        let mut moment = Vector3::zeros();
        let w_attached = 1.0 - sigma;
        if w_attached > 0.0 {
            let cl_ctrl = c.c_L_de * d.elevator + c.c_L_dfc * d.flap_collective;
            let (ft, mt) = Self::thesis_static(a, &fr, &c, cl_ctrl);
            let (fq, mq) = Self::thesis_rates(a, &fr, &c, omega_body);
            force += (ft + fq) * w_attached;
            moment += (mt + mq) * w_attached;
        }
        if sigma > 0.0 {
            let (fp, mp) = self.post_stall(a, &fr.v, omega_body);
            force += fp * (sigma * (1.0 - eta));
            moment += mp * (sigma * (1.0 - eta));
            let w_imm_attached = sigma * eta * (1.0 - sigma_s);
            if w_imm_attached > 0.0 {
                let cs = a.coefficients(self.coefficient_alpha(a, fs.alpha));
                let cl_ctrl = cs.c_L_de * d.elevator + cs.c_L_dfc * d.flap_collective;
                let (ft, mt) = Self::thesis_static(a, &fs, &cs, cl_ctrl);
                let (fq, mq) = Self::thesis_rates(a, &fs, &cs, omega_body);
                force += (ft + fq) * w_imm_attached;
                moment += (mt + mq) * w_imm_attached;
            }
            let w_imm_stalled = sigma * eta * sigma_s;
            if w_imm_stalled > 0.0 {
                let (fp, mp) = self.post_stall(a, &fs.v, omega_body);
                force += fp * w_imm_stalled;
                moment += mp * w_imm_stalled;
            }
        }

        // Ailerons (free stream), effectiveness fading with the chordwise flow after stall.
        // x_w's x component: v_x / V̄ (1 below AIRSPEED_EPS).
        let sx = fr.xw.x;
        let e_free = 1.0 - sigma + sigma * sx;
        force += fr.yw * (e_free * qs * c.c_Y_da * d.aileron);
        moment += (fr.xw * (c.c_l_da * b) + fr.zw * (c.c_n_da * b)) * (e_free * qs * d.aileron);

        // Surfaces in the slip-stream (thesis: q̄_s, slip-stream axes, derivatives at the
        // free-stream α), effectiveness fading with the local chordwise flow after stall.
        let sxs = fs.xw.x;
        let e_s = 1.0 - sigma_s + sigma_s * sxs;
        let lift_s = qss * (c.c_L_de * d.elevator + c.c_L_dfc * d.flap_collective);
        let side_s = qss * (c.c_Y_dr * d.rudder + c.c_Y_dv * d.vertical_flap);
        let l_s = qss * b * (c.c_l_dr * d.rudder + c.c_l_dfd * d.flap_differential + c.c_l_dv * d.vertical_flap);
        let m_s = qss * cbar * (c.c_m_de * d.elevator + c.c_m_dfc * d.flap_collective);
        let n_s = qss * b * (c.c_n_dr * d.rudder + c.c_n_dfd * d.flap_differential + c.c_n_dv * d.vertical_flap);
        force += (fs.yw * side_s + fs.zw * (-lift_s)) * e_s;
        moment += (fs.xw * l_s + fs.yw * m_s + fs.zw * n_s) * e_s;

        force.x += thrust;

        let fm = ForcesMoments {
            force_body: force,
            moment_body: moment,
            induced_velocity: wi,
            airspeed: fr.speed,
            alpha: fr.alpha,
            beta: fr.beta,
            slipstream_speed: vs,
        };
        let diag = AeroDiagnostics {
            stall_fraction: (sigma * ((1.0 - eta) + eta * sigma_s)).clamp(0.0, 1.0),
            sigma_free: sigma,
            sigma_slipstream: sigma_s,
            alpha_slipstream: fs.alpha,
        };
        (fm, diag)
    }

    /// Regime diagnostics only (cheap; used for the outputs of either model, so that
    /// `stall_fraction` also reports where the thesis's model is being used outside its
    /// validity).
    pub fn diagnostics(&self, a: &Airframe, v_air_body: &Vector3<f64>, thrust: f64) -> AeroDiagnostics {
        let fr = Flow::of(*v_air_body);
        let wi = a.induced_velocity(fr.speed, fr.v.x, thrust);
        let fs = Flow::of(Vector3::new(fr.v.x + 2.0 * wi, fr.v.y, fr.v.z));
        let sigma = self.stall_weight(fr.alpha, fr.beta);
        let sigma_s = self.stall_weight(fs.alpha, fs.beta);
        let eta = Self::immersed_fraction(a);
        AeroDiagnostics {
            stall_fraction: (sigma * ((1.0 - eta) + eta * sigma_s)).clamp(0.0, 1.0),
            sigma_free: sigma,
            sigma_slipstream: sigma_s,
            alpha_slipstream: fs.alpha,
        }
    }
}

/// Broadside side-force coefficient C_Y90 = C_D90 |C_Yβ|/C_Lα and the point (x, z) where the
/// side force acts, x = b C_nβ/C_Yβ, z = −b C_lβ/C_Yβ (α = 0 columns of Table C.3).
#[inline]
fn side_geometry(a: &Airframe, c_d_90: f64) -> (f64, f64, f64) {
    let cy90 = if a.c_L_alpha_a0 > 0.0 {
        c_d_90 * a.c_Y_beta_a0.abs() / a.c_L_alpha_a0
    } else {
        0.0
    };
    if a.c_Y_beta_a0 != 0.0 {
        (
            cy90,
            a.wing_span * a.c_n_beta_a0 / a.c_Y_beta_a0,
            -a.wing_span * a.c_l_beta_a0 / a.c_Y_beta_a0,
        )
    } else {
        (cy90, 0.0, 0.0)
    }
}
