//! Inner-loop stage (Fig. 4.1, §4.2): the control laws of the axial (4.2.1–4.2.8), normal
//! (4.2.9–4.2.17), roll-rate (4.2.21–4.2.26) and directional (4.2.27–4.2.31) specific-
//! acceleration loops with their feedback linearisation (App. B) and feed-forwards, without
//! the integrators (added in [`crate::integrators`]).

use crate::axes::{Airflow, LoopAxes};
use crate::design::LoopDesign;
use crate::deviations::Deviations;
use crate::SampleSignals;
use crate::{band_weight, gains, TsdController, HOVER_WEATHERCOCK_CROSSFLOW, NORMAL_FEEDFORWARD_RAMP};
use flight_mission::Measurement;
use nalgebra::Vector3;

/// The loop laws' parts outside the integrators.
#[derive(Debug, Clone, Copy)]
pub(crate) struct LoopLaws {
    /// Axial (4.2.8): −K_A A_W (N).
    pub thrust_p: f64,
    /// Normal (4.2.15): −K_C (C_W − C*) − K_Q (Q′ − Q′*) + δm* + δmg (rad).
    pub dm_p: f64,
    /// Roll (4.2.22): the roll-rate reference P_R = K_φ φ (4.3.11) and −K_P P + δA_f (rad).
    pub p_ref: f64,
    pub da_p: f64,
    /// Directional state feedback −K_B B_W − K_R R′ (rad).
    pub dr_state: f64,
    /// Gravity along the loop y axis g₂ = κ g e23 and its rate (m/s², m/s³).
    pub g2: f64,
    pub g2_dot: f64,
    /// Weathercock feed-forward δR_w (rad).
    pub weathercock_ff: f64,
}

impl TsdController {
    /// The four inner-loop laws at the sample; `sigma_ahead` is the previewed Σ^RE of the
    /// normal loop's feed-forward ([`crate::guidance_law::feedforward`]), `roll_error` the NVD
    /// error φ (4.3.5). Switches: `normal_feedforward`, `weathercock_feedforward`.
    pub(crate) fn inner_loops(
        &self,
        s: &SampleSignals,
        sigma_ahead: &Vector3<f64>,
        roll_error: f64,
        dev: Deviations,
    ) -> LoopLaws {
        let (meas, d, axes, air, r) = (s.meas, &s.d, &s.axes, &s.air, &s.r);
        let g = self.airframe.gravity;
        let (ka, _) = d.axial;
        let thrust_p = -ka * axes.a_w;
        let ff = if dev.normal_feedforward && !r.ground_phase() {
            let weight = ((r.reference.airspeed - self.mission.v_vertical) / NORMAL_FEEDFORWARD_RAMP).clamp(0.0, 1.0);
            normal_feedforward(d, weight, sigma_ahead, &axes.kw)
        } else {
            (0.0, 0.0, 0.0)
        };
        let dm_p = normal_law(d, axes, g, air.kappa, ff) + self.pitch_guard(s, dev);
        let (p_ref, da_p) = roll_law(d, roll_error, meas.beta, axes);
        let (g2, g2_dot, r_prime) = directional_gravity(d, axes, g, air.kappa);
        let k_d = d.directional_gains;
        // In the take-off and landing phases weighted with the measured wind (README,
        // "Take-off and landing in wind").
        let weathercock_ff = if !dev.weathercock_feedforward {
            0.0
        } else if r.ground_phase() {
            air.hover_wind * self.weathercock_feedforward(meas, d, air)
        } else {
            self.weathercock_feedforward(meas, d, air)
        };
        LoopLaws {
            thrust_p,
            dm_p,
            p_ref,
            da_p,
            dr_state: -k_d[0] * axes.b_w - k_d[1] * r_prime,
            g2,
            g2_dot,
            weathercock_ff,
        }
    }

    /// The normal loop's pitch guard in level flight and the back transition in wind
    /// ([`crate::wind_mission::pitch_guard`]; tuned configuration, not in the take-off and
    /// landing phases; 0 in still air).
    fn pitch_guard(&self, s: &SampleSignals, dev: Deviations) -> f64 {
        if !dev.hover_wind_design || s.r.ground_phase() {
            return 0.0;
        }
        let windy = self.wind_mission.wind_speed() >= self.weathervane.params().release_speed;
        let since_level = s.r.t_mission - self.mission.phase_starts()[flight_mission::Phase::Level as usize];
        crate::wind_mission::pitch_guard(s.meas.alpha, s.axes.q, s.r.reference.phase, windy, since_level)
    }

    /// Weathercock feed-forward of the directional loop (switch `weathercock_feedforward`;
    /// README, "Hover in a span-wise wind"): δR_w = −N̂/(I_zz b32) cancels the yawing moment
    /// of the sideslip, N = q̄Sb C_nβ β of (2.3.11), which the (B_W, R′) model only carries
    /// through B_W = V̄ a11 β (4.2.27). That holds in the wind axes (κ = 1) but not in the path
    /// frame of the hover, where B_W is mostly the wind's side force and the moment is set by
    /// the crossflow: weight 1 − κ, so it fades out as the flow comes along the nose (no double
    /// count in the transitions and level flight, and no jump at the phase boundaries). The
    /// side surfaces see the lateral air velocity v = V̄ sin β at the free-stream speed V̄ over
    /// the share 1 − η of the span and at the slip-stream speed V̄ + 2w ((2.3.18)) over the
    /// share η = min(1, 2D/b) the two propellers' wash covers (D = √(2A/π) each of disc area
    /// A/2), so N̂/I_zz = ½ρSb C_nβ/I_zz · v [(1 − η) V̄ + η (V̄ + 2w)]. Zero in still air.
    fn weathercock_feedforward(&self, meas: &Measurement, d: &LoopDesign, air: &Airflow) -> f64 {
        let af = &self.airframe;
        let weight = band_weight(air.crossflow, HOVER_WEATHERCOCK_CROSSFLOW) * (1.0 - air.kappa);
        let eta = (2.0 * (2.0 * af.prop_disc_area / core::f64::consts::PI).sqrt() / af.wing_span).min(1.0);
        let v_lat = meas.airspeed * meas.beta.sin();
        let v_s = meas.airspeed + 2.0 * meas.induced_velocity.max(0.0);
        let yaw_accel = d.weathercock * v_lat * ((1.0 - eta) * meas.airspeed + eta * v_s);
        -weight * yaw_accel / d.b32
    }
}

