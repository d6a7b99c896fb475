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
    /// Integrator anti-windup tracking gain of every loop (§4.2.1: 50) (1/s).
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
    /// 0 = tuned (these parameters as given), 1 = thesis: the wind axes at every speed
    /// (`wind_frame_speed_low` = 0, `wind_frame_speed_high` = 1e-6 m/s, §4.2) and no
    /// feed-forward preview (`feedforward_lead` = 0, (4.3.24)); see [`Self::effective`].
    pub configuration: i32,
}

// `impl Default for TsdParams` (Table 4.3 of the thesis, §4.2.1 anti-windup 50, (4.2.12)
// mixing 1.1): the start values of group `tsd` of modelDescription/tailsitter_tsd.json,
// generated by build.rs.
include!(concat!(env!("OUT_DIR"), "/tsd_params_generated.rs"));

impl TsdParams {
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

    /// The parameters the controller flies with: `self` for `configuration` 0 (tuned); for
    /// 1 (thesis) the thesis's vertical-flight frame, the wind axes at every speed (§4.2:
    /// the low-speed path frame is a deviation of this repository), and the feed-forward
    /// Σ^RE taken at the sample time (4.3.24), no preview, and Table 4.3's level-flight
    /// guidance poles (−0.75 ± 0.45i).
    pub fn effective(&self) -> Result<Self, ParamError> {
        match self.configuration {
            0 => Ok(*self),
            1 => Ok(Self {
                wind_frame_speed_low: 0.0,
                wind_frame_speed_high: 1e-6,
                feedforward_lead: 0.0,
                // Table 4.3, level-flight guidance (the tuned default is faster, issue 16).
                guidance_pole_re_level: TABLE_4_3_GUIDANCE_LEVEL.0,
                guidance_pole_im_level: TABLE_4_3_GUIDANCE_LEVEL.1,
                ..*self
            }),
            c => Err(ParamError(format!(
                "configuration = {c}: expected 0 (tuned) or 1 (thesis)"
            ))),
        }
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
