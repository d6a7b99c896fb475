//! Trajectory generator (thesis §3.3): the reference state x_t and input u_t of the
//! mission vertical → level → vertical, precomputed once at construction into a table
//! (step [`TABLE_STEP`]) shared between clones, interpolated linearly in the sample path.
//!
//! Flight-path (wind-axis) pitch γ and airspeed V are the thesis's cosine blends, with the
//! `t` the printed (3.3.1–3.3.2) miss restored (τ = time in the transition):
//!
//! ```text
//! V₁(τ) = V_V + (V_L − V_V)/2 · [1 − cos(π τ/T₁)]              (3.3.1)
//! V₂(τ) = V_L + (V_V − V_L)/2 · [1 − cos(π τ/T₂)]              (3.3.2)
//! γ₁(τ) = (γ_V − γ_L)/2 · [1 + cos(π τ/T₁)] + γ_L              (3.3.5 without α)
//! γ₂(τ) = (γ_V − γ_L)/2 · [1 − cos(π τ/T₂)] + γ_L              (3.3.6 without α)
//! ```
//!
//! with γ_V = 90°, γ_L = 0. The body pitch is θ = γ + α (3.3.5–3.3.6), q = θ̇ (3.3.7–3.3.8),
//! N, h by integrating V cos γ, V sin γ (3.3.9–3.3.12; "θ − α" = γ there).
//!
//! α, T and δe come in two modes ([`TrajectoryMode`]):
//! * `Thesis`: α by (3.3.3–3.3.4) with α_L the level trim and α_max a parameter; T by
//!   (3.3.13–3.3.14); δe by the moment balance (3.3.15–3.3.17) including the slip-stream
//!   scaling ((V/(V + 2w))², w from (2.3.21)).
//! * `ForceBalance` (default): α, T and δe solved at every table point from the model for
//!   control itself so that V̇, γ̇ (i.e. α̇ = q − γ̇) and q̇ = θ̈ are those of the reference:
//!   the "mathematically calculated" trajectory of §3.3.1 option 1. It contains (3.3.13–3.3.17)
//!   as its small-angle, drag-only special case and coincides with the physics crate's trims
//!   in the vertical and level segments. The thesis names trajectory accuracy as the
//!   limiting factor of the LQR (§3.5.1); this removes the α guesswork of (3.3.3–3.3.4).
//!   Each point is solved (residual < 1e-10) by a quasi-Newton iteration started from the
//!   previous points' solutions extrapolated (two residuals per point on average,
//!   the whole table in ≈ 4.5 ms instead of 11 ms; test `fast_construction_equals_the_slow_reference`).
//!
//! Banked turn (3.3.18–3.3.21), level segment only, `turn_radius` ρ ≠ 0: heading rate
//! ω = V/ρ (3.3.19) ramped in and out with cosine blends over [`TURN_RAMP`] s, bank
//! φ = atan(V ω / g) (3.3.18 with ω = V/ρ), body rates from the exact 3-2-1 kinematics
//! (which reduce to q = ω sin φ, r = ω cos φ (3.3.20–3.3.21) at θ = 0).
//! Thrust command leads the thrust state by the motor lag: T_c = T + τ_T Ṫ (2.3.16).

use std::sync::Arc;

use flight_mission::{MissionParams, Phase};
use guidance::{HeadingRef, PointMass, Profile, ProfileLimits};
use nalgebra::{Matrix3, Vector3, Vector4};
use tailsitter_physics::{quat_from_euler_321, Airframe, Surfaces};

#[cfg(test)]
use crate::model::derivatives;
#[cfg(test)]
use crate::model::ix;
use crate::model::{EulerRep, U, X};

/// Table step (s).
pub const TABLE_STEP: f64 = 0.01;
/// Ramp time of the turn rate at the start and the end of the level segment (s).
pub const TURN_RAMP: f64 = 2.0;
const FRAC_PI_2: f64 = core::f64::consts::FRAC_PI_2;
const PI: f64 = core::f64::consts::PI;

/// How α, T and δe of the reference are found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TrajectoryMode {
    /// The thesis's closed forms (3.3.3–3.3.4), (3.3.13–3.3.14), (3.3.17).
    Thesis = 0,
    /// Solved from the model for control (default).
    ForceBalance = 1,
}

/// Options of the trajectory generator.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrajectoryOptions {
    pub mode: TrajectoryMode,
    /// α_max of (3.3.4) (rad) (Thesis mode only).
    pub alpha_max: f64,
    /// Turn radius ρ (m) of the level segment (3.3.18–3.3.21); 0 = straight, < 0 left.
    pub turn_radius: f64,
    /// V and γ of the α- and thrust-limited point-mass profile
    /// ([`guidance::profile`]) instead of the thesis's cosine blends.
    pub limited_path: bool,
    /// Thrust command T_c = T + τ_T Ṫ leading the lagged thrust state (2.3.16); off: T_c = T,
    /// the printed (3.3.13–3.3.14) (docs/THESIS.md D-3.15).
    pub thrust_lead: bool,
}

impl Default for TrajectoryOptions {
    /// The options of the default [`crate::LqrParams`] (`trajectory_mode` 1, `configuration` 0).
    fn default() -> Self {
        let p = crate::LqrParams::default();
        Self {
            mode: TrajectoryMode::ForceBalance,
            alpha_max: p.alpha_max,
            turn_radius: p.turn_radius,
            limited_path: true,
            thrust_lead: true,
        }
    }
}

/// One reference point: state x_t and input u_t (positions relative to the start).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrajPoint {
    /// Mission time (s).
    pub t: f64,
    /// Airspeed V (m/s).
    pub v: f64,
    /// α (rad).
    pub alpha: f64,
    /// Flight-path angle γ (wind-axis pitch) (rad).
    pub gamma: f64,
    /// 3-2-1 Euler angles φ, θ, ψ (rad) (ψ not wrapped).
    pub euler_321: Vector3<f64>,
    /// Body rates p, q, r (rad/s).
    pub rates: Vector3<f64>,
    /// North, east, height relative to the start (m).
    pub pos_neh: Vector3<f64>,
    /// Thrust state T (N).
    pub thrust: f64,
    /// Reference inputs u_t = [T_c δe δa δr δfc δfd δv].
    pub u: U,
}

