//! The error state of Fig. 3.2: the Euler selection switch (§2.2.1, §3.2.3.2), the measured
//! state x and the trajectory state x_t in the selected set, and the deviation
//! x_p = x − x_t (3.2.1) augmented with the integrators (3.2.12–3.2.14) — the vector the
//! gain K multiplies.

use flight_mission::Measurement;
use guidance::VerticalReference;
use nalgebra::{SVector, Vector3};

use crate::model::{self, ix, state_of, wrap_pi, EulerRep, I_POS, NA, NX, X};
use crate::reference::Reference;
use crate::trajectory::TrajPoint;
use crate::{LqrController, GROUND_AIR_DATA_RAMP};

/// Switches of the error state (from [`crate::LqrParams::effective`]).
#[derive(Debug, Clone, Copy)]
pub(crate) struct ErrorStateSwitches {
    /// Reference 3-2-1 pitch above which the 2-3-1 Euler set is used (rad).
    pub euler_switch_pitch: f64,
}

/// The Euler selection switch for a reference 3-2-1 pitch: 2-3-1 when it exceeds
/// `euler_switch_pitch` (vertical flight and the nose-high parts of the transitions, where
/// 3-2-1 is singular), 3-2-1 otherwise (§2.2.1, §3.2.3.2).
pub(crate) fn euler_set(pitch_321: f64, sw: &ErrorStateSwitches) -> EulerRep {
    if pitch_321.abs() > sw.euler_switch_pitch {
        EulerRep::E231
    } else {
        EulerRep::E321
    }
}

/// The measured α taken to within π of the reference's (x[α] ± 2π): α is an angle, and in
/// the tail-first flow of a descent or a slowing climb (α ≈ ±π) the measured and reference
/// air angles sit on either side of the ±π cut, which as numbers differ by ≈ 2π. Without
/// this the error Δα jumped by 2π as the measured flow crossed the cut (turbulence at the
/// descent's 2 m/s: the aircraft was lost). Untouched (bit for bit) within π.
pub(crate) fn unwrap_alpha(x: &mut X, xt: &X) {
    let d = x[ix::ALPHA] - xt[ix::ALPHA];
    if d.abs() > core::f64::consts::PI {
        x[ix::ALPHA] = xt[ix::ALPHA] + wrap_pi(d);
    }
}

/// The reference α of a flow `vat` whose part in the body x–z plane has the speed `xz`
/// (m/s): below [`SPAN_WISE_FLOW`] the flow runs along the span (β → ±90°) and its α is
/// undefined — the reference's and the measured α are then two arbitrary numbers (0 and π at
/// an 8 m/s wind across the span at lift-off: Δα = −π, 0.2 rad of elevator, the aircraft
/// tipped over and was lost) —, so the reference takes the measured α (`alpha_m`, already on
/// the reference's side of the ±π cut), blended (smoothstep) into its own from
/// [`SPAN_WISE_FLOW`].0 to .1; above that `alpha_t` is returned bit for bit.
pub(crate) fn span_wise_alpha(alpha_m: f64, alpha_t: f64, xz: f64) -> f64 {
    let (lo, hi) = SPAN_WISE_FLOW;
    if xz.is_nan() || xz >= hi {
        return alpha_t;
    }
    let x = ((xz - lo) / (hi - lo)).clamp(0.0, 1.0);
    let s = x * x * (3.0 - 2.0 * x);
    alpha_m + s * wrap_pi(alpha_t - alpha_m)
}

/// Speeds (m/s) of the reference air velocity's part in the body x–z plane between which
/// its α passes from the measured one to its own ([`span_wise_alpha`]).
const SPAN_WISE_FLOW: (f64, f64) = (0.5, 1.0);

