//! Tuning parameters of the TSD controller (Table 4.3 and §4.2.1, §4.2.2, §4.3.2.1).

use flight_mission::ParamError;

/// Guidance pair of Table 4.3 for level flight, (re, im) (1/s): the thesis configuration's
/// level-flight guidance, and in the tuned configuration the guidance *across* the path
/// outside the hover (README, "Robustness on uncertain plants").
pub const TABLE_4_3_GUIDANCE_LEVEL: (f64, f64) = (-0.75, 0.45);

/// Largest guidance feedback acceleration of the tuned configuration, ‖−K_P e_P − K_V e_V‖ of
/// (4.3.24) (m/s²): half a g on top of the profile's feed-forward (README, "Robustness on
/// uncertain plants").
pub const GUIDANCE_FEEDBACK_LIMIT: f64 = 5.0;

/// Hover in wind, tuned configuration: the loops are designed at α = 0 and at this multiple of
/// the measured airspeed V̄ once the air flows across the nose (README, "Hover in a wind
/// step"). Found by a scan of the issue-16 hover steps: 1.25–1.4 hold the same cases.
pub const HOVER_WIND_DESIGN_SPEED_FACTOR: f64 = 1.3;

/// Crossflow V̄ √(1 − cos²α cos²β) (the air-velocity component across the nose, m/s) over
/// which the hover-in-wind design condition is blended in: none at the first value (still air,
/// the calm missions unchanged), fully at the second.
pub const HOVER_WIND_CROSSFLOW: (f64, f64) = (1.0, 3.0);

/// Tuned configuration, missions in wind: the band (m/s) of the mission logic's 1 s air-data
/// wind estimate over which the wind axes are also limited by the air velocity *along the
/// reference path* (none at the first value, the weathervane's release speed, so still air is
/// unchanged; fully from the second, its engage speed). With the wind behind, the air flows
/// along the nose while the path climbs and turns away from it; the axial airspeed alone
/// blended in wind axes that pointed against the path (README, "Missions in wind").
pub const PATH_AIR_WIND_BAND: (f64, f64) = (1.0, 3.0);

/// Airspeed band (m/s) over which the measured α enters the loop design in hover (tuned
/// configuration, the reference at the vertical speed, not the take-off and landing phases):
/// none at the first value, fully from the second (the still-air climb's 3 m/s, the calm
/// missions unchanged). Below 2 m/s the air data are no flight condition — a gust along the
/// nose of the climb leaves 1 m/s at α ≈ ±80–90° — and the coefficients and mixing ratios
/// designed there put the rudder, vertical flaps and ailerons into a bang-bang cycle that
/// tumbled the aircraft (README, "Missions in wind").
pub const HOVER_LOW_AIRSPEED_ALPHA: (f64, f64) = (2.0, 3.0);

/// Tuned configuration: the normal loop's steady-state feed-forward of the reference's normal
/// acceleration ([`crate::gains::normal_steady_state`]) is blended in as the reference airspeed rises from
/// v_vertical to v_vertical + this (m/s): none in the hover (the hover-in-wind design and the
/// take-off and landing phases are untouched), full through the transitions and level flight
/// (README, "Front transition: normal-loop feed-forward").
pub const NORMAL_FEEDFORWARD_RAMP: f64 = 1.0;

/// Hover in wind, tuned configuration: factor on the roll-rate pair of the NVD loop (the
/// rotation about the nose, i.e. the heading in hover) at the hover-in-wind design condition,
/// blended in with the [`HOVER_WIND_CROSSFLOW`] weight (README, "Hover in a span-wise wind").
/// Scanned 0.5–0.8: the same cases held; 1 (none) loses Jacobi 7/8 m/s to a roll–yaw limit
/// cycle.
pub const HOVER_WIND_ROLL_POLE_FACTOR: f64 = 0.7;

/// Hover in wind, tuned configuration: factor on the poles of the normal-acceleration loop in
/// a strong crossflow, blended in over [`HOVER_WIND_NORMAL_CROSSFLOW`] (times the
/// [`HOVER_WIND_CROSSFLOW`] weight). Scanned 0.6–0.85: the same cases held; 1 loses Jacobi
/// 5 m/s along the belly.
pub const HOVER_WIND_NORMAL_POLE_FACTOR: f64 = 0.7;