impl TrajPoint {
    fn lerp(&self, o: &TrajPoint, s: f64) -> TrajPoint {
        let l = |a: f64, b: f64| a + (b - a) * s;
        TrajPoint {
            t: l(self.t, o.t),
            v: l(self.v, o.v),
            alpha: l(self.alpha, o.alpha),
            gamma: l(self.gamma, o.gamma),
            euler_321: self.euler_321.lerp(&o.euler_321, s),
            rates: self.rates.lerp(&o.rates, s),
            pos_neh: self.pos_neh.lerp(&o.pos_neh, s),
            thrust: l(self.thrust, o.thrust),
            u: self.u.lerp(&o.u, s),
        }
    }

    /// The reference turned about the earth's down axis by the weathervane's heading ψ_w
    /// (3-2-1 heading + ψ_w: `DCM^BE · rot_z(ψ_w)`), its rate added to the body rates as
    /// `DCM^BE (0, 0, ψ̇_w)`; positions, air data and inputs unchanged. Zero heading and
    /// rate: `self` unchanged.
    pub fn turned(mut self, h: &HeadingRef) -> TrajPoint {
        if h.heading == 0.0 && h.rate == 0.0 {
            return self;
        }
        self.euler_321.z += h.heading;
        let c = EulerRep::E321.dcm(&self.euler_321);
        self.rates += c * Vector3::new(0.0, 0.0, h.rate);
        self
    }

    /// Attitude quaternion (A.2.8) of the reference.
    pub fn quat(&self) -> Vector4<f64> {
        quat_from_euler_321(self.euler_321.x, self.euler_321.y, self.euler_321.z)
    }

    /// The reference as a model state in sequence `rep` (positions relative to the start).
    pub fn state(&self, rep: EulerRep) -> X {
        let a = rep.angles(&self.quat());
        X::from_column_slice(&[
            self.v,
            self.alpha,
            0.0,
            self.rates.x,
            self.rates.y,
            self.rates.z,
            a.x,
            a.y,
            a.z,
            self.pos_neh.x,
            self.pos_neh.y,
            self.pos_neh.z,
            self.thrust,
        ])
    }
}

/// The precomputed reference trajectory.
#[derive(Debug, Clone)]
pub struct Trajectory {
    /// The table, shared by clones (an `Arc<Vec>`: taking over the built vector copies
    /// nothing, where `Arc<[T]>::from(Vec)` would copy the ≈ 0.6 MB table once more).
    points: Arc<Vec<TrajPoint>>,
    mission: MissionParams,
}

/// Kinematic reference of the flight path at τ: (V, V̇, γ, γ̇, γ̈), from the limited
/// profile if given, else the thesis's cosine blends.
fn path(m: &MissionParams, profile: Option<&Profile>, t: f64) -> (Phase, [f64; 5]) {
    if let Some(p) = profile {
        let q = p.at(t);
        return (m.phase_at(t).0, [q.v, q.v_dot, q.gamma, q.gamma_dot, q.gamma_ddot]);
    }
    let (phase, tau) = m.phase_at(t);
    let dv = m.v_level - m.v_vertical;
    let r = match phase {
        Phase::Vertical1 | Phase::Vertical2 => [m.v_vertical, 0.0, FRAC_PI_2, 0.0, 0.0],
        // Take-off and landing: flown from guidance::ground, never a mission time.
        Phase::OnGround | Phase::TakeOff | Phase::Approach | Phase::Descent | Phase::Flare | Phase::Landed => {
            [m.v_vertical, 0.0, FRAC_PI_2, 0.0, 0.0]
        }
        Phase::Level => [m.v_level, 0.0, 0.0, 0.0, 0.0],
        Phase::TransitionToLevel => {
            let w = PI / m.t_transition_1;
            let (s, c) = (w * tau).sin_cos();
            let g = FRAC_PI_2 / 2.0;
            [
                m.v_vertical + dv / 2.0 * (1.0 - c),
                dv / 2.0 * w * s,
                g * (1.0 + c),
                -g * w * s,
                -g * w * w * c,
            ]
        }
        Phase::TransitionToVertical => {
            let w = PI / m.t_transition_2;
            let (s, c) = (w * tau).sin_cos();
            let g = FRAC_PI_2 / 2.0;
            [
                m.v_level - dv / 2.0 * (1.0 - c),
                -dv / 2.0 * w * s,
                g * (1.0 - c),
                g * w * s,
                g * w * w * c,
            ]
        }
    };
    (phase, r)
}

/// Thesis α (3.3.3–3.3.4).
fn alpha_thesis(m: &MissionParams, t: f64, alpha_level: f64, alpha_max: f64) -> f64 {
    let (phase, tau) = m.phase_at(t);
    match phase {
        Phase::Vertical1 | Phase::Vertical2 => 0.0,
        Phase::OnGround | Phase::TakeOff | Phase::Approach | Phase::Descent | Phase::Flare | Phase::Landed => 0.0,
        Phase::Level => alpha_level,
        Phase::TransitionToLevel => alpha_level * (tau / m.t_transition_1 * FRAC_PI_2).sin(),
        Phase::TransitionToVertical => {
            let t2 = m.t_transition_2;
            if tau < t2 / 3.0 {
                alpha_level + (alpha_max - alpha_level) / 2.0 * (1.0 - (tau / (t2 / 3.0) * PI).cos())
            } else {
                alpha_max / 2.0 * (1.0 + (tau / (2.0 * t2 / 3.0) * PI - FRAC_PI_2).cos())
            }
        }
    }
}

