//! The gain schedule of Fig. 3.2 (§3.1.3, §3.2.4): every T_l = `relinearisation_period` and
//! at every Euler-set switch the model for control is relinearised (3.2.7–3.2.9), augmented
//! with the integrators (3.2.12–3.2.14), discretised by a zero-order hold (in place of
//! 3.2.10–3.2.11; the printed first order with `discretisation` 1) and the gain K solved from the Riccati equation (3.1.3–3.1.5: the
//! steady-state DARE, warm-started, or the thesis's backward iteration).

use flight_mission::{Measurement, Notice, Phase};
use nalgebra::{SMatrix, SVector};

use crate::linalg::{
    dare_newton_step, dare_residual, dare_sda, discretise_zoh, lqr_gain, riccati_backward, spectral_radius_bound,
    RiccatiError,
};
use crate::model::{ix, linearise, EulerRep, I_POS, NA, NU, NX, U, X};
use crate::reference::Reference;
use crate::weights::Weights;
use crate::{Gain, LqrController, LqrParams, HOVER_WIND_AIR_ANGLE};

/// Largest tailwind component along the track, in climb speeds V_V, for which the front
/// transition in wind is linearised about the reference (README, "Mission in wind").
pub const TRANSITION_TAILWIND_REFERENCE: f64 = 2.0;

/// Size of the augmented ZOH exponential: states + integrator + inputs.
const NM: usize = NA + NU;

/// The result of one gain computation.
#[derive(Debug, Clone, Copy)]
pub struct GainSolution {
    pub gain: Gain,
    pub phi: SMatrix<f64, NA, NA>,
    pub gamma: SMatrix<f64, NA, NU>,
    pub spectral_radius: f64,
    /// The DARE solution of the design on the [∫ΔV; x] block (inert position integrators,
    /// `riccati_method` 0): the warm start of the next solve. `None` otherwise.
    pub p: Option<SMatrix<f64, NR, NR>>,
    /// Whether the warm start was accepted (else the DARE was solved cold).
    pub warm: bool,
}

/// Size of the design when the position integrators are inert: integrator + model states.
pub const NR: usize = 1 + NX;
/// Size of the augmented ZOH exponential of that design.
const NRM: usize = NR + NU;

/// Warm start of the DARE (README, "Riccati"): a Newton step from the extrapolated previous
/// P is tried only when that start's relative DARE residual on the new model is at most this
/// (close enough for one quadratic step to reach rounding; a farther start goes cold at
/// once, having cost only the residual).
pub const WARM_MAX_START_RESIDUAL: f64 = 1e-7;
/// Newton steps of the warm start before it gives up and solves cold. One: a step (Smith's
/// doubling of the Stein equation, ≈ 13 doublings like the cold SDA's: the slow closed-loop
/// poles set both counts) costs ≈ 0.55 of the cold solve, so a second step loses.
pub const WARM_MAX_NEWTON_STEPS: usize = 1;
/// A further Newton step is taken only from a residual at most this.
pub const WARM_MAX_STEP_RESIDUAL: f64 = 1e-7;
/// The warm solution is accepted when its relative DARE residual is at most this (the cold
/// doubling reaches ≈ 1e-16); otherwise the cold doubling solves again.
pub const WARM_MAX_RESIDUAL: f64 = 1e-13;

/// Switches of the gain schedule (from [`LqrParams::effective`]).
#[derive(Debug, Clone, Copy)]
pub(crate) struct GainScheduleSwitches {
    /// T_l (§3.1.3, §3.2.4).
    pub relinearisation_period: f64,
    /// Tuned configuration: after the back transition, with the air angles of a wind across
    /// the slowing climb, relinearise about the reference instead of the measured state
    /// (README, "Gusts"); the thesis always relinearises about the measured state.
    pub reference_after_back_transition: bool,
    /// Tuned configuration: in the front transition in a steady wind stronger than the
    /// climb (README, "Mission in wind"), relinearise about the reference instead of the
    /// measured state.
    pub reference_in_transition_wind: bool,
    /// Tuned configuration: in the first vertical phase in a steady wind of the weathervane's
    /// engage speed (README, "Mission in wind"), relinearise about the reference.
    pub reference_in_hover_wind: bool,
}

