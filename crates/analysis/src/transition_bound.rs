//! Minimum time of the back transition (level flight at V_L → vertical climb at V_V),
//! independent of the missions' flight-path profile; and the transitions the two tuned
//! controllers actually fly with short T2. Method, tables and discussion: docs/TRANSITION.md.
//!
//! **Model** (point mass in the vertical plane, wind axes; thrust along the body, at α to
//! the path):
//!
//! ```text
//! m V̇   = T cos α − D − m g sin γ              ḣ = V sin γ
//! m V γ̇ = T sin α + L − m g cos γ              Ṫ = (T_c − T)/τ_T,  0 ≤ T_c ≤ T_max
//! α̇ = (α_c − α)/τ_α, |α_c| ≤ α_max  (τ_α = 0: α = α_c, commanded directly)
//! ```
//!
//! with the airframe's aerodynamics (the thesis model, `tailsitter_physics`: derivatives of
//! Tables C.3/C.4 interpolated in α, C_L0 = C_m0 = 0, surfaces in the slip-stream at
//! q̄_s = ½ρ(V + 2w)², w from momentum theory at the axial speed V cos α), **trimmed in pitch
//! at every instant**: the surface deflection solves
//!
//! ```text
//! q̄ (C_m0 + C_mα α + C_mq q̂) + q̄_s (C_mδe δe + C_mδfc δfc) = 0,    q̂ = q c̄/(2V), q = γ̇ + α̇
//! L = q̄ S (C_L0 + C_Lα α + C_Lq q̂) + q̄_s S (C_Lδe δe + C_Lδfc δfc)
//! D = q̄ S (C_D0 + C_L²/(π A e)),  C_L = C_L0 + C_Lα α + C_Lδe δe + C_Lδfc δfc   (2.3.12–13)
//! ```
//!
//! for two trim laws: [`TrimLaw::ElevatorOnly`] (δfc = 0) and [`TrimLaw::FlapMixing`] (the
//! thesis's normal-acceleration mixing, §4.2.2 (4.2.12), Table 4.1: δfc = r δe with
//! r = [`FLAP_MIX_RATIO`]; where |r δe| would exceed the deflection limit the flaps stay at
//! the limit and the elevator trims the rest). Without the rate terms and with q̄_s = q̄
//! the trimmed lift is q̄ S C_Lt(α), C_Lt = (C_Lα − C_mα C_Lδ/C_mδ) α: the slip-stream
//! factor cancels (the surface lift is fixed by the moment it must balance).
//!
//! **Optimal control.** With the lags the controls α_c, T_c enter the dynamics linearly, so
//! by Pontryagin's principle they are bang-bang wherever their switching functions do not
//! vanish on an interval; the minimum is found over bang-bang sequences with a few
//! switching times ([`rotation_bound`], [`complete_bound`]).

use std::f64::consts::{FRAC_PI_2, PI};

use closed_loop::{fly, Ordering, Scenario, Trace};
use flight_mission::MissionParams;
use guidance::{PointMass, Profile, ProfileLimits};
use lqr_control::{LqrController, LqrParams};
use nalgebra::Vector3;
use tailsitter_physics::{AeroModel, Airframe, GlobalAero, Plant, Surfaces};
use tsd_control::{TsdController, TsdParams};

use crate::controllers::Kind;

/// δfc / δe of the thesis's mixed normal actuator, (4.2.12): r = −1.1 C_Lδe / C_Lδfc = −1.833
/// (Table 4.1: mixed C_L = 1.246 − 1.833 · 0.748 = −0.125, C_m = −1.809 − 1.833 · (−0.083) = −1.657).
pub const FLAP_MIX_RATIO: f64 = -1.833;
/// Integration step of the point mass (s).
pub const STEP: f64 = 0.004;
/// Tolerances of the complete transition (the flown measure's): |γ − 90°| ≤ 5°, |V − V_V| ≤ 1 m/s.
pub const GAMMA_TOL: f64 = 5.0 * PI / 180.0;
pub const SPEED_TOL: f64 = 1.0;
/// Arrival in the steady climb also asks |T − T_climb| ≤ this fraction of the weight and
/// |α| ≤ [`ALPHA_ARRIVAL_TOL`]: the state then stays in the tolerances on constant controls.
pub const THRUST_ARRIVAL_TOL: f64 = 0.1;
pub const ALPHA_ARRIVAL_TOL: f64 = 2.0 * PI / 180.0;
/// Lag of α used besides "commanded directly" (s): the profile's `CONTROL_LAG`, close to the
/// short-period envelope time constant 1/7.36 s = 0.136 s of the level trim.
pub const ALPHA_LAG: f64 = 0.12;

/// How the aircraft is trimmed in pitch.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TrimLaw {
    /// Elevator only (δfc = 0).
    ElevatorOnly,
    /// δfc = [`FLAP_MIX_RATIO`] · δe (thesis §4.2.2, Table 4.1), flaps saturating at the limit.
    FlapMixing,
}