/// Turn: heading rate and its derivative at t (level segment only).
fn turn_rate(m: &MissionParams, t: f64, radius: f64) -> (f64, f64) {
    if radius == 0.0 || !radius.is_finite() {
        return (0.0, 0.0);
    }
    let (phase, tau) = m.phase_at(t);
    if phase != Phase::Level {
        return (0.0, 0.0);
    }
    let w = m.v_level / radius; // (3.3.19)
    let ramp = TURN_RAMP.min(0.5 * m.t_level).max(1e-6);
    let k = PI / ramp;
    if tau < ramp {
        let (s, c) = (k * tau).sin_cos();
        (w * 0.5 * (1.0 - c), w * 0.5 * k * s)
    } else if tau > m.t_level - ramp {
        let x = m.t_level - tau;
        let (s, c) = (k * x).sin_cos();
        (w * 0.5 * (1.0 - c), -w * 0.5 * k * s)
    } else {
        (w, 0.0)
    }
}

/// The model state and input of a longitudinal point for the force-balance solve (the
/// slow reference of the tests).
#[cfg(test)]
#[allow(clippy::too_many_arguments)]
fn point_state(
    v: f64,
    alpha: f64,
    gamma: f64,
    phi: f64,
    psi: f64,
    rates: &Vector3<f64>,
    thrust: f64,
    de: f64,
) -> (X, U) {
    let mut x = X::zeros();
    x[ix::V] = v;
    x[ix::ALPHA] = alpha;
    x[ix::P] = rates.x;
    x[ix::Q] = rates.y;
    x[ix::R] = rates.z;
    x[ix::PHI] = phi;
    x[ix::THETA] = gamma + alpha;
    x[ix::PSI] = psi;
    x[ix::T] = thrust;
    let mut u = U::zeros();
    u[0] = thrust;
    u[1] = de;
    (x, u)
}

/// The force balance of one reference point (`ForceBalance` mode): the residual
/// (V̇, α̇, q̇) − target of the model for control ([`crate::model::derivatives`], E321, β = 0,
/// p, q, r from the 3-2-1 kinematics of the path) as a function of z = (α, T, δe), only the
/// three rows it needs, the induced velocity warm-started from the previous residual's.
struct Balance<'a> {
    af: &'a Airframe,
    /// V (m/s).
    v: f64,
    /// sin γ, cos γ of the path.
    sincos_gamma: (f64, f64),
    /// sin φ, cos φ of the bank.
    sincos_phi: (f64, f64),
    /// θ̇ (rad/s).
    theta_dot: f64,
    /// Heading rate ψ̇ (rad/s).
    turn_rate: f64,
    /// φ̇ (rad/s).
    phi_dot: f64,
    /// Target (V̇, α̇, q̇) (m/s², rad/s, rad/s²).
    target: Vector3<f64>,
}

impl Balance<'_> {
    /// Body rates (3-2-1: p = φ̇ − ψ̇ sθ, q = θ̇ cφ + ψ̇ sφ cθ, r = −θ̇ sφ + ψ̇ cφ cθ) and
    /// (sin θ, cos θ) at θ = γ + α, given (sin α, cos α) (angle addition: one sine and
    /// cosine per residual instead of two).
    #[inline]
    fn rates(&self, (sa, ca): (f64, f64)) -> (Vector3<f64>, f64, f64) {
        let (sf, cf) = self.sincos_phi;
        let (sg, cg) = self.sincos_gamma;
        let (st, ct) = (sg * ca + cg * sa, cg * ca - sg * sa);
        let (w, td) = (self.turn_rate, self.theta_dot);
        (
            Vector3::new(self.phi_dot - w * st, td * cf + w * sf * ct, -td * sf + w * cf * ct),
            st,
            ct,
        )
    }

    /// (V̇, α̇, q̇) − target at z = (α, T, δe); `w_start` is the induced velocity to start
    /// from (NaN: cold) and receives this one's.
    #[inline]
    fn residual(&self, z: &[f64; 3], w_start: &mut f64) -> Vector3<f64> {
        let af = self.af;
        let (alpha, thrust) = (z[0], z[1]);
        let (sa, ca) = alpha.sin_cos();
        let (w, st, ct) = self.rates((sa, ca));
        // body_velocity(V, α, β = 0) and DCM^BE (0, 0, g) = g (−sθ, sφ cθ, cφ cθ) (A.2.7).
        let vb = Vector3::new(self.v * ca, 0.0, self.v * sa);
        let surfaces = Surfaces {
            elevator: z[2],
            ..Surfaces::default()
        };
        let fm = af.forces_moments_from(&vb, &w, thrust, &surfaces, *w_start);
        *w_start = fm.induced_velocity;
        let (sf, cf) = self.sincos_phi;
        let g_body = Vector3::new(-st, sf * ct, cf * ct) * af.gravity;
        let a = fm.force_body / af.mass + g_body - w.cross(&vb);
        let vdot = vb.dot(&a) / self.v;
        let alpha_dot = (vb.x * a.z - vb.z * a.x) / (vb.x * vb.x + vb.z * vb.z);
        // q̇ = (M_y − (ω × Iω)_y) / I_yy, (ω × Iω)_y = r I_xx p − p I_zz r.
        let qdot = (fm.moment_body.y - (w.z * af.i_xx * w.x - w.x * af.i_zz * w.z)) / af.i_yy;
        Vector3::new(vdot, alpha_dot, qdot) - self.target
    }
}

/// One reference point's force balance (`ForceBalance` mode), as a [`BalanceSolver`] sees it.
struct PointProblem<'a> {
    /// The residual (V̇, α̇, q̇) − target of z = (α, T, δe).
    bal: Balance<'a>,
    /// Mission time (s) and table index.
    t: f64,
    i: usize,
    /// Pass (0: on the kinematic α; 1: on α̇, α̈ of pass 0).
    pass: usize,
    /// γ, φ, ψ of the point (rad) (read by the tests' slow reference only).
    #[cfg_attr(not(test), allow(dead_code))]
    gamma: f64,
    #[cfg_attr(not(test), allow(dead_code))]
    phi: f64,
    #[cfg_attr(not(test), allow(dead_code))]
    psi: f64,
    /// (α, T, δe) in the table before this pass's solve (read by the tests' slow reference
    /// only).
    #[cfg_attr(not(test), allow(dead_code))]
    table: [f64; 3],
}