/// Discretised model, gain and closed-loop spectral-radius bound of one design.
struct Design<const N: usize> {
    k: SMatrix<f64, NU, N>,
    phi: SMatrix<f64, N, N>,
    gamma: SMatrix<f64, N, NU>,
    rho: f64,
    /// The DARE solution (`riccati_method` 0).
    p: Option<SMatrix<f64, N, N>>,
    /// Whether the warm start was accepted.
    warm: bool,
}

/// Discretisation of (A, B) over `ts`: the exact zero-order hold (`discretisation` 0,
/// `M` = N + NU) or the printed first order Φ = I + A T_s, Γ = B T_s (1, 3.2.10–3.2.11; on
/// the integrator-augmented A this is the corrected (3.2.13): Φ_I = [1 − λT_s, T_s H_I; 0 Φ],
/// Γ_I = [0; Γ]).
fn discretise<const N: usize, const M: usize>(
    a: &SMatrix<f64, N, N>,
    b: &SMatrix<f64, N, NU>,
    ts: f64,
    params: &LqrParams,
) -> (SMatrix<f64, N, N>, SMatrix<f64, N, NU>) {
    if params.discretisation == 1 {
        (SMatrix::<f64, N, N>::identity() + a * ts, b * ts)
    } else {
        discretise_zoh::<N, NU, M>(a, b, ts)
    }
}

/// Discretisation of (A, B) over `ts` ([`discretise`]), gain by the DARE (`riccati_method`
/// 0, [`dare_gain`]) or the backward iteration (1, 3.1.3–3.1.5 over `riccati_horizon`), and
/// the stability check of Φ − ΓK against `limit`.
#[allow(clippy::too_many_arguments)]
fn design<const N: usize, const M: usize>(
    a: &SMatrix<f64, N, N>,
    b: &SMatrix<f64, N, NU>,
    q_diag: &SVector<f64, N>,
    r: &SVector<f64, NU>,
    ts: f64,
    params: &LqrParams,
    limit: f64,
    warm: Option<&SMatrix<f64, N, N>>,
) -> Result<Design<N>, RiccatiError> {
    let (phi, gamma) = discretise::<N, M>(a, b, ts, params);
    let q = SMatrix::<f64, N, N>::from_diagonal(q_diag);
    let (k, p, warm) = if params.riccati_method == 0 {
        dare_gain(&phi, &gamma, &q, r, warm)?
    } else {
        let k = riccati_backward(&phi, &gamma, &q, r, params.riccati_horizon as usize, None)?.0;
        (k, None, false)
    };
    let rho = spectral_radius_bound(&(phi - gamma * k));
    if rho.is_nan() || rho >= limit {
        return Err(RiccatiError::Unstable(rho));
    }
    Ok(Design {
        k,
        phi,
        gamma,
        rho,
        p,
        warm,
    })
}

/// Gain and P of the steady-state DARE: warm-started by Newton steps from `warm` when given
/// and close enough ([`dare_warm`]), else the cold structured doubling, residual checked.
/// The flag tells whether the warm start was accepted.
#[allow(clippy::type_complexity)]
fn dare_gain<const N: usize>(
    phi: &SMatrix<f64, N, N>,
    gamma: &SMatrix<f64, N, NU>,
    q: &SMatrix<f64, N, N>,
    r: &SVector<f64, NU>,
    warm: Option<&SMatrix<f64, N, N>>,
) -> Result<(SMatrix<f64, NU, N>, Option<SMatrix<f64, N, N>>, bool), RiccatiError> {
    match warm.and_then(|p0| dare_warm(phi, gamma, q, r, p0)) {
        Some((k, p)) => Ok((k, Some(p), true)),
        None => {
            let p = dare_sda(phi, gamma, q, r)?;
            let k = lqr_gain(phi, gamma, &p, r)?;
            let res = dare_residual(phi, gamma, q, &p, &k);
            if res.is_nan() || res >= 1e-6 {
                return Err(RiccatiError::Residual(res));
            }
            Ok((k, Some(p), false))
        }
    }
}