/// Hover in wind, tuned configuration: factor on the normal-acceleration poles blended in with
/// the [`HOVER_WIND_CROSSFLOW`] weight alone (below the strong crossflow of
/// [`HOVER_WIND_NORMAL_CROSSFLOW`]; the smaller of the two factors applies; not in the take-off
/// and landing phases, where it cost landings in turbulence). Scanned 0.7–0.8. The one-sample
/// delay of a Jacobi master costs the hover's pitch loop its margin: in moderate turbulence
/// at 0 m/s mean wind (crossflow 1–2 m/s) the elevator and collective flaps went into a
/// bang-bang pitch cycle (≈ 3 Hz, α ±0.5 rad) with the full poles (README, "Missions in wind").
pub const HOVER_GUST_NORMAL_POLE_FACTOR: f64 = 0.75;

/// Crossflow (m/s) over which [`HOVER_WIND_NORMAL_POLE_FACTOR`] is blended in: from 2 m/s, so
/// that the pitch-up at the end of the back transition (crossflow ≈ 1 m/s) keeps the full
/// normal poles (blended in from 1 m/s, a 5 m/s gust from the north there went into a pitch
/// limit cycle under Jacobi, 8.5 m).
pub const HOVER_WIND_NORMAL_CROSSFLOW: (f64, f64) = (2.0, 4.0);

/// Crossflow (m/s) over which the weathercock feed-forward of the directional loop is blended
/// in (tuned configuration; times 1 − κ, the share of the path frame): none below a quarter
/// metre per second, full from half a metre per second (README, "Hover in a span-wise wind").
pub const HOVER_WEATHERCOCK_CROSSFLOW: (f64, f64) = (0.25, 0.5);

