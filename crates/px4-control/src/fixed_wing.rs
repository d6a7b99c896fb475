//! Fixed-wing loops of PX4: TECS speed and height control (PX4 `src/lib/tecs/TECS.cpp`,
//! `TECSControl::_calcThrottleControl`, `TECSControl::_calcPitchControl`), L1 lateral
//! guidance (PX4 `src/lib/l1/ECL_L1_Pos_Controller.cpp`, `navigate_waypoints`), the
//! attitude controllers (PX4 `src/modules/fw_att_control/ecl_pitch_controller.cpp`,
//! `ecl_roll_controller.cpp`, `ecl_yaw_controller.cpp`: a first-order attitude loop of
//! time constant FW_P_TC / FW_R_TC, coordinated turn, Euler rates to body rates) and the
//! airspeed scaling of the rate loop (PX4 `src/modules/fw_rate_control/FixedwingRateControl.cpp`,
//! `FixedwingRateControl::Run`: torque = (rate PID) · s², feed-forward gain / s,
//! s = FW_AIRSPD_TRIM / airspeed).

use nalgebra::{Vector2, Vector3};

/// TECS gains and the energy rates at the throttle limits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TecsParams {
    pub alt_tc: f64,
    pub tas_tc: f64,
    pub thr_damp: f64,
    pub i_gain_thr: f64,
    pub i_gain_pit: f64,
    pub ptch_damp: f64,
    pub spd_weight: f64,
    pub clmb_max: f64,
    pub sink_min: f64,
    pub sink_max: f64,
    pub thr_trim: f64,
    pub thr_min: f64,
    pub thr_max: f64,
    pub pitch_min: f64,
    pub pitch_max: f64,
    pub gravity: f64,
}

/// TECS state: the throttle and pitch integrators.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Tecs {
    pub thr_int: f64,
    pub pitch_int: f64,
}

/// TECS output: throttle (fraction of T_max) and pitch setpoint (rad, before the offset).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TecsOutput {
    pub throttle: f64,
    pub pitch: f64,
}

