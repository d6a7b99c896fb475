//! Sensor model of the tail-sitter's avionics (thesis App. D.3, Table D.1):
//! GPS, three-axis accelerometer and rate gyro, magnetometer and pitot, each at
//! its own sample rate, with the avionics' 8 Hz second-order Butterworth on the
//! analogue channels, Table D.1 noise from a seeded platform-independent
//! generator, optional constant biases and fault injection.
//!
//! Pure Rust, no FFI: [`SensorModel::start`] takes the first samples at the start
//! time, [`SensorModel::step`] advances over one communication step with the
//! true state held, and [`State`] is everything that evolves (saved and restored
//! bit-exactly). See README.md for the timing semantics.

pub mod butterworth;
pub mod geodesy;
pub mod rng;

use butterworth::Butterworth2;
use geodesy::LocalTangent;
use nalgebra::{Vector3, Vector4};
use rng::{NoiseRng, SplitMix64};
use std::fmt;
pub use tailsitter_physics::Site;

/// ISA sea-level air density ρ₀ (kg/m³) of the indicated-airspeed definition.
pub const RHO_0: f64 = 1.225;
/// At most this many samples of one sensor are generated in a single step; the
/// earlier ones of a longer step are skipped (the filter forgets them within a
/// few hundred samples, and the truth is held over the step anyway).
pub const MAX_SAMPLES_PER_STEP: u64 = 10_000;
/// Highest sample rate accepted (Hz).
pub const MAX_RATE: f64 = 10_000.0;
/// A truth quaternion whose norm is further than this from 1 is rejected.
pub const QUAT_NORM_TOLERANCE: f64 = 0.1;
/// Largest magnitude of a true-state input (SI units): beyond it a value is no state of an
/// aircraft, and the filter and noise arithmetic could overflow to a non-finite (unsavable)
/// state (found by the call-sequence fuzzer: 1e308 inputs).
pub const INPUT_LIMIT: f64 = 1e7;
/// Largest noise σ and bias magnitude of the parameters (SI units), for the same reason.
pub const PARAM_LIMIT: f64 = 1e6;

/// The sensors, each with its own clock and noise stream.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Sensor {
    Accel = 0,
    Gyro = 1,
    Mag = 2,
    Pitot = 3,
    Gps = 4,
}

pub const N_SENSORS: usize = 5;
pub const SENSORS: [Sensor; N_SENSORS] = [Sensor::Accel, Sensor::Gyro, Sensor::Mag, Sensor::Pitot, Sensor::Gps];

/// Analogue channels (filtered), numbered 1…10 for `fault_channel`.
pub const N_ANALOG: usize = 10;
/// Names of the analogue channels in order (FMU output names).
pub const ANALOG_NAMES: [&str; N_ANALOG] = [
    "imu_accel_x",
    "imu_accel_y",
    "imu_accel_z",
    "imu_gyro_p",
    "imu_gyro_q",
    "imu_gyro_r",
    "mag_x",
    "mag_y",
    "mag_z",
    "pitot_airspeed",
];
const PITOT: usize = 9;

/// Injected fault on one analogue channel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FaultMode {
    None,
    /// The output freezes at its last value before the window.
    Stuck,
    /// `magnitude` (output unit) is added to the output inside the window.
    Offset,
}

