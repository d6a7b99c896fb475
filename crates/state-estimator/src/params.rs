//! Parameters of the estimator: sensor noise (thesis Table D.1), process noise, the
//! reference point and Earth field, initial uncertainties.

use nalgebra::Vector3;
use tailsitter_physics::{Airframe, Site};

/// Measurement noise σ of the sensors (defaults: thesis Table D.1) and the IMU period.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SensorNoise {
    /// GPS latitude and longitude σ (rad) (Table D.1: 6.2832e-7 rad ≈ 4 m).
    pub sigma_gps_latlon: f64,
    /// GPS height σ (m) (Table D.1: 4 m).
    pub sigma_gps_height: f64,
    /// GPS velocity σ per NED axis (m/s) (Table D.1: 0.5 m/s).
    pub sigma_gps_vel: f64,
    /// Accelerometer σ per axis of the delivered samples (m/s²) (Table D.1: 0.1414 m/s²).
    pub sigma_accel: f64,
    /// Rate-gyro σ per axis of the delivered samples (rad/s) (Table D.1: 27.925e-3 rad/s).
    pub sigma_gyro: f64,
    /// Magnetometer σ per axis of the delivered samples (Gauss) (Table D.1: 0.02 Gauss).
    pub sigma_mag: f64,
    /// σ of the pitot's delivered differential pressure (Pa): the sensors' `pitot_std`
    /// (1 Pa). With Δp = ½ρ₀u|u| the airspeed σ is σ_Δp/(ρ₀|u|) (ρ₀ = 1.225 kg/m³, the
    /// sensors' indication density).
    pub sigma_pitot_dp: f64,
    /// Pitot model-error σ (m/s), added in quadrature: the reading lags the body-x airspeed
    /// by the filter's delay (≈ 28 ms: 0.14 m/s at 5 m/s²) and the air density may differ
    /// from ρ₀.
    pub sigma_pitot: f64,
    /// Correlation time T_imu of the IMU samples' noise (s): σ²·T_imu is the density of the
    /// white noise the strapdown integrates. 0 (default): derived from the sensors' filter at
    /// the estimator's step, [`AnalogFilter::noise_correlation_time`].
    pub imu_period: f64,
}

/// Process noise beyond the IMU's own noise.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProcessNoise {
    /// Acceleration model-error density (m/s^{3/2}): covers the zero-order hold of the
    /// specific force over a step while the aircraft manoeuvres.
    pub accel_model: f64,
    /// Angular-rate model-error density (rad/s^{1/2}): the same for the rates.
    pub gyro_model: f64,
    /// Gyro-bias random walk (rad/s/√s).
    pub gyro_bias_walk: f64,
    /// Accelerometer-bias random walk (m/s²/√s).
    pub accel_bias_walk: f64,
    /// Wind random walk (m/s/√s).
    pub wind_walk: f64,
}

/// Reference point of the local NED frame and the Earth's fields there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Earth {
    /// Reference point and magnetic field: the sensor model's (one declaration).
    pub site: Site,
    /// Gravitational acceleration (m/s²), as the plant's `gravity` (9.81).
    pub gravity: f64,
}

impl SensorNoise {
    /// σ of a pitot reading `airspeed` (m/s): σ_Δp/(ρ₀ max(|u|, `min_airspeed`)) and the
    /// model error in quadrature. Δp = ½ρ₀u|u| ⇒ du/dΔp = 1/(ρ₀|u|).
    pub fn pitot_sigma(&self, airspeed: f64, min_airspeed: f64) -> f64 {
        /// Density of the sensors' indicated airspeed (kg/m³) (ISA sea level).
        const RHO_0: f64 = 1.225;
        let u = airspeed.abs().max(min_airspeed).max(1e-3);
        ((self.sigma_pitot_dp / (RHO_0 * u)).powi(2) + self.sigma_pitot.powi(2)).sqrt()
    }
}

impl Earth {
    /// The Earth field in NED components (Gauss): F(cos I cos D, cos I sin D, sin I).
    pub fn mag_ned(&self) -> Vector3<f64> {
        let s = &self.site;
        let (si, ci) = s.mag_inclination.sin_cos();
        let (sd, cd) = s.mag_declination.sin_cos();
        s.mag_field_total * Vector3::new(ci * cd, ci * sd, si)
    }
}

