//! Mixing and saturation stage (Fig. 4.1, the actuator blocks; §4.2.2 Table 4.1, §4.2.3
//! Table 4.2): the virtual commands are allocated to the surfaces — δe = δm, δfc = r_n δm;
//! δa = δfd = δA; δr = δR, δv = r_v δR — and each clamped individually (so the elevator keeps
//! working when the collective flaps, at |r_n| ≈ 1.86 δm, saturate), thrust to
//! [thrust_min, thrust_max]; a notice is raised when a command newly saturates. Tuned
//! configuration, in wind: a larger collective-flap factor off the hover (README, "Robustness
//! to the aerodynamic uncertainty").

use crate::integrators::VirtualCommands;
use crate::{TsdController, COMMAND_NAMES};
use flight_mission::{Command, Notice};
use tailsitter_physics::Airframe;

/// Table 4.1: lift coefficients of the elevator and the collective flaps (per rad).
pub const TABLE_4_1_LIFT: (f64, f64) = (1.246, 0.748);
/// Table 4.2: side-force coefficients of the rudder and the vertical flaps (per rad).
pub const TABLE_4_2_SIDE_FORCE: (f64, f64) = (1.008, 0.312);
/// Collective-flap mixing factor off the hover in wind ([`TsdController::scheduled_mixing_ratios`]).
pub const WIND_FLAP_MIXING_FACTOR: f64 = 1.5;
/// Band of the air-data wind estimate (m/s) over which it is blended in.
pub const WIND_FLAP_MIXING_BAND: (f64, f64) = (0.5, 1.0);

impl TsdController {
    /// Mixing ratios (r_n, r_v): δfc = r_n·δm, δe = δm (4.2.12–4.2.13, Table 4.1) and
    /// δv = r_v·δR, δr = δR (Table 4.2), r = −k·(force of the main surface)/(force of the
    /// flap) so that the mixed actuator's force is −(k − 1) times the main surface's, of
    /// opposite sign, and the right-half-plane zero of (4.2.11) moves to the left (4.2.14).
    /// With `alpha_dependent_mixing` off (D-4.5, D-4.6) the printed constants: Table 4.1's
    /// C_Lδe/C_Lδfc = 1.246/0.748 and Table 4.2's C_Yδr/C_Yδv = 1.008/0.312, times the factors
    /// (1.1: r = −1.833, r_v = −3.554).
    pub fn mixing_ratios(&self, alpha: f64) -> (f64, f64) {
        if !crate::deviations::Deviations::of(&self.params).alpha_dependent_mixing {
            return (
                -self.params.flap_mixing_factor * TABLE_4_1_LIFT.0 / TABLE_4_1_LIFT.1,
                -self.params.vertical_flap_mixing_factor * TABLE_4_2_SIDE_FORCE.0 / TABLE_4_2_SIDE_FORCE.1,
            );
        }
        let c = self.airframe.coefficients(alpha);
        let rn = -self.params.flap_mixing_factor * c.c_L_de / c.c_L_dfc;
        let rv = -self.params.vertical_flap_mixing_factor * c.c_Y_dr / c.c_Y_dv;
        (rn, rv)
    }

    /// The mixing ratios at the flight condition `fc`: [`Self::mixing_ratios`], with the
    /// collective flaps' factor raised to [`WIND_FLAP_MIXING_FACTOR`] off the hover in wind
    /// (tuned configuration). The campaign scales C_Lδe by up to × 1.5 (Table 5.1) but not C_Lδfc:
    /// with the factor k the mixed lift (k_Lδe − k) C_Lδe changes sign, and the
    /// right-half-plane zero of (4.2.11) returns, once the elevator is k times the model's.
    /// 1.5 covers the range in the transitions and level flight, where |δm| stays small; in
    /// hover and the landing (|δm| up to the flaps' reach in wind) the printed 1.1 stays.
    /// Weighted with the reference airspeed over the first m/s above v_vertical and with the
    /// mission logic's air-data wind estimate over 0.5–1 m/s: still air is unchanged.
    pub(crate) fn scheduled_mixing_ratios(&self, fc: &crate::FlightCondition) -> (f64, f64) {
        let (rn, rv) = self.mixing_ratios(fc.alpha);
        if !crate::deviations::Deviations::of(&self.params).alpha_dependent_mixing {
            return (rn, rv);
        }
        let wind = self.wind_mission.wind_speed();
        let windy = if wind.is_finite() {
            crate::band_weight(wind, WIND_FLAP_MIXING_BAND)
        } else {
            0.0
        };
        let v0 = self.mission.v_vertical;
        let w = windy * crate::band_weight(fc.reference_airspeed, (v0, v0 + 1.0));
        if w <= 0.0 {
            return (rn, rv);
        }
        let k = self.params.flap_mixing_factor;
        (rn * crate::lerp(1.0, k.max(WIND_FLAP_MIXING_FACTOR) / k, w), rv)
    }