/// Warm start: Newton steps from the previous P `p0`, accepted on the residual
/// ([`WARM_MAX_START_RESIDUAL`], [`WARM_MAX_NEWTON_STEPS`], [`WARM_MAX_RESIDUAL`]).
fn dare_warm<const N: usize>(
    phi: &SMatrix<f64, N, N>,
    gamma: &SMatrix<f64, N, NU>,
    q: &SMatrix<f64, N, N>,
    r: &SVector<f64, NU>,
    p0: &SMatrix<f64, N, N>,
) -> Option<(SMatrix<f64, NU, N>, SMatrix<f64, N, N>)> {
    let mut p = *p0;
    let mut max_start = WARM_MAX_START_RESIDUAL;
    for _ in 0..WARM_MAX_NEWTON_STEPS {
        // A start already converged (the model has not changed: steady flight) is
        // returned as it is and accepted on the residual below.
        p = dare_newton_step(phi, gamma, q, r, &p, max_start, WARM_MAX_RESIDUAL)
            .ok()?
            .0;
        let k = lqr_gain(phi, gamma, &p, r).ok()?;
        let res = dare_residual(phi, gamma, q, &p, &k);
        if res <= WARM_MAX_RESIDUAL {
            return Some((k, p));
        }
        // The next step starts from here: it must converge at once.
        max_start = WARM_MAX_STEP_RESIDUAL;
    }
    None
}

/// The design on the [∫ΔV; x] block embedded in the full [∫ΔV; x; ∫Δp] one: the inert
/// position integrators' gain columns are zero and their Φ block e^{−T_s} I (first order:
/// (1 − T_s) I).
fn embed_inert(d: Design<NR>, ts: f64, first_order: bool) -> GainSolution {
    let mut k = Gain::zeros();
    k.fixed_view_mut::<NU, NR>(0, 0).copy_from(&d.k);
    let mut phi = SMatrix::<f64, NA, NA>::zeros();
    phi.fixed_view_mut::<NR, NR>(0, 0).copy_from(&d.phi);
    let inert = if first_order { 1.0 - ts } else { (-ts).exp() };
    for j in NR..NA {
        phi[(j, j)] = inert;
    }
    let mut gamma = SMatrix::<f64, NA, NU>::zeros();
    gamma.fixed_view_mut::<NR, NU>(0, 0).copy_from(&d.gamma);
    // The inert block's eigenvalue e^{−T_s} joins the spectrum of the closed loop.
    let rho = d.rho.max(inert);
    GainSolution {
        gain: k,
        phi,
        gamma,
        spectral_radius: rho,
        p: d.p,
        warm: d.warm,
    }
}

impl LqrController {
    /// Linearise about (x, u_t), discretise by ZOH with the airspeed integrator, and solve
    /// for the gain with the weights of time t. No allocation.
    ///
    /// Integrator (3.2.12–3.2.14), derived in continuous time and discretised with the
    /// model: `ẋ_I = V − V_t − λ x_I = H_I x_p − λ x_I`, so the augmented system is
    /// `[ẋ_I; ẋ_p] = [−λ H_I; 0 F] [x_I; x_p] + [0; G] u_p`, and ZOH gives
    /// `Φ_I = [e^{−λT_s} ∫H_I e^{Fτ}dτ; 0 Φ]`, `Γ_I = [·; Γ]` — to first order in T_s and
    /// for λ = 0 `Φ_I ≈ [1 T_s H_I; 0 Φ]`; the printed (3.2.13) has T_s in the (1,1)
    /// position and Γ_I's first row is not zero but O(T_s²). The small leak λ
    /// (`integrator_leak`) makes the augmented pair stabilisable (see [`LqrParams`]).
    ///
    /// The DARE is solved cold (structured doubling); [`Self::solve_gain_warm`] starts from a
    /// previous solution.
    pub fn solve_gain(&self, rep: EulerRep, x: &X, u: &U, t: f64) -> Result<GainSolution, RiccatiError> {
        self.solve_gain_warm(rep, x, u, t, None)
    }