/// Everything configurable (FMU parameters). Rates in Hz, standard deviations in
/// the unit of their channel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Params {
    /// Noise seed (–).
    pub seed: u64,
    /// Sample rates (Hz).
    pub accel_rate: f64,
    pub gyro_rate: f64,
    pub mag_rate: f64,
    pub pitot_rate: f64,
    pub gps_rate: f64,
    /// σ of latitude and longitude (rad), Table D.1.
    pub gps_latlon_std: f64,
    /// σ of height (m), Table D.1.
    pub gps_height_std: f64,
    /// σ of each NED velocity component (m/s), Table D.1.
    pub gps_vel_std: f64,
    /// σ of each accelerometer axis on the delivered (filtered) output (m/s²), Table D.1.
    pub accel_std: f64,
    /// σ of each gyro axis on the delivered output (rad/s), Table D.1.
    pub gyro_std: f64,
    /// σ of each magnetometer axis on the delivered output (Gauss), Table D.1.
    pub mag_std: f64,
    /// σ of the pitot's differential pressure after the filter (Pa).
    pub pitot_std: f64,
    /// Constant biases (channel units; pitot in Pa).
    pub accel_bias: Vector3<f64>,
    pub gyro_bias: Vector3<f64>,
    pub mag_bias: Vector3<f64>,
    pub pitot_bias: f64,
    /// Reference point (latitude, longitude, height above the ellipsoid) and Earth field
    /// (total intensity, declination, inclination), shared with the state estimator.
    pub site: Site,
    /// True air density at the pitot (kg/m³).
    pub air_density: f64,
    /// Butterworth on the analogue channels on/off, and its −3 dB frequency (Hz).
    pub filter_enabled: bool,
    pub filter_bandwidth: f64,
    /// GPS dropout window [start, start + duration) (s).
    pub gps_dropout_start: f64,
    pub gps_dropout_duration: f64,
    /// Fault on analogue channel `fault_channel` (1…10 as [`ANALOG_NAMES`], 0 none).
    pub fault_channel: i32,
    pub fault_mode: FaultMode,
    pub fault_start: f64,
    pub fault_duration: f64,
    pub fault_magnitude: f64,
}

// `impl Default for Params`: the start values of group `params` (and of `seed`,
// `fault_mode`) of modelDescription/tailsitter_sensors.json, generated by build.rs.
include!(concat!(env!("OUT_DIR"), "/sensor_params_generated.rs"));

/// A parameter out of range: its name and why.
#[derive(Debug, Clone, PartialEq)]
pub struct ParamError(pub String);

impl fmt::Display for ParamError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}
impl std::error::Error for ParamError {}

/// A truth input that cannot be measured (non-finite, not a rotation).
#[derive(Debug, Clone, PartialEq)]
pub struct InputError(pub String);

impl fmt::Display for InputError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}
impl std::error::Error for InputError {}

/// The true state the sensors see (plant outputs of the same names), held over a step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Truth {
    /// NED position of the CG (m).
    pub pos_ned: Vector3<f64>,
    /// Inertial velocity, earth axes (m/s).
    pub vel_ned: Vector3<f64>,
    /// Body rates p, q, r (rad/s).
    pub rates: Vector3<f64>,
    /// Attitude quaternion, thesis (A.2.8) order: `quat[3]` is the scalar part (–).
    pub quat: Vector4<f64>,
    /// Air-relative speed V̄ (m/s), angle of attack α and sideslip β (rad).
    pub airspeed: f64,
    pub alpha: f64,
    pub beta: f64,
    /// Specific force in body axes (m/s²).
    pub specific_force: Vector3<f64>,
}

impl Default for Truth {
    /// At rest, level, heading north: the accelerometer reads −g on z.
    fn default() -> Self {
        Self {
            pos_ned: Vector3::zeros(),
            vel_ned: Vector3::zeros(),
            rates: Vector3::zeros(),
            quat: Vector4::new(0.0, 0.0, 0.0, 1.0),
            airspeed: 0.0,
            alpha: 0.0,
            beta: 0.0,
            specific_force: Vector3::new(0.0, 0.0, -9.81),
        }
    }
}

impl Truth {
    /// Every input exactly 0 (the zero quaternion included: never a state of the plant).
    pub fn is_all_zero(&self) -> bool {
        self.pos_ned == Vector3::zeros()
            && self.vel_ned == Vector3::zeros()
            && self.rates == Vector3::zeros()
            && self.quat.iter().all(|x| *x == 0.0)
            && self.airspeed == 0.0
            && self.alpha == 0.0
            && self.beta == 0.0
            && self.specific_force == Vector3::zeros()
    }