/// A solver of the per-point force balance: the construction's [`QuasiNewton`] or the
/// tests' slow reference.
trait BalanceSolver {
    /// A pass over the `n` table points begins.
    fn start_pass(&mut self, pass: usize, n: usize);
    /// z = (α, T, δe) with residual < 1e-10, or why not.
    fn solve(&mut self, p: &PointProblem) -> Result<[f64; 3], String>;
}

/// Central-difference Jacobian of `f` at `z` (steps 1e-7 (1 + |z_j|)).
fn central_jacobian(z: &[f64; 3], f: impl Fn(&[f64; 3]) -> Vector3<f64>) -> Matrix3<f64> {
    let mut jac = Matrix3::zeros();
    for j in 0..3 {
        let h = 1e-7 * (1.0 + z[j].abs());
        let mut zp = *z;
        let mut zm = *z;
        zp[j] += h;
        zm[j] -= h;
        jac.set_column(j, &((f(&zp) - f(&zm)) / (2.0 * h)));
    }
    jac
}

/// The construction's solver: each point started from the previous points'
/// solutions extrapolated, one quasi-Newton (Broyden) iteration; the induced velocity of
/// the last residual warm-starts the next.
#[derive(Default)]
struct QuasiNewton {
    /// Solutions of this pass and of the previous one.
    z_hist: Vec<[f64; 3]>,
    z_prev_pass: Vec<[f64; 3]>,
    /// Induced velocity of the last residual (m/s) (NaN: cold).
    w_start: f64,
    /// Inverse Jacobian kept between points.
    chord: Option<Matrix3<f64>>,
}

impl QuasiNewton {
    /// Predictor of point `i` in pass `pass` (`weight`: m g, the first point's thrust):
    /// pass 0 extrapolates the previous points' solutions (quartic), later passes add the
    /// correction of the previous points over their previous-pass solutions, extrapolated
    /// (cubic), to this point's previous-pass solution. From there one quasi-Newton step
    /// usually meets the tolerance.
    fn predict(&self, i: usize, pass: usize, weight: f64) -> [f64; 3] {
        if pass == 0 {
            match i {
                0 => [0.0, weight, 0.0],
                1..=4 => self.z_hist[i - 1],
                _ => core::array::from_fn(|k| {
                    5.0 * (self.z_hist[i - 1][k] - self.z_hist[i - 4][k])
                        - 10.0 * (self.z_hist[i - 2][k] - self.z_hist[i - 3][k])
                        + self.z_hist[i - 5][k]
                }),
            }
        } else {
            let d = |j: usize, k: usize| self.z_hist[j][k] - self.z_prev_pass[j][k];
            let base = self.z_prev_pass[i];
            match i {
                0 => base,
                1..=3 => core::array::from_fn(|k| base[k] + d(i - 1, k)),
                _ => core::array::from_fn(|k| {
                    base[k] + 4.0 * (d(i - 1, k) + d(i - 3, k)) - 6.0 * d(i - 2, k) - d(i - 4, k)
                }),
            }
        }
    }
}

impl BalanceSolver for QuasiNewton {
    fn start_pass(&mut self, pass: usize, n: usize) {
        if pass == 0 {
            self.z_hist = vec![[0.0; 3]; n];
            self.z_prev_pass = vec![[0.0; 3]; n];
            self.w_start = f64::NAN;
        } else {
            self.z_prev_pass.copy_from_slice(&self.z_hist);
        }
        self.chord = None;
    }

    fn solve(&mut self, p: &PointProblem) -> Result<[f64; 3], String> {
        let (bal, t, i, pass) = (&p.bal, p.t, p.i, p.pass);
        let mut z = self.predict(i, pass, bal.af.mass * bal.af.gravity);
        let mut ok = false;
        let mut r_last = f64::INFINITY;
        // The last step and its residual (Broyden update of the Jacobian).
        let mut last: Option<(Vector3<f64>, Vector3<f64>)> = None;
        for _ in 0..50 {
            let r = bal.residual(&z, &mut self.w_start);
            if r.amax() < 1e-10 {
                ok = true;
                break;
            }
            // Quasi-Newton: the inverse Jacobian of an earlier point or iterate,
            // corrected along every step by Broyden's rank-one update, is kept
            // while it still reduces the residual tenfold per step, and refreshed
            // by central differences otherwise.
            if r.amax() > 0.1 * r_last {
                self.chord = None;
            } else if let (Some(b), Some((dz, r_prev))) = (self.chord.as_mut(), last) {
                // Broyden's update J += (Δr − J Δz) Δzᵀ / ΔzᵀΔz applied to
                // B = J⁻¹ by Sherman–Morrison:
                // B += (Δz − B Δr) Δzᵀ B / (Δzᵀ B Δr).
                let dr = r - r_prev;
                let bdr = *b * dr;
                let den = dz.dot(&bdr);
                if den.abs() > 1e-12 * dz.norm() * bdr.norm() {
                    *b += (dz - bdr) * (dz.transpose() * *b) / den;
                }
            }
            r_last = r.amax();
            let binv = match self.chord {
                Some(b) => b,
                None => {
                    let w_start = self.w_start;
                    let b = central_jacobian(&z, |zz| bal.residual(zz, &mut { w_start }))
                        .try_inverse()
                        .ok_or_else(|| format!("singular trajectory solve at t = {t}"))?;
                    self.chord = Some(b);
                    b
                }
            };
            let dz = binv * r;
            let scale = (0.1 / dz[0].abs().max(dz[2].abs()).max(1e-300)).min(1.0);
            for k in 0..3 {
                z[k] -= scale * dz[k];
            }
            last = Some((-scale * dz, r));
        }
        if !ok {
            let mut cold = f64::NAN;
            let r = bal.residual(&z, &mut cold);
            return Err(format!(
                "trajectory force balance did not converge at t = {t:.2} s (pass {pass}, z = {z:?}, residual {r:?})"
            ));
        }
        self.z_hist[i] = z;
        Ok(z)
    }
}

