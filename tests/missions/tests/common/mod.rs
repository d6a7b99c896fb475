//! Test helpers: true trajectories of the real physics, a seeded Gaussian RNG and the
//! synthesis of sensor measurements from the true state with thesis Table D.1 noise
//! (GPS at 4 Hz, IMU / magnetometer / pitot every 20 ms).

#![allow(dead_code)]

use closed_loop::{fly, plant_inputs, Scenario};
use flight_mission::MissionParams;
use lqr_control::{LqrController, LqrParams};
use nalgebra::{Matrix3, Vector3, Vector4};
use state_estimator::{attitude_error, Ekf, EstimatorParams, Measurements, StepReport};
use tailsitter_physics::{dcm_earth_to_body, idx, Airframe, InputVector, Plant, StateVector};

/// Communication / IMU step (s).
pub const H: f64 = 0.02;
/// GPS period (s): 4 Hz.
pub const GPS_PERIOD: f64 = 0.25;

/// SplitMix64 (Steele, Lea, Flood 2014) with Box–Muller normals.
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Self {
        Self(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ 0xD1B5_4A32_D192_ED03)
    }

    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in (0, 1).
    fn uniform(&mut self) -> f64 {
        ((self.next_u64() >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }

    /// Standard normal (Box–Muller).
    pub fn normal(&mut self) -> f64 {
        let (u1, u2) = (self.uniform(), self.uniform());
        (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
    }

    pub fn normal3(&mut self, sigma: f64) -> Vector3<f64> {
        Vector3::new(self.normal(), self.normal(), self.normal()) * sigma
    }
}

/// A true trajectory: states at t_k = k H and the commands held over [t_k, t_k + H).
pub struct Truth {
    pub plant: Plant,
    /// Constant wind, NED (m/s).
    pub wind: Vector3<f64>,
    pub x: Vec<StateVector>,
    pub u: Vec<InputVector>,
}

impl Truth {
    pub fn len(&self) -> usize {
        self.u.len()
    }
}

/// A trim moved into a constant wind: the same air-relative state, inertial velocity + wind.
fn in_wind(mut x: StateVector, wind: &Vector3<f64>) -> StateVector {
    let vw = dcm_earth_to_body(&quat(&x)) * wind;
    x[idx::U] += vw.x;
    x[idx::V] += vw.y;
    x[idx::W] += vw.z;
    x
}

/// The default mission (vertical climb → transition → level → transition → vertical,
/// 35 s) flown by the LQR controller on the true state in a constant wind: climb, level
/// flight and two manoeuvres.
pub fn mission_truth(wind: Vector3<f64>) -> Truth {
    let plant = Plant::new(Airframe::default());
    let m = MissionParams::default();
    let x0 = in_wind(plant.trim_vertical_climb(m.v_vertical).unwrap().state, &wind);
    let mut c = LqrController::new(Airframe::default(), m, LqrParams::default()).unwrap();
    let mut scenario = Scenario::mission(m);
    scenario.wind = closed_loop::Wind::Constant(wind);
    let trace = fly(&plant, x0, &mut c, &scenario);
    assert!(trace.failure.is_none(), "{:?}", trace.failure);
    let x: Vec<StateVector> = trace.samples.iter().map(|s| s.x).collect();
    // The last sample's command acts after the end: n states, n − 1 commands.
    let u = trace.samples[..x.len() - 1]
        .iter()
        .map(|s| plant_inputs(&s.command))
        .collect();
    Truth { plant, wind, x, u }
}

/// Trimmed level flight at 25 m/s in a constant wind, commands held, for `duration` s.
pub fn level_truth(duration: f64, wind: Vector3<f64>) -> Truth {
    let plant = Plant::new(Airframe::default());
    let trim = plant.trim_level(25.0).unwrap();
    let mut x = in_wind(trim.state, &wind);
    let n = (duration / H).round() as usize;
    let (mut xs, mut us) = (Vec::with_capacity(n + 1), Vec::with_capacity(n));
    for _ in 0..n {
        xs.push(x);
        us.push(trim.inputs);
        plant.advance(&mut x, &trim.inputs, &wind, H).unwrap();
    }
    xs.push(x);
    Truth {
        plant,
        wind,
        x: xs,
        u: us,
    }
}

/// Noise-free and noisy measurement synthesis.
pub struct SensorSim {
    pub params: EstimatorParams,
    pub rng: Rng,
    pub fix_count: i32,
    /// GPS valid (false: dropout, fix counter frozen).
    pub gps_on: bool,
    last_fix_slot: i64,
    held: [f64; 3],
    held_vel: Vector3<f64>,
    /// Constant sensor biases of this run, drawn from the filter's prior.
    pub gyro_bias: Vector3<f64>,
    pub accel_bias: Vector3<f64>,
}

impl SensorSim {
    pub fn new(params: &EstimatorParams, seed: u64) -> Self {
        let mut rng = Rng::new(seed);
        let gyro_bias = rng.normal3(params.tuning.init_std_gyro_bias);
        let accel_bias = rng.normal3(params.tuning.init_std_accel_bias);
        Self {
            gyro_bias,
            accel_bias,
            params: params.clone(),
            rng,
            fix_count: 0,
            gps_on: true,
            last_fix_slot: -1,
            held: [0.0; 3],
            held_vel: Vector3::zeros(),
        }
    }

    /// Measurements at step `k` of `truth` (time k H). The GPS samples the true state at the
    /// first communication point of each 250 ms period and holds it until the next fix.
    pub fn measure(&mut self, ekf: &Ekf, truth: &Truth, k: usize) -> Measurements {
        let u = truth.u[k.min(truth.len() - 1)];
        self.measure_state(ekf, &truth.plant, &truth.x[k], &u, &truth.wind, k)
    }

    /// Measurements of the plant state `x` (commands `u`, wind) at step `k` (time k H).
    pub fn measure_state(
        &mut self,
        ekf: &Ekf,
        plant: &Plant,
        x: &StateVector,
        u: &InputVector,
        wind: &Vector3<f64>,
        k: usize,
    ) -> Measurements {
        let wind = *wind;
        let y = plant.outputs(x, u, &wind);
        let n = self.params.noise;
        let c = dcm_earth_to_body(&quat(x));
        let pos = Vector3::new(x[idx::POS_N], x[idx::POS_E], x[idx::POS_D]);
        let slot = ((k as f64 * H + 1e-9) / GPS_PERIOD).floor() as i64;
        let mut m = Measurements {
            accel: y.specific_force_body + self.accel_bias + self.rng.normal3(n.sigma_accel),
            gyro: Vector3::new(x[idx::P], x[idx::Q], x[idx::R]) + self.gyro_bias + self.rng.normal3(n.sigma_gyro),
            mag: c * self.params.earth.mag_ned() + self.rng.normal3(n.sigma_mag),
            pitot: {
                let u = (c * (y.vel_ned - wind)).x;
                u + n.pitot_sigma(u, self.params.tuning.pitot_min_airspeed) * self.rng.normal()
            },
            gps_valid: self.gps_on,
            ..Default::default()
        };
        if self.gps_on && slot != self.last_fix_slot {
            // A new fix of the true state now.
            self.last_fix_slot = slot;
            self.fix_count += 1;
            let (la, lo, h) = ekf.frame().to_geodetic(&pos);
            self.held = [
                la + n.sigma_gps_latlon * self.rng.normal(),
                lo + n.sigma_gps_latlon * self.rng.normal(),
                h + n.sigma_gps_height * self.rng.normal(),
            ];
            self.held_vel = y.vel_ned + self.rng.normal3(n.sigma_gps_vel);
        }
        // Between fixes the receiver holds its last fix (same counter: not fused again).
        m.gps_latitude = self.held[0];
        m.gps_longitude = self.held[1];
        m.gps_height = self.held[2];
        m.gps_vel = self.held_vel;
        m.gps_fix_count = self.fix_count;
        m
    }
}

pub fn quat(x: &StateVector) -> Vector4<f64> {
    x.fixed_rows::<4>(idx::Q1).into_owned()
}

/// Errors (true − estimate) of position, velocity and attitude and their NEES.
pub struct Errors {
    pub pos: Vector3<f64>,
    pub vel: Vector3<f64>,
    pub att: Vector3<f64>,
    pub nees: [f64; 3],
}

pub fn errors(ekf: &Ekf, truth: &Truth, k: usize) -> Errors {
    let x = &truth.x[k];
    let u = &truth.u[k.min(truth.len() - 1)];
    let y = truth.plant.outputs(x, u, &truth.wind);
    let s = &ekf.state;
    let pos = Vector3::new(x[idx::POS_N], x[idx::POS_E], x[idx::POS_D]) - s.pos;
    let vel = y.vel_ned - s.vel;
    let att = attitude_error(&dcm_earth_to_body(&quat(x)), &dcm_earth_to_body(&s.quat));
    let nees_of = |e: &Vector3<f64>, k0: usize| {
        let p: Matrix3<f64> = s.cov.fixed_view::<3, 3>(k0, k0).into_owned();
        e.dot(&(p.try_inverse().expect("covariance block invertible") * e))
    };
    Errors {
        nees: [nees_of(&pos, 0), nees_of(&vel, 3), nees_of(&att, 6)],
        pos,
        vel,
        att,
    }
}

/// Run the filter along `truth` with the measurements of seed `seed`. `perturb(k, sim, m)`
/// may alter the measurements of step k; `observe(k + 1, ekf, report)` sees the estimate at
/// t_{k+1} after each step.
pub fn run_filter(
    truth: &Truth,
    params: &EstimatorParams,
    seed: u64,
    mut perturb: impl FnMut(usize, &mut SensorSim, &mut Measurements),
    mut observe: impl FnMut(usize, &Ekf, &StepReport),
) -> Ekf {
    let mut ekf = Ekf::new(params.clone()).unwrap();
    let mut sim = SensorSim::new(params, seed);
    let mut m0 = sim.measure(&ekf, truth, 0);
    perturb(0, &mut sim, &mut m0);
    ekf.initialize(&m0);
    for k in 0..truth.len() {
        let mut m = if k == 0 { m0 } else { sim.measure(&ekf, truth, k) };
        if k > 0 {
            perturb(k, &mut sim, &mut m);
        }
        let rep = ekf.step(&m, &truth.u[k], H);
        observe(k + 1, &ekf, &rep);
    }
    ekf
}

/// The parameters for the synthesised sensors of these tests: white noise per step of
/// Table D.1's σ (magnetometer 0.02 Gauss unfiltered), pitot white 0.5 m/s, no analogue
/// filter (its compensation would differentiate white noise).
pub fn unfiltered_params() -> EstimatorParams {
    let mut p = EstimatorParams::default();
    p.filter.enabled = false;
    p.noise.sigma_mag = 0.02;
    p.noise.sigma_pitot = 0.5;
    p.noise.sigma_pitot_dp = 1e-6;
    p
}