    fn check(&self) -> Result<(), InputError> {
        let named: [(&str, f64); 19] = [
            ("pos_n", self.pos_ned.x),
            ("pos_e", self.pos_ned.y),
            ("pos_d", self.pos_ned.z),
            ("vel_n", self.vel_ned.x),
            ("vel_e", self.vel_ned.y),
            ("vel_d", self.vel_ned.z),
            ("p", self.rates.x),
            ("q", self.rates.y),
            ("r", self.rates.z),
            ("quat_1", self.quat[0]),
            ("quat_2", self.quat[1]),
            ("quat_3", self.quat[2]),
            ("quat_4", self.quat[3]),
            ("airspeed", self.airspeed),
            ("alpha", self.alpha),
            ("beta", self.beta),
            ("accel_x", self.specific_force.x),
            ("accel_y", self.specific_force.y),
            ("accel_z", self.specific_force.z),
        ];
        for (name, value) in named {
            if !value.is_finite() {
                return Err(InputError(format!("input {name} = {value} is not finite")));
            }
            if value.abs() > INPUT_LIMIT {
                return Err(InputError(format!(
                    "input {name} = {value} outside the plausible range ±{INPUT_LIMIT:e} (SI units)"
                )));
            }
        }
        let norm = self.quat.norm();
        if (norm - 1.0).abs() > QUAT_NORM_TOLERANCE {
            return Err(InputError(format!(
                "attitude quaternion (quat_1..quat_4) has norm {norm}: not a rotation (expected 1 ± {QUAT_NORM_TOLERANCE})"
            )));
        }
        if self.airspeed < 0.0 {
            return Err(InputError(format!(
                "input airspeed = {} m/s is negative",
                self.airspeed
            )));
        }
        Ok(())
    }
}

/// The sensor outputs (FMU outputs of the same names).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Measurements {
    /// Latitude, longitude (rad), height above the ellipsoid (m) of the last fix.
    pub gps_latitude: f64,
    pub gps_longitude: f64,
    pub gps_height: f64,
    /// NED velocity of the last fix (m/s).
    pub gps_vel: Vector3<f64>,
    /// Number of fixes so far (–).
    pub gps_fix_count: u32,
    /// False from a missed fix (dropout) to the next good one, and before the first fix.
    pub gps_valid: bool,
    /// Filtered analogue channels in [`ANALOG_NAMES`] order: specific force (m/s²),
    /// body rates (rad/s), body-axis field (Gauss), indicated airspeed (m/s).
    pub analog: [f64; N_ANALOG],
}

impl Measurements {
    pub fn accel(&self) -> Vector3<f64> {
        Vector3::new(self.analog[0], self.analog[1], self.analog[2])
    }
    pub fn gyro(&self) -> Vector3<f64> {
        Vector3::new(self.analog[3], self.analog[4], self.analog[5])
    }
    pub fn mag(&self) -> Vector3<f64> {
        Vector3::new(self.analog[6], self.analog[7], self.analog[8])
    }
    pub fn pitot_airspeed(&self) -> f64 {
        self.analog[PITOT]
    }
}

/// Everything that evolves: noise streams, sample clocks, filter states, held outputs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct State {
    /// One noise stream per sensor, so a sensor's noise does not depend on the others' rates
    /// or on the communication step.
    pub rng: [NoiseRng; N_SENSORS],
    /// Start time: origin of every sample grid (s).
    pub t0: f64,
    /// Index of each sensor's next sample (sample k at t0 + k / rate).
    pub next_sample: [u64; N_SENSORS],
    /// Butterworth states of the analogue channels (pitot: on the differential pressure).
    pub filter: [[f64; 2]; N_ANALOG],
    /// The held outputs.
    pub out: Measurements,
    /// Value of the stuck channel inside its fault window.
    pub stuck: Option<f64>,
    /// A step has sampled a true state (after it, an all-zero input is an error).
    pub fed: bool,
}

/// Number of u64 words of [`State::save`].
pub const STATE_WORDS: usize = N_SENSORS * 4 + 1 + N_SENSORS + 2 * N_ANALOG + 8 + N_ANALOG + 3;