/// Initial values and uncertainties of the states not set from a measurement, and
/// behaviour limits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tuning {
    /// Initial wind σ per axis (m/s).
    pub init_std_wind: f64,
    /// Initial gyro-bias σ per axis (rad/s).
    pub init_std_gyro_bias: f64,
    /// Initial accelerometer-bias σ per axis (m/s²).
    pub init_std_accel_bias: f64,
    /// Initial position σ per axis without a GPS fix at initialisation (m).
    pub init_std_pos_no_gps: f64,
    /// Initial velocity σ per axis without a GPS fix at initialisation (m/s).
    pub init_std_vel_no_gps: f64,
    /// Thrust state T of the motor model at initialisation (N), clamped to the thrust
    /// limits: what the motor holds when the estimator starts (the plant's `trim_thrust`).
    /// A state of the lag (2.3.16), T(t₀) does not depend on the command at t₀.
    pub init_thrust: f64,
    /// Elevator deflection of the servo model at initialisation (rad), clamped to the
    /// deflection limit (the plant's `trim_elevator`); the other surfaces start at 0, as in
    /// every (symmetric) trim the plant starts in.
    pub init_elevator: f64,
    /// The pitot is fused only above this reading (m/s): at lower airspeed (hover) the
    /// pressure is too small to resolve.
    pub pitot_min_airspeed: f64,
    /// σ of the zero-sideslip pseudo-measurement (rad): above `sideslip_min_airspeed` the
    /// aircraft is assumed to fly with β ≈ 0, which makes the cross-wind observable (the
    /// pitot only measures along body x). 0 disables it.
    pub sigma_sideslip: f64,
    /// Airspeed above which the zero-sideslip pseudo-measurement is fused (m/s).
    pub sideslip_min_airspeed: f64,
    /// Fuse the zero-sideslip pseudo-measurement (an extra beyond App. D.4) (–).
    pub sideslip_pseudo_measurement: bool,
    /// After this many consecutive rejected GPS position (or velocity) fixes the filter
    /// resets that block to the GPS: the filter, not the GPS, has lost track.
    pub gps_reset_after: u32,
    /// The position outputs are relative to the aircraft's position at initialisation (the
    /// mission's start, where the reference path begins) instead of the reference point: the
    /// estimate of the start position is a clone of the position at initialisation in the
    /// filter state, refined by every later fix through its correlation, so the outputs carry
    /// the error of the displacement since the start, not the first fix's (σ 4 m per axis).
    /// The aircraft must start at the NED origin the controllers' mission assumes.
    pub relative_to_start: bool,
    /// Fuse zero velocity while the aircraft rests on its gear (an extra beyond App. D.4;
    /// see [`crate::Ekf`]'s at-rest detector): the start position is the mean of every fix
    /// taken on the gear, and the displacement since the start stays 0 until the lift-off.
    pub zero_velocity_update: bool,
    /// σ of the zero-velocity pseudo-measurement per axis (m/s).
    pub sigma_zero_velocity: f64,
    /// Fuse the accelerometer's body y/z specific force against the aircraft's force model
    /// at the estimated air velocity (an extra beyond App. D.4; see
    /// [`crate::Ekf`]'s aerodynamic specific-force update): the horizontal wind in hover.
    pub aero_force_update: bool,
    /// Model-error σ floor of that update per axis (m/s²).
    pub sigma_aero_force: f64,
    /// Relative model error of that update (–): σ = this × |model's f_y, f_z|.
    pub aero_force_model_error: f64,
    /// At rest: least share of the weight the gear carries, `f_x/g − T/(m g)` from the
    /// bias-corrected specific force along the thrust axis and the motor model's thrust (–).
    pub rest_gear_share: f64,
    /// At rest: largest estimated speed (m/s).
    pub rest_max_speed: f64,
    /// At rest: largest bias-corrected body rate |ω| (rad/s).
    pub rest_max_rate: f64,
    /// At rest: time the conditions must have held before zero velocity is fused (s).
    pub rest_dwell: f64,
}

/// The avionics' analogue low-pass filter on the IMU, magnetometer and pitot channels
/// (thesis App. D.3: second-order Butterworth), as the sensor model's `filter_enabled`,
/// `filter_bandwidth`. The estimator compensates its group delay (see [`AnalogFilter::delay`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AnalogFilter {
    /// The sensors' channels are filtered (–).
    pub enabled: bool,
    /// −3 dB frequency f_c of the Butterworth (Hz) (8 Hz).
    pub bandwidth: f64,
    /// Compensate the filter's group delay (an extra beyond App. D.4) (–): else the samples
    /// are taken as undelayed (only `latency` is compensated).
    pub compensate: bool,
    /// Transport delay of the measurement inputs (s) (0): the age of the latest sample at
    /// the communication point beyond the filter's delay, e.g. one communication step when
    /// a Jacobi master gives the estimator the sensors' outputs of the previous step.
    pub latency: f64,
}

