//! Airframe parameters (thesis App. C, docs/DESIGN.md §4) and the interpolation of the
//! stability and control derivatives in α.

use core::fmt;

/// Every physical parameter of the tail-sitter.
///
/// Field names are exactly the FMU parameter names of group `airframe` in
/// `modelDescription/tailsitter_plant.json` (the FMU builds this struct field by field).
/// Each stability/control derivative has two values: `_a0` at α = 0 and `_a1` at
/// α = `alpha_1` (the two columns of Tables C.3/C.4); [`Airframe::coefficients`]
/// interpolates linearly between them with α clamped to ±`alpha_interp_limit`.
/// Rate derivatives are per normalised rate (p b/(2V), q c̄/(2V), r b/(2V)), angle
/// and deflection derivatives per radian.
#[allow(non_snake_case)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Airframe {
    /// Aircraft mass m (C.1.1). (kg)
    pub mass: f64,
    /// Moment of inertia about body x (Table C.1). (kg.m2)
    pub i_xx: f64,
    /// Moment of inertia about body y (Table C.1). (kg.m2)
    pub i_yy: f64,
    /// Moment of inertia about body z (Table C.1). (kg.m2)
    pub i_zz: f64,
    /// Reference wing area S (Table C.2). (m2)
    pub wing_area: f64,
    /// Mean aerodynamic chord c, reference length for pitch (Table C.2). (m)
    pub mean_chord: f64,
    /// Wing span b = S / c (rectangular wing), reference length for roll and yaw. (m)
    pub wing_span: f64,
    /// Aspect ratio A = b^2 / S used in the induced drag (2.3.13).
    pub aspect_ratio: f64,
    /// Oswald efficiency e in the induced drag (2.3.13).
    pub oswald_efficiency: f64,
    /// Parasitic drag coefficient C_D0 = 0.0172 (wing) + 0.0100 (tail) (Table C.2).
    pub c_D0: f64,
    /// Lift coefficient at zero angle of attack C_L0 (C.2.1).
    pub c_L0: f64,
    /// Pitching-moment coefficient at zero angle of attack C_m0 (C.2.1).
    pub c_m0: f64,
    /// Air density rho (sea level). (kg/m3)
    pub air_density: f64,
    /// Gravitational acceleration g. (m/s2)
    pub gravity: f64,
    /// Propeller disc area A of both propellers (two 16-inch propellers) in (2.3.21). (m2)
    pub prop_disc_area: f64,
    /// Thrust time constant tau_T of the first-order motor lag (2.3.16). (s)
    pub tau_thrust: f64,
    /// Lower thrust limit (no reverse thrust). (N)
    pub thrust_min: f64,
    /// Upper thrust limit (thrust-to-weight about 1.7). (N)
    pub thrust_max: f64,
    /// Servo first-order time constant (App. D.5). (s)
    pub servo_tau: f64,
    /// Servo slew-rate limit (App. D.5). (rad/s)
    pub servo_rate_limit: f64,
    /// Deflection limit of every surface, +/- (App. D.5). (rad)
    pub deflection_limit: f64,
    /// Angle of attack of the second column of Tables C.3/C.4 (the first column is alpha = 0); derivatives are interpolated linearly in alpha. (rad)
    pub alpha_1: f64,
    /// The alpha used to interpolate the derivatives is clamped to +/- this value (2 x alpha_1 by default). (rad)
    pub alpha_interp_limit: f64,
    /// C_L_alpha, lift per rad of angle of attack, at alpha = 0 (Table C.3).
    pub c_L_alpha_a0: f64,
    /// C_L_alpha, lift per rad of angle of attack, at alpha = alpha_1 (Table C.3).
    pub c_L_alpha_a1: f64,
    /// C_m_alpha, pitching moment per rad of angle of attack, at alpha = 0 (Table C.3).
    pub c_m_alpha_a0: f64,
    /// C_m_alpha, pitching moment per rad of angle of attack, at alpha = alpha_1 (Table C.3).
    pub c_m_alpha_a1: f64,
    /// C_Y_beta, side force per rad of sideslip, at alpha = 0 (Table C.3).
    pub c_Y_beta_a0: f64,
    /// C_Y_beta, side force per rad of sideslip, at alpha = alpha_1 (Table C.3).
    pub c_Y_beta_a1: f64,
    /// C_l_beta, rolling moment per rad of sideslip, at alpha = 0 (Table C.3).
    pub c_l_beta_a0: f64,
    /// C_l_beta, rolling moment per rad of sideslip, at alpha = alpha_1 (Table C.3).
    pub c_l_beta_a1: f64,
    /// C_n_beta, yawing moment per rad of sideslip, at alpha = 0 (Table C.3).
    pub c_n_beta_a0: f64,
    /// C_n_beta, yawing moment per rad of sideslip, at alpha = alpha_1 (Table C.3).
    pub c_n_beta_a1: f64,
    /// C_Y_p, side force per normalised roll rate p b/(2V), at alpha = 0 (Table C.3).
    pub c_Y_p_a0: f64,
    /// C_Y_p, side force per normalised roll rate p b/(2V), at alpha = alpha_1 (Table C.3).
    pub c_Y_p_a1: f64,
    /// C_l_p, rolling moment per normalised roll rate, at alpha = 0 (Table C.3).
    pub c_l_p_a0: f64,
    /// C_l_p, rolling moment per normalised roll rate, at alpha = alpha_1 (Table C.3).
    pub c_l_p_a1: f64,
    /// C_n_p, yawing moment per normalised roll rate, at alpha = 0 (Table C.3).
    pub c_n_p_a0: f64,
    /// C_n_p, yawing moment per normalised roll rate, at alpha = alpha_1 (Table C.3).
    pub c_n_p_a1: f64,
    /// C_L_q, lift per normalised pitch rate q c/(2V), at alpha = 0 (Table C.3).
    pub c_L_q_a0: f64,
    /// C_L_q, lift per normalised pitch rate q c/(2V), at alpha = alpha_1 (Table C.3).
    pub c_L_q_a1: f64,
    /// C_m_q, pitching moment per normalised pitch rate, at alpha = 0 (Table C.3).
    pub c_m_q_a0: f64,
    /// C_m_q, pitching moment per normalised pitch rate, at alpha = alpha_1 (Table C.3).
    pub c_m_q_a1: f64,
    /// C_Y_r, side force per normalised yaw rate r b/(2V), at alpha = 0 (Table C.3).
    pub c_Y_r_a0: f64,
    /// C_Y_r, side force per normalised yaw rate r b/(2V), at alpha = alpha_1 (Table C.3).
    pub c_Y_r_a1: f64,
    /// C_l_r, rolling moment per normalised yaw rate, at alpha = 0 (Table C.3).
    pub c_l_r_a0: f64,
    /// C_l_r, rolling moment per normalised yaw rate, at alpha = alpha_1 (Table C.3).
    pub c_l_r_a1: f64,
    /// C_n_r, yawing moment per normalised yaw rate, at alpha = 0 (Table C.3).
    pub c_n_r_a0: f64,
    /// C_n_r, yawing moment per normalised yaw rate, at alpha = alpha_1 (Table C.3).
    pub c_n_r_a1: f64,
    /// C_L_delta_e, lift per rad of elevator, at alpha = 0 (Table C.4).
    pub c_L_de_a0: f64,
    /// C_L_delta_e, lift per rad of elevator, at alpha = alpha_1 (Table C.4).
    pub c_L_de_a1: f64,
    /// C_m_delta_e, pitching moment per rad of elevator, at alpha = 0 (Table C.4).
    pub c_m_de_a0: f64,
    /// C_m_delta_e, pitching moment per rad of elevator, at alpha = alpha_1 (Table C.4).
    pub c_m_de_a1: f64,
    /// C_Y_delta_a, side force per rad of aileron, at alpha = 0 (Table C.4).
    pub c_Y_da_a0: f64,
    /// C_Y_delta_a, side force per rad of aileron, at alpha = alpha_1 (Table C.4).
    pub c_Y_da_a1: f64,
    /// C_l_delta_a, rolling moment per rad of aileron, at alpha = 0 (Table C.4).
    pub c_l_da_a0: f64,
    /// C_l_delta_a, rolling moment per rad of aileron, at alpha = alpha_1 (Table C.4).
    pub c_l_da_a1: f64,
    /// C_n_delta_a, yawing moment per rad of aileron, at alpha = 0 (Table C.4).
    pub c_n_da_a0: f64,
    /// C_n_delta_a, yawing moment per rad of aileron, at alpha = alpha_1 (Table C.4).
    pub c_n_da_a1: f64,
    /// C_Y_delta_r, side force per rad of rudder, at alpha = 0 (Table C.4).
    pub c_Y_dr_a0: f64,
    /// C_Y_delta_r, side force per rad of rudder, at alpha = alpha_1 (Table C.4).
    pub c_Y_dr_a1: f64,
    /// C_l_delta_r, rolling moment per rad of rudder, at alpha = 0 (Table C.4).
    pub c_l_dr_a0: f64,
    /// C_l_delta_r, rolling moment per rad of rudder, at alpha = alpha_1 (Table C.4).
    pub c_l_dr_a1: f64,
    /// C_n_delta_r, yawing moment per rad of rudder, at alpha = 0 (Table C.4).
    pub c_n_dr_a0: f64,
    /// C_n_delta_r, yawing moment per rad of rudder, at alpha = alpha_1 (Table C.4).
    pub c_n_dr_a1: f64,
    /// C_L_delta_fc, lift per rad of collective flaps, at alpha = 0 (Table C.4).
    pub c_L_dfc_a0: f64,
    /// C_L_delta_fc, lift per rad of collective flaps, at alpha = alpha_1 (Table C.4).
    pub c_L_dfc_a1: f64,
    /// C_m_delta_fc, pitching moment per rad of collective flaps, at alpha = 0 (Table C.4).
    pub c_m_dfc_a0: f64,
    /// C_m_delta_fc, pitching moment per rad of collective flaps, at alpha = alpha_1 (Table C.4).
    pub c_m_dfc_a1: f64,
    /// C_l_delta_fd, rolling moment per rad of differential flaps, at alpha = 0 (Table C.4).
    pub c_l_dfd_a0: f64,
    /// C_l_delta_fd, rolling moment per rad of differential flaps, at alpha = alpha_1 (Table C.4).
    pub c_l_dfd_a1: f64,
    /// C_n_delta_fd, yawing moment per rad of differential flaps, at alpha = 0 (Table C.4).
    pub c_n_dfd_a0: f64,
    /// C_n_delta_fd, yawing moment per rad of differential flaps, at alpha = alpha_1 (Table C.4).
    pub c_n_dfd_a1: f64,
    /// C_Y_delta_v, side force per rad of vertical flaps, at alpha = 0 (Table C.4).
    pub c_Y_dv_a0: f64,
    /// C_Y_delta_v, side force per rad of vertical flaps, at alpha = alpha_1 (Table C.4).
    pub c_Y_dv_a1: f64,
    /// C_l_delta_v, rolling moment per rad of vertical flaps, at alpha = 0 (Table C.4).
    pub c_l_dv_a0: f64,
    /// C_l_delta_v, rolling moment per rad of vertical flaps, at alpha = alpha_1 (Table C.4).
    pub c_l_dv_a1: f64,
    /// C_n_delta_v, yawing moment per rad of vertical flaps, at alpha = 0 (Table C.4).
    pub c_n_dv_a0: f64,
    /// C_n_delta_v, yawing moment per rad of vertical flaps, at alpha = alpha_1 (Table C.4).
    pub c_n_dv_a1: f64,
}