    /// [`Self::solve_gain`] with the DARE warm-started from `warm`, the [`GainSolution::p`] of
    /// an earlier solve (README, "Riccati"): one Newton step, accepted when the residual of its
    /// result is ≤ [`WARM_MAX_RESIDUAL`], else the cold doubling. Only the design with inert
    /// position integrators (the default) is warm-started.
    pub fn solve_gain_warm(
        &self,
        rep: EulerRep,
        x: &X,
        u: &U,
        t: f64,
        warm: Option<&SMatrix<f64, NR, NR>>,
    ) -> Result<GainSolution, RiccatiError> {
        let (a, b) = self.augmented_model(rep, x, u)?;
        let w: Weights = self.schedule.at(&self.mission, t);
        let ts = self.mission.sample_time;
        // With the undamped integrator (leak 0, thesis) the integrator-minus-along-track
        // mode sits at z = 1 whatever the gain: accept the marginal bound (a Jordan block at
        // z = 1 raises the 2¹⁶-power bound to at most (2¹⁶)^(1/2¹⁶) ≈ 1 + 1.7e-4).
        let limit = if self.params.integrator_leak == 0.0 {
            1.0 + 1e-3
        } else {
            1.0
        };
        if (0..3).any(|j| self.position_integral_on(j)) {
            let d = design::<NA, NM>(&a, &b, &w.q, &w.r, ts, &self.params, limit, None)?;
            return Ok(GainSolution {
                gain: d.k,
                phi: d.phi,
                gamma: d.gamma,
                spectral_radius: d.rho,
                p: None,
                warm: false,
            });
        }
        // Inert position integrators (the default): they are decoupled (ẋ_Ip = −x_Ip, no
        // input), so Φ, Γ, P are block-diagonal and their gain columns zero. The design runs
        // on the leading [∫ΔV; x] block alone (NR = 14 states: ≈ 0.56× the cubic work of 17)
        // and the result is embedded: the same gains to rounding (an inert state only ever
        // adds exact zeros to the full problem's sums).
        let d = design::<NR, NRM>(
            &a.fixed_view::<NR, NR>(0, 0).into_owned(),
            &b.fixed_view::<NR, NU>(0, 0).into_owned(),
            &w.q.fixed_rows::<NR>(0).into_owned(),
            &w.r,
            ts,
            &self.params,
            limit,
            warm,
        )?;
        Ok(embed_inert(d, ts, self.params.discretisation == 1))
    }

    /// The continuous model for control augmented with the integrators, (A, B) over
    /// [∫ΔV; x; ∫ΔN, ∫ΔE, ∫Δh]: F, G of the linearisation about (x, u) (3.2.7–3.2.9; V kept
    /// ≥ 1 m/s), the airspeed integrator row ẋ_I = V − V_t − λ x_I (3.2.12–3.2.14) and the
    /// position integrators (active: ẋ_Ip = p − p_t − λ_p x_Ip; inert: ẋ_Ip = −x_Ip).
    fn augmented_model(
        &self,
        rep: EulerRep,
        x: &X,
        u: &U,
    ) -> Result<(SMatrix<f64, NA, NA>, SMatrix<f64, NA, NU>), RiccatiError> {
        let mut xl = *x;
        // Keep the linearisation point inside the model's domain (V > 0, away from the
        // Euler singularity the rep choice avoids anyway).
        xl[ix::V] = xl[ix::V].max(1.0);
        let (f, g) = linearise(&self.airframe, rep, &xl, u);
        let mut a = SMatrix::<f64, NA, NA>::zeros();
        a[(0, 0)] = -self.params.integrator_leak;
        a[(0, 1 + ix::V)] = 1.0;
        a.fixed_view_mut::<NX, NX>(1, 1).copy_from(&f);
        for j in 0..3 {
            if self.position_integral_on(j) {
                // ẋ_Ip = p − p_t − λ_p x_Ip, p ∈ {N, E, h}.
                a[(I_POS + j, 1 + ix::N + j)] = 1.0;
                a[(I_POS + j, I_POS + j)] = -self.params.position_integrator_leak;
            } else {
                // Thesis structure: the position integrators are inert, decoupled, stable
                // states (not driven by the model, not driving it). The DARE solution is then
                // block-diagonal and their gain columns are zero: K on the other states is
                // exactly the thesis's 14-state gain.
                a[(I_POS + j, I_POS + j)] = -1.0;
            }
        }
        let mut b = SMatrix::<f64, NA, NU>::zeros();
        b.fixed_view_mut::<NX, NU>(1, 0).copy_from(&g);
        if !a.iter().chain(b.iter()).all(|v| v.is_finite()) {
            return Err(RiccatiError::NonFinite);
        }
        Ok((a, b))
    }

