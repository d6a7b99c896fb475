//! The atmosphere of the tail-sitter co-simulation (pure Rust, no FFI): the wind
//! the plant's `wind_n`, `wind_e`, `wind_d` inputs take, as the sum of
//! - a steady wind with a height profile (uniform, power law or logarithmic law),
//! - Dryden turbulence, MIL-F-8785C §3.7 spectra with the low-altitude
//!   intensities and scale lengths, from shaping filters discretised exactly at an
//!   internal sample time ([`dryden`]) and driven by the project's seeded,
//!   platform-independent noise generator (`sensor_model::rng`),
//! - a discrete 1 − cos gust.
//!
//! [`Atmosphere::start`] at the start time, then [`Atmosphere::step`]`(inputs, t, h)`
//! returns the wind for [t, t + h): the steady wind at the height of the inputs set
//! for t, the turbulence and the gust of the last internal sample at or before t.
//! Internal samples sit at t₀ + k·T whatever the communication step (so the output
//! at a common instant does not depend on the step, to the bit, for inputs constant
//! over the coarser step); the samples in (t_prev, t] use the inputs set for t.
//! [`State`] saves and restores bit-exactly.

pub mod dryden;

use dryden::{Coefficients, Dryden};
use sensor_model::rng::NoiseRng;

/// One international knot (m/s): 1852 m per hour.
pub const KNOT: f64 = 1852.0 / 3600.0;
/// One foot (m).
pub const FOOT: f64 = 0.3048;
/// W20 (wind speed at 20 ft) of `turbulence_intensity` 0 none, 1 light,
/// 2 moderate, 3 severe: 0, 15, 30, 45 kt (MIL-F-8785C §3.7, low-altitude model).
pub const W20_PRESETS: [f64; 4] = [0.0, 15.0 * KNOT, 30.0 * KNOT, 45.0 * KNOT];
/// Above this height (m) the steady-wind profile holds its value (a numeric guard:
/// the boundary-layer laws mean nothing there, and the power law stays finite).
pub const PROFILE_MAX_HEIGHT: f64 = 10_000.0;
/// Most internal turbulence samples one step may take (a step of 10⁷ samples takes
/// about a second): beyond, the step is refused with a message naming the fix.
pub const MAX_SAMPLES_PER_STEP: u64 = 10_000_000;

/// Everything configurable (the FMU parameters; defaults generated from
/// `modelDescription/tailsitter_atmosphere.json`). SI units, angles in rad.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Params {
    /// Steady wind speed at `wind_ref_height` (m/s).
    pub wind_speed: f64,
    /// Direction the wind blows FROM, clockwise from north (rad).
    pub wind_from: f64,
    /// Reference height of `wind_speed` above the ground (m).
    pub wind_ref_height: f64,
    /// 0 uniform, 1 power law, 2 logarithmic law.
    pub wind_profile: i32,
    /// Power-law exponent (–).
    pub wind_profile_exponent: f64,
    /// Log-law roughness length z0 (m).
    pub wind_roughness_length: f64,
    /// Lowest height of the profile (m).
    pub wind_min_height: f64,
    /// Height of the NED origin above the ground (m).
    pub origin_height: f64,
    /// 0 none, 1 Dryden.
    pub turbulence_model: i32,
    /// 0 none, 1 light, 2 moderate, 3 severe ([`W20_PRESETS`]).
    pub turbulence_intensity: i32,
    /// W20 override (m/s); 0 = the preset of `turbulence_intensity`.
    pub turbulence_w20: f64,
    /// Internal sample time of the turbulence (s).
    pub turbulence_sample_time: f64,
    /// Floor of the airspeed in the Dryden filters (m/s).
    pub turbulence_min_airspeed: f64,
    /// Noise seed (every i32 maps to a distinct 64-bit seed).
    pub seed: i32,
    /// Peak of the 1 − cos gust, NED (m/s).
    pub gust_amplitude_n: f64,
    pub gust_amplitude_e: f64,
    pub gust_amplitude_d: f64,
    /// Start and duration of the gust (s).
    pub gust_start: f64,
    pub gust_duration: f64,
}