    /// Notice of the first command (in [`COMMAND_NAMES`] order) that saturates at this
    /// sample and did not at the last one; remembers this sample's saturations.
    pub(crate) fn saturation_notice(&mut self, u: &VirtualCommands, mixing: (f64, f64)) -> Option<Notice> {
        let diff_flaps = crate::deviations::Deviations::of(&self.params).roll_differential_flaps;
        let mask = saturation_mask(u, mixing, diff_flaps, &self.airframe);
        let fresh = mask & !self.saturated;
        self.saturated = mask;
        (fresh != 0).then(|| Notice::Saturated(COMMAND_NAMES[fresh.trailing_zeros() as usize]))
    }
}

/// The actuator command of the virtual commands `u` with the mixing ratios (r_n, r_v), each
/// clamped, and the saturated virtual commands (T, δm, δA, δR) the anti-windup tracks.
/// `diff_flaps` (D-4.4): the differential flaps follow δA; otherwise they stay at 0.
pub(crate) fn allocate(
    u: &VirtualCommands,
    (rn, rv): (f64, f64),
    diff_flaps: bool,
    af: &Airframe,
) -> (Command, VirtualCommands) {
    let lim = af.deflection_limit;
    let sat = VirtualCommands {
        thrust: u.thrust.clamp(af.thrust_min, af.thrust_max),
        dm: u.dm.clamp(-lim, lim),
        da: u.da.clamp(-lim, lim),
        dr: u.dr.clamp(-lim, lim),
    };
    let command = Command {
        thrust: sat.thrust,
        elevator: sat.dm,
        aileron: sat.da,
        rudder: sat.dr,
        flap_collective: (rn * u.dm).clamp(-lim, lim),
        flap_differential: if diff_flaps { sat.da } else { 0.0 },
        vertical_flap: (rv * u.dr).clamp(-lim, lim),
    };
    (command, sat)
}

/// Bit mask of the commands outside their limits, in [`COMMAND_NAMES`] order.
fn saturation_mask(u: &VirtualCommands, (rn, rv): (f64, f64), diff_flaps: bool, af: &Airframe) -> u32 {
    let lim = af.deflection_limit;
    let values = [
        (u.thrust, af.thrust_min, af.thrust_max),
        (u.dm, -lim, lim),
        (u.da, -lim, lim),
        (u.dr, -lim, lim),
        (rn * u.dm, -lim, lim),
        (if diff_flaps { u.da } else { 0.0 }, -lim, lim),
        (rv * u.dr, -lim, lim),
    ];
    let mut mask = 0u32;
    for (k, (x, lo, hi)) in values.iter().enumerate() {
        if x < lo || x > hi {
            mask |= 1 << k;
        }
    }
    mask
}

#[cfg(test)]
mod tests {
    use crate::TsdController;
    use flight_mission::MissionParams;
    use tailsitter_physics::Airframe;

    #[test]
    fn mixing_ratio_of_table_4_1_and_4_2() {
        let ctl = TsdController::with_mission(MissionParams::default()).unwrap();
        let (rn, rv) = ctl.mixing_ratios(0.0);
        let af = Airframe::default();
        // Table 4.1 uses C_Lδe = 1.246, C_Lδfc = 0.748: r = −1.833; the App. C numbers at α = 0
        // give −1.1·1.2618/0.7479.
        assert!((rn - (-1.1 * 1.2618 / 0.7479)).abs() < 1e-12);
        assert!((-1.1f64 * 1.246 / 0.748 - (-1.833)).abs() < 1e-3);
        let c_l_mixed = af.c_L_de_a0 + rn * af.c_L_dfc_a0;
        let c_m_mixed = af.c_m_de_a0 + rn * af.c_m_dfc_a0;
        // Mixed lift = −0.1 × elevator lift; mixed moment ≈ −1.66 (Table 4.1: −0.1246, −1.657).
        assert!((c_l_mixed + 0.1 * af.c_L_de_a0).abs() < 1e-12);
        assert!((c_m_mixed - (-1.657)).abs() < 0.02, "{c_m_mixed}");
        // Table 4.2: side force −0.101, yaw moment −0.327.
        let c_y_mixed = af.c_Y_dr_a0 + rv * af.c_Y_dv_a0;
        let c_n_mixed = af.c_n_dr_a0 + rv * af.c_n_dv_a0;
        assert!((c_y_mixed + 0.1 * af.c_Y_dr_a0).abs() < 1e-12);
        assert!((c_n_mixed - (-0.327)).abs() < 0.01, "{c_n_mixed}");
    }