impl State {
    /// Serialise to `STATE_WORDS` words (f64 as IEEE bits: bit-exact).
    pub fn save(&self, out: &mut dyn FnMut(u64)) {
        for r in &self.rng {
            r.to_parts().iter().for_each(|w| out(*w));
        }
        out(self.t0.to_bits());
        self.next_sample.iter().for_each(|k| out(*k));
        for f in &self.filter {
            out(f[0].to_bits());
            out(f[1].to_bits());
        }
        let m = &self.out;
        for x in [
            m.gps_latitude,
            m.gps_longitude,
            m.gps_height,
            m.gps_vel.x,
            m.gps_vel.y,
            m.gps_vel.z,
        ] {
            out(x.to_bits());
        }
        out(u64::from(m.gps_fix_count));
        out(u64::from(m.gps_valid));
        m.analog.iter().for_each(|x| out(x.to_bits()));
        out(u64::from(self.stuck.is_some()));
        out(self.stuck.unwrap_or(0.0).to_bits());
        out(u64::from(self.fed));
    }

    /// Read what [`Self::save`] wrote; rejects truncated or inconsistent data.
    pub fn restore(next: &mut dyn FnMut() -> Option<u64>) -> Result<Self, String> {
        let mut word = || next().ok_or_else(|| "sensor state truncated".to_string());
        let flag = |w: u64, what: &str| match w {
            0 => Ok(false),
            1 => Ok(true),
            _ => Err(format!("sensor state: {what} flag {w} is not 0/1")),
        };
        let mut rng = [NoiseRng::from_seed(0); N_SENSORS];
        for r in rng.iter_mut() {
            let s = [word()?, word()?, word()?, word()?];
            *r = NoiseRng::from_parts(s).ok_or_else(|| "sensor state: invalid noise generator state".to_string())?;
        }
        let finite = |x: f64, what: &str| {
            if x.is_finite() {
                Ok(x)
            } else {
                Err(format!("sensor state: {what} is not finite"))
            }
        };
        let t0 = finite(f64::from_bits(word()?), "t0")?;
        let mut next_sample = [0; N_SENSORS];
        for k in next_sample.iter_mut() {
            *k = word()?;
        }
        let mut filter = [[0.0; 2]; N_ANALOG];
        for f in filter.iter_mut() {
            f[0] = finite(f64::from_bits(word()?), "filter state")?;
            f[1] = finite(f64::from_bits(word()?), "filter state")?;
        }
        let mut g = [0.0; 6];
        for x in g.iter_mut() {
            *x = finite(f64::from_bits(word()?), "GPS output")?;
        }
        let count = word()?;
        let gps_fix_count = u32::try_from(count).map_err(|_| format!("sensor state: fix count {count}"))?;
        let gps_valid = flag(word()?, "gps_valid")?;
        let mut analog = [0.0; N_ANALOG];
        for x in analog.iter_mut() {
            *x = finite(f64::from_bits(word()?), "analogue output")?;
        }
        let has_stuck = flag(word()?, "stuck")?;
        let stuck = finite(f64::from_bits(word()?), "stuck value")?;
        let fed = flag(word()?, "fed")?;
        Ok(Self {
            rng,
            t0,
            next_sample,
            filter,
            out: Measurements {
                gps_latitude: g[0],
                gps_longitude: g[1],
                gps_height: g[2],
                gps_vel: Vector3::new(g[3], g[4], g[5]),
                gps_fix_count,
                gps_valid,
                analog,
            },
            stuck: has_stuck.then_some(stuck),
            fed,
        })
    }
}

/// Quantities derived once from the parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Derived {
    period: [f64; N_SENSORS],
    filter: [Butterworth2; 4],
    /// σ of the white noise before the filter (accel, gyro, mag, pitot): the delivered σ
    /// over the filter's noise gain, so that the output carries the parameter's σ.
    white_std: [f64; 4],
    tangent: LocalTangent,
    field_ned: Vector3<f64>,
}

/// The sensor model: parameters, derived constants and [`State`].
#[derive(Debug, Clone, PartialEq)]
pub struct SensorModel {
    params: Params,
    derived: Derived,
    state: State,
}

fn in_window(t: f64, start: f64, duration: f64) -> bool {
    duration > 0.0 && t >= start && t < start + duration
}