include!(concat!(env!("OUT_DIR"), "/params_generated.rs"));

/// The steady-wind height profile.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Profile {
    /// The reference speed at every height.
    Uniform,
    /// U(h) = U_ref (h / h_ref)^exponent.
    Power { exponent: f64 },
    /// U(h) = U_ref ln(h / z0) / ln(h_ref / z0).
    Log { z0: f64 },
}

/// A parameter out of range (its name and why), and an input or a step the model cannot
/// take (non-finite value, too many samples): the sensor model's error types.
pub use sensor_model::{InputError, ParamError};

/// What the atmosphere reads (plant outputs of the same names), held over a step.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Inputs {
    /// NED position of the CG (m); only the down component matters.
    pub pos_ned: [f64; 3],
    /// Air-relative speed (m/s).
    pub airspeed: f64,
}

impl Inputs {
    fn check(&self) -> Result<(), InputError> {
        let named = [
            ("pos_n", self.pos_ned[0]),
            ("pos_e", self.pos_ned[1]),
            ("pos_d", self.pos_ned[2]),
            ("airspeed", self.airspeed),
        ];
        for (name, value) in named {
            if !value.is_finite() {
                return Err(InputError(format!("input {name} = {value} is not finite")));
            }
        }
        Ok(())
    }
}

impl Params {
    /// Check every parameter; the error names the first one out of range.
    pub fn validate(&self) -> Result<(), ParamError> {
        let bad = |name: &str, value: f64, why: &str| Err(ParamError(format!("{name} = {value}: {why}")));
        let within = |name: &str, value: f64, lo: f64, hi: f64, unit: &str| {
            if value.is_finite() && (lo..=hi).contains(&value) {
                Ok(())
            } else {
                bad(name, value, &format!("must be finite and within [{lo}, {hi}] {unit}"))
            }
        };
        within("wind_speed", self.wind_speed, 0.0, 100.0, "m/s")?;
        let two_pi = 2.0 * std::f64::consts::PI;
        within("wind_from", self.wind_from, -two_pi, two_pi, "rad")?;
        within("wind_ref_height", self.wind_ref_height, 0.01, 1000.0, "m")?;
        within("wind_profile_exponent", self.wind_profile_exponent, 0.0, 1.0, "(-)")?;
        within("wind_roughness_length", self.wind_roughness_length, 1e-5, 10.0, "m")?;
        within("wind_min_height", self.wind_min_height, 1e-3, 100.0, "m")?;
        within("origin_height", self.origin_height, -1e4, 1e4, "m")?;
        within("turbulence_w20", self.turbulence_w20, 0.0, 50.0, "m/s")?;
        within("turbulence_sample_time", self.turbulence_sample_time, 1e-4, 1.0, "s")?;
        within(
            "turbulence_min_airspeed",
            self.turbulence_min_airspeed,
            0.1,
            100.0,
            "m/s",
        )?;
        for (name, a) in [
            ("gust_amplitude_n", self.gust_amplitude_n),
            ("gust_amplitude_e", self.gust_amplitude_e),
            ("gust_amplitude_d", self.gust_amplitude_d),
        ] {
            within(name, a, -100.0, 100.0, "m/s")?;
        }
        within("gust_start", self.gust_start, -1e9, 1e9, "s")?;
        within("gust_duration", self.gust_duration, 0.0, 1e6, "s")?;
        match self.wind_profile {
            0 | 1 => {}
            2 => {
                let z0 = self.wind_roughness_length;
                if self.wind_ref_height <= z0 {
                    return bad(
                        "wind_ref_height",
                        self.wind_ref_height,
                        &format!("the logarithmic law needs it above wind_roughness_length ({z0} m)"),
                    );
                }
                if self.wind_min_height <= z0 {
                    return bad(
                        "wind_min_height",
                        self.wind_min_height,
                        &format!("the logarithmic law needs it above wind_roughness_length ({z0} m)"),
                    );
                }
            }
            other => {
                return Err(ParamError(format!(
                    "wind_profile = {other}: expected 0 (uniform), 1 (power law) or 2 (logarithmic law)"
                )))
            }
        }
        if !(0..=1).contains(&self.turbulence_model) {
            return Err(ParamError(format!(
                "turbulence_model = {}: expected 0 (none) or 1 (Dryden)",
                self.turbulence_model
            )));
        }
        if !(0..=3).contains(&self.turbulence_intensity) {
            return Err(ParamError(format!(
                "turbulence_intensity = {}: expected 0 (none), 1 (light), 2 (moderate) or 3 (severe)",
                self.turbulence_intensity
            )));
        }
        Ok(())
    }

