//! Time-scale-decoupled (TSD) flight controller of the tail-sitter (S.C. Kriel's thesis,
//! chapter 4 and appendix B), as a plain Rust struct implementing
//! [`flight_mission::FlightController`].
//!
//! Structure (figures 4.1, 4.2):
//!
//! * **Outer loop** (§4.3), slow: the kinematic [`trajectory`] (§4.3.3) gives reference
//!   position, velocity and specific acceleration; the guidance controller (4.3.24)
//!   commands an earth-axis specific acceleration Σ, decomposed (4.3.27–4.3.30) into an
//!   axial command A_Wc, a normal command C_Wc and a commanded normal vector k^Wc; the
//!   normal-vector-direction (NVD) controller (4.3.1–4.3.6) turns the roll error into a
//!   roll-rate reference. In vertical flight and the transitions the normal vector is
//!   prescribed by the trajectory (§4.3.2.1) and the lateral part of Σ goes to the
//!   directional loop; the switch to the computed normal vector in level flight is a
//!   linear blend over `normal_vector_blend_time`, so commands stay continuous.
//! * **Inner loop** (§4.2), fast, gain-scheduled at every sample from the airspeed, the
//!   thrust and the dynamic pressures q̄ = ½ρV̄² (free stream: wing, ailerons) and
//!   q̄_s = ½ρ(V̄ + 2w)² (slip-stream: elevator, flaps, rudder):
//!   axial specific acceleration with thrust (4.2.1–4.2.8, anti-windup §4.2.1);
//!   normal specific acceleration with the mixed elevator/collective-flap actuator δm
//!   (4.2.9–4.2.17, Table 4.1) and gravity cancellation δmg (App. B);
//!   combined roll-rate / NVD loop (4.2.21–4.2.26, 4.3.7–4.3.11) with ailerons and
//!   differential flaps; directional loop regulating the lateral specific acceleration with
//!   the mixed rudder/vertical-flap actuator (4.2.27–4.2.31, Table 4.2) and feedback
//!   linearisation δR_f (the printed (4.2.29) is garbled; derived in the README).
//!
//! Every inner loop has integral action. Integrators are stored as their contribution
//! to the command (u_I = −K_E ∫e), so gain changes between samples cause no bumps;
//! they are initialised at the first sample so the first command equals the measured
//! actuator state (bumpless start from the plant's trim), wound back by back-calculation
//! with the tracking gain (§4.2.1) when a command saturates, and only finite values are
//! committed. `sample` does not allocate (static nalgebra types only).
//!
//! Frames: earth NED, body (x nose, y right wing, z belly), wind axes (x along the air
//! velocity, z in the plane of symmetry). Units SI, angles rad.

pub mod gains;
pub mod params;
pub mod trajectory;

pub use params::{
    TsdParams, GUIDANCE_FEEDBACK_LIMIT, HOVER_WEATHERCOCK_CROSSFLOW, HOVER_WIND_CROSSFLOW,
    HOVER_WIND_DESIGN_SPEED_FACTOR, HOVER_WIND_NORMAL_CROSSFLOW, HOVER_WIND_NORMAL_POLE_FACTOR,
    HOVER_WIND_ROLL_POLE_FACTOR, NORMAL_FEEDFORWARD_RAMP, TABLE_4_3_GUIDANCE_LEVEL,
};
pub use trajectory::{Reference, Trajectory};

use flight_mission::{
    Command, ControlError, ControllerInput, ControllerOutput, Diagnostics, MissionParams, Notice, ParamError, Phase,
    SampledUnit,
};
use guidance::{GroundMode, GroundPhases, Weathervane, WeathervaneParams};
use nalgebra::{Matrix3, Quaternion, RowVector3, UnitQuaternion, Vector3};
use tailsitter_physics::Airframe;

/// Number of f64 values written by [`TsdController::save`]: the loops' six, the
/// weathervane's and the take-off / landing phases'.
pub const STATE_LEN: usize = 6 + guidance::weathervane::WEATHERVANE_STATE_LEN + GroundPhases::SAVED_LEN;

/// Internal signals of the last sample, for tests, plots and tuning.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Internals {
    /// Guidance command Σ, NED (m/s²) (4.3.24).
    pub sigma_cmd: Vector3<f64>,
    /// Axial, lateral, normal specific-acceleration commands A_Wc, B_Wc, C_Wc (m/s²).
    pub accel_cmd: Vector3<f64>,
    /// Measured A_W, B_W, C_W (m/s²).
    pub accel: Vector3<f64>,
    /// Commanded normal vector k^Wc, NED.
    pub normal_cmd: Vector3<f64>,
    /// NVD error angle φ (4.3.5) (rad).
    pub roll_error: f64,
    /// Weight of the computed (vs prescribed) normal vector, 0..1.
    pub normal_weight: f64,
    /// Schedule variable: 0 at v_vertical, 1 at v_level.
    pub schedule: f64,
    /// Weight κ of the wind axes (vs the reference-path frame), 0..1.
    pub frame_weight: f64,
    /// Mixing ratios (δfc/δe, δv/δr) (4.2.12, Table 4.2).
    pub mixing: (f64, f64),
    /// Unsaturated virtual commands (T_c, δm, δA, δR).
    pub virtual_cmd: [f64; 4],
}

/// The flight condition the loops are scheduled on (measured).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FlightCondition {
    /// Airspeed V̄ (m/s).
    pub airspeed: f64,
    /// Angle of attack α (rad) (derivatives interpolated in it).
    pub alpha: f64,
    /// Thrust T (N).
    pub thrust: f64,
    /// Induced velocity w (m/s): the slip-stream surfaces see V̄ + 2w.
    pub induced_velocity: f64,
    /// Air-velocity component along the body x axis, V̄ cos α cos β (m/s): the variable of
    /// the low-speed frame blend κ ([`TsdController::frame_weight`]). Equal to V̄ when the
    /// air flows from the nose; in hover in a crosswind it stays at the climb rate.
    pub axial_airspeed: f64,
    /// Airspeed of the reference path (m/s): where it is the hover's (≤ v_vertical + 1 m/s)
    /// the tuned guidance poles are blended on `axial_airspeed` instead of V̄.
    pub reference_airspeed: f64,
    /// Weight (0–1) of the hover-in-wind design condition ([`HOVER_WIND_CROSSFLOW`]; 0 off the
    /// hover and in the thesis configuration): the path frame is kept (κ scaled by 1 − weight)
    /// and the roll and normal poles are slowed (README, "Hover in a span-wise wind").
    pub hover_wind: f64,
    /// Crossflow V̄ √(1 − cos²α cos²β), the air-velocity component across the nose (m/s).
    pub crossflow: f64,
}