/// Every tuning parameter of the controller. Field names are the FMU parameter names
/// (group `tsd` of `modelDescription/tailsitter_tsd.json`).
///
/// Poles are given per flight phase (vertical / level, Table 4.3) and blended linearly
/// in the airspeed between `v_vertical` and `v_level` of the mission. A loop's poles are
/// "real" (a real pole) and "re ± i·im" (a complex pair).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TsdParams {
    /// Axial specific acceleration, first pole, vertical flight (1/s).
    pub axial_pole_1_vertical: f64,
    /// Axial specific acceleration, second pole, vertical flight (1/s).
    pub axial_pole_2_vertical: f64,
    /// Axial specific acceleration, first pole, level flight (1/s).
    pub axial_pole_1_level: f64,
    /// Axial specific acceleration, second pole, level flight (1/s).
    pub axial_pole_2_level: f64,
    /// Roll rate pair, real part, vertical flight (1/s).
    pub roll_pole_re_vertical: f64,
    /// Roll rate pair, imaginary part, vertical flight (1/s).
    pub roll_pole_im_vertical: f64,
    /// Roll rate pair, real part, level flight (1/s).
    pub roll_pole_re_level: f64,
    /// Roll rate pair, imaginary part, level flight (1/s).
    pub roll_pole_im_level: f64,
    /// Normal specific acceleration, real pole, vertical flight (1/s).
    pub normal_pole_real_vertical: f64,
    /// Normal specific acceleration pair, real part, vertical flight (1/s).
    pub normal_pole_re_vertical: f64,
    /// Normal specific acceleration pair, imaginary part, vertical flight (1/s).
    pub normal_pole_im_vertical: f64,
    /// Normal specific acceleration, real pole, level flight (1/s).
    pub normal_pole_real_level: f64,
    /// Normal specific acceleration pair, real part, level flight (1/s).
    pub normal_pole_re_level: f64,
    /// Normal specific acceleration pair, imaginary part, level flight (1/s).
    pub normal_pole_im_level: f64,
    /// Directional (lateral specific acceleration), real pole, vertical flight (1/s).
    pub directional_pole_real_vertical: f64,
    /// Directional pair, real part, vertical flight (1/s).
    pub directional_pole_re_vertical: f64,
    /// Directional pair, imaginary part, vertical flight (1/s).
    pub directional_pole_im_vertical: f64,
    /// Directional, real pole, level flight (1/s).
    pub directional_pole_real_level: f64,
    /// Directional pair, real part, level flight (1/s).
    pub directional_pole_re_level: f64,
    /// Directional pair, imaginary part, level flight (1/s).
    pub directional_pole_im_level: f64,
    /// Normal-vector-direction pole, vertical flight (1/s).
    pub nvd_pole_vertical: f64,
    /// Normal-vector-direction pole, level flight (1/s).
    pub nvd_pole_level: f64,
    /// Guidance pair, real part, vertical flight (1/s).
    pub guidance_pole_re_vertical: f64,
    /// Guidance pair, imaginary part, vertical flight (1/s).
    pub guidance_pole_im_vertical: f64,
    /// Guidance pair, real part, level flight (1/s).
    pub guidance_pole_re_level: f64,
    /// Guidance pair, imaginary part, level flight (1/s).
    pub guidance_pole_im_level: f64,
    /// Integrator anti-windup tracking gain (§4.2.1: 50), on every inner loop or on the axial
    /// loop only (`antiwindup_all_loops`) (1/s).
    pub antiwindup_gain: f64,
    /// Factor k of the elevator/collective-flap mixing r = −k·C_Lδe/C_Lδfc (4.2.12: 1.1).
    pub flap_mixing_factor: f64,
    /// Factor k of the rudder/vertical-flap mixing r = −k·C_Yδr/C_Yδv (Table 4.2: 1.1).
    pub vertical_flap_mixing_factor: f64,
    /// Airspeed floor of the gain schedule: the loop models divide by V̄ (m/s).
    pub min_airspeed: f64,
    /// Time over which the commanded normal vector changes between the prescribed one
    /// (vertical flight, transitions) and the one from the guidance acceleration (level
    /// flight, (4.3.27–4.3.30)) at the start and end of level flight (s).
    pub normal_vector_blend_time: f64,
    /// Below this normal part of the commanded acceleration the prescribed normal vector is
    /// used even in level flight (§4.3.2.1) (m/s²).
    pub min_normal_accel: f64,
    /// Below this axial airspeed V̄ cos α cos β the specific accelerations are resolved in
    /// the reference-path frame instead of the wind axes (the wind axes turn as fast as the
    /// body at low speed, (C_W + g₁)/V̄, and the time-scale separation fails; the axial
    /// component keeps a hover crosswind out of the blend) (m/s).
    pub wind_frame_speed_low: f64,
    /// Above this axial airspeed V̄ cos α cos β the wind axes are used, as in the thesis;
    /// linear blend between (m/s).
    pub wind_frame_speed_high: f64,
    /// Preview of the feed-forward specific acceleration: Σ^RE of (4.3.24) is taken from the
    /// trajectory this much ahead of the sample, compensating the lag of the inner loops
    /// (servo, thrust and the specific-acceleration poles) at the acceleration steps of the
    /// unsmoothed trajectory (§4.3.3) (s).
    pub feedforward_lead: f64,
    /// 0 = tuned (every deviation switch on), 1 = the thesis as printed (every switch off):
    /// the default of each switch below that is −1; a switch set to 0 or 1 overrides it
    /// (see [`Self::effective`], docs/THESIS.md).
    pub configuration: i32,
    /// Switch (D-4.22, docs/THESIS.md): reference: the α- and thrust-limited point-mass profile (1) instead of the quarter loops of (4.3.31–4.3.40) (0). −1 = follow `configuration`.
    pub limited_profile: i32,
    /// Switch (D-X.1, docs/THESIS.md): reference: the weathervane turns the prescribed normal vector in hover (1) or not (0). −1 = follow `configuration`.
    pub weathervane_heading: i32,
    /// Switch (D-4.25, docs/THESIS.md): gain schedule: hover in wind designed at α = 0 and 1.3 V̄, path frame kept, roll and normal poles slowed (1); the measured condition (0). −1 = follow `configuration`.
    pub hover_wind_design: i32,
    /// Switch (D-4.25, docs/THESIS.md): guidance (4.3.24): in hover the poles blended on the axial airspeed (1) or on V̄ (0). −1 = follow `configuration`.
    pub guidance_axial_schedule: i32,
    /// Switch (D-4.25, docs/THESIS.md): guidance (4.3.24): off the hover, Table 4.3's level pair across the path (1) or one pair (0). −1 = follow `configuration`.
    pub guidance_lateral_pair: i32,
    /// Switch (D-4.25, docs/THESIS.md): guidance (4.3.24): the feedback −K_P e_P − K_V e_V bounded in norm (1) or not (0). −1 = follow `configuration`.
    pub guidance_feedback_bound: i32,
    /// Switch (D-4.25, docs/THESIS.md): normal loop (4.2.15): steady state at the reference's normal acceleration fed forward (1) or not (0). −1 = follow `configuration`.
    pub normal_feedforward: i32,
    /// Switch (D-4.25, docs/THESIS.md): directional loop (4.2.29): weathercock moment of the sideslip fed forward (1) or not (0). −1 = follow `configuration`.
    pub weathercock_feedforward: i32,
    /// Switch (D-4.17, docs/THESIS.md): loop frame: the reference-path frame below `wind_frame_speed_low/high` (1) or the wind axes at every airspeed, §4.2 (0). −1 = follow `configuration`.
    pub low_speed_path_frame: i32,
    /// Switch (D-4.18, docs/THESIS.md): guidance: Σ^RE read `feedforward_lead` ahead (1) or at the sample, (4.3.24) (0). −1 = follow `configuration`.
    pub feedforward_preview: i32,
    /// Switch (D-4.16, docs/THESIS.md): guidance: the level-flight pair `guidance_pole_*_level` as given (1) or Table 4.3's −0.75 ± 0.45i (0). −1 = follow `configuration`.
    pub tuned_level_guidance: i32,
    /// Switch (D-4.1, docs/THESIS.md): normal loop: Z_α = −(q̄S C_Lα + T cos α)/m (1) or the printed a11 = −q̄S C_Lα/(m V̄) of (4.2.17) (0). −1 = follow `configuration`.
    pub normal_thrust_term: i32,
    /// Switch (D-4.2, docs/THESIS.md): directional loop: Y_β = (q̄S C_Yβ − T cos α)/m (1) or the printed a11 = q̄S C_yβ/(m V̄) of (4.2.31) (0). −1 = follow `configuration`.
    pub lateral_thrust_term: i32,
    /// Switch (D-4.3, docs/THESIS.md): b2, b21, b31, b32 with the slip-stream q̄_s = ½ρ(V̄ + 2w)² on the surfaces behind the propellers (1) or the free-stream q̄ on every surface (0). −1 = follow `configuration`.
    pub slipstream_in_design: i32,
    /// Switch (D-4.4, docs/THESIS.md): roll loop through ailerons and differential flaps together (1) or the ailerons δA alone, (4.2.26) (0). −1 = follow `configuration`.
    pub roll_differential_flaps: i32,
    /// Switch (D-4.5, D-4.6, docs/THESIS.md): mixing ratios −k C_Lδe(α)/C_Lδfc(α), −k C_Yδr(α)/C_Yδv(α) (1) or the printed constants of Tables 4.1, 4.2, −k·1.246/0.748 and −k·1.008/0.312 (0). −1 = follow `configuration`.
    pub alpha_dependent_mixing: i32,
    /// Switch (D-4.14, docs/THESIS.md): back-calculation anti-windup on every inner loop (1) or on the axial loop only, §4.2.1 (0). −1 = follow `configuration`.
    pub antiwindup_all_loops: i32,
    /// Switch (D-4.19, docs/THESIS.md): computed normal vector blended over `normal_vector_blend_time` and faded below `min_normal_accel` (1) or switched at the ends of level flight, §4.3.2.1 (0). −1 = follow `configuration`.
    pub normal_vector_blend: i32,
    /// Switch (D-4.24, docs/THESIS.md): integrators stored as control accelerations b·δ (1) or as the integrals E of the printed loops, command −K_E E (0). −1 = follow `configuration`.
    pub integrators_as_accelerations: i32,
}

