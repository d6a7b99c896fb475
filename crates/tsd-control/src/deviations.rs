//! The switches between the printed thesis and the tuned configuration, one per deviation and
//! named after the stage that applies it (README, "Deviations, with reasons" and the sections
//! after it).
//!
//! Today all follow `TsdParams::configuration` (0 tuned: all on; 1 thesis: all off); the
//! frame blend and the preview are parameters of their own (`wind_frame_speed_low/high`,
//! `feedforward_lead`, set by `TsdParams::effective`). A stage reads only its own switches,
//! so each can become a parameter without touching the others.

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
}

impl Deviations {
    /// The switches of `params.configuration`: all on when tuned (0), all off for the thesis (1).
    pub fn of(params: &TsdParams) -> Self {
        let tuned = params.configuration == 0;
        Self {
            limited_profile: tuned,
            weathervane: tuned,
            hover_wind_design: tuned,
            guidance_axial_schedule: tuned,
            guidance_lateral_pair: tuned,
            guidance_feedback_bound: tuned,
            normal_feedforward: tuned,
            weathercock_feedforward: tuned,
        }
    }
}