impl LqrController {
    /// The measured state x (the estimated state of Fig. 3.2) and the trajectory state x_t in
    /// Euler set `rep` (§2.4): x_t at the regulated position `ctrl_neh` with the air-data
    /// reference; in the take-off and landing phases both carry the body air velocity
    /// ([`Self::hover_air_data`]). Where α is an angle, the measured one is taken to within π
    /// of the reference's ([`unwrap_alpha`]).
    pub(crate) fn state_and_reference(&self, rep: EulerRep, m: &Measurement, r: &Reference) -> (X, X) {
        let inertial;
        let m = if r.ground.is_some() && self.params.stages().reference.wind_compensation {
            inertial = self.ground_phase_air_data(m);
            &inertial
        } else {
            m
        };
        let mut x = state_of(
            rep, m.airspeed, m.alpha, m.beta, &m.rates, &m.quat, &m.pos_ned, m.thrust,
        );
        let mut xt = r.point.state(rep);
        xt[ix::N] = r.ctrl_neh.x;
        xt[ix::E] = r.ctrl_neh.y;
        xt[ix::H] = r.ctrl_neh.z;
        xt[ix::V] = r.air.x;
        xt[ix::ALPHA] = r.air.y;
        xt[ix::BETA] = r.air.z;
        if let Some(v) = &r.ground {
            if self.ground_in_wind() {
                let vat = model::dcm_of_quat(&r.point.quat()) * (v.vel - self.wind);
                let va = vat.norm().max(crate::MIN_AIRSPEED);
                xt[ix::V] = va;
                xt[ix::ALPHA] = vat.z.atan2(vat.x);
                xt[ix::BETA] = (vat.y / va).clamp(-1.0, 1.0).asin();
                unwrap_alpha(&mut x, &xt);
                xt[ix::ALPHA] = span_wise_alpha(x[ix::ALPHA], xt[ix::ALPHA], vat.x.hypot(vat.z));
                return (x, xt);
            } else {
                self.hover_air_data(m, v, &r.point, &mut x, &mut xt);
                return (x, xt);
            }
        }
        unwrap_alpha(&mut x, &xt);
        (x, xt)
    }

    /// The error state [x_I; x − x_t; x_Ip] (3.2.1, 3.2.12–3.2.14): the airspeed integrator,
    /// the deviation from the trajectory (angle errors wrapped to (−π, π]) and the position
    /// integrators.
    pub(crate) fn error_vector(&self, x: &X, xt: &X) -> SVector<f64, NA> {
        let mut dx = SVector::<f64, NA>::zeros();
        dx[0] = self.integrator;
        for j in 0..3 {
            dx[I_POS + j] = self.pos_integrator[j];
        }
        for i in 0..NX {
            let d = x[i] - xt[i];
            dx[1 + i] = if (ix::PHI..=ix::PSI).contains(&i) {
                wrap_pi(d)
            } else {
                d
            };
        }
        dx
    }

    /// Air data in the take-off and landing phases: near hover V, α, β are undefined (α
    /// jumps to π in the tail-first descent), so x and x_t carry the body air velocity
    /// `v_a = V (cα cβ, sβ, sα cβ)` as `(u_a, w_a/V_e, v_a/V_e)` in place of `(V, α, β)`, the
    /// reference's from `DCM_t (v_ref − ŵ)`, with `V_e = max(u_a,t, 1 m/s)`: to first order
    /// the model's (V, α, β) at α = β = 0 and V = V_e, where `solve_gain` linearises (the same
    /// 1 m/s floor), and continuous through V = 0 and reversed flow.
    /// Take-off and landing phases in wind (README, "Mission in wind"): once the wind
    /// estimate has latched the position integrators, the reference of those phases is
    /// headed by the weathervane and carries the air data (V, α, β) of its own velocity in
    /// the estimated wind, `DCM_t (v_ref − ŵ)`, like the mission's vertical flight in wind,
    /// and the gains are computed about it; in still air the near-hover air data of
    /// [`Self::hover_air_data`].
    pub(crate) fn ground_in_wind(&self) -> bool {
        self.wind_integral && self.wind.iter().all(|w| w.is_finite())
    }