    /// The steady-wind profile law.
    pub fn profile(&self) -> Profile {
        match self.wind_profile {
            1 => Profile::Power {
                exponent: self.wind_profile_exponent,
            },
            2 => Profile::Log {
                z0: self.wind_roughness_length,
            },
            _ => Profile::Uniform,
        }
    }

    /// The W20 that sets the turbulence intensity (m/s): the override, else the
    /// preset; 0 without turbulence.
    pub fn w20(&self) -> f64 {
        if self.turbulence_model == 0 {
            0.0
        } else if self.turbulence_w20 > 0.0 {
            self.turbulence_w20
        } else {
            W20_PRESETS[self.turbulence_intensity.clamp(0, 3) as usize]
        }
    }

    /// The 64-bit seed of the noise generator.
    pub fn seed64(&self) -> u64 {
        self.seed as i64 as u64
    }
}

/// Everything that evolves: the noise stream, the sample clock, the shaping-filter
/// states (unit-variance coordinates, see [`dryden`]) and the held output.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct State {
    pub rng: NoiseRng,
    /// Start time: origin of the sample grid t0 + k·T (s).
    pub t0: f64,
    /// Index of the next internal sample.
    pub next_sample: u64,
    /// Filter states of u, v, w.
    pub turbulence: Dryden,
    /// The held output: wind in NED (m/s).
    pub wind: [f64; 3],
    /// [`Atmosphere::start`] ran.
    pub started: bool,
}

/// Number of u64 words of [`State::save`].
pub const STATE_WORDS: usize = 4 + 1 + 1 + dryden::STATE_LEN + 3 + 1;

impl State {
    /// Serialise to [`STATE_WORDS`] words (f64 as IEEE bits: bit-exact).
    pub fn save(&self, out: &mut dyn FnMut(u64)) {
        self.rng.to_parts().iter().for_each(|w| out(*w));
        out(self.t0.to_bits());
        out(self.next_sample);
        self.turbulence.to_array().iter().for_each(|x| out(x.to_bits()));
        self.wind.iter().for_each(|x| out(x.to_bits()));
        out(u64::from(self.started));
    }

    /// Read what [`Self::save`] wrote; rejects truncated or inconsistent data.
    pub fn restore(next: &mut dyn FnMut() -> Option<u64>) -> Result<Self, String> {
        let mut word = || next().ok_or_else(|| "atmosphere state truncated".to_string());
        let finite = |w: u64, what: &str| {
            let x = f64::from_bits(w);
            if x.is_finite() {
                Ok(x)
            } else {
                Err(format!("atmosphere state: {what} is not finite"))
            }
        };
        let s = [word()?, word()?, word()?, word()?];
        let rng =
            NoiseRng::from_parts(s).ok_or_else(|| "atmosphere state: invalid noise generator state".to_string())?;
        let t0 = finite(word()?, "t0")?;
        let next_sample = word()?;
        let mut x = [0.0; dryden::STATE_LEN];
        for v in x.iter_mut() {
            *v = finite(word()?, "turbulence filter state")?;
        }
        let mut wind = [0.0; 3];
        for v in wind.iter_mut() {
            *v = finite(word()?, "wind output")?;
        }
        let started = match word()? {
            0 => false,
            1 => true,
            w => return Err(format!("atmosphere state: started flag {w} is not 0/1")),
        };
        Ok(Self {
            rng,
            t0,
            next_sample,
            turbulence: Dryden::from_array(x),
            wind,
            started,
        })
    }
}