/// The reference path of a mission: the flight-path blends (3.3.1–3.3.6, or the limited
/// profile) and the banked turn (3.3.18–3.3.21).
struct RefPath<'a> {
    mission: &'a MissionParams,
    profile: Option<&'a Profile>,
    opt: &'a TrajectoryOptions,
}

/// The kinematics of one table point (§3.3): path speed and angles, bank (3.3.18), heading
/// and the rates the body follows.
struct PointKinematics {
    t: f64,
    /// V, V̇ (m/s, m/s²).
    v: f64,
    vdot: f64,
    /// Flight-path angle γ (rad).
    gamma: f64,
    /// Bank φ (3.3.18) and heading ψ (rad).
    phi: f64,
    psi: f64,
    /// α̇ of the previous pass (rad/s); θ̇ = γ̇ + α̇, θ̈ = γ̈ + α̈ (3.3.7–3.3.8).
    alpha_dot: f64,
    theta_dot: f64,
    theta_ddot: f64,
    /// φ̇ (rad/s) and the turn rate ψ̇ (rad/s).
    phi_dot: f64,
    turn_rate: f64,
}

impl RefPath<'_> {
    /// Pass 0: the kinematic path, heading (the turn rate integrated by the trapezoidal
    /// rule) and zero bank, α by (3.3.3–3.3.4) in the thesis mode (0 for the force balance).
    /// The points and their α.
    fn kinematic_pass(&self, n: usize, alpha_level: f64) -> (Vec<TrajPoint>, Vec<f64>) {
        let (mission, opt) = (self.mission, self.opt);
        let mut pts: Vec<TrajPoint> = Vec::with_capacity(n);
        let mut psi = 0.0;
        let mut alphas = Vec::with_capacity(n);
        for i in 0..n {
            let t = i as f64 * TABLE_STEP;
            let (_, [v, _, gamma, _, _]) = path(mission, self.profile, t);
            if i > 0 {
                let (w0, _) = turn_rate(mission, t - TABLE_STEP, opt.turn_radius);
                let (w1, _) = turn_rate(mission, t, opt.turn_radius);
                psi += 0.5 * (w0 + w1) * TABLE_STEP;
            }
            let alpha = match opt.mode {
                TrajectoryMode::Thesis => alpha_thesis(mission, t, alpha_level, opt.alpha_max),
                TrajectoryMode::ForceBalance => 0.0,
            };
            alphas.push(alpha);
            pts.push(TrajPoint {
                t,
                v,
                alpha,
                gamma,
                euler_321: Vector3::new(0.0, gamma + alpha, psi),
                rates: Vector3::zeros(),
                pos_neh: Vector3::zeros(),
                thrust: 0.0,
                u: U::zeros(),
            });
        }
        (pts, alphas)
    }

    /// The kinematics of table point `p` with the pass's α̇, α̈ (`g`: gravity).
    fn point(&self, g: f64, p: &TrajPoint, alpha_dot: f64, alpha_ddot: f64) -> PointKinematics {
        let t = p.t;
        let (_, [v, vdot, gamma, gdot, gddot]) = path(self.mission, self.profile, t);
        let (w, wdot) = turn_rate(self.mission, t, self.opt.turn_radius);
        let phi = (v * w / g).atan(); // (3.3.18)
                                      // φ̇ from the derivative of atan(V ω / g).
        let k = v * w / g;
        PointKinematics {
            t,
            v,
            vdot,
            gamma,
            phi,
            psi: p.euler_321.z,
            alpha_dot,
            theta_dot: gdot + alpha_dot,
            theta_ddot: gddot + alpha_ddot,
            phi_dot: (vdot * w + v * wdot) / g / (1.0 + k * k),
            turn_rate: w,
        }
    }
}

impl PointKinematics {
    /// Body rates at θ = γ + α, 3-2-1: p = φ̇ − ψ̇ sθ, q = θ̇ cφ + ψ̇ sφ cθ,
    /// r = −θ̇ sφ + ψ̇ cφ cθ.
    fn rates(&self, alpha: f64) -> Vector3<f64> {
        let th = self.gamma + alpha;
        let (sf, cf) = self.phi.sin_cos();
        let (st, ct) = th.sin_cos();
        let (w, theta_dot) = (self.turn_rate, self.theta_dot);
        Vector3::new(
            self.phi_dot - w * st,
            theta_dot * cf + w * sf * ct,
            -theta_dot * sf + w * cf * ct,
        )
    }

    /// The force balance of this point (`ForceBalance` mode) in pass `pass`, `table` its
    /// (α, T, δe) before the solve.
    fn problem<'a>(&self, af: &'a Airframe, i: usize, pass: usize, table: [f64; 3]) -> PointProblem<'a> {
        PointProblem {
            bal: Balance {
                af,
                v: self.v,
                sincos_gamma: self.gamma.sin_cos(),
                sincos_phi: self.phi.sin_cos(),
                theta_dot: self.theta_dot,
                turn_rate: self.turn_rate,
                phi_dot: self.phi_dot,
                target: Vector3::new(self.vdot, self.alpha_dot, self.theta_ddot),
            },
            t: self.t,
            i,
            pass,
            gamma: self.gamma,
            phi: self.phi,
            psi: self.psi,
            table,
        }
    }
}