    /// The measurement with the air data (V, α, β) of the take-off and landing phases taken
    /// from the inertial velocity less the wind estimate, `DCM (v_g − ŵ)`, in place of the
    /// measured air velocity, phased in (smoothstep) as the air-data wind
    /// `v_g − DCMᵀ v_a` rises through [`GROUND_AIR_DATA_RAMP`] (below it, as in still air,
    /// the measurement untouched bit for bit). Near hover the velocity error the gains see is
    /// then the ground velocity's, as a multicopter's position loop has it: the measured air
    /// velocity carried the part of the wind the 0.3 s estimate has not caught, so an 8 m/s
    /// wind stepping in at lift-off read as an 8 m/s velocity error (tipped over in 0.5 s,
    /// lost) and in turbulence every gust entered the feedback (the descent swung in pitch
    /// until the thrust saturated).
    pub(crate) fn ground_phase_air_data(&self, m: &Measurement) -> Measurement {
        let dcm = model::dcm_of_quat(&m.quat);
        let va = model::body_velocity(m.airspeed, m.alpha, m.beta);
        let raw = m.vel_ned - dcm.transpose() * va;
        let (w0, w1) = GROUND_AIR_DATA_RAMP;
        let x = ((raw.norm() - w0) / (w1 - w0)).clamp(0.0, 1.0);
        let s = x * x * (3.0 - 2.0 * x);
        if !(s > 0.0 && self.wind.iter().all(|w| w.is_finite())) {
            return *m;
        }
        let v = va + s * (dcm * (raw - self.wind));
        let speed = v.norm();
        if !speed.is_finite() {
            return *m;
        }
        let mut out = *m;
        out.airspeed = speed;
        out.alpha = v.z.atan2(v.x);
        out.beta = if speed > 1e-9 {
            (v.y / speed).clamp(-1.0, 1.0).asin()
        } else {
            0.0
        };
        out
    }

    fn hover_air_data(&self, m: &Measurement, v: &VerticalReference, reference: &TrajPoint, x: &mut X, xt: &mut X) {
        let (sa, ca) = m.alpha.sin_cos();
        let (sb, cb) = m.beta.sin_cos();
        let va = m.airspeed * Vector3::new(ca * cb, sb, sa * cb);
        let wind = if self.wind.iter().all(|w| w.is_finite()) {
            self.wind
        } else {
            Vector3::zeros()
        };
        let vat = model::dcm_of_quat(&reference.quat()) * (v.vel - wind);
        let ve = vat.x.max(1.0);
        x[ix::V] = va.x;
        x[ix::ALPHA] = va.z / ve;
        x[ix::BETA] = va.y / ve;
        xt[ix::V] = vat.x;
        xt[ix::ALPHA] = vat.z / ve;
        xt[ix::BETA] = vat.y / ve;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A measured α just past the ±π cut from the reference's is taken to the reference's
    /// side (error 0.08 rad, not 2π − 0.08); within π the state is untouched bit for bit.
    #[test]
    fn alpha_error_across_the_cut_is_small() {
        let mut xt = X::zeros();
        xt[ix::ALPHA] = -3.1;
        let mut x = X::zeros();
        x[ix::ALPHA] = 3.1;
        unwrap_alpha(&mut x, &xt);
        let d = x[ix::ALPHA] - xt[ix::ALPHA];
        assert!((d + (core::f64::consts::TAU - 6.2)).abs() < 1e-12, "Δα = {d}");
        // The flow (sin, cos of α) is unchanged.
        assert!((x[ix::ALPHA].sin() - 3.1f64.sin()).abs() < 1e-12);
        for a in [0.0, -2.9, -3.0, -0.1 + 1e-17] {
            let mut y = X::zeros();
            y[ix::ALPHA] = a;
            unwrap_alpha(&mut y, &xt);
            assert_eq!(y[ix::ALPHA].to_bits(), a.to_bits(), "{a}");
        }
    }

    /// A reference flow along the span (its x–z part below 0.5 m/s) takes the measured α
    /// (0 against the reference's π at lift-off: no error); from 1 m/s the reference's own α
    /// bit for bit; in between a blend that passes through neither cut (the short way round).
    #[test]
    fn span_wise_flow_takes_the_measured_alpha() {
        let pi = core::f64::consts::PI;
        assert_eq!(span_wise_alpha(0.0, pi, 1e-16), 0.0);
        assert_eq!(span_wise_alpha(0.3, pi, 0.49), 0.3);
        for xz in [1.0, 2.0, 8.0] {
            assert_eq!(span_wise_alpha(0.0, pi, xz).to_bits(), pi.to_bits(), "{xz}");
        }
        // Halfway (0.75 m/s): half of the short way from −3.0 to 3.0 (0.28 rad across −π).
        let mid = span_wise_alpha(-3.0, 3.0, 0.75);
        let short = wrap_pi(3.0 - -3.0);
        assert!((mid - (-3.0 + 0.5 * short)).abs() < 1e-12, "{mid}");
        assert!(short.abs() < 0.3, "{short}");
    }
}