/// Indicated airspeed (m/s) of a differential pressure (Pa): signed, √(2|Δp|/ρ₀).
fn indicated_airspeed(dp: f64) -> f64 {
    (2.0 * dp.abs() / RHO_0).sqrt().copysign(dp)
}

impl Params {
    /// Check every parameter; the error names the first one out of range.
    pub fn validate(&self) -> Result<(), ParamError> {
        let bad = |name: &str, value: f64, why: &str| Err(ParamError(format!("{name} = {value}: {why}")));
        for (name, rate) in [
            ("accel_rate", self.accel_rate),
            ("gyro_rate", self.gyro_rate),
            ("mag_rate", self.mag_rate),
            ("pitot_rate", self.pitot_rate),
            ("gps_rate", self.gps_rate),
        ] {
            if !(rate.is_finite() && rate > 0.0 && rate <= MAX_RATE) {
                return bad(name, rate, &format!("a sample rate must be in (0, {MAX_RATE}] Hz"));
            }
        }
        for (name, std) in [
            ("gps_latlon_std", self.gps_latlon_std),
            ("gps_height_std", self.gps_height_std),
            ("gps_vel_std", self.gps_vel_std),
            ("accel_std", self.accel_std),
            ("gyro_std", self.gyro_std),
            ("mag_std", self.mag_std),
            ("pitot_std", self.pitot_std),
        ] {
            if !(std.is_finite() && (0.0..=PARAM_LIMIT).contains(&std)) {
                return bad(name, std, "a standard deviation must be finite, >= 0 and <= 1e6");
            }
        }
        let biases = [
            ("accel_bias", self.accel_bias.norm()),
            ("gyro_bias", self.gyro_bias.norm()),
            ("mag_bias", self.mag_bias.norm()),
            ("pitot_bias", self.pitot_bias),
        ];
        for (name, b) in biases {
            if !(b.is_finite() && b <= PARAM_LIMIT) {
                return bad(name, b, "a bias must be finite and <= 1e6 in magnitude");
            }
        }
        let s = &self.site;
        if LocalTangent::new(s.ref_latitude, s.ref_longitude, s.ref_height).is_none() {
            return Err(ParamError(format!(
                "reference point ({}, {}, {}): needs finite values, |ref_latitude| <= 89 deg, |ref_height| <= 100 km",
                s.ref_latitude, s.ref_longitude, s.ref_height
            )));
        }
        if !(s.mag_field_total.is_finite() && s.mag_field_total > 0.0 && s.mag_field_total < 1.0) {
            return bad(
                "mag_field_total",
                s.mag_field_total,
                "Earth field must be in (0, 1) Gauss",
            );
        }
        if !(s.mag_declination.is_finite() && s.mag_declination.abs() <= std::f64::consts::PI) {
            return bad("mag_declination", s.mag_declination, "must be within +/-pi rad");
        }
        if !(s.mag_inclination.is_finite() && s.mag_inclination.abs() <= std::f64::consts::FRAC_PI_2) {
            return bad("mag_inclination", s.mag_inclination, "must be within +/-pi/2 rad");
        }
        if !(self.air_density.is_finite() && self.air_density > 0.0 && self.air_density <= 2.0) {
            return bad("air_density", self.air_density, "must be in (0, 2] kg/m3");
        }
        if self.filter_enabled {
            for (name, rate) in [
                ("accel_rate", self.accel_rate),
                ("gyro_rate", self.gyro_rate),
                ("mag_rate", self.mag_rate),
                ("pitot_rate", self.pitot_rate),
            ] {
                if Butterworth2::low_pass(self.filter_bandwidth, rate).is_none() {
                    return Err(ParamError(format!(
                        "filter_bandwidth = {} Hz: must be > 0 and below {} x {name} ({rate} Hz)",
                        self.filter_bandwidth,
                        butterworth::MAX_CUTOFF_FRACTION
                    )));
                }
            }
        }
        for (name, x) in [
            ("gps_dropout_start", self.gps_dropout_start),
            ("fault_start", self.fault_start),
            ("fault_magnitude", self.fault_magnitude),
        ] {
            if !x.is_finite() {
                return bad(name, x, "must be finite");
            }
        }
        for (name, x) in [
            ("gps_dropout_duration", self.gps_dropout_duration),
            ("fault_duration", self.fault_duration),
        ] {
            if !(x.is_finite() && x >= 0.0) {
                return bad(name, x, "a duration must be finite and >= 0");
            }
        }
        if !(0..=N_ANALOG as i32).contains(&self.fault_channel) {
            return Err(ParamError(format!(
                "fault_channel = {}: expected 0 (none) or 1..{N_ANALOG} ({})",
                self.fault_channel,
                ANALOG_NAMES.join(", ")
            )));
        }
        Ok(())
    }

