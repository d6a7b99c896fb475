//! Gain-schedule stage (the gain blocks of Figs. 4.1–4.2, §4.2 and §4.3): at every
//! sample each loop's linear model is evaluated at the measured flight condition —
//! q̄ = ½ρV̄² (wing, ailerons, damping), q̄_s = ½ρ(V̄ + 2w)² (elevator, rudder, flaps in the
//! slip-stream), the thrust and α — and its gains placed on the poles of Table 4.3 blended
//! linearly in airspeed between `v_vertical` and `v_level`.

use crate::axes::Airflow;
use crate::deviations::Deviations;
use crate::reference::ReferenceSignals;
use crate::{
    band_weight, gains, lerp, TsdController, GUIDANCE_FEEDBACK_LIMIT, HOVER_GUST_NORMAL_POLE_FACTOR,
    HOVER_WIND_DESIGN_SPEED_FACTOR, HOVER_WIND_NORMAL_CROSSFLOW, HOVER_WIND_NORMAL_POLE_FACTOR,
    HOVER_WIND_ROLL_POLE_FACTOR, TABLE_4_3_GUIDANCE_LEVEL,
};
use flight_mission::{ControlError, Measurement};
use nalgebra::{Matrix3, RowVector3, Vector3};
use tailsitter_physics::Coefficients;

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
    /// Weight (0–1) of the hover-in-wind design condition ([`crate::HOVER_WIND_CROSSFLOW`]; 0 off the
    /// hover and in the thesis configuration): the path frame is kept (κ scaled by 1 − weight)
    /// and the roll and normal poles are slowed (README, "Hover in a span-wise wind").
    pub hover_wind: f64,
    /// Crossflow V̄ √(1 − cos²α cos²β), the air-velocity component across the nose (m/s).
    pub crossflow: f64,
    /// Weight (0–1) of [`crate::HOVER_GUST_NORMAL_POLE_FACTOR`]: `hover_wind` in hover, 0 in
    /// the take-off and landing phases and in the thesis configuration.
    pub gust_weight: f64,
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

/// The model quantities every loop shares at one flight condition (§4.2).
struct ModelPoint {
    /// Schedule variable: 0 at v_vertical, 1 at v_level.
    sched: f64,
    /// Weight κ of the wind axes (scales the path-rotation term a11 of (4.2.9), (4.2.27)).
    kappa: f64,
    /// V̄ floored at `min_airspeed` (m/s).
    v: f64,
    /// q̄ = ½ρV̄², q̄_s = ½ρ(V̄ + 2w)² (Pa) (q̄_s = q̄ with `slipstream_in_design` off).
    qbar: f64,
    qbar_s: f64,
    /// The switches of the models (D-4.1, D-4.2, D-4.4).
    dev: Deviations,
    /// q̄S/(2V̄) per unit rate derivative: (2.3.5) without dividing by V̄ (kg/s).
    kr: f64,
    /// Thrust T ≥ 0 (N) and cos α.
    thrust: f64,
    cos_alpha: f64,
    /// Aerodynamic coefficients at α (App. C).
    c: Coefficients,
    /// Mixing ratios (r_n, r_v) (4.2.12, Table 4.2).
    rn: f64,
    rv: f64,
}

/// Normal loop (4.2.9–4.2.17): model, poles, gains and the coefficients its laws use.
struct NormalDesign {
    model: (Matrix3<f64>, Vector3<f64>),
    poly: [f64; 3],
    gains: RowVector3<f64>,
    a22: f64,
    b2: f64,
}

/// Roll / NVD loop (4.2.21–4.2.26, 4.3.7–4.3.11).
struct RollDesign {
    model: (f64, f64, f64, f64),
    poly: [f64; 3],
    gains: (f64, f64, f64),
}

/// Directional loop (4.2.27–4.2.31).
struct DirectionalDesign {
    model: (Matrix3<f64>, Vector3<f64>),
    poly: [f64; 3],
    gains: RowVector3<f64>,
    a32: f64,
    a33: f64,
    b31: f64,
    b32: f64,
    weathercock: f64,
}

impl TsdController {
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