impl TrimLaw {
    pub const ALL: [TrimLaw; 2] = [TrimLaw::ElevatorOnly, TrimLaw::FlapMixing];
    pub fn name(self) -> &'static str {
        match self {
            TrimLaw::ElevatorOnly => "elevator only",
            TrimLaw::FlapMixing => "flap mixing",
        }
    }
}

/// Forces of the pitch-trimmed aircraft at one state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Trimmed {
    /// Aerodynamic lift L (N) (thrust excluded).
    pub lift: f64,
    /// Drag D (N).
    pub drag: f64,
    pub delta_e: f64,
    pub delta_fc: f64,
    /// Whether the trim needs more than the deflection limit on the elevator (it is then
    /// computed unclamped: the point is not flyable).
    pub saturated: bool,
}

/// The point mass of the trimmed airframe.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Model {
    pub airframe: Airframe,
    pub trim: TrimLaw,
    /// α lag τ_α (s); 0 = α commanded directly.
    pub tau_alpha: f64,
    /// Whether the pitch-rate derivatives C_Lq, C_mq are counted (q = γ̇ + α̇).
    pub rate_terms: bool,
    /// Aerodynamic model: [`AeroModel::Thesis`] (the derivatives, closed-form trim above) or
    /// [`AeroModel::Global`] (the plant FMU's default: stall blending from α = 10°; forces
    /// from `GlobalAero::forces_moments`, pitch trim solved numerically).
    pub aero: AeroModel,
}

/// State: V, γ, h, α, T.
pub type State = [f64; 5];

impl Model {
    pub fn new(trim: TrimLaw, tau_alpha: f64) -> Self {
        Self {
            airframe: Airframe::default(),
            trim,
            tau_alpha,
            rate_terms: true,
            aero: AeroModel::Thesis,
        }
    }

    /// The flap deflection of the trim law for an elevator deflection.
    fn flap_of(&self, de: f64) -> f64 {
        match self.trim {
            TrimLaw::ElevatorOnly => 0.0,
            TrimLaw::FlapMixing => {
                let lim = self.airframe.deflection_limit;
                (FLAP_MIX_RATIO * de).clamp(-lim, lim)
            }
        }
    }

    /// [`Model::trimmed`] on the global aerodynamics: the elevator (with the flaps of the law)
    /// solving M = 0 by the secant method from the thesis model's trim.
    fn trimmed_global(&self, v: f64, alpha: f64, thrust: f64, q: f64, start: f64) -> Trimmed {
        let a = &self.airframe;
        let g = GlobalAero::default();
        let vb = Vector3::new(v * alpha.cos(), 0.0, v * alpha.sin());
        let om = Vector3::new(0.0, if self.rate_terms { q } else { 0.0 }, 0.0);
        let fm = |de: f64| {
            let s = Surfaces {
                elevator: de,
                flap_collective: self.flap_of(de),
                ..Surfaces::default()
            };
            g.forces_moments(a, &vb, &om, thrust, &s).0
        };
        let (mut d0, mut d1) = (start, start + 0.01);
        let (mut m0, mut m1) = (fm(d0).moment_body.y, fm(d1).moment_body.y);
        for _ in 0..8 {
            if (m1 - m0).abs() < 1e-12 {
                break;
            }
            let d2 = d1 - m1 * (d1 - d0) / (m1 - m0);
            (d0, m0) = (d1, m1);
            d1 = d2;
            m1 = fm(d1).moment_body.y;
            if m1.abs() < 1e-9 {
                break;
            }
        }
        let f = fm(d1).force_body - Vector3::new(thrust, 0.0, 0.0);
        let (sa, ca) = alpha.sin_cos();
        Trimmed {
            lift: f.x * sa - f.z * ca,
            drag: -(f.x * ca + f.z * sa),
            delta_e: d1,
            delta_fc: self.flap_of(d1),
            saturated: d1.abs() > a.deflection_limit + 1e-9,
        }
    }

    fn weight(&self) -> f64 {
        self.airframe.mass * self.airframe.gravity
    }