    fn rate(&self, s: Sensor) -> f64 {
        match s {
            Sensor::Accel => self.accel_rate,
            Sensor::Gyro => self.gyro_rate,
            Sensor::Mag => self.mag_rate,
            Sensor::Pitot => self.pitot_rate,
            Sensor::Gps => self.gps_rate,
        }
    }

    /// Earth field in NED (Gauss): F (cos I cos D, cos I sin D, sin I).
    pub fn field_ned(&self) -> Vector3<f64> {
        let (f, d, i) = (
            self.site.mag_field_total,
            self.site.mag_declination,
            self.site.mag_inclination,
        );
        let h = f * libm::cos(i);
        Vector3::new(h * libm::cos(d), h * libm::sin(d), f * libm::sin(i))
    }
}

impl SensorModel {
    /// A model with checked parameters; [`Self::start`] must run before [`Self::step`].
    pub fn new(params: Params) -> Result<Self, ParamError> {
        params.validate()?;
        let mut period = [0.0; N_SENSORS];
        for s in SENSORS {
            period[s as usize] = 1.0 / params.rate(s);
        }
        let filter_of = |rate: f64| {
            if params.filter_enabled {
                Butterworth2::low_pass(params.filter_bandwidth, rate).expect("validated")
            } else {
                Butterworth2::IDENTITY
            }
        };
        let filter = [
            filter_of(params.accel_rate),
            filter_of(params.gyro_rate),
            filter_of(params.mag_rate),
            filter_of(params.pitot_rate),
        ];
        let delivered = [params.accel_std, params.gyro_std, params.mag_std, params.pitot_std];
        let white_std = std::array::from_fn(|i| delivered[i] / filter[i].noise_gain());
        let derived = Derived {
            period,
            filter,
            white_std,
            tangent: LocalTangent::new(
                params.site.ref_latitude,
                params.site.ref_longitude,
                params.site.ref_height,
            )
            .expect("validated"),
            field_ned: params.field_ned(),
        };
        let mut sm = SplitMix64(params.seed);
        let rng = std::array::from_fn(|_| NoiseRng::from_seed(sm.next_u64()));
        let zero = Measurements {
            gps_latitude: params.site.ref_latitude,
            gps_longitude: params.site.ref_longitude,
            gps_height: params.site.ref_height,
            gps_vel: Vector3::zeros(),
            gps_fix_count: 0,
            gps_valid: false,
            analog: [0.0; N_ANALOG],
        };
        Ok(Self {
            params,
            derived,
            state: State {
                rng,
                t0: 0.0,
                next_sample: [0; N_SENSORS],
                filter: [[0.0; 2]; N_ANALOG],
                out: zero,
                stuck: None,
                fed: false,
            },
        })
    }

    pub fn params(&self) -> &Params {
        &self.params
    }

    pub fn state(&self) -> &State {
        &self.state
    }

    /// Replace the state (FMU-state restore); the parameters stay.
    pub fn set_state(&mut self, state: State) {
        self.state = state;
    }

    pub fn measurements(&self) -> Measurements {
        self.state.out
    }

    /// σ_out/σ_in of the Butterworth for white noise (accel, gyro, mag, pitot pressure);
    /// 1 with the filter disabled. The white noise before the filter has σ = the parameter's
    /// σ over this gain, so the delivered output carries the parameter's σ (Table D.1).
    pub fn noise_gains(&self) -> [f64; 4] {
        self.derived.filter.map(|f| f.noise_gain())
    }