// `impl Default for TsdParams` (Table 4.3 of the thesis, §4.2.1 anti-windup 50, (4.2.12)
// mixing 1.1): the start values of group `tsd` of modelDescription/tailsitter_tsd.json,
// generated by build.rs.
include!(concat!(env!("OUT_DIR"), "/tsd_params_generated.rs"));

impl TsdParams {
    /// The deviation switches with their names, in declaration order.
    pub fn switches(&self) -> [(&'static str, i32); 19] {
        [
            ("limited_profile", self.limited_profile),
            ("weathervane_heading", self.weathervane_heading),
            ("hover_wind_design", self.hover_wind_design),
            ("guidance_axial_schedule", self.guidance_axial_schedule),
            ("guidance_lateral_pair", self.guidance_lateral_pair),
            ("guidance_feedback_bound", self.guidance_feedback_bound),
            ("normal_feedforward", self.normal_feedforward),
            ("weathercock_feedforward", self.weathercock_feedforward),
            ("low_speed_path_frame", self.low_speed_path_frame),
            ("feedforward_preview", self.feedforward_preview),
            ("tuned_level_guidance", self.tuned_level_guidance),
            ("normal_thrust_term", self.normal_thrust_term),
            ("lateral_thrust_term", self.lateral_thrust_term),
            ("slipstream_in_design", self.slipstream_in_design),
            ("roll_differential_flaps", self.roll_differential_flaps),
            ("alpha_dependent_mixing", self.alpha_dependent_mixing),
            ("antiwindup_all_loops", self.antiwindup_all_loops),
            ("normal_vector_blend", self.normal_vector_blend),
            ("integrators_as_accelerations", self.integrators_as_accelerations),
        ]
    }

    /// Every parameter with its name, in declaration order.
    pub fn named_values(&self) -> [(&'static str, f64); 35] {
        [
            ("axial_pole_1_vertical", self.axial_pole_1_vertical),
            ("axial_pole_2_vertical", self.axial_pole_2_vertical),
            ("axial_pole_1_level", self.axial_pole_1_level),
            ("axial_pole_2_level", self.axial_pole_2_level),
            ("roll_pole_re_vertical", self.roll_pole_re_vertical),
            ("roll_pole_im_vertical", self.roll_pole_im_vertical),
            ("roll_pole_re_level", self.roll_pole_re_level),
            ("roll_pole_im_level", self.roll_pole_im_level),
            ("normal_pole_real_vertical", self.normal_pole_real_vertical),
            ("normal_pole_re_vertical", self.normal_pole_re_vertical),
            ("normal_pole_im_vertical", self.normal_pole_im_vertical),
            ("normal_pole_real_level", self.normal_pole_real_level),
            ("normal_pole_re_level", self.normal_pole_re_level),
            ("normal_pole_im_level", self.normal_pole_im_level),
            ("directional_pole_real_vertical", self.directional_pole_real_vertical),
            ("directional_pole_re_vertical", self.directional_pole_re_vertical),
            ("directional_pole_im_vertical", self.directional_pole_im_vertical),
            ("directional_pole_real_level", self.directional_pole_real_level),
            ("directional_pole_re_level", self.directional_pole_re_level),
            ("directional_pole_im_level", self.directional_pole_im_level),
            ("nvd_pole_vertical", self.nvd_pole_vertical),
            ("nvd_pole_level", self.nvd_pole_level),
            ("guidance_pole_re_vertical", self.guidance_pole_re_vertical),
            ("guidance_pole_im_vertical", self.guidance_pole_im_vertical),
            ("guidance_pole_re_level", self.guidance_pole_re_level),
            ("guidance_pole_im_level", self.guidance_pole_im_level),
            ("antiwindup_gain", self.antiwindup_gain),
            ("flap_mixing_factor", self.flap_mixing_factor),
            ("vertical_flap_mixing_factor", self.vertical_flap_mixing_factor),
            ("min_airspeed", self.min_airspeed),
            ("normal_vector_blend_time", self.normal_vector_blend_time),
            ("min_normal_accel", self.min_normal_accel),
            ("wind_frame_speed_low", self.wind_frame_speed_low),
            ("wind_frame_speed_high", self.wind_frame_speed_high),
            ("feedforward_lead", self.feedforward_lead),
        ]
    }

    /// Whether switch value `switch` (−1 follow `configuration`, 0 printed, 1 addition)
    /// turns its deviation on: −1 gives the `configuration`'s choice — on for 0 (tuned), off
    /// for 1 (the thesis as printed) — and 0 / 1 force it.
    pub fn switch_on(&self, switch: i32) -> bool {
        match switch {
            -1 => self.configuration == 0,
            s => s == 1,
        }
    }

    /// The parameters the controller flies with: every switch resolved to 0 (printed) or 1
    /// (deviation) — `configuration` gives the default of each (0 tuned: all 1; 1 thesis:
    /// all 0 except `slipstream_in_design`, the thesis's own reading, docs/THESIS.md D-4.3),
    /// a switch set to 0 or 1 overrides it — and the parameters the switches stand
    /// for set to their printed values where a switch is 0: `low_speed_path_frame` 0 → the
    /// wind axes at every airspeed (`wind_frame_speed_low/high` = 0 / 1e-6 m/s, §4.2);
    /// `feedforward_preview` 0 → `feedforward_lead` = 0 ((4.3.24) at the sample);
    /// `tuned_level_guidance` 0 → Table 4.3's level guidance −0.75 ± 0.45i;
    /// `normal_vector_blend` 0 → `normal_vector_blend_time` = `min_normal_accel` = 0.
    pub fn effective(&self) -> Result<Self, ParamError> {
        if !matches!(self.configuration, 0 | 1) {
            return Err(ParamError(format!(
                "configuration = {}: expected 0 (tuned) or 1 (thesis)",
                self.configuration
            )));
        }
        for (name, value) in self.switches() {
            if !(-1..=1).contains(&value) {
                return Err(ParamError(format!(
                    "{name} = {value}: expected -1 (follow configuration), 0 (printed) or 1 (deviation)"
                )));
            }
        }
        let on = |s: i32| i32::from(self.switch_on(s));
        let mut p = Self {
            limited_profile: on(self.limited_profile),
            weathervane_heading: on(self.weathervane_heading),
            hover_wind_design: on(self.hover_wind_design),
            guidance_axial_schedule: on(self.guidance_axial_schedule),
            guidance_lateral_pair: on(self.guidance_lateral_pair),
            guidance_feedback_bound: on(self.guidance_feedback_bound),
            normal_feedforward: on(self.normal_feedforward),
            weathercock_feedforward: on(self.weathercock_feedforward),
            low_speed_path_frame: on(self.low_speed_path_frame),
            feedforward_preview: on(self.feedforward_preview),
            tuned_level_guidance: on(self.tuned_level_guidance),
            normal_thrust_term: on(self.normal_thrust_term),
            lateral_thrust_term: on(self.lateral_thrust_term),
            // D-4.3: the thesis's controller computes the induced velocity (App. D.1, §2.3.4),
            // so q̄_s is its reading of the print too: on in both configurations.
            slipstream_in_design: if self.slipstream_in_design == -1 {
                1
            } else {
                self.slipstream_in_design
            },
            roll_differential_flaps: on(self.roll_differential_flaps),
            alpha_dependent_mixing: on(self.alpha_dependent_mixing),
            antiwindup_all_loops: on(self.antiwindup_all_loops),
            normal_vector_blend: on(self.normal_vector_blend),
            integrators_as_accelerations: on(self.integrators_as_accelerations),
            ..*self
        };
        if p.low_speed_path_frame == 0 {
            p.wind_frame_speed_low = 0.0;
            p.wind_frame_speed_high = 1e-6;
        }
        if p.feedforward_preview == 0 {
            p.feedforward_lead = 0.0;
        }
        if p.tuned_level_guidance == 0 {
            p.guidance_pole_re_level = TABLE_4_3_GUIDANCE_LEVEL.0;
            p.guidance_pole_im_level = TABLE_4_3_GUIDANCE_LEVEL.1;
        }
        if p.normal_vector_blend == 0 {
            p.normal_vector_blend_time = 0.0;
            p.min_normal_accel = 0.0;
        }
        Ok(p)
    }

    /// All finite; every pole's real part negative (stable design); anti-windup gain,
    /// mixing factors, airspeed floor positive; blend time and minimum normal
    /// acceleration non-negative.
    pub fn validate(&self) -> Result<(), ParamError> {
        for (name, value) in self.named_values() {
            if !value.is_finite() {
                return Err(ParamError(format!("{name} = {value}: must be finite")));
            }
            let is_real_part = name.contains("_pole_") && !name.contains("_im_");
            if is_real_part && value >= 0.0 {
                return Err(ParamError(format!(
                    "{name} = {value}: a pole's real part must be negative"
                )));
            }
        }
        for (name, value) in [
            ("antiwindup_gain", self.antiwindup_gain),
            ("flap_mixing_factor", self.flap_mixing_factor),
            ("vertical_flap_mixing_factor", self.vertical_flap_mixing_factor),
            ("min_airspeed", self.min_airspeed),
        ] {
            if value <= 0.0 {
                return Err(ParamError(format!("{name} = {value}: must be > 0")));
            }
        }
        for (name, value) in [
            ("normal_vector_blend_time", self.normal_vector_blend_time),
            ("min_normal_accel", self.min_normal_accel),
            ("feedforward_lead", self.feedforward_lead),
        ] {
            if value < 0.0 {
                return Err(ParamError(format!("{name} = {value}: must be ≥ 0")));
            }
        }
        if self.wind_frame_speed_low < 0.0 || self.wind_frame_speed_high <= self.wind_frame_speed_low {
            return Err(ParamError(format!(
                "wind_frame_speed_low = {}, wind_frame_speed_high = {}: need 0 ≤ low < high",
                self.wind_frame_speed_low, self.wind_frame_speed_high
            )));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `configuration` picks the default of every switch left at −1 (0: all on; 1: all off but
    /// `slipstream_in_design`); a switch set to 0 or 1 overrides it; other values are errors.
    #[test]
    fn configuration_picks_the_switch_defaults_and_a_switch_overrides() {
        let tuned = TsdParams::default().effective().unwrap();
        assert!(tuned.switches().iter().all(|(_, v)| *v == 1), "{:?}", tuned.switches());
        assert_eq!(tuned.wind_frame_speed_low, TsdParams::default().wind_frame_speed_low);
        let thesis = TsdParams {
            configuration: 1,
            ..TsdParams::default()
        };
        let e = thesis.effective().unwrap();
        for (name, v) in e.switches() {
            assert_eq!(v, i32::from(name == "slipstream_in_design"), "{name}");
        }
        assert_eq!((e.wind_frame_speed_low, e.feedforward_lead), (0.0, 0.0));
        assert_eq!((e.normal_vector_blend_time, e.min_normal_accel), (0.0, 0.0));
        assert_eq!(
            (e.guidance_pole_re_level, e.guidance_pole_im_level),
            TABLE_4_3_GUIDANCE_LEVEL
        );
        let one = TsdParams {
            normal_thrust_term: 1,
            low_speed_path_frame: 1,
            ..thesis
        }
        .effective()
        .unwrap();
        assert_eq!((one.normal_thrust_term, one.lateral_thrust_term), (1, 0));
        assert_eq!(one.wind_frame_speed_low, TsdParams::default().wind_frame_speed_low);
        let off = TsdParams {
            slipstream_in_design: 0,
            feedforward_preview: 0,
            ..TsdParams::default()
        }
        .effective()
        .unwrap();
        assert_eq!((off.slipstream_in_design, off.feedforward_lead), (0, 0.0));
        assert_eq!(off.limited_profile, 1);
        let bad = TsdParams {
            antiwindup_all_loops: 2,
            ..TsdParams::default()
        };
        assert!(bad.effective().unwrap_err().0.contains("antiwindup_all_loops"));
    }
}
