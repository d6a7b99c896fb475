//! The switches between the printed thesis and the tuned configuration, one per deviation of
//! docs/THESIS.md and named after the stage that applies it (README, "Deviations, with
//! reasons" and the sections after it).
//!
//! Each is a parameter of its own (`TsdParams::limited_profile` … `integrators_as_accelerations`):
//! −1 follows `configuration` (0 tuned: on; 1 thesis: off — except `slipstream_in_design`, on
//! in both, docs/THESIS.md D-4.3), 0 forces the printed form, 1 the deviation.
//! `TsdParams::effective` resolves them; the switches that stand for parameter values (frame
//! blend, preview, level guidance, normal-vector blend) are applied there, the others here.
//! A stage reads only its own switches.

use crate::TsdParams;

/// Deviations from the printed thesis, per stage of Figs. 4.1–4.2.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Deviations {
    /// Reference: the α- and thrust-limited point-mass profile instead of the quarter loops of
    /// (4.3.31–4.3.40).
    pub limited_profile: bool,
    /// Reference: the weathervane turns the prescribed normal vector of §4.3.2.1 in hover.
    pub weathervane: bool,
    /// Gain schedule: in hover in wind the loops are designed at α = 0 and 1.3 V̄, the path
    /// frame kept and the roll and normal poles slowed (README, "Hover in a wind step",
    /// "Hover in a span-wise wind").
    pub hover_wind_design: bool,
    /// Guidance (4.3.24): in hover the poles are blended on the axial airspeed, not on V̄.
    pub guidance_axial_schedule: bool,
    /// Guidance (4.3.24): off the hover the pair across the path is Table 4.3's level pair.
    pub guidance_lateral_pair: bool,
    /// Guidance (4.3.24): the feedback −K_P e_P − K_V e_V is bounded in norm.
    pub guidance_feedback_bound: bool,
    /// Normal loop (4.2.15): the steady state at the reference's normal specific acceleration
    /// is fed forward.
    pub normal_feedforward: bool,
    /// Directional loop (4.2.29): the weathercock moment of the sideslip is fed forward.
    pub weathercock_feedforward: bool,
    /// Normal loop (4.2.17), D-4.1: Z_α with the thrust term −T cos α (printed: a11 = −q̄S
    /// C_Lα/(m V̄)).
    pub normal_thrust_term: bool,
    /// Directional loop (4.2.31), D-4.2: Y_β with the thrust term −T cos α.
    pub lateral_thrust_term: bool,
    /// Design, D-4.3: the slip-stream q̄_s on the surfaces behind the propellers in b2, b21,
    /// b31, b32 (free-stream q̄ otherwise).
    pub slipstream_in_design: bool,
    /// Roll loop, D-4.4: ailerons and differential flaps together (printed: δA alone).
    pub roll_differential_flaps: bool,
    /// Mixing, D-4.5/D-4.6: ratios from the derivatives at α (printed: the constants of
    /// Tables 4.1, 4.2).
    pub alpha_dependent_mixing: bool,
    /// Integrators, D-4.14: anti-windup on every loop (printed: the axial loop, §4.2.1).
    pub antiwindup_all_loops: bool,
    /// Integrators, D-4.24: stored as control accelerations b·δ (printed: E, command −K_E E).
    pub integrators_as_accelerations: bool,
}

impl Deviations {
    /// The switches of `params` (resolved by [`TsdParams::switch_on`] if still −1).
    pub fn of(params: &TsdParams) -> Self {
        let on = |s: i32| params.switch_on(s);
        Self {
            limited_profile: on(params.limited_profile),
            weathervane: on(params.weathervane_heading),
            hover_wind_design: on(params.hover_wind_design),
            guidance_axial_schedule: on(params.guidance_axial_schedule),
            guidance_lateral_pair: on(params.guidance_lateral_pair),
            guidance_feedback_bound: on(params.guidance_feedback_bound),
            normal_feedforward: on(params.normal_feedforward),
            weathercock_feedforward: on(params.weathercock_feedforward),
            normal_thrust_term: on(params.normal_thrust_term),
            lateral_thrust_term: on(params.lateral_thrust_term),
            slipstream_in_design: params.slipstream_in_design != 0,
            roll_differential_flaps: on(params.roll_differential_flaps),
            alpha_dependent_mixing: on(params.alpha_dependent_mixing),
            antiwindup_all_loops: on(params.antiwindup_all_loops),
            integrators_as_accelerations: on(params.integrators_as_accelerations),
        }
    }
}