impl AnalogFilter {
    /// Low-frequency group delay of the second-order Butterworth (s):
    /// H(s) = Ω²/(s² + √2Ωs + Ω²) has phase −atan(√2Ωω/(Ω² − ω²)) ≈ −√2 ω/Ω for ω ≪ Ω, so
    /// τ = √2/Ω = √2/(2π f_c) (28.1 ms at 8 Hz; 0 when the filter is off or not
    /// compensated), plus the transport `latency`.
    pub fn delay(&self) -> f64 {
        let filter = if self.enabled && self.compensate {
            std::f64::consts::SQRT_2 / (2.0 * std::f64::consts::PI * self.bandwidth)
        } else {
            0.0
        };
        filter + self.latency
    }
}

impl AnalogFilter {
    /// Correlation time (s) of the delivered noise as the estimator samples it, one sample
    /// per step `h`: T = h Σ_{k∈ℤ} ρ(kh), so that σ²T is the density of the white noise with
    /// the same low-frequency spectrum (what the strapdown integrates). Through the
    /// Butterworth (ζ = 1/√2, a = Ω/√2) the normalised autocorrelation is
    /// ρ(τ) = e^{−a|τ|}(cos aτ + sin a|τ|) (white input); with z = e^{(−1+i)ah} the sum is
    /// 1 + 2(Re + Im)(z/(1 − z)). T → ∫ρ dτ = 1/(2B_n) = √2/(π f_c) (56.3 ms at 8 Hz) for
    /// h ≪ 1/f_c (B_n = π f_c/(2√2), the noise bandwidth), 56.35 ms at h = 20 ms; h
    /// without the filter (independent samples, each held over its step).
    pub fn noise_correlation_time(&self, h: f64) -> f64 {
        if !self.enabled || h.is_nan() || h <= 0.0 {
            return h.max(0.0);
        }
        let ah = std::f64::consts::PI * std::f64::consts::SQRT_2 * self.bandwidth * h;
        let r = (-ah).exp();
        let (zr, zi) = (r * ah.cos(), r * ah.sin());
        // z/(1 − z) = z(1 − z̄)/|1 − z|².
        let d = (1.0 - zr).powi(2) + zi * zi;
        let (sr, si) = ((zr * (1.0 - zr) - zi * zi) / d, zi / d);
        h * (1.0 + 2.0 * (sr + si))
    }
}

/// Delay compensation of the outputs by the estimator's aircraft model.
///
/// The latest IMU sample describes the aircraft [`AnalogFilter::delay`] before the
/// communication point; the controller applies its command `lead` after the end of the
/// estimator's step. With `model` the estimator integrates its own model of the aircraft
/// (the [`Airframe`]'s forces and moments, motor and servos, driven by the commands it was
/// given) from the sample's time to the output's and adds the model's change of the rates
/// and specific force to the sample (a Smith predictor: the measurement anchors the
/// prediction, the model only supplies the change over the delay). Without `model` the
/// samples are extrapolated by their backward difference (noisy).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Prediction {
    /// Predict with the aircraft model (else extrapolate the samples) (–).
    pub model: bool,
    /// Lead of the outputs beyond the end of the step (s) (0): the controller applies the
    /// command computed from them this much later, e.g. one communication step under a
    /// Jacobi master (the plant gets the controller's output of the previous step).
    pub lead: f64,
    /// Aerodynamic model of the prediction, as the plant's `aero_model` (–): 0 the thesis's
    /// linear derivatives, 1 the global model (the plant FMU's default; identical to the
    /// thesis's for |α| ≤ 10°, |β| ≤ 15°).
    pub aero_model: i32,
}

// `impl Default` of SensorNoise, ProcessNoise, Earth, Tuning, AnalogFilter and Prediction:
// the start values of group `estimator` of modelDescription/tailsitter_ekf.json, generated
// by build.rs.
include!(concat!(env!("OUT_DIR"), "/estimator_params_generated.rs"));

/// Everything the estimator needs besides the measurements.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct EstimatorParams {
    pub noise: SensorNoise,
    /// The sensors' analogue filter (compensated).
    pub filter: AnalogFilter,
    /// Compensation of the delays by the aircraft model.
    pub prediction: Prediction,
    pub process: ProcessNoise,
    pub earth: Earth,
    pub tuning: Tuning,
    /// The airframe: motor and servo models (τ_T, thrust limits, servo τ, rate and
    /// deflection limits) and the propeller for the induced velocity (ρ, disc area).
    pub airframe: Airframe,
}

