//! Tuning parameters under PX4-Autopilot's own names (group `px4` of
//! `modelDescription/tailsitter_px4.json`, where every default and its source is stated:
//! PX4's default, or derived for this airframe, README "Derived parameters").

use flight_mission::ParamError;

/// Every tuning parameter; field names are the FMU parameter names, which are PX4's
/// parameter names (upper case, as PX4 spells them).
#[allow(non_snake_case)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Px4Params {
    /// Horizontal position error → velocity setpoint gain (PX4 default).
    pub MPC_XY_P: f64,
    /// Vertical position error → velocity setpoint gain (PX4 default).
    pub MPC_Z_P: f64,
    /// Horizontal velocity P gain, m/s² per m/s (PX4 default).
    pub MPC_XY_VEL_P_ACC: f64,
    /// Horizontal velocity I gain (PX4 default).
    pub MPC_XY_VEL_I_ACC: f64,
    /// Horizontal velocity D gain on the measured acceleration (PX4 default).
    pub MPC_XY_VEL_D_ACC: f64,
    /// Vertical velocity P gain (PX4 default).
    pub MPC_Z_VEL_P_ACC: f64,
    /// Vertical velocity I gain (PX4 default).
    pub MPC_Z_VEL_I_ACC: f64,
    /// Vertical velocity D gain (PX4 default).
    pub MPC_Z_VEL_D_ACC: f64,
    /// Largest horizontal velocity setpoint (PX4 default).
    pub MPC_XY_VEL_MAX: f64,
    /// Largest climb-rate setpoint. PX4 default 3 m/s; derived for this mission when ≤ 0 (README, 'Derived parameters'): the flight-path profile's largest climb rate, at least 2 v_vertical.
    pub MPC_Z_VEL_MAX_UP: f64,
    /// Largest descent-rate setpoint. PX4 default 1.5 m/s; here 3 m/s so the landings' descent rate is not clipped.
    pub MPC_Z_VEL_MAX_DN: f64,
    /// Largest tilt of the thrust vector in multicopter flight (PX4 default 45°).
    pub MPC_TILTMAX_AIR: f64,
    /// Hover thrust as a fraction of the largest thrust; derived for this airframe when ≤ 0 (README, 'Derived parameters'): m g / T_max.
    pub MPC_THR_HOVER: f64,
    /// Smallest collective thrust in multicopter flight, fraction of T_max (PX4 default).
    pub MPC_THR_MIN: f64,
    /// Largest collective thrust in multicopter flight, fraction of T_max (PX4 default).
    pub MPC_THR_MAX: f64,
    /// Multicopter roll attitude gain, below PX4's default 6.5 for this airframe's slow roll-rate loop (README, 'Roll-axis tuning'); multicopter axes (README, 'Frames').
    pub MC_ROLL_P: f64,
    /// Multicopter pitch attitude gain (PX4 default).
    pub MC_PITCH_P: f64,
    /// Multicopter yaw attitude gain (PX4 default).
    pub MC_YAW_P: f64,
    /// Yaw weight of the tilt-prioritised attitude control (PX4 default).
    pub MC_YAW_WEIGHT: f64,
    /// Largest roll-rate setpoint (PX4 default 220°/s).
    pub MC_ROLLRATE_MAX: f64,
    /// Largest pitch-rate setpoint (PX4 default 220°/s).
    pub MC_PITCHRATE_MAX: f64,
    /// Largest yaw-rate setpoint (PX4 default 200°/s).
    pub MC_YAWRATE_MAX: f64,
    /// Roll-rate P gain, normalised torque per rad/s (PX4 default; normalisation: README, 'Control allocation').
    pub MC_ROLLRATE_P: f64,
    /// Roll-rate I gain (PX4 default).
    pub MC_ROLLRATE_I: f64,
    /// Roll-rate D gain (PX4 default).
    pub MC_ROLLRATE_D: f64,
    /// Roll-rate feed-forward (PX4 default).
    pub MC_ROLLRATE_FF: f64,
    /// Roll-rate integrator limit (PX4 default).
    pub MC_RR_INT_LIM: f64,
    /// Pitch-rate P gain (PX4 default).
    pub MC_PITCHRATE_P: f64,
    /// Pitch-rate I gain (PX4 default).
    pub MC_PITCHRATE_I: f64,
    /// Pitch-rate D gain (PX4 default).
    pub MC_PITCHRATE_D: f64,
    /// Pitch-rate feed-forward (PX4 default).
    pub MC_PITCHRATE_FF: f64,
    /// Pitch-rate integrator limit (PX4 default).
    pub MC_PR_INT_LIM: f64,
    /// Yaw-rate P gain (PX4 default).
    pub MC_YAWRATE_P: f64,
    /// Yaw-rate I gain (PX4 default).
    pub MC_YAWRATE_I: f64,
    /// Yaw-rate D gain (PX4 default).
    pub MC_YAWRATE_D: f64,
    /// Yaw-rate feed-forward (PX4 default).
    pub MC_YAWRATE_FF: f64,
    /// Yaw-rate integrator limit (PX4 default).
    pub MC_YR_INT_LIM: f64,
    /// Front transition: the pitch ramp turns 90° in this time; ≤ 0: the mission's t_transition_1 (PX4 default 5 s, the default mission's T1).
    pub VT_F_TRANS_DUR: f64,
    /// Back transition: pitch ramp duration and time-out; ≤ 0: the mission's t_transition_2 (PX4 default 4 s).
    pub VT_B_TRANS_DUR: f64,
    /// Front transition: airspeed at which fixed-wing flight may begin (PX4 default 10 m/s, below this airframe's stall speed; PX4: between FW_AIRSPD_MIN and FW_AIRSPD_TRIM); derived when ≤ 0 (README, 'Derived parameters'): FW_AIRSPD_TRIM, the speed the mission's front transition ends at.
    pub VT_ARSP_TRANS: f64,
    /// Trim airspeed of the airspeed scaling and TECS; derived for this airframe when ≤ 0 (README, 'Derived parameters'): the mission's v_level.
    pub FW_AIRSPD_TRIM: f64,
    /// Smallest fixed-wing airspeed, also of the airspeed scaling (PX4 default 10 m/s, below this airframe's stall speed); derived for this airframe when ≤ 0 (README, 'Derived parameters'): level flight at the mission's transition_alpha_max, sqrt(2 m g / (ρ S C_Lα α_max)) with the trimmed lift slope.
    pub FW_AIRSPD_MIN: f64,
    /// Pitch setpoint offset of level flight; derived for this airframe when ≤ 0 (README, 'Derived parameters') (negative values are taken as derived): the level trim's pitch.
    pub FW_PSP_OFF: f64,
    /// Pitch attitude time constant (PX4 default).
    pub FW_P_TC: f64,
    /// Roll attitude time constant (PX4 default).
    pub FW_R_TC: f64,
    /// Fixed-wing pitch-rate P gain, normalised torque per rad/s at trim airspeed (PX4 default).
    pub FW_PR_P: f64,
    /// Fixed-wing pitch-rate I gain (PX4 default).
    pub FW_PR_I: f64,
    /// Fixed-wing pitch-rate feed-forward (PX4 default).
    pub FW_PR_FF: f64,
    /// Fixed-wing pitch-rate integrator limit (PX4 default).
    pub FW_PR_IMAX: f64,
    /// Fixed-wing roll-rate P gain (PX4 default).
    pub FW_RR_P: f64,
    /// Fixed-wing roll-rate I gain (PX4 default).
    pub FW_RR_I: f64,
    /// Fixed-wing roll-rate feed-forward (PX4 default).
    pub FW_RR_FF: f64,
    /// Fixed-wing roll-rate integrator limit (PX4 default).
    pub FW_RR_IMAX: f64,
    /// Fixed-wing yaw-rate P gain (PX4 default).
    pub FW_YR_P: f64,
    /// Fixed-wing yaw-rate I gain (PX4 default).
    pub FW_YR_I: f64,
    /// Fixed-wing yaw-rate feed-forward (PX4 default).
    pub FW_YR_FF: f64,
    /// Fixed-wing yaw-rate integrator limit (PX4 default).
    pub FW_YR_IMAX: f64,
    /// Largest roll setpoint (PX4 default 50°).
    pub FW_R_LIM: f64,
    /// Largest pitch setpoint (PX4 default 30°).
    pub FW_P_LIM_MAX: f64,
    /// Smallest pitch setpoint (PX4 default −30°).
    pub FW_P_LIM_MIN: f64,
    /// TECS altitude time constant (PX4 default).
    pub FW_T_ALT_TC: f64,
    /// TECS airspeed time constant (PX4 default).
    pub FW_T_TAS_TC: f64,
    /// TECS throttle damping on the total-energy-rate error (PX4 default).
    pub FW_T_THR_DAMP: f64,
    /// TECS throttle integrator gain (PX4 default).
    pub FW_T_I_GAIN_THR: f64,
    /// TECS pitch integrator gain (PX4 default).
    pub FW_T_I_GAIN_PIT: f64,
    /// TECS pitch damping on the energy-balance-rate error (PX4 default).
    pub FW_T_PTCH_DAMP: f64,
    /// TECS speed weight: 0 height only, 2 speed only (PX4 default).
    pub FW_T_SPDWEIGHT: f64,
    /// Climb rate at full throttle and trim airspeed (PX4 default 5 m/s, which this airframe exceeds eightfold); derived for this airframe when ≤ 0 (README, 'Derived parameters'): (FW_THR_MAX T_max − T_trim) V_trim / (m g) of the level trim.
    pub FW_T_CLMB_MAX: f64,
    /// Sink rate at idle throttle and trim airspeed (PX4 default 2 m/s); derived for this airframe when ≤ 0 (README, 'Derived parameters'): T_trim V_trim / (m g) of the level trim (idle thrust 0).
    pub FW_T_SINK_MIN: f64,
    /// Largest sink-rate setpoint (PX4 default).
    pub FW_T_SINK_MAX: f64,
    /// Throttle at trim airspeed in level flight, fraction of T_max; derived for this airframe when ≤ 0 (README, 'Derived parameters'): the level trim's thrust.
    pub FW_THR_TRIM: f64,
    /// Smallest fixed-wing throttle (PX4 default).
    pub FW_THR_MIN: f64,
    /// Largest fixed-wing throttle (PX4 default).
    pub FW_THR_MAX: f64,
    /// Fixed-wing pitch torque trim, normalised; below −1: derived, the normalised moment of the level trim's surfaces.
    pub TRIM_PITCH: f64,
    /// L1 guidance period (PX4 default).
    pub FW_L1_PERIOD: f64,
    /// L1 guidance damping (PX4 default).
    pub FW_L1_DAMPING: f64,
}