// `impl Default for Airframe` (the declared start values) and `Airframe::named_values`,
// generated by build.rs from the `airframe` group of modelDescription/tailsitter_plant.json.
include!(concat!(env!("OUT_DIR"), "/airframe_generated.rs"));

/// A rejected airframe parameter: names the parameter and says what is wrong.
#[derive(Debug, Clone, PartialEq)]
pub struct InvalidParameter {
    /// Parameter name (an `Airframe` field).
    pub name: &'static str,
    /// Offending value.
    pub value: f64,
    /// What it must be.
    pub requirement: &'static str,
}

impl InvalidParameter {
    /// `Err` of the parameter `name` whose `value` is not `requirement`.
    pub fn err<T>(name: &'static str, value: f64, requirement: &'static str) -> Result<T, Self> {
        Err(Self {
            name,
            value,
            requirement,
        })
    }
}

impl fmt::Display for InvalidParameter {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} = {} must be {}", self.name, self.value, self.requirement)
    }
}

impl std::error::Error for InvalidParameter {}

/// Stability and control derivatives at one angle of attack (interpolated, Tables C.3/C.4),
/// (C_D0, C_L0, C_m0 do not depend on α and stay in [`Airframe`]). Names follow the thesis: `c_L_alpha` is C_Lα etc.
#[allow(non_snake_case)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Coefficients {
    /// c_L_alpha interpolated in α.
    pub c_L_alpha: f64,
    /// c_m_alpha interpolated in α.
    pub c_m_alpha: f64,
    /// c_Y_beta interpolated in α.
    pub c_Y_beta: f64,
    /// c_l_beta interpolated in α.
    pub c_l_beta: f64,
    /// c_n_beta interpolated in α.
    pub c_n_beta: f64,
    /// c_Y_p interpolated in α.
    pub c_Y_p: f64,
    /// c_l_p interpolated in α.
    pub c_l_p: f64,
    /// c_n_p interpolated in α.
    pub c_n_p: f64,
    /// c_L_q interpolated in α.
    pub c_L_q: f64,
    /// c_m_q interpolated in α.
    pub c_m_q: f64,
    /// c_Y_r interpolated in α.
    pub c_Y_r: f64,
    /// c_l_r interpolated in α.
    pub c_l_r: f64,
    /// c_n_r interpolated in α.
    pub c_n_r: f64,
    /// c_L_de interpolated in α.
    pub c_L_de: f64,
    /// c_m_de interpolated in α.
    pub c_m_de: f64,
    /// c_Y_da interpolated in α.
    pub c_Y_da: f64,
    /// c_l_da interpolated in α.
    pub c_l_da: f64,
    /// c_n_da interpolated in α.
    pub c_n_da: f64,
    /// c_Y_dr interpolated in α.
    pub c_Y_dr: f64,
    /// c_l_dr interpolated in α.
    pub c_l_dr: f64,
    /// c_n_dr interpolated in α.
    pub c_n_dr: f64,
    /// c_L_dfc interpolated in α.
    pub c_L_dfc: f64,
    /// c_m_dfc interpolated in α.
    pub c_m_dfc: f64,
    /// c_l_dfd interpolated in α.
    pub c_l_dfd: f64,
    /// c_n_dfd interpolated in α.
    pub c_n_dfd: f64,
    /// c_Y_dv interpolated in α.
    pub c_Y_dv: f64,
    /// c_l_dv interpolated in α.
    pub c_l_dv: f64,
    /// c_n_dv interpolated in α.
    pub c_n_dv: f64,
}