impl EstimatorParams {
    /// The App.-D-faithful configuration (thesis App. D.4): the measurement variances of
    /// Table D.1 (GPS, accelerometers, rate gyros, magnetometer) and every extra beyond
    /// D.4 off — the model prediction over the delays, the start-relative position, the
    /// compensation of the sensors' filter delay, the zero-sideslip pseudo-measurement, the
    /// zero-velocity update at rest and the aerodynamic specific-force update. Everything else (process noise, pitot, priors, the airframe) is kept.
    pub fn app_d(mut self) -> Self {
        let table_d1 = SensorNoise::default();
        self.noise.sigma_gps_latlon = table_d1.sigma_gps_latlon;
        self.noise.sigma_gps_height = table_d1.sigma_gps_height;
        self.noise.sigma_gps_vel = table_d1.sigma_gps_vel;
        self.noise.sigma_accel = table_d1.sigma_accel;
        self.noise.sigma_gyro = table_d1.sigma_gyro;
        self.noise.sigma_mag = table_d1.sigma_mag;
        self.prediction.model = false;
        self.tuning.relative_to_start = false;
        self.filter.compensate = false;
        self.tuning.sideslip_pseudo_measurement = false;
        self.tuning.zero_velocity_update = false;
        self.tuning.aero_force_update = false;
        self
    }