    /// Gain schedule stage (Fig. 3.2, §3.1.3, §3.2.4): when T_l is due, at an Euler-set switch
    /// or without gains, relinearise about [`Self::linearisation_point`] with the trajectory's
    /// inputs u_t (3.2.7–3.2.9), discretise with the integrators (3.2.12–3.2.14) and solve for
    /// K (3.1.3–3.1.5), warm-started ([`Self::warm_start`]). A failed solve keeps the previous
    /// gains and their Euler set and returns [`Notice::GainFallback`].
    pub(crate) fn schedule_gains(
        &mut self,
        t: f64,
        m: &Measurement,
        r: &Reference,
        rep: EulerRep,
        (x, xt): (&X, &X),
        sw: &GainScheduleSwitches,
    ) -> Option<Notice> {
        let due = t + 1e-9 >= self.next_relinearisation && !self.holds_flare_gains(r);
        if self.have_gain && rep == self.rep && !due {
            return None;
        }
        let x_lin = self.linearisation_point(t, m, r, x, xt, sw);
        let warm = self.warm_start(rep);
        let notice = match self.solve_gain_warm(rep, &x_lin, &r.point.u, t, warm.as_ref()) {
            Ok(sol) => {
                self.accept_gains(&sol, rep, &x_lin, &r.point.u, t);
                self.rep = rep;
                None
            }
            Err(e) => {
                self.stats.fallbacks += 1;
                Some(Notice::GainFallback(e.describe()))
            }
        };
        self.stats.solves += 1;
        if due {
            self.next_relinearisation = t + sw.relinearisation_period;
        }
        notice
    }

    /// The point of the relinearisation (§3.1.3): the current estimated state x (positions do
    /// not enter the model), or the reference x_t in hover in wind (README, "Hover in wind":
    /// the measured tilt into the wind and α, β of 30–90° put the linear model far outside its
    /// range) and, tuned, after the back transition with the air angles of a wind across the
    /// slowing climb (README, "Gusts"). In the take-off and landing phases at α = β = 0 (x
    /// carries the body air velocity there, [`Self::hover_air_data`]).
    fn linearisation_point(
        &self,
        t: f64,
        m: &Measurement,
        r: &Reference,
        x: &X,
        xt: &X,
        sw: &GainScheduleSwitches,
    ) -> X {
        let lin_ref = r.in_wind
            || r.ground.is_none()
                && sw.reference_after_back_transition
                && self.mission.phase_at(t).0 == Phase::Vertical2
                && self.wind_in_air_data(m)
            || r.ground.is_none() && sw.reference_in_transition_wind && self.transition_in_wind(t)
            || r.ground.is_none() && sw.reference_in_hover_wind && self.steady_wind_in_vertical_1(t);
        if r.ground.is_some() && self.ground_in_wind() {
            // Take-off and landing in wind: about the reference (its air data in the wind).
            return *xt;
        }
        let mut x_lin = if lin_ref { *xt } else { *x };
        if r.ground.is_some() {
            x_lin[ix::ALPHA] = 0.0;
            x_lin[ix::BETA] = 0.0;
        }
        x_lin
    }

    /// The flare in wind keeps the gains of the end of the descent (README, "Take-off and
    /// landing"): its reference air data, those of `DCM_t (v_ref − ŵ)`, swing from α ≈ 130° to
    /// 90° as the sink stops, and the gains relinearised about them in the 1 s flare cut the
    /// thrust the flare needs (touchdown 0.54–0.81 m/s at 3 m/s with them, 0.09–0.37 m/s
    /// held). A structural relinearisation (`next_relinearisation` = −∞) still runs.
    fn holds_flare_gains(&self, r: &Reference) -> bool {
        self.ground_in_wind()
            && r.ground.is_some_and(|v| v.phase == Phase::Flare)
            && self.next_relinearisation.is_finite()
    }

    /// The front transition in a steady wind (the position integrators latched) whose
    /// estimate (the weathervane's 4 s filter) exceeds the climb speed V_V and is not within
    /// 45° of a tailwind along the track: the wind then dominates the air velocity of the
    /// transition's slow start (air angles > 45°; across the track β = 0.78–0.98 rad
    /// measured at 8 m/s), and the measured state, swinging through those angles, is no
    /// valid point for the model's linearisation (README, "Mission in wind"); the reference
    /// carries the wind-consistent air data instead. In a tailwind the measured state is
    /// the better point (about the reference a 10 m/s tailwind was lost, 361 m), unless the
    /// tailwind is weak ([`Self::weak_tailwind`]).
    fn transition_in_wind(&self, t: f64) -> bool {
        if !(self.wind_integral && self.mission.phase_at(t).0 == Phase::TransitionToLevel) {
            return false;
        }
        let w = self.weathervane.wind();
        let (s, c) = self.trajectory.at(t).euler_321.z.sin_cos();
        let (along, across) = (w.x * c + w.y * s, (w.y * c - w.x * s).abs());
        w.xy().norm() > self.mission.v_vertical && (along < across || self.weak_tailwind(c, s))
    }