/// Every loop's linear model and gains at one flight condition (§4.2, §4.3, Table 4.3).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LoopDesign {
    /// Schedule variable: 0 at v_vertical, 1 at v_level (pole blending).
    pub schedule: f64,
    /// Weight κ of the wind axes vs the reference-path frame (low-speed frame).
    pub kappa: f64,
    /// Airspeed used in the models, V̄ floored at `min_airspeed` (m/s).
    pub v: f64,
    /// Mixing ratios (δfc/δe, δv/δr).
    pub mixing: (f64, f64),
    /// Guidance (K_P, K_V) (4.3.24).
    pub guidance: (f64, f64),
    /// Guidance (K_P, K_V) across the reference path (along t̂ × k̂ of the path, the earth's
    /// east axis on the mission's northbound path): equal to `guidance` except in the tuned
    /// configuration off the hover, where the level-flight pair is Table 4.3's (README,
    /// "Robustness on uncertain plants").
    pub guidance_lateral: (f64, f64),
    /// Largest norm of the guidance feedback −K_P e_P − K_V e_V (m/s²): unbounded in the
    /// thesis configuration.
    pub guidance_feedback_limit: f64,
    /// Axial (K_A, K_E) (4.2.8).
    pub axial: (f64, f64),
    /// Normal loop model (A, B) in (C_W, Q′, E_C) ([`gains::normal_model`]).
    pub normal_model: (Matrix3<f64>, Vector3<f64>),
    /// Desired characteristic polynomial of the normal loop.
    pub normal_poly: [f64; 3],
    /// Normal loop gains (K_C, K_Q, K_E).
    pub normal_gains: RowVector3<f64>,
    /// Pitch damping a22 and mixed control effectiveness b2 of the normal loop (1/s, 1/s²).
    pub a22_n: f64,
    pub b2: f64,
    /// Roll model (a21, a22, a23, b21) (4.2.26).
    pub roll_model: (f64, f64, f64, f64),
    /// Desired characteristic polynomial of the roll/NVD loop.
    pub roll_poly: [f64; 3],
    /// Roll/NVD gains (K_P, K_E, K_φ) (4.3.11, corrected).
    pub roll_gains: (f64, f64, f64),
    /// Directional loop model (A, B) in (B_W, R′, E_B) ([`gains::directional_model`]).
    pub directional_model: (Matrix3<f64>, Vector3<f64>),
    /// Desired characteristic polynomial of the directional loop.
    pub directional_poly: [f64; 3],
    /// Directional gains (K_B, K_R, K_E).
    pub directional_gains: RowVector3<f64>,
    /// Yaw model coefficients a32, a33, b31, b32 (4.2.31).
    pub a32: f64,
    pub a33: f64,
    pub b31: f64,
    pub b32: f64,
    /// Weathercock coefficient ½ρSb C_nβ / I_zz of (2.3.11) (1/m²): a31 = (this) V̄².
    pub weathercock: f64,
}

/// Integrator state of the four inner loops: the thrust contribution (N) and, for the
/// surface loops, the contribution to the control *acceleration* b·δ (rad/s²) (pitch, roll,
/// yaw): the command is recovered as u_I/b with the current control effectiveness b, so
/// a trim held by an integrator stays trimmed when the dynamic pressure over the surfaces
/// changes (e.g. the slip-stream when thrust comes on) — integrators in the natural units
/// of a gain-scheduled loop.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
struct Integrators {
    thrust: f64,
    normal: f64,
    roll: f64,
    directional: f64,
}

/// The TSD controller.
#[derive(Debug, Clone, PartialEq)]
pub struct TsdController {
    params: TsdParams,
    mission: MissionParams,
    airframe: Airframe,
    trajectory: Trajectory,
    integrators: Integrators,
    initialized: bool,
    /// Take-off and landing phases around the mission (flight_mission::ground).
    ground: GroundPhases,
    /// Bit mask of the saturated commands at the last sample (notices on new saturation only).
    saturated: u32,
    internals: Internals,
    /// Heading reference in vertical flight (README, "Weathervaning").
    weathervane: Weathervane,
}

/// Names of the commands, bit order of the saturation mask.
use tailsitter_physics::idx::INPUT_NAMES as COMMAND_NAMES;

#[inline]
fn lerp(a: f64, b: f64, s: f64) -> f64 {
    a + (b - a) * s
}

/// Linear blend weight of `x` across the band `(lo, hi)`: 0 at or below `lo`, 1 at or above
/// `hi` (the schedules and the hover-in-wind bands).
#[inline]
fn band_weight(x: f64, (lo, hi): (f64, f64)) -> f64 {
    ((x - lo) / (hi - lo)).clamp(0.0, 1.0)
}

impl TsdController {
    /// A controller for `mission` with tuning `params`, using `airframe` (its own model of
    /// the aircraft, not necessarily the plant's) for gains and feedback linearisation.
    pub fn new(airframe: Airframe, mission: MissionParams, params: TsdParams) -> Result<Self, ParamError> {
        params.validate()?;
        let params = params.effective()?;
        mission.validate()?;
        airframe
            .validate()
            .map_err(|e| ParamError(format!("controller airframe: {e}")))?;
        // The tuned configuration flies the α- and thrust-limited profile (issue 16), the
        // thesis configuration the quarter loops of §4.3.3.
        let trajectory = if params.configuration == 0 {
            let pm = guidance::PointMass::from_level_trim(&airframe, mission.v_level)?;
            let profile = guidance::Profile::new(&mission, &pm, &guidance::ProfileLimits::of(&mission))?;
            Trajectory::limited(mission, airframe.gravity, profile)
        } else {
            Trajectory::new(mission, airframe.gravity)
        };
        Ok(Self {
            params,
            mission,
            airframe,
            trajectory,
            integrators: Integrators::default(),
            initialized: false,
            ground: GroundPhases::new(mission, airframe.mass * airframe.gravity),
            saturated: 0,
            internals: Internals::default(),
            weathervane: Weathervane::new(if params.configuration == 0 {
                WeathervaneParams::tuned()
            } else {
                WeathervaneParams::disabled()
            })
            .map_err(ParamError)?,
        })
    }

    /// The weathervane of the heading reference (tuned configuration: on; thesis: off).
    pub fn weathervane(&self) -> &Weathervane {
        &self.weathervane
    }

    /// Replace the weathervane's tuning (resets its state).
    pub fn set_weathervane(&mut self, params: WeathervaneParams) -> Result<(), ParamError> {
        self.weathervane = Weathervane::new(params).map_err(ParamError)?;
        Ok(())
    }

    /// The nominal airframe and Table 4.3 poles for `mission`.
    pub fn with_mission(mission: MissionParams) -> Result<Self, ParamError> {
        Self::new(Airframe::default(), mission, TsdParams::default())
    }

    /// Tuning parameters.
    pub fn params(&self) -> &TsdParams {
        &self.params
    }

    /// Mission flown.
    pub fn mission(&self) -> &MissionParams {
        &self.mission
    }

    /// The kinematic trajectory.
    pub fn trajectory(&self) -> &Trajectory {
        &self.trajectory
    }

    /// Internal signals of the last sample.
    pub fn internals(&self) -> &Internals {
        &self.internals
    }

    /// Forget integrators: the next sample starts bumplessly from the measured actuators.
    pub fn reset(&mut self) {
        self.integrators = Integrators::default();
        self.initialized = false;
        self.saturated = 0;
    }

    /// Write the complete dynamic state ([`STATE_LEN`] values) for FMU-state serialisation.
    pub fn save(&self, out: &mut impl FnMut(f64)) {
        out(if self.initialized { 1.0 } else { 0.0 });
        out(self.integrators.thrust);
        out(self.integrators.normal);
        out(self.integrators.roll);
        out(self.integrators.directional);
        out(self.saturated as f64);
        self.weathervane.save(out);
        self.ground.save(out);
    }

    /// Restore what [`Self::save`] wrote; a truncated state is an error and leaves `self` unchanged.
    pub fn restore(&mut self, next: &mut impl FnMut() -> Option<f64>) -> Result<(), ControlError> {
        let mut v = [0.0; STATE_LEN];
        for slot in v.iter_mut() {
            *slot = next().ok_or_else(|| ControlError("truncated TSD controller state".into()))?;
        }
        let mut weathervane = self.weathervane;
        let mut rest = v[6..].iter().copied();
        weathervane.restore(&mut || rest.next()).map_err(ControlError)?;
        self.weathervane = weathervane;
        self.initialized = v[0] != 0.0;
        self.integrators = Integrators {
            thrust: v[1],
            normal: v[2],
            roll: v[3],
            directional: v[4],
        };
        self.saturated = if v[5].is_finite() && v[5] >= 0.0 {
            v[5] as u32
        } else {
            0
        };
        let mut rest = v[6 + guidance::weathervane::WEATHERVANE_STATE_LEN..].iter().copied();
        self.ground
            .restore(&mut || rest.next())
            .ok_or_else(|| ControlError("truncated TSD controller state".into()))?;
        Ok(())
    }