    /// Lift and drag at airspeed `v`, α, thrust and pitch rate `q`, trimmed by the law.
    pub fn trimmed(&self, v: f64, alpha: f64, thrust: f64, q: f64) -> Trimmed {
        let a = &self.airframe;
        let c = a.coefficients(alpha);
        let qbar = 0.5 * a.air_density * v * v;
        let w = a.induced_velocity(v, v * alpha.cos(), thrust);
        let qs = 0.5 * a.air_density * (v + 2.0 * w).powi(2);
        let qhat = if self.rate_terms {
            q * a.mean_chord / (2.0 * v)
        } else {
            0.0
        };
        let moment = qbar * (a.c_m0 + c.c_m_alpha * alpha + c.c_m_q * qhat);
        let lim = a.deflection_limit;
        let (de, dfc) = match self.trim {
            TrimLaw::ElevatorOnly => (-moment / (qs * c.c_m_de), 0.0),
            TrimLaw::FlapMixing => {
                let de = -moment / (qs * (c.c_m_de + FLAP_MIX_RATIO * c.c_m_dfc));
                let dfc = FLAP_MIX_RATIO * de;
                if dfc.abs() <= lim {
                    (de, dfc)
                } else {
                    let dfc = dfc.clamp(-lim, lim);
                    (-(moment + qs * c.c_m_dfc * dfc) / (qs * c.c_m_de), dfc)
                }
            }
        };
        let lift = qbar * a.wing_area * (a.c_L0 + c.c_L_alpha * alpha + c.c_L_q * qhat)
            + qs * a.wing_area * (c.c_L_de * de + c.c_L_dfc * dfc);
        let cl = a.c_L0 + c.c_L_alpha * alpha + c.c_L_de * de + c.c_L_dfc * dfc;
        let drag = qbar * a.wing_area * (a.c_D0 + cl * cl / (PI * a.aspect_ratio * a.oswald_efficiency));
        if self.aero == AeroModel::Global {
            return self.trimmed_global(v, alpha, thrust, q, de);
        }
        Trimmed {
            lift,
            drag,
            delta_e: de,
            delta_fc: dfc,
            saturated: de.abs() > lim + 1e-9,
        }
    }

    /// Trimmed lift coefficient C_Lt(α) = L / (q̄ S) with q̄_s = q̄ (no thrust), no rates.
    pub fn trimmed_cl(&self, alpha: f64) -> f64 {
        let m = Model {
            rate_terms: false,
            ..*self
        };
        let v = 25.0;
        m.trimmed(v, alpha, 0.0, 0.0).lift / (0.5 * self.airframe.air_density * v * v * self.airframe.wing_area)
    }

    /// Level trim at `v`: (α, T) with L + T sin α = W, T cos α = D.
    pub fn level_trim(&self, v: f64) -> (f64, f64) {
        let (mut alpha, mut thrust) = (0.1, 10.0);
        for _ in 0..60 {
            let f = self.trimmed(v, alpha, thrust, 0.0);
            thrust = f.drag / alpha.cos();
            let g = |a: f64| {
                let f = self.trimmed(v, a, thrust, 0.0);
                f.lift + thrust * a.sin() - self.weight()
            };
            let h = 1e-6;
            alpha -= g(alpha) / ((g(alpha + h) - g(alpha - h)) / (2.0 * h));
        }
        (alpha, thrust)
    }

    /// Thrust of the steady vertical climb at `v` (α = 0): W + D.
    pub fn climb_thrust(&self, v: f64) -> f64 {
        self.weight() + self.trimmed(v, 0.0, self.weight(), 0.0).drag
    }

    /// Rates of the state under the commands; also the trim and the load factor of the
    /// aerodynamic lift n = L/(m g).
    pub fn rates(&self, x: &State, alpha_c: f64, thrust_c: f64) -> (State, Trimmed) {
        let a = &self.airframe;
        let [v, gamma, _, alpha, thrust] = *x;
        let alpha_dot = if self.tau_alpha > 0.0 {
            (alpha_c - alpha) / self.tau_alpha
        } else {
            0.0
        };
        let m = a.mass;
        let (sa, ca) = alpha.sin_cos();
        let (sg, cg) = gamma.sin_cos();
        // q = γ̇ + α̇ by fixed-point iteration (γ̇ depends on the lift through C_Lq, C_mq).
        let mut q = alpha_dot;
        let mut f = self.trimmed(v, alpha, thrust, q);
        for _ in 0..3 {
            let gamma_dot = (thrust * sa + f.lift - m * a.gravity * cg) / (m * v);
            q = gamma_dot + alpha_dot;
            f = self.trimmed(v, alpha, thrust, q);
        }
        let tc = thrust_c.clamp(a.thrust_min, a.thrust_max);
        (
            [
                (thrust * ca - f.drag) / m - a.gravity * sg,
                (thrust * sa + f.lift - m * a.gravity * cg) / (m * v),
                v * sg,
                alpha_dot,
                (tc - thrust) / a.tau_thrust,
            ],
            f,
        )
    }

    /// One RK4 step of length `h` with constant commands (α = α_c directly when τ_α = 0).
    pub fn step(&self, x: &State, alpha_c: f64, thrust_c: f64, h: f64) -> State {
        let mut x0 = *x;
        if self.tau_alpha <= 0.0 {
            x0[3] = alpha_c;
        }
        let add = |a: &State, b: &State, s: f64| -> State { core::array::from_fn(|k| a[k] + s * b[k]) };
        let k1 = self.rates(&x0, alpha_c, thrust_c).0;
        let k2 = self.rates(&add(&x0, &k1, 0.5 * h), alpha_c, thrust_c).0;
        let k3 = self.rates(&add(&x0, &k2, 0.5 * h), alpha_c, thrust_c).0;
        let k4 = self.rates(&add(&x0, &k3, h), alpha_c, thrust_c).0;
        core::array::from_fn(|k| x0[k] + h / 6.0 * (k1[k] + 2.0 * k2[k] + 2.0 * k3[k] + k4[k]))
    }