    /// A tailwind component along the track (`cos_track`, `sin_track`: its heading) of at most
    /// [`TRANSITION_TAILWIND_REFERENCE`] climb speeds: the front transition's gains are then
    /// computed about the reference too (README, "Mission in wind"). At 5 m/s from behind the
    /// transition's measured air angles pass through the same wind-dominated range as across
    /// the track (the handover's tailwind 3.05 → 2.95 m, its quartering tailwinds 19.5 →
    /// 7.0 m); from 8 m/s the measured state is the better point (about the reference the
    /// handover's 10 m/s tailwind was lost).
    ///
    /// The tailwind is read from the controller's own estimate (0.3 s filter), which has
    /// settled before the transition: on the weathervane's 4 s estimate a building 8 m/s
    /// tailwind passes through the range early in the transition.
    fn weak_tailwind(&self, cos_track: f64, sin_track: f64) -> bool {
        let along = self.wind.x * cos_track + self.wind.y * sin_track;
        along <= TRANSITION_TAILWIND_REFERENCE * self.mission.v_vertical
    }

    /// The first vertical phase with the weathervane's wind estimate (4 s filter) at or above
    /// its engage speed, whether or not the phase lets it turn (README, "Mission in wind"):
    /// in the default mission's 5 s hover the weathervane, whose return window before the
    /// transition is 6.5 s, never engages, and the tilt into a strong wind soon brings the
    /// measured α and β below [`HOVER_WIND_AIR_ANGLE`] — about the measured state (tilted
    /// 55–70°) the gains then cut the thrust to zero and the pitch fell to level at 4.3–4.9 s
    /// in 8–10 m/s quartering winds.
    fn steady_wind_in_vertical_1(&self, t: f64) -> bool {
        let vane = &self.weathervane;
        vane.params().enabled
            && self.mission.phase_at(t).0 == Phase::Vertical1
            && vane.wind().xy().norm() >= vane.params().engage_speed
            && self.wind.xy().norm() >= 2.0 * self.mission.v_vertical
    }

    /// Measured air angles beyond [`HOVER_WIND_AIR_ANGLE`] with an unfiltered air-data wind of
    /// at least the weathervane's engage speed (in still air the climb's air comes from the
    /// nose, α, β ≈ 0, and the air-data wind is zero).
    pub(crate) fn wind_in_air_data(&self, m: &Measurement) -> bool {
        (m.alpha.abs() > HOVER_WIND_AIR_ANGLE || m.beta.abs() > HOVER_WIND_AIR_ANGLE)
            && guidance::weathervane::air_data_wind(m).xy().norm() >= self.weathervane.params().engage_speed
    }

    /// Warm start of the DARE in Euler set `rep`: the previous solutions in the same set,
    /// extrapolated (quadratic through the last three, linear through two, else the last). A P
    /// of the other Euler set is no start (nor history) for this one: it is dropped.
    fn warm_start(&mut self, rep: EulerRep) -> Option<SMatrix<f64, NR, NR>> {
        if rep == self.rep {
            self.warm_p.map(|p1| match self.warm_len {
                0 => p1,
                1 => p1 * 2.0 - self.warm_hist[0],
                _ => p1 * 3.0 - self.warm_hist[0] * 3.0 + self.warm_hist[1],
            })
        } else {
            self.warm_p = None;
            self.warm_len = 0;
            None
        }
    }

    /// Take a solved gain into use: counters (with [`Self::verify_warm_start`] the warm gain
    /// is compared with a cold solve), the spectral-radius bound and the warm-start history.
    fn accept_gains(&mut self, sol: &GainSolution, rep: EulerRep, x_lin: &X, u: &U, t: f64) {
        if sol.warm {
            self.stats.warm_solves += 1;
            if self.verify_warm {
                if let Ok(cold) = self.solve_gain(rep, x_lin, u, t) {
                    let e = (sol.gain - cold.gain).amax() / cold.gain.amax();
                    self.stats.warm_max_gain_error = self.stats.warm_max_gain_error.max(e);
                } else {
                    self.stats.warm_max_gain_error = f64::INFINITY;
                }
            }
        }
        self.gain = sol.gain;
        self.have_gain = true;
        self.stats.last_spectral_radius = sol.spectral_radius;
        if let (Some(_), Some(old)) = (sol.p, self.warm_p) {
            self.warm_hist[1] = self.warm_hist[0];
            self.warm_hist[0] = old;
            self.warm_len = (self.warm_len + 1).min(2);
        } else {
            self.warm_len = 0;
        }
        self.warm_p = sol.p;
    }
}