    /// Mixing ratios (r_n, r_v): δfc = r_n·δm, δe = δm (4.2.12–4.2.13, Table 4.1) and
    /// δv = r_v·δR, δr = δR (Table 4.2), r = −k·(force of the main surface)/(force of the
    /// flap) so that the mixed actuator's force is −(k − 1) times the main surface's, of
    /// opposite sign, and the right-half-plane zero of (4.2.11) moves to the left (4.2.14).
    pub fn mixing_ratios(&self, alpha: f64) -> (f64, f64) {
        let c = self.airframe.coefficients(alpha);
        let rn = -self.params.flap_mixing_factor * c.c_L_de / c.c_L_dfc;
        let rv = -self.params.vertical_flap_mixing_factor * c.c_Y_dr / c.c_Y_dv;
        (rn, rv)
    }

    /// Weight κ of the wind axes against the reference-path frame at the axial airspeed
    /// `axial_airspeed` = V̄ cos α cos β (air-velocity component along the nose): 0 below
    /// `wind_frame_speed_low`, 1 above `wind_frame_speed_high`, linear between.
    ///
    /// The blend variable is the *axial* component, not V̄: in hover in a crosswind the air
    /// velocity points far off the nose (β = 59° in a 5 m/s crosswind at a 3 m/s climb), the
    /// wind axes turn with every change of the aircraft's horizontal velocity (1 m/s turns
    /// them by ~11° at V̄ = 5 m/s) and the small-α/β loop models do not hold, so the wind axes
    /// are no frame for the loops there; with V̄ as the variable a 4 m/s crosswind blended
    /// them in and the lateral position diverged after 8 s (README, "Low-speed frame").
    pub fn frame_weight(&self, axial_airspeed: f64) -> f64 {
        let p = &self.params;
        band_weight(axial_airspeed, (p.wind_frame_speed_low, p.wind_frame_speed_high))
    }

    /// Design every loop at flight condition `fc` (gain scheduling, §4.2): the models of
    /// (4.2.1–4.2.31) with q̄ = ½ρV̄² and q̄_s = ½ρ(V̄ + 2w)², poles of Table 4.3 blended in
    /// airspeed, gains by pole placement. `Err` names a loop whose gains are not finite.
    pub fn design(&self, fc: &FlightCondition) -> Result<LoopDesign, &'static str> {
        let p = &self.params;
        let af = &self.airframe;
        let m = af.mass;
        let (vv, vl) = (self.mission.v_vertical, self.mission.v_level);
        let v = fc.airspeed.max(p.min_airspeed);
        let sched = band_weight(fc.airspeed, (vv, vl));
        // Tuned configuration, hover in wind: the path frame (README, "Hover in a span-wise
        // wind"; κ = 0 in still air hover anyway, axial airspeed < 4 m/s).
        let kappa = self.frame_weight(fc.axial_airspeed) * (1.0 - fc.hover_wind);
        let rho = af.air_density;
        let (s_ref, b_ref, c_ref) = (af.wing_area, af.wing_span, af.mean_chord);
        let qbar = 0.5 * rho * v * v;
        let vs = v + 2.0 * fc.induced_velocity.max(0.0);
        let qbar_s = 0.5 * rho * vs * vs;
        // q̄S/(2V̄) · (rate derivative): (2.3.5) without dividing by V̄.
        let kr = 0.25 * rho * v * s_ref;
        let thrust = fc.thrust.max(0.0);
        let cos_alpha = fc.alpha.cos();
        let c = af.coefficients(fc.alpha);
        let (rn, rv) = self.mixing_ratios(fc.alpha);
        let (ixx, iyy, izz) = (af.i_xx, af.i_yy, af.i_zz);
        let blend = |a: f64, b: f64| lerp(a, b, sched);

        // Tuned configuration, hover (the path at the vertical speed): the guidance poles are
        // blended on the axial airspeed, not on V̄ — a wind across the hovering aircraft
        // (V̄ of 5–8 m/s) must not pull the hover guidance towards the faster level-flight
        // poles (it lost the 5 m/s crosswind that way). Elsewhere, and in the thesis
        // configuration, on the measured V̄ as before (README, "Hover in wind").
        let sched_path = if p.configuration == 0 {
            if fc.reference_airspeed > vv + 1.0 {
                sched
            } else {
                band_weight(fc.axial_airspeed, (vv, vl))
            }
        } else {
            sched
        };
        let guidance = gains::guidance_gains(
            lerp(p.guidance_pole_re_vertical, p.guidance_pole_re_level, sched_path),
            lerp(p.guidance_pole_im_vertical, p.guidance_pole_im_level, sched_path),
        );
        // Tuned configuration, off the hover: across the path the level-flight guidance pair is
        // Table 4.3's. In the transitions the lateral part of Σ is flown as sideslip by the
        // directional loop (prescribed normal vector), and the faster pair (retuned for the
        // front transition's height, a motion in the plane of the path) drove the rudder into
        // saturation and β beyond 60° in steady crosswinds ≥ 4 m/s (README, "Robustness on
        // uncertain plants"). In the hover both horizontal directions are alike (thrust tilt).
        let tuned = p.configuration == 0;
        let guidance_lateral = if tuned && fc.reference_airspeed > vv + 1.0 {
            gains::guidance_gains(
                lerp(p.guidance_pole_re_vertical, TABLE_4_3_GUIDANCE_LEVEL.0, sched_path),
                lerp(p.guidance_pole_im_vertical, TABLE_4_3_GUIDANCE_LEVEL.1, sched_path),
            )
        } else {
            guidance
        };
        let guidance_feedback_limit = if tuned { GUIDANCE_FEEDBACK_LIMIT } else { f64::INFINITY };
        let axial = gains::axial_gains(
            m,
            af.tau_thrust,
            gains::char_poly_2_real(
                blend(p.axial_pole_1_vertical, p.axial_pole_1_level),
                blend(p.axial_pole_2_vertical, p.axial_pole_2_level),
            ),
        );

        // Normal (4.2.9–4.2.17). Z_α = V̄ a11 includes the thrust's normal component
        // −T sin α of (2.5.28): in vertical flight it is the main normal force.
        let z_alpha = -(qbar * s_ref * c.c_L_alpha + thrust * cos_alpha) / m;
        let a11_n = z_alpha / v;
        let a21_n = qbar * s_ref * c_ref * c.c_m_alpha / iyy;
        let a22_n = kr * c_ref * c_ref * c.c_m_q / iyy;
        let b2 = qbar_s * s_ref * c_ref * (c.c_m_de + rn * c.c_m_dfc) / iyy;
        let normal_model = gains::normal_model(kappa * a11_n, a21_n, a22_n, b2, z_alpha);
        // Hover in a strong crossflow (tuned): slower normal poles (README, "Hover in a
        // span-wise wind"); factor 1 elsewhere.
        let strong = fc.hover_wind * band_weight(fc.crossflow, HOVER_WIND_NORMAL_CROSSFLOW);
        let n_scale = lerp(1.0, HOVER_WIND_NORMAL_POLE_FACTOR, strong);
        let normal_poly = gains::char_poly_3(
            n_scale * blend(p.normal_pole_real_vertical, p.normal_pole_real_level),
            n_scale * blend(p.normal_pole_re_vertical, p.normal_pole_re_level),
            n_scale * blend(p.normal_pole_im_vertical, p.normal_pole_im_level),
        );
        let normal_gains =
            gains::place_3(&normal_model.0, &normal_model.1, normal_poly).ok_or("normal-acceleration")?;

