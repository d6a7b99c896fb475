//! Integrator stage (Fig. 4.1, the integral states E_A, E_C, E_P, E_B of §4.2): the inner
//! loops' integral action, its bumpless start, the virtual commands (T_c, δm, δA, δR) it
//! completes, and back-calculation anti-windup with the tracking gain of §4.2.1.

use crate::axes::LoopAxes;
use crate::design::LoopDesign;
use crate::deviations::Deviations;
use crate::inner_loops::{directional_linearisation, LoopLaws};
use crate::nvd::AccelCommands;
use crate::SampleSignals;

/// Integrator state of the four inner loops: the thrust contribution (N) and, for the
/// surface loops, the contribution to the control *acceleration* b·δ (rad/s²) (pitch, roll,
/// yaw): the command is recovered as u_I/b with the current control effectiveness b, so
/// a trim held by an integrator stays trimmed when the dynamic pressure over the surfaces
/// changes (e.g. the slip-stream when thrust comes on) — integrators in the natural units
/// of a gain-scheduled loop. With `integrators_as_accelerations` off (D-4.24, the printed
/// loops) each holds the integral E of its loop error (E_A, E_C, E_P, E_B) and contributes
/// −K_E E with the current K_E.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) struct Integrators {
    pub thrust: f64,
    pub normal: f64,
    pub roll: f64,
    pub directional: f64,
}

/// The virtual commands (T_c, δm, δA, δR) of the four loops (N, rad), before mixing.
#[derive(Debug, Clone, Copy)]
pub(crate) struct VirtualCommands {
    pub thrust: f64,
    pub dm: f64,
    pub da: f64,
    pub dr: f64,
}

impl Integrators {
    /// Bumpless start: the integrators such that the first command equals the measured
    /// actuator state (the plant's trim; thrust and δe, δa, δr of the surfaces).
    pub fn bumpless_start(&mut self, s: &SampleSignals, laws: &LoopLaws, as_accel: bool) {
        let (meas, d) = (s.meas, &s.d);
        let sf = meas.surfaces; // δe, δa, δr, δfc, δfd, δv
        let da_now = sf[1];
        let dr_f0 = directional_linearisation(d, laws, s.axes.p_s, da_now) + laws.weathercock_ff;
        self.thrust = meas.thrust - laws.thrust_p;
        self.normal = d.b2 * (sf[0] - laws.dm_p);
        self.roll = d.roll_model.3 * (da_now - laws.da_p);
        self.directional = d.b32 * (sf[2] - (laws.dr_state + dr_f0));
        if !as_accel {
            // u_I = b·δ_I = −b K_E E.
            self.thrust /= -d.axial.1;
            self.normal /= -d.b2 * d.normal_gains[2];
            self.roll /= -d.roll_model.3 * d.roll_gains.1;
            self.directional /= -d.b32 * d.directional_gains[2];
        }
    }

    /// The integrators' contributions (T, δm, δA, δR) to the virtual commands.
    fn contributions(&self, d: &LoopDesign, as_accel: bool) -> [f64; 4] {
        if as_accel {
            [
                self.thrust,
                self.normal / d.b2,
                self.roll / d.roll_model.3,
                self.directional / d.b32,
            ]
        } else {
            [
                -d.axial.1 * self.thrust,
                -d.normal_gains[2] * self.normal,
                -d.roll_gains.1 * self.roll,
                -d.directional_gains[2] * self.directional,
            ]
        }
    }

    /// The virtual commands: each loop law plus its integrator, T_c (4.2.8), δm (4.2.15),
    /// δA (4.2.22) and δR = −K_B B_W − K_R R′ − K_E E_B + δR_f + δR_w (4.2.29) with δR_f
    /// at the aileron command clamped to ±`lim`.
    pub fn commands(&self, s: &SampleSignals, laws: &LoopLaws, lim: f64, as_accel: bool) -> VirtualCommands {
        let d = &s.d;
        let c = self.contributions(d, as_accel);
        let da = laws.da_p + c[2];
        let dr_f = directional_linearisation(d, laws, s.axes.p_s, da.clamp(-lim, lim));
        VirtualCommands {
            thrust: laws.thrust_p + c[0],
            dm: laws.dm_p + c[1],
            da,
            dr: laws.dr_state + c[3] + dr_f + laws.weathercock_ff,
        }
    }

    /// One integration step of every loop with back-calculation anti-windup (§4.2.1):
    /// u_I ← u_I + b·(−T_s K_E e + k_aw (u_sat − u)), k_aw = min(1, `antiwindup_gain`·T_s),
    /// b the control effectiveness, e the loop errors of [`loop_errors`]. Only finite values
    /// are committed. `dev`: with `antiwindup_all_loops` off (D-4.14) only the axial loop
    /// has the tracking term (§4.2.1); with `integrators_as_accelerations` off (D-4.24)
    /// E ← E + T_s e − k_aw (u_sat − u)/K_E.
    #[allow(clippy::too_many_arguments)]
    pub fn anti_windup_step(
        &mut self,
        d: &LoopDesign,
        e: [f64; 4],
        u: &VirtualCommands,
        u_sat: &VirtualCommands,
        ts: f64,
        antiwindup_gain: f64,
        dev: Deviations,
    ) {
        let kaw = (antiwindup_gain * ts).min(1.0);
        let kaw_surfaces = if dev.antiwindup_all_loops { kaw } else { 0.0 };
        let as_accel = dev.integrators_as_accelerations;
        let step = |u_i: &mut f64, b: f64, ke: f64, e: f64, u: f64, u_sat: f64, kaw: f64| {
            let next = if as_accel {
                *u_i + b * (-ts * ke * e + kaw * (u_sat - u))
            } else {
                *u_i + ts * e - kaw * (u_sat - u) / ke
            };
            if next.is_finite() {
                *u_i = next;
            }
        };
        step(&mut self.thrust, 1.0, d.axial.1, e[0], u.thrust, u_sat.thrust, kaw);
        step(
            &mut self.normal,
            d.b2,
            d.normal_gains[2],
            e[1],
            u.dm,
            u_sat.dm,
            kaw_surfaces,
        );
        step(
            &mut self.roll,
            d.roll_model.3,
            d.roll_gains.1,
            e[2],
            u.da,
            u_sat.da,
            kaw_surfaces,
        );
        step(
            &mut self.directional,
            d.b32,
            d.directional_gains[2],
            e[3],
            u.dr,
            u_sat.dr,
            kaw_surfaces,
        );
    }
}

/// The errors the integrators integrate: A_W − A_Wc (4.2.8), C_W − C_Wc (4.2.15),
/// P − P_R (4.2.22), B_W − B_Wc (4.2.29).
pub(crate) fn loop_errors(axes: &LoopAxes, cmd: &AccelCommands, laws: &LoopLaws) -> [f64; 4] {
    [
        axes.a_w - cmd.a_cmd,
        axes.c_w - cmd.c_cmd,
        axes.p_s - laws.p_ref,
        axes.b_w - cmd.b_cmd,
    ]
}