    /// The noise-free value of every analogue channel (pitot: differential pressure, Pa).
    fn analog_truth(&self, truth: &Truth) -> [f64; N_ANALOG] {
        let p = &self.params;
        let f = truth.specific_force + p.accel_bias;
        let w = truth.rates + p.gyro_bias;
        let c = tailsitter_physics::dcm_earth_to_body(&truth.quat);
        let m = c * self.derived.field_ned + p.mag_bias;
        // Flow along body x: u_r = V̄ cos α cos β (2.2.12–13); Δp = ½ρ u_r|u_r|.
        let u_r = truth.airspeed * libm::cos(truth.alpha) * libm::cos(truth.beta);
        let dp = 0.5 * p.air_density * u_r * u_r.abs() + p.pitot_bias;
        [f.x, f.y, f.z, w.x, w.y, w.z, m.x, m.y, m.z, dp]
    }

    /// First samples at the start time `t0`: filters start in steady state on the
    /// noise-free value (no start-up transient), then every sensor samples once
    /// (its sample k = 0). Resets the clocks, filters and fix count; the noise
    /// streams continue (reseed by building a new model).
    pub fn start(&mut self, truth: &Truth, t0: f64) -> Result<Measurements, InputError> {
        if !t0.is_finite() {
            return Err(InputError(format!("start time {t0} is not finite")));
        }
        truth.check()?;
        let x = self.analog_truth(truth);
        let st = &mut self.state;
        st.t0 = t0;
        st.next_sample = [0; N_SENSORS];
        for (c, xc) in x.iter().enumerate() {
            st.filter[c] = self.derived.filter[Self::group(c) as usize].steady_state(*xc);
        }
        let (lat, lon, h) = self
            .derived
            .tangent
            .geodetic(truth.pos_ned.x, truth.pos_ned.y, truth.pos_ned.z);
        st.out = Measurements {
            gps_latitude: lat,
            gps_longitude: lon,
            gps_height: h,
            gps_vel: truth.vel_ned,
            gps_fix_count: 0,
            gps_valid: false,
            analog: x,
        };
        st.out.analog[PITOT] = indicated_airspeed(x[PITOT]);
        st.stuck = None;
        st.fed = false;
        self.sample_until(
            truth,
            &x,
            t0 + 0.5 * self.derived.period.iter().copied().fold(f64::INFINITY, f64::min),
        );
        Ok(self.state.out)
    }

    /// Advance over the communication step [t, t + h) with the truth held: every
    /// sample instant t₀ + k/rate in it is taken (noise at the sensor's rate, filter
    /// at that rate); the outputs then hold each sensor's latest sample.
    pub fn step(&mut self, truth: &Truth, t: f64, h: f64) -> Result<Measurements, InputError> {
        if !(t.is_finite() && h.is_finite() && h >= 0.0) {
            return Err(InputError(format!("step from t = {t} s by h = {h} s")));
        }
        truth.check()?;
        let x = self.analog_truth(truth);
        self.sample_until(truth, &x, t + h);
        self.state.fed = true;
        Ok(self.state.out)
    }

    /// As [`Self::step`], except that an all-zero true state before the first step that
    /// sampled a true state is "no plant sample yet": nothing is sampled, the outputs of the
    /// start are held and the sample schedule is not advanced (the samples due are taken at
    /// the next step, on its true state, so each sensor's noise still depends only on its
    /// sample number). A master whose connections start at 0.0 before any unit has stepped
    /// (fmpy's `simulate_ssp`: every connector 0.0 in the first step, the zero quaternion
    /// among them) gets `Ok((outputs, true))`, and should be told (a warning). After a
    /// sampled step an all-zero state is refused like any other invalid state.
    pub fn step_or_hold(&mut self, truth: &Truth, t: f64, h: f64) -> Result<(Measurements, bool), InputError> {
        if !self.state.fed && truth.is_all_zero() && t.is_finite() && h.is_finite() && h >= 0.0 {
            return Ok((self.state.out, true));
        }
        self.step(truth, t, h).map(|m| (m, false))
    }