impl Tecs {
    /// One update: height `h` and its rate `h_rate`, true airspeed `tas` and its rate
    /// `tas_rate`, setpoints `h_sp` and `tas_sp`, height-rate feed-forward `h_rate_ff`.
    ///
    /// Specific energy rates (per unit weight times g): potential Ṡ_P = g ḣ, kinetic
    /// Ṡ_K = V V̇. Setpoints: ḣ_sp = (h_sp − h)/FW_T_ALT_TC + ff (limited to the sink and climb
    /// limits), V̇_sp = (V_sp − V)/FW_T_TAS_TC. Throttle on the total Ṡ_T = Ṡ_P + Ṡ_K:
    /// the predicted throttle of the setpoint (trim plus the fraction of the energy-rate range
    /// between idle-sink and full-climb), plus damping and integral of the error. Pitch on the
    /// balance Ṡ_B = w_P Ṡ_P − w_K Ṡ_K (w_K = FW_T_SPDWEIGHT, w_P = 2 − w_K): the setpoint
    /// plus damping and integral of the error, divided by V g (climb angle → Ṡ_B).
    #[allow(clippy::too_many_arguments)]
    pub fn update(
        &mut self,
        p: &TecsParams,
        h: f64,
        h_rate: f64,
        tas: f64,
        tas_rate: f64,
        h_sp: f64,
        tas_sp: f64,
        h_rate_ff: f64,
        dt: f64,
    ) -> TecsOutput {
        let g = p.gravity;
        let h_rate_sp = ((h_sp - h) / p.alt_tc + h_rate_ff).clamp(-p.sink_max, p.clmb_max);
        let tas_rate_sp = (tas_sp - tas) / p.tas_tc;
        let spe_rate_sp = h_rate_sp * g;
        let ske_rate_sp = tas * tas_rate_sp;
        let spe_rate = h_rate * g;
        let ske_rate = tas * tas_rate;
        // Throttle.
        let ste_rate_max = p.clmb_max * g;
        let ste_rate_min = -p.sink_min * g;
        let ste_rate_sp = (spe_rate_sp + ske_rate_sp).clamp(ste_rate_min, ste_rate_max);
        let ste_rate_err = ste_rate_sp - (spe_rate + ske_rate);
        let to_throttle = 1.0 / (ste_rate_max - ste_rate_min);
        let predicted = if ste_rate_sp >= 0.0 {
            p.thr_trim + ste_rate_sp / ste_rate_max * (p.thr_max - p.thr_trim)
        } else {
            p.thr_trim - ste_rate_sp / ste_rate_min * (p.thr_min - p.thr_trim)
        };
        let unclamped = predicted + ste_rate_err * p.thr_damp * to_throttle + self.thr_int;
        let throttle = unclamped.clamp(p.thr_min, p.thr_max);
        // Integrator, not further into a saturated throttle.
        let d_int = ste_rate_err * p.i_gain_thr * to_throttle * dt;
        let winding_up = (unclamped >= p.thr_max && d_int > 0.0) || (unclamped <= p.thr_min && d_int < 0.0);
        if !winding_up && d_int.is_finite() {
            self.thr_int = (self.thr_int + d_int).clamp(-(p.thr_max - p.thr_min), p.thr_max - p.thr_min);
        }
        // Pitch.
        let w_k = p.spd_weight.clamp(0.0, 2.0);
        let w_p = 2.0 - w_k;
        let seb_rate_sp = w_p * spe_rate_sp - w_k * ske_rate_sp;
        let seb_rate = w_p * spe_rate - w_k * ske_rate;
        let seb_err = seb_rate_sp - seb_rate;
        let climb_to_seb = tas.max(1.0) * g;
        let pitch_unc = (seb_rate_sp + seb_err * p.ptch_damp + self.pitch_int) / climb_to_seb;
        let pitch = pitch_unc.clamp(p.pitch_min, p.pitch_max);
        let d_pint = seb_err * p.i_gain_pit * dt;
        let pitch_wind = (pitch_unc >= p.pitch_max && d_pint > 0.0) || (pitch_unc <= p.pitch_min && d_pint < 0.0);
        if !pitch_wind && d_pint.is_finite() {
            let lim = climb_to_seb * (p.pitch_max - p.pitch_min);
            self.pitch_int = (self.pitch_int + d_pint).clamp(-lim, lim);
        }
        TecsOutput { throttle, pitch }
    }
}

/// L1 lateral acceleration (m/s²) towards the straight line through `a` along the unit
/// direction `dir` (north-east), at position `pos` with ground velocity `vel` (north-east):
/// L1 distance = FW_L1_PERIOD · FW_L1_DAMPING / π · |v|, η = η_cross-track + η_heading
/// (bounded by ±90°), a = 4 ζ² |v|² / L1 · sin η.
pub fn l1_lateral_accel(
    period: f64,
    damping: f64,
    a: &Vector2<f64>,
    dir: &Vector2<f64>,
    pos: &Vector2<f64>,
    vel: &Vector2<f64>,
) -> f64 {
    let speed = vel.norm().max(3.0);
    let l1_ratio = period * damping / core::f64::consts::PI;
    let l1 = l1_ratio * speed;
    let k_l1 = 4.0 * damping * damping;
    let rel = pos - a;
    // Cross-track distance, positive right of the line.
    let xtrack = dir.x * rel.y - dir.y * rel.x;
    let v = if vel.norm() > 0.1 { *vel } else { *dir * speed };
    let v_along = v.dot(dir);
    let v_cross = dir.x * v.y - dir.y * v.x;
    let eta2 = v_cross.atan2(v_along);
    let eta1 = (-xtrack / l1)
        .clamp(-1.0, 1.0)
        .asin()
        .clamp(-0.25 * core::f64::consts::PI, 0.25 * core::f64::consts::PI);
    let eta = (eta1 - eta2).clamp(-core::f64::consts::FRAC_PI_2, core::f64::consts::FRAC_PI_2);
    k_l1 * speed * speed / l1 * eta.sin()
}