/// The atmosphere: parameters, derived constants, [`State`] and a cache of the
/// filter coefficients of the last (height, airspeed) (not state: recomputed alike).
#[derive(Debug, Clone, PartialEq)]
pub struct Atmosphere {
    params: Params,
    profile: Profile,
    w20: f64,
    /// Unit vectors of the turbulence axes u (along the mean wind) and v (90° right of
    /// it), horizontal NED; w is down.
    axis_u: [f64; 2],
    axis_v: [f64; 2],
    state: State,
    cache: Option<(u64, u64, Coefficients)>,
}

impl Atmosphere {
    /// A model with checked parameters; [`Self::start`] must run before [`Self::step`].
    pub fn new(params: Params) -> Result<Self, ParamError> {
        params.validate()?;
        // Turbulence axes: u along the mean wind (it blows towards wind_from + π),
        // north without mean wind.
        let (axis_u, axis_v) = if params.wind_speed > 0.0 {
            let (s, c) = (libm::sin(params.wind_from), libm::cos(params.wind_from));
            ([-c, -s], [s, -c])
        } else {
            ([1.0, 0.0], [0.0, 1.0])
        };
        Ok(Self {
            params,
            profile: params.profile(),
            w20: params.w20(),
            axis_u,
            axis_v,
            state: State {
                rng: NoiseRng::from_seed(params.seed64()),
                t0: 0.0,
                next_sample: 0,
                turbulence: Dryden::default(),
                wind: [0.0; 3],
                started: false,
            },
            cache: None,
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

    /// The held output: wind in NED (m/s).
    pub fn wind(&self) -> [f64; 3] {
        self.state.wind
    }

    /// Whether the turbulence is on (Dryden with W20 > 0).
    pub fn turbulent(&self) -> bool {
        self.w20 > 0.0
    }

    /// Height of the CG above the ground (m).
    pub fn height(&self, inputs: &Inputs) -> f64 {
        self.params.origin_height - inputs.pos_ned[2]
    }

    /// Steady wind speed at height `h` (m/s).
    pub fn steady_speed(&self, h: f64) -> f64 {
        let p = &self.params;
        let hc = h.clamp(p.wind_min_height, PROFILE_MAX_HEIGHT);
        match self.profile {
            Profile::Uniform => p.wind_speed,
            Profile::Power { exponent } => p.wind_speed * libm::pow(hc / p.wind_ref_height, exponent),
            Profile::Log { z0 } => p.wind_speed * libm::log(hc / z0) / libm::log(p.wind_ref_height / z0),
        }
    }

    /// Steady wind at height `h`, NED (m/s): it blows from `wind_from`.
    pub fn steady_wind(&self, h: f64) -> [f64; 3] {
        let u = self.steady_speed(h);
        [u * self.axis_u[0], u * self.axis_u[1], 0.0]
    }

    /// The 1 − cos gust at time `t`, NED (m/s).
    pub fn gust(&self, t: f64) -> [f64; 3] {
        let p = &self.params;
        let s = t - p.gust_start;
        if p.gust_duration <= 0.0 || !(0.0..=p.gust_duration).contains(&s) {
            return [0.0; 3];
        }
        let shape = 0.5 * (1.0 - libm::cos(2.0 * std::f64::consts::PI * s / p.gust_duration));
        [
            shape * p.gust_amplitude_n,
            shape * p.gust_amplitude_e,
            shape * p.gust_amplitude_d,
        ]
    }

    /// Filter coefficients for the inputs (cached on their bits).
    fn coefficients(&mut self, h: f64, airspeed: f64) -> Coefficients {
        let key = (h.to_bits(), airspeed.to_bits());
        if let Some((kh, kv, c)) = self.cache {
            if (kh, kv) == key {
                return c;
            }
        }
        let v = airspeed.max(self.params.turbulence_min_airspeed);
        let c = Coefficients::new(h, v, self.w20, self.params.turbulence_sample_time);
        self.cache = Some((key.0, key.1, c));
        c
    }

    /// Time of the last internal sample taken (s).
    pub fn last_sample_time(&self) -> f64 {
        self.state.t0 + self.state.next_sample.saturating_sub(1) as f64 * self.params.turbulence_sample_time
    }

    /// The output from the held filter state: steady wind at the inputs' height,
    /// turbulence and gust at the last internal sample.
    fn output(&mut self, inputs: &Inputs) -> [f64; 3] {
        let h = self.height(inputs);
        let mut wind = self.steady_wind(h);
        if self.turbulent() {
            let c = self.coefficients(h, inputs.airspeed);
            let [u, v, w] = self.state.turbulence.output(&c);
            wind[0] += u * self.axis_u[0] + v * self.axis_v[0];
            wind[1] += u * self.axis_u[1] + v * self.axis_v[1];
            wind[2] += w;
        }
        let g = self.gust(self.last_sample_time());
        [wind[0] + g[0], wind[1] + g[1], wind[2] + g[2]]
    }

    /// Start at `t0`: the turbulence filters start in their stationary distribution
    /// (no start-up transient) and that is the internal sample k = 0 at t0. Returns
    /// the wind for t0. The noise stream continues (reseed by building a new model).
    pub fn start(&mut self, inputs: &Inputs, t0: f64) -> Result<[f64; 3], InputError> {
        if !t0.is_finite() {
            return Err(InputError(format!("start time {t0} is not finite")));
        }
        inputs.check()?;
        let st = &mut self.state;
        st.t0 = t0;
        st.next_sample = 1;
        st.turbulence = if self.w20 > 0.0 {
            Dryden::stationary(&mut st.rng)
        } else {
            Dryden::default()
        };
        st.started = true;
        self.state.wind = self.output(inputs);
        Ok(self.state.wind)
    }

    /// Advance to `t` (the internal samples at t0 + k·T ≤ t, with the inputs set for
    /// t) and return the wind for [t, t + h): steady wind at the inputs' height,
    /// turbulence and gust of the last sample. `h` ≥ 0 is only checked: the output
    /// holds over the step.
    pub fn step(&mut self, inputs: &Inputs, t: f64, h: f64) -> Result<[f64; 3], InputError> {
        if !(t.is_finite() && h.is_finite() && h >= 0.0) {
            return Err(InputError(format!("step from t = {t} s by h = {h} s")));
        }
        if !self.state.started {
            return Err(InputError("step before start".into()));
        }
        inputs.check()?;
        let period = self.params.turbulence_sample_time;
        // Sample k is due iff t0 + k·T ≤ t (a 10⁻⁶-period margin absorbs the rounding of t).
        let x = (t - self.state.t0) / period + 1e-6;
        let end = if x >= 0.0 {
            (x.floor() + 1.0).min(u64::MAX as f64) as u64
        } else {
            0
        };
        let next = self.state.next_sample;
        if end > next {
            if self.turbulent() {
                let n = end - next;
                if n > MAX_SAMPLES_PER_STEP {
                    return Err(InputError(format!(
                        "step to t = {t} s needs {n} turbulence samples (at most {MAX_SAMPLES_PER_STEP} per step): \
                         raise turbulence_sample_time or shorten the step"
                    )));
                }
                let c = self.coefficients(self.height(inputs), inputs.airspeed);
                let st = &mut self.state;
                for _ in 0..n {
                    st.turbulence.advance(&c, &mut st.rng);
                }
            }
            self.state.next_sample = end;
        }
        self.state.wind = self.output(inputs);
        Ok(self.state.wind)
    }
}

#[cfg(test)]
mod tests;