impl Airframe {
    /// The derivatives interpolated linearly in α between the α = 0 column (`_a0`) and the
    /// α = `alpha_1` column (`_a1`) of Tables C.3/C.4; α is clamped to ±`alpha_interp_limit`
    /// first so the straight line is not extrapolated without bound.
    #[inline(always)]
    pub fn coefficients(&self, alpha: f64) -> Coefficients {
        let a = alpha.clamp(-self.alpha_interp_limit, self.alpha_interp_limit);
        let s = if self.alpha_1 != 0.0 {
            a * (1.0 / self.alpha_1)
        } else {
            0.0
        };
        let lerp = |a0: f64, a1: f64| a0 + (a1 - a0) * s;
        Coefficients {
            c_L_alpha: lerp(self.c_L_alpha_a0, self.c_L_alpha_a1),
            c_m_alpha: lerp(self.c_m_alpha_a0, self.c_m_alpha_a1),
            c_Y_beta: lerp(self.c_Y_beta_a0, self.c_Y_beta_a1),
            c_l_beta: lerp(self.c_l_beta_a0, self.c_l_beta_a1),
            c_n_beta: lerp(self.c_n_beta_a0, self.c_n_beta_a1),
            c_Y_p: lerp(self.c_Y_p_a0, self.c_Y_p_a1),
            c_l_p: lerp(self.c_l_p_a0, self.c_l_p_a1),
            c_n_p: lerp(self.c_n_p_a0, self.c_n_p_a1),
            c_L_q: lerp(self.c_L_q_a0, self.c_L_q_a1),
            c_m_q: lerp(self.c_m_q_a0, self.c_m_q_a1),
            c_Y_r: lerp(self.c_Y_r_a0, self.c_Y_r_a1),
            c_l_r: lerp(self.c_l_r_a0, self.c_l_r_a1),
            c_n_r: lerp(self.c_n_r_a0, self.c_n_r_a1),
            c_L_de: lerp(self.c_L_de_a0, self.c_L_de_a1),
            c_m_de: lerp(self.c_m_de_a0, self.c_m_de_a1),
            c_Y_da: lerp(self.c_Y_da_a0, self.c_Y_da_a1),
            c_l_da: lerp(self.c_l_da_a0, self.c_l_da_a1),
            c_n_da: lerp(self.c_n_da_a0, self.c_n_da_a1),
            c_Y_dr: lerp(self.c_Y_dr_a0, self.c_Y_dr_a1),
            c_l_dr: lerp(self.c_l_dr_a0, self.c_l_dr_a1),
            c_n_dr: lerp(self.c_n_dr_a0, self.c_n_dr_a1),
            c_L_dfc: lerp(self.c_L_dfc_a0, self.c_L_dfc_a1),
            c_m_dfc: lerp(self.c_m_dfc_a0, self.c_m_dfc_a1),
            c_l_dfd: lerp(self.c_l_dfd_a0, self.c_l_dfd_a1),
            c_n_dfd: lerp(self.c_n_dfd_a0, self.c_n_dfd_a1),
            c_Y_dv: lerp(self.c_Y_dv_a0, self.c_Y_dv_a1),
            c_l_dv: lerp(self.c_l_dv_a0, self.c_l_dv_a1),
            c_n_dv: lerp(self.c_n_dv_a0, self.c_n_dv_a1),
        }
    }