    /// The flight condition of the sample, designed at ([`Self::design`]).
    ///
    /// In the take-off and landing phases (vertical, slow, the air possibly from behind in
    /// the descent, α → π) the loops are designed for hover at the axial airspeed: the
    /// attached-flow models of (4.2.x) at α ≈ π would reverse the surfaces' sign; in wind
    /// (tuned configuration) blended towards the hover-in-wind condition with the measured
    /// wind's weight (README, "Take-off and landing in wind"). Tuned
    /// configuration, hover (the reference at the vertical speed) in wind: at α = 0 and
    /// HOVER_WIND_DESIGN_SPEED_FACTOR × V̄, blended in with the crossflow (README, "Hover in a
    /// wind step"). At the measured condition (a wind step puts α at ±60° or β at ±65°, V̄ at
    /// 5–10 m/s) the elevator and flaps went into a bang-bang pitch limit cycle
    /// (q ≈ ±8 rad/s) that the Jacobi master's extra sample turned into a tumble from 5 m/s on.
    /// In hover below `HOVER_LOW_AIRSPEED_ALPHA` also at α = 0 (the air data of a near-still
    /// air flow are no flight condition).
    pub(crate) fn scheduled_design(
        &self,
        meas: &Measurement,
        r: &ReferenceSignals,
        air: &Airflow,
        t: f64,
    ) -> Result<LoopDesign, ControlError> {
        let (fc_airspeed, fc_alpha) = if r.ground_phase() {
            let hover_wind_speed = meas.airspeed * HOVER_WIND_DESIGN_SPEED_FACTOR;
            (lerp(air.axial_airspeed.max(0.0), hover_wind_speed, air.hover_wind), 0.0)
        } else {
            (
                meas.airspeed * lerp(1.0, HOVER_WIND_DESIGN_SPEED_FACTOR, air.hover_wind),
                meas.alpha * (1.0 - air.hover_wind) * air.alpha_weight,
            )
        };
        self.design(&FlightCondition {
            airspeed: fc_airspeed,
            alpha: fc_alpha,
            thrust: meas.thrust,
            induced_velocity: meas.induced_velocity,
            axial_airspeed: air.axial_airspeed,
            reference_airspeed: r.reference.airspeed,
            hover_wind: air.hover_wind,
            crossflow: air.design_crossflow,
            gust_weight: if r.ground_phase() { 0.0 } else { air.hover_wind },
        })
        .map_err(|what| Self::err(format!("{what} gains not computable at t = {t} s")))
    }