    /// The level trim at `v` as a state.
    pub fn level_state(&self, v: f64) -> State {
        let (alpha, thrust) = self.level_trim(v);
        [v, 0.0, 0.0, alpha, thrust]
    }
}

/// The switching parameters of a back transition (bang-bang with a terminal regulator):
/// thrust T_max on [0, t_cut), 0 from t_cut until V ≤ `v_on`, then T_max until T reaches the
/// climb thrust T_climb, then T_c = T_climb + 2 m (V_V − V) (clamped to 0…T_max); α_c = +α_max
/// until γ ≥ `gamma_s`, then the regulator α_c = 2 (90° − γ) − 0.3 γ̇ clamped to ±α_max
/// (at the bound −α_max first: it stops the turn at 90°). The rotation uses t_cut only
/// (`v_on` = 0, `gamma_s` = 90°).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Switches {
    pub t_cut: f64,
    pub v_on: f64,
    pub gamma_s: f64,
}

/// The result of one bound.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bound {
    /// Minimum time (s); NaN if not reached.
    pub time: f64,
    /// The optimal switching parameters.
    pub switches: Switches,
    /// Peak aerodynamic load factor L/(m g) and peak (L + T sin α)/(m g).
    pub peak_n: f64,
    pub peak_n_total: f64,
    /// Speed at the peak load (m/s).
    pub v_at_peak: f64,
    /// Whether the trim saturated the elevator somewhere on the way.
    pub saturated: bool,
    /// Largest |δfc| (rad) on the way.
    pub max_flap: f64,
    /// Complete transition only: the earliest first entry into |γ − 90°| ≤ 5°, |V − V_V| ≤ 1
    /// over every searched sequence (no condition on T, α: the state need not stay); and
    /// whether the optimal arrival then stays in the tolerances for 3 s.
    pub entry: f64,
    pub holds: bool,
}

impl Bound {
    fn nan() -> Self {
        Self {
            time: f64::NAN,
            switches: Switches {
                t_cut: f64::NAN,
                v_on: f64::NAN,
                gamma_s: f64::NAN,
            },
            peak_n: f64::NAN,
            peak_n_total: f64::NAN,
            v_at_peak: f64::NAN,
            saturated: false,
            max_flap: f64::NAN,
            entry: f64::NAN,
            holds: false,
        }
    }
}

/// Simulation of one switch sequence from the level trim at `v_level` until `stop` holds or
/// `t_max`; with `hold` > 0 the run continues `hold` s after the stop and `holds` tells
/// whether the tolerances were kept. Returns the bound figures (time NaN if not reached).
fn simulate(
    model: &Model,
    alpha_max: f64,
    v_level: f64,
    sw: &Switches,
    t_max: f64,
    stop: &dyn Fn(&State) -> bool,
    hold: f64,
) -> Bound {
    let a = &model.airframe;
    let v_v = 3.0;
    let t_climb = model.climb_thrust(v_v);
    let mut x = model.level_state(v_level);
    let mut b = Bound {
        switches: *sw,
        peak_n: 0.0,
        peak_n_total: 0.0,
        max_flap: 0.0,
        ..Bound::nan()
    };
    let w = a.mass * a.gravity;
    let n = ((t_max + hold) / STEP).ceil() as usize;
    // Modes: thrust 0 = T_max, 1 = off, 2 = on (T_max), 3 = regulated; α: regulator on.
    let mut thrust_mode = 0;
    let mut regulate = false;
    let mut gamma_dot = 0.0;
    let mut stopped_at: Option<f64> = None;
    b.holds = true;
    for i in 0..n {
        let t = i as f64 * STEP;
        if thrust_mode == 0 && t >= sw.t_cut {
            thrust_mode = 1;
        }
        if thrust_mode == 1 && x[0] <= sw.v_on {
            thrust_mode = 2;
        }
        if thrust_mode == 2 && x[4] >= t_climb {
            thrust_mode = 3;
        }
        regulate |= x[1] >= sw.gamma_s;
        let alpha_c = if regulate {
            (2.0 * (FRAC_PI_2 - x[1]) - 0.3 * gamma_dot).clamp(-alpha_max, alpha_max)
        } else {
            alpha_max
        };
        let thrust_c = match thrust_mode {
            0 | 2 => a.thrust_max,
            1 => 0.0,
            _ => (t_climb + 2.0 * a.mass * (v_v - x[0])).clamp(0.0, a.thrust_max),
        };
        let mut xa = x;
        if model.tau_alpha <= 0.0 {
            xa[3] = alpha_c;
        }
        let (d, f) = model.rates(&xa, alpha_c, thrust_c);
        gamma_dot = d[1];
        if stopped_at.is_none() {
            if f.lift / w > b.peak_n {
                b.peak_n = f.lift / w;
                b.v_at_peak = xa[0];
            }
            b.peak_n_total = b.peak_n_total.max((f.lift + xa[4] * xa[3].sin()) / w);
            b.saturated |= f.saturated;
            b.max_flap = b.max_flap.max(f.delta_fc.abs());
            if b.entry.is_nan() && in_tolerance(&xa) {
                b.entry = t;
            }
            if stop(&xa) {
                b.time = t;
                if hold <= 0.0 {
                    return b;
                }
                stopped_at = Some(t);
            }
        } else if !in_tolerance(&xa) {
            b.holds = false;
            return b;
        }
        if stopped_at.is_none() && t > t_max {
            break;
        }
        x = model.step(&x, alpha_c, thrust_c, STEP);
        if !(x.iter().all(|v| v.is_finite()) && x[0] > 0.2) {
            b.holds = false;
            break;
        }
    }
    b.holds &= stopped_at.is_some();
    b
}