/// `impl Default for Px4Params`, generated by build.rs from the declared start values (PX4's
/// defaults in radians, such as MPC_TILTMAX_AIR = 45° = π/4, are written as the numbers).
#[allow(clippy::approx_constant)]
mod generated {
    use super::Px4Params;
    include!(concat!(env!("OUT_DIR"), "/px4_params_generated.rs"));
}

impl Px4Params {
    /// Every parameter by name.
    pub fn named_values(&self) -> [(&'static str, f64); 76] {
        [
            ("MPC_XY_P", self.MPC_XY_P),
            ("MPC_Z_P", self.MPC_Z_P),
            ("MPC_XY_VEL_P_ACC", self.MPC_XY_VEL_P_ACC),
            ("MPC_XY_VEL_I_ACC", self.MPC_XY_VEL_I_ACC),
            ("MPC_XY_VEL_D_ACC", self.MPC_XY_VEL_D_ACC),
            ("MPC_Z_VEL_P_ACC", self.MPC_Z_VEL_P_ACC),
            ("MPC_Z_VEL_I_ACC", self.MPC_Z_VEL_I_ACC),
            ("MPC_Z_VEL_D_ACC", self.MPC_Z_VEL_D_ACC),
            ("MPC_XY_VEL_MAX", self.MPC_XY_VEL_MAX),
            ("MPC_Z_VEL_MAX_UP", self.MPC_Z_VEL_MAX_UP),
            ("MPC_Z_VEL_MAX_DN", self.MPC_Z_VEL_MAX_DN),
            ("MPC_TILTMAX_AIR", self.MPC_TILTMAX_AIR),
            ("MPC_THR_HOVER", self.MPC_THR_HOVER),
            ("MPC_THR_MIN", self.MPC_THR_MIN),
            ("MPC_THR_MAX", self.MPC_THR_MAX),
            ("MC_ROLL_P", self.MC_ROLL_P),
            ("MC_PITCH_P", self.MC_PITCH_P),
            ("MC_YAW_P", self.MC_YAW_P),
            ("MC_YAW_WEIGHT", self.MC_YAW_WEIGHT),
            ("MC_ROLLRATE_MAX", self.MC_ROLLRATE_MAX),
            ("MC_PITCHRATE_MAX", self.MC_PITCHRATE_MAX),
            ("MC_YAWRATE_MAX", self.MC_YAWRATE_MAX),
            ("MC_ROLLRATE_P", self.MC_ROLLRATE_P),
            ("MC_ROLLRATE_I", self.MC_ROLLRATE_I),
            ("MC_ROLLRATE_D", self.MC_ROLLRATE_D),
            ("MC_ROLLRATE_FF", self.MC_ROLLRATE_FF),
            ("MC_RR_INT_LIM", self.MC_RR_INT_LIM),
            ("MC_PITCHRATE_P", self.MC_PITCHRATE_P),
            ("MC_PITCHRATE_I", self.MC_PITCHRATE_I),
            ("MC_PITCHRATE_D", self.MC_PITCHRATE_D),
            ("MC_PITCHRATE_FF", self.MC_PITCHRATE_FF),
            ("MC_PR_INT_LIM", self.MC_PR_INT_LIM),
            ("MC_YAWRATE_P", self.MC_YAWRATE_P),
            ("MC_YAWRATE_I", self.MC_YAWRATE_I),
            ("MC_YAWRATE_D", self.MC_YAWRATE_D),
            ("MC_YAWRATE_FF", self.MC_YAWRATE_FF),
            ("MC_YR_INT_LIM", self.MC_YR_INT_LIM),
            ("VT_F_TRANS_DUR", self.VT_F_TRANS_DUR),
            ("VT_B_TRANS_DUR", self.VT_B_TRANS_DUR),
            ("VT_ARSP_TRANS", self.VT_ARSP_TRANS),
            ("FW_AIRSPD_TRIM", self.FW_AIRSPD_TRIM),
            ("FW_AIRSPD_MIN", self.FW_AIRSPD_MIN),
            ("FW_PSP_OFF", self.FW_PSP_OFF),
            ("FW_P_TC", self.FW_P_TC),
            ("FW_R_TC", self.FW_R_TC),
            ("FW_PR_P", self.FW_PR_P),
            ("FW_PR_I", self.FW_PR_I),
            ("FW_PR_FF", self.FW_PR_FF),
            ("FW_PR_IMAX", self.FW_PR_IMAX),
            ("FW_RR_P", self.FW_RR_P),
            ("FW_RR_I", self.FW_RR_I),
            ("FW_RR_FF", self.FW_RR_FF),
            ("FW_RR_IMAX", self.FW_RR_IMAX),
            ("FW_YR_P", self.FW_YR_P),
            ("FW_YR_I", self.FW_YR_I),
            ("FW_YR_FF", self.FW_YR_FF),
            ("FW_YR_IMAX", self.FW_YR_IMAX),
            ("FW_R_LIM", self.FW_R_LIM),
            ("FW_P_LIM_MAX", self.FW_P_LIM_MAX),
            ("FW_P_LIM_MIN", self.FW_P_LIM_MIN),
            ("FW_T_ALT_TC", self.FW_T_ALT_TC),
            ("FW_T_TAS_TC", self.FW_T_TAS_TC),
            ("FW_T_THR_DAMP", self.FW_T_THR_DAMP),
            ("FW_T_I_GAIN_THR", self.FW_T_I_GAIN_THR),
            ("FW_T_I_GAIN_PIT", self.FW_T_I_GAIN_PIT),
            ("FW_T_PTCH_DAMP", self.FW_T_PTCH_DAMP),
            ("FW_T_SPDWEIGHT", self.FW_T_SPDWEIGHT),
            ("FW_T_CLMB_MAX", self.FW_T_CLMB_MAX),
            ("FW_T_SINK_MIN", self.FW_T_SINK_MIN),
            ("FW_T_SINK_MAX", self.FW_T_SINK_MAX),
            ("FW_THR_TRIM", self.FW_THR_TRIM),
            ("FW_THR_MIN", self.FW_THR_MIN),
            ("FW_THR_MAX", self.FW_THR_MAX),
            ("TRIM_PITCH", self.TRIM_PITCH),
            ("FW_L1_PERIOD", self.FW_L1_PERIOD),
            ("FW_L1_DAMPING", self.FW_L1_DAMPING),
        ]
    }

    /// Every value finite; gains, limits and time constants that divide or bound non-negative;
    /// the time constants of the fixed-wing and TECS loops positive.
    pub fn validate(&self) -> Result<(), ParamError> {
        for (name, value) in self.named_values() {
            if !value.is_finite() {
                return Err(ParamError(format!("{name} = {value}: must be finite")));
            }
            // The sentinels "≤ 0: derived" and the signed pitch limits and trim may be negative.
            let signed = matches!(
                name,
                "MPC_THR_HOVER"
                    | "VT_F_TRANS_DUR"
                    | "VT_B_TRANS_DUR"
                    | "FW_AIRSPD_TRIM"
                    | "FW_PSP_OFF"
                    | "FW_THR_TRIM"
                    | "TRIM_PITCH"
                    | "FW_P_LIM_MIN"
                    | "FW_T_CLMB_MAX"
                    | "FW_AIRSPD_MIN"
                    | "VT_ARSP_TRANS"
                    | "FW_T_SINK_MIN"
                    | "MPC_Z_VEL_MAX_UP"
            );
            if !signed && value < 0.0 {
                return Err(ParamError(format!("{name} = {value}: must be ≥ 0")));
            }
        }
        for (name, value) in [
            ("FW_P_TC", self.FW_P_TC),
            ("FW_R_TC", self.FW_R_TC),
            ("FW_T_ALT_TC", self.FW_T_ALT_TC),
            ("FW_T_TAS_TC", self.FW_T_TAS_TC),
            ("FW_L1_PERIOD", self.FW_L1_PERIOD),
            ("FW_L1_DAMPING", self.FW_L1_DAMPING),
            ("MPC_THR_MAX", self.MPC_THR_MAX),
        ] {
            if value <= 0.0 {
                return Err(ParamError(format!("{name} = {value}: must be > 0")));
            }
        }
        if self.MPC_THR_MIN >= self.MPC_THR_MAX || self.MPC_THR_MAX > 1.0 {
            return Err(ParamError(format!(
                "MPC_THR_MIN = {}, MPC_THR_MAX = {}: need 0 ≤ MPC_THR_MIN < MPC_THR_MAX ≤ 1",
                self.MPC_THR_MIN, self.MPC_THR_MAX
            )));
        }
        if self.FW_THR_MIN >= self.FW_THR_MAX || self.FW_THR_MAX > 1.0 {
            return Err(ParamError(format!(
                "FW_THR_MIN = {}, FW_THR_MAX = {}: need 0 ≤ FW_THR_MIN < FW_THR_MAX ≤ 1",
                self.FW_THR_MIN, self.FW_THR_MAX
            )));
        }
        if self.FW_P_LIM_MIN >= self.FW_P_LIM_MAX {
            return Err(ParamError(format!(
                "FW_P_LIM_MIN = {} must be below FW_P_LIM_MAX = {}",
                self.FW_P_LIM_MIN, self.FW_P_LIM_MAX
            )));
        }
        if self.MC_YAW_WEIGHT > 1.0 {
            return Err(ParamError(format!(
                "MC_YAW_WEIGHT = {}: must lie in [0, 1]",
                self.MC_YAW_WEIGHT
            )));
        }
        Ok(())
    }
}
