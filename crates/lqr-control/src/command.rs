//! The feedback of Fig. 3.2: the command u = u_t − K [x_I; x − x_t; x_Ip] (3.1.2 on the
//! deviations, 3.2.2: trim feed-forward u_t plus the LQR's u_p) clamped to the plant's
//! limits, the integrator updates with anti-windup (3.2.12–3.2.14) and the diagnostics.

use flight_mission::{ControlError, Diagnostics, Notice};
use nalgebra::{SVector, Vector3};

use crate::model::{ix, I_POS, NA, NU, U, X};
use crate::reference::Reference;
use crate::{LqrController, COMMAND_NAMES};

/// Switches and tuning of the integrators (from [`crate::LqrParams::effective`]).
#[derive(Debug, Clone, Copy)]
pub(crate) struct IntegratorSwitches {
    /// Limit of the airspeed-error integrator |∫ΔV dt| (m), applied with `integrator_clamp`.
    pub integrator_limit: f64,
    /// Clamp the airspeed integrator to ±`integrator_limit` (off: printed, no limit).
    pub integrator_clamp: bool,
    /// Do not integrate further into a thrust limit (off: printed).
    pub integrator_freeze: bool,
    /// Leak λ of the airspeed integrator (1/s); 0 in the thesis configuration (3.2.12–3.2.14).
    pub integrator_leak: f64,
    /// Limit of each position-error integrator (m·s).
    pub position_integrator_limit: f64,
    /// Leak λ_p of the position integrators (1/s).
    pub position_integrator_leak: f64,
}

impl LqrController {
    /// Command stage (Fig. 3.2, feedback): u = u_t − K dx with `dx` the error state
    /// ([`Self::error_vector`]), each command clamped to the plant's limits (thrust range,
    /// deflection limit). Returns u and per command the direction of its saturation (+1
    /// above the upper limit, −1 below the lower, 0 inside); the first saturated command
    /// becomes the notice unless `notice` already holds one. A non-finite command is an error.
    pub(crate) fn command_stage(
        &self,
        t: f64,
        u_t: &U,
        dx: &SVector<f64, NA>,
        notice: &mut Option<Notice>,
    ) -> Result<(U, [f64; NU]), ControlError> {
        let mut u = u_t - self.gain * dx;
        let af = &self.airframe;
        let mut saturated = [0.0f64; NU];
        for i in 0..NU {
            let (lo, hi) = if i == 0 {
                (af.thrust_min, af.thrust_max)
            } else {
                (-af.deflection_limit, af.deflection_limit)
            };
            if u[i] < lo || u[i] > hi {
                saturated[i] = if u[i] > hi { 1.0 } else { -1.0 };
                u[i] = u[i].clamp(lo, hi);
                if notice.is_none() {
                    *notice = Some(Notice::Saturated(COMMAND_NAMES[i]));
                }
            }
        }
        if !u.iter().all(|v| v.is_finite()) {
            return Err(ControlError(format!("non-finite command at t = {t}")));
        }
        Ok((u, saturated))
    }

    /// Integrator stage: the airspeed integrator ([`Self::integrate_airspeed`]) and, where
    /// active, the position integrators ([`Self::integrate_position`]), with anti-windup
    /// against the saturations of this sample's command.
    pub(crate) fn integrator_stage(&mut self, x: &X, xt: &X, saturated: &[f64; NU], sw: &IntegratorSwitches) {
        self.integrate_airspeed(x, xt, saturated[0], sw);
        if self.has_position_integral() {
            self.integrate_position(x, xt, saturated, sw);
        }
    }

    /// Airspeed integrator x_I(k+1) = e^{−λ T_s} x_I(k) + T_s (V − V_t) (3.2.12–3.2.14, leak
    /// λ), with anti-windup where switched on: not integrated further into a thrust limit
    /// (`integrator_freeze`; `thrust_saturated` is the direction of the thrust's saturation),
    /// clamped to ±`integrator_limit` (`integrator_clamp`); only finite values committed.
    fn integrate_airspeed(&mut self, x: &X, xt: &X, thrust_saturated: f64, sw: &IntegratorSwitches) {
        let dv = x[ix::V] - xt[ix::V];
        // Negative airspeed error asks for more thrust (K row of T_c on x_I is negative).
        let pushes_up = dv < 0.0;
        let into_limit = thrust_saturated > 0.0 && pushes_up || thrust_saturated < 0.0 && !pushes_up;
        if !(sw.integrator_freeze && into_limit) {
            let ts = self.mission.sample_time;
            let decay = (-sw.integrator_leak * ts).exp();
            let mut next = decay * self.integrator + ts * dv;
            if sw.integrator_clamp {
                next = next.clamp(-sw.integrator_limit, sw.integrator_limit);
            }
            if next.is_finite() {
                self.integrator = next;
            }
        }
    }

    /// Position integrators ∫ΔN, ∫ΔE, ∫Δh: x_Ip(k+1) = e^{−λ_p T_s} x_Ip(k) + T_s (p − p_t),
    /// with anti-windup per integrator: the update is skipped when its increment would push a
    /// saturated command further into its limit (conditional integration, through the
    /// integrator's gain column), the result is clamped to `position_integrator_limit`, and
    /// only finite values are committed.
    fn integrate_position(&mut self, x: &X, xt: &X, saturated: &[f64; NU], sw: &IntegratorSwitches) {
        let ts = self.mission.sample_time;
        let lim = sw.position_integrator_limit;
        let decay = (-sw.position_integrator_leak * ts).exp();
        for j in 0..3 {
            if !self.position_integral_on(j) {
                continue;
            }
            let old = self.pos_integrator[j];
            let next = (decay * old + ts * (x[ix::N + j] - xt[ix::N + j])).clamp(-lim, lim);
            let delta = next - old;
            // Command change caused by this increment: −K[:, I_POS + j] · delta.
            let winds_up =
                (0..NU).any(|i| saturated[i] != 0.0 && -self.gain[(i, I_POS + j)] * delta * saturated[i] > 0.0);
            if next.is_finite() && !winds_up {
                self.pos_integrator[j] = next;
            }
        }
    }

    /// Diagnostics of the sample: the reference position (NED), airspeed and phase, and the
    /// distance of the measured position `measured_neh` from the reference.
    pub(crate) fn diagnostics(&self, t: f64, measured_neh: &Vector3<f64>, r: &Reference) -> Diagnostics {
        let ref_neh = &r.pos_neh;
        Diagnostics {
            ref_pos_ned: Vector3::new(ref_neh.x, ref_neh.y, -ref_neh.z),
            ref_airspeed: r.point.v,
            phase: r.ground.map_or(self.mission.phase_at(t).0, |v| v.phase),
            pos_error: flight_mission::distance(measured_neh, ref_neh),
        }
    }
}