/// Normal loop's steady-state feed-forward (C*, Q′*, δm*) (switch `normal_feedforward`;
/// README, "Front transition: normal-loop feed-forward"): the steady state of the loop model
/// at the normal part of the reference's own specific acceleration, C* = Σ^RE·k^W (4.3.24,
/// read at t + lead: the steady state the body must be in by then), times `weight` (ramped
/// in over the first NORMAL_FEEDFORWARD_RAMP m/s above the vertical speed). Without it the
/// trajectory's normal acceleration reached δm only through the integrator E_C, ≈ 0.3 s
/// behind: the height lost in the pull-out of a fast front transition. The guidance feedback
/// still enters through E_C alone (fed forward as well, it oscillated in level flight behind
/// the avionics' latency).
fn normal_feedforward(d: &LoopDesign, weight: f64, sigma_ahead: &Vector3<f64>, kw: &Vector3<f64>) -> (f64, f64, f64) {
    if weight > 0.0 {
        let c_ff = weight * sigma_ahead.dot(kw);
        let (q_ff, dm_ff) = gains::normal_steady_state(&d.normal_model, c_ff);
        (c_ff, q_ff, dm_ff)
    } else {
        (0.0, 0.0, 0.0)
    }
}

/// Normal loop (4.2.15) without the integrator, in (C_W, Q′ = Q + g₁/V̄): state feedback
/// about the feed-forward steady state `ff` = (C*, Q′*, δm*) plus the feedback
/// linearisation δmg′ = (a22 g₁ − ġ₁)/(V̄ b2) (App. B; the printed (4.2.16) once −K_Q g₁/V̄
/// is added back). g₁ = κ g e33 and ġ₁ from dk^W/dt = Q_W i^W − P_W j^W with
/// Q_W = −(C_W + g₁)/V̄ (2.5.12), (4.2.17).
fn normal_law(d: &LoopDesign, axes: &LoopAxes, g: f64, kappa: f64, ff: (f64, f64, f64)) -> f64 {
    let (k_n, a22_n, b2, v) = (d.normal_gains, d.a22_n, d.b2, d.v);
    let (c_w, e13, e23, e33, p_s) = (axes.c_w, axes.e13, axes.e23, axes.e33, axes.p_s);
    let (c_ff, q_ff, dm_ff) = ff;
    let g1 = kappa * g * e33;
    let g1_dot = -kappa * g * ((c_w + g * e33) / v * e13 + p_s * e23);
    let q_prime = axes.q + g1 / v;
    let dm_g = (a22_n * g1 - g1_dot) / (v * b2);
    -k_n[0] * (c_w - c_ff) - k_n[1] * (q_prime - q_ff) + dm_ff + dm_g
}

/// Roll-rate loop (4.2.22) with the NVD law (4.3.7–4.3.11): (P_R, δA without integrator).
/// P_R = P_Wc + K_φ φ with P_Wc = 0 (no turns in the mission); δA_f = −(a21 β + a23 R)/b21
/// (4.2.25) cancels the sideslip and yaw-rate roll moments.
fn roll_law(d: &LoopDesign, roll_error: f64, beta: f64, axes: &LoopAxes) -> (f64, f64) {
    let (a21_r, _, a23_r, b21) = d.roll_model;
    let (kp_r, _, kphi) = d.roll_gains;
    let p_ref = kphi * roll_error;
    let da_f = -(a21_r * beta + a23_r * axes.r_s) / b21;
    (p_ref, -kp_r * axes.p_s + da_f)
}

/// Gravity along the loop y axis g₂ = κ g e23 and its rate, from dj^W/dt = −R_W i^W +
/// P_W k^W with R_W = (B_W + g₂)/V̄ (2.5.12), and R′ = R − g₂/V̄ of the directional model
/// (4.2.27): (g₂, ġ₂, R′).
fn directional_gravity(d: &LoopDesign, axes: &LoopAxes, g: f64, kappa: f64) -> (f64, f64, f64) {
    let v = d.v;
    let g2 = kappa * g * axes.e23;
    let g2_dot = kappa * g * (-(axes.b_w + g * axes.e23) / v * axes.e13 + axes.p_s * axes.e33);
    (g2, g2_dot, axes.r_s - g2 / v)
}

/// Feedback linearisation of the directional loop, (4.2.29) derived (the printed one is
/// garbled): δR_f = −(a32 P + b31 δA + a33 g₂/V̄ − ġ₂/V̄)/b32 cancels every term of Ṙ′
/// outside the (B_W, R′) model.
pub(crate) fn directional_linearisation(d: &LoopDesign, laws: &LoopLaws, p_s: f64, da: f64) -> f64 {
    let v = d.v;
    -(d.a32 * p_s + d.b31 * da + d.a33 * laws.g2 / v - laws.g2_dot / v) / d.b32
}