/// Minimum time of the **rotation**: γ from 0 to 90° from the level trim at `v_level`.
/// α_c = α_max throughout; the thrust is searched over T_max → 0 at t_cut (t_cut = ∞: full
/// thrust throughout; on ties the later cut wins). Full thrust and full α both raise γ̇
/// directly (T sin α, L) and keep the speed the lift needs.
pub fn rotation_bound(model: &Model, alpha_max: f64, v_level: f64) -> Bound {
    let stop = |x: &State| x[1] >= FRAC_PI_2;
    let mut best = Bound::nan();
    for k in (0..=40).rev() {
        let t_cut = if k == 40 { f64::INFINITY } else { k as f64 * 0.1 };
        let sw = Switches {
            t_cut,
            v_on: 0.0,
            gamma_s: f64::INFINITY,
        };
        let b = simulate(model, alpha_max, v_level, &sw, 8.0, &stop, 0.0);
        if b.time.is_finite() && (best.time.is_nan() || b.time < best.time - 1e-9) {
            best = b;
        }
    }
    best
}

fn in_tolerance(x: &State) -> bool {
    (x[1] - FRAC_PI_2).abs() <= GAMMA_TOL && (x[0] - 3.0).abs() <= SPEED_TOL
}

/// Minimum time of the **complete** back transition: from the level trim at `v_level` to
/// the steady climb at 3 m/s, i.e. the first time with |γ − 90°| ≤ 5°, |V − 3| ≤ 1 m/s,
/// |T − T_climb| ≤ 0.1 W and |α| ≤ 2°, over the sequences of [`Switches`] (grid over
/// t_cut, v_on, γ_s, then pattern-search refinement).
pub fn complete_bound(model: &Model, alpha_max: f64, v_level: f64) -> Bound {
    let w = model.airframe.mass * model.airframe.gravity;
    let t_climb = model.climb_thrust(3.0);
    let stop = |x: &State| {
        in_tolerance(x) && (x[4] - t_climb).abs() <= THRUST_ARRIVAL_TOL * w && x[3].abs() <= ALPHA_ARRIVAL_TOL
    };
    let mut entry = f64::INFINITY;
    let mut cost = |p: &[f64; 3]| -> Bound {
        let sw = Switches {
            t_cut: p[0].max(0.0),
            v_on: p[1],
            gamma_s: p[2],
        };
        let b = simulate(model, alpha_max, v_level, &sw, 7.0, &stop, 0.0);
        if b.entry < entry {
            entry = b.entry;
        }
        b
    };
    let mut best: Option<([f64; 3], f64)> = None;
    for i in 0..=10 {
        for j in 0..=12 {
            for k in 0..=12 {
                let p = [0.2 * i as f64, 3.0 + j as f64, (30.0 + 5.0 * k as f64).to_radians()];
                let t = cost(&p).time;
                if t.is_finite() && best.is_none_or(|(_, bt)| t < bt) {
                    best = Some((p, t));
                }
            }
        }
    }
    let Some((mut p, mut bt)) = best else {
        return Bound::nan();
    };
    let mut step = [0.1, 0.5, 2.5f64.to_radians()];
    for _ in 0..5 {
        let mut improved = true;
        while improved {
            improved = false;
            for k in 0..3 {
                for s in [-1.0, 1.0] {
                    let mut q = p;
                    q[k] += s * step[k];
                    let t = cost(&q).time;
                    if t.is_finite() && t < bt - 1e-9 {
                        p = q;
                        bt = t;
                        improved = true;
                    }
                }
            }
        }
        for s in &mut step {
            *s *= 0.5;
        }
    }
    let sw = Switches {
        t_cut: p[0].max(0.0),
        v_on: p[1],
        gamma_s: p[2],
    };
    let mut b = simulate(model, alpha_max, v_level, &sw, 7.0, &stop, 3.0);
    b.entry = entry;
    b
}