        // Roll (4.2.21–4.2.26) with NVD (4.3.7–4.3.11): ailerons (free stream) and
        // differential flaps (slip-stream) deflected together.
        let a21_r = qbar * s_ref * b_ref * c.c_l_beta / ixx;
        let a22_r = kr * b_ref * b_ref * c.c_l_p / ixx;
        let a23_r = kr * b_ref * b_ref * c.c_l_r / ixx;
        let b21 = s_ref * b_ref * (qbar * c.c_l_da + qbar_s * c.c_l_dfd) / ixx;
        // Hover in wind (tuned): a slower roll-rate pair (README, "Hover in a span-wise wind").
        let r_scale = lerp(1.0, HOVER_WIND_ROLL_POLE_FACTOR, fc.hover_wind);
        let roll_poly = gains::char_poly_3(
            blend(p.nvd_pole_vertical, p.nvd_pole_level),
            r_scale * blend(p.roll_pole_re_vertical, p.roll_pole_re_level),
            r_scale * blend(p.roll_pole_im_vertical, p.roll_pole_im_level),
        );
        let roll_gains = gains::roll_nvd_gains(a22_r, b21, roll_poly).ok_or("roll")?;

        // Directional (4.2.27–4.2.31): Y_β = V̄ a11 with the thrust term −T cos α sin β.
        let y_beta = (qbar * s_ref * c.c_Y_beta - thrust * cos_alpha) / m;
        let a11_l = y_beta / v;
        let a31 = qbar * s_ref * b_ref * c.c_n_beta / izz;
        let a32 = kr * b_ref * b_ref * c.c_n_p / izz;
        let a33 = kr * b_ref * b_ref * c.c_n_r / izz;
        let b31 = s_ref * b_ref * (qbar * c.c_n_da + qbar_s * c.c_n_dfd) / izz;
        let b32 = qbar_s * s_ref * b_ref * (c.c_n_dr + rv * c.c_n_dv) / izz;
        let directional_model = gains::directional_model(kappa * a11_l, a31, a33, b32, y_beta);
        let directional_poly = gains::char_poly_3(
            blend(p.directional_pole_real_vertical, p.directional_pole_real_level),
            blend(p.directional_pole_re_vertical, p.directional_pole_re_level),
            blend(p.directional_pole_im_vertical, p.directional_pole_im_level),
        );
        let directional_gains =
            gains::place_3(&directional_model.0, &directional_model.1, directional_poly).ok_or("directional")?;

        let finite = [
            guidance.0,
            guidance.1,
            guidance_lateral.0,
            guidance_lateral.1,
            axial.0,
            axial.1,
            b2,
            b21,
            b32,
        ]
        .iter()
        .all(|x| x.is_finite());
        if !finite {
            return Err("scheduled");
        }
        Ok(LoopDesign {
            schedule: sched,
            kappa,
            v,
            mixing: (rn, rv),
            guidance,
            guidance_lateral,
            guidance_feedback_limit,
            axial,
            normal_model,
            normal_poly,
            normal_gains,
            a22_n,
            b2,
            roll_model: (a21_r, a22_r, a23_r, b21),
            roll_poly,
            roll_gains,
            directional_model,
            directional_poly,
            directional_gains,
            a32,
            a33,
            b31,
            b32,
            weathercock: 0.5 * rho * s_ref * b_ref * c.c_n_beta / izz,
        })
    }

    fn err(msg: impl Into<String>) -> ControlError {
        ControlError(msg.into())
    }
}

/// Everything a [`TsdController`] is built from: the FMU's parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TsdConfig {
    /// The controller's own model of the airframe (may differ from the plant's).
    pub airframe: Airframe,
    pub mission: MissionParams,
    pub params: TsdParams,
}

impl TsdConfig {
    /// The nominal airframe, the given mission and the default tuning (Table 4.3 poles).
    pub fn with_mission(mission: MissionParams) -> Self {
        Self {
            airframe: Airframe::default(),
            mission,
            params: TsdParams::default(),
        }
    }
}

impl SampledUnit for TsdController {
    type Config = TsdConfig;
    type Input = ControllerInput;
    type Output = ControllerOutput;

    fn build(c: &TsdConfig) -> Result<Self, ParamError> {
        Self::new(c.airframe, c.mission, c.params)
    }

    fn sample_time(c: &TsdConfig) -> f64 {
        c.mission.sample_time
    }

    fn save(&self, out: &mut impl FnMut(f64)) {
        Self::save(self, out)
    }

    fn restore(&mut self, next: &mut impl FnMut() -> Option<f64>) -> Result<(), ControlError> {
        Self::restore(self, next)
    }