/// `Thesis` mode: the rates of the kinematic α, T by (3.3.13–3.3.14) and δe by the moment
/// balance (3.3.15–3.3.17) with the slip-stream scaling, written into `p`.
fn thesis_point(af: &Airframe, k: &PointKinematics, alpha: f64, p: &mut TrajPoint) {
    let (v, g) = (k.v, af.gravity);
    let rates = k.rates(alpha);
    // (3.3.13–3.3.14).
    let thrust = af.mass * k.vdot + af.mass * g * k.gamma.sin() + 0.5 * af.air_density * v * v * af.wing_area * af.c_D0;
    // (3.3.15–3.3.17) with the slip-stream scaling.
    let c = af.coefficients(alpha);
    let wi = af.induced_velocity(v, v * alpha.cos(), thrust);
    let qbar = 0.5 * af.air_density * v * v * af.wing_area * af.mean_chord;
    let de =
        (af.i_yy * k.theta_ddot / qbar - af.c_m0 - c.c_m_alpha * alpha - af.mean_chord / (2.0 * v) * c.c_m_q * rates.y)
            / c.c_m_de
            * (v / (v + 2.0 * wi)).powi(2);
    p.rates = rates;
    p.thrust = thrust;
    p.u[1] = de;
    p.euler_321 = Vector3::new(k.phi, k.gamma + alpha, k.psi);
}

/// Positions by integrating the path velocity (3.3.9–3.3.12, trapezoidal rule) and the
/// thrust command, with `thrust_lead` leading the state by the lag, T_c = T + τ_T Ṫ (2.3.16),
/// else T_c = T (3.3.13–3.3.14), clamped to the thrust range; in the `Thesis` mode α back to
/// the kinematic `alphas`.
fn positions_and_commands(af: &Airframe, opt: &TrajectoryOptions, pts: &mut [TrajPoint], alphas: &[f64]) {
    let mode = opt.mode;
    let lead = if opt.thrust_lead { af.tau_thrust } else { 0.0 };
    let thrusts: Vec<f64> = pts.iter().map(|p| p.thrust).collect();
    let tdot = derivative(&thrusts);
    let mut pos = Vector3::zeros();
    for i in 0..pts.len() {
        if i > 0 {
            let vel = |p: &TrajPoint| {
                let (sg, cg) = p.gamma.sin_cos();
                let (sp, cp) = p.euler_321.z.sin_cos();
                Vector3::new(p.v * cg * cp, p.v * cg * sp, p.v * sg)
            };
            pos += 0.5 * (vel(&pts[i - 1]) + vel(&pts[i])) * TABLE_STEP;
        }
        let p = &mut pts[i];
        p.pos_neh = pos;
        p.u[0] = (p.thrust + lead * tdot[i]).clamp(af.thrust_min, af.thrust_max);
        if mode == TrajectoryMode::Thesis {
            p.alpha = alphas[i];
        }
    }
}

impl Trajectory {
    /// Build the table for `mission` with the controller's airframe `af`.
    pub fn new(af: &Airframe, mission: &MissionParams, opt: &TrajectoryOptions) -> Result<Self, String> {
        Self::build(af, mission, opt, &mut QuasiNewton::default())
    }

    /// Build the table, each `ForceBalance` point solved by `solver`: the kinematic path
    /// ([`kinematic_pass`]), then per pass the body rates, α, T and δe of every point (twice
    /// for the force balance: the second pass uses α̇, α̈ of the first), then the positions
    /// and thrust commands ([`positions_and_commands`]).
    fn build(
        af: &Airframe,
        mission: &MissionParams,
        opt: &TrajectoryOptions,
        solver: &mut dyn BalanceSolver,
    ) -> Result<Self, String> {
        mission.validate().map_err(|e| e.0)?;
        let end = mission.end_time() + 1.0;
        let n = (end / TABLE_STEP).ceil() as usize + 2;
        // Level trim α for the thesis mode (and the solve's initial guesses).
        let level = tailsitter_physics::Plant::new(*af)
            .trim_level(mission.v_level)
            .map_err(|e| format!("level trim at v_level = {} failed: {e}", mission.v_level))?;
        let profile = if opt.limited_path {
            let pm = PointMass::from_level_trim(af, mission.v_level).map_err(|e| e.0)?;
            Some(Profile::new(mission, &pm, &ProfileLimits::of(mission)).map_err(|e| e.0)?)
        } else {
            None
        };
        let path = RefPath {
            mission,
            profile: profile.as_ref(),
            opt,
        };
        let (mut pts, mut alphas) = path.kinematic_pass(n, level.alpha);
        let passes = if opt.mode == TrajectoryMode::ForceBalance { 2 } else { 1 };
        for pass in 0..passes {
            solver.start_pass(pass, n);
            // α̇ has kinks where γ̈ of the cosine blends steps (phase boundaries); a
            // 0.2 s moving average keeps α̈ (→ q̇ → δe) free of finite-difference spikes.
            let alpha_dot = smooth(&derivative(&alphas), 10);
            let alpha_ddot = smooth(&derivative(&alpha_dot), 10);
            for i in 0..n {
                let k = path.point(af.gravity, &pts[i], alpha_dot[i], alpha_ddot[i]);
                match opt.mode {
                    TrajectoryMode::Thesis => thesis_point(af, &k, alphas[i], &mut pts[i]),
                    TrajectoryMode::ForceBalance => {
                        let table = [alphas[i], pts[i].thrust, pts[i].u[1]];
                        let z = solver.solve(&k.problem(af, i, pass, table))?;
                        alphas[i] = z[0];
                        let p = &mut pts[i];
                        p.alpha = z[0];
                        p.rates = k.rates(z[0]);
                        p.thrust = z[1];
                        p.u[1] = z[2];
                        p.euler_321 = Vector3::new(k.phi, k.gamma + z[0], k.psi);
                    }
                }
            }
        }
        positions_and_commands(af, opt, &mut pts, &alphas);
        if pts
            .iter()
            .any(|p| !(p.v.is_finite() && p.u.iter().all(|x| x.is_finite()) && p.pos_neh.iter().all(|x| x.is_finite())))
        {
            return Err("non-finite trajectory".into());
        }
        Ok(Self {
            points: Arc::new(pts),
            mission: *mission,
        })
    }