    fn group(channel: usize) -> Sensor {
        match channel {
            0..=2 => Sensor::Accel,
            3..=5 => Sensor::Gyro,
            6..=8 => Sensor::Mag,
            _ => Sensor::Pitot,
        }
    }

    /// The sample indices [first, end) of sensor `s` with instants before `t_end`.
    fn due(&mut self, s: Sensor, t_end: f64) -> (u64, u64) {
        let period = self.derived.period[s as usize];
        // Sample k is due iff t0 + k·period < t_end (a 10⁻⁶-period margin absorbs the
        // rounding of t + h: an instant on a step boundary belongs to the next step).
        let x = (t_end - self.state.t0) / period - 1e-6;
        let end = if x > 0.0 {
            x.ceil().min(u64::MAX as f64) as u64
        } else {
            0
        };
        let next = self.state.next_sample[s as usize];
        if end <= next {
            return (next, next);
        }
        let first = next.max(end.saturating_sub(MAX_SAMPLES_PER_STEP));
        self.state.next_sample[s as usize] = end;
        (first, end)
    }

    fn sample_until(&mut self, truth: &Truth, x: &[f64; N_ANALOG], t_end: f64) {
        for s in [Sensor::Accel, Sensor::Gyro, Sensor::Mag, Sensor::Pitot] {
            let (first, end) = self.due(s, t_end);
            let channels = match s {
                Sensor::Accel => 0..3,
                Sensor::Gyro => 3..6,
                Sensor::Mag => 6..9,
                _ => 9..10,
            };
            let std = self.derived.white_std[s as usize];
            let period = self.derived.period[s as usize];
            let coeffs = self.derived.filter[s as usize];
            for k in first..end {
                let tk = self.state.t0 + k as f64 * period;
                for c in channels.clone() {
                    let raw = x[c] + std * self.state.rng[s as usize].normal();
                    let y = coeffs.apply(&mut self.state.filter[c], raw);
                    let y = if c == PITOT { indicated_airspeed(y) } else { y };
                    self.state.out.analog[c] = self.fault(c, tk, y);
                }
            }
        }
        let (first, end) = self.due(Sensor::Gps, t_end);
        let period = self.derived.period[Sensor::Gps as usize];
        for k in first..end {
            let tk = self.state.t0 + k as f64 * period;
            self.gps_fix(truth, tk);
        }
    }

    /// The output of channel `c` at sample instant `tk` after fault injection.
    fn fault(&mut self, c: usize, tk: f64, y: f64) -> f64 {
        let p = &self.params;
        if p.fault_channel as usize != c + 1 || p.fault_mode == FaultMode::None {
            return y;
        }
        if !in_window(tk, p.fault_start, p.fault_duration) {
            self.state.stuck = None;
            return y;
        }
        match p.fault_mode {
            FaultMode::Stuck => *self.state.stuck.get_or_insert(self.state.out.analog[c]),
            FaultMode::Offset => y + p.fault_magnitude,
            FaultMode::None => y,
        }
    }

    fn gps_fix(&mut self, truth: &Truth, tk: f64) {
        let p = self.params;
        if in_window(tk, p.gps_dropout_start, p.gps_dropout_duration) {
            self.state.out.gps_valid = false;
            return;
        }
        let rng = &mut self.state.rng[Sensor::Gps as usize];
        let (lat, lon, h) = self
            .derived
            .tangent
            .geodetic(truth.pos_ned.x, truth.pos_ned.y, truth.pos_ned.z);
        let out = &mut self.state.out;
        out.gps_latitude = lat + p.gps_latlon_std * rng.normal();
        out.gps_longitude = lon + p.gps_latlon_std * rng.normal();
        out.gps_height = h + p.gps_height_std * rng.normal();
        for i in 0..3 {
            out.gps_vel[i] = truth.vel_ned[i] + p.gps_vel_std * rng.normal();
        }
        out.gps_fix_count = out.gps_fix_count.wrapping_add(1);
        out.gps_valid = true;
    }
}