    /// Design every loop at flight condition `fc` (gain scheduling, §4.2): the models of
    /// (4.2.1–4.2.31) with q̄ = ½ρV̄² and q̄_s = ½ρ(V̄ + 2w)², poles of Table 4.3 blended in
    /// airspeed, gains by pole placement. `Err` names a loop whose gains are not finite.
    pub fn design(&self, fc: &FlightCondition) -> Result<LoopDesign, &'static str> {
        let mp = self.model_point(fc, Deviations::of(&self.params));
        let (guidance, guidance_lateral, guidance_feedback_limit) = self.guidance_design(fc, mp.sched);
        let axial = self.axial_design(mp.sched);
        let normal = self.normal_design(fc, &mp)?;
        let roll = self.roll_design(fc, &mp)?;
        let directional = self.directional_design(&mp)?;
        let finite = [
            guidance.0,
            guidance.1,
            guidance_lateral.0,
            guidance_lateral.1,
            axial.0,
            axial.1,
            normal.b2,
            roll.model.3,
            directional.b32,
        ]
        .iter()
        .all(|x| x.is_finite());
        if !finite {
            return Err("scheduled");
        }
        Ok(LoopDesign {
            schedule: mp.sched,
            kappa: mp.kappa,
            v: mp.v,
            mixing: (mp.rn, mp.rv),
            guidance,
            guidance_lateral,
            guidance_feedback_limit,
            axial,
            normal_model: normal.model,
            normal_poly: normal.poly,
            normal_gains: normal.gains,
            a22_n: normal.a22,
            b2: normal.b2,
            roll_model: roll.model,
            roll_poly: roll.poly,
            roll_gains: roll.gains,
            directional_model: directional.model,
            directional_poly: directional.poly,
            directional_gains: directional.gains,
            a32: directional.a32,
            a33: directional.a33,
            b31: directional.b31,
            b32: directional.b32,
            weathercock: directional.weathercock,
        })
    }

    /// Airspeed, schedule variable, frame weight, dynamic pressures and coefficients at `fc`.
    fn model_point(&self, fc: &FlightCondition, dev: Deviations) -> ModelPoint {
        let p = &self.params;
        let af = &self.airframe;
        let v = fc.airspeed.max(p.min_airspeed);
        let sched = band_weight(fc.airspeed, (self.mission.v_vertical, self.mission.v_level));
        // Tuned configuration, hover in wind: the path frame (README, "Hover in a span-wise
        // wind"; κ = 0 in still air hover anyway, axial airspeed < 4 m/s).
        let kappa = self.frame_weight(fc.axial_airspeed) * (1.0 - fc.hover_wind);
        let rho = af.air_density;
        let vs = if dev.slipstream_in_design {
            v + 2.0 * fc.induced_velocity.max(0.0)
        } else {
            v
        };
        let (rn, rv) = self.scheduled_mixing_ratios(fc);
        ModelPoint {
            sched,
            kappa,
            v,
            qbar: 0.5 * rho * v * v,
            qbar_s: 0.5 * rho * vs * vs,
            dev,
            kr: 0.25 * rho * v * af.wing_area,
            thrust: fc.thrust.max(0.0),
            cos_alpha: fc.alpha.cos(),
            c: af.coefficients(fc.alpha),
            rn,
            rv,
        }
    }

    /// Guidance (4.3.24): (K_P, K_V) along and across the path and the feedback bound, from
    /// the guidance poles of Table 4.3 blended in the schedule variable `sched`.
    ///
    /// Switches: `guidance_axial_schedule` — in hover (the path at the vertical speed) the
    /// poles are blended on the axial airspeed, not on V̄: a wind across the hovering aircraft
    /// (V̄ of 5–8 m/s) must not pull the hover guidance towards the faster level-flight poles
    /// (it lost the 5 m/s crosswind that way; README, "Hover in wind").
    /// `guidance_lateral_pair` — off the hover, across the path the level-flight pair is
    /// Table 4.3's: in the transitions the lateral part of Σ is flown as sideslip by the
    /// directional loop, and the faster pair (retuned for the front transition's height)
    /// drove the rudder into saturation and β beyond 60° in steady crosswinds ≥ 4 m/s (README,
    /// "Robustness on uncertain plants"). `guidance_feedback_bound` — the feedback norm is
    /// bounded by [`GUIDANCE_FEEDBACK_LIMIT`] (unbounded in the thesis).
    fn guidance_design(&self, fc: &FlightCondition, sched: f64) -> ((f64, f64), (f64, f64), f64) {
        let p = &self.params;
        let dev = Deviations::of(p);
        let (vv, vl) = (self.mission.v_vertical, self.mission.v_level);
        let sched_path = if dev.guidance_axial_schedule {
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
        let guidance_lateral = if dev.guidance_lateral_pair && fc.reference_airspeed > vv + 1.0 {
            gains::guidance_gains(
                lerp(p.guidance_pole_re_vertical, TABLE_4_3_GUIDANCE_LEVEL.0, sched_path),
                lerp(p.guidance_pole_im_vertical, TABLE_4_3_GUIDANCE_LEVEL.1, sched_path),
            )
        } else {
            guidance
        };
        let limit = if dev.guidance_feedback_bound {
            GUIDANCE_FEEDBACK_LIMIT
        } else {
            f64::INFINITY
        };
        (guidance, guidance_lateral, limit)
    }

    /// Axial loop (4.2.1–4.2.8): (K_A, K_E) of the thrust lag 1/(τs + 1) with integral action.
    fn axial_design(&self, sched: f64) -> (f64, f64) {
        let p = &self.params;
        let blend = |a: f64, b: f64| lerp(a, b, sched);
        gains::axial_gains(
            self.airframe.mass,
            self.airframe.tau_thrust,
            gains::char_poly_2_real(
                blend(p.axial_pole_1_vertical, p.axial_pole_1_level),
                blend(p.axial_pole_2_vertical, p.axial_pole_2_level),
            ),
        )
    }

    /// Normal loop (4.2.9–4.2.17) in (C_W, Q′, E_C) with the mixed actuator δm (Table 4.1).
    /// Z_α = V̄ a11 includes the thrust's normal component −T sin α of (2.5.28) with
    /// `normal_thrust_term` (D-4.1): in vertical flight it is the main normal force. Switch `hover_wind_design` (through
    /// `fc.hover_wind`): in hover in a strong crossflow the poles are slowed by
    /// HOVER_WIND_NORMAL_POLE_FACTOR (README, "Hover in a span-wise wind"), and with the
    /// hover-in-wind weight alone (`fc.gust_weight`; not in the take-off and landing phases) by
    /// HOVER_GUST_NORMAL_POLE_FACTOR (README, "Missions in wind"): the smaller factor applies.
    /// Still air: neither.
    fn normal_design(&self, fc: &FlightCondition, mp: &ModelPoint) -> Result<NormalDesign, &'static str> {
        let p = &self.params;
        let af = &self.airframe;
        let (s_ref, c_ref) = (af.wing_area, af.mean_chord);
        let (c, v, iyy) = (&mp.c, mp.v, af.i_yy);
        let blend = |a: f64, b: f64| lerp(a, b, mp.sched);
        // D-4.1 (`normal_thrust_term`): printed a11 = −q̄S C_Lα/(m V̄) without the thrust.
        let thrust_term = if mp.dev.normal_thrust_term {
            mp.thrust * mp.cos_alpha
        } else {
            0.0
        };
        let z_alpha = -(mp.qbar * s_ref * c.c_L_alpha + thrust_term) / af.mass;
        let a11_n = z_alpha / v;
        let a21_n = mp.qbar * s_ref * c_ref * c.c_m_alpha / iyy;
        let a22 = mp.kr * c_ref * c_ref * c.c_m_q / iyy;
        let b2 = mp.qbar_s * s_ref * c_ref * (c.c_m_de + mp.rn * c.c_m_dfc) / iyy;
        let model = gains::normal_model(mp.kappa * a11_n, a21_n, a22, b2, z_alpha);
        let strong = fc.hover_wind * band_weight(fc.crossflow, HOVER_WIND_NORMAL_CROSSFLOW);
        let gusty = lerp(1.0, HOVER_GUST_NORMAL_POLE_FACTOR, fc.gust_weight);
        let n_scale = lerp(1.0, HOVER_WIND_NORMAL_POLE_FACTOR, strong).min(gusty);
        let poly = gains::char_poly_3(
            n_scale * blend(p.normal_pole_real_vertical, p.normal_pole_real_level),
            n_scale * blend(p.normal_pole_re_vertical, p.normal_pole_re_level),
            n_scale * blend(p.normal_pole_im_vertical, p.normal_pole_im_level),
        );
        let gains = gains::place_3(&model.0, &model.1, poly).ok_or("normal-acceleration")?;
        Ok(NormalDesign {
            model,
            poly,
            gains,
            a22,
            b2,
        })
    }

    /// Roll rate (4.2.21–4.2.26) with the NVD loop (4.3.7–4.3.11): ailerons (free stream)
    /// and, with `roll_differential_flaps` (D-4.4), differential flaps (slip-stream)
    /// deflected together. Switch `hover_wind_design`
    /// (through `fc.hover_wind`): a slower roll-rate pair in hover in wind (README, "Hover in
    /// a span-wise wind").
    fn roll_design(&self, fc: &FlightCondition, mp: &ModelPoint) -> Result<RollDesign, &'static str> {
        let p = &self.params;
        let af = &self.airframe;
        let (s_ref, b_ref, ixx, c) = (af.wing_area, af.wing_span, af.i_xx, &mp.c);
        let blend = |a: f64, b: f64| lerp(a, b, mp.sched);
        let a21_r = mp.qbar * s_ref * b_ref * c.c_l_beta / ixx;
        let a22_r = mp.kr * b_ref * b_ref * c.c_l_p / ixx;
        let a23_r = mp.kr * b_ref * b_ref * c.c_l_r / ixx;
        let flaps = if mp.dev.roll_differential_flaps { 1.0 } else { 0.0 };
        let b21 = s_ref * b_ref * (mp.qbar * c.c_l_da + flaps * mp.qbar_s * c.c_l_dfd) / ixx;
        let r_scale = lerp(1.0, HOVER_WIND_ROLL_POLE_FACTOR, fc.hover_wind);
        let poly = gains::char_poly_3(
            blend(p.nvd_pole_vertical, p.nvd_pole_level),
            r_scale * blend(p.roll_pole_re_vertical, p.roll_pole_re_level),
            r_scale * blend(p.roll_pole_im_vertical, p.roll_pole_im_level),
        );
        let gains = gains::roll_nvd_gains(a22_r, b21, poly).ok_or("roll")?;
        Ok(RollDesign {
            model: (a21_r, a22_r, a23_r, b21),
            poly,
            gains,
        })
    }

    /// Directional loop (4.2.27–4.2.31) in (B_W, R′, E_B) with the mixed actuator δR
    /// (Table 4.2): Y_β = V̄ a11, with the thrust term −T cos α sin β under
    /// `lateral_thrust_term` (D-4.2).
    fn directional_design(&self, mp: &ModelPoint) -> Result<DirectionalDesign, &'static str> {
        let p = &self.params;
        let af = &self.airframe;
        let (s_ref, b_ref, izz, c) = (af.wing_area, af.wing_span, af.i_zz, &mp.c);
        let blend = |a: f64, b: f64| lerp(a, b, mp.sched);
        let flaps = if mp.dev.roll_differential_flaps { 1.0 } else { 0.0 };
        // D-4.2 (`lateral_thrust_term`): printed a11 = q̄S C_yβ/(m V̄) without the thrust.
        let thrust_term = if mp.dev.lateral_thrust_term {
            mp.thrust * mp.cos_alpha
        } else {
            0.0
        };
        let y_beta = (mp.qbar * s_ref * c.c_Y_beta - thrust_term) / af.mass;
        let a11_l = y_beta / mp.v;
        let a31 = mp.qbar * s_ref * b_ref * c.c_n_beta / izz;
        let a33 = mp.kr * b_ref * b_ref * c.c_n_r / izz;
        let b32 = mp.qbar_s * s_ref * b_ref * (c.c_n_dr + mp.rv * c.c_n_dv) / izz;
        let model = gains::directional_model(mp.kappa * a11_l, a31, a33, b32, y_beta);
        let poly = gains::char_poly_3(
            blend(p.directional_pole_real_vertical, p.directional_pole_real_level),
            blend(p.directional_pole_re_vertical, p.directional_pole_re_level),
            blend(p.directional_pole_im_vertical, p.directional_pole_im_level),
        );
        let gains = gains::place_3(&model.0, &model.1, poly).ok_or("directional")?;
        Ok(DirectionalDesign {
            model,
            poly,
            gains,
            a32: mp.kr * b_ref * b_ref * c.c_n_p / izz,
            a33,
            b31: s_ref * b_ref * (mp.qbar * c.c_n_da + flaps * mp.qbar_s * c.c_n_dfd) / izz,
            b32,
            weathercock: 0.5 * af.air_density * s_ref * b_ref * c.c_n_beta / izz,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::TsdParams;
    use flight_mission::MissionParams;
    use tailsitter_physics::Airframe;

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
            gust_weight: 0.0,
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
            gust_weight: 0.0,
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
    /// the normal band's lower end the normal poles are the vertical ones scaled by the gust
    /// factor; the larger slowing of the two applies.
    #[test]
    fn hover_wind_slows_the_roll_pair_and_in_strong_crossflow_the_normal_poles() {
        let ctl = TsdController::with_mission(MissionParams::default()).unwrap();
        let p = TsdParams::default();
        let (rf, nf) = (HOVER_WIND_ROLL_POLE_FACTOR, HOVER_WIND_NORMAL_POLE_FACTOR);
        for (crossflow, n_scale) in [
            (HOVER_WIND_NORMAL_CROSSFLOW.1 + 1.0, nf),
            (HOVER_WIND_NORMAL_CROSSFLOW.0, HOVER_GUST_NORMAL_POLE_FACTOR),
        ] {
            let fc = FlightCondition {
                axial_airspeed: 7.0,
                hover_wind: 1.0,
                crossflow,
                gust_weight: 1.0,
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
}