    /// The reference at mission time `t` (linear interpolation; beyond the table the
    /// last vertical climb continues at `v_vertical`). No allocation.
    pub fn at(&self, t: f64) -> TrajPoint {
        let n = self.points.len();
        let s = (t.max(0.0)) / TABLE_STEP;
        // Compare in floating point: a huge t must not overflow the index (fuzzing found it).
        if s + 1.0 >= n as f64 {
            let mut p = self.points[n - 1];
            let dt = t - p.t;
            let (sg, cg) = p.gamma.sin_cos();
            let (sp, cp) = p.euler_321.z.sin_cos();
            p.pos_neh += Vector3::new(cg * cp, cg * sp, sg) * p.v * dt;
            p.t = t;
            return p;
        }
        let i = s.floor() as usize;
        self.points[i].lerp(&self.points[i + 1], s - i as f64)
    }

    /// The mission the table was built for.
    pub fn mission(&self) -> &MissionParams {
        &self.mission
    }

    /// Every table point (for plots and tests).
    pub fn points(&self) -> &[TrajPoint] {
        &self.points
    }
}

/// Centred moving average over 2·`half` + 1 points (shrinking at the ends).
fn smooth(y: &[f64], half: usize) -> Vec<f64> {
    let n = y.len();
    (0..n)
        .map(|i| {
            let (a, b) = (i.saturating_sub(half), (i + half).min(n - 1));
            y[a..=b].iter().sum::<f64>() / (b - a + 1) as f64
        })
        .collect()
}