/// Time of the missions' profile (`flight_mission::Profile`, the controllers' reference) from
/// the start of T2 until γ stays within 5° of vertical (`gamma_only`) or, besides, V within
/// 1 m/s of V_V, to the end of the mission; NaN if it never settles.
pub fn profile_time(mission: &MissionParams, limits: &ProfileLimits, gamma_only: bool) -> f64 {
    profile_time_within(mission, limits, gamma_only, GAMMA_TOL)
}

/// [`profile_time`] with the γ tolerance `gamma_tol` (rad).
pub fn profile_time_within(mission: &MissionParams, limits: &ProfileLimits, gamma_only: bool, gamma_tol: f64) -> f64 {
    let pm = PointMass::from_level_trim(&Airframe::default(), mission.v_level).expect("level trim");
    let Ok(p) = Profile::new(mission, &pm, limits) else {
        return f64::NAN;
    };
    let s = mission.phase_starts();
    let mut settled: Option<f64> = None;
    for q in p.points().iter().filter(|q| q.t >= s[3] && q.t <= s[5]) {
        let ok =
            (q.gamma - FRAC_PI_2).abs() <= gamma_tol && (gamma_only || (q.v - mission.v_vertical).abs() <= SPEED_TOL);
        if ok {
            settled.get_or_insert(q.t - s[3]);
        } else {
            settled = None;
        }
    }
    settled.unwrap_or(f64::NAN)
}

/// T2 values flown.
pub const T2_VALUES: [f64; 8] = [10.0, 6.0, 5.0, 4.0, 3.5, 3.0, 2.5, 2.0];
/// Largest position error to the controller's own reference for a tracked flight (m).
pub const POS_ERROR_LIMIT: f64 = 3.0;

/// One flown back transition.
#[derive(Debug, Clone, PartialEq)]
pub struct Flown {
    pub controller: &'static str,
    pub aero: &'static str,
    pub t2: f64,
    pub completed: bool,
    pub max_pos_error: f64,
    /// Largest |α| from the start of T2 to the end (deg).
    pub max_alpha_deg: f64,
    /// Flown time from the start of T2 until γ stays within 5° of vertical (rotation) and
    /// until, besides, V stays within 1 m/s of V_V (complete) (s); NaN if never.
    pub rotation: f64,
    pub complete: bool,
    pub transition: f64,
    /// The same two times of the controllers' profile (their reference).
    pub profile_rotation: f64,
    pub profile_transition: f64,
}

impl Flown {
    /// Tracked: completed, position error < 3 m, ends vertical and at V_V.
    pub fn tracked(&self) -> bool {
        self.completed && self.max_pos_error < POS_ERROR_LIMIT && self.transition.is_finite()
    }
}

/// The default mission with T2 = `t2`.
/// The profile's limits with the whole α range up to `alpha_max`, full thrust and no push-over
/// limit: the profile at its fastest (the flight-mission README's settings, with T2 = 0.5 s).
pub fn fastest_profile_limits(alpha_max: f64) -> ProfileLimits {
    ProfileLimits {
        alpha_max,
        thrust_fraction: 1.0,
        thrust_floor: 0.1,
        push_over_fraction: 1.0,
    }
}

pub fn mission(t2: f64) -> MissionParams {
    MissionParams {
        t_transition_2: t2,
        ..MissionParams::default()
    }
}

/// Fly `kind` (tuned default configuration) through the default mission with T2 = `t2` on
/// the plant with `model`.
pub fn fly_t2(kind: Kind, model: AeroModel, t2: f64) -> Result<Trace, String> {
    let m = mission(t2);
    let mut plant = Plant::new(Airframe::default());
    plant.aero.model = model;
    let x0 = plant
        .trim_vertical_climb(m.v_vertical)
        .map_err(|e| e.to_string())?
        .state;
    let scenario = Scenario {
        ordering: Ordering::GaussSeidel,
        ..Scenario::mission(m)
    };
    Ok(match kind {
        Kind::Lqr => {
            let mut c = LqrController::new(Airframe::default(), m, LqrParams::default()).map_err(|e| e.0)?;
            fly(&plant, x0, &mut c, &scenario)
        }
        Kind::Tsd => {
            let mut c = TsdController::new(Airframe::default(), m, TsdParams::default()).map_err(|e| e.0)?;
            fly(&plant, x0, &mut c, &scenario)
        }
        Kind::Px4 => fly(&plant, x0, &mut Kind::Px4.make(&m), &scenario),
    })
}

/// Time from `t0` until the flown γ (and, unless `gamma_only`, V) stay in the tolerances.
fn flown_settle(trace: &Trace, t0: f64, t_end: f64, v_v: f64, gamma_only: bool) -> f64 {
    let mut settled: Option<f64> = None;
    for s in trace.window(t0, t_end + 1e-6) {
        let v = s.measurement.vel_ned;
        let gamma = (-v.z).atan2(v.x.hypot(v.y));
        let ok = (gamma - FRAC_PI_2).abs() <= GAMMA_TOL && (gamma_only || (v.norm() - v_v).abs() <= SPEED_TOL);
        if ok {
            settled.get_or_insert(s.t - t0);
        } else {
            settled = None;
        }
    }
    settled.unwrap_or(f64::NAN)
}