    fn sample(&mut self, input: &ControllerInput) -> Result<ControllerOutput, ControlError> {
        let meas = &input.measurement;
        if let Some(name) = meas.first_non_finite() {
            return Err(Self::err(format!(
                "measurement '{name}' is not finite at t = {} s",
                input.t
            )));
        }
        if !input.t.is_finite() || !input.ref_offset_ned.iter().all(|v| v.is_finite()) {
            return Err(Self::err(format!(
                "non-finite time or reference offset at t = {} s",
                input.t
            )));
        }
        let p = self.params;
        let af = self.airframe;
        let g = af.gravity;
        let ts = self.mission.sample_time;

        // ---- Reference (§4.3.3), or the take-off / landing phases around it -------------
        let trajectory = &self.trajectory;
        let origin = self.ground.origin().unwrap_or_else(Vector3::zeros);
        let mission_ref = |tm: f64| {
            let r = trajectory.at(tm);
            (r.pos + input.ref_offset_ned + origin, r.vel)
        };
        // Mission time of the trajectory (the FMU time shifted by the take-off), the
        // reference, its position with every offset, and the feed-forward Σ of a vertical
        // reference of the ground phases.
        let (t_mission, reference, ref_pos, sigma_ground) = match self.ground.step(input.t, meas, mission_ref) {
            GroundMode::Mission { t, offset } => {
                let r = self.trajectory.at(t);
                let shift = offset + origin;
                (t, r, r.pos + input.ref_offset_ned + shift, None)
            }
            GroundMode::Vertical(v) => {
                let r = trajectory::Reference {
                    phase: v.phase,
                    pos: v.pos,
                    vel: v.vel,
                    specific_accel: v.accel - Vector3::new(0.0, 0.0, g),
                    airspeed: v.vel.norm(),
                    gamma: core::f64::consts::FRAC_PI_2,
                };
                (f64::NAN, r, v.pos + input.ref_offset_ned, Some(r.specific_accel))
            }
            GroundMode::Idle { phase, thrust } => {
                // On the gear: no loop runs (no integrator wind-up); the next flight phase
                // starts bumpless from the measured thrust and surfaces.
                self.initialized = false;
                self.saturated = 0;
                let command = Command {
                    thrust: thrust.clamp(af.thrust_min, af.thrust_max),
                    ..Command::default()
                };
                return Ok(ControllerOutput {
                    command,
                    diagnostics: Diagnostics {
                        ref_pos_ned: meas.pos_ned,
                        ref_airspeed: 0.0,
                        phase,
                        pos_error: 0.0,
                    },
                    notice: None,
                });
            }
        };
        // Heading reference (weathervane, README "Weathervaning"): the prescribed normal
        // vector turned about the earth's down axis by ψ_w; zero in still air and in the
        // take-off and landing phases (their own vertical reference).
        let heading = if sigma_ground.is_some() {
            guidance::HeadingRef::default()
        } else {
            self.weathervane.update(&self.mission, t_mission, meas)
        };
        let pos_error_vec = meas.pos_ned - ref_pos;

        // ---- Measured wind axes and specific accelerations ----------------------------
        let q = &meas.quat;
        let att = UnitQuaternion::from_quaternion(Quaternion::new(q[3], q[0], q[1], q[2]));
        // Body → earth.
        let r_eb = att.to_rotation_matrix();
        // Frame of the specific accelerations: the wind axes (thesis) above
        // `wind_frame_speed_high`, the reference-path axes below `wind_frame_speed_low`
        // (κ = 0), blended between, in the axial airspeed V̄ cos α cos β (not V̄: a crosswind
        // in hover must not blend in wind axes that point along the span). κ also scales the
        // path-rotation terms of the loop models (a11 C_W, the gravity terms g₁/V̄, g₂/V̄ and
        // their feedback linearisation): at low speed the wind axes turn as fast as the body
        // and the time-scale separation fails.
        let axial_airspeed = meas.airspeed * meas.alpha.cos() * meas.beta.cos();
        let crossflow = (meas.airspeed * meas.airspeed - axial_airspeed * axial_airspeed)
            .max(0.0)
            .sqrt();
        let hover_wind = if p.configuration == 0 && reference.airspeed <= self.mission.v_vertical + 1.0 {
            band_weight(crossflow, HOVER_WIND_CROSSFLOW)
        } else {
            0.0
        };
        // Tuned configuration, hover in wind: the reference-path frame is kept, κ scaled by
        // 1 − hover_wind (README, "Hover in a span-wise wind"): with the nose tilted into a
        // strong wind the air comes along the nose, the axial airspeed passes 4 m/s and the
        // blend turned the loops to wind axes that pointed 50–75° off the vertical; the axial
        // command Σ·i^W then fell to nothing (thrust to 0 N) and the aircraft fell.
        // Not in the take-off and landing phases (their own hover design; unchanged).
        let hover_wind_loops = if sigma_ground.is_some() { 0.0 } else { hover_wind };
        let kappa = self.frame_weight(axial_airspeed) * (1.0 - hover_wind_loops);
        let (fa, fb) = {
            let (sa, ca) = meas.alpha.sin_cos();
            let (sb, cb) = meas.beta.sin_cos();
            let iw_e = r_eb * Vector3::new(ca * cb, sb, sa * cb);
            let blend = iw_e * kappa + reference.tangent() * (1.0 - kappa);
            let i_f = r_eb.transpose() * (if blend.norm() > 1e-6 { blend.normalize() } else { iw_e });
            (i_f.z.atan2(i_f.x), i_f.y.clamp(-1.0, 1.0).asin())
        };
        let (sa, ca) = fa.sin_cos();
        let (sb, cb) = fb.sin_cos();
        // Rows of DCM^WB (A.2.7): wind axes in body components.
        let iw_b = Vector3::new(ca * cb, sb, sa * cb);
        let jw_b = Vector3::new(-ca * sb, cb, -sa * sb);
        let kw_b = Vector3::new(-sa, 0.0, ca);
        let iw = r_eb * iw_b;
        let jw = r_eb * jw_b;
        let kw = r_eb * kw_b;
        let f = meas.specific_force_body;
        let a_w = iw_b.dot(&f);
        let b_w = jw_b.dot(&f);
        let c_w = kw_b.dot(&f);
        // Gravity direction cosines: e_i3 = (wind axis i)·(down) (4.2.17).
        let (e13, e23, e33) = (iw.z, jw.z, kw.z);
        let (pr, qr, rr) = (meas.rates.x, meas.rates.y, meas.rates.z);
        // Stability-axis roll and yaw rates (≈ P_W of (2.5.27) for small β).
        let p_s = pr * ca + rr * sa;
        let r_s = rr * ca - pr * sa;

        // ---- Gain schedule: every loop designed at this flight condition ----------------
        // In the take-off and landing phases (vertical, slow, the air possibly from behind
        // in the descent, α → π) the loops are designed for hover at the axial airspeed:
        // the attached-flow models of (4.2.x) at α ≈ π would reverse the surfaces' sign.
        // Tuned configuration, hover (the reference at the vertical speed) in wind: the loops
        // are designed at α = 0 and HOVER_WIND_DESIGN_SPEED_FACTOR × V̄, blended in with the
        // crossflow (README, "Hover in a wind step"). At the measured condition (a wind step
        // puts α at ±60° or β at ±65°, V̄ at 5–10 m/s) the elevator and flaps went into a
        // bang-bang pitch limit cycle (q ≈ ±8 rad/s) that the Jacobi master's extra sample
        // turned into a tumble from 5 m/s on.
        let (fc_airspeed, fc_alpha) = if sigma_ground.is_some() {
            (axial_airspeed.max(0.0), 0.0)
        } else {
            (
                meas.airspeed * lerp(1.0, HOVER_WIND_DESIGN_SPEED_FACTOR, hover_wind),
                meas.alpha * (1.0 - hover_wind),
            )
        };
        let d = self
            .design(&FlightCondition {
                airspeed: fc_airspeed,
                alpha: fc_alpha,
                thrust: meas.thrust,
                induced_velocity: meas.induced_velocity,
                axial_airspeed,
                reference_airspeed: reference.airspeed,
                hover_wind: hover_wind_loops,
                crossflow,
            })
            .map_err(|what| Self::err(format!("{what} gains not computable at t = {} s", input.t)))?;
        let (v, sched) = (d.v, d.schedule);
        let (rn, rv) = d.mixing;
        let lim = af.deflection_limit;

        // ---- Guidance (4.3.24) ---------------------------------------------------------
        let (kp_g, kv_g) = d.guidance;
        let vel_error = meas.vel_ned - reference.vel;
        // The previewed Σ^RE as read at t + lead (`sigma_ahead`: the normal loop's steady-state
        // feed-forward below) and resolved in the path axes of t (`sigma_ff`: the guidance
        // command, (4.3.24)). Read as a vector, the preview also turns the command with the
        // path by γ̇·lead — 7° of the ≈ 13 m/s² thrust acceleration in the fast push-over became
        // a normal command the integrator E_C then held: the attitude led the path, gravity
        // amplified the lead and the TSD sank 0.8 m and climbed back in the fast front
        // transition (README, "Front transition: preview in path axes").
        let (sigma_ff, sigma_ahead) = if let Some(s) = sigma_ground {
            (s, s)
        } else if p.feedforward_lead > 0.0 {
            (
                self.trajectory.previewed_specific_accel(t_mission, p.feedforward_lead),
                self.trajectory.at(t_mission + p.feedforward_lead).specific_accel,
            )
        } else {
            (reference.specific_accel, reference.specific_accel)
        };
        // (4.3.24), with the lateral pair across the path (t̂ × k̂: the path's own lateral axis,
        // independent of the weathervane's heading) and the feedback bounded in norm: for the
        // small errors the poles were placed for it is the linear law; a large error (a gust,
        // a wind step, an uncertain plant) is recovered at GUIDANCE_FEEDBACK_LIMIT instead of
        // commanding accelerations that saturate thrust and surfaces (README, "Robustness on
        // uncertain plants").
        let lateral = reference.tangent().cross(&reference.prescribed_normal());
        let (kp_l, kv_l) = d.guidance_lateral;
        let mut feedback = -pos_error_vec * kp_g - vel_error * kv_g;
        if (kp_l, kv_l) != (kp_g, kv_g) {
            feedback -=
                lateral * ((kp_l - kp_g) * lateral.dot(&pos_error_vec) + (kv_l - kv_g) * lateral.dot(&vel_error));
        }
        let size = feedback.norm();
        if size > d.guidance_feedback_limit {
            feedback *= d.guidance_feedback_limit / size;
        }
        let sigma = feedback + sigma_ff;

        // ---- Decomposition (4.3.27–4.3.30) and prescribed normal vector (§4.3.2.1) ---
        let a_cmd = sigma.dot(&iw);
        let n_vec = sigma - iw * a_cmd;
        let n_norm = n_vec.norm();
        let k_pres = if heading.heading == 0.0 {
            reference.prescribed_normal()
        } else {
            let k = reference.prescribed_normal();
            let (s, c) = heading.heading.sin_cos();
            Vector3::new(c * k.x - s * k.y, s * k.x + c * k.y, k.z)
        };
        // Weight of the computed normal vector: 1 inside level flight, ramping over the
        // blend time at both ends, and faded out when the normal command is too small.
        let normal_weight = if reference.phase == Phase::Level {
            let (_, tau) = self.mission.phase_at(t_mission);
            let bt = p.normal_vector_blend_time;
            let ramp = if bt > 0.0 {
                (tau / bt).min((self.mission.t_level - tau) / bt).clamp(0.0, 1.0)
            } else {
                1.0
            };
            let nmin = p.min_normal_accel;
            let size = if nmin > 0.0 {
                ((n_norm - nmin) / nmin).clamp(0.0, 1.0)
            } else {
                1.0
            };
            ramp * size
        } else {
            0.0
        };
        // Sign of C_Wc (4.3.29): normal flight lifts against the belly.
        let (c_comp, k_comp) = if n_norm > 1e-9 {
            if n_vec.dot(&k_pres) <= 0.0 {
                (-n_norm, -n_vec / n_norm)
            } else {
                (n_norm, n_vec / n_norm)
            }
        } else {
            (0.0, k_pres)
        };
        let w_n = normal_weight;
        let c_cmd = (1.0 - w_n) * sigma.dot(&kw) + w_n * c_comp;
        let b_cmd = (1.0 - w_n) * sigma.dot(&jw);
        let k_blend = k_pres * (1.0 - w_n) + k_comp * w_n;
        let k_cmd = if k_blend.norm() > 1e-9 {
            k_blend.normalize()
        } else {
            k_pres
        };
        // NVD error angle (4.3.3–4.3.5): the roll about i^W taking k^W to k^Wc;
        // k^Wc·j^W = −sin φ, k^Wc·k^W = cos φ (atan2 keeps the sign and the full range).
        let (sj, ck) = (-k_cmd.dot(&jw), k_cmd.dot(&kw));
        let roll_error = if sj.hypot(ck) > 0.1 { sj.atan2(ck) } else { 0.0 };

        // ---- Axial loop (4.2.1–4.2.8) --------------------------------------------------
        let (ka, ke_a) = d.axial;
        let thrust_p = -ka * a_w;

        // ---- Normal loop (4.2.9–4.2.17) ------------------------------------------------
        let (k_n, a22_n, b2) = (d.normal_gains, d.a22_n, d.b2);
        // Gravity along the wind z axis g₁ = g e33 and its rate (4.2.17), from
        // dk^W/dt = Q_W i^W − P_W j^W with Q_W = −(C_W + g₁)/V̄ (2.5.12).
        let g1 = kappa * g * e33;
        let g1_dot = -kappa * g * ((c_w + g * e33) / v * e13 + p_s * e23);
        let q_prime = qr + g1 / v;
        // Feedback linearisation (App. B), in the Q′ coordinates: cancels the gravity terms
        // of Q̇′; equals the printed δmg of (4.2.16) once −K_Q g₁/V̄ is added back.
        let dm_g = (a22_n * g1 - g1_dot) / (v * b2);
        // Tuned configuration, off the hover (and outside the take-off and landing phases): the
        // steady state (C*, Q′*, δm*) of the loop model at the normal part of the reference's own
        // specific acceleration, C* = Σ^RE·k^W (4.3.24, the previewed feed-forward), is fed
        // forward and the state feedback of (4.2.15) acts on the deviation from it (README,
        // "Front transition: normal-loop feed-forward"). Without it the trajectory's normal
        // acceleration reached δm only through the integrator E_C, ≈ 0.3 s behind at the
        // vertical-flight poles: the height lost in the pull-out of a fast front transition. The
        // guidance feedback still enters through E_C alone: fed forward as well, it closed a fast
        // pitch → velocity error → δm path that oscillated in level flight behind the avionics'
        // latency (Jacobi master with sensors and EKF, pitch ±9°).
        let (c_ff, q_ff, dm_ff) = if p.configuration == 0 && sigma_ground.is_none() {
            let weight = ((reference.airspeed - self.mission.v_vertical) / NORMAL_FEEDFORWARD_RAMP).clamp(0.0, 1.0);
            if weight > 0.0 {
                // As read at t + lead: the steady state the body must be in by then, so the
                // attitude leads the path by the preview (the command's own turn stays out of
                // E_C, which integrates C_W − C_Wc with C_Wc from the path-axes preview).
                let c_ff = weight * sigma_ahead.dot(&kw);
                let (q_ff, dm_ff) = gains::normal_steady_state(&d.normal_model, c_ff);
                (c_ff, q_ff, dm_ff)
            } else {
                (0.0, 0.0, 0.0)
            }
        } else {
            (0.0, 0.0, 0.0)
        };
        let dm_p = -k_n[0] * (c_w - c_ff) - k_n[1] * (q_prime - q_ff) + dm_ff + dm_g;

        // ---- Roll / NVD (4.2.21–4.2.26, 4.3.7–4.3.11) -----------------------------------
        let (a21_r, _, a23_r, b21) = d.roll_model;
        let (kp_r, ke_r, kphi) = d.roll_gains;
        // P_R = P_Wc + K_φ φ, P_Wc = 0 (no turns in the mission).
        let p_ref = kphi * roll_error;
        // (4.2.25): cancel the sideslip and yaw-rate roll moments.
        let da_f = -(a21_r * meas.beta + a23_r * r_s) / b21;
        let da_p = -kp_r * p_s + da_f;

        // ---- Directional (4.2.27–4.2.31) -----------------------------------------------
        let (k_d, a32, a33, b31, b32) = (d.directional_gains, d.a32, d.a33, d.b31, d.b32);
        // Gravity along the wind y axis g₂ = g e23 and its rate, from dj^W/dt = −R_W i^W +
        // P_W k^W with R_W = (B_W + g₂)/V̄ (2.5.12).
        let g2 = kappa * g * e23;
        let g2_dot = kappa * g * (-(b_w + g * e23) / v * e13 + p_s * e33);
        let r_prime = r_s - g2 / v;
        // Weathercock feed-forward (tuned configuration, outside the take-off and landing
        // phases; README, "Hover in a span-wise wind"): δR_w = −N̂/(I_zz b32) cancels the
        // yawing moment of the sideslip, N = q̄Sb C_nβ β of (2.3.11), which the (B_W, R′)
        // model only carries through B_W = V̄ a11 β (4.2.27). That holds in the wind axes
        // (κ = 1) but not in the path frame of the hover, where B_W is mostly the wind's side
        // force and the moment is set by the crossflow: weight 1 − κ, so it fades out as the
        // flow comes along the nose (no double count in the transitions and level flight, and
        // no jump at the phase boundaries). The side surfaces see the lateral air velocity
        // v = V̄ sin β (sin β: bounded where β is not small) at the free-stream speed V̄ over
        // the share 1 − η of the span and at the slip-stream speed V̄ + 2w ((2.3.18), the speed
        // of q̄_s) over the share η = min(1, 2D/b) the two propellers' wash covers
        // (D = √(2A/π) each of disc area A/2), so
        // N̂/I_zz = ½ρSb C_nβ/I_zz · v [(1 − η) V̄ + η (V̄ + 2w)]. Zero in still air (β = 0).
        let weathercock_ff = if p.configuration == 0 && sigma_ground.is_none() {
            let weight = band_weight(crossflow, HOVER_WEATHERCOCK_CROSSFLOW) * (1.0 - kappa);
            let eta = (2.0 * (2.0 * af.prop_disc_area / core::f64::consts::PI).sqrt() / af.wing_span).min(1.0);
            let v_lat = meas.airspeed * meas.beta.sin();
            let v_s = meas.airspeed + 2.0 * meas.induced_velocity.max(0.0);
            let yaw_accel = d.weathercock * v_lat * ((1.0 - eta) * meas.airspeed + eta * v_s);
            -weight * yaw_accel / b32
        } else {
            0.0
        };

        // ---- Bumpless start -------------------------------------------------------------
        let integ = &mut self.integrators;
        if !self.initialized {
            let s = meas.surfaces; // δe, δa, δr, δfc, δfd, δv
            let da_now = s[1];
            let dr_f0 = -(a32 * p_s + b31 * da_now + a33 * g2 / v - g2_dot / v) / b32 + weathercock_ff;
            integ.thrust = meas.thrust - thrust_p;
            integ.normal = b2 * (s[0] - dm_p);
            integ.roll = b21 * (da_now - da_p);
            integ.directional = b32 * (s[2] - (-k_d[0] * b_w - k_d[1] * r_prime + dr_f0));
            self.initialized = true;
        }

        // ---- Commands ------------------------------------------------------------------
        let thrust_c = thrust_p + integ.thrust;
        let dm = dm_p + integ.normal / b2;
        let da = da_p + integ.roll / b21;
        // (4.2.29), derived: δR_f = −(a32 P + b31 δA + a33 g₂/V̄ − ġ₂/V̄)/b32 cancels every
        // term of Ṙ′ outside the (B_W, R′) model.
        let dr_f = -(a32 * p_s + b31 * da.clamp(-lim, lim) + a33 * g2 / v - g2_dot / v) / b32;
        let dr = -k_d[0] * b_w - k_d[1] * r_prime + integ.directional / b32 + dr_f + weathercock_ff;

        let thrust_sat = thrust_c.clamp(af.thrust_min, af.thrust_max);
        let dm_sat = dm.clamp(-lim, lim);
        let da_sat = da.clamp(-lim, lim);
        let dr_sat = dr.clamp(-lim, lim);
        let command = Command {
            thrust: thrust_sat,
            elevator: dm_sat,
            aileron: da_sat,
            rudder: dr_sat,
            flap_collective: (rn * dm).clamp(-lim, lim),
            flap_differential: da_sat,
            vertical_flap: (rv * dr).clamp(-lim, lim),
        };
        if !command.is_finite() {
            return Err(Self::err(format!("non-finite command at t = {} s", input.t)));
        }

        // ---- Integrators with back-calculation anti-windup (§4.2.1) ---------------------
        let kaw = (p.antiwindup_gain * ts).min(1.0);
        // u_I ← u_I + b·(−T_s K_E e + k_aw (u_sat − u)), b the control effectiveness.
        let step = |u_i: &mut f64, b: f64, ke: f64, e: f64, u: f64, u_sat: f64| {
            let next = *u_i + b * (-ts * ke * e + kaw * (u_sat - u));
            if next.is_finite() {
                *u_i = next;
            }
        };
        step(&mut integ.thrust, 1.0, ke_a, a_w - a_cmd, thrust_c, thrust_sat);
        step(&mut integ.normal, b2, k_n[2], c_w - c_cmd, dm, dm_sat);
        step(&mut integ.roll, b21, ke_r, p_s - p_ref, da, da_sat);
        step(&mut integ.directional, b32, k_d[2], b_w - b_cmd, dr, dr_sat);

        // ---- Notices: saturations newly reached ------------------------------------------
        let values = [
            (thrust_c, af.thrust_min, af.thrust_max),
            (dm, -lim, lim),
            (da, -lim, lim),
            (dr, -lim, lim),
            (rn * dm, -lim, lim),
            (da, -lim, lim),
            (rv * dr, -lim, lim),
        ];
        let mut mask = 0u32;
        for (k, (x, lo, hi)) in values.iter().enumerate() {
            if x < lo || x > hi {
                mask |= 1 << k;
            }
        }
        let fresh = mask & !self.saturated;
        self.saturated = mask;
        let notice = (fresh != 0).then(|| Notice::Saturated(COMMAND_NAMES[fresh.trailing_zeros() as usize]));

        self.internals = Internals {
            sigma_cmd: sigma,
            accel_cmd: Vector3::new(a_cmd, b_cmd, c_cmd),
            accel: Vector3::new(a_w, b_w, c_w),
            normal_cmd: k_cmd,
            roll_error,
            normal_weight,
            schedule: sched,
            frame_weight: d.kappa,
            mixing: (rn, rv),
            virtual_cmd: [thrust_c, dm, da, dr],
        };

        Ok(ControllerOutput {
            command,
            diagnostics: Diagnostics {
                ref_pos_ned: ref_pos,
                ref_airspeed: reference.airspeed,
                phase: reference.phase,
                pos_error: flight_mission::distance(&meas.pos_ned, &ref_pos),
            },
            notice,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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

    fn sorted(mut v: Vec<nalgebra::Complex<f64>>) -> Vec<nalgebra::Complex<f64>> {
        v.sort_by(|a, b| a.re.partial_cmp(&b.re).unwrap().then(a.im.partial_cmp(&b.im).unwrap()));
        v
    }

    fn assert_poles(m: &Matrix3<f64>, want: &[(f64, f64)], what: &str) {
        let got = sorted(m.complex_eigenvalues().iter().copied().collect());
        let mut want: Vec<_> = want.iter().map(|&(re, im)| nalgebra::Complex::new(re, im)).collect();
        want = sorted(want);
        for (w, g) in want.iter().zip(got.iter()) {
            assert!(
                (w - g).norm() < 1e-6 * (1.0 + w.norm()),
                "{what}: want {want:?}, got {got:?}"
            );
        }
    }

    /// The 3 m/s vertical climb (T ≈ mg, w ≈ 10.4 m/s) as the loops' design sees it.
    fn vertical_climb_condition() -> FlightCondition {
        FlightCondition {
            airspeed: 3.0,
            alpha: 0.0,
            thrust: 88.3,
            induced_velocity: 10.4,
            axial_airspeed: 3.0,
            reference_airspeed: 3.0,
            hover_wind: 0.0,
            crossflow: 0.0,
        }
    }

    /// Level flight at 25 m/s (α ≈ 5.3°, T ≈ 9.3 N) as the loops' design sees it.
    fn level_flight_condition() -> FlightCondition {
        FlightCondition {
            airspeed: 25.0,
            alpha: 0.092,
            thrust: 9.3,
            induced_velocity: 0.6,
            axial_airspeed: 25.0 * 0.092f64.cos(),
            reference_airspeed: 25.0,
            hover_wind: 0.0,
            crossflow: 0.0,
        }
    }

    /// At the vertical climb (3 m/s, T = mg, w ≈ 10.4 m/s) and in level flight (25 m/s), every
    /// scheduled loop closed on its own model has exactly the poles of Table 4.3.
    #[test]
    fn scheduled_loops_have_the_poles_of_table_4_3() {
        let ctl = TsdController::with_mission(MissionParams::default()).unwrap();
        let p = TsdParams::default();
        let vertical = vertical_climb_condition();
        let level = level_flight_condition();
        for (fc, lvl) in [(vertical, false), (level, true)] {
            let d = ctl.design(&fc).unwrap();
            assert_eq!(d.schedule, if lvl { 1.0 } else { 0.0 });
            let pick = |v: f64, l: f64| if lvl { l } else { v };
            let (a, b) = d.normal_model;
            let (re, im) = (
                pick(p.normal_pole_re_vertical, p.normal_pole_re_level),
                pick(p.normal_pole_im_vertical, p.normal_pole_im_level),
            );
            let real = pick(p.normal_pole_real_vertical, p.normal_pole_real_level);
            assert_poles(&(a - b * d.normal_gains), &[(real, 0.0), (re, im), (re, -im)], "normal");
            let (a, b) = d.directional_model;
            let (re, im) = (
                pick(p.directional_pole_re_vertical, p.directional_pole_re_level),
                pick(p.directional_pole_im_vertical, p.directional_pole_im_level),
            );
            let real = pick(p.directional_pole_real_vertical, p.directional_pole_real_level);
            assert_poles(
                &(a - b * d.directional_gains),
                &[(real, 0.0), (re, im), (re, -im)],
                "directional",
            );
            let (_, a22, _, b21) = d.roll_model;
            let (kp, ke, kphi) = d.roll_gains;
            let (re, im) = (
                pick(p.roll_pole_re_vertical, p.roll_pole_re_level),
                pick(p.roll_pole_im_vertical, p.roll_pole_im_level),
            );
            let nvd = pick(p.nvd_pole_vertical, p.nvd_pole_level);
            assert_poles(
                &gains::roll_nvd_closed_loop(a22, b21, kp, ke, kphi),
                &[(nvd, 0.0), (re, im), (re, -im)],
                "roll/NVD",
            );
            // Axial (4.2.6) in (T, E_A).
            let (ka, ke) = d.axial;
            let (m, tau) = (Airframe::default().mass, Airframe::default().tau_thrust);
            let acl = nalgebra::Matrix2::new(-(1.0 + ka / m) / tau, -ke / tau, 1.0 / m, 0.0);
            let mut e: Vec<f64> = acl.complex_eigenvalues().iter().map(|c| c.re).collect();
            e.sort_by(|a, b| a.partial_cmp(b).unwrap());
            assert!((e[0] + 15.0).abs() < 1e-9 && (e[1] + 10.0).abs() < 1e-9, "axial {e:?}");
            // Slip-stream: the vertical climb keeps full pitch authority (b2 from q̄_s).
            assert!(d.b2 < -100.0, "b2 = {}", d.b2);
            // Low-speed frame in vertical flight, wind axes in level flight.
            assert_eq!(d.kappa, if lvl { 1.0 } else { 0.0 });
        }
    }

    /// Hover in a span-wise wind (README): at the full hover-in-wind weight and a strong
    /// crossflow the roll pair and the normal poles are the vertical ones scaled by their
    /// factors (the NVD pole and the directional poles unchanged) and the path frame is kept
    /// even where the axial airspeed alone would blend in the wind axes; at a crossflow inside
    /// the normal band's lower end the normal poles are the vertical ones.
    #[test]
    fn hover_wind_slows_the_roll_pair_and_in_strong_crossflow_the_normal_poles() {
        let ctl = TsdController::with_mission(MissionParams::default()).unwrap();
        let p = TsdParams::default();
        let (rf, nf) = (HOVER_WIND_ROLL_POLE_FACTOR, HOVER_WIND_NORMAL_POLE_FACTOR);
        for (crossflow, n_scale) in [
            (HOVER_WIND_NORMAL_CROSSFLOW.1 + 1.0, nf),
            (HOVER_WIND_NORMAL_CROSSFLOW.0, 1.0),
        ] {
            let fc = FlightCondition {
                axial_airspeed: 7.0,
                hover_wind: 1.0,
                crossflow,
                ..vertical_climb_condition()
            };
            let d = ctl.design(&fc).unwrap();
            assert_eq!(d.kappa, 0.0, "path frame kept");
            assert!(ctl.frame_weight(7.0) > 0.0);
            let (a, b) = d.normal_model;
            let (re, im) = (p.normal_pole_re_vertical * n_scale, p.normal_pole_im_vertical * n_scale);
            let real = p.normal_pole_real_vertical * n_scale;
            assert_poles(&(a - b * d.normal_gains), &[(real, 0.0), (re, im), (re, -im)], "normal");
            let (_, a22, _, b21) = d.roll_model;
            let (kp, ke, kphi) = d.roll_gains;
            let (re, im) = (p.roll_pole_re_vertical * rf, p.roll_pole_im_vertical * rf);
            assert_poles(
                &gains::roll_nvd_closed_loop(a22, b21, kp, ke, kphi),
                &[(p.nvd_pole_vertical, 0.0), (re, im), (re, -im)],
                "roll/NVD",
            );
            let (a, b) = d.directional_model;
            let (re, im) = (p.directional_pole_re_vertical, p.directional_pole_im_vertical);
            assert_poles(
                &(a - b * d.directional_gains),
                &[(p.directional_pole_real_vertical, 0.0), (re, im), (re, -im)],
                "directional",
            );
            // ½ρSb C_nβ / I_zz of (2.3.11).
            let af = Airframe::default();
            let want = 0.5 * af.air_density * af.wing_area * af.wing_span * af.coefficients(0.0).c_n_beta / af.i_zz;
            assert!(
                (d.weathercock - want).abs() <= 1e-12 * want.abs(),
                "{} vs {want}",
                d.weathercock
            );
        }
    }

    /// Tuned configuration: across the path, off the hover, the guidance has Table 4.3's
    /// level-flight pair; along it (and everywhere in the hover) the tuned pair; the
    /// thesis configuration has one pair and no feedback bound.
    #[test]
    fn lateral_guidance_and_feedback_bound_of_the_tuned_configuration() {
        let level = level_flight_condition();
        let hover = vertical_climb_condition();
        let p = TsdParams::default();
        let tuned = TsdController::with_mission(MissionParams::default()).unwrap();
        let d = tuned.design(&level).unwrap();
        // (s − re)² + im² = s² + K_V s + K_P.
        let pair = |re: f64, im: f64| (re * re + im * im, -2.0 * re);
        let close = |a: (f64, f64), b: (f64, f64)| (a.0 - b.0).abs() < 1e-12 && (a.1 - b.1).abs() < 1e-12;
        assert!(close(
            d.guidance,
            pair(p.guidance_pole_re_level, p.guidance_pole_im_level)
        ));
        assert!(close(d.guidance_lateral, pair(-0.75, 0.45)), "{:?}", d.guidance_lateral);
        assert_eq!(d.guidance_feedback_limit, GUIDANCE_FEEDBACK_LIMIT);
        let d = tuned.design(&hover).unwrap();
        assert_eq!(d.guidance, d.guidance_lateral);
        assert!(close(
            d.guidance,
            pair(p.guidance_pole_re_vertical, p.guidance_pole_im_vertical)
        ));
        let thesis = TsdController::new(
            Airframe::default(),
            MissionParams::default(),
            TsdParams {
                configuration: 1,
                ..TsdParams::default()
            },
        )
        .unwrap();
        let d = thesis.design(&level).unwrap();
        assert_eq!(d.guidance, d.guidance_lateral);
        assert!(close(d.guidance, pair(-0.75, 0.45)));
        assert_eq!(d.guidance_feedback_limit, f64::INFINITY);
    }

    #[test]
    fn save_restore_round_trip() {
        let mut a = TsdController::with_mission(MissionParams::default()).unwrap();
        a.integrators = Integrators {
            thrust: 1.0,
            normal: 2.0,
            roll: 3.0,
            directional: 4.0,
        };
        a.initialized = true;
        a.saturated = 5;
        let mut buf = Vec::new();
        a.save(&mut |x| buf.push(x));
        assert_eq!(buf.len(), STATE_LEN);
        let mut b = TsdController::with_mission(MissionParams::default()).unwrap();
        let mut it = buf.into_iter();
        b.restore(&mut || it.next()).unwrap();
        assert_eq!(a.integrators, b.integrators);
        assert_eq!((a.initialized, a.saturated), (b.initialized, b.saturated));
        let mut empty = std::iter::empty();
        assert!(b.restore(&mut || empty.next()).is_err());
    }

    #[test]
    fn invalid_parameters_are_named() {
        let p = TsdParams {
            normal_pole_re_level: 1.0,
            ..Default::default()
        };
        let e = TsdController::new(Airframe::default(), MissionParams::default(), p).unwrap_err();
        assert!(e.0.contains("normal_pole_re_level"), "{e}");
    }
}