/// Central-difference derivative of a table sampled at [`TABLE_STEP`].
fn derivative(y: &[f64]) -> Vec<f64> {
    let n = y.len();
    (0..n)
        .map(|i| {
            let (a, b) = (i.saturating_sub(1), (i + 1).min(n - 1));
            if b > a {
                (y[b] - y[a]) / ((b - a) as f64 * TABLE_STEP)
            } else {
                0.0
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The plain force-balance solver: each point started from the previous point's solution, a chord iteration with
    /// central-difference Jacobians of the full model for control
    /// ([`crate::model::derivatives`]), cold induced-velocity solves. The slow reference
    /// the fast construction is compared against.
    struct SlowChord {
        z_prev: [f64; 3],
        chord: Option<nalgebra::LU<f64, nalgebra::U3, nalgebra::U3>>,
    }

    impl SlowChord {
        fn new(af: &Airframe) -> Self {
            Self {
                z_prev: [0.0, af.mass * af.gravity, 0.0],
                chord: None,
            }
        }
    }

    impl BalanceSolver for SlowChord {
        fn start_pass(&mut self, _pass: usize, _n: usize) {
            self.chord = None;
        }

        fn solve(&mut self, p: &PointProblem) -> Result<[f64; 3], String> {
            let (b, t, i, pass) = (&p.bal, p.t, p.i, p.pass);
            let af = b.af;
            let rates_of = |alpha: f64| {
                let th = p.gamma + alpha;
                let (sf, cf) = p.phi.sin_cos();
                let (st, ct) = th.sin_cos();
                let (w, td) = (b.turn_rate, b.theta_dot);
                Vector3::new(b.phi_dot - w * st, td * cf + w * sf * ct, -td * sf + w * cf * ct)
            };
            let resid = |z: &[f64; 3]| {
                let rates = rates_of(z[0]);
                let (x, u) = point_state(b.v, z[0], p.gamma, p.phi, p.psi, &rates, z[1], z[2]);
                let d = derivatives(af, EulerRep::E321, &x, &u);
                Vector3::new(d[ix::V], d[ix::ALPHA], d[ix::Q]) - b.target
            };
            let mut z = if i == 0 || pass > 0 {
                [p.table[0], p.table[1].max(1.0), p.table[2]]
            } else {
                self.z_prev
            };
            if pass == 0 && i == 0 {
                z = [0.0, af.mass * af.gravity, 0.0];
            }
            let mut ok = false;
            let mut r_last = f64::INFINITY;
            for _ in 0..50 {
                let r = resid(&z);
                if r.amax() < 1e-10 {
                    ok = true;
                    break;
                }
                // Chord iteration: the Jacobian of the previous point (10 ms earlier)
                // or iterate is kept while it still reduces the residual tenfold per
                // step, and refreshed by central differences otherwise.
                if r.amax() > 0.1 * r_last {
                    self.chord = None;
                }
                r_last = r.amax();
                let lu = match self.chord {
                    Some(lu) => lu,
                    None => {
                        let lu = central_jacobian(&z, resid).lu();
                        self.chord = Some(lu);
                        lu
                    }
                };
                let dz = lu
                    .solve(&r)
                    .ok_or_else(|| format!("singular trajectory solve at t = {t}"))?;
                let scale = (0.1 / dz[0].abs().max(dz[2].abs()).max(1e-300)).min(1.0);
                for k in 0..3 {
                    z[k] -= scale * dz[k];
                }
            }
            if !ok {
                return Err(format!(
                    "trajectory force balance did not converge at t = {t:.2} s (pass {pass}, z = {z:?}, residual {:?})",
                    resid(&z)
                ));
            }
            self.z_prev = z;
            Ok(z)
        }
    }

    /// The table built with the slow reference solver.
    fn slow_reference(
        af: &Airframe,
        mission: &MissionParams,
        opt: &TrajectoryOptions,
    ) -> Result<Vec<TrajPoint>, String> {
        Trajectory::build(af, mission, opt, &mut SlowChord::new(af)).map(|t| t.points().to_vec())
    }

    /// Every component of a table point, for comparisons.
    fn components(p: &TrajPoint) -> Vec<f64> {
        let mut c = vec![p.t, p.v, p.alpha, p.gamma, p.thrust];
        c.extend(
            p.euler_321
                .iter()
                .chain(p.rates.iter())
                .chain(p.pos_neh.iter())
                .chain(p.u.iter()),
        );
        c
    }

    /// The fast construction gives the table of the slow reference ([`slow_reference`]) at
    /// every point (10 ms apart) of the default, the fast and a turning mission in every
    /// mode. Tolerance 1e-9 of each component's largest magnitude over the table: the
    /// reference's own solves stop at a residual of 1e-10 (m/s², rad/s, rad/s²), which
    /// leaves α, T, δe uncertain by |J⁻¹|·1e-10 ≲ 1e-10 of their scales.
    #[test]
    fn fast_construction_equals_the_slow_reference() {
        let af = Airframe::default();
        let fast = MissionParams::fast_limited();
        let slow_turns = MissionParams {
            t_transition_1: 3.0,
            t_transition_2: 4.0,
            ..Default::default()
        };
        let cases = [
            (MissionParams::default(), TrajectoryOptions::default()),
            (
                MissionParams::default(),
                TrajectoryOptions {
                    limited_path: false,
                    ..Default::default()
                },
            ),
            (
                MissionParams::default(),
                TrajectoryOptions {
                    mode: TrajectoryMode::Thesis,
                    limited_path: false,
                    ..Default::default()
                },
            ),
            (fast, TrajectoryOptions::default()),
            (slow_turns, TrajectoryOptions::default()),
            (
                MissionParams::default(),
                TrajectoryOptions {
                    turn_radius: -150.0,
                    ..Default::default()
                },
            ),
        ];
        for (k, (m, opt)) in cases.iter().enumerate() {
            let new = Trajectory::new(&af, m, opt).unwrap();
            let old = slow_reference(&af, m, opt).unwrap();
            assert_eq!(new.points().len(), old.len());
            let ncomp = components(&old[0]).len();
            let mut scale = vec![0.0f64; ncomp];
            for p in &old {
                for (s, c) in scale.iter_mut().zip(components(p)) {
                    *s = s.max(c.abs());
                }
            }
            let mut worst = 0.0f64;
            for (a, b) in new.points().iter().zip(&old) {
                for ((x, y), s) in components(a).iter().zip(components(b)).zip(&scale) {
                    let e = (x - y).abs() / s.max(1e-300);
                    assert!(e <= 1e-9, "case {k}: t = {}: {x} vs {y} (scale {s})", b.t);
                    worst = worst.max(e);
                }
            }
            eprintln!("case {k}: largest difference {worst:.2e} of the component's scale");
        }
    }

    fn max_jump(traj: &Trajectory, f: impl Fn(&TrajPoint) -> f64) -> f64 {
        traj.points()
            .windows(2)
            .map(|w| (f(&w[1]) - f(&w[0])).abs())
            .fold(0.0, f64::max)
    }

    /// Regression (fuzzing): a huge mission time overflowed the table index.
    #[test]
    fn huge_times_continue_the_last_climb() {
        let traj = Trajectory::new(
            &Airframe::default(),
            &MissionParams::default(),
            &TrajectoryOptions::default(),
        )
        .unwrap();
        for t in [1e20, 1e300, f64::MAX] {
            let p = traj.at(t);
            assert_eq!(p.t, t);
            assert!(p.v.is_finite());
        }
        let last = traj.points().last().unwrap();
        let p = traj.at(last.t + 1.0);
        assert!(
            (p.pos_neh.z - last.pos_neh.z - last.v).abs() < 1e-9,
            "climbs at v_vertical"
        );
    }

    #[test]
    fn trajectory_is_continuous_across_phase_boundaries() {
        let af = Airframe::default();
        let m = MissionParams::default();
        for (mode, limited_path) in [
            (TrajectoryMode::ForceBalance, true),
            (TrajectoryMode::ForceBalance, false),
            (TrajectoryMode::Thesis, false),
        ] {
            let traj = Trajectory::new(
                &af,
                &m,
                &TrajectoryOptions {
                    mode,
                    limited_path,
                    ..Default::default()
                },
            )
            .unwrap();
            // Per table step (10 ms): no jumps in any reference quantity. V: the limited
            // profile accelerates at up to 0.8 T_max / m = 13.3 m/s² (0.133 m/s per step).
            assert!(max_jump(&traj, |p| p.v) < 0.14, "{mode:?} V");
            assert!(max_jump(&traj, |p| p.euler_321.y) < 0.01, "{mode:?} θ");
            assert!(max_jump(&traj, |p| p.pos_neh.norm()) < 0.3, "{mode:?} pos");
            // T_c: the limited profile slews its thrust between the floor and 0.8 T_max
            // (111 N) through two 60 ms lags, so T_c = T + τ_T Ṫ moves up to ~20 N per step.
            let t_jump = if limited_path { 20.0 } else { 3.0 };
            assert!(
                max_jump(&traj, |p| p.u[0]) < t_jump,
                "{mode:?} T_c: {}",
                max_jump(&traj, |p| p.u[0])
            );
            assert!(
                max_jump(&traj, |p| p.u[1]) < 0.01,
                "{mode:?} δe {}",
                max_jump(&traj, |p| p.u[1])
            );
            for b in m.phase_starts() {
                let before = traj.at(b - 1e-9);
                let after = traj.at(b + 1e-9);
                assert!((before.v - after.v).abs() < 1e-6);
                assert!((before.pos_neh - after.pos_neh).norm() < 1e-6);
                assert!((before.euler_321 - after.euler_321).norm() < 1e-6);
            }
        }
    }

    #[test]
    fn force_balance_matches_trims_in_steady_segments() {
        let af = Airframe::default();
        let m = MissionParams::default();
        let traj = Trajectory::new(&af, &m, &TrajectoryOptions::default()).unwrap();
        let plant = tailsitter_physics::Plant::new(af);
        let level = plant.trim_level(m.v_level).unwrap();
        // Late in the level segment (the limited profile settles on V_L after the transition).
        let p = traj.at(19.5);
        assert!((p.alpha - level.alpha).abs() < 1e-6, "{} vs {}", p.alpha, level.alpha);
        assert!((p.u[0] - level.thrust).abs() < 1e-3);
        assert!((p.u[1] - level.elevator).abs() < 1e-6);
        let climb = plant.trim_vertical_climb(m.v_vertical).unwrap();
        let p = traj.at(2.0);
        assert!((p.u[0] - climb.thrust).abs() < 1e-3, "{} vs {}", p.u[0], climb.thrust);
        assert!((p.pos_neh.z - 6.0).abs() < 1e-9);
    }
}