    /// Every value finite and in its domain; the error names the parameter.
    pub fn validate(&self) -> Result<(), String> {
        let positive = [
            ("sigma_gps_latlon", self.noise.sigma_gps_latlon),
            ("sigma_gps_height", self.noise.sigma_gps_height),
            ("sigma_gps_vel", self.noise.sigma_gps_vel),
            ("sigma_accel", self.noise.sigma_accel),
            ("sigma_gyro", self.noise.sigma_gyro),
            ("sigma_mag", self.noise.sigma_mag),
            ("sigma_pitot", self.noise.sigma_pitot),
            ("sigma_pitot_dp", self.noise.sigma_pitot_dp),
            ("mag_field_total", self.earth.site.mag_field_total),
            ("gravity", self.earth.gravity),
            ("init_std_wind", self.tuning.init_std_wind),
            ("init_std_gyro_bias", self.tuning.init_std_gyro_bias),
            ("init_std_accel_bias", self.tuning.init_std_accel_bias),
            ("init_std_pos_no_gps", self.tuning.init_std_pos_no_gps),
            ("init_std_vel_no_gps", self.tuning.init_std_vel_no_gps),
            ("sigma_zero_velocity", self.tuning.sigma_zero_velocity),
        ];
        for (name, v) in positive {
            if !(v.is_finite() && v > 0.0) {
                return Err(format!("{name} = {v} must be finite and > 0"));
            }
        }
        let non_negative = [
            ("imu_period", self.noise.imu_period),
            ("accel_model_noise", self.process.accel_model),
            ("gyro_model_noise", self.process.gyro_model),
            ("gyro_bias_walk", self.process.gyro_bias_walk),
            ("accel_bias_walk", self.process.accel_bias_walk),
            ("wind_walk", self.process.wind_walk),
            ("pitot_min_airspeed", self.tuning.pitot_min_airspeed),
            ("sigma_sideslip", self.tuning.sigma_sideslip),
            ("sideslip_min_airspeed", self.tuning.sideslip_min_airspeed),
            ("init_thrust", self.tuning.init_thrust),
            ("rest_max_speed", self.tuning.rest_max_speed),
            ("rest_max_rate", self.tuning.rest_max_rate),
            ("rest_dwell", self.tuning.rest_dwell),
            ("sigma_aero_force", self.tuning.sigma_aero_force),
            ("aero_force_model_error", self.tuning.aero_force_model_error),
        ];
        for (name, v) in non_negative {
            if !(v.is_finite() && v >= 0.0) {
                return Err(format!("{name} = {v} must be finite and >= 0"));
            }
        }
        if !self.tuning.rest_gear_share.is_finite() {
            return Err(format!(
                "rest_gear_share = {} must be finite",
                self.tuning.rest_gear_share
            ));
        }
        if !self.tuning.init_elevator.is_finite() {
            return Err(format!(
                "init_elevator = {} rad must be finite",
                self.tuning.init_elevator
            ));
        }
        if !(self.filter.bandwidth.is_finite() && self.filter.bandwidth > 0.0) {
            return Err(format!(
                "filter_bandwidth = {} Hz must be finite and > 0",
                self.filter.bandwidth
            ));
        }
        if !(self.filter.latency.is_finite() && (0.0..=1.0).contains(&self.filter.latency)) {
            return Err(format!(
                "measurement_latency = {} s must be within [0, 1] s",
                self.filter.latency
            ));
        }
        if !(self.prediction.lead.is_finite() && (0.0..=1.0).contains(&self.prediction.lead)) {
            return Err(format!(
                "prediction_lead = {} s must be within [0, 1] s",
                self.prediction.lead
            ));
        }
        if tailsitter_physics::AeroModel::from_index(self.prediction.aero_model).is_none() {
            return Err(format!("aero_model = {} must be 0 or 1", self.prediction.aero_model));
        }
        let e = &self.earth.site;
        if !e.ref_latitude.is_finite() || e.ref_latitude.abs() > 1.5 {
            return Err(format!(
                "ref_latitude = {} rad must be within ±1.5 rad (the NED frame degenerates at the poles)",
                e.ref_latitude
            ));
        }
        if !e.ref_longitude.is_finite() || e.ref_longitude.abs() > std::f64::consts::PI {
            return Err(format!("ref_longitude = {} rad must be within ±π", e.ref_longitude));
        }
        if !(e.ref_height.is_finite() && e.ref_height.abs() <= 1e5) {
            return Err(format!("ref_height = {} m must be within ±1e5 m", e.ref_height));
        }
        if !(e.mag_inclination.is_finite() && e.mag_declination.is_finite())
            || e.mag_inclination.abs() >= 1.5
            || e.mag_declination.abs() > std::f64::consts::PI
        {
            return Err(format!(
                "mag_inclination = {} rad must be within ±1.5 rad (a horizontal component is needed for heading) and mag_declination = {} rad within ±π",
                e.mag_inclination, e.mag_declination
            ));
        }
        self.airframe.validate().map_err(|e| e.to_string())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The closed form of T = h Σ ρ(kh) against the brute-force sum, its limits (h without
    /// the filter; √2/(π f_c) = 1/(2B_n) for h ≪ 1/f_c) and the value at the 20 ms step.
    #[test]
    fn imu_noise_correlation_time() {
        let f = AnalogFilter::default();
        let rho = |tau: f64| {
            let a = 2.0 * std::f64::consts::PI * f.bandwidth / std::f64::consts::SQRT_2;
            (-a * tau.abs()).exp() * ((a * tau).cos() + (a * tau.abs()).sin())
        };
        for h in [0.001, 0.005, 0.02, 0.05] {
            let brute = h * (1.0 + 2.0 * (1..100_000).map(|k| rho(k as f64 * h)).sum::<f64>());
            let t = f.noise_correlation_time(h);
            assert!((t - brute).abs() < 1e-12, "{h}: {t} vs {brute}");
        }
        let limit = std::f64::consts::SQRT_2 / (std::f64::consts::PI * f.bandwidth);
        assert!((f.noise_correlation_time(1e-5) / limit - 1.0).abs() < 1e-6);
        let t20 = f.noise_correlation_time(0.02);
        assert!((t20 - 0.05635).abs() < 5e-5, "{t20}");
        let off = AnalogFilter { enabled: false, ..f };
        assert_eq!(off.noise_correlation_time(0.02), 0.02);
        // The compensation switch does not change the noise.
        let uncompensated = AnalogFilter { compensate: false, ..f };
        assert_eq!(uncompensated.noise_correlation_time(0.02), t20);
        assert_eq!(uncompensated.delay(), 0.0);
    }

    #[test]
    fn app_d_turns_every_extra_off_and_keeps_table_d1() {
        let mut tuned = EstimatorParams::default();
        tuned.noise.sigma_mag = 0.5;
        let p = tuned.app_d();
        assert!(!p.prediction.model && !p.tuning.relative_to_start);
        assert!(!p.filter.compensate && !p.tuning.sideslip_pseudo_measurement);
        assert!(!p.tuning.zero_velocity_update && !p.tuning.aero_force_update);
        assert_eq!(p.noise.sigma_mag, 0.02);
        assert_eq!(p.noise.sigma_accel, 0.1414);
        assert_eq!(p.noise.sigma_gyro, 27.925e-3);
        assert!(p.validate().is_ok());
    }
}