/// Body-rate setpoint of the fixed-wing attitude loops: Euler-rate setpoints φ̇ = (φ_sp − φ)/FW_R_TC,
/// θ̇ = (θ_sp − θ)/FW_P_TC and the coordinated-turn ψ̇ = g tan φ / V, mapped to body rates
/// (Euler 3-2-1 kinematics).
pub fn fw_attitude_rates(
    euler: &Vector3<f64>,
    roll_sp: f64,
    pitch_sp: f64,
    r_tc: f64,
    p_tc: f64,
    airspeed: f64,
    gravity: f64,
) -> Vector3<f64> {
    let (phi, theta) = (euler.x, euler.y);
    let phi_dot = (roll_sp - phi) / r_tc;
    let theta_dot = (pitch_sp - theta) / p_tc;
    let psi_dot = gravity * phi.tan().clamp(-5.0, 5.0) / airspeed.max(1.0);
    let (sp, cp) = phi.sin_cos();
    let (st, ct) = theta.sin_cos();
    Vector3::new(
        phi_dot - st * psi_dot,
        cp * theta_dot + sp * ct * psi_dot,
        -sp * theta_dot + cp * ct * psi_dot,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tecs() -> TecsParams {
        TecsParams {
            alt_tc: 5.0,
            tas_tc: 5.0,
            thr_damp: 0.1,
            i_gain_thr: 0.3,
            i_gain_pit: 0.1,
            ptch_damp: 0.1,
            spd_weight: 1.0,
            clmb_max: 5.0,
            sink_min: 2.0,
            sink_max: 5.0,
            thr_trim: 0.2,
            thr_min: 0.0,
            thr_max: 1.0,
            pitch_min: -0.5,
            pitch_max: 0.5,
            gravity: 9.81,
        }
    }

    #[test]
    fn tecs_trim_at_the_setpoint_and_energy_split() {
        let mut t = Tecs::default();
        let o = t.update(&tecs(), 50.0, 0.0, 25.0, 0.0, 50.0, 25.0, 0.0, 0.02);
        assert!((o.throttle - 0.2).abs() < 1e-12 && o.pitch.abs() < 1e-12, "{o:?}");
        // Too low: more throttle and pitch up. Too slow at the right height: more throttle, pitch down.
        let low = Tecs::default().update(&tecs(), 45.0, 0.0, 25.0, 0.0, 50.0, 25.0, 0.0, 0.02);
        assert!(low.throttle > 0.2 && low.pitch > 0.0, "{low:?}");
        let slow = Tecs::default().update(&tecs(), 50.0, 0.0, 20.0, 0.0, 50.0, 25.0, 0.0, 0.02);
        assert!(slow.throttle > 0.2 && slow.pitch < 0.0, "{slow:?}");
    }

    #[test]
    fn l1_turns_towards_the_line() {
        let a = Vector2::zeros();
        let dir = Vector2::new(1.0, 0.0);
        // 10 m east of a northward line flying north: accelerate west (negative).
        let acc = l1_lateral_accel(20.0, 0.75, &a, &dir, &Vector2::new(0.0, 10.0), &Vector2::new(25.0, 0.0));
        assert!(acc < 0.0, "{acc}");
        let on = l1_lateral_accel(20.0, 0.75, &a, &dir, &Vector2::new(5.0, 0.0), &Vector2::new(25.0, 0.0));
        assert!(on.abs() < 1e-12);
    }

    #[test]
    fn attitude_rates_level_turn() {
        let w = fw_attitude_rates(&Vector3::new(0.3, 0.0, 0.0), 0.3, 0.0, 0.4, 0.4, 25.0, 9.81);
        let psi_dot = 9.81 * 0.3f64.tan() / 25.0;
        assert!((w.z - 0.3f64.cos() * psi_dot).abs() < 1e-12 && (w.y - 0.3f64.sin() * psi_dot).abs() < 1e-12);
    }
}