/// Fly and measure one (controller, plant model, T2).
pub fn flown(kind: Kind, model: AeroModel, t2: f64) -> Flown {
    let m = mission(t2);
    let s = m.phase_starts();
    let limits = ProfileLimits::of(&m);
    let mut r = Flown {
        controller: kind.name(),
        aero: match model {
            AeroModel::Thesis => "thesis",
            AeroModel::Global => "global",
        },
        t2,
        completed: false,
        max_pos_error: f64::NAN,
        max_alpha_deg: f64::NAN,
        rotation: f64::NAN,
        complete: false,
        transition: f64::NAN,
        profile_rotation: profile_time(&m, &limits, true),
        profile_transition: profile_time(&m, &limits, false),
    };
    if let Ok(trace) = fly_t2(kind, model, t2) {
        r.completed = trace.completed();
        r.max_pos_error = trace.max_pos_error();
        r.max_alpha_deg = trace
            .window(s[3], s[5])
            .map(|x| x.measurement.alpha.abs())
            .fold(0.0, f64::max)
            .to_degrees();
        let end = trace.samples.last().map_or(s[5], |x| x.t);
        r.rotation = flown_settle(&trace, s[3], end, m.v_vertical, true);
        r.transition = flown_settle(&trace, s[3], end, m.v_vertical, false);
        r.complete = r.transition.is_finite();
    }
    r
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Trimmed lift slopes from Tables C.3/C.4: elevator only ≈ 3.08 /rad at small α (the
    /// profile's C_Lα from the level trim is 3.1), flap mixing ≈ 4.34 /rad (the mixed actuator lifts down, C_Lδm = −0.11 at α = 0, and
    /// trims nose-up: its trim lift adds to the wing's).
    #[test]
    fn trimmed_lift_slopes() {
        let e = Model::new(TrimLaw::ElevatorOnly, 0.0);
        let f = Model::new(TrimLaw::FlapMixing, 0.0);
        let a = 2f64.to_radians();
        assert!((e.trimmed_cl(a) / a - 3.08).abs() < 0.05, "{}", e.trimmed_cl(a) / a);
        assert!((f.trimmed_cl(a) / a - 4.34).abs() < 0.05, "{}", f.trimmed_cl(a) / a);
        // The level trim of the elevator-only model is the plant's (α = 7.405°).
        let (alpha, _) = e.level_trim(25.0);
        assert!((alpha.to_degrees() - 7.405).abs() < 0.05, "{}", alpha.to_degrees());
    }

    /// The rotation bound at α_max = 15° with flap mixing (α commanded directly), and the
    /// bound lies below the profile's own rotation time for the same case.
    #[test]
    fn rotation_bound_at_15_deg_with_flap_mixing() {
        let model = Model::new(TrimLaw::FlapMixing, 0.0);
        let b = rotation_bound(&model, 15f64.to_radians(), 25.0);
        assert!((b.time - EXPECTED_ROTATION_15_FLAP).abs() < 0.02, "{b:?}");
        assert!(b.switches.t_cut.is_infinite(), "full thrust throughout: {b:?}");
        // The profile of the controllers (elevator-only lift slope, lagged α) with T2 = 0.5 s
        // and the whole α range: its rotation to within 5° of vertical.
        let m = mission(0.5);
        let limits = fastest_profile_limits(15f64.to_radians());
        let profile = profile_time(&m, &limits, true);
        assert!(b.time < profile, "bound {} vs profile {profile}", b.time);
        // Elevator-only with the lag is slower than flap mixing commanded directly.
        let slow = rotation_bound(&Model::new(TrimLaw::ElevatorOnly, ALPHA_LAG), 15f64.to_radians(), 25.0);
        assert!(slow.time > b.time, "{slow:?}");
        assert!(slow.time < profile, "bound {} vs profile {profile}", slow.time);
    }

    const EXPECTED_ROTATION_15_FLAP: f64 = 1.284;

    /// The complete back transition (to the steady 3 m/s climb) at α_max = 15° with the
    /// profile's own lift model (elevator-only trim, α lag 0.12 s): ≈ 3.59 s, with the thrust
    /// cut after ≈ 0.6 s; longer than the rotation, shorter than the profile's 4.96 s.
    #[test]
    fn complete_bound_at_15_deg_elevator_only_is_below_the_profile() {
        let a = 15f64.to_radians();
        let model = Model::new(TrimLaw::ElevatorOnly, ALPHA_LAG);
        let c = complete_bound(&model, a, 25.0);
        assert!((c.time - 3.59).abs() < 0.05, "{c:?}");
        assert!(c.holds && !c.saturated, "{c:?}");
        assert!(c.entry <= c.time, "{c:?}");
        assert!((c.switches.t_cut - 0.62).abs() < 0.1, "{c:?}");
        let r = rotation_bound(&model, a, 25.0);
        assert!(c.time > r.time + 1.0, "{c:?} vs {r:?}");
        let limits = fastest_profile_limits(a);
        let profile = profile_time(&mission(0.5), &limits, false);
        assert!(c.time < profile, "bound {} vs profile {profile}", c.time);
    }

    /// `cargo test -p analysis transition_bound_table -- --ignored --nocapture`.
    #[test]
    #[ignore]
    fn transition_bound_table() {
        for trim in TrimLaw::ALL {
            let m = Model::new(trim, 0.0);
            println!(
                "{}: C_Lt(α)/α at 2°: {:.3}",
                trim.name(),
                m.trimmed_cl(2f64.to_radians()) / 2f64.to_radians()
            );
            for deg in [12.0f64, 15.0] {
                let a = deg.to_radians();
                let mm = Model { rate_terms: false, ..m };
                let (_, t_trim) = m.level_trim(25.0);
                for thrust in [0.0, t_trim, m.airframe.thrust_max] {
                    let f = mm.trimmed(25.0, a, thrust, 0.0);
                    let w = m.airframe.mass * m.airframe.gravity;
                    println!(
                        "  α {deg}° T {thrust:.1}: C_Lt {:.3} n_aero {:.2} n_total {:.2} δe {:.1}° δfc {:.1}° sat {}",
                        mm.trimmed_cl(a),
                        f.lift / w,
                        (f.lift + thrust * a.sin()) / w,
                        f.delta_e.to_degrees(),
                        f.delta_fc.to_degrees(),
                        f.saturated
                    );
                }
            }
        }
        // The profile's own times with the README's settings (T2 = 0.5 s, T_max, the whole α range).
        for deg in [12.0f64, 15.0] {
            let limits = fastest_profile_limits(deg.to_radians());
            let m = mission(0.5);
            println!(
                "profile T2 0.5 α {deg}: γ within 2°: {:.2} s, 5°: {:.2} s; complete (5°, 1 m/s): {:.2} s",
                profile_time_within(&m, &limits, true, 2f64.to_radians()),
                profile_time(&m, &limits, true),
                profile_time(&m, &limits, false)
            );
        }
        for (aero, rates) in [(AeroModel::Thesis, false), (AeroModel::Global, true)] {
            for trim in TrimLaw::ALL {
                for deg in [12.0f64, 15.0] {
                    let m = Model {
                        aero,
                        rate_terms: rates,
                        ..Model::new(trim, 0.0)
                    };
                    let r = rotation_bound(&m, deg.to_radians(), 25.0);
                    let c = if aero == AeroModel::Global {
                        complete_bound(&m, deg.to_radians(), 25.0)
                    } else {
                        Bound::nan()
                    };
                    println!(
                        "{aero:?} rates {rates} {:<13} α {deg}: rotation {:.3} s n {:.2}/{:.2} sat {} | complete {:.3} s entry {:.3} n {:.2}/{:.2} holds {} sat {} {:?}",
                        trim.name(), r.time, r.peak_n, r.peak_n_total, r.saturated, c.time, c.entry, c.peak_n, c.peak_n_total, c.holds, c.saturated, c.switches
                    );
                }
            }
        }
        for trim in TrimLaw::ALL {
            for tau in [0.0, ALPHA_LAG] {
                for deg in [12.0f64, 15.0] {
                    let m = Model::new(trim, tau);
                    let r = rotation_bound(&m, deg.to_radians(), 25.0);
                    let c = complete_bound(&m, deg.to_radians(), 25.0);
                    println!(
                        "{:<13} τα {tau:.2} α {deg}: rotation {:.3} s (t_cut {:.1}) n {:.2}/{:.2} at {:.1} m/s flap {:.1}° sat {} | \
                         complete {:.3} s entry {:.3} s t_cut {:.2} v_on {:.2} γ_s {:.1}° n {:.2}/{:.2} at {:.1} m/s flap {:.1}° sat {} holds {}",
                        trim.name(), r.time, r.switches.t_cut, r.peak_n, r.peak_n_total, r.v_at_peak,
                        r.max_flap.to_degrees(), r.saturated, c.time, c.entry, c.switches.t_cut, c.switches.v_on,
                        c.switches.gamma_s.to_degrees(), c.peak_n, c.peak_n_total, c.v_at_peak,
                        c.max_flap.to_degrees(), c.saturated, c.holds
                    );
                }
            }
        }
    }

    /// `cargo test -p analysis flown_table -- --ignored --nocapture`.
    #[test]
    #[ignore]
    fn flown_table() {
        for model in [AeroModel::Thesis, AeroModel::Global] {
            for kind in Kind::THESIS {
                for t2 in T2_VALUES {
                    let r = flown(kind, model, t2);
                    println!("{r:?} tracked {}", r.tracked());
                }
            }
        }
    }
}