    /// Check every parameter: finite everywhere; mass, inertias, areas, lengths, density,
    /// disc area, time constants, servo rate and the interpolation angle positive; gravity,
    /// deflection limit and interpolation limit non-negative; `thrust_min <= thrust_max`.
    pub fn validate(&self) -> Result<(), InvalidParameter> {
        let bad = InvalidParameter::err;
        for (name, value) in self.named_values() {
            if !value.is_finite() {
                return bad(name, value, "finite");
            }
        }
        // Looked up by name in `named_values` (the generated list of every field).
        let values = self.named_values();
        let value_of = |name: &str| {
            let found = values.iter().find(|(n, _)| *n == name);
            found.unwrap_or_else(|| panic!("{name} is not an Airframe parameter")).1
        };
        const POSITIVE: [&str; 15] = [
            "mass",
            "i_xx",
            "i_yy",
            "i_zz",
            "wing_area",
            "mean_chord",
            "wing_span",
            "aspect_ratio",
            "oswald_efficiency",
            "prop_disc_area",
            "tau_thrust",
            "servo_tau",
            "servo_rate_limit",
            "alpha_1",
            "alpha_interp_limit",
        ];
        for name in POSITIVE {
            let value = value_of(name);
            if value <= 0.0 {
                return bad(name, value, "positive");
            }
        }
        let non_negative: [(&'static str, f64); 4] = [
            ("air_density", self.air_density),
            ("gravity", self.gravity),
            ("deflection_limit", self.deflection_limit),
            ("c_D0", self.c_D0),
        ];
        for (name, value) in non_negative {
            if value < 0.0 {
                return bad(name, value, "non-negative");
            }
        }
        if self.thrust_min > self.thrust_max {
            return bad("thrust_min", self.thrust_min, "<= thrust_max");
        }
        Ok(())
    }
}