    #[test]
    fn wind_flap_factor_leaves_still_air_and_hover_unchanged() {
        use crate::FlightCondition;
        let ctl = TsdController::with_mission(MissionParams::default()).unwrap();
        let fc = FlightCondition {
            airspeed: 15.0,
            alpha: 0.1,
            thrust: 10.0,
            induced_velocity: 2.0,
            axial_airspeed: 15.0,
            reference_airspeed: 15.0,
            hover_wind: 0.0,
            crossflow: 0.0,
            gust_weight: 0.0,
        };
        // No wind estimate yet, or still air: the printed factors.
        assert_eq!(ctl.scheduled_mixing_ratios(&fc), ctl.mixing_ratios(0.1));
        let mut ctl = ctl;
        ctl.wind_mission.restore(&[0.3, 0.3, 0.0, 0.0]);
        assert_eq!(ctl.scheduled_mixing_ratios(&fc), ctl.mixing_ratios(0.1));
        // In a 3 m/s wind: 1.5 instead of 1.1 off the hover, the printed factor in hover.
        ctl.wind_mission.restore(&[3.0, 0.0, 0.0, 0.0]);
        let (rn0, rv0) = ctl.mixing_ratios(0.1);
        let (rn, rv) = ctl.scheduled_mixing_ratios(&fc);
        assert!(
            (rn / rn0 - super::WIND_FLAP_MIXING_FACTOR / 1.1).abs() < 1e-12,
            "{rn} {rn0}"
        );
        assert_eq!(rv, rv0);
        let hover = FlightCondition {
            reference_airspeed: ctl.mission().v_vertical,
            ..fc
        };
        assert_eq!(ctl.scheduled_mixing_ratios(&hover), (rn0, rv0));
        // The mixed lift stays opposite to the elevator's up to C_Lδe × 1.5 (the campaign's largest).
        let af = Airframe::default();
        let c = af.coefficients(0.1);
        assert!(1.49 * c.c_L_de + rn * c.c_L_dfc < 0.0);
        assert!(1.49 * c.c_L_de + rn0 * c.c_L_dfc > 0.0);
    }

    /// Zeros of C_W/δ for the short-period model with the direct lift of the surfaces,
    /// α̇ = a11 α + Q + (Z_δ/V̄) δ, Q̇ = a21 α + a22 Q + b2 δ, C_W = V̄ a11 α + Z_δ δ:
    /// N(s) = Z_δ (s² − (a11 + a22) s + a11 a22 − a21) + V̄ a11 ((Z_δ/V̄)(s − a22) + b2).
    fn short_period_zeros(v: f64, w: f64, thrust: f64, c_l: f64, c_m: f64) -> [nalgebra::Complex<f64>; 2] {
        let af = Airframe::default();
        let c = af.coefficients(0.0);
        let (rho, s, cbar, m) = (af.air_density, af.wing_area, af.mean_chord, af.mass);
        let qbar = 0.5 * rho * v * v;
        let qbar_s = 0.5 * rho * (v + 2.0 * w).powi(2);
        let a11 = -(qbar * s * c.c_L_alpha + thrust) / (m * v);
        let a21 = qbar * s * cbar * c.c_m_alpha / af.i_yy;
        let a22 = 0.25 * rho * v * s * cbar * cbar * c.c_m_q / af.i_yy;
        let b2 = qbar_s * s * cbar * c_m / af.i_yy;
        let zd = -qbar_s * s * c_l / m;
        // N(s) = n2 s² + n1 s + n0
        let n2 = zd;
        let n1 = -zd * (a11 + a22) + a11 * zd;
        let n0 = zd * (a11 * a22 - a21) + v * a11 * (-(zd / v) * a22 + b2);
        let disc = nalgebra::Complex::new(n1 * n1 - 4.0 * n2 * n0, 0.0).sqrt();
        [(-disc - n1) / (2.0 * n2), (disc - n1) / (2.0 * n2)]
    }

    #[test]
    fn mixing_moves_the_non_minimum_phase_zero_to_the_left_half_plane() {
        let ctl = TsdController::with_mission(MissionParams::default()).unwrap();
        let (rn, _) = ctl.mixing_ratios(0.0);
        let af = Airframe::default();
        // Level flight at 25 m/s (w ≈ 1.2 m/s at the trim thrust), compare (4.2.11) and (4.2.14).
        let elevator = short_period_zeros(25.0, 1.2, 10.0, af.c_L_de_a0, af.c_m_de_a0);
        assert!(elevator.iter().any(|z| z.re > 0.0), "elevator alone: {elevator:?}");
        let mixed = short_period_zeros(
            25.0,
            1.2,
            10.0,
            af.c_L_de_a0 + rn * af.c_L_dfc_a0,
            af.c_m_de_a0 + rn * af.c_m_dfc_a0,
        );
        assert!(mixed.iter().all(|z| z.re < 0.0), "mixed: {mixed:?}");
        println!("zeros of C_W/δe: {elevator:?}; of C_W/δm: {mixed:?}");
    }
}
